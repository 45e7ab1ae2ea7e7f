"""
The manual (doc/): built with warnings as errors, made from the code, offline, and true.

- The generated reference is current (doc/generate.py --check), and its tables are
  what the running nodes have on the ROS graph: every topic, service and parameter.
- ``sphinx-build -W`` passes; every internal link and anchor resolves; no page loads
  anything from the network.
- Headless Chromium opens the index, a node page and the physics page from disk
  with no console error, and MathJax has rendered the physics page's math.
- Every bash block of the tutorials and how-to guides runs as written (blocks that
  begin with ``# on a ROS 2 install`` need ros2 / colcon and are not run here).
"""

from html.parser import HTMLParser
import os
from pathlib import Path
import re
import subprocess
import sys

import pytest
from rcl_interfaces.srv import ListParameters
from rigid_body_dynamics.nodes import analyzer, controller, estimator, poinsot, simulator
from rigid_body_dynamics.nodes.interfaces import NODES
from rigid_body_dynamics.ros import simulator_interface
from rigid_body_dynamics.ros.client import WaitTimeout
from test_report_browser import _chromium, FLAGS

ROOT = Path(__file__).resolve().parent.parent
DOC = ROOT / 'doc'
ON_ROS = '# on a ROS 2 install'


@pytest.fixture(scope='module')
def built(tmp_path_factory):
    """Build the manual once (HTML, -W); return the output folder."""
    out = tmp_path_factory.mktemp('doc') / 'html'
    run = subprocess.run([sys.executable, '-m', 'sphinx', '-W', '--keep-going', '-q', '-b',
                          'html', str(DOC), str(out)], capture_output=True, text=True,
                         timeout=600, cwd=ROOT)
    assert run.returncode == 0, run.stderr[-5000:]
    return out


def test_the_generated_reference_is_current():
    run = subprocess.run([sys.executable, str(DOC / 'generate.py'), '--check'],
                         capture_output=True, text=True, timeout=120, cwd=ROOT)
    assert run.returncode == 0, run.stderr


def test_every_key_of_the_analyzer_s_input_status_is_documented():
    """The keys _input_status writes (read from its source) are the documented INPUT_KEYS."""
    import inspect
    source = inspect.getsource(analyzer.AttitudeAnalyzer._input_status)
    written = set(re.findall(r"\('([^']+)', ", source))
    assert written == set(analyzer.INPUT_KEYS), written ^ set(analyzer.INPUT_KEYS)


class _Page(HTMLParser):
    """The links, resources and element ids of one HTML page."""

    def __init__(self):
        super().__init__()
        self.links, self.resources, self.ids = [], [], set()

    def handle_starttag(self, tag, attrs):
        attrs = dict(attrs)
        if 'id' in attrs:
            self.ids.add(attrs['id'])
        if tag == 'a' and attrs.get('href'):
            self.links.append(attrs['href'])
        for key in ('src', 'href'):
            if tag in ('script', 'img', 'link', 'iframe') and attrs.get(key):
                self.resources.append(attrs[key])


def _pages(built):
    pages = {}
    for path in built.rglob('*.html'):
        page = _Page()
        page.feed(path.read_text())
        pages[path.resolve()] = page
    return pages


def test_every_internal_link_resolves_and_nothing_loads_from_the_network(built):
    pages = _pages(built)
    assert len(pages) > 25
    broken, remote = [], []
    for path, page in pages.items():
        remote += [(path.name, r) for r in page.resources if re.match(r'(https?:)?//', r)]
        for link in page.links + page.resources:
            if re.match(r'[a-z]+:', link) or link.startswith('//'):
                continue                        # http(s), mailto: followed only on a click
            target, _, anchor = link.partition('#')
            target = target.partition('?')[0]
            file = (path.parent / target).resolve() if target else path
            if not file.exists():
                broken.append((str(path.relative_to(built)), link))
            elif anchor and file.suffix == '.html' and anchor not in pages[file].ids:
                broken.append((str(path.relative_to(built)), link))
    assert broken == [] and remote == []


def test_the_built_manual_names_no_sessions_issues_or_the_seed(built):
    """
    What a user reads: no work sessions, issue numbers, unnamed machines or "the seed".

    (A pytest session and "this machine" for the local host, where DDS stays, are fine.)
    """
    import html
    words = re.compile(r'\b(?:last|this|next|previous|earlier|one) sessions?\b|\bsessions? \d+|'
                       r'\b(?:two|three) sessions ago\b|\bissue \d+|\bseed text\b|'
                       r"\bseed's\b|\bthe (?:faster|slower|other) machine\b", re.I)
    found = {}
    for page in built.rglob('*.html'):
        if '_modules' in page.parts or page.name in ('genindex.html', 'search.html'):
            continue
        text = html.unescape(re.sub(r'<[^>]+>', ' ', page.read_text()))
        hits = sorted({m.group(0) for m in words.finditer(text)})
        if hits:
            found[str(page.relative_to(built))] = hits
    assert not found, found


def test_pages_open_from_disk_without_errors_and_the_math_is_rendered(built, tmp_path):
    chromium = _chromium()
    dom = {}
    for page in ('index', 'reference/nodes/attitude_simulator', 'explanation/physics'):
        run = subprocess.run([chromium, *FLAGS, f'--user-data-dir={tmp_path / "profile"}',
                              '--enable-logging=stderr', '--v=0', '--dump-dom',
                              (built / f'{page}.html').as_uri()],
                             capture_output=True, text=True, timeout=120)
        assert run.returncode == 0, run.stderr[-2000:]
        console = [line for line in run.stderr.splitlines() if ':CONSOLE' in line]
        assert [line for line in console if 'error' in line.lower()] == [], console
        dom[page] = run.stdout
    assert 'Where to start' in dom['index']
    assert dom['reference/nodes/attitude_simulator'].count('<tr') > 40
    assert 'torque_cmd' in dom['reference/nodes/attitude_simulator']
    physics = dom['explanation/physics']
    # MathJax 3 replaced every formula by an SVG; none failed to parse
    assert physics.count('<mjx-container') >= 40 and physics.count('<svg') >= 40
    assert not re.search(r'<[^>]*data-mml-node="merror"', physics)
    assert 'data-mjx-error' not in physics


def test_the_reference_lists_what_the_running_nodes_have(launch, probe, tf2_msgs_env):
    """Every topic, service and parameter of the four nodes, as the graph shows them."""
    env = tf2_msgs_env               # so /tf is there too (publish_tf is on by default)
    modules = {'attitude_simulator': ('simulator', ['-p', 'publish_clock:=true',
                                                    '-p', 'wheel_axes:=[0.0, 0.0, 1.0]',
                                                    '-p', 'wheel_inertia:=[0.01]',
                                                    '-p', 'orbit_elements:=[7.0e6, 0.0, 0.0, '
                                                    '0.0, 0.0, 0.0]',
                                                    '-p', 'magnetic_field_model:=dipole',
                                                    '-p', 'magnetometer_rate:=10.0',
                                                    '-p', 'epoch:=2026-03-20T12:00:00Z',
                                                    '-p', 'star_tracker_rate:=10.0',
                                                    '-p', 'sun_sensor_rate:=10.0']),
               'attitude_analyzer': ('analyzer', []), 'poinsot_visualizer': ('poinsot', []),
               'attitude_estimator': ('estimator', []),
               'attitude_controller': ('controller', [
                   '-p', 'actuator:=wheels', '-p', 'wheel_axes:=[1.0, 0.0, 0.0, 0.0, 1.0, 0.0, '
                   '0.0, 0.0, 1.0]', '-p', 'wheel_inertia:=[0.01, 0.01, 0.01]'])}
    for node, (module, args) in modules.items():
        launch(f'rigid_body_dynamics.nodes.{module}', *args, name=node, env=env)
    tables = {'attitude_simulator': simulator.PARAMETERS, 'attitude_analyzer': analyzer.PARAMETERS,
              'poinsot_visualizer': poinsot.PARAMETERS,
              'attitude_controller': controller.PARAMETERS,
              'attitude_estimator': estimator.PARAMETERS}
    for node, interfaces in NODES.items():
        # publish_clock, a wheel, an orbit, a field; the controller flies wheels, not B-dot
        want = interfaces.resolved('/', present=lambda when: 'bdot' not in when and (
            'simulation_interfaces' not in when or simulator_interface.available()))

        def have():
            out = {kind: probe.endpoints(kind, node) for kind in ('pub', 'srv')}
            # the take-based subscriptions are on a hidden helper node
            out['sub'] = {**probe.endpoints('sub', node),
                          **probe.endpoints('sub', f'_{node}_intake')}
            return out
        try:
            probe.spin_until(lambda: have() == want, 30.0, f'the graph of {node} as documented')
        except WaitTimeout:
            got = have()
            diff = {kind: (sorted(set(got[kind].items()) - set(want[kind].items())),
                           sorted(set(want[kind].items()) - set(got[kind].items())))
                    for kind in want}
            raise AssertionError(f'{node}: (on the graph only, documented only): {diff}')
        _check_qos(probe, node, interfaces, want)
        names = probe.call(ListParameters, f'/{node}/list_parameters',
                           ListParameters.Request()).result.names
        extra = {n for n in names if n not in tables[node].params}
        assert set(tables[node].params) <= set(names)
        assert {n for n in extra if not n.startswith('qos_overrides.')} <= {
            'use_sim_time', 'start_type_description_service'}, extra


def _check_qos(probe, node, interfaces, want):
    """Compare the documented reliability and durability with the node's endpoints."""
    for item in interfaces.items:
        full = interfaces._full(item.name, '')
        if item.kind in ('srv', 'action') or full not in want[item.kind]:
            continue
        info = (probe.node.get_publishers_info_by_topic if item.kind == 'pub' else
                probe.node.get_subscriptions_info_by_topic)(full)
        mine = [e for e in info if e.node_name in (node, f'_{node}_intake')]
        assert mine, f'{node}: no {item.kind} endpoint on {full}'
        reliability, durability, _depth = interfaces.qos_of(item).split(', ')
        got = {(e.qos_profile.reliability.name.lower().replace('_', ' '),
                e.qos_profile.durability.name.lower().replace('_', ' ')) for e in mine}
        assert got == {(reliability, durability)}, (node, full, got)


def _bash_blocks():
    """(page, index, text) of every bash block of the tutorials and how-to guides."""
    blocks = []
    for page in sorted((DOC / 'tutorials').glob('*.md')) + sorted((DOC / 'howto').glob('*.md')):
        found = re.findall(r'^```bash\n(.*?)^```', page.read_text(), re.S | re.M)
        blocks += [(f'{page.parent.name}/{page.stem}', k, text) for k, text in enumerate(found)]
    return blocks


BLOCKS = _bash_blocks()


def test_the_blocks_not_run_here_are_the_ros_install_ones():
    skipped = [(p, k) for p, k, text in BLOCKS if text.startswith(ON_ROS)]
    assert skipped and all('ros2 ' in text or 'colcon' in text for p, k, text in BLOCKS
                           if text.startswith(ON_ROS))
    assert len(BLOCKS) - len(skipped) >= 10


PAGES = sorted({p for p, _k, text in BLOCKS if not text.startswith(ON_ROS)})


@pytest.mark.parametrize('page', PAGES)
def test_the_command_blocks_of_a_page_run_as_written(tmp_path, page):
    """
    Run a page's blocks as a reader would: in order, in one folder.

    A later block may use what an earlier one made (a bag, a report).
    """
    stack = {'.venv': 'pinned', '.venv-jazzy': 'jazzy'}.get(Path(sys.prefix).name)
    if stack is None or Path(sys.prefix).parent != ROOT:
        pytest.skip(f'the blocks call ./dev, and this suite runs outside its venvs ({sys.prefix})')
    # the reader's folder: ./dev, and the files the blocks name, as in a clone
    for name in ('dev', 'doc', 'config'):
        os.symlink(ROOT / name, tmp_path / name)
    env = dict(os.environ, RBD_STACK=stack)
    for _page, index, text in (b for b in BLOCKS if b[0] == page):
        if text.startswith(ON_ROS):
            continue
        run = subprocess.run(['bash', '-euo', 'pipefail', '-c', text], cwd=tmp_path, env=env,
                             capture_output=True, text=True, timeout=300)
        assert run.returncode == 0, f'{page} block {index}:\n{text}\n{run.stdout[-3000:]}' \
                                    f'\n{run.stderr[-3000:]}'
        assert 'Traceback' not in run.stdout + run.stderr, run.stdout + run.stderr


def test_the_python_api_tour_prints_what_it_says():
    run = subprocess.run([sys.executable, str(DOC / 'examples' / 'physics_api.py')],
                         capture_output=True, text=True, timeout=120)
    assert run.returncode == 0, run.stderr
    state, flip, chandler = run.stdout.strip().splitlines()
    omega, _, work = state.partition(']')
    # I3 omega3_dot = 0.1 for 10 s on the symmetric top: omega3 = 2 + 1 / 1.5
    # (numpy prints 8 decimals)
    assert float(omega.strip('[ ').split()[2]) == pytest.approx(2.0 + 1.0 / 1.5, abs=1e-8)
    w, t = (float(x) for x in work.split())
    assert w == pytest.approx(t, rel=1e-12)                 # T - T0 = W
    assert float(flip) == pytest.approx(10.9775729, rel=1e-7)
    assert float(chandler) == pytest.approx(300.0, rel=1e-12)


def test_the_igrf_comparison_prints_what_the_tle_tutorial_says():
    """doc/examples/igrf_vs_dipole.py: its two lines are the tutorial's text block."""
    run = subprocess.run([sys.executable, str(DOC / 'examples' / 'igrf_vs_dipole.py')],
                         capture_output=True, text=True, timeout=120)
    assert run.returncode == 0, run.stderr
    page = (DOC / 'tutorials' / 'satellite_tle.md').read_text()
    blocks = re.findall(r'^```text\n(.*?)^```', page, re.S | re.M)
    assert run.stdout == blocks[-1], (run.stdout, blocks[-1])


def test_the_surface_torques_example_prints_what_the_tle_tutorial_says():
    """doc/examples/surface_torques.py: its lines are the tutorial's block after its name."""
    run = subprocess.run([sys.executable, str(DOC / 'examples' / 'surface_torques.py')],
                         capture_output=True, text=True, timeout=120)
    assert run.returncode == 0, run.stderr
    page = (DOC / 'tutorials' / 'satellite_tle.md').read_text()
    block = re.search(r'surface_torques\.py` prints:\n\n```text\n(.*?)^```', page,
                      re.S | re.M).group(1)
    assert run.stdout == block, (run.stdout, block)


def test_the_torque_model_example_runs_in_the_stages_and_balances_its_energy():
    """doc/examples/torque_model.py: its model in the stages, at round-off, dissipating."""
    run = subprocess.run([sys.executable, str(DOC / 'examples' / 'torque_model.py')],
                         capture_output=True, text=True, timeout=120)
    assert run.returncode == 0, run.stderr
    stages, statements, balance = run.stdout.strip().splitlines()
    assert stages == 'in the stages: True'
    assert float(statements.split()[-1]) < 4e-15
    words = balance.split()
    omega, change, work = float(words[2]), float(words[7]), float(words[-1])
    assert omega < 0.5 * (0.3 ** 2 + 0.2 ** 2 + 0.35 ** 2) ** 0.5     # it damps ...
    assert change < 0.0 and change == pytest.approx(work, rel=1e-6)   # ... and T - T0 = W


def test_the_send_torque_example_turns_the_body_as_euler_says(launch, probe):
    """0.1 N m about body z on the symmetric top: omega_3 grows at 0.1 / 1.5 rad/s^2."""
    from geometry_msgs.msg import WrenchStamped
    from nav_msgs.msg import Odometry
    from rigid_body_dynamics.ros.conversions import time_ns
    launch('rigid_body_dynamics.nodes.simulator', '-p', 'preset:=symmetric_top', name='sim')
    odom = probe.subscribe(Odometry, 'odom')
    applied = probe.subscribe(WrenchStamped, 'applied_torque')
    probe.wait_for('odom', 10)
    example = subprocess.Popen([sys.executable, str(DOC / 'examples' / 'send_torque.py')])
    probe.spin_until(lambda: example.poll() is not None, 30.0, 'the example to end')
    assert example.returncode == 0
    period = 10_000_000                                     # 100 Hz ticks

    def released():
        """Tell whether the timeout passed: a zero torque after the last 0.1, odom beyond it."""
        on = [time_ns(m.header.stamp) for m in applied if m.wrench.torque.z == 0.1]
        return on and any(time_ns(m.header.stamp) > max(on) and m.wrench.torque.z == 0.0
                          for m in applied) and any(
            time_ns(m.header.stamp) >= max(on) + period for m in odom)
    probe.spin_until(released, 20.0, 'the torque to time out')
    on = [time_ns(m.header.stamp) for m in applied if m.wrench.torque.z == 0.1]
    assert applied[-1].wrench.torque.z == 0.0 and on
    first, last = min(on), max(on)
    assert 2.0 < (last - first) * 1e-9 < 3.0                # 2 s of commands + the timeout
    w3 = {time_ns(m.header.stamp): m.twist.twist.angular.z for m in odom}
    gained = w3[last + period] - w3[first - period]
    # the torque began within the tick before `first` and ended within the one after `last`
    assert 0.1 / 1.5 * (last - first) * 1e-9 - 1e-9 < gained
    assert gained < 0.1 / 1.5 * (last - first + 2 * period) * 1e-9 + 1e-9


def test_the_spin_wheels_example_keeps_h_and_drives_the_wheels(launch, probe):
    """wheels.yaml and spin_wheels.py: H (world) constant to 1e-12, each wheel driven 0.01 N m."""
    from geometry_msgs.msg import Vector3Stamped
    import numpy as np
    from rigid_body_dynamics.ros.conversions import vector_array
    from sensor_msgs.msg import JointState
    launch('rigid_body_dynamics.nodes.simulator', '--params-file',
           str(DOC / 'examples' / 'wheels.yaml'), name='sim')
    joints = probe.subscribe(JointState, 'wheel_state')
    momentum = probe.subscribe(Vector3Stamped, 'angular_momentum')
    probe.wait_for('wheel_state', 10)
    example = subprocess.Popen([sys.executable, str(DOC / 'examples' / 'spin_wheels.py')])
    probe.spin_until(lambda: example.poll() is not None, 30.0, 'the example to end')
    assert example.returncode == 0
    probe.spin_until(lambda: any(tuple(m.effort) == (0.01,) * 4 for m in joints) and tuple(
        joints[-1].effort) == (0.0,) * 4, 20.0, 'the wheel command to time out (0.5 s)')
    driven = [m for m in joints if tuple(m.effort) == (0.01,) * 4]
    assert driven and tuple(joints[-1].effort) == (0.0,) * 4
    # about 2 s of 0.01 N m: each wheel gains about 0.01 * 2 / J_eff rad/s (J = 0.01 kg m^2)
    assert all(1.0 < v < 4.0 for v in joints[-1].velocity), joints[-1].velocity
    h = np.array([vector_array(m.vector) for m in momentum])
    assert np.max(np.abs(h - h[0])) / np.linalg.norm(h[0]) < 1e-12


def test_the_readme_is_a_short_landing_page_whose_links_resolve():
    readme = (ROOT / 'README.md').read_text()
    assert len(readme.splitlines()) < 150
    first = re.search(r'```bash\n(.*?)```', readme, re.S).group(1)
    assert first.startswith('./dev demo') and '\n./dev test' in first
    links = re.findall(r'\]\(([^)#]+)\)', readme)
    assert len(links) > 20
    assert [link for link in links if not (ROOT / link).exists()] == []


def test_the_readme_lists_every_page_of_the_manual():
    """Check that README's list of the manual names each tutorial, how-to and explanation."""
    readme = (ROOT / 'README.md').read_text()
    pages = [p.relative_to(ROOT).as_posix() for folder in ('tutorials', 'howto', 'explanation')
             for p in sorted((DOC / folder).glob('*.md'))] + ['doc/benchmarks.md']
    missing = [p for p in pages if f']({p})' not in readme]
    assert not missing, missing
