"""
An independent reference under a zero-order-hold torque: scipy's DOP853 at tight tolerance.

For checking the fixed-step integrators (tests, benchmarks) and for users who
want a second opinion on a run. Slow (a solve_ivp call per hold), accurate to
about 1e-13 rad over tens of seconds at |omega| of a few rad/s.
"""

import numpy as np
from scipy.integrate import solve_ivp

from .equations import state_rhs


def zoh_reference(moments, omega0, q0, hold, holds, command, rtol=2.5e-14):
    """
    Integrate the motion under a torque recomputed every ``hold`` s and held in between.

    ``moments`` (kg m^2, principal, body-axis order), ``omega0`` (rad/s,
    body), ``q0`` (x, y, z, w, body -> world). ``command(k, q, omega)`` returns
    the body torque (N m) held over [k hold, (k + 1) hold), from the state at
    its start (so a controller closes its loop on the reference's own state).
    DOP853 restarts at every hold at ``rtol`` (2.5e-14: near scipy's floor of
    100 eps) and an absolute tolerance of 1e-16 (times |omega| for omega).
    Returns (q, omega) at the ``holds`` + 1 hold boundaries, arrays (N, 4) and
    (N, 3), q renormalised.
    """
    m = np.asarray(moments, dtype=float)
    y = np.concatenate([np.asarray(omega0, dtype=float), np.asarray(q0, dtype=float)])
    y[3:7] /= np.linalg.norm(y[3:7])
    qs, ws = [y[3:7].copy()], [y[:3].copy()]
    for k in range(holds):
        tau = np.asarray(command(k, tuple(y[3:7]), tuple(y[:3])), dtype=float)
        scale = max(float(np.linalg.norm(y[:3])), 1e-9)
        sol = solve_ivp(lambda _t, s: state_rhs(m, s, tau), (0.0, hold), y, method='DOP853',
                        rtol=rtol, atol=np.array([1e-16 * scale] * 3 + [1e-16] * 4))
        if not sol.success:
            raise RuntimeError(f'reference solver failed at hold {k}: {sol.message}')
        y = sol.y[:, -1].copy()
        y[3:7] /= np.linalg.norm(y[3:7])
        qs.append(y[3:7].copy())
        ws.append(y[:3].copy())
    return np.array(qs), np.array(ws)
