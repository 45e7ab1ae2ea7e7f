"""
Several hosts: simulator, analyzer and an operator each in a network namespace of its own.

The namespaces are made by the test on a private subnet behind a bridge and
deleted afterwards (test/netns.py); DDS discovery runs on that subnet only
and over UDP, so every message crosses the (virtual) network. Skipped, with
the reason, where network namespaces cannot be made (no root, no iproute2).
"""

import json
import os
import subprocess
import sys

from diagnostic_msgs.msg import DiagnosticStatus
import netns
import numpy as np
import pytest
from rigid_body_dynamics.physics import presets
from ros_harness import interrupt

HERE = os.path.dirname(os.path.abspath(__file__))
SIM = 'rigid_body_dynamics.nodes.simulator'
ANALYZER = 'rigid_body_dynamics.nodes.analyzer'
FLEET = 'rigid_body_dynamics.nodes.fleet'


def made_hosts(names):
    """Make hosts ``names`` on a private subnet (skip where impossible, unless required)."""
    reason = netns.unavailable()
    if reason and os.environ.get('RBD_REQUIRE_NETNS'):
        pytest.fail(f'RBD_REQUIRE_NETNS is set, but no network namespaces here: {reason}')
    if reason:
        pytest.skip(reason)
    return netns.Hosts(names)


@pytest.fixture
def hosts():
    """Make three hosts, sim, analyzer and operator, on a private subnet; removed afterwards."""
    with made_hosts(['sim', 'analyzer', 'operator']) as made:
        yield made


def start(hosts, host, module, log_path, *params, options=()):
    """Start a node in ``host`` with its output in ``log_path`` (``options`` before ROS's)."""
    log = open(log_path, 'w')
    cmd = [sys.executable, '-m', module, *options, '--ros-args']
    for p in params:
        cmd += ['-p', p]
    proc = hosts.popen(host, cmd, stdout=log, stderr=subprocess.STDOUT)
    proc.log_path = log_path
    log.close()
    return proc


def stop(proc):
    """SIGINT; returns (exit code, output). Kills after 10 s."""
    code = interrupt(proc)
    with open(proc.log_path) as f:
        return code, f.read()


def test_simulator_and_analyzer_on_different_hosts(hosts, probe, tmp_path):
    """
    Run the simulator, the analyzer and an operator on three hosts.

    The analyzer estimates the precession of the simulator on another host to
    1e-4; commands from the third host reach the simulator and come back in
    its applied_torque. Nothing of it reaches this machine's own network: a
    node here, in the same domain, never discovers the simulator.
    """
    sim = start(hosts, 'sim', SIM, tmp_path / 'sim.log', 'real_time_factor:=4.0',
                'publish_clock:=true')
    analyzer = start(hosts, 'analyzer', ANALYZER, tmp_path / 'analyzer.log')
    procs = [sim, analyzer]
    try:
        done = hosts.run('operator', [sys.executable, os.path.join(HERE, 'netns_operator.py'),
                                      '--rounds', '30', '--timeout', '60'], timeout=150)
        assert done.returncode == 0, done.stdout + done.stderr
        report = json.loads(done.stdout.strip().splitlines()[-1])
        # discovery stayed on the private subnet (the probe's graph is filled by DDS threads)
        assert probe.node.count_publishers('/odom') == 0
        assert probe.node.count_subscribers('/torque_cmd') == 0
    finally:
        results = [stop(p) for p in procs]
    for code, output in results:
        assert code == 0, output
        assert 'Traceback' not in output

    level, message, values = report['analyzer']['precession']
    assert float(values['body rate error (rel.)']) < 1e-4
    assert float(values['lab rate error (rel.)']) < 1e-4
    level, message, values = report['analyzer']['conservation']
    assert level == ord(DiagnosticStatus.OK), message
    level, message, values = report['analyzer']['input']
    assert values['inertia source'] == 'topic'   # the latched inertia crossed hosts too
    assert float(values['rate (Hz)']) > 100.0
    # 100 Hz of simulated time at 4x real time
    assert report['odom_rate'] == pytest.approx(400.0, rel=0.1)
    trips = sorted(report['round_trips'])
    assert len(trips) >= 0.9 * report['rounds']
    assert trips[len(trips) // 2] < 0.05


def test_one_fleet_split_over_two_hosts(probe, tmp_path):
    """
    Run bodies 1-2 of a fleet on one host and 3-4 on another (two processes each).

    An operator on a third host sees every body by its name, each with the exact free
    motion at its stamps (1e-9 rad) and answering its pause service, as one fleet would.
    """
    names = ['body1', 'body2', 'body3', 'body4']
    top = presets.get('symmetric_top')
    with made_hosts(['fleet_a', 'fleet_b', 'operator']) as hosts:
        procs = [start(hosts, host, FLEET, tmp_path / f'{host}.log', 'publish_rate:=50.0',
                       options=('--bodies', '2', '--first', first, '--processes', '2'))
                 for host, first in (('fleet_a', '1'), ('fleet_b', '3'))]
        try:
            done = hosts.run('operator', [sys.executable, os.path.join(HERE, 'netns_operator.py'),
                                          '--fleet', ','.join(names), '--timeout', '60'],
                             timeout=150)
            assert done.returncode == 0, done.stdout + done.stderr
            report = json.loads(done.stdout.strip().splitlines()[-1])
        finally:
            results = [stop(p) for p in procs]
    for code, output in results:
        assert code == 0, output
        assert 'Traceback' not in output
    assert sorted(report) == names
    for name, (attitude, rate, paused) in report.items():
        assert attitude < 1e-9 and rate < 1e-9 * np.linalg.norm(top.omega0), (name, attitude, rate)
        assert paused, name
