"""
A small ROS client for tools and tests: a private context, one node, waits with deadlines.

Used by the report's recorder, the demo, the test harness and the benchmarks,
so that none of them writes its own context set-up, spin loop or teardown.
Also starts a package node as its own process (``python -m``, as a user
would) and interrupts it as Ctrl-C does.
"""

import os
import signal
import subprocess
import sys
import time

import rclpy
from rclpy.context import Context
from rclpy.executors import SingleThreadedExecutor

#: Longest single wait for work inside the spin loops (s).
SPIN_SLICE = 0.02


class WaitTimeout(AssertionError):
    """A wait ran past its deadline; the message says what was awaited."""


class RosClient:
    """
    One rclpy node in a context of its own, spun on the caller's thread.

    ``name``: the node name. Use as a context manager, or call :meth:`close`.
    """

    def __init__(self, name):
        self.context = Context()
        rclpy.init(context=self.context)
        self.node = rclpy.create_node(name, context=self.context)
        self.executor = SingleThreadedExecutor(context=self.context)
        self.executor.add_node(self.node)

    def __enter__(self):
        """Return the client."""
        return self

    def __exit__(self, *_exc):
        """Tear everything down."""
        self.close()

    def spin_until(self, predicate, timeout, what='condition'):
        """Spin until ``predicate()`` holds; WaitTimeout naming ``what`` after ``timeout`` s."""
        deadline = time.monotonic() + timeout
        while not predicate():
            if time.monotonic() > deadline:
                raise WaitTimeout(f'timed out after {timeout} s waiting for {what}')
            self.executor.spin_once(timeout_sec=SPIN_SLICE)

    def spin_for(self, seconds):
        """Spin for a fixed time (s)."""
        deadline = time.monotonic() + seconds
        while time.monotonic() < deadline:
            self.executor.spin_once(timeout_sec=SPIN_SLICE)

    def close(self):
        """Tear down executor, node and context."""
        self.executor.shutdown()
        self.node.destroy_node()
        rclpy.try_shutdown(context=self.context)


def start_node(module, ros_args=(), **popen):
    """
    Start ``rigid_body_dynamics.nodes.<module>`` (or a full module path) as its own process.

    ``ros_args`` go after ``--ros-args``; the environment is this process'
    (ROS_DOMAIN_ID, discovery range, log folder). Returns the Popen.
    """
    if '.' not in module:
        module = f'rigid_body_dynamics.nodes.{module}'
    popen.setdefault('env', os.environ.copy())
    return subprocess.Popen([sys.executable, '-m', module, '--ros-args', *ros_args], **popen)


def interrupt(proc, timeout=10.0):
    """
    SIGINT a process (as Ctrl-C does) and wait; its exit code.

    One still running after ``timeout`` s is killed with :func:`dump_and_kill`, so its
    output says where each of its threads was.
    """
    if proc.poll() is None:
        proc.send_signal(signal.SIGINT)
        try:
            proc.wait(timeout)
        except subprocess.TimeoutExpired:
            dump_and_kill(proc)
    return proc.returncode


def dump_and_kill(proc, grace=1.0):
    """
    Have a stuck package process print its threads' stacks (SIGUSR1), then SIGKILL it.

    Every node registers SIGUSR1 with faulthandler (``runner.run``), which writes the
    Python stack of each thread to stderr at once, whatever the interpreter is doing.
    ``grace``: seconds given to the dump before the kill. Returns the exit code.
    """
    try:
        proc.send_signal(signal.SIGUSR1)
        proc.wait(grace)
    except subprocess.TimeoutExpired:
        pass
    if proc.poll() is None:
        proc.kill()
    return proc.wait(5.0)
