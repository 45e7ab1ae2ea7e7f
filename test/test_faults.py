"""
Faults (issue 6): signals at any moment, a crashed analyzer, a restarted simulator.

Node processes killed with SIGKILL here use UDP only
(FASTDDS_BUILTIN_TRANSPORTS=UDPv4), so they leave no Fast DDS shared-memory
files behind in /dev/shm.
"""

import os
import signal
import subprocess
import sys
import time

from diagnostic_msgs.msg import DiagnosticArray, DiagnosticStatus
import pytest

SCRIPTS = os.path.join(sys.prefix, 'lib', 'rigid_body_dynamics')


@pytest.mark.skipif(not os.path.exists(os.path.join(SCRIPTS, 'attitude_simulator')),
                    reason='console scripts not installed (run ./dev setup)')
@pytest.mark.parametrize('delay', [0.15, 0.3, 0.5, 0.8, 1.2, 2.0])
def test_signal_at_any_moment_exits_zero_without_traceback(delay, tmp_path):
    """SIGINT or SIGTERM during imports, start-up or running: exit 0, no traceback."""
    for name, sig in (('attitude_simulator', signal.SIGINT), ('attitude_analyzer',
                                                              signal.SIGTERM)):
        log = open(tmp_path / f'{name}.log', 'w')
        proc = subprocess.Popen([os.path.join(SCRIPTS, name)], stdout=log,
                                stderr=subprocess.STDOUT)
        time.sleep(delay)
        proc.send_signal(sig)
        code = proc.wait(15.0)
        log.close()
        output = open(tmp_path / f'{name}.log').read()
        assert code == 0 and 'Traceback' not in output, f'exit code {code}:\n{output}'


def test_analyzer_crash_and_simulator_restart(launch, probe, monkeypatch):
    """A killed analyzer restarts and recovers; a restarted simulator is detected."""
    monkeypatch.setenv('FASTDDS_BUILTIN_TRANSPORTS', 'UDPv4')
    sim = launch('rigid_body_dynamics.nodes.simulator', '-p', 'publish_clock:=true',
                 '-p', 'real_time_factor:=4.0', name='sim')
    analyzer = launch('rigid_body_dynamics.nodes.analyzer', '-p', 'window:=4.0',
                      name='analyzer')
    probe.subscribe(DiagnosticArray, '/diagnostics')

    def good_estimate():
        found = probe.newest_status('attitude_analyzer: precession')
        return found is not None and 'body rate error (rel.)' in found[2] and \
            float(found[2]['body rate error (rel.)']) < 1e-6
    probe.spin_until(good_estimate, 40.0, 'estimates')
    analyzer.kill()                                      # a crash: no clean shutdown
    analyzer.proc.wait(5.0)
    probe.messages['/diagnostics'].clear()
    analyzer = launch('rigid_body_dynamics.nodes.analyzer', '-p', 'window:=4.0',
                      name='analyzer2')
    probe.spin_until(good_estimate, 40.0, 'estimates from the restarted analyzer')
    # the latched inertia was read again
    assert probe.newest_status('attitude_analyzer: input')[2]['inertia source'] == 'topic'
    # now the simulator restarts under the running analyzer: its stamps go back to 0
    code, _ = sim.stop()
    assert code == 0
    sim = launch('rigid_body_dynamics.nodes.simulator', '-p', 'publish_clock:=true',
                 '-p', 'real_time_factor:=4.0', name='sim2')

    def resets():
        found = probe.newest_status('attitude_analyzer: input')
        return int(found[2]['restarts after a time reset']) if found else 0
    probe.spin_until(lambda: resets() >= 1, 40.0, 'the time reset to be detected')
    probe.messages['/diagnostics'].clear()
    probe.spin_until(good_estimate, 40.0, 'estimates after the simulator restart')
    level, _, _ = probe.newest_status('attitude_analyzer: conservation')
    assert level == DiagnosticStatus.OK
    for proc in (analyzer, sim):
        code, _ = proc.stop()
        assert code == 0, proc.output()


def test_a_node_that_does_not_stop_says_where_it_is_before_it_is_killed(
        launch, probe, monkeypatch):
    """
    dump_and_kill: SIGUSR1 makes a running node print each thread's stack, then SIGKILL.

    The fleet's parent does this to a worker that does not exit after the stop, and the test
    harness to a node; the stacks name the integration thread and the executor.
    """
    from nav_msgs.msg import Odometry
    from rcl_interfaces.srv import ListParameters
    from rigid_body_dynamics.ros.client import dump_and_kill
    monkeypatch.setenv('FASTDDS_BUILTIN_TRANSPORTS', 'UDPv4')     # SIGKILL: no shm left
    sim = launch('rigid_body_dynamics.nodes.simulator', name='sim')
    probe.subscribe(Odometry, '/odom')
    # Running, both threads: the first odom is published from __init__ (the initial state),
    # the second by the integration thread, and a parameter service answers from the executor.
    probe.wait_for('/odom', count=2)
    probe.call(ListParameters, '/attitude_simulator/list_parameters', ListParameters.Request())
    sim.handled = True                  # killed on purpose
    assert dump_and_kill(sim.proc) == -signal.SIGKILL
    output = sim.output()
    assert output.count('Thread 0x') + output.count('Current thread 0x') == 3, output
    for where in ('in integration_loop', 'in spin\n', 'in _spin'):
        assert where in output, output


def test_a_second_signal_during_the_first_ones_stop_does_not_deadlock():
    """
    The handler takes no lock: a signal arriving inside a stop in progress returns at once.

    A fleet worker got SIGINT from its parent and SIGTERM from its closed lifeline at once;
    the second handler ran inside the first's Event.set(), waited for the lock that set()
    held, and the worker never exited. Here the lock is held as set() holds it.
    """
    from rigid_body_dynamics.ros.runner import Stop
    stop = Stop()
    with stop._event._cond:                  # inside Event.set(), as the second signal came
        stop.on_signal(signal.SIGTERM, None)
    assert stop.is_set() and stop.wait(0.0)
