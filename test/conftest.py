"""Shared fixtures: reference solutions, a ROS domain per session, node processes."""

import os

import numpy as np
import pytest
from rigid_body_dynamics.physics import quaternions
from rigid_body_dynamics.physics.dynamics.equations import state_rhs
from scipy.integrate import solve_ivp


def dop853_reference(moments, omega0, q0, times, rtol=2.5e-14, torque=(0.0, 0.0, 0.0)):
    """
    Return the reference (q, omega) at ``times`` from scipy's DOP853 at tight tolerance.

    At the default rtol 2.5e-14 (near scipy's floor of 100 eps) the reference
    is good to about 1e-12 rad over 25 s at |omega| = 6 rad/s; at rtol 1e-13
    its own error reaches 4e-12 there (measured against rtol 2.3e-14).

    moments in the body-axis order (principal frame), omega0 body rad/s, q0
    x-y-z-w body -> world, constant body torque.
    """
    y0 = np.concatenate([np.asarray(omega0, dtype=float), np.asarray(q0, dtype=float)])
    scale = max(np.linalg.norm(omega0), 1e-12)
    atol = np.array([rtol * scale] * 3 + [rtol] * 4)
    sol = solve_ivp(lambda _t, y: state_rhs(moments, y, torque), (0.0, float(np.max(times))), y0,
                    method='DOP853', rtol=rtol, atol=atol, t_eval=times)
    assert sol.success
    return quaternions.normalize(sol.y[3:].T), sol.y[:3].T


@pytest.fixture
def rng():
    """Return a seeded generator, so that tests are deterministic."""
    return np.random.default_rng(20261123)


def random_attitude(rng):
    """Return a random unit quaternion (x, y, z, w)."""
    q = rng.normal(size=4)
    return q / np.linalg.norm(q)


@pytest.fixture(scope='session', autouse=True)
def ros_domain(ros_isolation):
    """
    Reserve a free ROS_DOMAIN_ID for this session and keep DDS on this machine.

    The package's own pytest plugin (rigid_body_dynamics.testing, the fixture
    users get) sets the environment every node process inherits and that this
    process's rclpy contexts read: ROS_DOMAIN_ID, localhost-only discovery,
    and ROS_LOG_DIR in a temporary folder.
    """
    return ros_isolation


@pytest.fixture
def probe():
    """Give the test an rclpy node in its own Context, torn down after the test."""
    from ros_harness import Probe
    p = Probe()
    yield p
    p.close()


@pytest.hookimpl(hookwrapper=True)
def pytest_runtest_makereport(item, call):
    """Keep each phase's report on the test item (the launch fixture reads the call's)."""
    outcome = yield
    report = outcome.get_result()
    setattr(item, f'report_{report.when}', report)


#: Lines of each node's output shown when a test that launched it failed.
LOG_TAIL = 60


@pytest.fixture
def launch(tmp_path, request):
    """
    Start node processes: call the fixture with a module, ros args, a name (and env additions).

    Every process still running at the end of the test is stopped with SIGINT. A process
    the test neither stopped nor waited for must then have exited 0 with no traceback in
    its output (a node that crashed, or did not end cleanly on SIGINT, fails the test that
    passed). When the test failed, the end of each node's output is printed (the report's
    teardown output), since the temporary folder holding it is not kept.
    """
    from ros_harness import NodeProcess
    started = []

    def start(module, *ros_args, name='node', env=None):
        proc = NodeProcess(module, ros_args, log_dir=str(tmp_path), name=name, env=env)
        started.append(proc)
        return proc
    yield start
    unclean = []
    for proc in started:
        if proc.handled:
            continue
        code = proc.stop()[0] if proc.proc.poll() is None else proc.proc.returncode
        if code != 0 or 'Traceback' in proc.output():
            unclean.append(f'{proc.log_path}: exit code {code}')
    report = getattr(request.node, 'report_call', None)
    failed = report is not None and report.failed
    if failed or unclean:
        for proc in started:
            lines = proc.output().splitlines()[-LOG_TAIL:]
            print(f'--- {proc.log_path} (last {len(lines)} lines) ---', *lines, sep='\n')
    if unclean and not failed:
        pytest.fail('a node did not end cleanly (exit 0, no traceback): ' + '; '.join(unclean))


@pytest.fixture(scope='session')
def tf2_msgs_env():
    """
    Build the tf2_msgs interface once per venv (test/tf2_msgs_build.py); its environment.

    Returns the variables a process needs to import it. Where it cannot be
    built the test is skipped with the reason, unless RBD_REQUIRE_TF2_MSGS is
    set (.ci/run sets it: CI must build it).
    """
    import tf2_msgs_build
    try:
        prefix = tf2_msgs_build.build()
    except (tf2_msgs_build.BuildError, OSError) as err:
        if os.environ.get('RBD_REQUIRE_TF2_MSGS'):
            pytest.fail(f'tf2_msgs interface could not be built: {err}')
        pytest.skip(f'tf2_msgs interface could not be built here: {err}')
    return tf2_msgs_build.environment(prefix)
