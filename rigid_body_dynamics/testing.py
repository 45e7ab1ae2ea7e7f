"""
pytest fixtures for topic-based tests of your own controller against attitude_simulator.

Installed with the package and registered through the ``pytest11`` entry
point; inert unless a test asks for one of its fixtures (nothing here runs,
and rclpy is not imported, otherwise):

- ``ros_isolation`` (session): a free ``ROS_DOMAIN_ID`` (domain_coordinator),
  discovery on this machine only (``ROS_AUTOMATIC_DISCOVERY_RANGE=LOCALHOST``)
  and a temporary ``ROS_LOG_DIR``, set in ``os.environ`` for the session, so
  every process a test starts inherits them; restored afterwards.
- ``attitude_sim``: a factory. ``attitude_sim(preset, lockstep=True,
  **parameters)`` starts ``attitude_simulator`` as its own process (stamps from
  0 on ``/clock``; in lockstep unless told otherwise), waits for its first
  state and returns a :class:`SimulatorHandle`; every simulator and every
  process started through a handle is stopped at the end of the test.

A complete test of a controller is in the manual's lockstep tutorial
(doc/examples/test_detumble.py), and the suite runs it as it stands there.
"""

import os
import subprocess
import tempfile
import time

import pytest

_SIM = 'rigid_body_dynamics.nodes.simulator'


@pytest.fixture(scope='session')
def ros_isolation():
    """Reserve a free ROS domain, keep DDS on loopback, log to a temporary folder."""
    from domain_coordinator import domain_id
    keys = ('ROS_DOMAIN_ID', 'ROS_AUTOMATIC_DISCOVERY_RANGE', 'ROS_LOG_DIR', 'ROS_LOCALHOST_ONLY')
    saved = {k: os.environ.get(k) for k in keys}
    with domain_id() as domain, tempfile.TemporaryDirectory(prefix='ros_log_') as logs:
        os.environ['ROS_DOMAIN_ID'] = str(domain)
        os.environ['ROS_AUTOMATIC_DISCOVERY_RANGE'] = 'LOCALHOST'
        os.environ['ROS_LOG_DIR'] = logs
        os.environ.pop('ROS_LOCALHOST_ONLY', None)
        try:
            yield domain
        finally:
            for key, value in saved.items():
                if value is None:
                    os.environ.pop(key, None)
                else:
                    os.environ[key] = value


def _ros_value(value):
    """Return a Python value as ``-p name:=value`` text (lists and bools as ROS reads them)."""
    if isinstance(value, bool):
        return 'true' if value else 'false'
    if isinstance(value, (list, tuple)):
        return '[' + ', '.join(_ros_value(float(v) if isinstance(v, int) else v)
                               for v in value) + ']'
    return str(value)


class SimulatorHandle:
    """
    A running attitude_simulator and a recorder of its ``odom``, in the test's process.

    ``odom``: every nav_msgs/Odometry received, in order. Times are simulated
    seconds (stamps start at 0). Waits raise AssertionError after their timeout.
    """

    def __init__(self, process, node_name='/attitude_simulator'):
        from rclpy.qos import QoSProfile, ReliabilityPolicy
        from nav_msgs.msg import Odometry
        from .ros.client import RosClient
        self.process = process
        self.name = node_name
        self.started = []
        self._client = RosClient('attitude_sim_test_handle')
        self.odom = []
        self._client.node.create_subscription(
            Odometry, 'odom', self.odom.append,
            QoSProfile(depth=10000, reliability=ReliabilityPolicy.RELIABLE))

    def _spin_until(self, predicate, timeout, what):
        if self.process.poll() is not None:
            raise AssertionError(f'attitude_simulator exited with {self.process.returncode}')
        self._client.spin_until(predicate, timeout, what)

    def time(self):
        """Return the newest received state's simulated time in s, or None before any."""
        if not self.odom:
            return None
        stamp = self.odom[-1].header.stamp
        return stamp.sec + stamp.nanosec * 1e-9

    def wait_until(self, t, timeout=60.0):
        """Spin until a state at simulated time >= t (s) has arrived."""
        self._spin_until(lambda: self.odom and self.time() >= t - 1e-12, timeout,
                         f'simulated time {t:g} s')

    def latest(self):
        """Return (t s, q (x, y, z, w) body -> world, omega rad/s body) of the newest state."""
        self._client.spin_for(0.0)
        if not self.odom:
            raise AssertionError('no state received yet')
        m = self.odom[-1]
        o, w = m.pose.pose.orientation, m.twist.twist.angular
        return self.time(), (o.x, o.y, o.z, o.w), (w.x, w.y, w.z)

    def _call(self, srv_type, service, request, timeout=10.0):
        client = self._client.node.create_client(srv_type, f'{self.name}/{service}')
        try:
            self._spin_until(client.service_is_ready, timeout, f'{service} service')
            future = client.call_async(request)
            self._spin_until(future.done, timeout, f'{service} response')
            return future.result()
        finally:
            self._client.node.destroy_client(client)

    def reset(self):
        """Call ~/reset: back to the initial state, simulated time 0 (odom is cleared)."""
        from std_srvs.srv import Trigger
        response = self._call(Trigger, 'reset', Trigger.Request())
        self.odom.clear()
        return response.success

    def pause(self, paused=True):
        """Call ~/pause with ``paused``; returns the state the simulator reports."""
        from std_srvs.srv import SetBool
        return self._call(SetBool, 'pause', SetBool.Request(data=bool(paused))).message

    def start(self, executable, *ros_args):
        """
        Start a controller as its own process in this test's ROS environment.

        ``executable``: a package node name (``attitude_controller``), a module
        path for ``python -m``, or a full command list (your own controller).
        Stopped with SIGINT at the end of the test.
        """
        from .ros.client import start_node
        if isinstance(executable, (list, tuple)):
            proc = subprocess.Popen(list(executable) + (['--ros-args', *ros_args]
                                                        if ros_args else []))
        else:
            module = {'attitude_controller': 'controller', 'attitude_estimator': 'estimator',
                      'attitude_simulator': 'simulator'}.get(executable, executable)
            proc = start_node(module, ros_args)
        self.started.append(proc)
        return proc

    def stop(self):
        """Stop what this handle started and the simulator (SIGINT); the simulator's exit code."""
        from .ros.client import interrupt
        for proc in self.started:
            interrupt(proc)
        code = interrupt(self.process)
        self._client.close()
        return code


@pytest.fixture
def attitude_sim(ros_isolation):
    """
    Start attitude_simulator processes: call it with a preset, lockstep and parameters.

    Returns a :class:`SimulatorHandle` once the first state arrived.
    """
    from .ros.client import start_node
    handles = []

    def start(preset='symmetric_top', lockstep=True, timeout=30.0, **parameters):
        args = ['-p', f'preset:={preset}', '-p', f'lockstep:={_ros_value(lockstep)}',
                '-p', 'publish_clock:=true', '-p', 'qos_overrides./odom.publisher.depth:=10000']
        for name, value in parameters.items():
            args += ['-p', f'{name}:={_ros_value(value)}']
        handle = SimulatorHandle(start_node(_SIM, args))
        handles.append(handle)
        deadline = time.monotonic() + timeout
        handle._spin_until(lambda: bool(handle.odom), max(0.0, deadline - time.monotonic()),
                           'the first state of attitude_simulator')
        return handle
    yield start
    for handle in handles:
        handle.stop()
