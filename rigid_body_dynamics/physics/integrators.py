"""
Fixed-step attitude integrators behind one protocol.

Every integrator advances the state (q, omega) of one body by a fixed step dt
(s) under a torque held constant over the step: ``torque`` fixed in the body
frame and, optionally, ``torque_world`` fixed in the world frame (both N m;
the world part is rotated into the body wherever the method evaluates the
torque, so its impulse is exactly torque_world dt for the kick scheme). The state is
kept in the principal frame: ``moments`` are the principal moments (kg m^2)
in the order of the body axes, omega (rad/s) is body-frame, q (x, y, z, w)
rotates body vectors into the world frame.

Each integrator also accumulates the work W = int omega . tau dt (J) and the
world-frame impulse H = int R tau dt (N m s), so the balances
T - T0 = W and L_w - L_w0 = H can be checked under torque.

=========  ==========================================================  =====================
name       method                                                      conserves
=========  ==========================================================  =====================
rk4        classic RK4 on (omega, q), hand-unrolled, q renormalised     nothing exactly
exact      torque-free: exact flow from the start of the torque-free   T, L to round-off;
           segment; torque: Strang kick-drift-kick with the exact flow  W, H balances exactly
exact4     Yoshida order-4 composition of the kick-drift-kick step     as exact
dop853     scipy DOP853, rtol 1e-12, restarted when the torque changes  to its tolerance
=========  ==========================================================  =====================
"""

from abc import ABC, abstractmethod
import math

import numpy as np
from scipy.integrate import DOP853

from .equations import state_rhs
from .free_motion import BodyShape

#: Largest |omega| dt of one RK4 sub-step used for flows near the separatrix.
SEPARATRIX_SUBSTEP = 2e-3


class KahanSum:
    """Compensated running sum (Neumaier) of ``size`` float components."""

    __slots__ = ('total', '_comp')

    def __init__(self, size):
        self.total = [0.0] * size
        self._comp = [0.0] * size

    def add(self, *values):
        """Add one value per component."""
        total, comp = self.total, self._comp
        for i, v in enumerate(values):
            t = total[i]
            s = t + v
            comp[i] += (t - s) + v if abs(t) >= abs(v) else (v - s) + t
            total[i] = s

    def value(self):
        """Return the current sums as a tuple."""
        return tuple(t + c for t, c in zip(self.total, self._comp))


def _stage_torque(tau, tau_world, q):
    """Body torque at attitude q: tau + R(q)^T tau_world (N m)."""
    x, y, z, w = q
    return tuple(a + b for a, b in zip(tau, _rotate((-x, -y, -z, w), tau_world)))


def rk4_step(inv, q, w, h, tau, balances=False, tau_world=None):
    """
    One classic RK4 step of Euler's equations (4.26) and dq/dt = q (x) (omega, 0) / 2.

    ``inv`` = (c1, c2, c3, 1/I1, 1/I2, 1/I3) with c1 = (I2 - I3) / I1 and
    cyclic; q and w are tuples; the torque tau (body, N m) is held over the
    step, and ``tau_world`` (world, N m), if given, is held fixed in the world
    frame (rotated into the body at every stage). Returns the new (q, w) with
    q renormalised. With ``balances`` also the step's work (J) and world
    impulse (N m s) by the same RK4 stages, i.e. RK4 on the system augmented
    with dW/dt = omega . tau, dH/dt = R tau.
    """
    c1, c2, c3, j1, j2, j3 = inv
    x, y, z, s = q
    a, b, c = w
    hh = 0.5 * h
    stage_tau = [tau] * 4
    # stage 1
    if tau_world is not None:
        stage_tau[0] = _stage_torque(tau, tau_world, q)
    t1, t2, t3 = stage_tau[0][0] * j1, stage_tau[0][1] * j2, stage_tau[0][2] * j3
    ka1 = c1 * b * c + t1
    kb1 = c2 * c * a + t2
    kc1 = c3 * a * b + t3
    kx1 = 0.5 * (s * a + y * c - z * b)
    ky1 = 0.5 * (s * b + z * a - x * c)
    kz1 = 0.5 * (s * c + x * b - y * a)
    ks1 = -0.5 * (x * a + y * b + z * c)
    # stage 2
    a2, b2, c2_ = a + hh * ka1, b + hh * kb1, c + hh * kc1
    x2, y2, z2, s2 = x + hh * kx1, y + hh * ky1, z + hh * kz1, s + hh * ks1
    if tau_world is not None:
        stage_tau[1] = _stage_torque(tau, tau_world, (x2, y2, z2, s2))
        t1, t2, t3 = stage_tau[1][0] * j1, stage_tau[1][1] * j2, stage_tau[1][2] * j3
    ka2 = c1 * b2 * c2_ + t1
    kb2 = c2 * c2_ * a2 + t2
    kc2 = c3 * a2 * b2 + t3
    kx2 = 0.5 * (s2 * a2 + y2 * c2_ - z2 * b2)
    ky2 = 0.5 * (s2 * b2 + z2 * a2 - x2 * c2_)
    kz2 = 0.5 * (s2 * c2_ + x2 * b2 - y2 * a2)
    ks2 = -0.5 * (x2 * a2 + y2 * b2 + z2 * c2_)
    # stage 3
    a3, b3, c3_ = a + hh * ka2, b + hh * kb2, c + hh * kc2
    x3, y3, z3, s3 = x + hh * kx2, y + hh * ky2, z + hh * kz2, s + hh * ks2
    if tau_world is not None:
        stage_tau[2] = _stage_torque(tau, tau_world, (x3, y3, z3, s3))
        t1, t2, t3 = stage_tau[2][0] * j1, stage_tau[2][1] * j2, stage_tau[2][2] * j3
    ka3 = c1 * b3 * c3_ + t1
    kb3 = c2 * c3_ * a3 + t2
    kc3 = c3 * a3 * b3 + t3
    kx3 = 0.5 * (s3 * a3 + y3 * c3_ - z3 * b3)
    ky3 = 0.5 * (s3 * b3 + z3 * a3 - x3 * c3_)
    kz3 = 0.5 * (s3 * c3_ + x3 * b3 - y3 * a3)
    ks3 = -0.5 * (x3 * a3 + y3 * b3 + z3 * c3_)
    # stage 4
    a4, b4, c4 = a + h * ka3, b + h * kb3, c + h * kc3
    x4, y4, z4, s4 = x + h * kx3, y + h * ky3, z + h * kz3, s + h * ks3
    if tau_world is not None:
        stage_tau[3] = _stage_torque(tau, tau_world, (x4, y4, z4, s4))
        t1, t2, t3 = stage_tau[3][0] * j1, stage_tau[3][1] * j2, stage_tau[3][2] * j3
    ka4 = c1 * b4 * c4 + t1
    kb4 = c2 * c4 * a4 + t2
    kc4 = c3 * a4 * b4 + t3
    kx4 = 0.5 * (s4 * a4 + y4 * c4 - z4 * b4)
    ky4 = 0.5 * (s4 * b4 + z4 * a4 - x4 * c4)
    kz4 = 0.5 * (s4 * c4 + x4 * b4 - y4 * a4)
    ks4 = -0.5 * (x4 * a4 + y4 * b4 + z4 * c4)
    h6 = h / 6.0
    a += h6 * (ka1 + 2.0 * (ka2 + ka3) + ka4)
    b += h6 * (kb1 + 2.0 * (kb2 + kb3) + kb4)
    c += h6 * (kc1 + 2.0 * (kc2 + kc3) + kc4)
    x += h6 * (kx1 + 2.0 * (kx2 + kx3) + kx4)
    y += h6 * (ky1 + 2.0 * (ky2 + ky3) + ky4)
    z += h6 * (kz1 + 2.0 * (kz2 + kz3) + kz4)
    s += h6 * (ks1 + 2.0 * (ks2 + ks3) + ks4)
    r = 1.0 / math.sqrt(x * x + y * y + z * z + s * s)
    if not balances:
        return (x * r, y * r, z * r, s * r), (a, b, c)
    omegas = (w, (a2, b2, c2_), (a3, b3, c3_), (a4, b4, c4))
    quats = (q, (x2, y2, z2, s2), (x3, y3, z3, s3), (x4, y4, z4, s4))
    weights = (h6, 2.0 * h6, 2.0 * h6, h6)
    work = sum(wt * (tq[0] * om[0] + tq[1] * om[1] + tq[2] * om[2])
               for wt, tq, om in zip(weights, stage_tau, omegas))
    rotated = [_rotate(qs, tq) for qs, tq in zip(quats, stage_tau)]
    impulse = tuple(sum(wt * r_[i] for wt, r_ in zip(weights, rotated)) for i in range(3))
    return (x * r, y * r, z * r, s * r), (a, b, c), work, impulse


def _rk4_constants(moments):
    i1, i2, i3 = moments
    return ((i2 - i3) / i1, (i3 - i1) / i2, (i1 - i2) / i3, 1.0 / i1, 1.0 / i2, 1.0 / i3)


def _rotate(q, v):
    """R(q) v on float tuples (body -> world)."""
    x, y, z, w = q
    vx, vy, vz = v
    tx = 2.0 * (y * vz - z * vy)
    ty = 2.0 * (z * vx - x * vz)
    tz = 2.0 * (x * vy - y * vx)
    return (vx + w * tx + y * tz - z * ty, vy + w * ty + z * tx - x * tz,
            vz + w * tz + x * ty - y * tx)


class Integrator(ABC):
    """
    Protocol: a fixed-step stepper for one body, state in the principal frame.

    ``moments`` (kg m^2, body-axis order), ``dt`` (s), initial ``q0`` (x, y,
    z, w; body -> world) and ``omega0`` (rad/s, body). After :meth:`step`:
    ``q``, ``omega`` (tuples), ``steps`` (int), ``time`` = steps * dt (s),
    ``work`` (J) and ``impulse`` (world, N m s) since the last :meth:`reset`.
    """

    name = ''

    def __init__(self, moments, dt, q0=(0.0, 0.0, 0.0, 1.0), omega0=(0.0, 0.0, 0.0)):
        self.moments = tuple(float(i) for i in moments)
        if not (dt > 0.0 and math.isfinite(dt)):
            raise ValueError(f'dt must be positive and finite, got {dt!r}')
        self.dt = float(dt)
        self.reset(q0, omega0)

    def reset(self, q, omega):
        """Restart from attitude q and angular velocity omega; zero steps, work and impulse."""
        q = tuple(float(c) for c in q)
        norm = math.sqrt(sum(c * c for c in q))
        if not (norm > 0.0 and math.isfinite(norm)):
            raise ValueError(f'attitude quaternion must be finite and non-zero, got {q}')
        omega = tuple(float(c) for c in omega)
        if not all(math.isfinite(c) for c in omega):
            raise ValueError(f'angular velocity must be finite, got {omega}')
        self.q = tuple(c / norm for c in q)
        self.omega = omega
        self.steps = 0
        self._work = KahanSum(1)
        self._impulse = KahanSum(3)
        self._reset()

    def _reset(self):
        """Reset integrator-specific state (a hook for :meth:`reset`)."""

    @property
    def time(self):
        """Return the simulated time since the last reset (s): integer step count times dt."""
        return self.steps * self.dt

    @property
    def work(self):
        """Work done by the torque since the last reset, int omega . tau dt (J)."""
        return self._work.value()[0]

    @property
    def impulse(self):
        """World-frame angular impulse since the last reset, int R tau dt (N m s)."""
        return self._impulse.value()

    @property
    def angular_momentum_body(self):
        """I omega in the body frame (kg m^2/s)."""
        return tuple(i * w for i, w in zip(self.moments, self.omega))

    @property
    def kinetic_energy(self):
        """1/2 omega . I omega (J)."""
        return 0.5 * sum(i * w * w for i, w in zip(self.moments, self.omega))

    @abstractmethod
    def step(self, torque=(0.0, 0.0, 0.0), torque_world=None):
        """
        Advance by one step dt, the torque held in the body frame over it (N m).

        ``torque_world`` (N m), if not None, is held fixed in the world frame.
        """


class RK4Integrator(Integrator):
    """Classic fixed-step RK4 on (omega, q), q renormalised each step; order 4."""

    name = 'rk4'

    def _reset(self):
        self._inv = _rk4_constants(self.moments)

    def step(self, torque=(0.0, 0.0, 0.0), torque_world=None):
        """Advance by dt; see :class:`Integrator`."""
        if torque_world is not None and not any(torque_world):
            torque_world = None
        if torque_world is not None or torque[0] != 0.0 or torque[1] != 0.0 or torque[2] != 0.0:
            # The balances are then at RK4's truncation level, not round-off.
            self.q, self.omega, work, impulse = rk4_step(
                self._inv, self.q, self.omega, self.dt, torque, balances=True,
                tau_world=torque_world)
            self._work.add(work)
            self._impulse.add(*impulse)
        else:
            self.q, self.omega = rk4_step(self._inv, self.q, self.omega, self.dt, torque)
        self.steps += 1


class ExactIntegrator(Integrator):
    """
    Exact free flow; with torque, Strang kick-drift-kick splitting (order 2).

    Torque-free steps evaluate the closed-form flow from the start of the
    torque-free segment (``time`` since then), so T and L stay at round-off
    however long the segment. A step under torque is
    K(h/2) F(h) K(h/2): a momentum kick m += (h/2) tau, the exact free flow,
    another kick. The kicks change T by exactly (h/2) tau . (omega- + omega+)/2
    and L_w by exactly (h/2) R tau, and those amounts are what ``work`` and
    ``impulse`` accumulate, so the balances hold to round-off. Near the
    separatrix the free flow of one step is RK4 with sub-steps of
    |omega| h <= SEPARATRIX_SUBSTEP (see ``free_motion``).
    """

    name = 'exact'
    #: (flow fraction, kick fraction before it) of one step; the last kick closes.
    _stages = ((1.0, 0.5),)
    _last_kick = 0.5

    def _reset(self):
        if not hasattr(self, '_shape'):
            self._shape = BodyShape(self.moments)
            self._inv = _rk4_constants(self.moments)
        self._segment = None

    def _start_segment(self):
        m = self.angular_momentum_body
        flow = self._shape.flow(self.q, m)
        self._segment = None if flow.near_separatrix else (flow, self.steps)

    def _kick(self, h, torque, torque_world=None):
        """
        Kick m += h tau at fixed attitude; accumulate its exact work and impulse.

        The work and impulse booked are those of the change actually made to
        the stored omega (w1 - w0 is exact in floating point), so a rounding
        bias of the kick (the same increment rounded the same way every step)
        cannot separate the state from its balance.
        """
        if torque_world is not None:
            torque = _stage_torque(torque, torque_world, self.q)
        w0 = self.omega
        i1, i2, i3 = self.moments
        w1 = (w0[0] + h * torque[0] / i1, w0[1] + h * torque[1] / i2, w0[2] + h * torque[2] / i3)
        dm = (i1 * (w1[0] - w0[0]), i2 * (w1[1] - w0[1]), i3 * (w1[2] - w0[2]))
        self._work.add(0.5 * (dm[0] * (w0[0] + w1[0]) + dm[1] * (w0[1] + w1[1])
                              + dm[2] * (w0[2] + w1[2])))
        self._impulse.add(*_rotate(self.q, dm))
        self.omega = w1

    def _drift(self, h):
        """Exact torque-free flow over h (s) from the current state."""
        flow = self._shape.flow(self.q, self.angular_momentum_body)
        if flow.near_separatrix:
            q, w = self.q, self.omega
            speed = math.sqrt(sum(c * c for c in w))
            n = max(1, math.ceil(abs(h) * speed / SEPARATRIX_SUBSTEP))
            for _ in range(n):
                q, w = rk4_step(self._inv, q, w, h / n, (0.0, 0.0, 0.0))
            self.q, self.omega = q, w
            return
        self._set_from(*flow.state(h))

    def _set_from(self, q, m):
        q = tuple(float(c) for c in q)
        r = 1.0 / math.sqrt(sum(c * c for c in q))
        self.q = tuple(c * r for c in q)
        self.omega = tuple(float(mi) / i for mi, i in zip(m, self.moments))

    def step(self, torque=(0.0, 0.0, 0.0), torque_world=None):
        """Advance by dt; see :class:`ExactIntegrator`."""
        h = self.dt
        if torque_world is not None and not any(torque_world):
            torque_world = None
        if torque_world is None and torque[0] == 0.0 and torque[1] == 0.0 and torque[2] == 0.0:
            if self._segment is None:
                self._start_segment()
            if self._segment is not None:
                flow, start = self._segment
                self.steps += 1
                self._set_from(*flow.state((self.steps - start) * h))
                return
            self._drift(h)
        else:
            self._segment = None
            for flow_frac, kick_frac in self._stages:
                self._kick(kick_frac * h, torque, torque_world)
                self._drift(flow_frac * h)
            self._kick(self._last_kick * h, torque, torque_world)
        self.steps += 1


_W1 = 1.0 / (2.0 - 2.0 ** (1.0 / 3.0))
_W0 = -(2.0 ** (1.0 / 3.0)) / (2.0 - 2.0 ** (1.0 / 3.0))


class Exact4Integrator(ExactIntegrator):
    """
    Order-4 Yoshida triple jump of the exact kick-drift-kick step.

    Weights w1, w0, w1 with w1 = 1 / (2 - 2^(1/3)), w0 = 1 - 2 w1; adjacent
    kicks are merged (three exact flows per step). Torque-free steps are the
    same exact segment evaluation as ``exact``.
    """

    name = 'exact4'
    _stages = ((_W1, 0.5 * _W1), (_W0, 0.5 * (_W1 + _W0)), (_W1, 0.5 * (_W0 + _W1)))
    _last_kick = 0.5 * _W1


class DOP853Integrator(Integrator):
    """
    scipy's DOP853 (order 8 with dense output), rtol 1e-12, atol 1e-12 * scale.

    The solver takes its own steps; states at multiples of dt come from its
    dense output, the quaternion normalised on output only. The solver is
    restarted from the current state whenever the torque changes. Work and
    impulse are integrated as extra ODE components.
    """

    name = 'dop853'
    rtol = 1e-12

    def _reset(self):
        self._solver = None
        self._torque = None

    def _restart(self, torque, torque_world):
        moments = np.array(self.moments)
        tau_body = tuple(torque)

        def rhs(_t, y):
            q = tuple(y[3:7])
            tau = tau_body if torque_world is None else _stage_torque(tau_body, torque_world, q)
            d = state_rhs(moments, y[:7], tau)
            return np.concatenate([d, [np.dot(y[:3], tau)], _rotate(q, tau)])

        y0 = np.concatenate([self.omega, self.q, np.zeros(4)])
        scale = max(math.sqrt(sum(c * c for c in self.omega)), 1e-9)
        big = max(scale * max(self.moments), 1e-9)
        atol = np.array([1e-12 * scale] * 3 + [1e-12] * 4 + [1e-12 * big] * 4)
        self._solver = DOP853(rhs, 0.0, y0, np.inf, rtol=self.rtol, atol=atol)
        self._torque = (tuple(torque), torque_world)
        self._t0 = self.steps
        self._base = (self.work, self.impulse)
        self._dense = None

    def step(self, torque=(0.0, 0.0, 0.0), torque_world=None):
        """Advance by dt; see :class:`DOP853Integrator`."""
        torque = tuple(float(c) for c in torque)
        if torque_world is not None:
            torque_world = tuple(float(c) for c in torque_world)
        if self._solver is None or (torque, torque_world) != self._torque:
            self._restart(torque, torque_world)
        self.steps += 1
        t = (self.steps - self._t0) * self.dt
        solver = self._solver
        while solver.t < t:
            solver.step()
            if solver.status == 'failed':
                raise RuntimeError('DOP853 failed to advance')
            self._dense = None
        if self._dense is None:
            self._dense = solver.dense_output()
        y = self._dense(t)
        q = y[3:7] / math.sqrt(float(np.dot(y[3:7], y[3:7])))
        self.q = tuple(float(c) for c in q)
        self.omega = tuple(float(c) for c in y[:3])
        work0, imp0 = self._base
        self._work = KahanSum(1)
        self._work.add(work0 + float(y[7]))
        self._impulse = KahanSum(3)
        self._impulse.add(*(a + float(b) for a, b in zip(imp0, y[8:11])))


#: Integrator classes by name; ``exact`` is the default.
INTEGRATORS = {cls.name: cls for cls in
               (ExactIntegrator, Exact4Integrator, RK4Integrator, DOP853Integrator)}


def make_integrator(name, moments, dt, q0=(0.0, 0.0, 0.0, 1.0), omega0=(0.0, 0.0, 0.0)):
    """
    Build the integrator called ``name`` (see INTEGRATORS).

    Raises ValueError naming the known integrators for an unknown name.
    """
    try:
        cls = INTEGRATORS[name]
    except KeyError:
        raise ValueError(f'unknown integrator {name!r}; choose one of '
                         f'{", ".join(sorted(INTEGRATORS))}') from None
    return cls(moments, dt, q0, omega0)
