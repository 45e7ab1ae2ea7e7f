"""
simulate() with a callable torque across the separatrix: cost and accuracy, frames and torques.

The held-out case: I = (1, 2, 3) kg m^2, omega0 = (0.02, 2.0, 0.05) rad/s (a spin next to
the intermediate axis), a torque of 0.2 N m about axis 1 that carries it across the
separatrix (S/G^2 from +4.4e-4 to -3.2e-2), 20 s at dt = 10 ms, the torque a callable
evaluated at every step. Variants: the body given by its principal moments or by a full
tensor (the same body turned by a rotation vector (0.3, -0.5, 0.4) rad, so every step
changes frames), the torque a constant tuple or a numpy expression of the state, and a held
torque switched on, off, reversed and off (0.2 N m about axis 1 for t < 3 s, none to 8 s,
-0.2 N m to 11 s, none after: S/G^2 from +4.4e-4 to -3.2e-2 and back to +4.1e-3, two
crossings, with torque-free segments on the exact flow). Cost is wall time per simulated
second (least of five), also over a plain pure-Python RK4 at 1 ms (``torque.plain_rk4``,
the unit the cost targets are stated in) measured in the same run. Accuracy: the largest
attitude error (rad) at the 10 ms holds against scipy's DOP853 at rtol 2.5e-14
(``zoh_reference``), in the principal frame.  ``./dev bench --only simulate-cost``.
"""

import math
import time

from common import best_of, fmt
import numpy as np
from rigid_body_dynamics.physics import Inertia, quaternions, simulate
from rigid_body_dynamics.physics.dynamics.reference import zoh_reference
from scipy.spatial.transform import Rotation
import torque

MOMENTS = (1.0, 2.0, 3.0)
OMEGA0 = (0.02, 2.0, 0.05)
TAU = (0.2, 0.0, 0.0)
TURN = (0.3, -0.5, 0.4)
DURATION, DT = 20.0, 1e-2
REPEATS = 5


def _bodies():
    """{label: (Inertia, q0, omega0 and torque in its body frame)}: one motion."""
    turn = Rotation.from_rotvec(TURN).as_matrix()
    tensor = Inertia.from_tensor(turn @ np.diag(MOMENTS) @ turn.T)
    # the same motion: the principal frame starts at the identity; omega0 and the torque
    # given in the tensor's body frame
    return {'principal moments': (Inertia(MOMENTS), (0.0, 0.0, 0.0, 1.0), OMEGA0, TAU),
            'full tensor': (tensor, tuple(tensor.attitude_to_body(np.array([0.0, 0.0, 0.0, 1.0]))),
                            tuple(tensor.to_body(np.array(OMEGA0))),
                            tuple(tensor.to_body(np.array(TAU))))}


def _switched(t):
    """Return the on-off schedule's sign at t (s): +1 before 3 s, -1 in [8, 11) s, else 0."""
    return 1.0 if t < 3.0 else (-1.0 if 8.0 <= t < 11.0 else 0.0)


def _torques(tau):
    """{label: callable torque(t, q, omega)} for a body torque ``tau``."""
    scale = math.hypot(*tau)
    return {'constant tuple': lambda t, q, w: tau,
            'numpy from the state': lambda t, q, w: scale * np.asarray(tau) /
            np.linalg.norm(tau) + 0.0 * np.asarray(w),
            SWITCHED: lambda t, q, w: tuple(_switched(t) * c for c in tau)}


#: The variant with torque-free segments between the holds of torque.
SWITCHED = 'on, off, reversed, off (two crossings)'


def rows():
    """Return (unit s per simulated s, [(body, torque, error, cost s per s)]) of this tree."""
    torque.CASES['T3 across the separatrix'] = (MOMENTS, OMEGA0, lambda k, q, w: TAU)
    unit = best_of(lambda: torque.plain_rk4('T3 across the separatrix'), REPEATS)[0]
    holds = int(round(DURATION / DT))
    q_ref, _ = zoh_reference(MOMENTS, OMEGA0, (0.0, 0.0, 0.0, 1.0), DT, holds,
                             lambda k, q, w: TAU)
    q_switched, _ = zoh_reference(MOMENTS, OMEGA0, (0.0, 0.0, 0.0, 1.0), DT, holds,
                                  lambda k, q, w: tuple(_switched(k * DT) * c for c in TAU))
    out = []
    for body_label, (inertia, q0, omega0, tau) in _bodies().items():
        for torque_label, fn in _torques(tau).items():
            best, run = math.inf, None
            for _ in range(REPEATS):
                start = time.perf_counter()
                run = simulate(inertia, omega0, q0, duration=DURATION, dt=DT, torque=fn)
                best = min(best, (time.perf_counter() - start) / DURATION)
            q_principal = inertia.attitude_to_principal(run.q)
            reference = q_switched if torque_label == SWITCHED else q_ref
            error = float(quaternions.angle_between(q_principal, reference).max())
            out.append((body_label, torque_label, error, best))
    return unit, out


def measure():
    """Return RESULTS.md lines: cost and accuracy of each variant."""
    unit, after = rows()
    lines = [f'The unit, plain pure-Python RK4 at 1 ms: {unit * 1e3:.2f} ms per simulated s.', '',
             '| body given by | torque callable | attitude error (rad) | cost / unit | '
             'ms per simulated s |', '|---|---|---|---|---|']
    for body, fn, error, cost in after:
        lines.append(f'| {body} | {fn} | {fmt(error)} | {cost / unit:.2f} | {cost * 1e3:.2f} |')
    return lines


if __name__ == '__main__':
    print('\n'.join(measure()))
