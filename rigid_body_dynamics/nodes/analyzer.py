"""
attitude_analyzer: measures what an attitude stream does and checks it against physics.

Works from ``odom`` alone (plus ``applied_torque`` when present), so it can
audit any attitude source. Inertia comes from the ``inertia`` parameter or else
from the latched ``inertia`` topic. Only header stamps are used, never arrival
times: samples are kept sorted by stamp, duplicates dropped; a stamp more than
``reset_jump`` s before the newest one (a simulator reset or restart) or a gap
longer than ``max_gap`` s restarts the estimates instead of corrupting them.

Every ``diagnostic_period`` (steady clock) the samples of the last ``window``
s (by stamp) are analysed with :mod:`rigid_body_dynamics.physics.estimators`
and compared with :mod:`rigid_body_dynamics.physics.theory`. Until there is
enough data a measurement is reported as not available, never as a number.
"""

import bisect
import math
import sys

from diagnostic_msgs.msg import DiagnosticArray, DiagnosticStatus
from geometry_msgs.msg import InertiaStamped, WrenchStamped
from nav_msgs.msg import Odometry
import numpy as np
from rclpy.clock import Clock, ClockType
from rclpy.node import Node
from rclpy.qos import DurabilityPolicy, HistoryPolicy, QoSProfile, ReliabilityPolicy
from std_msgs.msg import Float64
from std_srvs.srv import Trigger

from . import conversions as conv
from .parameters import as_float, as_vector, check_change, ConfigurationError, descriptor
from .runner import run
from .throttle import ThrottledWarnings
from ..physics import equations, estimators, Inertia, theory

NODE_NAME = 'attitude_analyzer'
#: Samples needed before any rate is estimated.
MIN_SAMPLES = 20

INPUT_QOS = QoSProfile(history=HistoryPolicy.KEEP_LAST, depth=1000,
                       reliability=ReliabilityPolicy.BEST_EFFORT)
LATCHED_QOS = QoSProfile(history=HistoryPolicy.KEEP_LAST, depth=1,
                         reliability=ReliabilityPolicy.RELIABLE,
                         durability=DurabilityPolicy.TRANSIENT_LOCAL)

OK, WARN, ERROR, STALE = (DiagnosticStatus.OK, DiagnosticStatus.WARN, DiagnosticStatus.ERROR,
                          DiagnosticStatus.STALE)


class SampleBuffer:
    """
    Attitude samples sorted by stamp (s): q (x, y, z, w), omega (rad/s, body), torque (N m, body).

    ``add`` returns why the history restarted ('reset', 'gap') or None.
    """

    def __init__(self):
        self.clear()

    def clear(self):
        """Forget every sample."""
        self.t, self.q, self.w = [], [], []
        self.torque_t, self.torque = [], []

    def add(self, t, q, w, reset_jump, max_gap):
        """Insert one state sample in stamp order; duplicates are dropped."""
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
        """Insert one applied-torque sample in stamp order."""
        i = bisect.bisect_left(self.torque_t, t)
        if i < len(self.torque_t) and self.torque_t[i] == t:
            return
        self.torque_t.insert(i, t)
        self.torque.insert(i, torque)

    def trim(self, keep_from):
        """Drop samples older than ``keep_from`` (s)."""
        i = bisect.bisect_left(self.t, keep_from)
        del self.t[:i], self.q[:i], self.w[:i]
        j = bisect.bisect_left(self.torque_t, keep_from)
        del self.torque_t[:j], self.torque[:j]

    def arrays(self):
        """(t, q, omega, torque at the state stamps) as arrays; torque 0 where none is known."""
        t = np.array(self.t)
        tau = np.zeros((t.size, 3))
        if self.torque_t:
            idx = np.searchsorted(np.array(self.torque_t), t, side='right') - 1
            known = idx >= 0
            tau[known] = np.array(self.torque)[idx[known]]
        return t, np.array(self.q), np.array(self.w), tau


class AttitudeAnalyzer(Node):
    """The attitude_analyzer node. ``kwargs`` go to rclpy's Node."""

    def __init__(self, **kwargs):
        super().__init__(NODE_NAME, **kwargs)
        self._warnings = ThrottledWarnings(self.get_logger(), period=5.0)
        num = {'dynamic_typing': True}
        self.declare_parameter('inertia', None, descriptor(
            'Principal moments [I1, I2, I3] (kg m^2) of the body in its odom child frame, or '
            '6 tensor elements [Ixx, Iyy, Izz, Ixy, Ixz, Iyz]; unset = from the latched '
            'inertia topic.', **num))
        self.declare_parameter('window', 10.0, descriptor(
            'Length of the analysed history (s of stamps).', low=0.1, high=1e9, **num))
        self.declare_parameter('energy_tolerance', 1e-6, descriptor(
            'Relative drift of T (or work-energy residual under torque) above which '
            'conservation is WARN; 100x that is ERROR.', low=0.0, high=1.0, **num))
        self.declare_parameter('momentum_tolerance', 1e-6, descriptor(
            'Relative drift of |L| and L direction (rad), or impulse-momentum residual under '
            'torque, above which conservation is WARN; 100x that is ERROR.',
            low=0.0, high=1.0, **num))
        self.declare_parameter('balance_tolerance', 1e-2, descriptor(
            'Under torque: relative work-energy and impulse-momentum residual above which '
            'conservation is WARN (100x: ERROR). Sampled torque costs an O(dt) quadrature '
            'error at each torque change, so this is looser than the free-motion tolerances.',
            low=0.0, high=1.0, **num))
        self.declare_parameter('stale_timeout', 1.0, descriptor(
            'Input is STALE when no odom arrived for this long (s, steady clock).',
            low=0.0, high=1e6, **num))
        self.declare_parameter('reset_jump', 0.5, descriptor(
            'A stamp this much (s) before the newest is a reset: estimates restart.',
            low=0.0, high=1e9, **num))
        self.declare_parameter('max_gap', 1.0, descriptor(
            'A gap between stamps longer than this (s) restarts the estimates.',
            low=0.0, high=1e9, **num))
        self.declare_parameter('diagnostic_period', 1.0, descriptor(
            'Period of the analysis and of /diagnostics (s, steady clock).', read_only=True,
            low=0.01, high=3600.0, **num))
        self._settings = self._validate({p.name: p.value for p in self._parameters.values()})
        self._inertia_source = 'parameter' if self._settings['inertia'] else None
        self._inertia = self._settings['inertia']
        self._buffer = SampleBuffer()
        self._baseline = None
        self._restarts = {'reset': 0, 'gap': 0, 'non_finite': 0}
        self._received = 0
        self._last_arrival = None
        self._rate_window = []
        self.add_on_set_parameters_callback(self._on_set_parameters)
        self.add_post_set_parameters_callback(self._post_set_parameters)

        self.create_subscription(Odometry, 'odom', self._on_odom, INPUT_QOS)
        self.create_subscription(WrenchStamped, 'applied_torque', self._on_torque, INPUT_QOS)
        self.create_subscription(InertiaStamped, 'inertia', self._on_inertia, LATCHED_QOS)
        self._pub = {name: self.create_publisher(Float64, name, 10) for name in (
            'precession/body_rate', 'precession/lab_rate', 'kinetic_energy',
            'angular_momentum_norm')}
        self._pub_diag = self.create_publisher(DiagnosticArray, '/diagnostics', 10)
        self.create_service(Trigger, '~/reset_baseline', self._on_reset_baseline)
        self._steady = Clock(clock_type=ClockType.STEADY_TIME)
        self.create_timer(self._settings['diagnostic_period'], self._analyse, clock=self._steady)
        self.get_logger().info(
            'analysing odom' + (f' with inertia {self._inertia.moments.tolist()} kg m^2'
                                if self._inertia else '; waiting for the inertia topic'))

    # ---------------------------------------------------------------- parameters
    def _validate(self, values):
        out = dict(values)
        raw = values.get('inertia')
        try:
            if raw is None or (hasattr(raw, '__len__') and len(raw) == 0):
                out['inertia'] = None
            elif len(raw) == 3:
                out['inertia'] = Inertia(as_vector('inertia', raw, 3))
            else:
                out['inertia'] = Inertia.from_tensor(as_vector('inertia', raw, 6))
        except (TypeError, ValueError) as err:
            raise ConfigurationError(f'inertia: {err}') from None
        for name, low, high in (('window', 0.1, 1e9), ('energy_tolerance', 0.0, 1.0),
                                ('balance_tolerance', 0.0, 1.0),
                                ('momentum_tolerance', 0.0, 1.0), ('stale_timeout', 0.0, 1e6),
                                ('reset_jump', 0.0, 1e9), ('max_gap', 0.0, 1e9),
                                ('diagnostic_period', 0.01, 3600.0)):
            out[name] = as_float(name, values[name], low, high)
        return out

    def _on_set_parameters(self, params):
        """Validate only (no side effects); the post-set callback applies."""
        values = {p.name: p.value for p in self._parameters.values()}
        values.update({p.name: p.value for p in params})
        return check_change(self.get_logger(), self._validate, values)

    def _post_set_parameters(self, params):
        settings = self._validate({p.name: p.value for p in self._parameters.values()})
        if 'inertia' in {p.name for p in params} and settings['inertia'] is not None:
            self._inertia, self._inertia_source = settings['inertia'], 'parameter'
            self._restart('inertia changed')
        self._settings = settings

    # ---------------------------------------------------------------- inputs
    def _on_inertia(self, msg):
        if self._inertia_source == 'parameter':
            return
        i = msg.inertia
        try:
            body = Inertia.from_tensor([i.ixx, i.iyy, i.izz, i.ixy, i.ixz, i.iyz])
        except ValueError as err:
            self.get_logger().error(f'inertia topic refused: {err}')
            return
        if self._inertia is None or not np.allclose(body.tensor, self._inertia.tensor):
            self._inertia, self._inertia_source = body, 'topic'
            self._restart('inertia received')
            self.get_logger().info(f'inertia from topic: {body.moments.tolist()} kg m^2')

    def _on_odom(self, msg):
        self._received += 1
        self._last_arrival = self._steady.now().nanoseconds
        q = conv.quaternion_array(msg.pose.pose.orientation)
        w = conv.vector_array(msg.twist.twist.angular)
        norm = float(np.linalg.norm(q))
        if not (np.all(np.isfinite(q)) and np.all(np.isfinite(w))) or norm < 0.5:
            self._restarts['non_finite'] += 1
            self._warnings.warn('non-finite', 'odom sample with a non-finite or zero quaternion '
                                'or rate dropped')
            return
        t = conv.time_ns(msg.header.stamp) * 1e-9
        s = self._settings
        reason = self._buffer.add(t, q / norm, w, s['reset_jump'], s['max_gap'])
        if reason:
            self._restarts[reason] += 1
            self._restart(f'{"time went backwards" if reason == "reset" else "gap in stamps"} '
                          f'at t = {t:.6g} s')

    def _on_torque(self, msg):
        vec = conv.vector_array(msg.wrench.torque)
        if np.all(np.isfinite(vec)):
            self._buffer.add_torque(conv.time_ns(msg.header.stamp) * 1e-9, vec)

    def _restart(self, why):
        self._baseline = None
        self.get_logger().info(f'estimates restart: {why}')

    def _on_reset_baseline(self, _request, response):
        self._baseline = None
        response.success = True
        response.message = 'drift is measured from the next sample on'
        return response

    # ---------------------------------------------------------------- analysis
    def _analyse(self):
        s = self._settings
        name = self.get_name()
        hw = self.get_fully_qualified_name()
        statuses = [self._input_status(name, hw)]
        buf = self._buffer
        if buf.t:
            buf.trim(buf.t[-1] - s['window'])
        if self._inertia is None:
            text = 'no inertia yet: set the inertia parameter or publish the inertia topic'
            for check in ('conservation', 'precession', 'stability'):
                statuses.append(conv.status(f'{name}: {check}', WARN, text, [], hw))
        elif len(buf.t) < MIN_SAMPLES:
            text = f'not enough data yet ({len(buf.t)} of {MIN_SAMPLES} samples)'
            for check in ('conservation', 'precession', 'stability'):
                statuses.append(conv.status(f'{name}: {check}', OK, text, [], hw))
        else:
            t, q, w, tau = buf.arrays()
            moments, frame = self._principal(q, w)
            self._publish('kinetic_energy', float(equations.kinetic_energy(moments, frame[1][-1])))
            self._publish('angular_momentum_norm',
                          float(np.linalg.norm(moments * frame[1][-1])))
            statuses.append(self._conservation(name, hw, t, frame, tau, moments))
            statuses.append(self._precession(name, hw, t, frame, moments))
            statuses.append(self._stability(name, hw, t, frame[1], moments))
        array = DiagnosticArray(status=statuses)
        array.header.stamp = self.get_clock().now().to_msg()
        self._pub_diag.publish(array)

    def _principal(self, q, w):
        """Return the moments and the samples in the principal frame: (q, omega)."""
        body = self._inertia
        return body.moments, (body.attitude_to_principal(q), body.to_principal(w))

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
                  ('restarts after a time reset', self._restarts['reset']),
                  ('restarts after a gap', self._restarts['gap']),
                  ('dropped non-finite samples', self._restarts['non_finite']),
                  ('inertia source', self._inertia_source or 'none')]
        if self._last_arrival is None:
            return conv.status(f'{name}: input', STALE, 'no odom received yet', values, hw)
        age = (now - self._last_arrival) * 1e-9
        values.append(('age of the last message (s)', age))
        if age > max(self._settings['stale_timeout'], period):
            return conv.status(f'{name}: input', STALE, f'no odom for {age:.1f} s', values, hw)
        return conv.status(f'{name}: input', OK, f'receiving odom at {rate:.3g} Hz', values, hw)

    def _conservation(self, name, hw, t, frame, tau, moments):
        """
        Free motion: drift of T, |L| and L_w direction since the baseline.

        While the window holds torque: the work-energy and impulse-momentum
        residuals over the window instead (sampled torque, trapezoid), against
        ``balance_tolerance``. Once the torque has left the window the
        baseline restarts from the newest sample.
        """
        q, w = frame
        s = self._settings
        tau_p = self._inertia.to_principal(tau)
        under_torque = bool(np.any(tau_p != 0.0))
        if under_torque:
            self._baseline = None
        elif self._baseline is None:
            self._baseline = (t[-1], equations.kinetic_energy(moments, w[-1]),
                              equations.angular_momentum_world(moments, q[-1], w[-1]))
        if under_torque:
            bal = estimators.balance(t, q, w, tau_p, moments)
            e_err, l_err, d_err = bal.energy, bal.momentum, 0.0
            tol_e = tol_l = s['balance_tolerance']
            values = [('mode', 'balance laws (torque applied in the window)'),
                      ('work-energy residual (rel.)', e_err),
                      ('impulse-momentum residual (rel.)', l_err),
                      ('work over the window (J)', bal.work)]
        else:
            t0, e0, l0 = self._baseline
            e1 = equations.kinetic_energy(moments, w[-1])
            l1 = equations.angular_momentum_world(moments, q[-1], w[-1])
            e_err = abs(e1 - e0) / e0 if e0 else 0.0
            g0 = float(np.linalg.norm(l0))
            l_err = abs(float(np.linalg.norm(l1)) - g0) / g0 if g0 else 0.0
            d_err = float(estimators.vector_angle(l1, l0))
            tol_e, tol_l = s['energy_tolerance'], s['momentum_tolerance']
            values = [('mode', 'free motion'), ('baseline stamp (s)', float(t0)),
                      ('energy drift since baseline (rel.)', e_err),
                      ('|L| drift since baseline (rel.)', l_err),
                      ('L direction drift since baseline (rad)', d_err)]
        worst_e = e_err / tol_e if tol_e else 0.0
        worst_l = max(l_err, d_err) / tol_l if tol_l else 0.0
        worst = max(worst_e, worst_l)
        level = OK if worst <= 1.0 else (WARN if worst <= 100.0 else ERROR)
        if level == OK:
            message = 'balance laws hold under torque' if under_torque else 'conserved'
        else:
            what = 'energy' if worst_e >= worst_l else 'angular momentum'
            message = f'{what} off by {worst:.3g} x tolerance'
        values += [('energy tolerance', tol_e), ('momentum tolerance', tol_l)]
        return conv.status(f'{name}: conservation', level, message, values, hw)

    def _precession(self, name, hw, t, frame, moments):
        q, w = frame
        body = self._inertia
        axis = body.symmetry_axis
        values = []
        if axis is None and body.kind == 'spherical':
            return conv.status(f'{name}: precession', OK, 'a spherical body does not precess',
                               values, hw)
        if axis is None:
            return self._asymmetric_precession(name, hw, t, q, w, moments)
        i_perp = float(np.mean([moments[(axis + 1) % 3], moments[(axis + 2) % 3]]))
        w_axis = float(w[-1, axis])
        w_perp = float(math.hypot(w[-1, (axis + 1) % 3], w[-1, (axis + 2) % 3]))
        g = float(np.linalg.norm(moments * w[-1]))
        body_theory = theory.body_precession_rate(i_perp, moments[axis], w_axis)
        lab_theory = theory.lab_precession_rate(i_perp, g)
        cones = theory.cone_angles(i_perp, moments[axis], w_perp, w_axis)
        body_rate = estimators.body_precession_rate(t, w, axis).rate
        lab_rate = estimators.lab_precession_rate(t, q, w, moments, axis).rate
        self._publish('precession/body_rate', body_rate)
        self._publish('precession/lab_rate', lab_rate)
        rel_body = abs(body_rate - body_theory) / abs(body_theory) if body_theory else math.nan
        rel_lab = abs(lab_rate - lab_theory) / abs(lab_theory)
        values += [('body rate, measured (rad/s)', body_rate),
                   ('body rate, theory (rad/s)', body_theory),
                   ('body rate error (rel.)', rel_body),
                   ('lab rate, measured (rad/s)', lab_rate),
                   ('lab rate, theory (rad/s)', lab_theory), ('lab rate error (rel.)', rel_lab),
                   ('body cone half-angle (rad)', cones.body),
                   ('lab cone half-angle (rad)', cones.lab),
                   ('nutation angle (rad)', cones.nutation)]
        return conv.status(f'{name}: precession', OK,
                           f'body {body_rate:.6g} rad/s (theory {body_theory:.6g}), '
                           f'lab {lab_rate:.6g} rad/s (theory {lab_theory:.6g})', values, hw)

    def _asymmetric_precession(self, name, hw, t, q, w, moments):
        """
        Period of omega(t) and mean precession about L of the axis the polhode circles.

        Both are measured only once the window spans a full period of omega
        (a shorter window would alias the nutation into the rates).
        """
        period = theory.omega_period(moments, w[-1])
        polhode = theory.polhode(moments, w[-1])
        values = [('polhode family', polhode.family), ('omega period, theory (s)', period)]
        if not math.isfinite(period) or polhode.circled_axis is None:
            return conv.status(f'{name}: precession', OK,
                               f'no periodic precession ({polhode.family})', values, hw)
        axis = polhode.circled_axis
        mean_rate = theory.mean_precession_rate(moments, w[-1], axis)
        values.append((f'mean precession of axis {axis + 1} about L, theory (rad/s)', mean_rate))
        if t[-1] - t[0] < period:
            return conv.status(f'{name}: precession', OK,
                               f'window ({t[-1] - t[0]:.3g} s) shorter than a period of omega '
                               f'({period:.6g} s): no measurement yet', values, hw)
        # omega about the middle axis is a2 sn(u) in both families: its zero crossings
        # are exactly half a period apart (no mean to remove)
        mid = int(np.argsort(moments)[1])
        try:
            measured = estimators.crossing_period(t, w[:, mid], 0)
        except ValueError:
            measured = math.nan
        lab = estimators.lab_precession_rate(t, q, w, moments, axis).rate
        values += [('omega period, measured (s)', measured),
                   ('omega period error (rel.)', abs(measured - period) / period),
                   (f'mean precession of axis {axis + 1} about L, measured (rad/s)', lab)]
        return conv.status(f'{name}: precession', OK,
                           f'omega period {measured:.6g} s (theory {period:.6g}), axis '
                           f'{axis + 1} precesses about L at {lab:.6g} rad/s (theory '
                           f'{mean_rate:.6g})', values, hw)

    def _stability(self, name, hw, t, w, moments):
        """
        Classify the spin about the principal axis the motion stays nearest over the window.

        (During a tennis-racket flip omega passes other axes for a moment; the
        window average does not.) The spin about that axis is |L| / I_axis.
        """
        omega = w[-1]
        axis = int(np.argmax(np.mean(np.abs(w), axis=0)))
        spin = math.copysign(float(np.linalg.norm(moments * omega)) / moments[axis],
                             omega[axis] if omega[axis] else 1.0)
        st = theory.axis_stability(moments, axis, spin)
        pol = theory.polhode(moments, omega)
        values = [('nearest principal axis', st.axis + 1), ('class', st.kind),
                  ('polhode family', pol.family),
                  ('separatrix distance (S/G^2)', pol.separatrix_distance)]
        if st.kind == 'unstable':
            flip = theory.flip_interval(moments, omega)
            values += [('growth rate, theory (1/s)', st.rate), ('flip interval, theory (s)', flip)]
            message = f'spin about axis {st.axis + 1} is unstable: growth rate {st.rate:.6g} 1/s'
            for label, estimate in (('growth rate, measured (1/s)', lambda: (
                    estimators.separatrix_growth_rate(t, w, moments))),
                    ('flip interval, measured (s)', lambda: estimators.flip_interval(
                        t, w, st.axis))):
                try:
                    values.append((label, estimate()))
                except ValueError as err:
                    values.append((label, f'not available: {err}'))
            level = WARN
        else:
            values.append(('wobble frequency (rad/s)', st.rate))
            message = f'spin about axis {st.axis + 1} is {st.kind}'
            level = OK
        return conv.status(f'{name}: stability', level, message, values, hw)


def main(args=None, early=None):
    """Run until Ctrl-C / SIGTERM; exit 0, or 1 on bad configuration (see runner.run)."""
    return run(AttitudeAnalyzer, NODE_NAME, args, early=early)


if __name__ == '__main__':
    sys.exit(main())
