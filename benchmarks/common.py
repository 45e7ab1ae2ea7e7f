"""Helpers shared by the benchmarks: machine description, errors against the exact solution."""

import datetime
import os
import platform
import subprocess

import numpy as np
from rigid_body_dynamics.physics import FreeRigidBody, quaternions
from rigid_body_dynamics.physics.dynamics import equations
import scipy


def machine():
    """Describe in one line where and when the numbers were measured."""
    cpu = platform.processor() or platform.machine()
    try:
        with open('/proc/cpuinfo') as f:
            for line in f:
                if line.startswith('model name'):
                    cpu = line.split(':', 1)[1].strip()
                    break
    except OSError:
        pass
    load = f', load average {os.getloadavg()[0]:.2f}' if hasattr(os, 'getloadavg') else ''
    try:        # the commit measured (with + when the working tree differs from it)
        here = os.path.dirname(os.path.abspath(__file__))
        commit = subprocess.run(['git', 'describe', '--always', '--dirty=+'], cwd=here,
                                capture_output=True, text=True, timeout=10).stdout.strip()
    except (OSError, subprocess.SubprocessError):
        commit = ''
    load += f', commit {commit}' if commit else ''
    return (f'{datetime.date.today().isoformat()}, {cpu}, {os.cpu_count()} cores, '
            f'Python {platform.python_version()}, numpy {np.__version__}, '
            f'scipy {scipy.__version__}{load}')


def errors(moments, omega0, q0, t, q, omega):
    """
    Largest errors of a sampled run (body frame = principal frame) against the exact motion.

    Returns relative energy, relative |L|, L_w direction (rad) and attitude (rad).
    """
    m = np.asarray(moments, dtype=float)
    t0 = equations.kinetic_energy(m, omega0)
    l0 = equations.angular_momentum_world(m, q0, omega0)
    energy = np.abs(equations.kinetic_energy(m, omega) / t0 - 1.0)
    lw = equations.angular_momentum_world(m, q, omega)
    norm = np.abs(np.linalg.norm(lw, axis=1) / np.linalg.norm(l0) - 1.0)
    cross = np.linalg.norm(np.cross(lw, l0), axis=1)
    direction = np.arctan2(cross, lw @ l0)
    q_exact, _ = FreeRigidBody(moments, omega0, q0).state_at(t)
    attitude = quaternions.angle_between(q, q_exact)
    return float(energy.max()), float(norm.max()), float(direction.max()), float(attitude.max())


def attitude_errors(q_ref, w_ref, qs, ws):
    """
    Return (largest attitude error (rad), largest omega error relative to max |omega|).

    ``q_ref``, ``qs`` (N, 4) quaternions and ``w_ref``, ``ws`` (N, 3) rates (rad/s) at the
    same N times.
    """
    attitude = float(np.max(quaternions.angle_between(np.array(qs), q_ref)))
    omega = float(np.max(np.linalg.norm(np.array(ws) - w_ref, axis=1))
                  / np.max(np.linalg.norm(w_ref, axis=1)))
    return attitude, omega


def fmt(x):
    """Format a table cell in short scientific notation."""
    if x is None:
        return 'n/a'
    if x == 0.0:
        return '0'
    return f'{x:.1e}'


def table(header, rows):
    """Render a Markdown table."""
    out = ['| ' + ' | '.join(header) + ' |', '|' + '---|' * len(header)]
    out += ['| ' + ' | '.join(str(c) for c in row) + ' |' for row in rows]
    return '\n'.join(out)


def best_of(run, repeats):
    """Run ``run()`` ``repeats`` times; return the result of least cost (its item 0)."""
    best = None
    for _ in range(repeats):
        result = run()
        if best is None or result[0] < best[0]:
            best = result
    return best
