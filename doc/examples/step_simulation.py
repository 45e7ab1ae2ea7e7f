"""Stop attitude_simulator, step it 1.5 s exactly, and read the body's state (no ROS CLI)."""
import rclpy
from rclpy.action import ActionClient
from simulation_interfaces.action import SimulateSteps
from simulation_interfaces.msg import Result, SimulationState
from simulation_interfaces.srv import (GetEntities, GetEntityState, SetSimulationState,
                                       StepSimulation)

rclpy.init()
node = rclpy.create_node('stepper')


def call(srv_type, name, request):
    client = node.create_client(srv_type, name)
    if not client.wait_for_service(timeout_sec=10.0):
        raise SystemExit(f'{name}: no such service (is attitude_simulator running?)')
    future = client.call_async(request)
    rclpy.spin_until_future_complete(node, future, timeout_sec=10.0)
    return future.result()


# stopped = paused at simulated time 0 and the initial state
request = SetSimulationState.Request()
request.state.state = SimulationState.STATE_STOPPED
assert call(SetSimulationState, 'set_simulation_state', request).result.result == Result.RESULT_OK
# 1000 integration steps (1 kHz: 1 s), then 500 more with feedback
call(StepSimulation, 'step_simulation', StepSimulation.Request(steps=1000))
action = ActionClient(node, SimulateSteps, 'simulate_steps')
action.wait_for_server(timeout_sec=10.0)
goal = action.send_goal_async(SimulateSteps.Goal(steps=500))
rclpy.spin_until_future_complete(node, goal, timeout_sec=10.0)
done = goal.result().get_result_async()
rclpy.spin_until_future_complete(node, done, timeout_sec=30.0)
# the one entity is the body, named by its body frame
body = call(GetEntities, 'get_entities', GetEntities.Request()).entities[0]
state = call(GetEntityState, 'get_entity_state', GetEntityState.Request(entity=body)).state
t = state.header.stamp.sec + state.header.stamp.nanosec * 1e-9
q, w = state.pose.orientation, state.twist.angular
print(f'{body} at t = {t:.3f} s: q = ({q.x:.9f}, {q.y:.9f}, {q.z:.9f}, {q.w:.9f}), '
      f'omega = ({w.x:.9f}, {w.y:.9f}, {w.z:.9f}) rad/s in {state.header.frame_id}')
node.destroy_node()
rclpy.shutdown()
