"""
Closed loops without ROS on the engine's one stepping core (what the node runs, offline).

:func:`detumble` flies B-dot (:class:`~rigid_body_dynamics.physics.control.BDot`) on a
:class:`~.body.BodySimulation` with a magnetometer and magnetorquers: at every
magnetometer sample the law's dipole is held from that sample's time on, as
attitude_controller's ``bdot`` mode answers ``magnetic_field`` with
``magnetorquer_cmd`` in lockstep.
"""

import math

from .commands import DipoleCommands


def detumble(body, law, duration, target_rate=math.radians(0.5)):
    """
    Fly ``law`` (BDot) on ``body`` for ``duration`` s; return what happened.

    ``body``: a BodySimulation with magnetorquers and a magnetometer (its
    readings are the control period). Returns a dict: the
    sample ``times`` (s), ``rates`` |omega| (rad/s), ``omegas`` (rad/s) and
    ``attitudes`` (x, y, z, w, body -> world) in the user's body frame, and
    ``dipoles`` (A m^2, body) at each, and ``reached`` the first time (s)
    |omega| <= ``target_rate`` (rad/s),
    or None.
    """
    every = body.every('magnetometer')
    if not every or body.max_dipole is None:
        raise ValueError('detumble needs a body with magnetorquers and a magnetometer')
    times, rates, dipoles, omegas, attitudes, reached = [], [], [], [], [], None
    with body.lock:
        items = body.first_items()
        for _ in range(int(round(duration / (every * body.dt)))):
            for item in items:
                if getattr(item, 'sensor', None) == 'magnetometer':
                    t = item.stamp_ns * 1e-9
                    m = law.dipole(t, item.reading.field)
                    body.hold(body.check(DipoleCommands.one(m, 0, item.stamp_ns)), 0, 1)
                    w = body.stepper.omega
                    rate = math.sqrt(w[0] * w[0] + w[1] * w[1] + w[2] * w[2])
                    times.append(t)
                    rates.append(rate)
                    dipoles.append(m)
                    q, omega = body.body_state()
                    attitudes.append(tuple(q))
                    omegas.append(tuple(omega))
                    if reached is None and rate <= target_rate:
                        reached = t
            items = []
            for _ in range(every):
                body.advance(0, items)
    return {'times': times, 'rates': rates, 'dipoles': dipoles, 'omegas': omegas,
            'attitudes': attitudes, 'reached': reached}
