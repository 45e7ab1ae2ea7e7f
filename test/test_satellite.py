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
from rigid_body_dynamics.ros.conversions import time_ns
from ros_harness import odom_arrays
from sensor_msgs.msg import MagneticField
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
        magnetometer=(0.0, (0.0, 0.0, 0.0)), magnetometer_every=every)
    gain = config['/**/attitude_controller']['ros__parameters']['bdot_gain']
    return detumble(body, BDot(gain, tuple(common['magnetorquer_max_dipole'])), seconds)


def test_bdot_detumbles_the_cubesat_over_topics_in_lockstep_as_offline(launch, probe):
    """
    Detumble over topics in lockstep, bit for bit the offline loop.

    600 s simulated (600 lockstep ticks of 1 s): |omega| from 10 deg/s well down, the
    magnetometer readings answered by magnetorquer_cmd with their stamps, and q, omega at
    every tick equal to the offline loop's bit for bit.
    """
    seconds = 600
    odom = probe.subscribe(Odometry, 'odom')
    fields = probe.subscribe(MagneticField, 'magnetic_field')
    commands = probe.subscribe(Vector3Stamped, 'magnetorquer_cmd')
    launch('rigid_body_dynamics.nodes.simulator', '--params-file', PARAMS, name='sim')
    probe.wait_for('odom', 1, timeout=30.0)
    launch('rigid_body_dynamics.nodes.controller', '--params-file', PARAMS, name='controller')
    launch('rigid_body_dynamics.nodes.analyzer', '--params-file', PARAMS, name='analyzer')
    probe.spin_until(lambda: any(time_ns(m.header.stamp) >= seconds * 10 ** 9 for m in odom),
                     120.0, f'{seconds} s of lockstep')
    by_stamp = {time_ns(m.header.stamp): m for m in odom}
    offline = _offline(seconds)
    for k, t in enumerate(offline['times']):
        _, q, w = odom_arrays([by_stamp[round(t * 1e9)]])
        assert np.linalg.norm(w[0]) == offline['rates'][k]
    last = by_stamp[seconds * 10 ** 9]
    rate = math.degrees(np.linalg.norm(odom_arrays([last])[2][0]))
    assert rate < 5.0, rate
    answered = {time_ns(m.header.stamp) for m in commands}
    read = {time_ns(m.header.stamp) for m in fields}
    assert {k * 10 ** 9 for k in range(seconds)} <= answered <= read
