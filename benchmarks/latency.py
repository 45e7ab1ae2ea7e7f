"""
Torque command to published state: attitude_simulator against a bare relay, three rounds each.

One process publishes 200 torque_cmd 50 ms apart and times each until the first
applied_torque carrying it (the simulator at 1 kHz integration and publishing, so one step
is 1 ms; the integration thread takes pending commands itself before every step) or until
a minimal rclpy relay republishes it (the floor: two DDS hops and an executor). Rounds
alternate, so machine noise hits both. ``./dev bench --only latency`` (about 1 minute).
"""

from nodes import FLOOR_RELAY, latency, script, sim
import numpy as np


def measure(rounds=3):
    """Alternate simulator and relay; Markdown lines."""
    lines = ['| round | path | samples | p50 (ms) | p99 (ms) | max (ms) |',
             '|---|---|---|---|---|---|']
    for k in range(1, rounds + 1):
        for label, cmd in (('attitude_simulator', sim('publish_rate:=1000.0',
                                                      'torque_timeout:=0.0')),
                           ('floor: relay', script(FLOOR_RELAY))):
            lat = latency(cmd)
            lines.append(f'| {k} | {label} | {lat.size} | {1e3 * np.percentile(lat, 50):.2f} | '
                         f'{1e3 * np.percentile(lat, 99):.2f} | {1e3 * lat.max():.2f} |')
            print(lines[-1], flush=True)
    return lines
