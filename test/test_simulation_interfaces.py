"""
ROS 2's standard simulator interface (simulation_interfaces) over real services and the action.

The simulator runs as its own process with ``publish_clock:=true`` (stamps are the
simulated time from 0); a probe in this process calls its services and the
SimulateSteps action as a test harness or scenario runner would. The stepped
states are compared with simulate() (the same stepping core offline) bit for bit.
"""

import math
import os

from action_msgs.msg import GoalStatus
from nav_msgs.msg import Odometry
import numpy as np
import pytest
from rigid_body_dynamics.physics import presets, quaternions, simulate
from rigid_body_dynamics.physics.environment import KeplerOrbit
from rigid_body_dynamics.ros.conversions import quaternion_array, time_ns, vector_array

if os.environ.get('RBD_REQUIRE_SIMULATION_INTERFACES'):
    import simulation_interfaces  # noqa: F401  (CI: ./dev builds it; its absence is a failure)
sim_srv = pytest.importorskip('simulation_interfaces.srv', reason='simulation_interfaces is not '
                              'built in this venv (./dev builds it; cmake and c++ are needed)')
from simulation_interfaces.action import SimulateSteps  # noqa: E402
from simulation_interfaces.msg import Result, SimulationState, SimulatorFeatures  # noqa: E402

SIM = 'rigid_body_dynamics.nodes.simulator'
OMEGA0 = [0.3, 1.5, -0.4]
OK, FAILED = Result.RESULT_OK, Result.RESULT_OPERATION_FAILED


def started(launch, probe, *args, ns=''):
    """
    Launch the simulator with ``args`` and return once its first odom arrived.

    Then it has discovered this probe (its odom reached the probe's reader): a service
    that answers a client it has not discovered yet drops the response (rmw_fastrtps
    waits 100 ms for the match), which beside a CPU hog lost a first call in CI runs.
    """
    launch(SIM, *args, name='sim')
    probe.subscribe(Odometry, f'{ns}/odom')
    probe.wait_for(f'{ns}/odom', 1, timeout=30.0)


def call(probe, name, request, ns=''):
    """Call the simulator's service ``name`` (a simulation_interfaces type) and return it."""
    srv_type = {'get_simulator_features': sim_srv.GetSimulatorFeatures,
                'get_simulation_state': sim_srv.GetSimulationState,
                'set_simulation_state': sim_srv.SetSimulationState,
                'reset_simulation': sim_srv.ResetSimulation,
                'step_simulation': sim_srv.StepSimulation,
                'get_entities': sim_srv.GetEntities,
                'get_entity_state': sim_srv.GetEntityState,
                'set_entity_state': sim_srv.SetEntityState}[name]
    return probe.call(srv_type, f'{ns}/{name}', request or srv_type.Request())


def set_state(probe, state, ns=''):
    """Ask for SimulationState ``state``; return the result code."""
    request = sim_srv.SetSimulationState.Request()
    request.state.state = state
    return call(probe, 'set_simulation_state', request, ns).result.result


def state_of(probe, ns=''):
    """Return the SimulationState code the simulator reports."""
    return call(probe, 'get_simulation_state', None, ns).state.state


def entity(probe, name='base_link', ns=''):
    """Return (stamp ns, q, omega_world, response) of GetEntityState."""
    response = call(probe, 'get_entity_state', sim_srv.GetEntityState.Request(entity=name), ns)
    st = response.state
    return (time_ns(st.header.stamp), quaternion_array(st.pose.orientation),
            vector_array(st.twist.angular), response)


def offline(duration, moments, omega0=OMEGA0, q0=(0.0, 0.0, 0.0, 1.0)):
    """
    (q, omega_world) of simulate() at ``duration`` s, 1 kHz, the exact flow.

    omega is turned into the world frame as the node turns it (R(q) omega), so that the
    comparison is of the states, bit for bit.
    """
    run = simulate(moments, omega0, q0, duration=duration, dt=1e-3)
    q = run.q[-1]
    return q, quaternions.matrix(q) @ run.omega[-1]


def step_action(probe, steps, ns=''):
    """Run the SimulateSteps action; return (goal status, result, feedback messages)."""
    from rclpy.action import ActionClient
    client = ActionClient(probe.node, SimulateSteps, f'{ns}/simulate_steps')
    probe.spin_until(client.server_is_ready, 20.0, 'the simulate_steps action server')
    feedback = []
    sent = client.send_goal_async(SimulateSteps.Goal(steps=steps),
                                  feedback_callback=lambda m: feedback.append(m.feedback))
    probe.spin_until(sent.done, 20.0, 'the goal accepted')
    result = sent.result().get_result_async()
    probe.spin_until(result.done, 60.0, 'the action result')
    # (feedback is a topic of its own: rclpy's client drops what lands after the result)
    client.destroy()
    return result.result().status, result.result().result, feedback


def test_the_simulation_state_machine_and_exact_stepping(launch, probe):
    """
    Features, STOPPED / PLAYING / PAUSED, StepSimulation and SimulateSteps, exact to the bit.

    A run stopped at launch and stepped 1234 steps by the service, then 500 by the action,
    is at t = 1.734 s in the same state as simulate() run free to 1.734 s, bit for bit.
    """
    started(launch, probe, '-p', 'preset:=tennis_racket', '-p', 'publish_clock:=true',
            '-p', f'initial_angular_velocity:={OMEGA0}')
    moments = presets.get('tennis_racket').moments
    features = call(probe, 'get_simulator_features', None).features.features
    f = SimulatorFeatures
    assert set(features) == {f.ENTITY_STATE_GETTING, f.ENTITY_STATE_SETTING, f.SIMULATION_RESET,
                             f.SIMULATION_RESET_TIME, f.SIMULATION_RESET_STATE,
                             f.SIMULATION_STATE_GETTING, f.SIMULATION_STATE_SETTING,
                             f.SIMULATION_STATE_PAUSE, f.STEP_SIMULATION_SINGLE,
                             f.STEP_SIMULATION_MULTIPLE, f.STEP_SIMULATION_ACTION}
    s = SimulationState
    assert state_of(probe) == s.STATE_PLAYING
    refused = call(probe, 'step_simulation', sim_srv.StepSimulation.Request(steps=5)).result
    assert refused.result == FAILED and 'paused' in refused.error_message
    assert set_state(probe, s.STATE_STOPPED) == OK and state_of(probe) == s.STATE_STOPPED
    assert set_state(probe, s.STATE_STOPPED) == \
        sim_srv.SetSimulationState.Response.ALREADY_IN_TARGET_STATE
    assert set_state(probe, s.STATE_QUITTING) == Result.RESULT_FEATURE_UNSUPPORTED
    t0, q0, _w, _ = entity(probe)
    assert t0 == 0 and np.array_equal(q0, [0.0, 0.0, 0.0, 1.0])
    step = call(probe, 'step_simulation', sim_srv.StepSimulation.Request(steps=1234))
    assert step.result.result == OK and state_of(probe) == s.STATE_PAUSED
    t, q, w, _ = entity(probe)
    q_ref, w_ref = offline(1.234, moments)
    assert t == 1_234_000_000
    assert np.array_equal(q, q_ref) and np.array_equal(w, w_ref)
    status, result, feedback = step_action(probe, 500)
    assert status == GoalStatus.STATUS_SUCCEEDED and result.result.result == OK
    done = [m.completed_steps for m in feedback]
    assert len(done) > 100 and done == sorted(set(done)) and done[-1] <= 500
    assert all(m.completed_steps + m.remaining_steps == 500 for m in feedback)
    t, q, w, _ = entity(probe)
    q_ref, w_ref = offline(1.734, moments)
    assert t == 1_734_000_000 and np.array_equal(q, q_ref) and np.array_equal(w, w_ref)
    # paused: time does not move
    probe.spin_for(0.3)
    assert entity(probe)[0] == 1_734_000_000
    # playing again: the action is refused and time moves on
    assert set_state(probe, s.STATE_PLAYING) == OK and state_of(probe) == s.STATE_PLAYING
    status, result, feedback = step_action(probe, 10)
    assert status == GoalStatus.STATUS_ABORTED and result.result.result == FAILED
    assert feedback == []
    probe.spin_until(lambda: entity(probe)[0] > 1_900_000_000, 20.0, 'time to move on')
    # stopped, then resumed and paused again by ~/pause: paused, no longer stopped
    from std_srvs.srv import SetBool
    assert set_state(probe, s.STATE_STOPPED) == OK
    pause = '/attitude_simulator/pause'
    assert probe.call(SetBool, pause, SetBool.Request(data=False)).success
    probe.spin_until(lambda: entity(probe)[0] > 0, 20.0, 'time to move after ~/pause')
    assert probe.call(SetBool, pause, SetBool.Request(data=True)).success
    assert state_of(probe) == s.STATE_PAUSED


def test_resets_by_scope_and_setting_the_entity_state(launch, probe):
    """Reset by the TIME, STATE and ALL scopes; GetEntities; SetEntityState and its refusals."""
    started(launch, probe, '-p', 'publish_clock:=true', '-p',
            f'initial_angular_velocity:={OMEGA0}')
    s = SimulationState
    assert set_state(probe, s.STATE_STOPPED) == OK
    call(probe, 'step_simulation', sim_srv.StepSimulation.Request(steps=700))
    _t, q700, w700, _ = entity(probe)
    r = sim_srv.ResetSimulation.Request
    # time alone: the same state at t = 0
    assert call(probe, 'reset_simulation', r(scope=r.SCOPE_TIME)).result.result == OK
    t, q, w, _ = entity(probe)
    assert t == 0 and np.array_equal(q, q700) and np.allclose(w, w700, rtol=0, atol=1e-15)
    assert state_of(probe) == s.STATE_PAUSED
    call(probe, 'step_simulation', sim_srv.StepSimulation.Request(steps=300))
    # state alone: the initial state at the same time
    assert call(probe, 'reset_simulation', r(scope=r.SCOPE_STATE)).result.result == OK
    t, q, w, _ = entity(probe)
    assert t == 300_000_000 and np.array_equal(q, [0.0, 0.0, 0.0, 1.0])
    np.testing.assert_allclose(w, OMEGA0, rtol=0, atol=1e-15)
    # all: time 0 and the initial state
    call(probe, 'step_simulation', sim_srv.StepSimulation.Request(steps=10))
    assert call(probe, 'reset_simulation', r(scope=r.SCOPE_ALL)).result.result == OK
    t, q, w, _ = entity(probe)
    assert t == 0 and np.array_equal(q, [0.0, 0.0, 0.0, 1.0])
    # the one entity, by name and regular expression
    names = call(probe, 'get_entities', None).entities
    assert names == ['base_link']
    request = sim_srv.GetEntities.Request()
    request.filters.filter = '^base_.*k$'
    assert call(probe, 'get_entities', request).entities == ['base_link']
    request.filters.filter = 'wheel'
    assert call(probe, 'get_entities', request).entities == []
    request.filters.filter = '('
    assert call(probe, 'get_entities', request).result.result == FAILED
    assert entity(probe, 'nothing')[3].result.result == Result.RESULT_NOT_FOUND
    # set: the attitude and the world angular velocity, read back as sent
    target = np.array([0.1, -0.7, 0.2, 0.6])
    target /= np.linalg.norm(target)
    set_request = sim_srv.SetEntityState.Request(entity='base_link')
    o = set_request.state.pose.orientation
    o.x, o.y, o.z, o.w = target.tolist()
    a = set_request.state.twist.angular
    a.x, a.y, a.z = 0.2, -0.1, 0.05
    assert call(probe, 'set_entity_state', set_request).result.result == OK
    t, q, w, _ = entity(probe)
    assert t == 0
    assert quaternions.angle_between(q, target) < 1e-15
    np.testing.assert_allclose(w, [0.2, -0.1, 0.05], rtol=0, atol=1e-15)
    # refusals, each leaving the state as it was
    o.x = o.y = o.z = o.w = 0.0
    bad = call(probe, 'set_entity_state', set_request).result
    assert bad.result == sim_srv.SetEntityState.Response.INVALID_POSE
    o.w = 1.0
    set_request.state.pose.position.x = 5.0
    bad = call(probe, 'set_entity_state', set_request).result
    assert bad.result == FAILED and 'orbit' in bad.error_message
    assert quaternions.angle_between(entity(probe)[1], target) < 1e-15


def test_in_orbit_the_entity_state_carries_the_orbit(launch, probe):
    """In orbit: pose.position and twist.linear are Kepler's, acceleration two-body gravity."""
    elements = [7.0e6, 0.01, 1.7, 0.8, 0.3, 0.2]
    started(launch, probe, '-p', 'publish_clock:=true', '-p', f'orbit_elements:={elements}',
            '-p', 'gravity_gradient:=true')
    assert set_state(probe, SimulationState.STATE_STOPPED) == OK
    call(probe, 'step_simulation', sim_srv.StepSimulation.Request(steps=2500))
    t, _q, _w, response = entity(probe)
    st = response.state
    r, v = KeplerOrbit(elements).state(2.5)
    p = st.pose.position
    assert t == 2_500_000_000 and st.header.frame_id == 'odom'
    np.testing.assert_array_equal([p.x, p.y, p.z], r)
    np.testing.assert_array_equal(vector_array(st.twist.linear), v)
    mu = 3.986004418e14
    np.testing.assert_allclose(vector_array(st.acceleration.linear),
                               -mu * np.asarray(r) / np.linalg.norm(r) ** 3, rtol=1e-15)


def test_each_fleet_body_answers_for_itself(launch, probe):
    """attitude_fleet, told so: each body has the services in its namespace and its own state."""
    launch('rigid_body_dynamics.nodes.fleet', '-p', 'simulation_interfaces:=true', '--',
           '--bodies', '2', name='fleet')
    # both bodies step (each in a worker process of its own) before the first call: a service
    # that answers a client it has not discovered yet drops the response (rmw_fastrtps waits
    # 100 ms for the match), which beside a CPU hog lost one in a CI run
    for ns in ('/body1', '/body2'):
        probe.subscribe(Odometry, f'{ns}/odom')
        probe.wait_for(f'{ns}/odom', 5, timeout=30.0)
    assert call(probe, 'get_entities', None, '/body2').entities == ['body2/base_link']
    assert set_state(probe, SimulationState.STATE_STOPPED, '/body1') == OK
    assert call(probe, 'step_simulation', sim_srv.StepSimulation.Request(steps=100),
                '/body1').result.result == OK
    assert state_of(probe, '/body1') == SimulationState.STATE_PAUSED
    assert state_of(probe, '/body2') == SimulationState.STATE_PLAYING
    t1 = entity(probe, 'body1/base_link', '/body1')[0]
    stamps = [entity(probe, 'body1/base_link', '/body1')[0] for _ in range(3)]
    assert stamps == [t1] * 3
    assert math.isfinite(entity(probe, 'body2/base_link', '/body2')[1][3])


def test_the_step_simulation_example_lands_where_simulate_does(launch):
    """doc/examples/step_simulation.py: stopped, 1500 steps, the state printed is simulate()'s."""
    import subprocess
    import sys
    launch(SIM, '-p', 'publish_clock:=true', name='sim')
    example = os.path.join(os.path.dirname(__file__), '..', 'doc', 'examples',
                           'step_simulation.py')
    out = subprocess.run([sys.executable, example], capture_output=True, text=True,
                         timeout=120, check=True).stdout
    preset = presets.get(presets.DEFAULT)
    q_ref, w_ref = offline(1.5, preset.moments, preset.omega0)
    assert out.startswith('base_link at t = 1.500 s: q = (') and 'odom' in out
    numbers = [float(x) for x in out.replace('(', ' ').replace(')', ' ').replace(',', ' ')
               .split() if x.lstrip('-').replace('.', '').isdigit()]
    np.testing.assert_allclose(numbers[1:5], q_ref, rtol=0, atol=1e-9)
    np.testing.assert_allclose(numbers[5:8], w_ref, rtol=0, atol=1e-9)


def _fill(msg, values):
    """Set a message's fields from a YAML mapping (nested mappings into nested messages)."""
    for key, value in values.items():
        if isinstance(value, dict):
            _fill(getattr(msg, key), value)
        else:
            setattr(msg, key, value)
    return msg


def _manual_commands():
    """Return the how-to's ros2 service call / action send_goal lines, split as a shell would."""
    import re
    import shlex
    page = os.path.join(os.path.dirname(__file__), '..', 'doc', 'howto',
                        'simulation_interfaces.md')
    with open(page) as f:
        blocks = re.findall(r'^```bash\n(.*?)^```', f.read(), re.S | re.M)
    return [shlex.split(line) for block in blocks for line in block.splitlines()
            if line.startswith(('ros2 service call', 'ros2 action send_goal'))]


def test_the_manuals_command_lines_are_answered_as_written(launch, probe):
    """
    The how-to's ros2 service call and action send_goal lines, made through rclpy.

    ros2cli has no wheel, so each line's service or action name, type and YAML request are
    taken as written and sent from the probe: every answer is RESULT_OK (the pause first,
    then the steps, then play), and the simulated time moved by exactly the 200 steps.
    """
    import importlib
    import yaml
    commands = _manual_commands()
    assert [c[3] for c in commands] == ['/set_simulation_state', '/step_simulation',
                                        '/simulate_steps', '/set_simulation_state'], commands
    started(launch, probe, '-p', 'publish_clock:=true')
    stamps = []
    for words in commands:
        kind, name, type_name, request = words[2], words[3], words[4], yaml.safe_load(words[5])
        package, group, leaf = type_name.split('/')
        interface = getattr(importlib.import_module(f'{package}.{group}'), leaf)
        if kind == 'call':
            response = probe.call(interface, name, _fill(interface.Request(), request))
            assert response.result.result == OK, (words, response.result.error_message)
        else:
            assert kind == 'send_goal' and '--feedback' in words[6:]
            status, result, _ = step_action(probe, _fill(interface.Goal(), request).steps)
            assert status == GoalStatus.STATUS_SUCCEEDED and result.result.result == OK, words
        if len(stamps) < 3:                 # paused, then after each stepping command
            stamps.append(entity(probe)[0])
    assert np.diff(stamps).tolist() == [100_000_000, 100_000_000], stamps
    assert call(probe, 'get_simulation_state', None).state.state == SimulationState.STATE_PLAYING
