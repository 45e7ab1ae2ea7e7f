"""
Attitude control laws (ROS-free), so a closed loop can run offline and in the node.

A law is a callable ``law(q, omega) -> torque``: q (x, y, z, w) body -> world,
omega (rad/s, body frame), torque (N m, body frame) as a 3-tuple. In
:func:`~rigid_body_dynamics.physics.simulate` it closes the loop with
``torque=lambda t, q, w: law(q, w)``. :class:`BDot` is a magnetorquer law: it
answers magnetometer readings with a dipole.
"""

import math


def _saturate(tau, limit):
    """Scale the vector tau down to |tau| = limit (N m) if longer; limit 0 = none."""
    size = math.sqrt(tau[0] ** 2 + tau[1] ** 2 + tau[2] ** 2)
    if limit > 0.0 and size > limit:
        scale = limit / size
        return (tau[0] * scale, tau[1] * scale, tau[2] * scale)
    return tau


def _check_moments(moments):
    moments = tuple(float(i) for i in moments)
    if len(moments) != 3 or not all(i > 0.0 and math.isfinite(i) for i in moments):
        raise ValueError(f'moments must be three positive numbers, got {moments}')
    return moments


def settling_time(natural_frequency, damping_ratio, band=0.02):
    """
    Settling time (s) of the small-angle PD slew: the last time |theta| = band theta0.

    Each axis of :class:`QuaternionPD` linearises to theta'' + 2 zeta wn
    theta' + wn^2 theta = 0 (theta the error angle, from rest at theta0);
    this is the last exit of that response from the band, found on its
    closed form (0 < zeta < 1: theta0 e^(-zeta wn t) (cos wd t + zeta wn / wd
    sin wd t), wd = wn sqrt(1 - zeta^2); zeta >= 1: the critically or over-
    damped form). Near the envelope estimate -ln(band) / (zeta wn) but exact.
    """
    from scipy.optimize import brentq
    wn, zeta = float(natural_frequency), float(damping_ratio)
    if not (wn > 0.0 and zeta > 0.0 and 0.0 < band < 1.0):
        raise ValueError('natural_frequency and damping_ratio must be > 0, band in (0, 1)')
    if zeta < 1.0:
        wd = wn * math.sqrt(1.0 - zeta * zeta)

        def theta(t):
            return math.exp(-zeta * wn * t) * (math.cos(wd * t)
                                               + zeta * wn / wd * math.sin(wd * t))
    elif zeta == 1.0:
        def theta(t):
            return math.exp(-wn * t) * (1.0 + wn * t)
    else:
        r1 = -wn * (zeta - math.sqrt(zeta * zeta - 1.0))
        r2 = -wn * (zeta + math.sqrt(zeta * zeta - 1.0))

        def theta(t):
            return (r2 * math.exp(r1 * t) - r1 * math.exp(r2 * t)) / (r2 - r1)
    # past the envelope's bound the response stays inside; scan back to its last exit
    end = -math.log(band * 1e-3) / (zeta * wn) if zeta < 1.0 else \
        -math.log(band * 1e-3) / (wn * (zeta - math.sqrt(max(zeta * zeta - 1.0, 0.0))))
    grid = [end * k / 20000.0 for k in range(20001)]
    outside = [abs(theta(t)) - band for t in grid]
    last = max(k for k, v in enumerate(outside) if v > 0.0)
    sign = 1.0 if theta(grid[last]) > 0.0 else -1.0
    return brentq(lambda t: sign * theta(t) - band, grid[last], grid[last + 1], xtol=1e-14)


class RateDamper:
    """
    Detumbling: tau_i = -kd_i omega_i, kd_i = 2 zeta wn I_i, vector-saturated at max_torque.

    Each axis' rate decays as exp(-2 zeta wn t) until the torque saturates;
    the same gains as :class:`QuaternionPD` without the attitude term.
    """

    def __init__(self, moments, natural_frequency, damping_ratio, max_torque=0.0):
        moments = _check_moments(moments)
        if not (natural_frequency > 0.0 and damping_ratio > 0.0 and max_torque >= 0.0):
            raise ValueError('natural_frequency and damping_ratio must be > 0, max_torque >= 0')
        self.kd = tuple(2.0 * damping_ratio * natural_frequency * i for i in moments)
        self.max_torque = float(max_torque)

    def __call__(self, q, omega):
        """Body torque (N m) for body rate omega (rad/s); q is not used."""
        d1, d2, d3 = self.kd
        w1, w2, w3 = (float(c) for c in omega)
        return _saturate((-d1 * w1, -d2 * w2, -d3 * w3), self.max_torque)


class BDot:
    """
    B-dot detumbling with magnetorquers (Stickler and Alfriend), saturated per axis.

    The law is m = -k dB/dt.

    ``gain`` k (A m^2 s / T, > 0), ``max_dipole`` (A m^2 per body axis, 0 = none).
    :meth:`dipole` takes one magnetometer reading (t s, B T in the body frame)
    and returns the dipole (A m^2, body frame): dB/dt by the difference with the
    previous reading, zero for the first reading (and after time went back, e.g.
    a reset); a dipole over a limit is scaled down as a whole (its direction kept)
    until every axis is within its limit. In the body frame dB/dt = -omega x B
    plus the field's slow change along the orbit, so m x B = -k (B x (omega x B))
    removes rate about every axis but the field's.
    """

    def __init__(self, gain, max_dipole=(0.0, 0.0, 0.0)):
        if not (gain > 0.0 and math.isfinite(gain)):
            raise ValueError(f'gain must be positive and finite, got {gain!r}')
        self.gain = float(gain)
        self.max_dipole = tuple(float(c) for c in max_dipole)
        if len(self.max_dipole) != 3 or not all(c >= 0.0 for c in self.max_dipole):
            raise ValueError(f'max_dipole must be three numbers >= 0, got {max_dipole!r}')
        self._last = None

    def dipole(self, t, field_body):
        """Return the moment to command (A m^2, body frame) for ``field_body`` (T) at t (s)."""
        b = tuple(float(c) for c in field_body)
        last, self._last = self._last, (t, b)
        if last is None or t <= last[0]:
            return (0.0, 0.0, 0.0)
        k = -self.gain / (t - last[0])
        m = [k * (b[i] - last[1][i]) for i in range(3)]
        scale = max([abs(c) / top for c, top in zip(m, self.max_dipole) if top > 0.0],
                    default=0.0)
        if scale > 1.0:           # (clamped too: c / scale may round past the limit)
            m = [min(max(c / scale, -top), top) if top > 0.0 else c / scale
                 for c, top in zip(m, self.max_dipole)]
        return tuple(m)


class QuaternionPD:
    """
    Quaternion-feedback PD to a fixed target attitude, vector-saturated.

    tau_i = -kp_i s e_i - kd_i omega_i with e the vector part of the body-frame
    error q_target^-1 (x) q and s = sign(e_w) (the shorter way round), gains
    kp_i = 2 I_i wn^2 and kd_i = 2 zeta wn I_i per principal axis (for small
    errors each axis is a second-order system of natural frequency ``wn``
    rad/s and damping ratio ``zeta``, as e_i ~ angle_i / 2). If |tau| exceeds
    ``max_torque`` (N m; 0 = no limit) the vector is scaled down to it,
    keeping its direction. ``moments`` (kg m^2) are those of the body axes.
    """

    def __init__(self, moments, target, natural_frequency, damping_ratio, max_torque=0.0):
        moments = _check_moments(moments)
        norm = math.sqrt(sum(float(c) ** 2 for c in target))
        if not (norm > 0.0 and math.isfinite(norm)):
            raise ValueError(f'target must be a finite non-zero quaternion, got {target}')
        if not (natural_frequency > 0.0 and damping_ratio >= 0.0 and max_torque >= 0.0):
            raise ValueError('natural_frequency must be > 0, damping_ratio and max_torque >= 0')
        self.target = tuple(float(c) / norm for c in target)
        wn, zeta = float(natural_frequency), float(damping_ratio)
        self.kp = tuple(2.0 * i * wn * wn for i in moments)
        self.kd = tuple(2.0 * zeta * wn * i for i in moments)
        self.max_torque = float(max_torque)

    def __call__(self, q, omega):
        """Body torque (N m) for attitude q (x, y, z, w) and body rate omega (rad/s)."""
        tx, ty, tz, tw = self.target
        x, y, z, s = (float(c) for c in q)
        ex = tw * x - tx * s - ty * z + tz * y
        ey = tw * y - ty * s - tz * x + tx * z
        ez = tw * z - tz * s - tx * y + ty * x
        sign = 1.0 if tw * s + tx * x + ty * y + tz * z >= 0.0 else -1.0
        (p1, p2, p3), (d1, d2, d3) = self.kp, self.kd
        w1, w2, w3 = (float(c) for c in omega)
        return _saturate((-p1 * sign * ex - d1 * w1, -p2 * sign * ey - d2 * w2,
                          -p3 * sign * ez - d3 * w3), self.max_torque)


class WheelAllocator:
    """
    A body torque flown by reaction wheels, and when to dump their momentum.

    ``wheels``: a :class:`~.gyrostat.Wheels` (axes in the body frame, at least three
    spanning space). ``allocate(torque, omega, speeds)`` returns (motor torques, dump
    torque): the motor torques u (N m, one per wheel) whose reaction on the body is
    the wanted body ``torque`` (N m) with the wheels' gyroscopic coupling cancelled,
    -G u = torque + omega x h_w, solved with the minimum-norm pseudo-inverse of
    G = [g_1 .. g_n] and scaled down together (direction kept) to each wheel's
    ``max_torque``; and the external torque (N m, body frame, for torque_cmd: the
    stand-in for magnetorquers or thrusters) that unloads the wheels,
    -``dump_gain`` h_w, from when a wheel passes ``dump_fraction`` of its
    ``max_speed`` until every wheel is back under half that fraction (zero
    otherwise, and always without speed limits). h_w = sum J_i Omega_i g_i.
    """

    def __init__(self, wheels, dump_fraction=0.8, dump_gain=0.5):
        import numpy as np
        g = np.array(wheels.axes, dtype=float).T                   # 3 x n
        if g.shape[1] < 3 or np.linalg.matrix_rank(g) < 3:
            raise ValueError('the wheel axes must span three dimensions (at least three '
                             'wheels, not in one plane) for the wheels to fly any torque')
        self.wheels = wheels
        self.pinv = tuple(tuple(row) for row in np.linalg.pinv(g).tolist())   # n x 3
        if not 0.0 < dump_fraction <= 1.0 or not dump_gain >= 0.0:
            raise ValueError(f'dump_fraction must be in (0, 1] and dump_gain >= 0, got '
                             f'{dump_fraction!r}, {dump_gain!r}')
        self.dump_fraction, self.dump_gain = float(dump_fraction), float(dump_gain)
        self.dumping = False

    def momentum(self, speeds):
        """Return h_w = sum J_i Omega_i g_i (kg m^2/s, body frame)."""
        h = [0.0, 0.0, 0.0]
        for g, j, s in zip(self.wheels.axes, self.wheels.inertia, speeds):
            for k in range(3):
                h[k] += j * s * g[k]
        return tuple(h)

    def allocate(self, torque, omega, speeds):
        """
        Return (motor torques, dump torque) for the wanted body ``torque``; see the class.

        While dumping, the wheels also take up the dump torque (they fly ``torque`` -
        dump), so the body feels ``torque`` alone and the wheels lose the momentum the
        dump torque takes out.
        """
        h = self.momentum(speeds)
        fractions = [abs(s) / top for s, top in zip(speeds, self.wheels.max_speed) if top > 0.0]
        if fractions and max(fractions) >= self.dump_fraction:
            self.dumping = True
        elif not fractions or max(fractions) <= 0.5 * self.dump_fraction:
            self.dumping = False
        dump = tuple(-self.dump_gain * c for c in h) if self.dumping else (0.0, 0.0, 0.0)
        w1, w2, w3 = omega
        t1, t2, t3 = (a - b for a, b in zip(torque, dump))
        want = (-(t1 + w2 * h[2] - w3 * h[1]), -(t2 + w3 * h[0] - w1 * h[2]),
                -(t3 + w1 * h[1] - w2 * h[0]))
        u = [row[0] * want[0] + row[1] * want[1] + row[2] * want[2] for row in self.pinv]
        scale = 1.0
        for ui, top in zip(u, self.wheels.max_torque):
            if top > 0.0 and abs(ui) > top:
                scale = min(scale, top / abs(ui))
        return tuple(ui * scale for ui in u), dump


def fly_on_wheels(moments, wheels, law, allocator, duration, control_period=0.01, dt=1e-3,
                  q0=(0.0, 0.0, 0.0, 1.0), omega0=(0.0, 0.0, 0.0), speeds0=None,
                  disturbance=(0.0, 0.0, 0.0)):
    """
    Close a control loop on reaction wheels offline, as attitude_controller does in lockstep.

    ``moments`` (kg m^2, principal = body frame), ``wheels`` (a
    :class:`~.gyrostat.Wheels`, the simulated ones), ``law(q, omega)`` -> body torque,
    ``allocator`` a :class:`WheelAllocator`; every ``control_period`` s (a whole number
    of steps ``dt``) the law's torque is allocated from the state and held: the motor
    torques on the wheels, the dump torque plus the constant body ``disturbance`` (N m)
    as external torque. Returns a list of (t s, q, omega, speeds, motor torques, dump
    torque) at each control tick, and the final :class:`~.gyrostat.GyrostatIntegrator`.
    The body steps on the one stepping core
    (:class:`~.dynamics.plant.Plant`), as the simulator's does.
    """
    from .dynamics.plant import Plant
    from .environment import Disturbances
    from .inertia import Inertia
    every = round(control_period / dt)
    if every < 1 or abs(every * dt - control_period) > 1e-9 * control_period:
        raise ValueError(f'control_period must be a whole number of steps dt = {dt:g} s')
    plant = Plant(Inertia(moments), 'exact', dt, q0, omega0,
                  Disturbances(body=tuple(float(c) for c in disturbance)), wheels, speeds0)
    body = plant.stepper
    records = []
    for _ in range(int(round(duration / control_period))):
        u, dump = allocator.allocate(law(body.q, body.omega), body.omega, body.speeds)
        plant.command_motors(u)
        records.append((body.time, body.q, body.omega, body.speeds, u, dump))
        for _ in range(every):
            plant.step(dump)
    return records, body
