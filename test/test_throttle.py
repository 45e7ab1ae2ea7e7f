"""ThrottledWarnings: one warning per period and kind, with the count held back."""

import logging
import math
import time

from rigid_body_dynamics.ros.throttle import ThrottledWarnings


class Records(logging.Handler):
    """Collect the messages a standard-library logger emits."""

    def __init__(self):
        super().__init__()
        self.messages = []

    def emit(self, record):
        self.messages.append(record.getMessage())


def make_logger(name):
    logger = logging.getLogger(name)
    logger.propagate = False
    records = Records()
    logger.addHandler(records)
    return logger, records


def test_one_per_period_and_kind_with_the_held_back_count():
    logger, records = make_logger('throttle_period')
    warnings = ThrottledWarnings(logger, period=0.2)
    printed = [warnings.warn('nan', 'bad torque') for _ in range(50)]
    assert printed == [True] + [False] * 49
    assert warnings.warn('frame', 'bad frame')           # another kind is not held back
    time.sleep(0.25)
    assert warnings.warn('nan', 'bad torque')
    assert records.messages == ['bad torque', 'bad frame',
                                'bad torque (49 more like this since the last report)']


def test_once():
    logger, records = make_logger('throttle_once')
    warnings = ThrottledWarnings(logger)
    printed = [warnings.warn('force', 'force ignored', period=math.inf) for _ in range(1000)]
    assert printed == [True] + [False] * 999
    assert records.messages == ['force ignored']
