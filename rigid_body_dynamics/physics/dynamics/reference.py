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


def gyrostat_rhs(moments, wheels, motors, torque=(0.0, 0.0, 0.0),
                 torque_world=(0.0, 0.0, 0.0)):
    """
    Return f(t, y) of the gyrostat in matrix form, y = [omega (3), q (4), speeds (n), angles (n)].

    Written apart from :mod:`.gyrostat`'s scalar code (np.linalg.solve of the coupled
    equations), so the two check each other. ``moments`` principal (kg m^2, the wheels
    locked in), ``wheels`` a :class:`~.gyrostat.Wheels` with axes in that frame,
    ``motors`` n motor torques (N m, within their limits), ``torque`` body and
    ``torque_world`` world external torques (N m), all held.
    """
    from .gyrostat import FRICTION_SMOOTHING
    from ..quaternions import rotate_components
    inertia = np.diag(np.asarray(moments, dtype=float))
    g = np.array(wheels.axes, dtype=float).reshape(-1, 3)
    j = np.array(wheels.inertia, dtype=float)
    a = inertia - (g.T * j) @ g
    coulomb, viscous = np.array(wheels.coulomb), np.array(wheels.viscous)
    u = np.asarray(motors, dtype=float).reshape(len(j))
    n = len(j)

    def rhs(_t, y):
        w, q, s = y[:3], y[3:7], y[7:7 + n]
        h = inertia @ w + g.T @ (j * s)
        tau = np.asarray(torque, dtype=float) + np.array(
            rotate_components((-q[0], -q[1], -q[2], q[3]), torque_world))
        net = u - (coulomb * np.tanh(s / FRICTION_SMOOTHING) + viscous * s)
        w_dot = np.linalg.solve(a, tau - np.cross(w, h) - g.T @ net)
        x, yq, z, qw = q
        q_dot = 0.5 * np.array([qw * w[0] + yq * w[2] - z * w[1], qw * w[1] + z * w[0] - x * w[2],
                                qw * w[2] + x * w[1] - yq * w[0],
                                -(x * w[0] + yq * w[1] + z * w[2])])
        return np.concatenate([w_dot, q_dot, net / j - g @ w_dot, s])
    return rhs


def gyrostat_zoh_reference(moments, wheels, q0, omega0, speeds0, hold, holds, command,
                           rtol=2.5e-14):
    """
    Integrate a gyrostat under commands recomputed every ``hold`` s and held in between.

    ``command(k, q, omega, speeds)`` -> (motor torques, body torque) held over
    [k hold, (k + 1) hold), from the reference's own state; DOP853 restarts at every
    hold at ``rtol`` (absolute 1e-16, times the size of omega and of the speeds).
    Returns (q (N, 4), omega (N, 3), speeds (N, n)) at the ``holds`` + 1 boundaries.
    """
    n = wheels.count
    y = np.concatenate([np.asarray(omega0, float), np.asarray(q0, float),
                        np.asarray(speeds0, float), np.zeros(n)])
    y[3:7] /= np.linalg.norm(y[3:7])
    qs, ws, ss = [y[3:7].copy()], [y[:3].copy()], [y[7:7 + n].copy()]
    for k in range(holds):
        motors, torque = command(k, tuple(y[3:7]), tuple(y[:3]), tuple(y[7:7 + n]))
        w_scale = max(float(np.linalg.norm(y[:3])), 1e-9)
        s_scale = max(float(np.abs(y[7:7 + n]).max(initial=0.0)), 1.0)
        atol = np.array([1e-16 * w_scale] * 3 + [1e-16] * 4 + [1e-16 * s_scale] * n
                        + [1e-16 * s_scale * hold * holds] * n)
        sol = solve_ivp(gyrostat_rhs(moments, wheels, motors, torque), (0.0, hold), y,
                        method='DOP853', rtol=rtol, atol=atol)
        if not sol.success:
            raise RuntimeError(f'reference solver failed at hold {k}: {sol.message}')
        y = sol.y[:, -1].copy()
        y[3:7] /= np.linalg.norm(y[3:7])
        qs.append(y[3:7].copy())
        ws.append(y[:3].copy())
        ss.append(y[7:7 + n].copy())
    return np.array(qs), np.array(ws), np.array(ss)


def space_rhs(moments, mu, field=None, gravity_gradient=True, dipole=(0.0, 0.0, 0.0)):
    """
    Return f(t, y) of a body in orbit, y = [omega (3), q (4), r (3), v (3)], in matrix form.

    Written apart from :mod:`.environment` (which solves Kepler's equation and
    sums scalar torque models): the orbit is integrated here as the two-body ODE
    r'' = -mu r / |r|^3, the field is d = (g11, h11, g10) turned by scipy's
    Rotation, and the torques are numpy cross products. ``moments`` principal (kg
    m^2), ``mu`` (m^3/s^2), ``field`` six numbers (g10, g11, h11 (nT), the
    reference radius (m), the planet's rotation rate (rad/s), its angle at t = 0
    (rad)), given by the caller, not read from the model under test (None = no
    field), ``gravity_gradient`` on or off, ``dipole`` the
    body's total dipole (A m^2, principal frame) held.
    """
    from scipy.spatial.transform import Rotation
    inertia = np.diag(np.asarray(moments, dtype=float))
    m = np.asarray(dipole, dtype=float)
    if field is not None:
        g10, g11, h11, radius, rate, theta0 = (float(c) for c in field)
        d_fixed = np.array([g11, h11, g10]) * 1e-9
        r_ref3 = radius ** 3

    def rhs(t, y):
        w, q, r, v = y[:3], y[3:7], y[7:10], y[10:13]
        body_from_world = Rotation.from_quat(q).inv()
        r_b = body_from_world.apply(r)
        rn = np.linalg.norm(r)
        tau = np.zeros(3)
        if gravity_gradient:
            tau += 3.0 * mu / rn ** 5 * np.cross(r_b, inertia @ r_b)
        if field is not None:
            d = Rotation.from_euler('z', theta0 + rate * t).apply(d_fixed)
            rhat = r / rn
            b_w = r_ref3 / rn ** 3 * (3.0 * (d @ rhat) * rhat - d)
            tau += np.cross(m, body_from_world.apply(b_w))
        w_dot = np.linalg.solve(inertia, tau - np.cross(w, inertia @ w))
        x, yq, z, qw = q
        q_dot = 0.5 * np.array([qw * w[0] + yq * w[2] - z * w[1], qw * w[1] + z * w[0] - x * w[2],
                                qw * w[2] + x * w[1] - yq * w[0],
                                -(x * w[0] + yq * w[1] + z * w[2])])
        return np.concatenate([w_dot, q_dot, v, -mu * r / rn ** 3])
    return rhs


def space_zoh_reference(moments, mu, r0, v0, q0, omega0, hold, holds, command, field=None,
                        gravity_gradient=True, residual=(0.0, 0.0, 0.0), rtol=2.5e-14):
    """
    Integrate a body in orbit under magnetorquer dipoles recomputed every ``hold`` s.

    ``command(k, q, omega)`` -> the dipole (A m^2, principal frame) held over
    [k hold, (k + 1) hold), added to the constant ``residual`` dipole; r0 (m), v0
    (m/s) world, q0 (x, y, z, w), omega0 (rad/s). DOP853 restarts at every hold
    (absolute tolerances 1e-16 of each part's scale). Returns (q (N, 4), omega
    (N, 3), r (N, 3)) at the ``holds`` + 1 boundaries, q renormalised.
    """
    y = np.concatenate([np.asarray(omega0, float), np.asarray(q0, float),
                        np.asarray(r0, float), np.asarray(v0, float)])
    y[3:7] /= np.linalg.norm(y[3:7])
    r_scale, v_scale = float(np.linalg.norm(r0)), float(np.linalg.norm(v0))
    qs, ws, rs = [y[3:7].copy()], [y[:3].copy()], [y[7:10].copy()]
    for k in range(holds):
        dipole = np.asarray(command(k, tuple(y[3:7]), tuple(y[:3])), float) + residual
        w_scale = max(float(np.linalg.norm(y[:3])), 1e-9)
        atol = np.array([1e-16 * w_scale] * 3 + [1e-16] * 4 + [1e-16 * r_scale] * 3
                        + [1e-16 * v_scale] * 3)
        sol = solve_ivp(space_rhs(moments, mu, field, gravity_gradient, dipole),
                        (k * hold, (k + 1) * hold), y, method='DOP853', rtol=rtol, atol=atol)
        if not sol.success:
            raise RuntimeError(f'reference solver failed at hold {k}: {sol.message}')
        y = sol.y[:, -1].copy()
        y[3:7] /= np.linalg.norm(y[3:7])
        qs.append(y[3:7].copy())
        ws.append(y[:3].copy())
        rs.append(y[7:10].copy())
    return np.array(qs), np.array(ws), np.array(rs)


def dop853_through_kinks(rate, y0, end, times, kinks, rtol=2.5e-14, atol=1e-18):
    """
    Return the states (len(times), n) of scipy's DOP853 from 0 to ``end`` s, stopped at kinks.

    ``rate(t, y)`` the right-hand side; ``times`` (s, sorted, within [0, end]) where the
    states are wanted; ``kinks`` event functions g(t, y) whose zeros are where the
    right-hand side has a kink (a facet turning into the light or the flow, the edges of
    a penumbra). A step across one is of low order whatever its tolerance (an adaptive
    step's error estimate does not see it), so the integration ends there and starts
    again: first a microsecond without the events, so that the same zero is not found
    again (the kink inside that step moves the state by the square of a microsecond).
    RuntimeError when an integration fails.
    """
    for g in kinks:
        g.terminal = True
    times = np.asarray(times, float)
    t, y, out = 0.0, np.asarray(y0, float), []
    while True:
        piece = solve_ivp(rate, (t, end), y, method='DOP853', rtol=rtol, atol=atol,
                          t_eval=times[len(out):], events=kinks or None)
        if not piece.success:
            raise RuntimeError(f'the reference failed at t = {t:g} s: {piece.message}')
        out += list(piece.y.T) if len(piece.t) else []
        if piece.status != 1:
            break
        k = [len(e) > 0 for e in piece.t_events].index(True)
        t, y = float(piece.t_events[k][0]), piece.y_events[k][0]
        past = solve_ivp(rate, (t, t + 1e-6), y, method='DOP853', rtol=rtol, atol=atol)
        out += [past.y[:, -1]] * int(np.sum((times > t) & (times <= t + 1e-6)))
        t, y = t + 1e-6, past.y[:, -1]
    return np.array(out)
