"""
A satellite in orbit over topics: B-dot in lockstep, one YAML for the three nodes.

attitude_simulator, attitude_controller (mode bdot) and attitude_analyzer start as their
own processes on doc/examples/satellite.yaml; the CubeSat detumbles over real topics in
lockstep, and every state equals the offline loop (engine.offline.detumble on the same
engine) bit for bit.
"""

import math
import os

from geometry_msgs.msg import Vector3Stamped
from nav_msgs.msg import Odometry
import numpy as np
from rigid_body_dynamics.engine import BodySimulation, Disturbances
from rigid_body_dynamics.engine.offline import detumble
from rigid_body_dynamics.physics import Inertia
from rigid_body_dynamics.physics.control import BDot
from rigid_body_dynamics.physics.environment import DipoleField, KeplerOrbit
from rigid_body_dynamics.physics.sensors import Magnetometer
from rigid_body_dynamics.ros.conversions import time_ns
from ros_harness import odom_arrays
import yaml

PARAMS = os.path.join(os.path.dirname(__file__), '..', 'doc', 'examples', 'satellite.yaml')


def _offline(seconds):
    """Fly the YAML's CubeSat and B-dot offline on the engine."""
    with open(PARAMS) as f:
        config = yaml.safe_load(f)
    common = config['/**']['ros__parameters']
    sim = config['/**/attitude_simulator']['ros__parameters']
    rate = sim['integration_rate']
    every = round(rate / sim['magnetometer_rate'])
    body = BodySimulation(
        Inertia(common['inertia']), 'exact', rate, ((0.0, 0.0, 0.0, 1.0),
                                                    tuple(sim['initial_angular_velocity'])),
        torque_timeout=0.0, publish_every=every,
        disturbances=Disturbances(orbit=KeplerOrbit(common['orbit_elements']),
                                  field=DipoleField(), gravity_gradient=True),
        magnetorquers=tuple(common['magnetorquer_max_dipole']),
        sensors=[Magnetometer(sim['magnetometer_rate'])])
    gain = config['/**/attitude_controller']['ros__parameters']['bdot_gain']
    return detumble(body, BDot(gain, tuple(common['magnetorquer_max_dipole'])), seconds)


def test_bdot_detumbles_the_cubesat_over_topics_in_lockstep_as_offline(launch, probe):
    """
    Detumble over topics in lockstep, bit for bit the offline loop.

    600 s simulated (600 lockstep ticks of 1 s): |omega| from 10 deg/s well down, the
    dipole the simulator held over each tick (applied_dipole), and the attitude and the
    angular velocity vector at every tick equal to the offline loop's bit for bit.
    """
    seconds = 600
    odom = probe.subscribe(Odometry, 'odom')
    applied = probe.subscribe(Vector3Stamped, 'applied_dipole')
    launch('rigid_body_dynamics.nodes.simulator', '--params-file', PARAMS,
           '-p', 'qos_overrides./odom.publisher.depth:=10000',
           '-p', 'qos_overrides./applied_dipole.publisher.depth:=10000', name='sim')
    probe.wait_for('odom', 1, timeout=30.0)
    probe.spin_until(lambda: probe.node.count_publishers('applied_dipole'), 30.0,
                     'the applied_dipole publisher')
    launch('rigid_body_dynamics.nodes.controller', '--params-file', PARAMS, name='controller')
    launch('rigid_body_dynamics.nodes.analyzer', '--params-file', PARAMS, name='analyzer')
    end = seconds * 10 ** 9
    probe.spin_until(lambda: any(time_ns(m.header.stamp) >= end for m in odom) and any(
        time_ns(m.header.stamp) >= end for m in applied), 120.0, f'{seconds} s of lockstep')
    by_stamp = {time_ns(m.header.stamp): m for m in odom}
    held = {time_ns(m.header.stamp): (m.vector.x, m.vector.y, m.vector.z) for m in applied}
    offline = _offline(seconds)
    for k, t in enumerate(offline['times']):
        stamp = round(t * 1e9)
        _, q, w = odom_arrays([by_stamp[stamp]])
        assert tuple(w[0]) == offline['omegas'][k] and tuple(q[0]) == offline['attitudes'][k], k
        if stamp + 10 ** 9 in held:     # the dipole held over the tick from t on
            assert held[stamp + 10 ** 9] == offline['dipoles'][k], k
    last = by_stamp[end]
    rate = math.degrees(np.linalg.norm(odom_arrays([last])[2][0]))
    assert rate < 5.0, rate
    assert all(k * 10 ** 9 in held for k in range(1, seconds + 1))
