"""
ROS 2's standard simulator interface (simulation_interfaces) for one simulated body.

The services and the action of the ROS Simulation Working Group's
``simulation_interfaces`` (Jazzy, 1.5), under the relative names Gazebo's
``gz_simulation_interfaces`` gives them, so that they live in the simulator's
namespace (``/sat1/step_simulation`` for ``-r __ns:=/sat1``, per body in a
fleet): ``get_simulator_features``, ``get_simulation_state``,
``set_simulation_state``, ``reset_simulation``, ``step_simulation``, the action
``simulate_steps``, ``get_entities``, ``get_entity_state`` and
``set_entity_state``.

What they mean here:

- States: STOPPED is paused at the initial state and time 0; PLAYING runs (at
  the real-time factor, or in lockstep with the controller); PAUSED is frozen.
  The simulator starts PLAYING, as it always has. STOPPED -> PAUSED,
  PLAYING, PAUSED -> PLAYING, STOPPED, PLAYING -> PAUSED, STOPPED; the target
  state again is ALREADY_IN_TARGET_STATE; QUITTING, NO_WORLD and
  LOADING_WORLD are FEATURE_UNSUPPORTED.
- ResetSimulation: SCOPE_TIME (the current state at time 0), SCOPE_STATE (the
  initial state at the current time), both, or SCOPE_DEFAULT / SCOPE_ALL (as
  ``~/reset``: time 0, the initial state, no command, the sensors' streams from
  their seeds); SCOPE_SPAWNED does nothing (nothing is spawned). Playing or
  paused stays as it was (a stopped simulator reset by state alone is paused).
- StepSimulation and SimulateSteps advance exactly N integration steps (of
  ``integration_rate``) while paused or stopped, the commands that came held as
  a run holds them, and publish what those steps publish; then the simulation
  is PAUSED. While playing they are refused with RESULT_OPERATION_FAILED, the
  code StepSimulation.srv names (SimulateSteps.action names OPERATION_FAILED
  too). The action's feedback comes after every step; a cancel is taken
  between steps.
- The one entity is the body, named by its body frame (with ``frame_prefix``).
  Its EntityState is in ``world_frame``: pose = attitude (and, with an orbit,
  the position), twist = angular velocity (and orbital velocity) in the world
  frame, acceleration = the angular acceleration of Euler's equations under the
  last step's torque (without wheels; zero with wheels) and, with an orbit, the
  two-body gravity. SetEntityState sets the attitude and angular velocity
  (world frame; ``header.frame_id`` empty or ``world_frame``); a quaternion that
  is not finite and non-zero is INVALID_POSE; a position or linear velocity
  other than zero or the current one is refused (the orbit sets them).

Everything runs in the node's executor; the action yields to it between steps.
"""

import math
import re

import numpy as np
from rclpy.action import ActionServer, CancelResponse, GoalResponse
from rclpy.task import Future

from .conversions import quaternion_array, quaternion_msg, time_msg, vector_array, vector_msg
from ..physics.quaternions import matrix

try:
    from simulation_interfaces import action as sim_action, msg as sim_msg, srv as sim_srv
except ImportError:     # a venv where it was not built (./dev builds it; a ROS install has it)
    sim_action = sim_msg = sim_srv = None

#: A position or linear velocity this close to the current one (m, m/s) is "unchanged".
KEEP_TOLERANCE = 1e-3


_said = []


def available():
    """Whether simulation_interfaces can be imported here."""
    return sim_srv is not None


def say_unavailable(logger):
    """Log, once per process, that the standard simulator interface is not offered."""
    if not _said:
        _said.append(True)
        logger.info('simulation_interfaces is not importable here (./dev builds it into its '
                    'venv; a ROS install has it from apt), so the standard simulator services '
                    '(get_simulator_features, step_simulation, ...) are not offered; ~/reset '
                    'and ~/pause are')


class SimulatorInterface:
    """
    The standard simulator services and action of one body on ``node``.

    ``body`` (the engine's BodySimulation), ``pace`` (its Pace or Lockstep),
    ``publish`` (the node's StatePublisher.publish), ``frames`` = (world, body)
    frame ids (the body frame is the entity's name), ``log`` a logger.
    """

    def __init__(self, node, body, pace, publish, frames, log):
        self.node, self.body, self.pace, self.publish = node, body, pace, publish
        self.world_frame, self.entity = frames
        self.log = log
        self.stopped = False
        r = sim_msg.Result
        self.OK, self.FAILED, self.UNSUPPORTED = (r.RESULT_OK, r.RESULT_OPERATION_FAILED,
                                                  r.RESULT_FEATURE_UNSUPPORTED)
        for srv_type, name, callback in (
                (sim_srv.GetSimulatorFeatures, 'get_simulator_features', self._features),
                (sim_srv.GetSimulationState, 'get_simulation_state', self._get_state),
                (sim_srv.SetSimulationState, 'set_simulation_state', self._set_state),
                (sim_srv.ResetSimulation, 'reset_simulation', self._reset),
                (sim_srv.StepSimulation, 'step_simulation', self._step),
                (sim_srv.GetEntities, 'get_entities', self._entities),
                (sim_srv.GetEntityState, 'get_entity_state', self._get_entity),
                (sim_srv.SetEntityState, 'set_entity_state', self._set_entity)):
            node.create_service(srv_type, name, callback)
        self._action = ActionServer(node, sim_action.SimulateSteps, 'simulate_steps',
                                    execute_callback=self._simulate_steps,
                                    goal_callback=lambda goal: GoalResponse.ACCEPT,
                                    cancel_callback=lambda handle: CancelResponse.ACCEPT)

    def destroy(self):
        """Destroy the action server (the services go with the node)."""
        self._action.destroy()

    # ------------------------------------------------------------------ helpers
    def _result(self, result, code, message=''):
        result.result = code
        result.error_message = message
        if code not in (self.OK,) and message:
            self.log.info(message)

    def _emit(self, items):
        for item in items:
            self.publish(item)

    def state_code(self):
        """
        Return the SimulationState code now: STOPPED, PAUSED or PLAYING.

        STOPPED needs the stop to be the last word: paused, and still at step 0 (``~/pause``
        may have resumed and paused it since).
        """
        s = sim_msg.SimulationState
        if not self.body.paused:
            return s.STATE_PLAYING
        return s.STATE_STOPPED if self.stopped and self.body.steps == 0 else s.STATE_PAUSED

    # ------------------------------------------------------------------ simulation
    def _features(self, _request, response):
        f = sim_msg.SimulatorFeatures
        response.features.features = [
            f.ENTITY_STATE_GETTING, f.ENTITY_STATE_SETTING, f.SIMULATION_RESET,
            f.SIMULATION_RESET_TIME, f.SIMULATION_RESET_STATE, f.SIMULATION_STATE_GETTING,
            f.SIMULATION_STATE_SETTING, f.SIMULATION_STATE_PAUSE, f.STEP_SIMULATION_SINGLE,
            f.STEP_SIMULATION_MULTIPLE, f.STEP_SIMULATION_ACTION]
        response.features.custom_info = (
            'rigid_body_dynamics attitude_simulator: one entity, the body (named by its body '
            'frame); a step is one integration step (1 / integration_rate s)')
        return response

    def _get_state(self, _request, response):
        response.state.state = self.state_code()
        self._result(response.result, self.OK)
        return response

    def _set_state(self, request, response):
        s = sim_msg.SimulationState
        want, now = request.state.state, self.state_code()
        if want == now:
            self._result(response.result, response.ALREADY_IN_TARGET_STATE,
                         f'already in state {want}')
            return response
        if want not in (s.STATE_STOPPED, s.STATE_PLAYING, s.STATE_PAUSED):
            self._result(response.result, self.UNSUPPORTED,
                         f'set_simulation_state: state {want} is not supported (stopped, '
                         'playing and paused are)')
            return response
        body = self.body
        with body.lock:
            if want == s.STATE_STOPPED:
                body.reset()
                body.set_paused(True)
                self.pace.restart()
                items = self.pace.first_items()
            else:
                items = []
                body.set_paused(want == s.STATE_PAUSED)
                if want == s.STATE_PLAYING:
                    self.pace.anchor()
            self.stopped = want == s.STATE_STOPPED
            t = body.steps * body.dt
        self._emit(items)
        self.log.info(f'simulation {("stopped", "playing", "paused")[want]} at t = {t:.6g} s')
        self._result(response.result, self.OK)
        return response

    def _reset(self, request, response):
        r = sim_srv.ResetSimulation.Request
        scope = request.scope
        if scope in (r.SCOPE_DEFAULT, r.SCOPE_ALL):
            time, state = True, True
        else:
            time, state = bool(scope & r.SCOPE_TIME), bool(scope & r.SCOPE_STATE)
        body = self.body
        with body.lock:
            if time or state:
                body.restart(time=time, state=state)
            if time:
                self.pace.restart()
                items = self.pace.first_items()
            else:
                self.pace.anchor()
                items = [body.snapshot()]
            self.stopped = self.stopped and time and state
        self._emit(items)
        what = {(True, True): 'time 0 and the initial state', (True, False): 'time 0',
                (False, True): 'the initial state', (False, False): 'nothing to reset'}
        self.log.info(f'reset_simulation: {what[(time, state)]}')
        self._result(response.result, self.OK)
        return response

    def _refuse_stepping(self, result):
        if not self.body.paused:
            self._result(result, self.FAILED, 'stepping needs a paused or stopped simulation '
                         '(set_simulation_state to paused first)')
            return True
        return False

    def step(self, count):
        """Integrate ``count`` steps now (paused) and publish what they publish."""
        outbox = []
        with self.body.lock:
            self.pace.step_paused(count, outbox)
            self.stopped = self.stopped and count == 0
        self._emit(outbox)

    def _step(self, request, response):
        if self._refuse_stepping(response.result):
            return response
        done = 0
        while done < request.steps:                # (in slices: publish as they go)
            run = min(request.steps - done, 1000)
            self.step(run)
            done += run
        self._result(response.result, self.OK)
        return response

    async def _simulate_steps(self, handle):
        goal = handle.request
        result = sim_action.SimulateSteps.Result()
        if self._refuse_stepping(result.result):
            handle.abort()
            return result
        feedback = sim_action.SimulateSteps.Feedback()
        self.stopped = self.stopped and goal.steps == 0
        for done in range(1, goal.steps + 1):
            if handle.is_cancel_requested:
                handle.canceled()
                self._result(result.result, self.OK, f'simulate_steps: canceled after '
                             f'{done - 1} of {goal.steps} steps')
                return result
            if self._refuse_stepping(result.result):   # (set to playing meanwhile)
                handle.abort()
                return result
            self.step(1)
            feedback.completed_steps, feedback.remaining_steps = done, goal.steps - done
            handle.publish_feedback(feedback)
            await self._yield()
        handle.succeed()
        self._result(result.result, self.OK)
        return result

    async def _yield(self):
        """Let the executor run what is ready (a cancel, a service) before going on."""
        future = Future()
        self.node.executor.create_task(future.set_result, None)
        await future

    # ------------------------------------------------------------------ entities
    def _entities(self, request, response):
        f = request.filters
        if f.categories or f.tags.tags or f.bounds.type != sim_msg.Bounds.TYPE_EMPTY:
            self._result(response.result, self.UNSUPPORTED, 'get_entities: only the name '
                         'filter is supported (one entity, the body)')
            return response
        try:
            match = re.search(f.filter, self.entity) if f.filter else True
        except re.error as err:
            self._result(response.result, self.FAILED,
                         f'get_entities: filter {f.filter!r} is not a regular expression: {err}')
            return response
        response.entities = [self.entity] if match else []
        self._result(response.result, self.OK)
        return response

    def _known(self, name, result):
        if name != self.entity:
            self._result(result, sim_msg.Result.RESULT_NOT_FOUND,
                         f'no entity {name!r}: the one entity is {self.entity!r}')
            return False
        return True

    def _get_entity(self, request, response):
        if not self._known(request.entity, response.result):
            return response
        with self.body.lock:
            snap = self.body.snapshot()
            inertia = self.body.inertia
        st = response.state
        st.header.stamp = time_msg(snap.stamp_ns)
        st.header.frame_id = self.world_frame
        q = np.array(snap.q_principal)
        q_body = inertia.attitude_to_body(q)
        rotate = matrix(q)
        st.pose.orientation = quaternion_msg(q_body)
        st.twist.angular = vector_msg(rotate @ np.array(snap.omega_principal))
        if self.body.wheels is None:
            moments = inertia.moments
            w = np.array(snap.omega_principal)
            alpha = (np.array(snap.torque_principal) - np.cross(w, moments * w)) / moments
            st.acceleration.angular = vector_msg(rotate @ alpha)
        if snap.position is not None:
            r, v = snap.position
            st.pose.position.x, st.pose.position.y, st.pose.position.z = (float(c) for c in r)
            st.twist.linear = vector_msg(v)
            mu, norm = self.body.disturbances.orbit.mu, math.sqrt(sum(c * c for c in r))
            st.acceleration.linear = vector_msg([-mu * c / norm ** 3 for c in r])
        self._result(response.result, self.OK)
        return response

    def _set_entity(self, request, response):
        if not self._known(request.entity, response.result):
            return response
        st = request.state
        if st.header.frame_id not in ('', self.world_frame):
            self._result(response.result, self.FAILED, f'set_entity_state: frame_id '
                         f'{st.header.frame_id!r} is not the world frame {self.world_frame!r}')
            return response
        q = quaternion_array(st.pose.orientation)
        norm = float(np.linalg.norm(q))
        if not (math.isfinite(norm) and norm > 0.0):
            self._result(response.result, response.INVALID_POSE, f'set_entity_state: the '
                         f'orientation {q.tolist()} is not a finite non-zero quaternion')
            return response
        omega_world = vector_array(st.twist.angular)
        if not np.all(np.isfinite(omega_world)):
            self._result(response.result, self.FAILED, 'set_entity_state: the angular '
                         f'velocity {omega_world.tolist()} is not finite')
            return response
        position = np.array([st.pose.position.x, st.pose.position.y, st.pose.position.z])
        velocity = vector_array(st.twist.linear)
        with self.body.lock:
            snap = self.body.snapshot()
            here = (np.zeros(3), np.zeros(3)) if snap.position is None else \
                tuple(np.array(c, float) for c in snap.position)
            for asked, current, what in ((position, here[0], 'position'),
                                         (velocity, here[1], 'linear velocity')):
                if np.any(asked) and not np.all(np.abs(asked - current) <= KEEP_TOLERANCE):
                    self._result(response.result, self.FAILED, f'set_entity_state: the '
                                 f'{what} follows the orbit (orbit_elements) and cannot be '
                                 'set; send zeros or the current one')
                    return response
            q = q / norm
            # the body frame's angular velocity: R(q_body)^T omega_world
            omega_body = matrix(q).T @ omega_world
            self.body.set_state(tuple(q), tuple(omega_body))
            self.stopped = False
            snap = self.body.snapshot()
        self._emit([snap])
        self.log.info(f'set_entity_state: attitude {q.tolist()}, angular velocity '
                      f'{omega_world.tolist()} rad/s (world), at t = '
                      f'{snap.steps * self.body.dt:.6g} s')
        self._result(response.result, self.OK)
        return response
