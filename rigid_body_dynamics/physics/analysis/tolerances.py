"""
The tolerance policy of the analysis: what counts as agreement, and the status it gives.

A tolerance is a positive number (0 or less is refused with the reason: 0 used
to switch a check off). A measurement is compared with its prediction on a
relative scale; a prediction of exactly 0 has none, so the measurement is
compared on an absolute one; a missing measurement or prediction is
``unavailable``, saying which. Never a silent OK.
"""

from dataclasses import dataclass
import math

from .findings import ERROR, OK, Quantity, RANK, UNAVAILABLE, WARN


@dataclass(frozen=True)
class Tolerances:
    """
    What counts as agreement. Relative unless said; WARN above, ERROR above 100 times.

    ``energy``, ``momentum``: free-motion drift of T, and of |L| and the L
    direction (rad). ``balance``: work-energy and impulse-momentum residuals
    under torque (sampled torque costs an O(dt) quadrature error at each
    change). ``rate``: measured against predicted rates and periods of the
    free motion. ``growth``: the measured growth rate near the intermediate
    axis against the linearised prediction (finite amplitudes differ by
    about 1e-4). ``libration``: measured gravity-gradient libration frequencies
    against the small-angle theory (finite amplitudes differ by about the
    squared angle). ``min_samples``: fewer samples give no estimate.
    """

    energy: float = 1e-6
    momentum: float = 1e-6
    balance: float = 1e-2
    rate: float = 1e-6
    growth: float = 1e-2
    libration: float = 1e-3
    min_samples: int = 20

    def __post_init__(self):
        """Refuse a tolerance that is not a positive number: 0 switched its check off."""
        for name in ('energy', 'momentum', 'balance', 'rate', 'growth', 'libration'):
            value = getattr(self, name)
            if isinstance(value, bool) or not isinstance(value, (int, float)) \
                    or not math.isfinite(value) or value <= 0.0:
                raise ValueError(f'the {name} tolerance must be a finite number > 0, got '
                                 f'{value!r}')
        if isinstance(self.min_samples, bool) or not isinstance(self.min_samples, int) \
                or self.min_samples < 2:
            raise ValueError(f'min_samples must be an integer >= 2, got {self.min_samples!r}')


def level(ratio):
    """Return the status of a ratio error / tolerance: OK up to 1, WARN up to 100, ERROR."""
    return OK if ratio <= 1.0 else (WARN if ratio <= 100.0 else ERROR)


def compare(measured, predicted, tolerance, unit=''):
    """
    Make a :class:`Quantity` of a measurement and its prediction at a relative tolerance.

    ``tolerance`` must be > 0 (ValueError). Without a measurement or without a
    prediction the quantity is ``unavailable``, saying which is missing; a
    prediction of exactly 0 has no relative scale, so the measurement is
    compared on an absolute one: ``|measured|`` against ``tolerance`` (in ``unit``).
    """
    if not tolerance > 0.0:
        raise ValueError(f'a tolerance must be > 0, got {tolerance!r}')
    measured = None if measured is None or not math.isfinite(measured) else float(measured)
    predicted = None if predicted is None or not math.isfinite(predicted) else float(predicted)
    if measured is None:
        return Quantity(None, predicted, UNAVAILABLE, unit, tolerance, 'no measurement')
    if predicted is None:
        return Quantity(measured, None, UNAVAILABLE, unit, tolerance, 'no prediction')
    if predicted == 0.0:
        return Quantity(measured, predicted, level(abs(measured) / tolerance), unit, tolerance,
                        'compared on an absolute scale: the prediction is 0')
    rel = abs(measured - predicted) / abs(predicted)
    return Quantity(measured, predicted, level(rel / tolerance), unit, tolerance)


def unavailable(why, predicted=None, unit=''):
    """Make a :class:`Quantity` without a measurement, saying why (a prediction may exist)."""
    predicted = None if predicted is None or not math.isfinite(predicted) else float(predicted)
    return Quantity(None, predicted, UNAVAILABLE, unit, math.nan, why)


def worst(*statuses):
    """Return the worst of ``statuses`` (``unavailable`` only if all are)."""
    known = [s for s in statuses if s != UNAVAILABLE]
    return max(known, key=RANK.get) if known else UNAVAILABLE
