"""
Several hosts on one machine: the latency a network hop adds to a torque command.

Three network namespaces as hosts on a private subnet behind a bridge (made
and removed by test/netns.py; needs root and iproute2): the simulator on one
(1 kHz integration and publishing, real time, no torque timeout), the
analyzer on another, and an operator that sends 200 torque commands 50 ms
apart and times each until the simulator's applied_torque carries it. Two
placements of the operator, alternated three times each: on the simulator's
host (DDS over UDP on that host's loopback) and on a third host (across the
bridge). Discovery runs on the private subnet only, over UDP (no shared
memory between "hosts"). The network's own round trip comes from a Python
UDP echo (1000 datagrams), within one host and between two. ``./dev bench
--only hosts`` (about 3 minutes).
"""

import json
import os
import subprocess
import sys
import textwrap

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
TEST = os.path.join(HERE, '..', 'test')
sys.path.insert(0, TEST)
import netns  # noqa: E402, I100 (after the path set-up)
from nodes import ANALYZER, sim  # noqa: E402
from ros_harness import interrupt  # noqa: E402

OPERATOR = [sys.executable, os.path.join(TEST, 'netns_operator.py'), '--skip-analyzer',
            '--rounds', '200', '--period', '0.05']


ECHO = textwrap.dedent("""
    import socket, sys
    s = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
    s.bind((sys.argv[1], 47001))
    s.settimeout(30.0)
    print('ready', flush=True)
    while True:
        data, peer = s.recvfrom(64)
        s.sendto(data, peer)
        if data == b'end':
            break
""")
CLIENT = textwrap.dedent("""
    import json, socket, sys, time
    s = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
    s.settimeout(1.0)
    trips = []
    for k in range(1000):
        t0 = time.perf_counter()
        s.sendto(b'%d' % k, (sys.argv[1], 47001))
        s.recvfrom(64)
        trips.append(time.perf_counter() - t0)
        time.sleep(0.001)
    s.sendto(b'end', (sys.argv[1], 47001))
    print(json.dumps(trips))
""")


def udp_echo(hosts, source, target):
    """Round trips (s) of 1000 UDP datagrams from host ``source`` to an echo on ``target``."""
    address = hosts.addresses[target]
    echo = hosts.popen(target, [sys.executable, '-c', ECHO, address], stdout=-1, text=True)
    try:
        echo.stdout.readline()
        done = hosts.run(source, [sys.executable, '-c', CLIENT, address])
        return np.array(json.loads(done.stdout))
    finally:
        echo.wait(10.0)


def placement(hosts, operator_host):
    """Round trips (s) with the operator on ``operator_host``."""
    quiet = {'stdout': subprocess.DEVNULL, 'stderr': subprocess.DEVNULL}
    procs = [hosts.popen('sim', sim('publish_rate:=1000.0', 'torque_timeout:=0.0'), **quiet),
             hosts.popen('analyzer', ANALYZER, **quiet)]
    try:
        done = hosts.run(operator_host, OPERATOR, timeout=120)
        if done.returncode != 0:
            raise RuntimeError(done.stdout + done.stderr)
        report = json.loads(done.stdout.strip().splitlines()[-1])
    finally:
        for p in procs:
            interrupt(p)
    return np.array(report['round_trips']), report['odom_rate'], report['rounds']


def measure():
    """Both placements and the ping floor; returns Markdown lines."""
    reason = netns.unavailable()
    if reason:
        return [f'Not measured: {reason}.']
    lines = ['| operator on | answered | p50 (ms) | p99 (ms) | max (ms) | odom received (Hz) |',
             '|---|---|---|---|---|---|']
    labels = {'sim': "the simulator's host (UDP over loopback)",
              'operator': 'another host (across the bridge)'}
    with netns.Hosts(['sim', 'analyzer', 'operator']) as hosts:
        trips = {'sim': [], 'operator': []}
        rates = {'sim': [], 'operator': []}
        rounds = {'sim': 0, 'operator': 0}
        for _ in range(3):
            for host in ('sim', 'operator'):
                got, rate, sent = placement(hosts, host)
                trips[host].extend(got)
                rates[host].append(rate)
                rounds[host] += sent
        udp = {'sim': udp_echo(hosts, 'sim', 'sim'),
               'operator': udp_echo(hosts, 'operator', 'sim')}
    for host in ('sim', 'operator'):
        got = np.array(trips[host])
        lines.append(f'| {labels[host]} | {got.size}/{rounds[host]} | '
                     f'{1e3 * np.percentile(got, 50):.2f} | {1e3 * np.percentile(got, 99):.2f} | '
                     f'{1e3 * got.max():.2f} | {min(rates[host]):.0f} |')
    added = 1e3 * (np.percentile(trips['operator'], 50) - np.percentile(trips['sim'], 50))
    lines += ['', f'Difference of the medians (across the bridge minus the same host, round '
              f'trip command -> state): {added:+.2f} ms.', '',
              '| UDP echo (Python), 1000 datagrams | p50 (ms) | p99 (ms) | max (ms) |',
              '|---|---|---|---|']
    for host in ('sim', 'operator'):
        got = udp[host]
        lines.append(f'| from {labels[host]} | {1e3 * np.percentile(got, 50):.3f} | '
                     f'{1e3 * np.percentile(got, 99):.3f} | {1e3 * got.max():.3f} |')
    return lines
