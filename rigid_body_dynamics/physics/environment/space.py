"""
The space environment of one body: orbit, magnetic field and the torque models they drive.

:class:`SpaceEnvironment` is what the integrators call at every stage (their
``field`` argument): at simulated time t it finds the position on the orbit
and the magnetic field there, turns both into the principal frame of the body's
attitude at that stage, and sums the torques of its models
(:mod:`.torque_models`). It knows no model by name. :class:`Disturbances` is what a body's
environment is, as data (what the nodes' parameters say).
"""

from dataclasses import dataclass

from .orbit import R_EARTH

_ZERO = (0.0, 0.0, 0.0)


class Surroundings:
    """
    What the models share at one stage: ``r_body`` (m) and ``b_body`` (T), principal frame.

    Also ``r_world`` (m) and ``b_world`` (T); None where the environment has no orbit or
    no field.
    """

    __slots__ = ('r_world', 'r_body', 'b_world', 'b_body')

    def __init__(self):
        self.r_world = self.r_body = self.b_world = self.b_body = None


def _to_body(qx, qy, qz, qw, v):
    """Rotate world vector v by the conjugate of q (q need not be unit): R(q)^T v."""
    gx, gy, gz = v
    s = 1.0 / (qx * qx + qy * qy + qz * qz + qw * qw)
    ux = 2.0 * (-qy * gz + qz * gy)
    uy = 2.0 * (-qz * gx + qx * gz)
    uz = 2.0 * (-qx * gy + qy * gx)
    return (gx + s * (qw * ux - qy * uz + qz * uy),
            gy + s * (qw * uy - qz * ux + qx * uz),
            gz + s * (qw * uz - qx * uy + qy * ux))


class SpaceEnvironment:
    """
    Orbit, field and torque models of one body, as the integrators' stage torque.

    ``orbit`` (a :class:`~.orbit.KeplerOrbit` or None), ``field`` (a
    :class:`~.magnetic_field.DipoleField` or None), ``models`` (objects on the
    protocol of :mod:`.torque_models`). ``epoch`` (s) is added to the
    integrator's time (the simulated time at the integrator's time 0).
    A model that needs the position without an orbit, or the field without one,
    is refused with ValueError.

    Called as ``env(t, qx, qy, qz, qw, wx, wy, wz)`` (t in s, q principal ->
    world, omega rad/s principal) it returns the summed torque (N m, principal).
    """

    def __init__(self, orbit=None, field=None, models=(), epoch=0.0):
        self.orbit, self.field, self.models = orbit, field, tuple(models)
        needs = set()
        for model in self.models:
            needs |= model.needs
        if field is not None:
            needs.add('field')
        if 'field' in needs:
            if field is None:
                raise ValueError('a magnetic torque needs a magnetic field model '
                                 '(magnetic_field_model dipole)')
            needs.add('position')
        if 'position' in needs and orbit is None:
            raise ValueError('the gravity gradient and the magnetic field need an orbit '
                             '(orbit_elements)')
        self._position = 'position' in needs
        self._field = 'field' in needs and field is not None
        self.epoch = float(epoch)
        self.env = Surroundings()
        # (r, B) in the world frame by time: an RK step evaluates a few times more than
        # once (Butcher's order 6 has 5 distinct nodes in 7 stages, and a step's end is the
        # next one's start), and they depend on the time alone
        self._world = {}
        self._last = (None, None)      # (arguments, torque) of the last call

    def surroundings(self, t, q):
        """Fill and return the :class:`Surroundings` at simulated time t (s) and attitude q."""
        env = self.env
        if self._position:
            world = self._world.get(t)
            if world is None:
                if len(self._world) > 32:
                    self._world.clear()
                r = self.orbit.position(t)
                world = self._world[t] = (r, self.field.world(t, r) if self._field else None)
            env.r_world, env.b_world = world
            env.r_body = _to_body(*q, world[0])
            if self._field:
                env.b_body = _to_body(*q, world[1])
        return env

    def __call__(self, t, qx, qy, qz, qw, wx=0.0, wy=0.0, wz=0.0):
        """Return the summed torque (N m, principal frame) at integrator time t (s)."""
        args = (t, qx, qy, qz, qw, wx, wy, wz)
        last, torque = self._last
        if args == last:          # (the integrator asks at a step's start, then its stage 0)
            return torque
        torque = self._torque(t + self.epoch, qx, qy, qz, qw, wx, wy, wz)
        self._last = (args, torque)
        return torque

    def _torque(self, t, qx, qy, qz, qw, wx, wy, wz):
        """Return the summed torque (N m, principal) at simulated time t (s)."""
        q = (qx, qy, qz, qw)
        env = self.surroundings(t, q)
        r, omega = env.r_world, (wx, wy, wz)
        tx = ty = tz = 0.0
        for model in self.models:
            a, b, c = model.torque(t, r, q, omega, env)
            tx, ty, tz = tx + a, ty + b, tz + c
        return tx, ty, tz


@dataclass(frozen=True)
class Disturbances:
    """
    The environment and its disturbance torques, summed into the commanded torque (N m).

    ``body``: constant in the body frame; ``world``: constant in the world
    frame; ``orbit``: a :class:`~rigid_body_dynamics.physics.environment.KeplerOrbit`
    (None = no orbit); ``field``: a
    :class:`~rigid_body_dynamics.physics.environment.DipoleField` (None = none);
    ``gravity_gradient``: its torque on the orbit; ``residual_dipole`` (A m^2,
    body frame): the torque m x B in the field. ``sun`` (a
    :class:`~rigid_body_dynamics.physics.environment.Sun`, None = none) and
    ``planet_radius`` (m) are what the sensors see (the Sun, the shadow, the
    Earth's disc); they make no torque.
    """

    body: tuple = _ZERO
    world: tuple = _ZERO
    orbit: object = None
    field: object = None
    gravity_gradient: bool = False
    residual_dipole: tuple = _ZERO
    sun: object = None
    planet_radius: float = R_EARTH

    @property
    def active(self):
        """Whether any disturbance torque acts."""
        return bool(any(self.body) or any(self.world) or self.gravity_gradient
                    or any(self.residual_dipole))

    def __str__(self):
        parts = [f'{name} {value}' for name, value in (
            ('body torque', self.body), ('world torque', self.world),
            ('residual dipole', self.residual_dipole)) if any(value)]
        if self.gravity_gradient:
            parts.append('gravity gradient')
        return ', '.join(parts) or 'none'
