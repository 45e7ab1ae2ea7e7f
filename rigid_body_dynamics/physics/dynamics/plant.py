"""
The one stepping core: a body, its wheels and its environment, advanced one step at a time.

attitude_simulator and attitude_fleet (through the engine's ``BodySimulation``),
:func:`~rigid_body_dynamics.physics.simulate` and
:func:`~rigid_body_dynamics.physics.control.fly_on_wheels` all step a
:class:`Plant`, so a run offline and a run in a node take the same arithmetic
(test/test_simulation.py checks one schedule through both, bit for bit).

What a step integrates: the torque it is given (held over the step), plus the
constant disturbances of :class:`~rigid_body_dynamics.physics.environment.Disturbances`,
plus the environment's torque models (gravity gradient, residual dipole,
magnetorquers), which the integrator evaluates at every stage. With wheels the
body is a gyrostat (:mod:`.gyrostat`) and the motor torques are held until the
next :meth:`Plant.command_motors`.

Frames: the user's body frame is the frame of the ``inertia``; the state is
kept in its principal frame (torques given to :meth:`Plant.step` are
principal-frame, as the integrators take them). Time: ``steps`` counts the
steps since simulated time 0 (a new integrator after a change of inertia or
integrator counts from 0 again; the environment is told the offset).
"""

import numpy as np

from .gyrostat import GyrostatIntegrator
from .integrators import make_integrator
from .. import quaternions
from ..environment.space import Disturbances, SpaceEnvironment
from ..environment.torque_models import (DragTorque, GravityGradient, MagneticDipole,
                                         Magnetorquers, SolarPressureTorque)
from ..quaternions import rotate_components

_ZERO = (0.0, 0.0, 0.0)


class Plant:
    """
    One body stepped: its integrator, its wheels and its environment.

    ``inertia`` (an :class:`~rigid_body_dynamics.physics.Inertia`),
    ``integrator`` (a name from INTEGRATORS), ``dt`` (s), ``q`` (x, y, z, w,
    body -> world) and ``omega`` (rad/s) in the user's body frame,
    ``disturbances`` (:class:`~rigid_body_dynamics.physics.environment.Disturbances`,
    None = none), ``wheels`` (a :class:`~.gyrostat.Wheels` in the body frame, or
    None), ``speeds`` and ``angles`` (rad/s and rad, one per wheel; default 0).

    ``stepper`` is the integrator (its ``q`` and ``omega`` in the principal
    frame, ``work``, ``impulse``; with wheels ``speeds``, ``applied``, ...);
    ``steps`` the steps since simulated time 0; ``dipole`` the magnetorquers'
    dipole in force (A m^2, body frame; set with :meth:`set_dipole`).
    """

    def __init__(self, inertia, integrator, dt, q, omega, disturbances=None, wheels=None,
                 speeds=None, angles=None):
        self.inertia = inertia
        self.integrator = integrator
        self.dt = float(dt)
        self.wheels = wheels if wheels is not None and wheels.count else None
        self.disturbances = disturbances or Disturbances()
        self.dipole = _ZERO
        self.steps = 0
        self.held = (_ZERO, None, None)
        self._make(inertia.attitude_to_principal(np.asarray(q, float)),
                   inertia.to_principal(np.asarray(omega, float)), speeds, angles)

    def _make(self, q_principal, omega_principal, speeds=None, angles=None):
        """Make the stepper of a principal-frame state and set up the environment."""
        self.frame = UserFrame(self.inertia)
        if self.wheels is None:
            self.stepper = make_integrator(self.integrator, self.inertia.moments, self.dt,
                                           q_principal, omega_principal)
        else:
            turn = self.inertia.to_principal
            self.stepper = GyrostatIntegrator(
                self.inertia.moments, self.wheels.turned(lambda g: turn(np.array(g))), self.dt,
                q_principal, omega_principal, speeds,
                method='rk4' if self.integrator == 'rk4' else 'exact')
            if angles is not None:
                self.stepper.angles = tuple(angles)
        self._setup()

    def _setup(self):
        """Set up the disturbances for the current inertia, stepper and dipole."""
        d = self.disturbances
        self.constant_body = self.principal(d.body) if any(d.body) else None
        self.constant_world = tuple(float(c) for c in d.world) if any(d.world) else None
        models = []
        if d.gravity_gradient:
            models.append(GravityGradient(self.inertia.moments, d.orbit.mu))
        if any(d.residual_dipole):
            models.append(MagneticDipole(self.principal(d.residual_dipole)))
        if any(self.dipole):
            magnetorquers = Magnetorquers()
            magnetorquers.set_dipole(self.principal(self.dipole))
            models.append(magnetorquers)
        if d.solar_pressure:
            models.append(SolarPressureTorque(d.facets.turned(self.principal)))
        if d.drag:
            models.append(DragTorque(d.facets.turned(self.principal)))
        # the stepper's time starts at 0 when it is made: the environment is told the offset
        previous = getattr(self, 'field', None)
        self.field = SpaceEnvironment(
            d.orbit, d.field, models, epoch=(self.steps - self.stepper.steps) * self.dt,
            sun=d.sun, shadow=d.shadow_model, planet_radius=d.planet_radius,
            atmosphere=d.atmosphere) \
            if models else None
        if self.field is not None:
            self.field.adopt_world(previous)

    def principal(self, vector):
        """Return a body-frame vector (3 numbers) in the principal frame, a tuple of floats."""
        return self.frame.to_principal(tuple(float(c) for c in vector))

    @property
    def disturbed(self):
        """Whether a torque acts on every step whatever is commanded (disturbances, field)."""
        return (self.constant_body is not None or self.constant_world is not None
                or self.field is not None)

    @property
    def time(self):
        """Return the simulated time since 0 (s): the step count times dt."""
        return self.steps * self.dt

    # ------------------------------------------------------------------ changes
    def set_dipole(self, dipole):
        """Hold the magnetorquers' dipole (A m^2, body frame) from the next step on."""
        self.dipole = dipole
        self._setup()

    def set_disturbances(self, disturbances):
        """Take new :class:`Disturbances` from the next step on."""
        self.disturbances = disturbances
        self._setup()

    def command_motors(self, torques):
        """Hold the wheels' motor torques (N m, one per wheel) from the next step on."""
        self.stepper.command_motors(torques)

    def rebuild(self, inertia=None, integrator=None):
        """
        Take a new inertia and/or integrator, continuing from the current state.

        A new inertia keeps the body-frame attitude and angular velocity (the
        wheels their speeds and angles); the motor torques are not held over
        (command them again).
        """
        old = self.stepper
        q, omega = old.q, old.omega
        if inertia is not None and inertia is not self.inertia:
            q_b, w_b = self.body_state()
            self.inertia = inertia
            q = inertia.attitude_to_principal(np.asarray(q_b, float))
            omega = inertia.to_principal(np.asarray(w_b, float))
        if integrator is not None:
            self.integrator = integrator
        self._make(q, omega, getattr(old, 'speeds', None), getattr(old, 'angles', None))

    def restart(self, q, omega, speeds=None, angles=None, steps=None):
        """
        Start again from a state: ``q`` (x, y, z, w) and ``omega`` (rad/s), body frame.

        ``speeds`` and ``angles``: the wheels' (default 0); ``steps``: the step
        count from which to go on (default: the current one; 0 = simulated time 0).
        Work and impulse count from here; command the motor torques again.
        """
        if steps is not None:
            self.steps = int(steps)
        self.held = (_ZERO, None, None)
        self._make(self.inertia.attitude_to_principal(np.asarray(q, float)),
                   self.inertia.to_principal(np.asarray(omega, float)), speeds, angles)

    # ------------------------------------------------------------------ stepping
    def step(self, torque=_ZERO, torque_world=None):
        """
        Advance one step dt: ``torque`` (N m, principal frame) held over it, plus the rest.

        ``torque_world`` (N m, world frame, or None) is held fixed in the
        world. The constant disturbances are added to them; the environment's
        models act at every stage. A torque that is not three finite numbers
        raises ValueError and leaves the state as it was.
        """
        body = self.constant_body
        if body is not None:
            torque = (torque[0] + body[0], torque[1] + body[1], torque[2] + body[2])
        world = self.constant_world
        if world is not None:
            torque_world = world if torque_world is None else (
                torque_world[0] + world[0], torque_world[1] + world[1],
                torque_world[2] + world[2])
        field = self.field
        self.stepper.step(torque, torque_world, field)
        self.steps += 1
        self.held = (torque, torque_world, field)

    def free_steps(self, count):
        """Advance ``count`` torque-free steps at once (no disturbance may act: see disturbed)."""
        self.stepper.free_steps(count)
        self.steps += count
        self.held = (_ZERO, None, None)

    # ------------------------------------------------------------------ reading
    @property
    def last_torque(self):
        """
        Principal-frame body torque (N m) of the last step, as reported (zero before one).

        The held body part, plus the world part and the field (gravity gradient,
        dipoles) evaluated at the state at the end of the step.
        """
        torque, torque_world, field = self.held
        if torque_world is None and field is None:
            return torque
        s = self.stepper
        q = s.q
        if torque_world is not None:
            w = rotate_components((-q[0], -q[1], -q[2], q[3]), torque_world)
            torque = (torque[0] + w[0], torque[1] + w[1], torque[2] + w[2])
        if field is not None:
            f = field(s.time, *q, *s.omega)
            torque = (torque[0] + f[0], torque[1] + f[1], torque[2] + f[2])
        return torque

    def body_state(self):
        """(q (x, y, z, w), omega (rad/s)) in the user's body frame, as float sequences."""
        s, body = self.stepper, self.inertia
        if body.is_principal_frame:
            return s.q, s.omega
        return body.attitude_to_body(np.array(s.q)), body.to_body(np.array(s.omega))


class UserFrame:
    """
    The user's body frame against the principal frame, for one state at a time.

    What :func:`~rigid_body_dynamics.physics.simulate` does at every step of a
    callable torque: the state into the user's frame (``state``) and the torque
    out of it (``torque_principal``); what a :class:`Plant` does to a body-frame
    command (``to_principal``), so both doors turn a torque the same way.
    Plain Python on tuples: numpy's per-call cost (quaternions.multiply, ``@`` on
    3-vectors) made a body given by a full tensor cost 2.1 times one given by its
    principal moments (benchmarks/RESULTS.md, "simulate() with a callable torque").
    Tested against :class:`~.inertia.Inertia`'s array methods.
    """

    def __init__(self, inertia):
        self.identity = inertia.is_principal_frame
        self.r = tuple(tuple(row) for row in inertia.rotation.tolist())
        x, y, z, w = (float(c) for c in inertia.quaternion)
        self.q_conj = (-x, -y, -z, w)

    def to_body(self, v):
        """Principal-frame components (3,) -> body-frame components, a tuple."""
        if self.identity:
            return tuple(v)
        (a, b, c), (d, e, f), (g, h, i) = self.r
        x, y, z = v
        return (a * x + b * y + c * z, d * x + e * y + f * z, g * x + h * y + i * z)

    def to_principal(self, v):
        """Body-frame components (3,) -> principal-frame components, a tuple."""
        if self.identity:
            return tuple(v)
        (a, b, c), (d, e, f), (g, h, i) = self.r
        x, y, z = v
        return (a * x + d * y + g * z, b * x + e * y + h * z, c * x + f * y + i * z)

    def attitude_to_body(self, q):
        """Attitude of the principal frame (x, y, z, w) -> of the body frame, a tuple."""
        return tuple(q) if self.identity else quaternions.mul_components(q, self.q_conj)

    def state(self, stepper):
        """(q (4,), omega (3,)) of a stepper in the user's body frame, as arrays."""
        return (np.array(self.attitude_to_body(stepper.q)), np.array(self.to_body(stepper.omega)))

    def torque_principal(self, torque_body, t):
        """Return a user's body torque (3 numbers, N m) as a principal-frame tuple (ValueError)."""
        try:
            x, y, z = np.asarray(torque_body, dtype=float).reshape(3).tolist() \
                if not isinstance(torque_body, tuple) else torque_body
            values = (float(x), float(y), float(z))
        except (TypeError, ValueError):
            raise ValueError(f'torque(t={t!r}) must return three numbers (N m), '
                             f'got {torque_body!r}') from None
        return self.to_principal(values)
