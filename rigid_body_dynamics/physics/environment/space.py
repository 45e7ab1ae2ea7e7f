"""
The space environment of one body: orbit, magnetic field and the torque models they drive.

:class:`SpaceEnvironment` is what the integrators call at every stage (their
``field`` argument): at simulated time t it finds the position on the orbit
and the magnetic field there, turns both into the principal frame of the body's
attitude at that stage, and sums the torques of its models
(:mod:`.torque_models`). It knows no model by name. When every model gives its
torque as statements (:mod:`.stage_code`), the integrators put them into their
generated stages, and a call runs the same statements compiled.

The world quantities (the position, the field, the Sun, the air) depend on time
alone, and the steps of a body fall on a grid (step k starts at k h): the generated
stages ask for a whole step's nodes at once (:meth:`SpaceEnvironment.world_nodes`),
and those come from a table computed a block of :data:`WORLD_BLOCK` steps at a time
with numpy (:meth:`SpaceEnvironment.world_many`), the same formulas over arrays; in
pure Python each node cost a dozen calls. The table's times are the stages' own to the
bit (k h + c h); its values agree with :meth:`SpaceEnvironment.world_at` to a few
units in the last place (numpy's sine and exponential are not the C library's; the
Chebyshev sums of the orbit and the field are the same to the bit). A time off the
grid, or a block that cannot be computed (an orbit SGP4 cannot fly a little ahead),
is evaluated node by node as before, so an error comes at its own time.
:class:`Disturbances` is what a body's environment is, as data (what the nodes'
parameters say).
"""

from dataclasses import dataclass
import math

import numpy as np

from .facets import SOLAR_PRESSURE_1AU
from .orbit import R_EARTH
from .shadow import sunlit_fraction, sunlit_fractions
from .stage_code import stage_code, torque_source
from .sun import AU
from ..dynamics.rk_kernels import compile_source

_ZERO = (0.0, 0.0, 0.0)
#: Steps per block of the world table (500 steps: about 1.5 ms of numpy for the whole
#: mission model, once per 0.5 s of a 1 kHz body).
WORLD_BLOCK = 500


class Surroundings:
    """
    What the models share at one stage: ``r_body`` (m) and ``b_body`` (T), principal frame.

    Also ``r_world`` (m) and ``b_world`` (T); with the Sun, ``s_world`` and ``s_body``
    (the unit direction from the body to the Sun) and ``pressure`` (the solar radiation
    pressure there, N/m^2, the shadow's fraction included); with the atmosphere,
    ``f_world`` and ``f_body`` (the body's velocity relative to the air, m/s) and
    ``density`` (kg/m^3). None where the environment has no orbit, no field, no Sun
    or no atmosphere.
    """

    __slots__ = ('r_world', 'r_body', 'b_world', 'b_body', 's_world', 's_body', 'pressure',
                 'f_world', 'f_body', 'density')

    def __init__(self):
        self.r_world = self.r_body = self.b_world = self.b_body = None
        self.s_world = self.s_body = self.pressure = None
        self.f_world = self.f_body = self.density = None


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
    is refused with ValueError. ``stages`` False calls the models at every stage even
    when they have statements (to compare the two). ``sun`` (a
    :class:`~.sun.Sun`), ``shadow`` (a :data:`~.shadow.SHADOW_MODELS` name) and
    ``planet_radius`` (m) give the Sun to models whose ``needs`` has 'sun' (refused
    without a Sun or an orbit); ``atmosphere`` (e.g. an
    :class:`~.atmosphere.ExponentialAtmosphere`) the air to models whose ``needs`` has
    'flow' (refused without an atmosphere or an orbit).

    Called as ``env(t, qx, qy, qz, qw, wx, wy, wz)`` (t in s, q principal ->
    world, omega rad/s principal) it returns the summed torque (N m, principal).
    ``stage_code`` is the models as stage statements (None when a model has no
    ``stage_source``), ``constants`` their parameters, read when it is made: a
    model's parameter changed later (``Magnetorquers.set_dipole``) takes effect in a
    new SpaceEnvironment, as :class:`~rigid_body_dynamics.physics.dynamics.plant.Plant`
    makes on every change.
    """

    def __init__(self, orbit=None, field=None, models=(), epoch=0.0, stages=True, sun=None,
                 shadow='cylindrical', planet_radius=R_EARTH, atmosphere=None):
        self.orbit, self.field, self.models = orbit, field, tuple(models)
        self.sun, self.shadow, self.planet_radius = sun, shadow, float(planet_radius)
        self.atmosphere = atmosphere
        needs = set()
        for model in self.models:
            needs |= model.needs
        self._sun = 'sun' in needs
        if self._sun:
            if sun is None or orbit is None:
                raise ValueError('solar radiation pressure needs an orbit and the Sun '
                                 '(orbit_elements or orbit_tle, and epoch)')
            needs.add('position')
        self._flow = 'flow' in needs
        if self._flow:
            if atmosphere is None or orbit is None:
                raise ValueError('drag needs an orbit and an atmosphere (orbit_elements or '
                                 'orbit_tle, and atmosphere_model)')
            needs.add('position')
        if field is not None:
            needs.add('field')
        if 'field' in needs:
            if field is None:
                raise ValueError('a magnetic torque needs a magnetic field model '
                                 '(magnetic_field_model dipole or igrf)')
            needs.add('position')
        if 'position' in needs and orbit is None:
            raise ValueError('the gravity gradient and the magnetic field need an orbit '
                             '(orbit_elements)')
        self._position = 'position' in needs
        self._field = 'field' in needs and field is not None
        self.epoch = float(epoch)
        self.env = Surroundings()
        # the world quantities by integrator time: an RK step evaluates a few times more than
        # once (a step's end is the next one's start, and the order is chosen at the start)
        self._world = {}
        self._tables = {}              # (h, nodes) -> _WorldTable: a step grid's nodes
        self._grid = None              # the table whose first node is 0: world_at reads it
        self._last = (None, None)      # (arguments, torque) of the last call
        #: the models as stage statements (None: one has none; they are then called)
        # where each world quantity starts in world_at's tuple: r and |r|^2, B, the Sun, the air
        self._at_b = 4
        self._at_s = self._at_b + 3 * self._field
        self._at_f = self._at_s + 4 * self._sun
        self.stage_code = stage_code(self.models, self._position, self._field) if stages \
            else None
        #: the models' constants in the order of ``stage_code.names``, read now
        self.constants = self.stage_code.values if self.stage_code is not None else ()
        self._compiled = compiled_torque(self.stage_code) if self.stage_code is not None \
            else None

    def world_at(self, t):
        """
        Return (r (m), norm(r)^2 (m^2), B (T), s, P, f (m/s), rho), world frame, at time t.

        A flat tuple at integrator time t (s); r and its norm only when the models need
        the position, B only with a field, the unit direction s from the body to the Sun
        and the solar radiation pressure P there (N/m^2, times the shadow's sunlit
        fraction) only when a model needs the Sun, the velocity f relative to the air and
        the density rho (kg/m^3) only when a model needs the flow (see
        :class:`~.stage_code.StageCode`).
        """
        world = self._world.get(t)
        if world is None:
            if not self._position:
                return ()
            if self._grid is not None:           # a step's start: the table's node 0
                row = self._grid.row(t)
                if row is not None:
                    return tuple(row[:self.width])
            if len(self._world) > 32:
                self._world.clear()
            s = t + self.epoch
            if self._flow:
                r, v = self.orbit.state(s)
                r, v = tuple(r), tuple(v)
            else:
                r = self.orbit.position(s)
            world = r + (r[0] * r[0] + r[1] * r[1] + r[2] * r[2],)
            if self._field:
                world += self.field.world(s, r)
            if self._sun:
                world += self._sunlight(s, r)
            if self._flow:
                world += self.atmosphere.flow(r, v) + (self.atmosphere.density(s, r),)
            world = self._world[t] = world
        return world

    @property
    def width(self):
        """Return how many numbers :meth:`world_at` gives at one time."""
        return (self._at_f + 4 * self._flow) if self._position else 0

    def world_many(self, times):
        """
        Return :meth:`world_at` at integrator times ``times`` (s, an array): (N, width).

        The same quantities, world frame, computed over the array (numpy); an orbit or a
        field without an array method (``positions``, ``states``, ``world_many``) is
        called at each time.
        """
        s = np.asarray(times, float) + self.epoch
        orbit = self.orbit
        if self._flow:
            r, v = orbit.states(s) if hasattr(orbit, 'states') else (
                np.array(part) for part in zip(*(orbit.state(x) for x in s)))
        else:
            r = orbit.positions(s) if hasattr(orbit, 'positions') else np.array(
                [orbit.position(x) for x in s])
        columns = [r, (r[:, 0] * r[:, 0] + r[:, 1] * r[:, 1] + r[:, 2] * r[:, 2])[:, None]]
        if self._field:
            columns.append(self.field.world_many(s, r) if hasattr(self.field, 'world_many')
                           else np.array([self.field.world(x, p) for x, p in zip(s, r)]))
        if self._sun:
            sun = self.sun.positions(s)
            d = sun - r
            distance = np.sqrt(d[:, 0] * d[:, 0] + d[:, 1] * d[:, 1] + d[:, 2] * d[:, 2])
            light = sunlit_fractions(r, sun, self.planet_radius, self.shadow)
            columns += [d / distance[:, None],
                        (SOLAR_PRESSURE_1AU * (AU / distance) ** 2 * light)[:, None]]
        if self._flow:
            columns += [self.atmosphere.flows(r, v), self.atmosphere.densities(s, r)[:, None]]
        return np.hstack(columns)

    @property
    def world_key(self):
        """Return what the world quantities depend on: two environments with one key share them."""
        return (id(self.orbit), id(self.field), id(self.sun), id(self.atmosphere), self.shadow,
                self.planet_radius, self.epoch, self._position, self._field, self._sun,
                self._flow)

    def adopt_world(self, previous):
        """
        Take over the world tables of ``previous`` (a SpaceEnvironment or None) of our world.

        A plant makes a new environment for every change of a model's parameter (a
        magnetorquer command, at 10 Hz or 100 Hz); the table's blocks of 500 steps are
        the same for both and are not computed again.
        """
        if previous is not None and previous.world_key == self.world_key:
            self._tables, self._grid = previous._tables, previous._grid

    def world_nodes(self, t, h, nodes):
        """
        Return :meth:`world_at` at t + c h for each c of ``nodes``, one flat sequence.

        t (s) a step's start, h (s) its length, ``nodes`` the step's distinct nodes (a
        tuple of floats): what the generated stages unpack at a step's start. From the
        world table of (h, nodes) when t is on its grid (module docstring), else node by
        node.
        """
        table = self._tables.get((h, nodes))
        if table is None:
            if len(self._tables) > 8:
                self._tables.clear()
            table = self._tables[h, nodes] = _WorldTable(self, h, nodes)
            if nodes and nodes[0] == 0.0:
                self._grid = table
        row = table.row(t)
        if row is None:
            row = ()
            for c in nodes:
                row += self.world_at(t + c * h)
        return row

    def _sunlight(self, s, r):
        """Return (s_x, s_y, s_z, P): the unit direction to the Sun from r (m) and P (N/m^2)."""
        sun = self.sun.position(s)
        dx, dy, dz = sun[0] - r[0], sun[1] - r[1], sun[2] - r[2]
        d = math.sqrt(dx * dx + dy * dy + dz * dz)
        light = sunlit_fraction(r, sun, self.planet_radius, self.shadow)
        return (dx / d, dy / d, dz / d, SOLAR_PRESSURE_1AU * (AU / d) ** 2 * light)

    def surroundings(self, t, q):
        """Fill and return the :class:`Surroundings` at integrator time t (s) and attitude q."""
        env = self.env
        if self._position:
            world = self.world_at(t)
            env.r_world = world[:3]
            env.r_body = _to_body(*q, env.r_world)
            if self._field:
                env.b_world = world[self._at_b:self._at_b + 3]
                env.b_body = _to_body(*q, env.b_world)
            if self._sun:
                env.s_world, env.pressure = world[self._at_s:self._at_s + 3], world[self._at_s + 3]
                env.s_body = _to_body(*q, env.s_world)
            if self._flow:
                env.f_world, env.density = world[self._at_f:self._at_f + 3], world[self._at_f + 3]
                env.f_body = _to_body(*q, env.f_world)
        return env

    def __call__(self, t, qx, qy, qz, qw, wx=0.0, wy=0.0, wz=0.0):
        """Return the summed torque (N m, principal frame) at integrator time t (s)."""
        if self._compiled is not None:
            return self._compiled(self, t, qx, qy, qz, qw, wx, wy, wz)
        args = (t, qx, qy, qz, qw, wx, wy, wz)
        last, torque = self._last
        if args == last:          # (the integrator asks at a step's start, then its stage 0)
            return torque
        torque = self.torque_of_models(t, qx, qy, qz, qw, wx, wy, wz)
        self._last = (args, torque)
        return torque

    def torque_of_models(self, t, qx, qy, qz, qw, wx=0.0, wy=0.0, wz=0.0):
        """
        Return the summed torque (N m, principal) at integrator time t (s), model by model.

        Each model's ``torque()`` at simulated time t + epoch: the definition the stage
        statements are held to.
        """
        q = (qx, qy, qz, qw)
        env = self.surroundings(t, q)
        t, r, omega = t + self.epoch, env.r_world, (wx, wy, wz)
        tx = ty = tz = 0.0
        for model in self.models:
            a, b, c = model.torque(t, r, q, omega, env)
            tx, ty, tz = tx + a, ty + b, tz + c
        return tx, ty, tz


class _WorldTable:
    """
    :meth:`SpaceEnvironment.world_many` at the nodes k h + c h of the steps of length h.

    Computed :data:`WORLD_BLOCK` steps at a time; :meth:`row` is step k's quantities,
    node after node (None off the grid, or where a block could not be computed).
    """

    def __init__(self, environment, h, nodes):
        self.environment, self.h = environment, float(h)
        self.offsets = np.array([c * h for c in nodes])
        self._blocks = {}

    def row(self, t):
        """Return the quantities of the step that starts at t (s) = k h, or None."""
        k = round(t / self.h)
        if k * self.h != t:
            return None
        b = k // WORLD_BLOCK
        block = self._blocks.get(b)
        if block is None:
            block = self._build(b)
        return block[k - b * WORLD_BLOCK] if block else None

    def _build(self, b):
        k0 = b * WORLD_BLOCK
        times = np.arange(k0, k0 + WORLD_BLOCK, dtype=float) * self.h
        try:
            values = self.environment.world_many(
                (times[:, None] + self.offsets[None, :]).ravel())
        except ValueError:          # (node by node, each error at its own time)
            values = None
        if len(self._blocks) > 4:
            self._blocks.clear()
        block = self._blocks[b] = (() if values is None else
                                   values.reshape(WORLD_BLOCK, -1).tolist())
        return block


_COMPILED = {}


def compiled_torque(code):
    """Return the compiled :func:`~.stage_code.torque_source` of a StageCode (cached by key)."""
    function = _COMPILED.get(code.key)
    if function is None:
        function = _COMPILED[code.key] = compile_source(
            torque_source(code), f'<environment torque {len(_COMPILED)}>', {'sqrt': math.sqrt})
    return function


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
    Earth's disc), with ``shadow_model`` (cylindrical or conical: see
    :class:`~rigid_body_dynamics.physics.sensors.base.Sky`). ``facets`` (a
    :class:`~.facets.Facets`, body frame; None = none) is the body's surface, and
    ``solar_pressure`` the torque of the Sun's light on it (needs the orbit, the Sun
    and facets); ``atmosphere`` (e.g. an :class:`~.atmosphere.ExponentialAtmosphere`,
    None = none) and ``drag`` the torque of the air on the facets (needs the orbit, the
    atmosphere and facets).
    """

    body: tuple = _ZERO
    world: tuple = _ZERO
    orbit: object = None
    field: object = None
    gravity_gradient: bool = False
    residual_dipole: tuple = _ZERO
    sun: object = None
    planet_radius: float = R_EARTH
    shadow_model: str = 'cylindrical'
    facets: object = None
    solar_pressure: bool = False
    atmosphere: object = None
    drag: bool = False

    @property
    def active(self):
        """Whether any disturbance torque acts."""
        return bool(any(self.body) or any(self.world) or self.gravity_gradient
                    or any(self.residual_dipole) or self.solar_pressure or self.drag)

    def __str__(self):
        parts = [f'{name} {value}' for name, value in (
            ('body torque', self.body), ('world torque', self.world),
            ('residual dipole', self.residual_dipole)) if any(value)]
        if self.gravity_gradient:
            parts.append('gravity gradient')
        if self.solar_pressure:
            parts.append(f'solar pressure on {len(self.facets)} facets ({self.shadow_model} '
                         'shadow)')
        if self.drag:
            parts.append(f'drag on {len(self.facets)} facets ({self.atmosphere})')
        return ', '.join(parts) or 'none'
