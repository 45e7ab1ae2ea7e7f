"""
Fleets of asymmetric bodies with four reaction wheels each: how many run in real time.

attitude_fleet with the asymmetric body of the bodies sweeps (I = (1, 2, 3) kg m^2, omega0 =
(0.3, 1.5, -0.4) rad/s) carrying ``doc/examples/wheels.yaml``'s four pyramid wheels (with
their friction, motors at 0), at the defaults (1 kHz steps, 7 state topics and the imu at
100 Hz, wheel_state at the publish rate), in one process and over two. A body with wheels
has no closed-form flow to skip steps on; with its motors idle, as here, the gyrostat takes
the steps between two reads of its state as one span (order 8, at the same accuracy).
Same criterion as the bodies sweep. Then the same bodies stepped at 100 Hz, the
rate of their state (``integration_rate: 100``): the gyrostat's ``exact`` step takes 10 ms in
order-8 sub-steps at the same accuracy against DOP853 (test_gyrostat.py), and a command is
held for 10 ms. ``./dev bench --only bodies-wheels`` (about 10 minutes).
"""

import os

from bodies import measure_asymmetric, ONE, TWO

HERE = os.path.dirname(os.path.abspath(__file__))
WHEELS = os.path.join(HERE, '..', 'doc', 'examples', 'wheels.yaml')
AT_100_HZ = ('--params-file', WHEELS, '-p', 'integration_rate:=100.0')
SETUPS = (('four wheels (wheels.yaml), defaults', ONE, ('--params-file', WHEELS)),
          ('four wheels (wheels.yaml), defaults', TWO, ('--params-file', WHEELS)),
          ('four wheels (wheels.yaml), steps at 100 Hz', ONE, AT_100_HZ),
          ('four wheels (wheels.yaml), steps at 100 Hz', TWO, AT_100_HZ))


def measure():
    """Run the sweep; Markdown lines."""
    return measure_asymmetric(counts=(8, 16, 24, 32, 48, 64), setups=SETUPS)
