"""
One simulated body, without ROS: integrator, held torque command, watchdog, clip, counters.

``attitude_simulator`` and ``attitude_fleet`` wrap one ``BodySimulation``
per body; everything here is plain Python on the physics layer, so it is
unit-tested on a fake clock (test/test_engine.py). Times: ``now_ns`` is the
steady clock (int ns) the caller passes in, never read here; the simulated
time is an integer step count times dt, and snapshots carry the stamp
``start_ns + int(steps * dt_ns)`` (int ns) their messages will have.

Frames: the body frame is the user's (the inertia's); the state is kept in
the principal frame of the inertia. Torques in N m, body frame, or world frame
for a command given in the world frame (rotated into the body at every RK
stage by the integrator). :class:`Disturbances` are summed into the torque
that is integrated (and reported in snapshots): the constant ones held over
each step, the environment's torque models (gravity gradient, residual
dipole, magnetorquers: :mod:`rigid_body_dynamics.physics.environment`)
evaluated at every RK stage.

Ticks. Every item a body puts out (the state, each sensor's readings) comes every
whole number of steps; one schedule says when (:meth:`BodySimulation.steps_to_tick`,
which the paces read). Sensors are objects on the protocol of
:mod:`rigid_body_dynamics.physics.sensors.base` (``sample(state, t, rng)``), each
with a seeded stream of its own; their readings leave as :class:`SensorSample`.
"""

from dataclasses import dataclass
import math
import threading
from typing import NamedTuple

import numpy as np

from .commands import TorqueCommands
from ..physics.dynamics.plant import Plant
from ..physics.environment import Disturbances
from ..physics.sensors import BodyTruth, Sky, stream_rng

_ZERO = (0.0, 0.0, 0.0)
_NS = 1_000_000_000

#: Counters of torque commands, in the order diagnostics list them.
COUNTS = ('accepted', 'rejected_non_finite', 'rejected_frame', 'clipped', 'force_ignored',
          'stale')
#: Counters of wheel commands (wheel_cmd), in the order diagnostics list them.
WHEEL_COUNTS = ('accepted', 'rejected')
#: Counters of magnetorquer commands (magnetorquer_cmd), in the order diagnostics list them.
DIPOLE_COUNTS = ('accepted', 'rejected_non_finite', 'rejected_frame', 'clipped', 'stale')


@dataclass(frozen=True)
class TorqueCommand:
    """The held command: ``vector`` (N m), body or ``world`` frame, steady receive time (ns)."""

    vector: tuple
    world: bool
    received_ns: int
    principal: object   # the body vector in the principal frame (None for a world command)
    stamp_ns: object = None   # the command's header stamp (int ns), if it has one


class SensorSample(NamedTuple):
    """
    One sensor reading as the body puts it out: ``stamp_ns`` (int ns), ``sensor`` (its name).

    ``reading`` is the sensor's NamedTuple (e.g. a
    :class:`~rigid_body_dynamics.physics.sensors.GyroReading`), in the user's body
    frame or the world frame as that sensor says.
    """

    stamp_ns: int
    sensor: str
    reading: tuple


class WheelState(NamedTuple):
    """
    The reaction wheels at a tick.

    ``speeds`` (rad/s relative to the body), ``angles`` (rad), the motor torques
    ``applied`` over the last step after the limits (N m), and the wheels' angular
    momentum ``momentum_principal`` (kg m^2/s, principal frame).
    """

    speeds: tuple
    angles: tuple
    applied: tuple
    momentum_principal: tuple


class Snapshot(NamedTuple):
    """
    What one publish tick needs, taken under the lock.

    ``stamp_ns`` (int ns: start + simulated time), ``steps``, the state in the
    principal frame of the inertia (the field names say so; ``inertia`` turns it
    into the user's body frame): ``q_principal`` (x, y, z, w, principal -> world),
    ``omega_principal`` (rad/s), the ``torque_principal`` (N m) integrated over the
    step that ended here, and the ``inertia``. A NamedTuple: one is made at every
    publish tick of every body, where a frozen dataclass cost 2-3 us to build.
    """

    stamp_ns: int
    steps: int
    q_principal: tuple
    omega_principal: tuple
    torque_principal: tuple
    inertia: object
    odom_only: bool = False    # lockstep's tick state between publish ticks: odom (and clock, TF)
    wheels: object = None      # a WheelState when the body has reaction wheels
    position: object = None    # (r m, v m/s) in the world frame, with an orbit
    dipole: object = None      # the magnetorquers' dipole (A m^2, body frame) over the last step


#: Up to this many commands are checked one by one in plain Python, more as arrays: numpy's
#: fixed cost (20-30 us) tripled a lockstep tick's command cost (benchmarks/command_path.py).
CHECK_ARRAYS_FROM = 8


class CheckedTorques:
    """
    Torque (or magnetorquer dipole) commands checked at once, for the body to count and hold.

    Made by :meth:`BodySimulation.check`, read by :meth:`BodySimulation.hold`;
    ``kind`` is the commands' ('torque' or 'dipole'), ``limits`` the per-axis
    limits (0 = none).
    Plain data: the clipped vectors, each command's frame, the running counts of
    refused, clipped and force-carrying commands before each index, and the
    newest finite index at or before each. So a flood of N commands costs one
    check of N vectors (as arrays from CHECK_ARRAYS_FROM on), and a slice a few
    integer operations.
    """

    def __init__(self, commands, limits):
        self.kind = commands.kind
        self.received_ns = commands.received_ns
        self.stamps_ns = commands.stamps_ns
        self.world_of = commands.world_of
        check = _check_each if len(commands) < CHECK_ARRAYS_FROM else _check_arrays
        # the clipped vectors; counts of commands before index i that were refused, clipped,
        # carried a force; the newest finite index at or before i
        self.vectors, self.bad, self.over, self.pushed, self.newest = check(commands, limits)

    def __len__(self):
        return len(self.received_ns)


def _check_each(commands, limits):
    """(vectors, bad, over, pushed, newest) of :class:`CheckedTorques`, one by one in Python."""
    vectors, bad, over, pushed, newest = [], [0], [0], [0], []
    forces, last = commands.forces, -1
    limited = any(limits)
    for i, torque in enumerate(commands.torques):
        v = [float(c) for c in torque]
        ok = all(math.isfinite(c) for c in v)
        clip = ok and limited and any(0.0 < top < abs(c) for c, top in zip(v, limits))
        if clip:
            v = [min(max(c, -top), top) if top > 0.0 else c for c, top in zip(v, limits)]
        f = forces[i] if forces is not None else None
        push = ok and f is not None and any(not math.isfinite(c) or c != 0.0 for c in f)
        vectors.append(v)
        bad.append(bad[-1] + (not ok))
        over.append(over[-1] + clip)
        pushed.append(pushed[-1] + push)
        last = i if ok else last
        newest.append(last)
    return vectors, bad, over, pushed, newest


def _check_arrays(commands, limits):
    """As :func:`_check_each`, over (N, 3) arrays at once."""
    v = np.asarray(commands.torques, dtype=float).reshape(-1, 3)
    n = len(v)
    finite = np.all(np.isfinite(v), axis=1)
    if any(limits):
        top = np.array([c if c > 0.0 else np.inf for c in limits])
        over = finite & np.any(np.abs(v) > top, axis=1)
        v = np.clip(v, -top, top)
    else:
        over = np.zeros(n, dtype=bool)
    if commands.forces is not None:
        f = np.asarray(commands.forces, dtype=float).reshape(-1, 3)
        pushed = finite & np.any((f != 0.0) | ~np.isfinite(f), axis=1)
    else:
        pushed = np.zeros(n, dtype=bool)
    bad, over, pushed = ([0] + np.cumsum(mask).tolist() for mask in (~finite, over, pushed))
    newest = np.maximum.accumulate(np.where(finite, np.arange(n), -1)).tolist()
    return v.tolist(), bad, over, pushed, newest


class CheckedWheels:
    """
    Wheel commands checked at once: each valid (``count`` finite numbers) or refused.

    Made by :meth:`BodySimulation.check`, read by :meth:`BodySimulation.hold`: the
    vectors, the running count of refused commands before each index, and the
    newest valid index at or before each.
    """

    kind = 'wheels'

    def __init__(self, commands, count):
        self.received_ns, self.stamps_ns = commands.received_ns, None
        self.vectors, self.bad, self.newest = [], [0], []
        last = -1
        for i, torques in enumerate(commands.torques):
            try:
                v = tuple(float(c) for c in torques)
            except (TypeError, ValueError):
                v = ()
            ok = len(v) == count and all(math.isfinite(c) for c in v)
            self.vectors.append(v)
            self.bad.append(self.bad[-1] + (not ok))
            last = i if ok else last
            self.newest.append(last)

    def __len__(self):
        return len(self.received_ns)


class BodySimulation:
    """
    The state of one simulated body and the rules for changing it.

    ``inertia`` (Inertia), ``integrator`` (a name from INTEGRATORS), ``rate``
    (Hz; dt = 1 / rate), ``initial`` = (q0 x-y-z-w, omega0 rad/s) in the body
    frame, ``torque_timeout`` (s; 0 = hold forever), ``max_torque`` (N m per
    axis; 0 = no limit), ``publish_every`` (steps per publish tick), ``sensors``
    (objects on the sensor protocol, each sampled every round(rate / its rate)
    steps, at least 1) and the ``seed`` of their streams, ``start_ns`` (stamp of
    simulated time 0), ``disturbances``
    (:class:`Disturbances`; None = none), ``wheels`` (a
    :class:`~rigid_body_dynamics.physics.dynamics.gyrostat.Wheels` in the body frame, or None)
    and their ``wheel_speeds`` at the start (rad/s; default 0): with wheels the body is
    a gyrostat and its motor torques are commands of their own (``WheelCommands``),
    held and timed out like the torque. ``magnetorquers`` (A m^2 per body axis, 0 =
    no limit; None = no magnetorquers) makes the dipole a command too
    (``DipoleCommands``, body frame, clipped per axis, held and timed out like
    the torque; its torque m x B acts through the environment's field).
    ``sensor_counts`` counts each sensor's readings ('valid') and exclusions
    (by the reason the sensor gives) since the start. ``notes`` collects what a node should
    log (the watchdog's timeouts, lockstep's misses), drained with
    :meth:`take_notes`; ``events`` the command events since the last
    :meth:`take_events` (for the node's warnings).

    Commands come as values (:mod:`.commands`) through :meth:`check` and
    :meth:`hold`, the one path a pace uses in every mode; :meth:`command` is
    that path for a single torque. Only the body writes its fields.

    ``lock`` (re-entrant) guards the state. The methods other threads call take it
    themselves: :meth:`reset`, :meth:`set_paused`, :meth:`configure`,
    :meth:`check`, :meth:`hold`, :meth:`command`, :meth:`reject`, :meth:`note`,
    :meth:`take_notes`, :meth:`take_events`, :meth:`health`, :meth:`sensor_health`. The
    stepping methods
    are called by the one thread that holds it for a whole wake (the engine's
    Pace or Lockstep) and say "call under ``lock``": :meth:`advance`,
    :meth:`advance_free`, :meth:`torque_now`, :meth:`first_items`,
    :meth:`snapshot`, :meth:`invariants`, :meth:`body_state`.
    """

    def __init__(self, inertia, integrator, rate, initial, torque_timeout=0.5, max_torque=0.0,
                 publish_every=1, start_ns=0, sensors=(), seed=0,
                 disturbances=None, wheels=None, wheel_speeds=None, magnetorquers=None):
        self.lock = threading.RLock()
        self.rate = float(rate)
        self.dt = 1.0 / self.rate
        self.dt_ns = _NS / self.rate
        self.start_ns = int(start_ns)
        self.inertia = inertia
        self.integrator_name = integrator
        self.initial = initial
        self.timeout_ns = int(torque_timeout * _NS)
        self.max_torque = float(max_torque)
        self.publish_every = int(publish_every)
        self.seed = int(seed)
        self.disturbances = disturbances or Disturbances()
        d = self.disturbances
        self.sky = Sky(d.field, d.sun, d.planet_radius, d.shadow_model)
        # (steps per reading, sensor): a sensor between two steps samples at the nearer one
        self.sensors = [(max(1, round(self.rate / sensor.rate)), sensor) for sensor in sensors]
        self.sensor_counts = {sensor.name: {'valid': 0} for _, sensor in self.sensors}
        self.wheels = wheels if wheels is not None and wheels.count else None
        n = self.wheels.count if self.wheels is not None else 0
        self.wheel_speeds0 = tuple(float(v) for v in wheel_speeds) if wheel_speeds else (0.0,) * n
        self._no_motors = (0.0,) * n
        self._wheel_friction = self.wheels is not None and bool(
            any(self.wheels.coulomb) or any(self.wheels.viscous))
        self.wheel_counts = dict.fromkeys(WHEEL_COUNTS, 0)
        self.counts = dict.fromkeys(COUNTS, 0)
        self.max_dipole = None if magnetorquers is None else tuple(float(c) for c in magnetorquers)
        self.dipole_counts = dict.fromkeys(DIPOLE_COUNTS, 0)
        self.notes = []
        self.events = set()
        self._schedule = self._make_schedule()
        self.reset()

    # ------------------------------------------------------------------ state
    def reset(self):
        """Back to the initial state at simulated time 0, no command, not paused."""
        with self.lock:
            q0, w0 = self.initial
            self.plant = Plant(self.inertia, self.integrator_name, self.dt, q0, w0,
                               self.disturbances, self.wheels, self.wheel_speeds0)
            self.paused = False
            self.command_held = None
            self.timed_out = False
            self.wheel_held = None
            self.wheel_timed_out = False
            self.dipole_held = None          # (body vector, received_ns, stamp_ns)
            self.dipole_timed_out = False
            self._motors_given = None        # the motor torques the stepper holds
            # the same seeds: the same streams after a reset
            self._streams = []
            for every, sensor in self.sensors:
                rng = stream_rng(self.seed, sensor.stream)
                sensor.start(rng, self.rate / every)
                self._streams.append(rng)
            self._baseline()

    @property
    def stepper(self):
        """Return the integrator of the body's plant (its state in the principal frame)."""
        return self.plant.stepper

    @property
    def steps(self):
        """Return the steps since simulated time 0."""
        return self.plant.steps

    @property
    def _dipole_given(self):
        """Return the dipole (A m^2, body frame) the environment holds."""
        return self.plant.dipole

    def _baseline(self):
        """Remember T and L_w now: drift is reported since the last torque or change."""
        self.base = self.invariants()
        self._base_stale = False

    def invariants(self):
        """(T in J, L_w in kg m^2/s, world frame) of the current state (call under ``lock``)."""
        s = self.stepper
        return s.kinetic_energy, s.angular_momentum_world

    def body_state(self):
        """
        (q (x, y, z, w), omega (rad/s)) in the user's body frame, as float sequences.

        Call under ``lock``.
        """
        return self.plant.body_state()

    def restart(self, time=True, state=True):
        """
        Go back to simulated time 0 and/or the initial state; keeps paused or not.

        Both: as :meth:`reset` (commands dropped, sensor streams from their
        seeds). ``state`` alone: the initial attitude, angular velocity and
        wheel speeds at the current time (commands and streams kept). ``time``
        alone: the current state at time 0 (the environment's clock restarts).
        """
        with self.lock:
            paused = self.paused
            if time and state:
                self.reset()
            elif state or time:
                s = self.stepper
                if state:
                    (q, omega), speeds, angles = self.initial, self.wheel_speeds0, None
                else:
                    (q, omega) = self.body_state()
                    speeds, angles = getattr(s, 'speeds', None), getattr(s, 'angles', None)
                self.plant.restart(q, omega, speeds, angles, steps=0 if time else None)
                self._motors_given = None            # the new stepper holds none yet
                self._baseline()
            self.paused = paused

    def set_state(self, q, omega):
        """
        Set the attitude q (x, y, z, w, unit) and angular velocity omega (rad/s), body frame.

        At the current simulated time; the wheels keep their speeds and angles.
        """
        with self.lock:
            s = self.stepper
            self.plant.restart(q, omega, getattr(s, 'speeds', None), getattr(s, 'angles', None))
            self._motors_given = None
            self._baseline()

    def set_paused(self, paused):
        """Freeze (True) or resume (False); returns whether it was paused before."""
        with self.lock:
            was, self.paused = self.paused, bool(paused)
            return was

    # ------------------------------------------------------------------ configuration
    def configure(self, inertia=None, integrator=None, initial=None, torque_timeout=None,
                  max_torque=None, publish_every=None, disturbances=None):
        """
        Take validated settings into effect; returns lines saying what changed.

        A new inertia keeps the body-frame attitude and angular velocity; a new
        integrator continues from the current state; both restart the drift
        baseline and keep the held command (re-expressed in the new frame).
        """
        lines = []
        with self.lock:
            if initial is not None:
                self.initial = initial
            if torque_timeout is not None:
                self.timeout_ns = int(torque_timeout * _NS)
            if max_torque is not None:
                self.max_torque = float(max_torque)
            if publish_every is not None:
                self.publish_every = int(publish_every)
                self._schedule = self._make_schedule()
            if disturbances is not None and disturbances != self.disturbances:
                self.disturbances = d = disturbances
                self.sky = Sky(d.field, d.sun, d.planet_radius, d.shadow_model)
                self.plant.set_disturbances(d)
                self._base_stale = True
                lines.append(f'disturbances now {disturbances}')
            rebuild = False
            if inertia is not None and inertia is not self.inertia:
                self.inertia = inertia
                rebuild = True
                lines.append(f'inertia now {inertia.moments.tolist()} kg m^2 ({inertia.kind}); '
                             'attitude and angular velocity kept')
            if integrator is not None and integrator != self.integrator_name:
                self.integrator_name = integrator
                rebuild = True
                lines.append(f'integrator now {integrator}, continuing from the current state')
            if rebuild:
                self.plant.rebuild(self.inertia, self.integrator_name)
                self._motors_given = None            # the new stepper holds none yet
                self._baseline()
                cmd = self.command_held
                if cmd is not None:
                    self.command_held = self._make_command(cmd.vector, cmd.world,
                                                           cmd.received_ns, cmd.stamp_ns)
        return lines

    # ------------------------------------------------------------------ torque
    def _make_command(self, vector, world, received_ns, stamp_ns=None):
        # (no numpy: a flood makes 1000 a second; the plant's frame, as simulate() turns one)
        principal = None if world else self.plant.principal(vector)
        return TorqueCommand(tuple(vector), world, received_ns, principal, stamp_ns)

    def check(self, commands):
        """
        Check a command value at once (e.g. TorqueCommands): a value for :meth:`hold`.

        Takes the lock (the limits read are the current ones).
        """
        with self.lock:
            if commands.kind == 'torque':
                return CheckedTorques(commands, (self.max_torque,) * 3)
            if commands.kind == 'dipole':
                if self.max_dipole is None:
                    raise ValueError('this body has no magnetorquers')
                return CheckedTorques(commands, self.max_dipole)
            if commands.kind == 'wheels':
                return CheckedWheels(commands, self.wheels.count if self.wheels else 0)
            raise ValueError(f'unknown kind of command {commands.kind!r}')

    def hold(self, checked, start, stop):
        """
        Take commands ``start:stop`` of ``checked`` (from :meth:`check`) as having arrived.

        They are counted as they would be one after the other (non-finite refused,
        components beyond ``max_torque`` clipped, forces ignored), and the newest
        finite one is held from now on, with the receive time of command
        ``stop - 1``. Returns the set of events, which are also kept for
        :meth:`take_events`. Takes the lock.
        """
        if checked.kind == 'wheels':
            return self._hold_wheels(checked, start, stop)
        events = set()
        dipole = checked.kind == 'dipole'     # (events of the dipole say so: 'dipole_clipped')
        counts, prefix = (self.dipole_counts, 'dipole_') if dipole else (self.counts, '')
        with self.lock:
            bad = checked.bad[stop] - checked.bad[start]
            if bad:
                counts['rejected_non_finite'] += bad
                events.add(prefix + 'rejected_non_finite')
            good = stop - start - bad
            if good:
                over = checked.over[stop] - checked.over[start]
                if over:
                    counts['clipped'] += over
                    events.add(prefix + 'clipped')
                pushed = checked.pushed[stop] - checked.pushed[start]
                if pushed:
                    counts['force_ignored'] += pushed
                    events.add('force_ignored')
                counts['accepted'] += good
                events.add(prefix + 'accepted')
                i = checked.newest[stop - 1]
                stamp = None if checked.stamps_ns is None else checked.stamps_ns[i]
                if dipole:
                    self.dipole_held = (tuple(checked.vectors[i]), checked.received_ns[stop - 1],
                                        stamp)
                else:
                    self.command_held = self._make_command(
                        tuple(checked.vectors[i]), checked.world_of(i),
                        checked.received_ns[stop - 1], stamp)
            self.events |= events
        return events

    def _hold_wheels(self, checked, start, stop):
        """Count wheel commands start:stop and hold the newest valid one (see hold)."""
        events = set()
        with self.lock:
            bad = checked.bad[stop] - checked.bad[start]
            if bad:
                self.wheel_counts['rejected'] += bad
                events.add('wheel_rejected')
            if stop - start - bad:
                self.wheel_counts['accepted'] += stop - start - bad
                events.add('wheel_accepted')
                self.wheel_held = (checked.vectors[checked.newest[stop - 1]],
                                   checked.received_ns[stop - 1])
            self.events |= events
        return events

    def motor_torques_now(self, now_ns):
        """
        Return the held motor torques (N m) for the next step, zero once timed out.

        The wheels' watchdog, as :meth:`torque_now` for the torque (the same
        ``torque_timeout``; a note says so once). Call under ``lock``.
        """
        held = self.wheel_held
        if held is None or not self._in_force(
                held[1], now_ns, 'wheel_timed_out',
                'wheel command timed out: motor torques are zero until the next wheel_cmd'):
            return self._no_motors
        return held[0]

    def dipole_now(self, now_ns):
        """
        Return the held magnetorquer dipole (A m^2, body frame) for the next step, or zero.

        Its watchdog is the torque's (``torque_timeout``; a note says so once).
        Call under ``lock``.
        """
        held = self.dipole_held
        if held is None or not self._in_force(
                held[1], now_ns, 'dipole_timed_out',
                'magnetorquer command timed out: the dipole is zero until the next '
                'magnetorquer_cmd'):
            return _ZERO
        return held[0]

    def held_stamp(self, kind):
        """Return the header stamp (int ns or None) of the held command of ``kind``."""
        if kind == 'torque':
            return None if self.command_held is None else self.command_held.stamp_ns
        if kind == 'dipole':
            return None if self.dipole_held is None else self.dipole_held[2]
        return None

    def _in_force(self, received_ns, now_ns, flag, note):
        """
        Tell whether a command received at ``received_ns`` is still held: the watchdog.

        Of the torque and of the motors: False once ``torque_timeout`` has passed
        since ``received_ns``; the attribute ``flag`` says so, and ``note`` is
        logged once per timeout. Call under ``lock``.
        """
        if self.timeout_ns and now_ns - received_ns > self.timeout_ns:
            if not getattr(self, flag):
                setattr(self, flag, True)
                self.notes.append(note)
            return False
        setattr(self, flag, False)
        return True

    def command(self, vector, world, now_ns, force=_ZERO, stamp_ns=None):
        """
        Hold one torque now: N m in the body frame, or in the world frame if ``world``.

        The same path as a pace's (:meth:`check`, then :meth:`hold`), for one
        command received at ``now_ns`` (steady int ns) and stamped ``stamp_ns``
        (int ns or None). Returns the set of events ('accepted', 'clipped',
        'force_ignored', or 'rejected_non_finite' with the state untouched).
        """
        one = TorqueCommands.one(vector, world, now_ns, stamp_ns, force)
        return self.hold(self.check(one), 0, 1)

    def reject(self, reason, count=1, kind='torque'):
        """
        Count ``count`` commands of ``kind`` refused before they were held; also an event.

        E.g. 'rejected_frame' (the decoder) or 'stale' (lockstep); a dipole
        command's event is prefixed with ``dipole_``. Takes the lock.
        """
        with self.lock:
            if kind == 'dipole':
                self.dipole_counts[reason] += count
                self.events.add('dipole_' + reason)
            else:
                self.counts[reason] += count
                self.events.add(reason)

    def note(self, text):
        """Add a line for the node's log (:meth:`take_notes`). Takes the lock."""
        with self.lock:
            self.notes.append(text)

    def take_events(self):
        """Return and forget the set of command events since the last call (for warnings)."""
        with self.lock:
            events, self.events = self.events, set()
        return events

    def torque_now(self, now_ns):
        """
        Torque for the next step: (principal-frame part, world-frame part or None).

        Also the watchdog: zero once ``torque_timeout`` has passed since the
        command arrived, and a note says so once per timeout; so it is called
        for that alone where a step does not ask for the torque (call under
        ``lock``).
        """
        cmd = self.command_held
        if cmd is None or not self._in_force(
                cmd.received_ns, now_ns, 'timed_out',
                'torque command timed out: torque is zero until the next command'):
            return _ZERO, None
        if cmd.world:
            return _ZERO, cmd.vector
        return cmd.principal, None

    def take_notes(self):
        """Return and forget the notes for the log."""
        with self.lock:
            notes, self.notes = self.notes, []
        return notes

    # ------------------------------------------------------------------ stepping
    def advance(self, now_ns, outbox):
        """One integration step (call under ``lock``); a publish tick's snapshot goes to outbox."""
        torque, torque_world = self.torque_now(now_ns)
        plant = self.plant
        if self.max_dipole is not None:
            dipole = self.dipole_now(now_ns)
            if dipole is not plant.dipole:      # (a new command, or its timeout)
                plant.set_dipole(dipole)
        torqued = (plant.disturbed or torque_world is not None or torque[0] or torque[1]
                   or torque[2])
        if self.wheels is not None:
            motors = self.motor_torques_now(now_ns)
            if motors is not self._motors_given:     # (checked once, when it was held)
                plant.command_motors(motors)
                self._motors_given = motors
            # motor torques and friction change T (not H): no free-motion drift baseline
            torqued = torqued or self._wheel_friction or any(motors)
        if self._base_stale and not torqued:
            self._baseline()          # the state after the last step under torque
        plant.step(torque, torque_world)
        self._base_stale = self._base_stale or bool(torqued)
        self._ticks(outbox)

    def _make_schedule(self):
        """Return the ticks: (steps per item, the method that takes it or None), state first."""
        schedule = [(self.publish_every, self.snapshot)]
        for index, (every, _) in enumerate(self.sensors):
            schedule.append((every, lambda index=index: self.read_sensor(index)))
        return schedule

    def every(self, name):
        """Return the steps between two readings of the sensor called ``name`` (0 = none)."""
        return next((every for every, sensor in self.sensors if sensor.name == name), 0)

    @property
    def shortest_tick(self):
        """Return the fewest steps between two items of the schedule."""
        return min(every for every, _ in self._schedule)

    def steps_to_tick(self):
        """Return the steps from now to the next item of the schedule (1 .. shortest_tick)."""
        steps = self.steps
        return min(every - steps % every for every, _ in self._schedule)

    def _ticks(self, outbox):
        """Put the items due at the current step (state, sensor samples) in ``outbox``."""
        steps = self.steps
        for every, take in self._schedule:
            if steps % every == 0:
                item = take()
                if item is not None:
                    outbox.append(item)

    def advance_free(self, count, now_ns, outbox):
        """
        Advance ``count`` steps at once if no torque acts on them (call under ``lock``).

        Returns False, and does nothing, unless the steps are torque-free
        whatever their time: no disturbance, and no command or one the
        watchdog has already dropped at ``now_ns`` (the first step's time). Then
        the integrator counts them in one go (the exact flow evaluates nothing
        until read) and the ticks among them go to ``outbox``: the same state
        and items as ``count`` calls of :meth:`advance`.
        """
        if self.plant.disturbed or self.wheels is not None:
            return False
        if self.command_held is not None:
            self.torque_now(now_ns)            # the watchdog, as the first step would ask it
            if not self.timed_out:
                return False
        if self.dipole_held is not None and any(self.dipole_now(now_ns)):
            return False
        if self._base_stale:
            self._baseline()                   # the state after the last step under torque
        while count > 0:
            run = min(self.steps_to_tick(), count)
            self.plant.free_steps(run)
            count -= run
            self._ticks(outbox)
        return True

    def first_items(self):
        """Return the items of time 0 (call under ``lock``): the state and sensor samples."""
        items = (take() for _, take in self._schedule)
        return [item for item in items if item is not None]

    def truth(self):
        """Return the :class:`~rigid_body_dynamics.physics.sensors.BodyTruth` now (under lock)."""
        q, omega = self.body_state()
        orbit = self.disturbances.orbit
        r = None if orbit is None else orbit.position(self.steps * self.dt)
        return BodyTruth(tuple(q), tuple(omega), r, self.sky)

    def read_sensor(self, index):
        """
        Read sensor ``index`` at the current state (call under ``lock``).

        Returns a :class:`SensorSample`, or None when the sensor gives a reason
        instead of a reading (counted under that reason).
        """
        sensor = self.sensors[index][1]
        reading = sensor.sample(self.truth(), self.steps * self.dt, self._streams[index])
        counts = self.sensor_counts[sensor.name]
        if isinstance(reading, str):
            counts[reading] = counts.get(reading, 0) + 1
            return None
        counts['valid'] += 1
        return SensorSample(self.stamp_now(), sensor.name, reading)

    def sensor_health(self):
        """Return each sensor's counts of readings and exclusions since the start (a copy)."""
        with self.lock:
            return {name: dict(counts) for name, counts in self.sensor_counts.items()}

    def stamp_now(self):
        """Return the stamp (int ns) of the current simulated time."""
        return self.start_ns + int(self.steps * self.dt_ns)

    @property
    def last_torque(self):
        """Principal-frame body torque (N m) of the last step, as reported (zero before one)."""
        return self.plant.last_torque

    def snapshot(self, odom_only=False):
        """Take the current :class:`Snapshot` (call under ``lock``)."""
        s = self.stepper
        wheels = None if self.wheels is None else WheelState(
            s.speeds, s.angles, s.applied, s.wheel_momentum_body)
        orbit = self.disturbances.orbit
        return Snapshot(self.stamp_now(), self.steps, s.q, s.omega,
                        self.last_torque, self.inertia, odom_only, wheels,
                        None if orbit is None else orbit.state(self.steps * self.dt),
                        None if self.max_dipole is None else self._dipole_given)

    # ------------------------------------------------------------------ diagnostics
    def health(self):
        """
        Numbers for diagnostics, read under the lock.

        Returns a dict: steps, simulated time (s), quaternion norm error,
        energy / |L| drift (rel.) and L direction drift (rad) since the last
        torque or change, work since reset (J), the held command (or None),
        timed_out, paused and a copy of the counters.
        """
        with self.lock:
            s = self.stepper
            # under torque the baseline is the state after the latest torque step: this one
            t0, l0 = self.invariants() if self._base_stale else self.base
            t1, l1 = self.invariants()
            g0 = math.sqrt(sum(c * c for c in l0))
            g1 = math.sqrt(sum(c * c for c in l1))
            return {
                'steps': self.steps, 'time': self.steps * self.dt,
                'quaternion norm error': abs(math.sqrt(sum(c * c for c in s.q)) - 1.0),
                'energy drift': abs(t1 - t0) / t0 if t0 else 0.0,
                'momentum drift': abs(g1 - g0) / g0 if g0 else 0.0,
                'direction drift': math.atan2(float(np.linalg.norm(np.cross(l0, l1))),
                                              float(np.dot(l0, l1))),
                'work': s.work, 'command': self.command_held, 'timed_out': self.timed_out,
                'paused': self.paused, 'counts': dict(self.counts),
                'wheels': None if self.wheels is None else self._wheel_health(),
                'magnetorquers': None if self.max_dipole is None else {
                    'dipole': self._dipole_given, 'command': self.dipole_held,
                    'timed_out': self.dipole_timed_out, 'counts': dict(self.dipole_counts)}}

    def _wheel_health(self):
        """Return the wheels' numbers for diagnostics (call under ``lock``)."""
        s, w = self.stepper, self.wheels
        return {'speeds': s.speeds,
                'speed fractions': tuple(abs(v) / top if top else 0.0
                                         for v, top in zip(s.speeds, w.max_speed)),
                'applied': s.applied, 'clipped': tuple(s.clipped), 'cut off': tuple(s.cut),
                'command': self.wheel_held, 'timed_out': self.wheel_timed_out,
                'counts': dict(self.wheel_counts), 'motor work': s.motor_work,
                'friction loss': s.friction_loss}
