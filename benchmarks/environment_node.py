"""
attitude_simulator in orbit: CPU at 1 kHz, free against the space environment.

The asymmetric body I = (2, 3, 1.2) kg m^2 tumbling at omega0 = (0.3, -0.5, 0.8) rad/s, 1 kHz
steps, 100 Hz publishing, real time: free (no orbit), on a 500 km circular orbit with
nothing acting (the exact torque-free flow still serves), with the gravity gradient,
and with the gravity gradient, the dipole field, a residual dipole and a magnetometer
at 10 Hz (every stage evaluates the orbit, the field and the torques). CPU is the
simulator's share of one core over 8 s after 3 s of warm-up, each case twice,
alternating. ``./dev bench --only environment-node``.
"""

import statistics

from diagnostic_msgs.msg import DiagnosticArray
from nodes import measure_cpu, Probe, sim

ROUNDS = 2
BODY = ('inertia:=[2.0, 3.0, 1.2]', 'initial_angular_velocity:=[0.3, -0.5, 0.8]')
ORBIT = ('orbit_elements:=[6878137.0, 0.0, 1.0, 0.3, 0.0, 0.0]',)


def measure():
    """Return RESULTS.md lines: the simulator's CPU free and in orbit."""
    probe = Probe('bench_environment')
    probe.subscribe(DiagnosticArray, '/diagnostics')
    cases = {
        'free body': sim(*BODY),
        'in orbit, no torque model': sim(*BODY, *ORBIT),
        'in orbit, gravity gradient': sim(*BODY, *ORBIT, 'gravity_gradient:=true'),
        'gravity gradient, field, residual dipole, magnetometer at 10 Hz': sim(
            *BODY, *ORBIT, 'gravity_gradient:=true', 'magnetic_field_model:=dipole',
            'residual_dipole:=[0.01, -0.02, 0.005]', 'magnetometer_rate:=10.0'),
    }
    found = {name: [] for name in cases}
    try:
        for _ in range(ROUNDS):
            for name, cmd in cases.items():
                cpu, diag = measure_cpu(cmd, probe)
                rtf = float(diag[1]['achieved real-time factor']) if diag else float('nan')
                found[name].append((cpu, rtf))
                print(f'{name}: {cpu:.3f} of a core, achieved {rtf:.3f}', flush=True)
    finally:
        probe.close()
    base = statistics.median(c for c, _r in found['free body'])
    lines = ['| simulator | CPU (share of one core, each run) | / free body | achieved '
             'real-time factor |', '|---|---|---|---|']
    for name, runs in found.items():
        median = statistics.median(c for c, _r in runs)
        lines.append(f'| {name} | {", ".join(f"{c:.3f}" for c, _r in runs)} (median '
                     f'{median:.3f}) | {median / base:.1f} | '
                     f'{", ".join(f"{r:.3f}" for _c, r in runs)} |')
    return lines


if __name__ == '__main__':
    print('\n'.join(measure()))
