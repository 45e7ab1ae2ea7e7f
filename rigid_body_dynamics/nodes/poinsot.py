"""
poinsot_visualizer: the Poinsot construction as RViz markers, from odom and the body's inertia.

Publishes ``poinsot_markers`` (visualization_msgs/MarkerArray) in the odom
frame (``header.frame_id`` of odom; no TF is needed): the inertia ellipsoid
(oriented with the body, semi-axes sqrt(2T / I_i)), omega and the normal from
the origin to the invariant plane (along L), the invariant plane it touches at
omega's tip, the polhode (omega's path on the ellipsoid, drawn on the current
ellipsoid) and the herpolhode (omega's path on the plane). Lengths are omega in
rad/s times ``scale`` (m per rad/s); traces keep the last ``trace_length``
points. The geometry is :mod:`rigid_body_dynamics.physics.analysis.poinsot`.

Namespace ``momentum_sphere`` (to toggle apart in RViz): the momentum sphere
|L| = |L0| turning with the body, drawn with the radius of the ellipsoid's
largest semi-axis, the L arrow on it, and the intersection curve with the
energy ellipsoid that L currently runs along
(:func:`rigid_body_dynamics.physics.analysis.momentum_sphere.current_curve`).
"""

from collections import deque
import sys

from builtin_interfaces.msg import Duration
from geometry_msgs.msg import InertiaStamped, Point
from nav_msgs.msg import Odometry
import numpy as np
from rclpy.node import Node
from rclpy.qos import DurabilityPolicy, HistoryPolicy, QoSProfile, ReliabilityPolicy
from std_msgs.msg import ColorRGBA
from visualization_msgs.msg import Marker, MarkerArray

from ..physics import Inertia, quaternions
from ..physics.analysis import momentum_sphere, poinsot
from ..ros import conversions as conv
from ..ros.parameters import ConfigurationError, Param, ParameterTable
from ..ros.runner import run

NODE_NAME = 'poinsot_visualizer'
INPUT_QOS = QoSProfile(history=HistoryPolicy.KEEP_LAST, depth=100,
                       reliability=ReliabilityPolicy.BEST_EFFORT)
LATCHED_QOS = QoSProfile(history=HistoryPolicy.KEEP_LAST, depth=1,
                         reliability=ReliabilityPolicy.RELIABLE,
                         durability=DurabilityPolicy.TRANSIENT_LOCAL)
COLORS = {'ellipsoid': (0.2, 0.5, 0.9, 0.35), 'omega': (0.9, 0.2, 0.2, 1.0),
          'normal': (0.2, 0.8, 0.2, 1.0), 'plane': (0.8, 0.8, 0.2, 0.25),
          'polhode': (1.0, 0.5, 0.0, 1.0), 'herpolhode': (0.6, 0.2, 0.8, 1.0),
          'sphere': (0.7, 0.7, 0.7, 0.2), 'momentum': (0.1, 0.1, 0.1, 1.0),
          'curve': (0.9, 0.1, 0.1, 1.0)}
IDS = {name: i for i, name in enumerate(COLORS)}
#: Markers in the momentum-sphere namespace (the others are in ``poinsot``).
SPHERE_MARKERS = ('sphere', 'momentum', 'curve')


def _point(v):
    return Point(x=float(v[0]), y=float(v[1]), z=float(v[2]))


def _trace_length(value):
    if isinstance(value, bool) or not isinstance(value, int) or value < 2:
        raise ConfigurationError(f'trace_length must be an integer >= 2, got {value!r}')
    return value


#: The parameters of poinsot_visualizer (the manual's table is made from this; test_docs checks).
PARAMETERS = ParameterTable([
    Param('scale', 'double', 1.0, '1.0 m per rad/s',
          'Marker length per rad/s of angular velocity (m per rad/s).', low=1e-12, high=1e12),
    Param('trace_length', 'int', 2000, '2000',
          'Points kept in the polhode and herpolhode traces (at least 2).', read_only=True,
          convert=_trace_length),
    Param('marker_rate', 'double', 20.0, '20.0 Hz',
          'Marker arrays per second of odom stamps (Hz).', low=1e-6, high=1e4),
])


class PoinsotVisualizer(Node):
    """The poinsot_visualizer node; ``kwargs`` go to rclpy's Node."""

    def __init__(self, **kwargs):
        super().__init__(NODE_NAME, **kwargs)
        values = PARAMETERS.validate(PARAMETERS.declare(self))
        self._scale = values['scale']
        self._period = 1.0 / values['marker_rate']
        length = values['trace_length']
        self._polhode = deque(maxlen=length)      # body-frame omega (principal axes)
        self._herpolhode = deque(maxlen=length)   # world-frame omega
        self._inertia = None
        self._last = None
        self.add_on_set_parameters_callback(lambda params: PARAMETERS.on_set(self, params))
        self.add_post_set_parameters_callback(self._apply)
        self.create_subscription(InertiaStamped, 'inertia', self._on_inertia, LATCHED_QOS)
        self.create_subscription(Odometry, 'odom', self._on_odom, INPUT_QOS)
        self._pub = self.create_publisher(MarkerArray, 'poinsot_markers', 10)
        self.get_logger().info('waiting for the inertia topic and odom')

    def _apply(self, params):
        for p in params:
            if p.name == 'scale':
                self._scale = float(p.value)
            elif p.name == 'marker_rate':
                self._period = 1.0 / float(p.value)

    def _on_inertia(self, msg):
        i = msg.inertia
        try:
            self._inertia = Inertia.from_tensor([i.ixx, i.iyy, i.izz, i.ixy, i.ixz, i.iyz])
        except ValueError as err:
            self.get_logger().error(f'inertia topic refused: {err}')
            return
        self._polhode.clear()
        self._herpolhode.clear()

    def _on_odom(self, msg):
        if self._inertia is None:
            return
        q = conv.quaternion_array(msg.pose.pose.orientation)
        w = conv.vector_array(msg.twist.twist.angular)
        if not (np.all(np.isfinite(q)) and np.all(np.isfinite(w))) or np.linalg.norm(q) < 0.5:
            return
        t = conv.time_ns(msg.header.stamp) * 1e-9
        if self._last is not None and t < self._last:      # time went back: a new run
            self._polhode.clear()
            self._herpolhode.clear()
            self._last = None
        q_p = self._inertia.attitude_to_principal(q / np.linalg.norm(q))
        w_p = self._inertia.to_principal(w)
        try:
            geometry = poinsot.construction(self._inertia.moments, q_p, w_p)
        except ValueError:
            return
        self._polhode.append(w_p)
        self._herpolhode.append(geometry.omega)
        if self._last is None or t >= self._last + self._period:
            self._last = t
            self._pub.publish(self._markers(msg.header, geometry))

    def _marker(self, header, name, kind):
        ns = 'momentum_sphere' if name in SPHERE_MARKERS else 'poinsot'
        m = Marker(header=header, ns=ns, id=IDS[name], type=kind, action=Marker.ADD)
        m.color = ColorRGBA(r=COLORS[name][0], g=COLORS[name][1], b=COLORS[name][2],
                            a=COLORS[name][3])
        m.pose.orientation.w = 1.0
        m.lifetime = Duration(sec=0)
        return m

    def _markers(self, header, g):
        """Build the marker array for one instant; see the module docstring."""
        k = self._scale
        out = []
        ellipsoid = self._marker(header, 'ellipsoid', Marker.SPHERE)
        ellipsoid.pose.orientation = conv.quaternion_msg(g.orientation)
        ellipsoid.scale.x, ellipsoid.scale.y, ellipsoid.scale.z = (2.0 * k * g.semi_axes)
        out.append(ellipsoid)
        width = 0.02 * k * float(np.min(g.semi_axes))
        for name, tip in (('omega', g.omega), ('normal', g.distance * g.normal)):
            arrow = self._marker(header, name, Marker.ARROW)
            arrow.points = [_point((0.0, 0.0, 0.0)), _point(k * tip)]
            arrow.scale.x, arrow.scale.y, arrow.scale.z = width, 2.0 * width, 4.0 * width
            out.append(arrow)
        plane = self._marker(header, 'plane', Marker.CUBE)
        plane.pose.position = _point(k * g.distance * g.normal)
        plane.pose.orientation = conv.quaternion_msg(poinsot.plane_orientation(g.normal))
        size = 4.0 * k * float(np.max(g.semi_axes))
        plane.scale.x, plane.scale.y, plane.scale.z = size, size, 1e-3 * size
        out.append(plane)
        polhode = self._marker(header, 'polhode', Marker.LINE_STRIP)
        body_points = np.array(self._polhode)
        polhode.points = [_point(k * p) for p in quaternions.rotate(g.orientation, body_points)]
        herpolhode = self._marker(header, 'herpolhode', Marker.LINE_STRIP)
        herpolhode.points = [_point(k * p) for p in self._herpolhode]
        for trace in (polhode, herpolhode):
            trace.scale.x = width
            out.append(trace)
        out += self._sphere_markers(header, g, k * float(np.max(g.semi_axes)), width)
        return MarkerArray(markers=out)

    def _sphere_markers(self, header, g, radius, width):
        """Draw the momentum sphere (radius m), L on it and L's current curve, world frame."""
        moments = self._inertia.moments
        l_body = moments * quaternions.rotate_inverse(g.orientation, g.omega)
        l0 = float(np.linalg.norm(l_body))
        sphere = self._marker(header, 'sphere', Marker.SPHERE)
        sphere.pose.orientation = conv.quaternion_msg(g.orientation)
        sphere.scale.x = sphere.scale.y = sphere.scale.z = 2.0 * radius
        arrow = self._marker(header, 'momentum', Marker.ARROW)
        arrow.points = [_point((0.0, 0.0, 0.0)), _point(radius * g.normal)]
        arrow.scale.x, arrow.scale.y, arrow.scale.z = width, 2.0 * width, 4.0 * width
        out = [sphere, arrow]
        curve = momentum_sphere.current_curve(moments, l_body)
        if curve is not None:
            line = self._marker(header, 'curve', Marker.LINE_STRIP)
            world = quaternions.rotate(g.orientation, curve) * (radius / l0)
            line.points = [_point(p) for p in world]
            line.scale.x = width
            out.append(line)
        return out


def main(args=None, early=None):
    """Run until Ctrl-C / SIGTERM; exit 0, or 1 on bad configuration (see runner.run)."""
    return run(PoinsotVisualizer, NODE_NAME, args, early=early)


if __name__ == '__main__':
    from .entry import exiting
    sys.exit(exiting(main()))
