"""
Run the benchmarks and rewrite benchmarks/RESULTS.md.

``./dev bench`` (full: 1e6 steps) or ``./dev bench --quick`` (1e5 steps);
``--peers`` adds MuJoCo and Basilisk if installed
(``.venv/bin/pip install -r benchmarks/requirements-peers.txt``);
``--nodes`` measures the simulator node as a process (CPU, rates, latency);
``--only nodes`` skips the physics sections; ``--only torque`` runs the
torque section alone (with ``--peers``: MuJoCo and Basilisk too); ``--only soak |
soak-rt | flood | bodies | bodies-asymmetric | hosts | analyzer-memory | bag | lockstep |
latency | publish | flow-batch | estimation | discovery | late-steps |
bodies-wheels | fleet-check | campaign``
runs one reliability / scale measurement (see each script).
Sections from other benchmark scripts (nodes) are kept: each section sits
between ``<!-- NAME -->`` and ``<!-- /NAME -->`` markers and only the sections
run now are replaced.
"""

import argparse
import os
import re
import subprocess
import sys

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)

import accuracy  # noqa: E402
import common  # noqa: E402
import peers  # noqa: E402
import torque  # noqa: E402

RESULTS = os.path.join(HERE, 'RESULTS.md')


def replace_section(text, name, body):
    """Put ``body`` between the markers of section ``name`` (appended if absent)."""
    block = f'<!-- {name} -->\n{body.strip()}\n<!-- /{name} -->'
    pattern = re.compile(rf'<!-- {name} -->.*?<!-- /{name} -->', re.S)
    if pattern.search(text):
        return pattern.sub(lambda _m: block, text)
    return text.rstrip() + '\n\n' + block + '\n'


def main():
    """Measure and write RESULTS.md."""
    parser = argparse.ArgumentParser(description='rigid_body_dynamics benchmarks')
    parser.add_argument('--quick', action='store_true', help='1e5 steps instead of 1e6')
    parser.add_argument('--peers', action='store_true', help='also MuJoCo and Basilisk')
    parser.add_argument('--nodes', action='store_true', help='also the simulator node')
    parser.add_argument('--only', choices=['nodes', 'torque', 'soak', 'soak-rt', 'flood',
                                           'bodies', 'hosts', 'analyzer-memory', 'bag',
                                           'lockstep', 'bodies-asymmetric', 'latency',
                                           'publish', 'flow-batch', 'command-path',
                                           'simulate-cost', 'wheels', 'wheels-node',
                                           'environment', 'environment-node', 'estimation',
                                           'discovery', 'late-steps', 'bodies-wheels',
                                           'fleet-check', 'surface', 'campaign'],
                        help='run only this section')
    args = parser.parse_args()
    steps = 100_000 if args.quick else 1_000_000
    machine = common.machine()
    sections = {}

    if args.only == 'torque':
        torque_section(sections, machine, args.peers)
    elif args.only in ('soak', 'soak-rt'):
        soak_section(sections, machine, real_time=args.only == 'soak-rt')
    elif args.only in SCALE:
        scale_section(sections, machine, args.only)
    else:
        if args.only == 'nodes':
            args.nodes = True
        else:
            physics_sections(sections, steps, machine, args.peers)
        if args.nodes:
            node_section(sections, machine, args.quick)
    write(sections)


def _own_domain():
    """Keep DDS on this machine, in a domain id of our own."""
    from domain_coordinator import domain_id
    os.environ['ROS_AUTOMATIC_DISCOVERY_RANGE'] = 'LOCALHOST'
    os.environ.pop('ROS_LOCALHOST_ONLY', None)
    return domain_id()


def soak_section(sections, machine, real_time=False):
    """Soak both nodes for 1e7 steps and record memory, drift and missed deadlines."""
    import soak
    print(f'soak (about {17 if real_time else 5} minutes) ...', flush=True)
    with _own_domain() as domain:
        os.environ['ROS_DOMAIN_ID'] = str(domain)
        lines = soak.measure(real_time=real_time)
    if real_time:
        header = ['## Soak in real time: 1e7 steps at 10 kHz with both nodes', '',
                  f'Measured {machine}; see the soak section above for the set-up.', '']
        sections['soak-rt'] = '\n'.join(header + lines)
        return
    header = ['## Soak: 1e7 steps with both nodes', '', f'Measured {machine}.', '',
              soak.__doc__.strip().replace('\n', ' '), '']
    sections['soak'] = '\n'.join(header + lines)


#: Sections measured by one script each: name -> (module, heading).
SCALE = {
    'flood': ('flood', 'Torque-command flood: 10 kHz for 10 s'),
    'bodies': ('bodies', 'Many bodies on one machine'),
    'hosts': ('hosts', 'Several hosts: network namespaces on one machine'),
    'analyzer-memory': ('analyzer_memory', 'Analyzer memory when fed faster than real time'),
    'bag': ('bag_speed', 'rigid_body_analyze on a bag of 1e6 Odometry messages'),
    'lockstep': ('lockstep', 'Lockstep closed loop: throughput and period'),
    'bodies-asymmetric': ('bodies_asymmetric', 'Many asymmetric bodies in fleets'),
    'latency': ('latency', 'Torque command to published state, against the relay floor'),
    'publish': ('publish', 'Publishing serialised state'),
    'flow-batch': ('flow_batch', 'The exact flow one time at a time and over arrays'),
    'command-path': ('command_path', 'The command path in the engine, before and after'),
    'simulate-cost': ('simulate_cost', 'simulate() with a callable torque across the separatrix'),
    'wheels': ('wheels', 'Reaction wheels beside Basilisk'),
    'wheels-node': ('wheels_node', 'attitude_simulator with reaction wheels: CPU'),
    'environment': ('environment', 'A satellite in orbit beside Basilisk'),
    'environment-node': ('environment_node', 'attitude_simulator in orbit: CPU'),
    'surface': ('surface', "The air's drag on a CubeSat's facets beside Basilisk"),
    'estimation': ('estimation', "The estimator's sensors and the example MEKF"),
    'discovery': ('discovery', 'DDS discovery time and the number of participants'),
    'bodies-wheels': ('bodies_wheels', 'Many bodies with reaction wheels in fleets'),
    'late-steps': ('late_steps', 'Late steps in one fleet process, and what they waited for'),
    'fleet-check': ('fleet_check', '96 asymmetric bodies at the defaults, watched'),
    'campaign': ('campaign', 'A Monte Carlo campaign of 1000 runs on Dask'),
}


def scale_section(sections, machine, name):
    """Run one of the reliability / scale scripts in a DDS domain of its own."""
    import importlib
    module_name, heading = SCALE[name]
    module = importlib.import_module(module_name)
    print(f'{name} ...', flush=True)
    with _own_domain() as domain:
        os.environ['ROS_DOMAIN_ID'] = str(domain)
        lines = module.measure()
    header = [f'## {heading}', '', f'Measured {machine}.', '',
              module.__doc__.strip().replace('\n', ' '), '']
    sections[name] = '\n'.join(header + lines)


def node_section(sections, machine, quick):
    """Measure attitude_simulator as a process, in a DDS domain of its own on this machine."""
    import nodes
    print('nodes ...', flush=True)
    with _own_domain() as domain:
        os.environ['ROS_DOMAIN_ID'] = str(domain)
        lines = nodes.measure(quick)
    header = ['## attitude_simulator as a process', '', f'Measured {machine}.', '',
              nodes.__doc__.strip().replace('\n', ' '), '']
    sections['nodes'] = '\n'.join(header + lines)


def torque_section(sections, machine, with_peers):
    """Accuracy against cost under a held torque (T1, T2), with the peers if asked."""
    print('under torque ...', flush=True)
    tables = torque.measure(peers=with_peers)
    body = ['## Under a held torque: accuracy against cost', '',
            f'Measured {machine}.', '', torque.__doc__.strip().replace('\n', ' ')]
    for case, rows in tables.items():
        body += ['', f'### {case}', '',
                 common.table(['method', 'dt (ms)', 'attitude (rad, max)',
                               'omega (rel., max)', 'ms per sim. s',
                               'cost / plain RK4 at 1 ms', 'T - T0 - W (rel.)'], rows)]
        cost = {(row[0], row[1]): float(row[4]) for row in rows if row[4]}
        ratio = cost[('ours `exact`', '1')] / cost[('ours `rk4`', '1')]
        body += ['', f'Per step at 1 ms, `exact` costs {ratio:.2f}x our `rk4`.']
        basilisk = cost.get(('Basilisk 2.12.1 RKF78', '10'))
        if basilisk:
            body[-1] += (f' At 10 ms `exact` costs 1/{basilisk / cost[("ours `exact`", "10")]:.0f}'
                         ' of Basilisk RKF78 at 10 ms.')
    sections['physics-torque'] = '\n'.join(body)


def physics_sections(sections, steps, machine, with_peers):
    """Accuracy, torque and (optionally) peer sections."""
    print(f'accuracy and cost, {steps} steps per integrator ...', flush=True)
    rows = accuracy.measure(steps)
    sections['physics-accuracy'] = '\n'.join([
        '## Free rigid body: accuracy against cost',
        '',
        f'Measured {machine}; {steps:.0e} steps at 1 kHz ({steps / 1000:g} s).',
        '',
        accuracy.__doc__.strip().replace('\n', ' '),
        '',
        common.table(['integrator', 'us/step (1 ms)', 's per sim. s (1 ms)',
                      's per sim. s (10 ms)', 'cost / scipy RK45', 'energy (rel.)',
                      '\\|L\\| (rel.)', 'L_w direction (rad)', 'attitude (rad)'], rows),
        '',
        'For `exact` the reference is the same closed form (the torque-free step '
        'evaluates it from the segment start), so its attitude column is round-off by '
        'construction; '
        'the test suite checks that closed form against DOP853 at rtol 2.5e-14 (agreement '
        '< 1.5e-12 rad over 25 s). Under torque `exact` does not use the closed form: see the '
        'torque section, measured against an independent reference.',
    ])

    torque_section(sections, machine, with_peers)

    if with_peers:
        print('peers ...', flush=True)
        rows = peers.measure()
        sections['peers'] = '\n'.join([
            '## Against MuJoCo and Basilisk',
            '',
            f'Measured {machine}.',
            '',
            peers.__doc__.strip().replace('\n', ' '),
            '',
            common.table(['simulator, integrator', 'energy (rel., max)',
                          'L_w direction (rad, max)', 'attitude at 200 s (rad)',
                          'ms per sim. s', 'cost / our rk4'], rows),
        ])


def write(sections):
    """Replace the measured sections in RESULTS.md and print it."""
    text = open(RESULTS).read() if os.path.exists(RESULTS) else (
        '# Benchmark results\n\nWritten by `./dev bench` (see benchmarks/run.py); '
        'each section records the machine and date it was measured on.\n')
    for name, body in sections.items():
        text = replace_section(text, name, body)
    with open(RESULTS, 'w') as f:
        f.write(text)
    print(f'wrote {RESULTS}')
    print(text)
    # The manual's pages generated from RESULTS.md (the benchmarks index, the discovery
    # table) follow it at once: a rewritten RESULTS.md never leaves them stale.
    subprocess.run([sys.executable, os.path.join(HERE, '..', 'doc', 'generate.py')], check=True)


if __name__ == '__main__':
    main()
