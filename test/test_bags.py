"""
Bags: rosbag2 (MCAP and sqlite3) and bare MCAP files through rigid_body_analyze.

Bags are written by rosbags (the package's BagWriter) and by an independent
writer (mcap-ros2-support, definitions from the message wheels' .msg files),
and recorded from the live nodes; the findings are checked against the same
analysis of the source samples, against the live analyzer on the same
stamps, and hostile bags give one-line errors or counted drops.
"""

import json
import os
import subprocess
import sys

from bag_writers import rosbags_messages, write_mcap_ros2, write_rosbags
import numpy as np
import pytest
from rigid_body_dynamics.messages import bags, cdr
from rigid_body_dynamics.physics import presets, quaternions, simulate
from rigid_body_dynamics.physics.analysis import analyse, Trajectory

EPOCH_2026 = 1_764_547_200_000_000_000
TENSOR_123 = [1.0, 2.0, 3.0, 0.0, 0.0, 0.0]


def analyze(*args, timeout=120):
    """Run rigid_body_analyze as a user does; returns (exit code, stdout, stderr)."""
    out = subprocess.run([sys.executable, '-m', 'rigid_body_dynamics.tools.analyze',
                          *map(str, args)], capture_output=True, text=True, timeout=timeout)
    return out.returncode, out.stdout, out.stderr


@pytest.fixture(scope='module')
def racket():
    """Tennis racket, 40 s at 100 Hz, stamped from 2026 (absolute ns)."""
    body = presets.get('tennis_racket')
    run = simulate(body.moments, body.omega0, body.q0, duration=40.0, dt=1e-2)
    return EPOCH_2026 + np.round(run.t * 1e9).astype(np.int64), run


def reference(t_ns, run):
    return analyse(Trajectory.from_samples(t_ns, run.q, run.omega, run.inertia))


@pytest.mark.parametrize('writer', ['rosbags-mcap', 'rosbags-sqlite3', 'mcap-ros2'])
def test_bags_from_two_writers_give_the_analysis_of_their_samples(writer, racket, tmp_path):
    t_ns, run = racket
    if writer == 'mcap-ros2':
        path = write_mcap_ros2(tmp_path / 'run.mcap', t_ns, run.q, run.omega, TENSOR_123)
    else:
        path = write_rosbags(tmp_path / 'run', rosbags_messages(t_ns, run.q, run.omega,
                                                                TENSOR_123),
                             writer.split('-')[1])
    code, out, err = analyze(path, '--json')
    assert code == 0, err
    got, want = json.loads(out), reference(t_ns, run).to_dict()
    assert got['samples'] == want['samples'] == t_ns.size
    assert got['bag']['first_stamp_ns'] == int(t_ns[0])
    for section, key in (('precession', 'lab_rate'), ('precession', 'omega_period'),
                         ('stability', 'flip_interval'), ('stability', 'growth_rate')):
        assert got[section][key] == pytest.approx(want[section][key], rel=1e-12), key
        assert got[section][f'{key}_theory'] == pytest.approx(want[section][f'{key}_theory'],
                                                              rel=1e-12)
    assert got['stability']['axis'] == 2 and got['stability']['class'] == 'unstable'
    assert got['stability']['status'] == 'WARN' and got['conservation']['status'] == 'OK'
    # the text form says the same, beside theory
    code, out, _ = analyze(path)
    assert code == 0 and 'flip interval (s)' in out and 'theory +10.977572' in out


def test_fast_cdr_fields_equal_rosbags_deserialiser(racket, tmp_path):
    """cdr.py against rosbags on the same raw messages, uniform and mixed frame ids."""
    t_ns, run = racket
    messages = rosbags_messages(t_ns[:50], run.q[:50], run.omega[:50], TENSOR_123,
                                torque=run.omega[:50] * 0.1)
    store = bags._typestore()
    odom = [raw for topic, _, raw in messages if topic == 'odom']
    t, q, w, world, child = cdr.odometry_arrays(odom)
    decoded = [store.deserialize_cdr(raw, bags.ODOMETRY) for raw in odom]
    assert (world, child) == ('odom', 'base_link')
    assert t.tolist() == [m.header.stamp.sec * 10 ** 9 + m.header.stamp.nanosec for m in decoded]
    np.testing.assert_array_equal(q, [[m.pose.pose.orientation.x, m.pose.pose.orientation.y,
                                       m.pose.pose.orientation.z, m.pose.pose.orientation.w]
                                      for m in decoded])
    np.testing.assert_array_equal(w, [[m.twist.twist.angular.x, m.twist.twist.angular.y,
                                       m.twist.twist.angular.z] for m in decoded])
    wrench = [raw for topic, _, raw in messages if topic == 'applied_torque']
    t2, tau, frame = cdr.wrench_arrays(wrench)
    np.testing.assert_array_equal(tau, run.omega[:50] * 0.1)
    assert frame == 'base_link' and t2.tolist() == t.tolist()
    # child frames of different lengths in one batch: not uniform, so rosbags decodes them
    other = rosbags_messages(t_ns[:3], run.q[:3], run.omega[:3], TENSOR_123, child='base')
    with pytest.raises(cdr.NotUniform):
        cdr.odometry_arrays(odom[:3] + [raw for topic, _, raw in other if topic == 'odom'])
    mixed = [m for m in messages if m[0] != 'odom'] + [
        m for m in messages if m[0] == 'odom'][:25] + [m for m in other if m[0] == 'odom']
    path = write_rosbags(tmp_path / 'mixed', sorted(mixed, key=lambda m: m[1]))
    traj, info = bags.read_trajectory(path)
    assert len(traj) == 25 and info.dropped.get('odom in another frame') == 3


def test_world_frame_twists_are_rotated_and_other_frames_dropped(racket, tmp_path):
    t_ns, run = racket
    w_world = quaternions.rotate(run.q, run.omega)
    path = write_rosbags(tmp_path / 'world', rosbags_messages(t_ns, run.q, w_world, TENSOR_123,
                                                              child='odom'))
    traj, _ = bags.read_trajectory(path)
    np.testing.assert_allclose(traj.omega, run.omega, atol=1e-14)
    path = write_rosbags(tmp_path / 'imu', rosbags_messages(t_ns, run.q, run.omega, TENSOR_123,
                                                            child='imu_link'))
    code, _, err = analyze(path)
    assert code == 2 and 'no usable' in err and len(err.splitlines()) == 1


def test_hostile_bags_give_one_line_errors(racket, tmp_path):
    t_ns, run = racket
    good = write_rosbags(tmp_path / 'good', rosbags_messages(t_ns, run.q, run.omega, TENSOR_123))
    mcap = good / 'good.mcap'
    cases = {
        'missing': (tmp_path / 'nothing-here', 'no such file'),
        'garbage': (tmp_path / 'garbage.mcap', 'not a readable rosbag2 bag or MCAP file'),
        'truncated': (tmp_path / 'truncated.mcap', ''),
        'empty folder': (tmp_path / 'empty', 'not a readable'),
    }
    (tmp_path / 'garbage.mcap').write_bytes(b'\x89MCAP0\r\n' + os.urandom(3000))
    (tmp_path / 'truncated.mcap').write_bytes(mcap.read_bytes()[:mcap.stat().st_size // 2])
    (tmp_path / 'empty').mkdir()
    for name, (path, text) in cases.items():
        code, out, err = analyze(path)
        assert code == 2, (name, out, err)
        assert 'Traceback' not in err and len(err.strip().splitlines()) == 1, (name, err)
        assert text in err, (name, err)
    # wrong type, missing topic, no inertia
    code, _, err = analyze(good, '--odom-topic', 'inertia')
    assert code == 2 and 'is geometry_msgs/msg/InertiaStamped, not nav_msgs/msg/Odometry' in err
    code, _, err = analyze(good, '--odom-topic', '/sat9/odom')
    assert code == 2 and "no topic '/sat9/odom'" in err
    bare = write_rosbags(tmp_path / 'bare', [m for m in rosbags_messages(
        t_ns, run.q, run.omega, TENSOR_123) if m[0] != 'inertia'])
    code, _, err = analyze(bare)
    assert code == 2 and '--inertia' in err
    code, out, _ = analyze(bare, '--inertia', 1, 2, 3)
    assert code == 0 and 'inertia from argument' in out
    code, _, err = analyze(bare, '--inertia', 1, 1, 3)
    assert code == 2 and 'triangle' in err


def test_nan_duplicated_reordered_samples_and_a_reset(racket, tmp_path):
    """Counted drops, stamp order restored, and the segment after a reset analysed."""
    t_ns, run = racket
    messages = rosbags_messages(t_ns, run.q, run.omega, TENSOR_123)
    odom = [m for m in messages if m[0] == 'odom']
    store = bags._typestore()
    bad = store.deserialize_cdr(odom[10][2], bags.ODOMETRY)
    bad.pose.pose.orientation.w = float('nan')
    odom[10] = ('odom', odom[10][1], store.serialize_cdr(bad, bags.ODOMETRY))
    rng = np.random.default_rng(5)
    shuffled = []
    duplicates = 0
    for i in range(0, len(odom), 7):                       # reordered in blocks of 7
        block = odom[i:i + 7]
        shuffled += [block[k] for k in rng.permutation(len(block))]
        if i % 70 == 0:                                    # and now and then a duplicate
            shuffled.append(block[-1])
            duplicates += 1
    # then the source restarts from its initial state, stamps back at the start
    restart = rosbags_messages(t_ns[:500] - t_ns[0] + EPOCH_2026 - 10 ** 9, run.q[:500],
                               run.omega[:500], TENSOR_123)
    # recorded in this order (log times increase; header stamps do not)
    shuffled = [(topic, int(t_ns[0]) + i * 10 ** 7, raw) for i, (topic, _, raw)
                in enumerate(shuffled)]
    path = write_rosbags(tmp_path / 'messy', [messages[0]] + shuffled)
    traj, info = bags.read_trajectory(path)
    assert duplicates > 50 and info.odom_messages == len(odom) + duplicates
    assert len(traj) == len(odom) - 1 and info.dropped['non-finite or zero quaternion'] == 1
    assert np.all(np.diff(traj.t_ns) > 0)
    want = reference(t_ns, run)
    got = analyse(traj)
    assert got.stability.flip_interval.measured == pytest.approx(
        want.stability.flip_interval.measured, rel=1e-9)
    # recorded after the first run: receive (log) times go on, header stamps went back
    later = int(t_ns[-1] - restart[1][1]) + 10 ** 7
    reset = write_rosbags(tmp_path / 'reset', [messages[0]] + odom + [
        (topic, t + later, raw) for topic, t, raw in restart if topic == 'odom'])
    code, out, err = analyze(reset, '--json')
    assert code == 0, err
    got = json.loads(out)
    assert got['bag']['segments'] == 2 and got['samples'] == 500
    assert got['bag']['first_stamp_ns'] == EPOCH_2026 - 10 ** 9
    code, out, _ = analyze(reset)
    assert '2 segments after resets or gaps: the last analysed' in out


def test_start_end_cut_the_samples(racket, tmp_path):
    t_ns, run = racket
    path = write_rosbags(tmp_path / 'cut', rosbags_messages(t_ns, run.q, run.omega, TENSOR_123))
    code, out, _ = analyze(path, '--start', 10, '--end', 30, '--json')
    got = json.loads(out)
    assert code == 0 and got['samples'] == 2001 and got['span_s'] == pytest.approx(20.0)
    assert got['bag']['first_stamp_ns'] == int(t_ns[1000])


def test_live_analyzer_and_rigid_body_analyze_agree_on_the_same_stamps(launch, probe, tmp_path):
    """
    Compare the live analyzer with rigid_body_analyze on one window of a recorded bag.

    The nodes run; rigid_body_report --record writes a bag meanwhile; for an analysis tick whose
    window lies inside the bag, rigid_body_analyze on that window's stamps gives the analyzer's
    rates to 1e-9.
    """
    from diagnostic_msgs.msg import DiagnosticArray
    from rigid_body_dynamics.ros.conversions import status_values
    sim = launch('rigid_body_dynamics.nodes.simulator', '-p', 'publish_clock:=true',
                 '-p', 'real_time_factor:=4.0', name='sim')
    analyzer = launch('rigid_body_dynamics.nodes.analyzer', '-p', 'window:=4.0', name='analyzer')
    arrays = probe.subscribe(DiagnosticArray, '/diagnostics')
    probe.wait_for('/diagnostics', 1, timeout=30.0)
    bag = tmp_path / 'live'
    recorder = subprocess.Popen([sys.executable, '-m', 'rigid_body_dynamics.tools.report',
                                 '--record', str(bag), '--duration', '12', '--out',
                                 str(tmp_path / 'r')],
                                stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
    probe.spin_until(lambda: recorder.poll() is not None, 90.0, 'the recording')
    assert recorder.returncode == 0, recorder.stdout.read()
    traj, _ = bags.read_trajectory(bag)
    first, last = traj.origin_ns + int(traj.t_ns[0]), traj.origin_ns + int(traj.t_ns[-1])
    compared = 0
    for array in reversed(arrays):
        found = {st.name.split(': ', 1)[1]: status_values(st) for st in array.status
                 if st.name.startswith('attitude_analyzer: ')}
        window = found.get('input', {})
        pre = found.get('precession', {})
        if 'window first stamp (ns)' not in window or 'body rate, measured (rad/s)' not in pre:
            continue
        a, b = int(window['window first stamp (ns)']), int(window['window last stamp (ns)'])
        if a < first or b > last:
            continue
        code, out, err = analyze(bag, '--start', (a - first) / 1e9, '--end', (b - first) / 1e9,
                                 '--json')
        assert code == 0, err
        got = json.loads(out)
        assert got['bag']['first_stamp_ns'] == a
        for key, label in (('body_rate', 'body rate'), ('lab_rate', 'lab rate')):
            assert got['precession'][key] == pytest.approx(
                float(pre[f'{label}, measured (rad/s)']), rel=1e-9)
            assert got['precession'][f'{key}_theory'] == pytest.approx(
                float(pre[f'{label}, theory (rad/s)']), rel=1e-12)
        compared += 1
        if compared == 3:
            break
    assert compared >= 1, 'no analysis window inside the recorded bag'
    for proc in (analyzer, sim):
        assert proc.stop()[0] == 0
