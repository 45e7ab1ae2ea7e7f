"""
Commands as values: what a node decodes from its messages and the engine takes, without ROS.

There is one path for a command, whatever the pacing (real time, as fast as
possible, lockstep, a fleet's bodies):

1. a decoder (the node's, :mod:`rigid_body_dynamics.ros.command_decoder`) turns the
   messages taken from a topic into one value, e.g. :class:`TorqueCommands`: N
   commands, oldest first, each with its steady-clock receive time;
2. the pace (:class:`~.pacer.Pace` or :class:`~.lockstep.Lockstep`) takes the values
   from its ``inbox()`` at every wake and has the body check each at once
   (:meth:`~.body.BodySimulation.check`);
3. it hands the body the commands that came by each step's deadline
   (:meth:`~.body.BodySimulation.hold`), which counts them and holds the newest.

A new kind of command is a new value class (with ``kind``, ``received_ns``,
``stamps_ns``, ``__len__``, and ``select`` if it has stamps) and its decoder, and
the body's rule for it; the paces do not change. :class:`WheelCommands`
(reaction-wheel motor torques) and :class:`DipoleCommands` (magnetorquers) were
added that way. :class:`Mailbox` is an inbox
for code without ROS (tests, a Python controller in the same process).
"""

import threading


class TorqueCommands:
    """
    N torque commands, oldest first (kind ``'torque'``).

    ``received_ns``: steady-clock receive times (int ns, non-decreasing);
    ``torques`` (N, 3) array-like, N m, each in the body frame or, where ``world``
    is true, in the world frame (``world``: one bool for all, or N); ``stamps_ns``:
    the messages' header stamps (int ns) or None; ``forces`` (N, 3) array-like, N,
    or None (a non-zero force is ignored and counted: the body does not translate).
    Non-finite values are kept: the body refuses and counts them. Nothing is
    copied or converted here (a controller's one command per tick stays cheap);
    the body's check reads the values.
    """

    kind = 'torque'
    __slots__ = ('received_ns', 'torques', 'world', 'stamps_ns', 'forces')

    def __init__(self, received_ns, torques, world=False, stamps_ns=None, forces=None):
        self.received_ns = received_ns
        self.torques = torques
        self.world = world
        self.stamps_ns = stamps_ns
        self.forces = forces
        n = len(received_ns)
        if len(torques) != n or (forces is not None and len(forces) != n) or \
                (stamps_ns is not None and len(stamps_ns) != n):
            raise ValueError(f'{n} receive times, {len(torques)} torques: lengths differ')

    @classmethod
    def one(cls, torque, world, received_ns, stamp_ns=None, force=None):
        """Return a single command: ``torque`` (3,) N m, body or ``world`` frame."""
        return cls((int(received_ns),), (torque,), bool(world),
                   None if stamp_ns is None else (int(stamp_ns),),
                   None if force is None else (force,))

    def __len__(self):
        return len(self.received_ns)

    def world_of(self, i):
        """Return whether command ``i`` is in the world frame."""
        return bool(self.world if isinstance(self.world, bool) else self.world[i])

    def select(self, keep):
        """Return the commands where the boolean sequence ``keep`` is true, in order."""
        index = [i for i, k in enumerate(keep) if k]

        def pick(values):
            return None if values is None else [values[i] for i in index]
        world = self.world if isinstance(self.world, bool) else pick(self.world)
        return TorqueCommands(pick(self.received_ns), pick(self.torques), world,
                              pick(self.stamps_ns), pick(self.forces))


class DipoleCommands(TorqueCommands):
    """
    N magnetorquer commands, oldest first (kind ``'dipole'``): dipoles (A m^2, body frame).

    As :class:`TorqueCommands` in the body frame without forces: ``received_ns``,
    ``torques`` (here the (N, 3) dipoles), ``stamps_ns``. The body clips each axis
    to its ``magnetorquer_max_dipole`` and refuses non-finite ones.
    """

    kind = 'dipole'
    __slots__ = ()

    def __init__(self, received_ns, dipoles, stamps_ns=None):
        super().__init__(received_ns, dipoles, False, stamps_ns)

    @classmethod
    def one(cls, dipole, received_ns, stamp_ns=None):
        """Return a single command: ``dipole`` (3,) A m^2, body frame."""
        return cls((int(received_ns),), (dipole,), None if stamp_ns is None else (int(stamp_ns),))

    def select(self, keep):
        """Return the commands where the boolean sequence ``keep`` is true, in order."""
        index = [i for i, k in enumerate(keep) if k]
        return DipoleCommands([self.received_ns[i] for i in index],
                              [self.torques[i] for i in index],
                              None if self.stamps_ns is None else
                              [self.stamps_ns[i] for i in index])


class Mailbox:
    """
    A thread-safe inbox of command values for a pace, without ROS.

    :meth:`put` from any thread; the pace takes them with :meth:`take` (its
    ``inbox``) and, in lockstep, blocks in :meth:`wait` (its ``wait``).
    """

    def __init__(self):
        self._lock = threading.Lock()
        self._items = []
        self._arrived = threading.Event()

    def put(self, commands):
        """Queue one command value (e.g. :class:`TorqueCommands`)."""
        with self._lock:
            self._items.append(commands)
            self._arrived.set()

    def take(self):
        """Return the queued values, oldest first, and forget them."""
        with self._lock:
            items, self._items = self._items, []
            self._arrived.clear()
        return items

    def wait(self, timeout):
        """Block until something is queued or ``timeout`` s pass; whether something is."""
        return self._arrived.wait(timeout)


class WheelCommands:
    """
    N reaction-wheel commands, oldest first (kind ``'wheels'``): motor torques, N m.

    ``received_ns``: steady-clock receive times (int ns, non-decreasing);
    ``torques``: N sequences, each meant to hold one motor torque per wheel (a
    wrong length or a non-finite value is refused and counted by the body). No
    stamps (std_msgs/Float64MultiArray has no header), so nothing is ever
    dropped as stale and no ``select`` is needed.
    """

    kind = 'wheels'
    stamps_ns = None
    __slots__ = ('received_ns', 'torques')

    def __init__(self, received_ns, torques):
        self.received_ns = received_ns
        self.torques = torques
        if len(torques) != len(received_ns):
            raise ValueError(f'{len(received_ns)} receive times, {len(torques)} commands: '
                             'lengths differ')

    @classmethod
    def one(cls, torques, received_ns):
        """Return a single command: ``torques`` (n motor torques, N m)."""
        return cls((int(received_ns),), (tuple(torques),))

    def __len__(self):
        return len(self.received_ns)
