"""
Fixed-step attitude integrators behind one protocol.

Every integrator advances the state (q, omega) of one body by a fixed step dt
(s) under a torque held constant over the step (a zero-order hold):
``torque`` fixed in the body frame and, optionally, ``torque_world`` fixed in
the world frame (both N m; the world part is rotated into the body wherever
the method evaluates the torque). The state is kept in the principal frame
of the inertia (the body frame when the tensor is diagonal; ``Inertia``
converts between the two): ``moments`` are the principal moments (kg m^2),
omega (rad/s) and the body torque are principal-frame components, and q
(x, y, z, w) rotates principal-frame vectors into the world frame.

Each integrator also books the work W = int omega . tau dt (J) and the
world-frame impulse H = int R tau dt (N m s), so the balances T - T0 = W and
L_w - L_w0 = H can be checked under torque. W is the method's own quadrature
of omega . tau at its stages: it is accurate to the method's order, so
T - T0 - W measures the truncation error (round-off class for ``exact``).
H is booked as the change of L_w = R I omega over each step under torque
(zero when torque-free), so L_w - L_w0 - H holds by construction and checks
the bookkeeping only; the accuracy of L_w itself is measured against
independent references in the tests and benchmarks.

=========  ===========================================================  =================
name       method                                                       conserves
=========  ===========================================================  =================
exact      torque-free: exact flow from the start of the torque-free    T, L to round-off
           segment; torque: explicit RK of order 6 or 8 (by |omega| h)  when torque-free
rk4        classic RK4 on (omega, q), q renormalised                    nothing exactly
=========  ===========================================================  =================

``exact4`` (Yoshida splitting) and ``dop853`` (scipy's adaptive solver) were
removed: under a held torque ``exact`` is more accurate than both at every
step measured and cheaper (benchmarks/RESULTS.md, torque section).
"""

from abc import ABC, abstractmethod
import math

from .free_motion import BodyShape
from .rk_kernels import environment_kernel, KERNELS
from ..quaternions import rotate_components

_ZERO = (0.0, 0.0, 0.0)

#: Integrators that existed and were removed, with what to use instead.
REMOVED = {
    'exact4': 'exact4 (Yoshida splitting) was removed: `exact` is now order 6-8 under '
              'torque, more accurate and cheaper; use integrator `exact`',
    'dop853': 'dop853 was removed: `exact` is more accurate under torque at a fraction of '
              'the cost; use integrator `exact`',
}


def field_kernel(field, order, kernels, torque_world):
    """
    Return (the step of ``order`` for the stage torque ``field``, the world torque to give it).

    The kernel with the field's statements in its stages when it has them (a
    :class:`~rigid_body_dynamics.physics.environment.SpaceEnvironment` whose models all
    give ``stage_source``; without a world torque when ``torque_world`` is None), else
    ``kernels[order]``, which calls ``field`` at each stage.
    """
    code = getattr(field, 'stage_code', None)
    if code is None:
        return kernels[order], torque_world or _ZERO
    return environment_kernel(order, code, torque_world is not None), torque_world


def _neumaier(total, comp, value):
    """One step of Neumaier's compensated sum: returns the new (total, compensation)."""
    t = total + value
    if abs(total) >= abs(value):
        return t, comp + ((total - t) + value)
    return t, comp + ((value - t) + total)


def rk_constants(moments):
    """(c1, c2, c3, 1/I1, 1/I2, 1/I3) of Euler's equations; c1 = (I2 - I3) / I1 and cyclic."""
    i1, i2, i3 = moments
    return ((i2 - i3) / i1, (i3 - i1) / i2, (i1 - i2) / i3, 1.0 / i1, 1.0 / i2, 1.0 / i3)


def as_torque(value, what):
    """Return ``value`` as a 3-tuple of finite floats (N m), or raise ValueError saying why."""
    if value.__class__ is not tuple or len(value) != 3:
        try:
            value = tuple(float(c) for c in value)
        except (TypeError, ValueError):
            raise ValueError(f'{what} must be three numbers (N m), got {value!r}') from None
        if len(value) != 3:
            raise ValueError(f'{what} must be three numbers (N m), got {value!r}')
    x, y, z = value
    if (x - x) + (y - y) + (z - z) != 0.0:   # inf - inf and nan are nan
        raise ValueError(f'{what} must be finite, got {value!r}')
    return value


class Integrator(ABC):
    """
    Protocol: a fixed-step stepper for one body, state in the principal frame.

    ``moments`` (principal, kg m^2), ``dt`` (s), initial ``q0`` (x, y, z, w;
    principal frame -> world) and ``omega0`` (rad/s, principal frame). After :meth:`step`:
    ``q``, ``omega`` (tuples), ``steps`` (int), ``time`` = steps * dt (s),
    ``work`` (J) and ``impulse`` (world, N m s) since the last :meth:`reset`.

    :meth:`step` is the one template (as scipy's ``OdeSolver.step``): it
    checks the torque, calls :meth:`_free_step` or :meth:`_torque_step`,
    books work and impulse and counts the step. Subclasses implement the two
    hooks and nothing else of the bookkeeping.
    """

    name = ''

    def __init__(self, moments, dt, q0=(0.0, 0.0, 0.0, 1.0), omega0=(0.0, 0.0, 0.0)):
        self.moments = tuple(float(i) for i in moments)
        if not (dt > 0.0 and math.isfinite(dt)):
            raise ValueError(f'dt must be positive and finite, got {dt!r}')
        self.dt = float(dt)
        self._inv = rk_constants(self.moments)
        self.reset(q0, omega0)

    def reset(self, q, omega):
        """Restart from attitude q and angular velocity omega; zero steps, work and impulse."""
        q = tuple(float(c) for c in q)
        norm = math.sqrt(sum(c * c for c in q))
        if not (norm > 0.0 and math.isfinite(norm)):
            raise ValueError(f'attitude quaternion must be finite and non-zero, got {q}')
        omega = tuple(float(c) for c in omega)
        if len(omega) != 3 or not all(math.isfinite(c) for c in omega):
            raise ValueError(f'angular velocity must be three finite numbers, got {omega}')
        self.q = tuple(c / norm for c in q)
        self.omega = omega
        self.steps = 0
        self._work = (0.0, 0.0)                # (sum, compensation), J
        self._impulse = [(0.0, 0.0)] * 3       # per world axis, N m s
        self._lw = None                        # L_w of the current state, when known
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
        return self._work[0] + self._work[1]

    @property
    def impulse(self):
        """World-frame angular impulse since the last reset, int R tau dt (N m s)."""
        return tuple(total + comp for total, comp in self._impulse)

    @property
    def angular_momentum_body(self):
        """I omega in the body frame (kg m^2/s)."""
        return tuple(i * w for i, w in zip(self.moments, self.omega))

    @property
    def angular_momentum_world(self):
        """L_w = R(q) I omega in the world frame (kg m^2/s)."""
        i1, i2, i3 = self.moments
        w1, w2, w3 = self.omega
        return rotate_components(self.q, (i1 * w1, i2 * w2, i3 * w3))

    @property
    def kinetic_energy(self):
        """1/2 omega . I omega (J)."""
        return 0.5 * sum(i * w * w for i, w in zip(self.moments, self.omega))

    def step(self, torque=(0.0, 0.0, 0.0), torque_world=None, field=None):
        """
        Advance by one step dt, the torque held in the body frame over it (N m).

        ``torque_world`` (N m), if not None, is held fixed in the world frame.
        ``field``, if not None, adds a torque that depends on time and state,
        ``field(t, qx, qy, qz, qw, wx, wy, wz)`` -> principal-frame torque (N m) with t
        the integrator's time (s), q principal -> world and omega (rad/s,
        principal): the method evaluates it at its stages (e.g.
        :class:`~rigid_body_dynamics.physics.environment.SpaceEnvironment`).
        A torque that is not three finite numbers raises ValueError and
        leaves the state as it was.
        """
        torque = as_torque(torque, 'torque')
        if torque_world is not None:
            torque_world = as_torque(torque_world, 'torque_world')
            if not (torque_world[0] or torque_world[1] or torque_world[2]):
                torque_world = None
        if field is None and torque_world is None and not (torque[0] or torque[1] or torque[2]):
            self._lw = None
            self._free_step()
        else:
            before = self._lw or self.angular_momentum_world
            work = (self._torque_step(torque, torque_world) if field is None else
                    self._field_step(torque, torque_world, field))
            self._work = _neumaier(*self._work, work)
            after = self._lw = self.angular_momentum_world
            self._impulse = [_neumaier(*acc, a - b)
                             for acc, a, b in zip(self._impulse, after, before)]
        self.steps += 1

    def free_steps(self, count):
        """Advance by ``count`` torque-free steps: the same state as ``count`` calls of step()."""
        for _ in range(count):
            self.step()

    @abstractmethod
    def _free_step(self):
        """Advance self.q, self.omega by dt without torque (the step is counted by step())."""

    @abstractmethod
    def _torque_step(self, torque, torque_world):
        """Advance self.q, self.omega by dt under the held torque; return the work (J)."""

    @abstractmethod
    def _field_step(self, torque, torque_world, field):
        """Advance by dt under the held torques (world: None or N m) plus ``field``; work (J)."""


class RK4Integrator(Integrator):
    """Classic fixed-step RK4 on (omega, q), q renormalised each step; order 4."""

    name = 'rk4'
    _free = staticmethod(KERNELS[(4, 'free')])
    _body = staticmethod(KERNELS[(4, 'body')])
    _world = staticmethod(KERNELS[(4, 'world')])

    def _free_step(self):
        self.q, self.omega, _ = self._free(self._inv, self.q, self.omega, self.dt, None, None)

    _field = {4: KERNELS[(4, 'field')]}

    def _torque_step(self, torque, torque_world):
        kernel = self._body if torque_world is None else self._world
        self.q, self.omega, work = kernel(self._inv, self.q, self.omega, self.dt, torque,
                                          torque_world)
        return work

    def _field_step(self, torque, torque_world, field):
        kernel, torque_world = field_kernel(field, 4, self._field, torque_world)
        self.q, self.omega, work = kernel(self._inv, self.q, self.omega, self.dt, torque,
                                          torque_world, field, self.time)
        return work


#: Marks a torque-free segment stepped by RK (near the separatrix) in ExactIntegrator.
_RK_SEGMENT = object()


class ExactIntegrator(Integrator):
    """
    Exact free flow; under torque, an explicit Runge-Kutta step of order 6 or 8.

    Torque-free steps evaluate the closed-form flow from the start of the
    torque-free segment (``time`` since then), so T and L stay at round-off
    however long the segment; they do so when q or omega is read, so a step
    that nobody reads costs only its count. A step under torque is one explicit RK step of
    the seven-state system: Butcher's order-6 method while rho h <=
    ``ORDER6_LIMIT``, else DOP853's order-8 formula, in n equal sub-steps with
    rho h / n <= ``ORDER8_LIMIT``; rho = |omega| + sqrt(max |tau_i| / I_min)
    (1/s) at the start of the step is the body's fastest time scale. Both
    limits are where the method's error per step stops being round-off
    (measured: order 6 is at round-off to |omega| h = 0.01 and 7e-17 per step
    at 0.02; order 8 to 0.1). The RK step never touches the elliptic
    parameters, so a torque that carries the state across the separatrix
    loses nothing. Near the separatrix a torque-free step is the order-8 RK
    step too (the elliptic functions lose accuracy there, see
    ``free_motion``).

    Work is the RK quadrature of omega . tau (truncation level, round-off
    class); the impulse is the change of L_w (by construction); see the
    module docstring.
    """

    name = 'exact'
    ORDER6_LIMIT = 0.01
    ORDER8_LIMIT = 0.08
    _kernels = {mode: {6: KERNELS[(6, mode)], 8: KERNELS[(8, mode)]}
                for mode in ('free', 'body', 'world', 'field')}

    _lazy = False       # whether q and omega are still to be read off the free flow

    def _reset(self):
        if not hasattr(self, '_shape'):
            self._shape = BodyShape(self.moments)
            self._i_min = min(self.moments)
            self._order6_rate = self.ORDER6_LIMIT / self.dt   # rho (1/s) up to which order 6
        # the torque-free segment: None (starts at the next free step), (flow, start step),
        # or _RK_SEGMENT near the separatrix (free motion keeps S, so it stays near it)
        self._segment = None
        self._torque_key = None        # the torque whose time scale is cached below
        self._torque_rate = 0.0        # sqrt(max |tau_i| / I_min), 1/s

    def _free_step(self):
        if self._segment is None:
            flow = self._shape.flow(self.q, self.angular_momentum_body)
            self._segment = _RK_SEGMENT if flow.near_separatrix else (flow, self.steps)
        if self._segment is _RK_SEGMENT:
            self._rk('free', None, None, 0.0)
            return
        # The state after this step is the flow at the step count: evaluated when q or
        # omega is read (a snapshot, a torque step, diagnostics), not at every step. The
        # same closed form at the same time, so the same numbers, bit for bit.
        self._lazy = True

    def free_steps(self, count):
        """
        Advance by ``count`` torque-free steps; on the closed-form flow, one count.

        The state after them is the flow's at the step count, read when q or
        omega is read: bit for bit what ``count`` calls of step() give.
        """
        if count <= 0:
            return
        self.step()
        if self._lazy:              # a closed-form segment (not RK near the separatrix)
            self.steps += count - 1
        else:
            for _ in range(count - 1):
                self.step()

    # q and omega: plain attributes in the other integrators; here read through the flow
    @property
    def q(self):
        """Attitude (x, y, z, w), principal frame -> world, after the steps so far."""
        if self._lazy:
            self._evaluate()
        return self._q

    @q.setter
    def q(self, value):
        if self._lazy:             # (set alone, omega would be the flow's: fix it first)
            self._evaluate()
        self._q = value

    @property
    def omega(self):
        """Angular velocity (rad/s, principal frame) after the steps so far."""
        if self._lazy:
            self._evaluate()
        return self._omega

    @omega.setter
    def omega(self, value):
        if self._lazy:
            self._evaluate()
        self._omega = value

    def _evaluate(self):
        """Put the free flow's state at the current step count into q and omega."""
        self._lazy = False
        flow, start = self._segment
        q, m = flow.state((self.steps - start) * self.dt)
        r = 1.0 / math.sqrt(q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3])
        self._q = (float(q[0]) * r, float(q[1]) * r, float(q[2]) * r, float(q[3]) * r)
        i1, i2, i3 = self.moments
        self._omega = (float(m[0]) / i1, float(m[1]) / i2, float(m[2]) / i3)

    def _torque_step(self, torque, torque_world):
        self._segment = None
        key = (torque, torque_world)
        if key != self._torque_key:
            largest = max(abs(torque[0]), abs(torque[1]), abs(torque[2]))
            if torque_world is not None:
                largest += max(abs(torque_world[0]), abs(torque_world[1]),
                               abs(torque_world[2]))
            self._torque_rate = math.sqrt(largest / self._i_min)
            self._torque_key = key
        return self._rk('body' if torque_world is None else 'world', torque, torque_world,
                        self._torque_rate)

    def _field_step(self, torque, torque_world, field):
        self._segment = None
        t = self.time
        f = field(t, *self.q, *self.omega)
        largest = max(abs(torque[0] + f[0]), abs(torque[1] + f[1]), abs(torque[2] + f[2]))
        if torque_world is not None:
            largest += max(abs(torque_world[0]), abs(torque_world[1]), abs(torque_world[2]))
        return self._rk('field', torque, torque_world, math.sqrt(largest / self._i_min),
                        field)

    def _rk(self, mode, torque, torque_world, torque_rate, field=None):
        """
        Advance by dt with the order-6 or order-8 kernel of ``mode``; return the work (J).

        ``torque_rate`` (1/s) is the torque's part of rho, sqrt(max |tau_i| / I_min);
        ``field`` the time- and attitude-dependent torque of mode ``field``.
        """
        wx, wy, wz = self.omega
        t = self.time
        kernels = self._kernels[mode]
        spare = self._order6_rate - torque_rate     # what |omega| may be for order 6
        if spare > 0.0 and wx * wx + wy * wy + wz * wz <= spare * spare:
            order6 = kernels[6]
            if field is not None:
                order6, torque_world = field_kernel(field, 6, kernels, torque_world)
            self.q, self.omega, work = order6(
                self._inv, self.q, self.omega, self.dt, torque, torque_world, field, t)
            return work
        rho = math.sqrt(wx * wx + wy * wy + wz * wz) + torque_rate
        n = max(1, math.ceil(rho * self.dt / self.ORDER8_LIMIT))
        h = self.dt / n
        order8 = kernels[8]
        if field is not None:
            order8, torque_world = field_kernel(field, 8, kernels, torque_world)
        q, w, work = self.q, self.omega, 0.0
        for k in range(n):
            q, w, dw = order8(self._inv, q, w, h, torque, torque_world, field, t + k * h)
            work += dw
        self.q, self.omega = q, w
        return work


#: Integrator classes by name; ``exact`` is the default.
INTEGRATORS = {cls.name: cls for cls in (ExactIntegrator, RK4Integrator)}


def make_integrator(name, moments, dt, q0=(0.0, 0.0, 0.0, 1.0), omega0=(0.0, 0.0, 0.0)):
    """
    Build the integrator called ``name`` (see INTEGRATORS).

    Raises ValueError naming the known integrators for an unknown name, and
    saying what replaced it for a removed one.
    """
    if name in REMOVED:
        raise ValueError(REMOVED[name])
    try:
        cls = INTEGRATORS[name]
    except KeyError:
        raise ValueError(f'unknown integrator {name!r}; choose one of '
                         f'{", ".join(sorted(INTEGRATORS))}') from None
    return cls(moments, dt, q0, omega0)
