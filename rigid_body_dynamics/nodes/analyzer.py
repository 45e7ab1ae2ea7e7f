"""
attitude_analyzer: measures what an attitude stream does and checks it against physics.

Works from ``odom`` alone (plus ``applied_torque`` when present), so it can
audit any attitude source. A body with reaction wheels also needs its wheels
(the ``wheel_*`` parameters, as the simulator's) and ``wheel_state``: then the
total H and the energy with the motor work are checked. Inertia comes from the
``inertia`` parameter or else from the latched ``inertia`` topic. Only header
stamps are used, never arrival times: samples are kept sorted by stamp,
duplicates dropped; a stamp more than ``reset_jump`` s before the newest one (a
simulator reset or restart) or a gap longer than ``max_gap`` s restarts the
estimates instead of corrupting them.

Every ``diagnostic_period`` (steady clock) the samples of the last ``window`` s
(by stamp) go to :func:`rigid_body_dynamics.physics.analysis.analyse`, the one
analysis every door shares, and its findings are formatted by
:mod:`.analyzer_diagnostics`. Odometry is read by
:mod:`rigid_body_dynamics.messages.samples` (twist frames honoured; stamps as
integer ns). Free-motion drift is measured from the first sample by stamp of
the current torque-free segment, kept here because the window may have dropped
it. Until there is enough data a measurement is reported as not available,
never as a number.
"""

import bisect
import math
import sys

from diagnostic_msgs.msg import DiagnosticArray, DiagnosticStatus
from geometry_msgs.msg import InertiaStamped, PoseWithCovarianceStamped, Vector3Stamped
from geometry_msgs.msg import WrenchStamped
from nav_msgs.msg import Odometry
import numpy as np
from rclpy.clock import Clock, ClockType
from rclpy.node import Node
from rclpy.qos import DurabilityPolicy, HistoryPolicy, QoSProfile, ReliabilityPolicy
from rclpy.serialization import deserialize_message
from sensor_msgs.msg import JointState
from std_msgs.msg import Float64
from std_srvs.srv import Trigger

from . import analyzer_diagnostics as diagnostics
from .environment_parameters import environment_params
from .wheel_parameters import wheel_params, wheels_from
from ..messages import samples
from ..physics import Inertia
from ..physics.analysis import analyse, estimation, Tolerances, Trajectory
from ..ros import conversions as conv
from ..ros.intake import Intake
from ..ros.parameters import as_vector, ConfigurationError, Param, ParameterTable
from ..ros.runner import run
from ..ros.throttle import ThrottledWarnings

NODE_NAME = 'attitude_analyzer'
#: Samples needed before any rate is estimated.
MIN_SAMPLES = 20
#: Period of the batch intake of odom and applied_torque (s, steady clock). Every executor
#: wake costs ~1 ms here (the wait set of the services and the publishers' QoS events):
#: at 100 Hz odom, 50 ms cost 5.0-6.0 % of a core, 100 ms 4.1-4.7 %. The input queue
#: (1000) holds 100 ms of odom up to 10 kHz; the analysis runs at 1 Hz.
INTAKE_PERIOD = 0.1

INPUT_QOS = QoSProfile(history=HistoryPolicy.KEEP_LAST, depth=1000,
                       reliability=ReliabilityPolicy.BEST_EFFORT)
LATCHED_QOS = QoSProfile(history=HistoryPolicy.KEEP_LAST, depth=1,
                         reliability=ReliabilityPolicy.RELIABLE,
                         durability=DurabilityPolicy.TRANSIENT_LOCAL)

#: The gyro's true bias and its estimate: the simulator's ~/imu_bias and the example
#: estimator's ~/gyro_bias_estimate, as seen from a node in the same namespace (remap them
#: for other nodes).
BIAS_TOPICS = {'true': 'attitude_simulator/imu_bias',
               'estimate': 'attitude_estimator/gyro_bias_estimate'}

#: The keys of the ``input`` status and what they mean (the manual's table is made from this).
INPUT_KEYS = {
    'messages received': 'odom messages taken since the start',
    'rate (Hz)': 'odom messages per second of wall time over the last few periods',
    'restarts after a time reset': 'stamps that jumped back by more than `reset_jump` (a '
                                   'simulator reset): the estimates restarted',
    'restarts after a gap': 'gaps between stamps longer than `max_gap`: the estimates '
                            'restarted',
    'dropped non-finite samples': 'odom samples with a non-finite or zero quaternion or rate',
    'dropped samples in another frame': 'odom samples whose twist is neither in the body frame '
                                        'nor in the world frame',
    'inertia source': '`parameter`, `topic` or `none`',
    'body frame': "the inertia's frame id (`any` until it is known)",
    'samples in the window': 'odom samples the analysis uses',
    'window first stamp (ns)': 'the oldest of them',
    'window last stamp (ns)': 'the newest of them',
    'age of the last message (s)': 'wall time since an odom last arrived; above '
                                   '`stale_timeout` the status is STALE',
}

#: Stamps (ns) before and after any real one: the baseline floor's "no limit" and "not yet".
_ALWAYS, _NEVER = -2 ** 63, 2 ** 63 - 1

OK, WARN, ERROR, STALE = (DiagnosticStatus.OK, DiagnosticStatus.WARN, DiagnosticStatus.ERROR,
                          DiagnosticStatus.STALE)


def _inertia(raw):
    """Convert the inertia parameter: 3 principal moments or 6 tensor elements (kg m^2)."""
    try:
        size = len(raw)
        if size == 3:
            return Inertia(as_vector('inertia', raw, 3))
        return Inertia.from_tensor(as_vector('inertia', raw, 6))
    except (TypeError, ValueError) as err:
        raise ConfigurationError(f'inertia: {err}') from None


def _wheels(values, out):
    """Cross-check: the wheels (out['wheels'], None without), with the reason if refused."""
    out['wheels'] = wheels_from(out)


#: The parameters of attitude_analyzer (the manual's table is made from this; test_docs checks).
PARAMETERS = ParameterTable([
    Param('inertia', 'double[3|6]', None, 'unset',
          'Principal moments [I1, I2, I3] (kg m^2) of the body in its odom child frame, or 6 '
          'tensor elements [Ixx, Iyy, Izz, Ixy, Ixz, Iyz]; unset = from the latched inertia '
          'topic.', convert=_inertia),
    Param('window', 'double', 10.0, '10.0 s', 'Length of the analysed history (s of stamps).',
          low=0.1, high=1e9),
    Param('energy_tolerance', 'double', 1e-6, '1e-6',
          'Relative drift of T in free motion above which conservation is WARN; 100x that is '
          'ERROR.', low=0.0, high=1.0, above_low=True),
    Param('momentum_tolerance', 'double', 1e-6, '1e-6',
          'Relative drift of |L| and of the L direction (rad) in free motion above which '
          'conservation is WARN; 100x that is ERROR.', low=0.0, high=1.0, above_low=True),
    Param('balance_tolerance', 'double', 1e-2, '1e-2',
          'Under torque: relative work-energy and impulse-momentum residual above which '
          'conservation is WARN (100x: ERROR). Sampled torque costs an O(dt) quadrature error '
          'at each torque change, so this is looser than the free-motion tolerances.',
          low=0.0, high=1.0, above_low=True),
    Param('rate_tolerance', 'double', 1e-6, '1e-6',
          'Relative difference between a measured rate or period of the free motion and '
          'theory above which precession is WARN; 100x that is ERROR.', low=0.0, high=1.0,
          above_low=True),
    Param('stale_timeout', 'double', 1.0, '1.0 s',
          'Input is STALE when no odom arrived for this long (s, steady clock).',
          low=0.0, high=1e6),
    Param('reset_jump', 'double', 0.5, '0.5 s',
          'A stamp this much (s) before the newest is a reset: estimates restart.',
          low=0.0, high=1e9),
    Param('max_gap', 'double', 1.0, '1.0 s',
          'A gap between stamps longer than this (s) restarts the estimates.',
          low=0.0, high=1e9),
    Param('diagnostic_period', 'double', 1.0, '1.0 s',
          'Period of the analysis and of /diagnostics (s, steady clock).', low=0.01,
          high=3600.0, read_only=True),
    *wheel_params('wheel_axes', 'wheel_inertia', 'wheel_friction_coulomb',
                  'wheel_friction_viscous'),
    *environment_params('gravity_gradient'),
    Param('libration_tolerance', 'double', 1e-3, '1e-3',
          'With gravity_gradient: relative difference between a measured libration frequency '
          'and the small-angle theory above which the orbit status is WARN (100x: ERROR); '
          'finite amplitudes differ by about the squared angle.', low=0.0, high=1.0,
          above_low=True),
    Param('estimation_confidence', 'double', 0.95, '0.95',
          'Confidence of the mean NEES interval of the estimation status: a consistent '
          'estimator is called overconfident or pessimistic in a share 1 - this of windows '
          '(0.9999 for a test that must not fail by chance).', low=0.5, high=1.0 - 1e-9),
], cross_checks=(_wheels,))


def _insert(stamps, values, t, value):
    """Insert ``value`` stamped ``t`` (ns) into the sorted ``stamps`` and ``values``, once."""
    i = bisect.bisect_left(stamps, t)
    if i < len(stamps) and stamps[i] == t:
        return
    stamps.insert(i, t)
    values.insert(i, value)


class SampleBuffer:
    """
    Attitude samples sorted by stamp (integer ns): q (x, y, z, w), omega (rad/s, body).

    Applied-torque samples (N m, body) are kept beside them. ``add`` returns
    why the history restarted ('reset', 'gap') or None.
    """

    def __init__(self):
        self.clear()

    def clear(self):
        """Forget every sample."""
        self.t, self.q, self.w = [], [], []
        self.torque_t, self.torque = [], []
        self.wheel_t, self.wheel = [], []
        self.orbit_t, self.orbit = [], []
        self.estimate_t, self.estimate = [], []
        self.bias = {'true': {}, 'estimate': {}}      # stamp (ns) -> bias (rad/s, body)

    def add(self, t, q, w, reset_jump, max_gap):
        """Insert one state sample (stamp t, ns) in stamp order; duplicates are dropped."""
        reason = None
        if self.t and t < self.t[-1] - reset_jump:
            reason = 'reset'
        elif self.t and t > self.t[-1] + max_gap:
            reason = 'gap'
        if reason:
            self.clear()
        i = bisect.bisect_left(self.t, t)
        if i < len(self.t) and self.t[i] == t:
            return reason
        self.t.insert(i, t)
        self.q.insert(i, q)
        self.w.insert(i, w)
        return reason

    def add_torque(self, t, torque):
        """Insert one applied-torque sample (stamp t, ns) in stamp order."""
        _insert(self.torque_t, self.torque, t, torque)

    def add_wheels(self, t, speeds, efforts):
        """Insert one wheel_state sample (stamp t, ns): speeds (rad/s), motor torques (N m)."""
        _insert(self.wheel_t, self.wheel, t, (tuple(speeds), tuple(efforts)))

    def add_orbit(self, t, position, velocity):
        """Insert one orbit sample (stamp t, ns): position (m) and velocity (m/s), world."""
        _insert(self.orbit_t, self.orbit, t, (tuple(position), tuple(velocity)))

    def add_estimate(self, t, q, covariance):
        """Insert one attitude estimate (stamp t, ns): q and its covariance (3 x 3, rad^2)."""
        _insert(self.estimate_t, self.estimate, t, (q, covariance))

    def add_bias(self, kind, t, bias):
        """Keep one gyro bias (rad/s, body) stamped t (ns): ``kind`` 'true' or 'estimate'."""
        self.bias[kind][t] = tuple(bias)

    def estimate_arrays(self):
        """
        Return (true q, estimated q, covariances, true bias, bias estimate) at common stamps.

        The attitudes at the stamps both odom and the estimate have; the biases (M, 3)
        at those of the stamps that have both biases too, else None. The inputs are
        best effort: a bias message lost under load leaves out its stamp, not the
        bias finding (the bias error's RMS needs no alignment with the attitudes).
        """
        index = {t: i for i, t in enumerate(self.t)}
        rows = [(t, index[t], e) for t, e in zip(self.estimate_t, self.estimate) if t in index]
        true, estimate = self.bias['true'], self.bias['estimate']
        both = [t for t, _, _ in rows if t in true and t in estimate]
        biases = (np.array([true[t] for t in both]), np.array([estimate[t] for t in both])) \
            if both else (None, None)
        return (np.array([self.q[i] for _, i, _ in rows]).reshape(-1, 4),
                np.array([e[0] for _, _, e in rows]).reshape(-1, 4),
                np.array([e[1] for _, _, e in rows]).reshape(-1, 3, 3)) + biases

    def orbit_arrays(self):
        """Return (position, velocity) (N, 3) at the state stamps, or None unless all have one."""
        found = dict(zip(self.orbit_t, self.orbit))
        rows = [found.get(t) for t in self.t]
        if not rows or any(r is None for r in rows):
            return None
        return np.array([r[0] for r in rows]), np.array([r[1] for r in rows])

    def wheel_arrays(self, count):
        """
        Return (speeds, motor torques) (N, count) at the state stamps, or None.

        The wheel sample at each state stamp; None unless every state sample has
        one of ``count`` wheels (the simulator stamps wheel_state with odom's stamp).
        """
        found = dict(zip(self.wheel_t, self.wheel))
        rows = [found.get(t) for t in self.t]
        if not rows or any(r is None or len(r[0]) != count or len(r[1]) != count
                           for r in rows):
            return None
        return np.array([r[0] for r in rows]), np.array([r[1] for r in rows])

    def first_from(self, t):
        """Return the earliest state sample (t, q, w) with stamp >= t (ns), or None."""
        i = bisect.bisect_left(self.t, t)
        return (self.t[i], self.q[i], self.w[i]) if i < len(self.t) else None

    def trim(self, keep_from):
        """Drop samples older than ``keep_from`` (ns)."""
        i = bisect.bisect_left(self.t, keep_from)
        del self.t[:i], self.q[:i], self.w[:i]
        j = bisect.bisect_left(self.torque_t, keep_from)
        del self.torque_t[:j], self.torque[:j]
        j = bisect.bisect_left(self.wheel_t, keep_from)
        del self.wheel_t[:j], self.wheel[:j]
        j = bisect.bisect_left(self.orbit_t, keep_from)
        del self.orbit_t[:j], self.orbit[:j]
        j = bisect.bisect_left(self.estimate_t, keep_from)
        del self.estimate_t[:j], self.estimate[:j]
        for kind, found in self.bias.items():
            self.bias[kind] = {t: b for t, b in found.items() if t >= keep_from}

    def arrays(self):
        """(t ns int64, q, omega, torque at the state stamps); torque 0 where none is known."""
        t = np.array(self.t, dtype=np.int64)
        tau = np.zeros((t.size, 3))
        if self.torque_t:
            idx = np.searchsorted(np.array(self.torque_t, dtype=np.int64), t, side='right') - 1
            known = idx >= 0
            tau[known] = np.array(self.torque)[idx[known]]
        return t, np.array(self.q), np.array(self.w), tau


class AttitudeAnalyzer(Node):
    """The attitude_analyzer node. ``kwargs`` go to rclpy's Node."""

    def __init__(self, **kwargs):
        super().__init__(NODE_NAME, **kwargs)
        self._warnings = ThrottledWarnings(self.get_logger(), period=5.0)
        self._settings = PARAMETERS.validate(PARAMETERS.declare(self))
        self._inertia_source = 'parameter' if self._settings['inertia'] else None
        self._inertia = self._settings['inertia']
        self._buffer = SampleBuffer()
        self._baseline = None                  # (t ns, q, omega) drift is measured from
        self._baseline_floor = _ALWAYS         # ns: the baseline is a sample at/after this
        self._last_torque = _ALWAYS            # ns: stamp of the newest non-zero torque
        self._body_frame = None                # frame id of the inertia, when known
        self._topic_inertia = (None, None)     # the latched topic's (Inertia, frame id)
        # restarts (a time reset, a gap) and dropped samples (non-finite or zero q, wrong frame)
        self._counts = {'reset': 0, 'gap': 0, 'non_finite': 0, 'wrong_frame': 0}
        self._received = 0
        self._last_arrival = None
        self._rate_window = []
        self.add_on_set_parameters_callback(self._on_set_parameters)
        self.add_post_set_parameters_callback(self._post_set_parameters)

        # odom and applied_torque are taken in batches every INTAKE_PERIOD, not one
        # executor callback per message (a quarter of a core at 1 kHz)
        self._intake = Intake(self)
        self._intake.subscribe(Odometry, 'odom', INPUT_QOS)
        self._intake.subscribe(WrenchStamped, 'applied_torque', INPUT_QOS)
        self._intake.subscribe(JointState, 'wheel_state', INPUT_QOS)
        self._intake.subscribe(PoseWithCovarianceStamped, 'attitude_estimate', INPUT_QOS)
        # the gyro's true bias and an estimate of it, under the default nodes' private names
        self._intake.subscribe(Vector3Stamped, BIAS_TOPICS['true'], INPUT_QOS)
        self._intake.subscribe(Vector3Stamped, BIAS_TOPICS['estimate'], INPUT_QOS)
        self._estimates = 0
        self.create_subscription(InertiaStamped, 'inertia', self._on_inertia, LATCHED_QOS)
        self._pub = {name: self.create_publisher(Float64, name, 10) for name in (
            'precession/body_rate', 'precession/lab_rate', 'kinetic_energy',
            'angular_momentum_norm')}
        self._pub_diag = self.create_publisher(DiagnosticArray, '/diagnostics', 10)
        self.create_service(Trigger, '~/reset_baseline', self._on_reset_baseline)
        self._steady = Clock(clock_type=ClockType.STEADY_TIME)
        self.create_timer(INTAKE_PERIOD, self._drain, clock=self._steady)
        self.create_timer(self._settings['diagnostic_period'], self._analyse, clock=self._steady)
        self.get_logger().info(
            'analysing odom' + (f' with inertia {self._inertia.moments.tolist()} kg m^2'
                                if self._inertia else '; waiting for the inertia topic'))

    # ---------------------------------------------------------------- parameters
    def _on_set_parameters(self, params):
        """Validate only (no side effects); the post-set callback applies."""
        return PARAMETERS.on_set(self, params)

    def _post_set_parameters(self, params):
        settings = PARAMETERS.validate(PARAMETERS.values(self))
        if 'inertia' in {p.name for p in params}:
            if settings['inertia'] is not None:
                self._inertia, self._inertia_source = settings['inertia'], 'parameter'
                self._restart('inertia changed')
            elif self._inertia_source == 'parameter':
                # cleared: back to the latched topic (its last message, if one came)
                self._inertia, self._body_frame = self._topic_inertia
                self._inertia_source = 'topic' if self._inertia is not None else None
                self._restart('inertia parameter cleared: using the inertia topic')
        self._settings = settings

    # ---------------------------------------------------------------- inputs
    def _on_inertia(self, msg):
        tensor, frame = samples.inertia_tensor(msg)
        try:
            body = Inertia.from_tensor(tensor)
        except ValueError as err:
            self.get_logger().error(f'inertia topic refused: {err}')
            return
        self._topic_inertia = (body, frame or None)
        if self._inertia_source == 'parameter':
            return
        self._body_frame = frame or None
        if self._inertia is None or not np.allclose(body.tensor, self._inertia.tensor):
            self._inertia, self._inertia_source = body, 'topic'
            self._restart('inertia received')
            self.get_logger().info(f'inertia from topic: {body.moments.tolist()} kg m^2 '
                                   f'in frame {frame!r}')

    def _drain(self):
        """Take every odom and applied_torque message pending (one batch each) and file them."""
        raws = self._intake.take('odom')
        if raws:
            self._received += len(raws)
            self._last_arrival = self._steady.now().nanoseconds
            t, q, w, dropped = samples.odometry_batch(
                raws, lambda raw: deserialize_message(raw, Odometry), self._body_frame)
            if dropped:
                self._counts['wrong_frame'] += dropped
                self._warnings.warn('frame', f'{dropped} odom samples dropped: the twist is '
                                    'in another frame than the body frame '
                                    f'{self._body_frame!r} or the world frame')
            norm = np.linalg.norm(q, axis=1)
            good = np.isfinite(norm) & (norm >= 0.5) & np.all(np.isfinite(w), axis=1)
            if not np.all(good):
                self._counts['non_finite'] += int(np.count_nonzero(~good))
                self._warnings.warn('non-finite', 'odom sample with a non-finite or zero '
                                    'quaternion or rate dropped')
            q = q[good] / norm[good, None]
            for sample in zip(t[good].tolist(), q, w[good]):
                self._add_odom(*sample)
            if self._settings['gravity_gradient']:
                decode = lambda raw: deserialize_message(raw, Odometry)  # noqa: E731
                for stamp, r, v in zip(*samples.odometry_translation(raws, decode)):
                    if np.all(np.isfinite(r)) and np.all(np.isfinite(v)):
                        self._buffer.add_orbit(int(stamp), r, v)
        raws = self._intake.take('applied_torque')
        if raws:
            t, tau, dropped = samples.torque_batch(
                raws, lambda raw: deserialize_message(raw, WrenchStamped), self._body_frame)
            if dropped:
                self._warnings.warn('torque frame', f'{dropped} applied torques dropped: not '
                                    f'in the body frame {self._body_frame!r}')
            for stamp, vec in zip(t.tolist(), tau.tolist()):
                if all(math.isfinite(c) for c in vec):
                    self._add_torque(stamp, vec)
        raws = self._intake.take('attitude_estimate')
        if raws:
            self._estimates += len(raws)
            decode = lambda raw: deserialize_message(raw, PoseWithCovarianceStamped)  # noqa
            for stamp, q, cov in zip(*samples.pose_covariance_batch(raws, decode)):
                if np.all(np.isfinite(q)) and np.all(np.isfinite(cov)):
                    self._buffer.add_estimate(int(stamp), q, cov)
        for kind, topic in BIAS_TOPICS.items():
            for raw in self._intake.take(topic):
                msg = deserialize_message(raw, Vector3Stamped)
                v = msg.vector
                if all(math.isfinite(c) for c in (v.x, v.y, v.z)):
                    self._buffer.add_bias(kind, samples.stamp_ns(msg.header.stamp),
                                          (v.x, v.y, v.z))
        for raw in self._intake.take('wheel_state'):
            msg = deserialize_message(raw, JointState)
            self._buffer.add_wheels(samples.stamp_ns(msg.header.stamp), msg.velocity,
                                    msg.effort)

    def _add_odom(self, t, q, w):
        """File one valid state sample (stamp t ns, unit q, body omega)."""
        s = self._settings
        reason = self._buffer.add(t, q, w, int(s['reset_jump'] * 1e9), int(s['max_gap'] * 1e9))
        if reason:
            self._counts[reason] += 1
            self._restart(f'{"time went backwards" if reason == "reset" else "gap in stamps"} '
                          f'at t = {t * 1e-9:.6f} s')
        # the baseline is the earliest sample (by stamp) of the torque-free segment
        if t >= self._baseline_floor and (self._baseline is None or t < self._baseline[0]):
            self._baseline = (t, q, w)

    def _add_torque(self, t, vec):
        """File one applied-torque sample (stamp t ns, body torque N m)."""
        self._buffer.add_torque(t, vec)
        # the torque-free segment (and so the baseline) starts at the first zero applied
        # torque after the last non-zero one: the state stamped there is past every torque
        if any(vec):
            if t > self._last_torque:
                self._last_torque = t
                self._baseline_floor = _NEVER
                self._baseline = None
        elif self._baseline_floor == _NEVER and t > self._last_torque:
            self._baseline_floor = t
            self._baseline = self._buffer.first_from(t)

    def destroy_node(self):
        """Destroy the intake helper node, then this one."""
        self._intake.destroy()
        return super().destroy_node()

    def _restart(self, why, floor=_ALWAYS):
        self._baseline = None
        self._baseline_floor = floor
        self._last_torque = _ALWAYS
        self.get_logger().info(f'estimates restart: {why}')

    def _on_reset_baseline(self, _request, response):
        newest = self._buffer.t[-1] + 1 if self._buffer.t else _ALWAYS
        floor, last = max(newest, self._baseline_floor), self._last_torque
        self._restart('baseline reset on request', floor=floor)
        self._last_torque = last
        response.success = True
        response.message = 'drift is measured from the next sample on'
        return response

    # ---------------------------------------------------------------- analysis
    def _analyse(self):
        s = self._settings
        name = self.get_name()
        hw = self.get_fully_qualified_name()
        buf = self._buffer
        if buf.t:
            buf.trim(buf.t[-1] - int(s['window'] * 1e9))
        statuses = [self._input_status(name, hw)]
        checks = ('conservation', 'precession', 'stability')
        if self._inertia is None:
            text = 'no inertia yet: set the inertia parameter or publish the inertia topic'
            statuses += [conv.status(f'{name}: {c}', WARN, text, [], hw) for c in checks]
        else:
            t, q, w, tau = buf.arrays()
            origin = int(t[0]) if t.size else 0
            orbit = buf.orbit_arrays() if s['gravity_gradient'] else None
            trajectory = Trajectory.from_samples(
                t, q, w, self._inertia, tau, origin_ns=origin, **self._wheel_samples(),
                **({} if orbit is None else {'position': orbit[0], 'velocity': orbit[1]}))
            baseline = None
            if self._baseline is not None:
                b_t, b_q, b_w = self._baseline
                baseline = (b_t - origin, b_q, b_w)
            found = analyse(trajectory, baseline, self._tolerances(),
                            gravity_gradient=s['gravity_gradient'])
            if found.kinetic_energy is not None:
                self._publish('kinetic_energy', found.kinetic_energy)
                self._publish('angular_momentum_norm', found.angular_momentum_norm)
            pre = found.precession
            for topic, qty in (('precession/body_rate', pre.body_rate),
                               ('precession/lab_rate', pre.lab_rate)):
                if qty is not None and qty.measured is not None:
                    self._publish(topic, qty.measured)
            statuses += diagnostics.statuses(found, name, hw, origin)
        if self._estimates:
            statuses.append(diagnostics.estimation_status(
                estimation(*buf.estimate_arrays(), level=s['estimation_confidence']), name, hw))
        array = DiagnosticArray(status=statuses)
        array.header.stamp = self.get_clock().now().to_msg()
        self._pub_diag.publish(array)

    def _wheel_samples(self):
        """Trajectory keyword arguments of the wheels (empty without wheels or their samples)."""
        wheels = self._settings['wheels']
        if wheels is None:
            if self._buffer.wheel_t and any(any(s) for s, _u in self._buffer.wheel[-1:]):
                self._warnings.warn('wheels', 'wheel_state shows spinning wheels but '
                                    'wheel_axes / wheel_inertia are not set: their momentum '
                                    'is not counted (set them as on attitude_simulator)')
            return {}
        arrays = self._buffer.wheel_arrays(wheels.count)
        if arrays is None:
            self._warnings.warn('wheel samples', f'wheel_state does not match the odom stamps '
                                f'with {wheels.count} wheels yet: analysed without wheels')
            return {}
        return {'wheels': wheels, 'wheel_speeds': arrays[0], 'motor_torques': arrays[1]}

    def _tolerances(self):
        s = self._settings
        return Tolerances(energy=s['energy_tolerance'], momentum=s['momentum_tolerance'],
                          balance=s['balance_tolerance'], rate=s['rate_tolerance'],
                          libration=s['libration_tolerance'], min_samples=MIN_SAMPLES)

    def _publish(self, topic, value):
        self._pub[topic].publish(Float64(data=value))

    def _input_status(self, name, hw):
        now = self._steady.now().nanoseconds
        period = self._settings['diagnostic_period']
        self._rate_window.append((now, self._received))
        self._rate_window = self._rate_window[-6:]
        (t0, n0), (t1, n1) = self._rate_window[0], self._rate_window[-1]
        rate = (n1 - n0) / ((t1 - t0) * 1e-9) if t1 > t0 else math.nan
        values = [('messages received', self._received), ('rate (Hz)', rate),
                  ('restarts after a time reset', self._counts['reset']),
                  ('restarts after a gap', self._counts['gap']),
                  ('dropped non-finite samples', self._counts['non_finite']),
                  ('dropped samples in another frame', self._counts['wrong_frame']),
                  ('inertia source', self._inertia_source or 'none'),
                  ('body frame', self._body_frame or 'any'),
                  ('samples in the window', len(self._buffer.t))]
        if self._buffer.t:
            values += [('window first stamp (ns)', self._buffer.t[0]),
                       ('window last stamp (ns)', self._buffer.t[-1])]
        if self._last_arrival is None:
            return conv.status(f'{name}: input', STALE, 'no odom received yet', values, hw)
        age = (now - self._last_arrival) * 1e-9
        values.append(('age of the last message (s)', age))
        if age > max(self._settings['stale_timeout'], period):
            return conv.status(f'{name}: input', STALE, f'no odom for {age:.1f} s', values, hw)
        return conv.status(f'{name}: input', OK, f'receiving odom at {rate:.3g} Hz', values, hw)


def main(args=None, early=None):
    """Run until Ctrl-C / SIGTERM; exit 0, or 1 on bad configuration (see runner.run)."""
    return run(AttitudeAnalyzer, NODE_NAME, args, early=early)


if __name__ == '__main__':
    from .entry import exiting
    sys.exit(exiting(main()))
