"""
Fleets of asymmetric bodies: how many run in real time, and what to switch off for more.

attitude_fleet processes of asymmetric bodies, I = (1, 2, 3) kg m^2 (three different moments),
odom of every body, 1 kHz integration: how many run in real time with the defaults, and what a
user can switch off to carry more (the other state topics and the imu, a lower publish_rate),
with every body in one process (``--processes 1``) and shared round-robin by two worker
processes (``--processes 2``, the default on 2 cores; the CPU is the parent's and the
workers'). Same criterion as the bodies sweep. ``./dev bench --only bodies-asymmetric``
(about 20 minutes).
"""

from bodies import measure_asymmetric


def measure():
    """Run the sweep; Markdown lines."""
    return measure_asymmetric()
