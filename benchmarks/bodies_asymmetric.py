"""
One attitude_fleet (shared integration thread) of asymmetric bodies, I = (1, 2, 3) kg m^2
spinning near the intermediate axis, odom of every body at 100 Hz: how many run in real time
with the defaults, and what a user can switch off to carry more (integration_rate, which
costs no accuracy for exact; state_topics; publish_imu). Same criterion as the bodies sweep.
``./dev bench --only bodies-asymmetric`` (about 10 minutes).
"""

from bodies import measure_asymmetric


def measure():
    """Run the sweep; Markdown lines."""
    return measure_asymmetric()
