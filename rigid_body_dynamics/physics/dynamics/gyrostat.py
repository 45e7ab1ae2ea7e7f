"""
The gyrostat: a rigid body carrying n reaction wheels (0 to 6), without ROS.

The model (the manual states it the same way). Wheel i has the unit spin axis
g_i (body frame), the spin-axis moment J_i (kg m^2) and the speed Omega_i (rad/s)
relative to the body; the body's inertia I is that of the whole spacecraft with
the wheels locked (wheels included). Then

- total angular momentum H = I omega + sum_i J_i Omega_i g_i (body frame);
- body: dH/dt (in the body) = tau_ext - omega x H;
- wheel i: J_i (g_i . omega_dot + Omega_i_dot) = u_i - f_i(Omega_i), u_i the motor
  torque after its limits, f_i the friction;
- so (I - sum_i J_i g_i g_i^T) omega_dot = tau_ext - omega x H - sum_i g_i (u_i - f_i);
- kinetic energy T = 1/2 omega.I.omega + sum_i J_i Omega_i (g_i.omega)
  + 1/2 sum_i J_i Omega_i^2, and dT/dt = omega.tau_ext + sum_i Omega_i (u_i - f_i).

Limits, in Basilisk's order (``reactionWheelStateEffector``), applied to the held
command at the start of every step: |u_i| clipped to ``max_torque`` (0 = none); then
if |Omega_i| >= ``max_speed`` (0 = none) and Omega_i u_i > 0, u_i = 0. Friction:
f_i = c_i tanh(Omega_i / FRICTION_SMOOTHING) + v_i Omega_i (Coulomb ``coulomb`` c_i N m,
viscous ``viscous`` v_i N m s). The tanh is the smoothing: within a few
FRICTION_SMOOTHING of rest the Coulomb torque fades to zero instead of flipping sign
at every step (a wheel at rest under a fixed step would chatter between +c and -c);
beyond 20 FRICTION_SMOOTHING it equals c sign(Omega) to double precision.

:class:`GyrostatIntegrator` integrates the augmented state (omega, q, Omega, wheel
angles) with an explicit Runge-Kutta formula of fixed step, unrolled for the wheel
count by :mod:`.gyrostat_kernels`: ``exact`` takes Butcher's order-6 formula while
the body's fastest rate rho (|omega| + |sum J Omega g| / lambda_min(A) + sqrt(largest
torque / lambda_min(A)), 1/s, A = I - sum J g g^T) times dt is at most
``ORDER6_LIMIT``, else DOP853's order-8 formula in sub-steps with rho h <=
``ORDER8_LIMIT`` (the torque-free gyrostat has no closed form here; the limits are the
plain body's, :class:`~.integrators.ExactIntegrator`); ``rk4`` the classic RK4. The
motor command is held over each step. It books the work of the external torque, the
motor work, the friction loss and the external impulse (world frame) by the same
formula's quadrature of their rates, so T - T0 = W_ext + W_motor - W_friction and
H_w - H_w0 = impulse check the accuracy (tests: to round-off against a tight DOP853).

Idle motors: while no motor torque is commanded (the limits then cannot act) and the
external torque stays the same, ``exact`` defers its steps and takes the ones in a row
as one span, sub-stepped by the same rho rule, when the state is next read, the input
changes, or ``DEFER_LIMIT`` steps are pending. The rule keeps a 10 ms step as accurate
against DOP853 as a 1 ms one, so the state is the same to round-off; a body read at
100 Hz and stepped at 1 kHz takes one order-8 step per read instead of ten order-6 ones.
"""

from dataclasses import dataclass
import math

from .gyrostat_kernels import constants, environment_kernel, kernel
from .integrators import as_torque, ExactIntegrator
from ..quaternions import rotate_components

_ZERO = (0.0, 0.0, 0.0)
#: Speed (rad/s) over which the Coulomb friction fades to zero at rest (tanh width).
FRICTION_SMOOTHING = 0.1
#: Most wheels a body may carry.
MAX_WHEELS = 6
#: How far a wheel axis may be from unit length (it is then normalised exactly).
AXIS_TOLERANCE = 1e-6

_METHODS = ('exact', 'rk4')


def _numbers(values, n, what, positive=False):
    """Return ``values`` as n finite floats >= 0 (> 0 if ``positive``), or ValueError."""
    out = tuple(float(v) for v in values)
    if len(out) != n:
        raise ValueError(f'{what} needs {n} values (one per wheel), got {len(out)}')
    for i, v in enumerate(out):
        if not math.isfinite(v) or v < 0.0 or (positive and v == 0.0):
            raise ValueError(f'{what}[{i}] must be a finite number '
                             f'{"> 0" if positive else ">= 0"}, got {v!r}')
    return out


@dataclass(frozen=True)
class Wheels:
    """
    n reaction wheels (n = 0 .. MAX_WHEELS), validated.

    ``axes``: n unit spin axes (body frame), or 3n numbers; ``inertia``: n
    spin-axis moments J_i > 0 (kg m^2); ``max_torque`` (N m) and ``max_speed``
    (rad/s relative to the body): n values, 0 = no limit; ``coulomb`` (N m) and
    ``viscous`` (N m s): n friction coefficients >= 0. Limits and friction left
    out (None or empty) are zeros. Wrong lengths, zero or non-unit axes and negative values are
    refused with the reason (ValueError).
    """

    axes: tuple = ()
    inertia: tuple = ()
    max_torque: tuple = None
    max_speed: tuple = None
    coulomb: tuple = None
    viscous: tuple = None

    def __post_init__(self):
        """Validate and normalise (the fields become tuples of floats)."""
        flat = [float(c) for axis in self.axes for c in (axis if hasattr(axis, '__len__')
                                                         else (axis,))]
        if len(flat) % 3:
            raise ValueError(f'wheel_axes needs 3 numbers per wheel, got {len(flat)}')
        n = len(flat) // 3
        if n > MAX_WHEELS:
            raise ValueError(f'at most {MAX_WHEELS} wheels, got {n}')
        axes = []
        for i in range(n):
            g = flat[3 * i:3 * i + 3]
            norm = math.sqrt(sum(c * c for c in g))
            if not math.isfinite(norm) or norm == 0.0:
                raise ValueError(f'wheel_axes: axis {i} must be a finite non-zero vector, got {g}')
            if abs(norm - 1.0) > AXIS_TOLERANCE:
                raise ValueError(f'wheel_axes: axis {i} must be a unit vector (normalised), got '
                                 f'{g} of length {norm:.9g}')
            axes.append(tuple(c / norm for c in g))
        set_ = object.__setattr__
        set_(self, 'axes', tuple(axes))
        set_(self, 'inertia', _numbers(self.inertia, n, 'wheel_inertia', positive=True))
        for name in ('max_torque', 'max_speed', 'coulomb', 'viscous'):
            value = getattr(self, name)
            set_(self, name, (0.0,) * n if value is None or len(value) == 0
                 else _numbers(value, n, {'max_torque': 'wheel_max_torque',
                                          'max_speed': 'wheel_max_speed',
                                          'coulomb': 'wheel_friction_coulomb',
                                          'viscous': 'wheel_friction_viscous'}[name]))

    @property
    def count(self):
        """Return the number of wheels n."""
        return len(self.axes)

    def turned(self, to_frame):
        """Return the same wheels with axes taken into another frame: ``to_frame(g)`` -> g'."""
        return Wheels(tuple(tuple(float(c) for c in to_frame(g)) for g in self.axes),
                      self.inertia, self.max_torque, self.max_speed, self.coulomb, self.viscous)

    def limit(self, commanded, speeds):
        """
        Return the motor torques applied (N m) and whether each was clipped or cut off.

        ``commanded`` n motor torques (N m), ``speeds`` n wheel speeds (rad/s relative
        to the body). Basilisk's order: clip |u| to max_torque, then cut u to 0 where
        |Omega| >= max_speed and Omega u > 0. Returns (applied, clipped, cut).
        """
        if not any(commanded):           # nothing to clip, nothing to cut off
            none = (False,) * len(commanded)
            return tuple(commanded), none, none
        applied, clipped, cut = [], [], []
        for u, omega, top, fastest in zip(commanded, speeds, self.max_torque, self.max_speed):
            clip = top > 0.0 and abs(u) > top
            if clip:
                u = math.copysign(top, u)
            stop = fastest > 0.0 and abs(omega) >= fastest and omega * u > 0.0
            if stop:
                u = 0.0
            applied.append(u)
            clipped.append(clip)
            cut.append(stop)
        return tuple(applied), tuple(clipped), tuple(cut)

    def friction(self, speeds):
        """Return the friction torques f_i (N m) at wheel speeds ``speeds`` (rad/s)."""
        return tuple(c * math.tanh(omega / FRICTION_SMOOTHING) + v * omega
                     for omega, c, v in zip(speeds, self.coulomb, self.viscous))


def _deferred(name, doc):
    """Return a property for a state attribute: a read or write first takes deferred steps."""
    private = '_' + name

    def get(self):
        if self._pending:
            self._take_pending()
        return getattr(self, private)

    def put(self, value):
        if self._pending:
            self._take_pending()
        setattr(self, private, value)
    return property(get, put, doc=doc)


class GyrostatIntegrator:
    """
    Fixed-step integrator of a gyrostat in the principal frame of its inertia.

    ``moments`` (principal, kg m^2, the wheels included), ``wheels`` (:class:`Wheels`,
    axes in the principal frame), ``dt`` (s), ``q0`` (x, y, z, w; principal frame ->
    world), ``omega0`` (rad/s, principal frame), ``speeds0`` (rad/s relative to the
    body), ``method`` 'exact' (order 6 or 8) or 'rk4'. The motor command is held
    (:meth:`command_motors`, N m) and limited at the start of every step. The same
    protocol as :mod:`.integrators` (``step``, ``free_steps``, ``q``, ``omega``,
    ``time``, ``work``, ``impulse``, ``kinetic_energy``, ``angular_momentum_world``),
    with H and T those of the whole gyrostat, and: ``speeds``, ``angles`` (rad),
    ``applied`` (the motor torques of the last step, after limits), ``motor_work``
    and ``friction_loss`` (J), ``clipped`` and ``cut`` (steps at which a command was
    clipped / cut off by the speed limit, per wheel). ``defer`` False takes every step
    when it is called (see the module docstring on idle motors).
    """

    name = 'gyrostat'
    ORDER6_LIMIT = ExactIntegrator.ORDER6_LIMIT
    ORDER8_LIMIT = ExactIntegrator.ORDER8_LIMIT
    #: Most idle steps deferred before they are taken (as one span).
    DEFER_LIMIT = 100

    q = _deferred('q', 'Attitude (x, y, z, w), principal frame -> world.')
    omega = _deferred('omega', 'Angular velocity (rad/s, principal frame).')
    speeds = _deferred('speeds', 'Wheel speeds relative to the body (rad/s).')
    angles = _deferred('angles', 'Wheel angles relative to the body (rad).')
    work = _deferred('work', 'Work of the external torque since the reset (J).')
    motor_work = _deferred('motor_work', 'Work of the motors since the reset (J).')
    friction_loss = _deferred('friction_loss', 'Energy the friction took since the reset (J).')
    impulse = _deferred('impulse', 'External impulse since the reset (N m s, world frame).')
    _pending = 0                # idle steps deferred (see step)

    def __init__(self, moments, wheels, dt, q0=(0.0, 0.0, 0.0, 1.0), omega0=(0.0, 0.0, 0.0),
                 speeds0=None, method='exact', defer=True):
        self.moments = tuple(float(i) for i in moments)
        self.wheels = wheels
        if not (dt > 0.0 and math.isfinite(dt)):
            raise ValueError(f'dt must be positive and finite, got {dt!r}')
        if method not in _METHODS:
            raise ValueError(f'unknown method {method!r} (exact or rk4)')
        self.dt, self.method = float(dt), method
        # (the step's hot path: no tanh per wheel and stage for wheels without friction)
        self._friction = any(wheels.coulomb) or any(wheels.viscous)
        self._k, self._a_min = constants(self.moments, wheels, self._friction,
                                         FRICTION_SMOOTHING)
        self._order6_rate = self.ORDER6_LIMIT / self.dt   # rho (1/s) up to which order 6
        self._jg = tuple(tuple(j * c for c in g) for j, g in zip(wheels.inertia, wheels.axes))
        self._kernels = {}          # (order, mode) -> the compiled step for these wheels
        self._defer = bool(defer) and method == 'exact'
        self._pending_key = None    # (torque, torque_world) of the deferred steps
        self.commanded = (0.0,) * wheels.count
        self.reset(q0, omega0, speeds0)

    def reset(self, q, omega, speeds=None, angles=None):
        """Restart from q, omega and wheel speeds (default: kept); zero steps and balances."""
        if self._pending:
            self._take_pending()
        q = tuple(float(c) for c in q)
        norm = math.sqrt(sum(c * c for c in q))
        if not (norm > 0.0 and math.isfinite(norm)):
            raise ValueError(f'attitude quaternion must be finite and non-zero, got {q}')
        n = self.wheels.count
        if speeds is None:
            speeds = getattr(self, 'speeds', (0.0,) * n)
        speeds = tuple(float(s) for s in speeds)
        if len(speeds) != n or not all(math.isfinite(s) for s in speeds):
            raise ValueError(f'wheel speeds must be {n} finite numbers, got {speeds}')
        self.q = tuple(c / norm for c in q)
        self.omega = tuple(float(c) for c in omega)
        self.speeds = speeds
        self.angles = tuple(float(a) for a in angles) if angles is not None else (0.0,) * n
        self.steps = 0
        self.work = self.motor_work = self.friction_loss = 0.0
        self.impulse = (0.0, 0.0, 0.0)
        self.applied = (0.0,) * n
        self.clipped = [0] * n
        self.cut = [0] * n

    def command_motors(self, torques):
        """Hold ``torques`` (n motor torques, N m, finite) from the next step on."""
        torques = tuple(float(u) for u in torques)
        if len(torques) != self.wheels.count or not all(math.isfinite(u) for u in torques):
            raise ValueError(f'motor torques must be {self.wheels.count} finite numbers, got '
                             f'{torques}')
        self.commanded = torques

    @property
    def time(self):
        """Return the simulated time steps * dt (s)."""
        return self.steps * self.dt

    @property
    def angular_momentum_body(self):
        """H = I omega + sum J_i Omega_i g_i, principal frame (kg m^2/s)."""
        return self._momentum(self.omega, self.speeds)

    def _momentum(self, omega, speeds):
        hx, hy, hz = (i * w for i, w in zip(self.moments, omega))
        for (gx, gy, gz), j, s in zip(self.wheels.axes, self.wheels.inertia, speeds):
            hx, hy, hz = hx + j * s * gx, hy + j * s * gy, hz + j * s * gz
        return hx, hy, hz

    @property
    def angular_momentum_world(self):
        """H in the world frame (kg m^2/s)."""
        return rotate_components(self.q, self.angular_momentum_body)

    @property
    def wheel_momentum_body(self):
        """Return the wheels' share of H, sum J_i Omega_i g_i, principal frame (kg m^2/s)."""
        return self._momentum((0.0, 0.0, 0.0), self.speeds)

    @property
    def kinetic_energy(self):
        """T = 1/2 omega.I.omega + sum J_i Omega_i (g_i.omega) + 1/2 sum J_i Omega_i^2 (J)."""
        w = self.omega
        t = 0.5 * sum(i * c * c for i, c in zip(self.moments, w))
        for g, j, s in zip(self.wheels.axes, self.wheels.inertia, self.speeds):
            t += j * s * (g[0] * w[0] + g[1] * w[1] + g[2] * w[2]) + 0.5 * j * s * s
        return t

    def _rate(self, torque, torque_world, field, applied):
        """
        Return rho (1/s), the body's fastest rate at the start of the step.

        |omega| + |sum J Omega g| / lambda_min(A) + sqrt(largest torque / lambda_min(A)),
        the largest torque the sum of the largest external components and of the motor
        torques' sizes (N m).
        """
        wx, wy, wz = self._omega
        hx = hy = hz = 0.0
        for (jx, jy, jz), s in zip(self._jg, self._speeds):
            hx, hy, hz = hx + jx * s, hy + jy * s, hz + jz * s
        largest = max(abs(torque[0]), abs(torque[1]), abs(torque[2])) + sum(map(abs, applied))
        if torque_world is not None:
            largest += max(abs(torque_world[0]), abs(torque_world[1]), abs(torque_world[2]))
        if field is not None:
            f = field(self.time, *self._q, wx, wy, wz)
            largest += max(abs(f[0]), abs(f[1]), abs(f[2]))
        return (math.sqrt(wx * wx + wy * wy + wz * wz)
                + math.sqrt(hx * hx + hy * hy + hz * hz) / self._a_min
                + math.sqrt(largest / self._a_min))

    def step(self, torque=_ZERO, torque_world=None, field=None):
        """
        Advance by dt, the motor command limited now and held over the step.

        ``torque``: external body torque (N m, principal frame), held;
        ``torque_world``: held in the world frame; ``field(t, qx, qy, qz, qw, wx, wy, wz)``: a
        principal-frame torque evaluated at the stages. A torque that is not three finite
        numbers raises ValueError and leaves the state as it was. With idle motors the
        step may be deferred (see the module docstring); reading the state takes it.
        """
        torque = as_torque(torque, 'torque')
        if torque_world is not None:
            torque_world = as_torque(torque_world, 'torque_world')
            if not (torque_world[0] or torque_world[1] or torque_world[2]):
                torque_world = None
        idle = self._defer and field is None and not any(self.commanded)
        if self._pending and not (idle and self._pending_key == (torque, torque_world)
                                  and self._pending < self.DEFER_LIMIT):
            self._take_pending()
        if idle:
            self._pending += 1
            self._pending_key = (torque, torque_world)
            self.applied = self.commanded
            self.steps += 1
            return
        code = None if field is None else getattr(field, 'stage_code', None)
        if code is not None:
            mode = 'environment'
        elif field is not None:
            mode, torque_world = 'field', torque_world or _ZERO
        elif torque_world is not None:
            mode = 'world'
        else:
            mode = 'body' if torque[0] or torque[1] or torque[2] else 'free'
        applied, clipped, cut = self.wheels.limit(self.commanded, self._speeds)
        if True in clipped or True in cut:
            for i, (cl, ct) in enumerate(zip(clipped, cut)):
                self.clipped[i] += cl
                self.cut[i] += ct
        self.applied = applied
        self._advance(torque, torque_world, field, mode, code, applied, 1)
        self.steps += 1

    def _take_pending(self):
        """Take the deferred idle steps as one span (the step count already has them)."""
        count, self._pending = self._pending, 0
        torque, torque_world = self._pending_key
        mode = ('world' if torque_world is not None else
                'body' if torque[0] or torque[1] or torque[2] else 'free')
        self._advance(torque, torque_world, None, mode, None, (0.0,) * self.wheels.count,
                      count, self.steps - count)

    def _advance(self, torque, torque_world, field, mode, code, applied, count, start=None):
        """
        Integrate ``count`` steps from step ``start`` (default: the current one) as one span.

        Sub-stepped by the rho rule over the span: order 6 while rho times the span is
        at most ORDER6_LIMIT, else order 8 with rho h <= ORDER8_LIMIT.
        """
        span = self.dt * count
        order, parts = 4, 1
        if self.method == 'exact':
            rho = self._rate(torque, torque_world, field, applied)
            order = 6 if (rho <= self._order6_rate if count == 1 else
                          rho * span <= self.ORDER6_LIMIT) else 8
            if order == 8:
                parts = max(1, math.ceil(rho * span / self.ORDER8_LIMIT))
        if code is not None:
            step = environment_kernel(order, self.wheels.count, self._friction, code,
                                      torque_world is not None)
        else:
            step = self._kernels.get((order, mode))
            if step is None:
                step = self._kernels[order, mode] = kernel(order, self.wheels.count, mode,
                                                           self._friction)
        h = span / parts
        t0 = (self.steps if start is None else start) * self.dt
        q, w, speeds, angles = self._q, self._omega, self._speeds, self._angles
        for i in range(parts):
            q, w, speeds, angles, work, motor, loss, impulse = step(
                self._k, q, w, speeds, angles, h, applied, torque, torque_world, field,
                t0 + i * h)
            self._work += work
            self._motor_work += motor
            self._friction_loss += loss
            if mode != 'free':
                ix, iy, iz = self._impulse
                self._impulse = (ix + impulse[0], iy + impulse[1], iz + impulse[2])
        self._q, self._omega, self._speeds, self._angles = q, w, speeds, angles

    def free_steps(self, count):
        """Advance ``count`` steps without external torque (the wheels still act)."""
        for _ in range(count):
            self.step()


# ------------------------------------------------------------------------------- theory
def precession_rate(moments, omega_axis, h, axis=2):
    """
    Rate (rad/s) at which omega's transverse part turns in the body of an axisymmetric gyrostat.

    ``moments`` (kg m^2) with the two moments other than ``axis`` equal (I_perp),
    rotor momentum ``h`` = sum J Omega along ``axis`` (kg m^2/s), ``omega_axis`` the
    (constant) spin about it (rad/s): lambda = ((I_axis - I_perp) omega_axis + h) / I_perp,
    counter-clockwise about +axis. With h = 0 it is Shapiro's body rate Omega.
    """
    others = [moments[k] for k in range(3) if k != axis]
    if not math.isclose(others[0], others[1], rel_tol=1e-12):
        raise ValueError(f'the body is not axisymmetric about axis {axis + 1}: {moments}')
    return ((moments[axis] - others[0]) * omega_axis + h) / others[0]


def spin_stability(moments, axis, omega, h):
    """
    Linear stability of a spin ``omega`` (rad/s) about principal ``axis`` with rotor momentum h.

    ``h`` (kg m^2/s) along the same axis, held (no motor torque). With i, j the other
    axes the spin is stable iff ((I_k - I_i) omega + h) ((I_k - I_j) omega + h) > 0;
    otherwise a small departure grows at sqrt(-product / (I_i I_j)) (1/s). Returns
    (stable, growth rate in 1/s: 0.0 when stable).
    """
    k = axis
    i, j = [m for m in range(3) if m != k]
    product = ((moments[k] - moments[i]) * omega + h) * ((moments[k] - moments[j]) * omega + h)
    if product > 0.0:
        return True, 0.0
    return False, math.sqrt(-product / (moments[i] * moments[j]))
