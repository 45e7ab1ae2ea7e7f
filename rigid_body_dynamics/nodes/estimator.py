"""
attitude_estimator: an example attitude estimator (a multiplicative EKF) for the sensors.

It fuses the gyro (``imu``'s angular velocity) with the ``star_tracker`` and,
where they publish, the ``sun_sensor`` and the magnetometer (``magnetic_field``)
against the Sun and field models it is configured with
(:class:`~rigid_body_dynamics.physics.mekf.MEKF`, ROS-free). Its noise
parameters have the simulator's sensor parameter names, so one parameters file
with a ``/**`` section configures both, and a node section can detune the
estimator. It starts at the first star tracker reading.

Messages are taken in stamp order, not arrival order: every reading waits until
a gyro sample with a later stamp has come, so the estimate at a stamp is
published one gyro sample later (the stamp is the state's, not the arrival's).
A reading older than the estimate it would correct is dropped and counted.
The Sun and field models need stamps in simulated time (the simulator's
``publish_clock: true``): the Sun moves with ``epoch`` plus the stamp, and the
field with the Earth's rotation and the orbit (``orbit_elements`` or ``orbit_tle``). The
magnetometer's bias is not estimated.

Publishes ``attitude_estimate`` (geometry_msgs/PoseWithCovarianceStamped,
``world_frame``: the orientation and its covariance about the world's fixed
axes; the position is not estimated: 0, variance 1e12 m^2) and
``~/gyro_bias_estimate`` (geometry_msgs/Vector3Stamped, rad/s, ``body_frame``)
at every gyro stamp, and a ``filter`` status on /diagnostics.
"""

import heapq
import math
import sys

from diagnostic_msgs.msg import DiagnosticArray, DiagnosticStatus
from geometry_msgs.msg import PoseWithCovarianceStamped, Vector3Stamped
import numpy as np
from rclpy.node import Node
from rclpy.qos_overriding_options import QoSOverridingOptions
from sensor_msgs.msg import Imu, MagneticField

from .environment_parameters import environment_params, field_from, orbit_from
from .sensor_parameters import sensor_params, sun_from
from .simulator_parameters import PARAMETERS as SIMULATOR
from ..physics import quaternions as quat
from ..physics.mekf_fusion import MekfFusion
from ..ros import conversions as conv
from ..ros.parameters import ConfigurationError, Param, ParameterTable
from ..ros.runner import run
from ..ros.state_publisher import STATE_QOS, UNMEASURED

NODE_NAME = 'attitude_estimator'
#: Order of the kinds of message at one stamp: the gyro first (propagate), then the updates.
_GYRO, _UPDATE = 0, 1


def _models(values, out):
    """Cross-check: the orbit, the Sun and the field the vector readings are compared with."""
    out['orbit'] = orbit_from(out)
    out['sun'] = sun_from(out, out['orbit'])
    out['field'] = field_from(out, out['orbit'])
    q = out['star_tracker_orientation']
    norm = math.sqrt(sum(c * c for c in q))
    if abs(norm - 1.0) > 1e-6:
        raise ConfigurationError('star_tracker_orientation must be a unit quaternion (x, y, z, '
                                 f'w), got {list(q)}')
    if any(not (0.0 <= c <= 1.0) for c in out['star_tracker_noise']):
        raise ConfigurationError('star_tracker_noise must be in [0, 1] rad per axis, got '
                                 f'{list(out["star_tracker_noise"])}')
    mount = quat.matrix(tuple(c / norm for c in q))
    noise = np.diag([max(c, 1e-12) ** 2 for c in out['star_tracker_noise']])
    out['tracker_covariance'] = mount @ noise @ mount.T        # body frame


def _simulator(name):
    return SIMULATOR.params[name]


#: The parameters of attitude_estimator (the manual's table is made from this; test_docs checks).
PARAMETERS = ParameterTable([
    _simulator('world_frame'), _simulator('body_frame'),
    _simulator('gyro_noise_density'), _simulator('gyro_bias_random_walk'),
    _simulator('gyro_turn_on_bias'),
    *sensor_params('epoch', 'sun_direction', 'star_tracker_noise', 'star_tracker_orientation',
                   'sun_sensor_noise'),
    *environment_params('orbit_elements', 'orbit_tle', 'orbit_zonal_degree',
                        'orbit_ballistic_coefficient', 'atmosphere_model', 'solar_flux_f107',
                        'solar_flux_f107a', 'geomagnetic_ap', 'orbit_mu',
                        'planet_radius', 'magnetic_field_model', 'magnetic_field_degree',
                        'magnetic_dipole_coefficients', 'earth_rotation_angle',
                        'earth_rotation_rate', 'magnetometer_noise'),
    Param('initial_bias_sigma', 'double', 0.0, '0.0 rad/s',
          'The bias estimate starts at 0 with this 1 sigma per axis; 0 = gyro_turn_on_bias.',
          low=0.0, high=1.0, read_only=True),
], cross_checks=(_models,))


def fusion_from(values):
    """Return the MekfFusion of attitude_estimator's validated ``values`` (PARAMETERS)."""
    v = values
    return MekfFusion(
        v['gyro_noise_density'], v['gyro_bias_random_walk'], v['tracker_covariance'],
        v['initial_bias_sigma'] or v['gyro_turn_on_bias'], sun=v['sun'],
        sun_noise=v['sun_sensor_noise'], field=v['field'], orbit=v['orbit'],
        magnetometer_noise=v['magnetometer_noise'])


#: A gyro interval longer than this times the shortest one seen is a gap: readings lost.
GAP = 1.5
#: Diagnostic value names of the counters that are not messages used.
NAMES = {'late': 'late readings dropped', 'gyro gaps': 'gyro gaps (readings missing)',
         'restarts': 'restarts'}


class AttitudeEstimator(Node):
    """The attitude_estimator node; ``kwargs`` go to rclpy's Node."""

    def __init__(self, **kwargs):
        super().__init__(NODE_NAME, **kwargs)
        v = self._values = PARAMETERS.validate(PARAMETERS.declare(self))
        self._world, self._body = v['world_frame'], v['body_frame']
        self.fusion = fusion_from(v)
        self._pending = []            # heap of (stamp ns, kind order, sequence, kind, data)
        self._sequence = 0
        # the fusion counts the readings it takes; the node counts gaps and restarts
        self._node_counts = {'gyro gaps': 0, 'restarts': 0}
        self._restart()
        self._pub = self.create_publisher(PoseWithCovarianceStamped, 'attitude_estimate',
                                          STATE_QOS)
        self._pub_bias = self.create_publisher(Vector3Stamped, '~/gyro_bias_estimate',
                                               STATE_QOS)
        self._pub_diag = self.create_publisher(DiagnosticArray, '/diagnostics', 10)
        # reliable (as the simulator publishes), or as qos_overrides.<topic>.subscription say
        qos = {'qos_overriding_options': QoSOverridingOptions.with_default_policies()}
        self.create_subscription(Imu, 'imu', self._on_imu, STATE_QOS, **qos)
        for msg_type, topic, kind in ((PoseWithCovarianceStamped, 'star_tracker', 'star_tracker'),
                                      (Vector3Stamped, 'sun_sensor', 'sun_sensor'),
                                      (MagneticField, 'magnetic_field', 'magnetometer')):
            self.create_subscription(msg_type, topic, lambda m, kind=kind: self._queue(m, kind),
                                     STATE_QOS, **qos)
        self.create_timer(1.0, self._diagnose)
        estimate = PoseWithCovarianceStamped()
        estimate.header.frame_id = self._world
        self._estimate = estimate
        self.get_logger().info(
            f'MEKF: gyro N = {v["gyro_noise_density"]:g} rad/s/sqrt(Hz), K = '
            f'{v["gyro_bias_random_walk"]:g} rad/s^2/sqrt(Hz); star tracker noise '
            f'{list(v["star_tracker_noise"])} rad; waiting for the first star_tracker reading')

    def _restart(self):
        """Forget the estimate (at start, and when the stamps go back: a simulator reset)."""
        self.fusion.restart()
        self._newest = None
        # the shortest interval between gyro stamps seen (ns): a reset simulator may sample
        # at another rate
        self._gyro_interval = None

    @property
    def counts(self):
        """Return the counts: readings used per kind, gyro samples, late, gaps, restarts."""
        return {**self.fusion.counts, **self._node_counts}

    # ---------------------------------------------------------------- intake
    def _queue(self, msg, kind):
        stamp = conv.time_ns(msg.header.stamp)
        heapq.heappush(self._pending, (stamp, _UPDATE, self._sequence, kind, msg))
        self._sequence += 1

    def _on_imu(self, msg):
        stamp = conv.time_ns(msg.header.stamp)
        if self._newest is not None and stamp < self._newest:
            self._node_counts['restarts'] += 1
            self.get_logger().info('the gyro stamps went back (a reset): the estimate restarts')
            # what is still pending at or after the last gyro stamp came from the run before
            # the reset; what came since, stamped before this sample, is too early to use
            newest = self._newest
            self._restart()
            self._pending = [p for p in self._pending if stamp <= p[0] < newest]
            heapq.heapify(self._pending)
        self._newest = stamp
        w = msg.angular_velocity
        heapq.heappush(self._pending, (stamp, _GYRO, self._sequence, 'gyro', (w.x, w.y, w.z)))
        self._sequence += 1
        self._process(before=stamp)

    def _process(self, before):
        """Take every pending message stamped before ``before`` (ns), in stamp order."""
        moved = False
        while self._pending and self._pending[0][0] < before:
            stamp, _, _, kind, data = heapq.heappop(self._pending)
            if kind == 'gyro':
                moved = self._propagate(stamp, np.array(data)) or moved
            else:
                moved = self._update(stamp, kind, data) or moved
        if moved and self.fusion.started:
            self._publish()

    def _propagate(self, stamp, omega):
        """Propagate to a gyro sample's stamp with the previous sample's rate (held)."""
        last = self.fusion.last_gyro
        if last is not None and stamp > last[0]:
            self._check_gap(stamp - last[0])
        return self.fusion.gyro(stamp, omega)

    def _check_gap(self, interval):
        """Count (and warn of) a gyro interval over GAP times the shortest seen (ns)."""
        shortest = self._gyro_interval = min(interval, self._gyro_interval or interval)
        if interval > GAP * shortest:
            self._node_counts['gyro gaps'] += 1
            self.get_logger().warning(
                f'gyro readings missing: {interval * 1e-6:.3g} ms between two where '
                f'{shortest * 1e-6:.3g} ms is usual ({self._node_counts["gyro gaps"]} gaps so '
                'far); the estimate holds the rate across them and is worse than it says (a busy '
                'machine? a deeper queue: qos_overrides./imu.subscription.depth)',
                throttle_duration_sec=5.0)

    def _update(self, stamp, kind, msg):
        """Correct with one reading at its stamp (after propagating to it); False if not used."""
        if kind == 'star_tracker':
            o = msg.pose.pose.orientation
            value = (o.x, o.y, o.z, o.w)
        elif kind == 'sun_sensor':
            s = msg.vector
            value = (s.x, s.y, s.z)
        else:
            b = msg.magnetic_field
            value = (b.x, b.y, b.z)
        started = self.fusion.started
        if not self.fusion.reading(stamp, kind, value):
            return False
        if not started:
            self.get_logger().info(
                f'started at {stamp * 1e-9:.3f} s from the star tracker; bias 1 sigma '
                f'{self.fusion.bias_sigma:g} rad/s, magnetometer noise '
                f'{self._values["magnetometer_noise"]:g} T')
        return True

    # ---------------------------------------------------------------- output
    def _publish(self):
        f, msg = self.fusion.filter, self._estimate
        msg.header.stamp = conv.time_msg(self.fusion.time)
        msg.pose.pose.orientation = conv.quaternion_msg(f.q)
        cov = np.zeros((6, 6))
        cov[:3, :3] = np.eye(3) * UNMEASURED
        cov[3:, 3:] = f.attitude_covariance_world()
        msg.pose.covariance = cov.ravel().tolist()
        self._pub.publish(msg)
        bias = Vector3Stamped()
        bias.header.stamp, bias.header.frame_id = msg.header.stamp, self._body
        bias.vector = conv.vector_msg(f.bias)
        self._pub_bias.publish(bias)

    def _diagnose(self):
        f = self.fusion.filter
        if f.started:
            sigma = np.sqrt(np.diag(f.P))
            level, message = DiagnosticStatus.OK, (
                f'estimating: attitude 1 sigma {float(np.linalg.norm(sigma[:3])):.3g} rad')
            values = [('attitude sigma (rad, body axes)', sigma[:3].tolist()),
                      ('bias sigma (rad/s)', sigma[3:].tolist()),
                      ('bias estimate (rad/s)', f.bias.tolist())]
        else:
            level, message = DiagnosticStatus.OK, 'waiting for the first star_tracker reading'
            values = []
        values += [(NAMES.get(kind, f'{kind} messages used'), n)
                   for kind, n in self.counts.items()]
        array = DiagnosticArray(status=[conv.status(
            f'{self.get_name()}: filter', level, message, values,
            self.get_fully_qualified_name())])
        array.header.stamp = self.get_clock().now().to_msg()
        self._pub_diag.publish(array)


def main(args=None, early=None):
    """Run until Ctrl-C / SIGTERM; exit 0, or 1 on bad configuration (see runner.run)."""
    return run(AttitudeEstimator, NODE_NAME, args, early=early)


if __name__ == '__main__':
    from .entry import exiting
    sys.exit(exiting(main()))
