"""Stop attitude_simulator, step it 1.5 s exactly, and read the body's state (no ROS CLI)."""
import sys

import rclpy
from rclpy.action import ActionClient
from simulation_interfaces.action import SimulateSteps
from simulation_interfaces.msg import Result, SimulationState
from simulation_interfaces.srv import (GetEntities, GetEntityState, SetSimulationState,
                                       StepSimulation)

TIMEOUT = 10.0      # s for each answer

rclpy.init()
node = rclpy.create_node('stepper')
# One client per service, made up front and kept: a new client is a new response reader,
# and a server that answers a reader it has not yet discovered drops the answer.
clients = {name: node.create_client(srv_type, name) for name, srv_type in (
    ('set_simulation_state', SetSimulationState), ('step_simulation', StepSimulation),
    ('get_entities', GetEntities), ('get_entity_state', GetEntityState))}
action = ActionClient(node, SimulateSteps, 'simulate_steps')


def fail(text):
    """End with a one-line error (exit code 1), shutting ROS down first."""
    node.destroy_node()
    rclpy.try_shutdown()
    sys.exit(f'step_simulation.py: {text}')


def wait(future, what, timeout=TIMEOUT):
    """Spin until ``future`` is done; its result, or a one-line error after ``timeout`` s."""
    rclpy.spin_until_future_complete(node, future, timeout_sec=timeout)
    if not future.done() or future.result() is None:
        fail(f'no answer from {what} within {timeout:g} s')
    return future.result()


def call(name, request, tries=1):
    """Call service ``name``; ``tries`` > 1 only for requests that may be asked again."""
    client = clients[name]
    if not client.wait_for_service(timeout_sec=TIMEOUT):
        fail(f'{name}: no such service (is attitude_simulator running?)')
    for _ in range(tries):
        future = client.call_async(request)
        rclpy.spin_until_future_complete(node, future, timeout_sec=TIMEOUT)
        if future.done() and future.result() is not None:
            return future.result()
        client.remove_pending_request(future)
    fail(f'no answer from {name} within {TIMEOUT:g} s ({tries} tries)')


# stopped = paused at simulated time 0 and the initial state (asking twice stops it once)
request = SetSimulationState.Request()
request.state.state = SimulationState.STATE_STOPPED
if call('set_simulation_state', request, tries=3).result.result != Result.RESULT_OK:
    fail('the simulator refused to stop')
# 1000 integration steps (1 kHz: 1 s), then 500 more with feedback
if call('step_simulation', StepSimulation.Request(steps=1000)).result.result != Result.RESULT_OK:
    fail('the simulator refused to step')
if not action.wait_for_server(timeout_sec=TIMEOUT):
    fail('simulate_steps: no such action server')
handle = wait(action.send_goal_async(SimulateSteps.Goal(steps=500)), 'simulate_steps')
if not handle.accepted:
    fail('simulate_steps refused the goal')
wait(handle.get_result_async(), 'simulate_steps (its result)', timeout=30.0)
# the one entity is the body, named by its body frame
body = call('get_entities', GetEntities.Request(), tries=3).entities[0]
state = call('get_entity_state', GetEntityState.Request(entity=body), tries=3).state
t = state.header.stamp.sec + state.header.stamp.nanosec * 1e-9
q, w = state.pose.orientation, state.twist.angular
print(f'{body} at t = {t:.3f} s: q = ({q.x:.9f}, {q.y:.9f}, {q.z:.9f}, {q.w:.9f}), '
      f'omega = ({w.x:.9f}, {w.y:.9f}, {w.z:.9f}) rad/s in {state.header.frame_id}')
node.destroy_node()
rclpy.try_shutdown()
