"""
Under torque: cost per step and the work-energy / impulse-momentum residuals.

Same body as accuracy.py; a time-varying body torque
tau = (0.05 sin 2 pi t, 0.04 cos 2 pi t, 0.02) N m held over each 1 ms step; T
changes by a few percent, as in a controller's manoeuvre.
"""

import math
import time

from accuracy import MOMENTS, OMEGA0, Q0
from common import fmt
import numpy as np
from rigid_body_dynamics.physics import equations, make_integrator


def measure(steps):
    """Rows: integrator, us/step under torque, |T change|, energy and momentum residuals."""
    m = np.array(MOMENTS)
    t0 = equations.kinetic_energy(m, OMEGA0)
    l0 = equations.angular_momentum_world(m, Q0, OMEGA0)
    rows = []
    for name in ('exact', 'exact4', 'rk4', 'dop853'):
        stepper = make_integrator(name, MOMENTS, 1e-3, Q0, OMEGA0)
        torques = [(0.05 * math.sin(2 * math.pi * k * 1e-3),
                    0.04 * math.cos(2 * math.pi * k * 1e-3), 0.02) for k in range(steps)]
        start = time.perf_counter()
        for tau in torques:
            stepper.step(tau)
        per_step = (time.perf_counter() - start) / steps
        t1 = equations.kinetic_energy(m, np.array(stepper.omega))
        l1 = equations.angular_momentum_world(m, np.array(stepper.q), np.array(stepper.omega))
        rows.append([name, f'{per_step * 1e6:.1f}', fmt(abs(t1 - t0) / t0),
                     fmt(abs(t1 - t0 - stepper.work) / t0),
                     fmt(np.linalg.norm(l1 - l0 - np.array(stepper.impulse))
                         / np.linalg.norm(l0))])
    return rows
