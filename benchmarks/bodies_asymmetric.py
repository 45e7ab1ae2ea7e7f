"""
Fleets of asymmetric bodies: how many run in real time, and what to switch off for more.

attitude_fleet processes of asymmetric bodies, I = (1, 2, 3) kg m^2 (three different moments),
odom of every body, 1 kHz integration: how many run in real time with the defaults, and what a
user can switch off to carry more (the other state topics and the imu, a lower publish_rate),
in one fleet and in two (one per core). Same criterion as the bodies sweep.
``./dev bench --only bodies-asymmetric`` (about 15 minutes).
"""

from bodies import measure_asymmetric


def measure():
    """Run the sweep; Markdown lines."""
    return measure_asymmetric()
