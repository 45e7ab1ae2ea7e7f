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
angles) with an explicit Runge-Kutta formula of fixed step: DOP853's order-8 weights
(``exact``: the torque-free gyrostat has no closed form here) or the classic RK4
(``rk4``), the motor command held over each step. It books the work of the external
torque, the motor work, the friction loss and the external impulse (world frame) by
the same formula's quadrature of their rates, so T - T0 = W_ext + W_motor - W_friction
and H_w - H_w0 = impulse check the accuracy (tests: to round-off against a tight
DOP853).
"""

from dataclasses import dataclass
import math

from . import dop853_tableau
from ..quaternions import rotate_components

_ZERO = (0.0, 0.0, 0.0)
#: Speed (rad/s) over which the Coulomb friction fades to zero at rest (tanh width).
FRICTION_SMOOTHING = 0.1
#: Most wheels a body may carry.
MAX_WHEELS = 6
#: How far a wheel axis may be from unit length (it is then normalised exactly).
AXIS_TOLERANCE = 1e-6

_RK4 = ((0.0, 0.5, 0.5, 1.0), (1 / 6, 1 / 3, 1 / 3, 1 / 6),
        ((), (0.5,), (0.0, 0.5), (0.0, 0.0, 1.0)))
_TABLEAUX = {'exact': (dop853_tableau.C, dop853_tableau.B, dop853_tableau.A), 'rk4': _RK4}


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


def _inverse3(m):
    """Inverse of a symmetric positive-definite 3x3 matrix (nested tuples), or ValueError."""
    (a, b, c), (_, e, f), (_, _, i) = m
    co = (e * i - f * f, c * f - b * i, b * f - c * e,
          a * i - c * c, b * c - a * f, a * e - b * b)
    det = a * co[0] + b * co[1] + c * co[2]
    if not (det > 0.0 and a > 0.0 and a * e - b * b > 0.0):
        raise ValueError('the body without its wheels spinning has no positive-definite '
                         'inertia (I - sum J g g^T): the wheels are too heavy for the body')
    return ((co[0] / det, co[1] / det, co[2] / det),
            (co[1] / det, co[3] / det, co[4] / det),
            (co[2] / det, co[4] / det, co[5] / det))


class GyrostatIntegrator:
    """
    Fixed-step integrator of a gyrostat in the principal frame of its inertia.

    ``moments`` (principal, kg m^2, the wheels included), ``wheels`` (:class:`Wheels`,
    axes in the principal frame), ``dt`` (s), ``q0`` (x, y, z, w; principal frame ->
    world), ``omega0`` (rad/s, principal frame), ``speeds0`` (rad/s relative to the
    body), ``method`` 'exact' (order 8) or 'rk4'. The motor command is held
    (:meth:`command_motors`, N m) and limited at the start of every step. The same
    protocol as :mod:`.integrators` (``step``, ``free_steps``, ``q``, ``omega``,
    ``time``, ``work``, ``impulse``, ``kinetic_energy``, ``angular_momentum_world``),
    with H and T those of the whole gyrostat, and: ``speeds``, ``angles`` (rad),
    ``applied`` (the motor torques of the last step, after limits), ``motor_work``
    and ``friction_loss`` (J), ``clipped`` and ``cut`` (steps at which a command was
    clipped / cut off by the speed limit, per wheel).
    """

    name = 'gyrostat'

    def __init__(self, moments, wheels, dt, q0=(0.0, 0.0, 0.0, 1.0), omega0=(0.0, 0.0, 0.0),
                 speeds0=None, method='exact'):
        self.moments = tuple(float(i) for i in moments)
        self.wheels = wheels
        if not (dt > 0.0 and math.isfinite(dt)):
            raise ValueError(f'dt must be positive and finite, got {dt!r}')
        if method not in _TABLEAUX:
            raise ValueError(f'unknown method {method!r} (exact or rk4)')
        self.dt, self.method = float(dt), method
        self._c, self._b, self._a = _TABLEAUX[method]
        locked = [[self.moments[r] if r == k else 0.0 for k in range(3)] for r in range(3)]
        for g, j in zip(wheels.axes, wheels.inertia):
            for r in range(3):
                for k in range(3):
                    locked[r][k] -= j * g[r] * g[k]
        self._a_inv = _inverse3(tuple(tuple(row) for row in locked))
        # (the step's hot path: no tanh per wheel and stage for wheels without friction)
        self._friction = wheels.friction if any(wheels.coulomb) or any(wheels.viscous) \
            else (lambda speeds, zeros=(0.0,) * wheels.count: zeros)
        self.commanded = (0.0,) * wheels.count
        self.reset(q0, omega0, speeds0)

    def reset(self, q, omega, speeds=None, angles=None):
        """Restart from q, omega and wheel speeds (default: kept); zero steps and balances."""
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

    def _rates(self, t, y, torque, torque_world, field, applied):
        """
        Return the derivatives of the state y and of the booked balances at time t.

        y = [omega (3), q (4), speeds (n), angles (n)]; returns (dy, (work rate,
        motor power, friction power, world torque (3))).
        """
        w1, w2, w3, qx, qy, qz, qw = y[:7]
        n = self.wheels.count
        speeds = y[7:7 + n]
        tx, ty, tz = torque
        if torque_world is not None:
            a = rotate_components((-qx, -qy, -qz, qw), torque_world)
            tx, ty, tz = tx + a[0], ty + a[1], tz + a[2]
        if field is not None:
            f = field(t, qx, qy, qz, qw, w1, w2, w3)
            tx, ty, tz = tx + f[0], ty + f[1], tz + f[2]
        i1, i2, i3 = self.moments
        hx, hy, hz = i1 * w1, i2 * w2, i3 * w3
        rx, ry, rz = tx, ty, tz
        friction = self._friction(speeds)
        nets, motor, loss = [], 0.0, 0.0
        for (gx, gy, gz), j, s, u, fr in zip(self.wheels.axes, self.wheels.inertia, speeds,
                                             applied, friction):
            hx, hy, hz = hx + j * s * gx, hy + j * s * gy, hz + j * s * gz
            net = u - fr
            rx, ry, rz = rx - gx * net, ry - gy * net, rz - gz * net
            nets.append(net)
            motor += s * u
            loss += s * fr
        rx -= w2 * hz - w3 * hy
        ry -= w3 * hx - w1 * hz
        rz -= w1 * hy - w2 * hx
        (a11, a12, a13), (a21, a22, a23), (a31, a32, a33) = self._a_inv
        d1 = a11 * rx + a12 * ry + a13 * rz
        d2 = a21 * rx + a22 * ry + a23 * rz
        d3 = a31 * rx + a32 * ry + a33 * rz
        dy = [d1, d2, d3,
              0.5 * (qw * w1 + qy * w3 - qz * w2), 0.5 * (qw * w2 + qz * w1 - qx * w3),
              0.5 * (qw * w3 + qx * w2 - qy * w1), -0.5 * (qx * w1 + qy * w2 + qz * w3)]
        dy += [net / j - (g[0] * d1 + g[1] * d2 + g[2] * d3)
               for net, j, g in zip(nets, self.wheels.inertia, self.wheels.axes)]
        dy += list(speeds)
        world = rotate_components((qx, qy, qz, qw), (tx, ty, tz)) if tx or ty or tz else _ZERO
        return dy, (w1 * tx + w2 * ty + w3 * tz, motor, loss, world)

    def step(self, torque=(0.0, 0.0, 0.0), torque_world=None, field=None):
        """
        Advance by dt, the motor command limited now and held over the step.

        ``torque``: external body torque (N m, principal frame), held;
        ``torque_world``: held in the world frame; ``field(t, qx, qy, qz, qw, wx, wy, wz)``: a
        principal-frame torque evaluated at the stages.
        """
        torque = tuple(float(c) for c in torque)
        if len(torque) != 3 or not all(math.isfinite(c) for c in torque):
            raise ValueError(f'torque must be three finite numbers (N m), got {torque}')
        applied, clipped, cut = self.wheels.limit(self.commanded, self.speeds)
        for i, (cl, ct) in enumerate(zip(clipped, cut)):
            self.clipped[i] += cl
            self.cut[i] += ct
        self.applied = applied
        h, t0 = self.dt, self.time
        y = list(self.omega) + list(self.q) + list(self.speeds) + list(self.angles)
        ks, ps = [], []
        for c, row in zip(self._c, self._a):
            ys = y if not row else [v + d for v, d in zip(y, self._increment(row, ks))]
            k, p = self._rates(t0 + c * h, ys, torque, torque_world, field, applied)
            ks.append(k)
            ps.append(p)
        b = self._b
        y = [v + d for v, d in zip(y, self._increment(b, ks))]
        self.work += h * sum(bi * p[0] for bi, p in zip(b, ps) if bi)
        self.motor_work += h * sum(bi * p[1] for bi, p in zip(b, ps) if bi)
        self.friction_loss += h * sum(bi * p[2] for bi, p in zip(b, ps) if bi)
        self.impulse = tuple(acc + h * sum(bi * p[3][m] for bi, p in zip(b, ps) if bi)
                             for m, acc in enumerate(self.impulse))
        n = self.wheels.count
        q = y[3:7]
        norm = math.sqrt(sum(c * c for c in q))
        self.omega = tuple(y[:3])
        self.q = tuple(c / norm for c in q)
        self.speeds = tuple(y[7:7 + n])
        self.angles = tuple(y[7 + n:])
        self.steps += 1

    def _increment(self, weights, ks):
        """
        Return h sum_j w_j k_j, summed term by term apart from the state.

        (Adding each term to the state instead loses its low bits at every term: the
        errors against DOP853 grew 3-5 times.)
        """
        h, out = self.dt, None
        for w, k in zip(weights, ks):
            if w:
                hw = h * w
                out = [hw * kv for kv in k] if out is None else \
                    [o + hw * kv for o, kv in zip(out, k)]
        return out

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
