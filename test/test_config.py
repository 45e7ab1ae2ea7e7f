"""
Config files and the launch file, checked without ROS launch (not installable here).

Every config loads through rclpy's own parameter-file parsing on the real
nodes (``--ros-args --params-file``); every parameter the launch file sets is
declared by the node it starts; the configs agree with the presets.
"""

import ast
import glob
import os

from geometry_msgs.msg import InertiaStamped
import pytest
import rclpy
from rclpy.context import Context
from rigid_body_dynamics.nodes.analyzer import AttitudeAnalyzer
from rigid_body_dynamics.nodes.estimator import AttitudeEstimator
from rigid_body_dynamics.nodes.poinsot import PoinsotVisualizer
from rigid_body_dynamics.nodes.simulator import AttitudeSimulator
from rigid_body_dynamics.physics import presets
from ros_harness import LATCHED
import yaml

ROOT = os.path.join(os.path.dirname(__file__), '..')
CONFIGS = sorted(glob.glob(os.path.join(ROOT, 'config', '*.yaml')))
LAUNCH = os.path.join(ROOT, 'launch', 'attitude.launch.py')


def _declared(node_class):
    """Return the parameter names a node class declares (built in a private context)."""
    ctx = Context()
    rclpy.init(context=ctx)
    try:
        node = node_class(context=ctx)
        try:
            return set(node.list_parameters([], 0).names)
        finally:
            if hasattr(node, 'stop'):
                node.stop()
            node.destroy_node()
    finally:
        rclpy.shutdown(context=ctx)


def test_there_is_a_config_for_every_preset():
    names = {os.path.splitext(os.path.basename(p))[0] for p in CONFIGS}
    assert names == set(presets.PRESETS)


@pytest.mark.parametrize('path', CONFIGS, ids=os.path.basename)
def test_config_matches_its_preset_and_declared_parameters(path):
    data = yaml.safe_load(open(path))
    preset = presets.get(os.path.splitext(os.path.basename(path))[0])
    shared = data['/**']['ros__parameters']
    sim = data['/**/attitude_simulator']['ros__parameters']
    assert shared['inertia'] == list(preset.moments)
    assert sim['preset'] == preset.name
    assert sim['initial_angular_velocity'] == list(preset.omega0)
    assert sim['integration_rate'] == preset.integration_rate
    declared_sim = _declared(AttitudeSimulator)
    declared_an = _declared(AttitudeAnalyzer)
    assert set(sim) <= declared_sim
    assert set(data['/**/attitude_analyzer']['ros__parameters']) <= declared_an
    assert set(shared) <= declared_sim & declared_an


def test_every_config_starts_both_real_nodes(launch, probe):
    """--params-file on the real node processes, all presets at once, one namespace each."""
    procs, latched = [], {}
    for path in CONFIGS:
        name = os.path.splitext(os.path.basename(path))[0]
        ns = f'/cfg_{name}'
        procs.append(launch('rigid_body_dynamics.nodes.simulator', '-r', f'__ns:={ns}',
                            '--params-file', path, name=f'sim_{name}'))
        procs.append(launch('rigid_body_dynamics.nodes.analyzer', '-r', f'__ns:={ns}',
                            '--params-file', path, name=f'analyzer_{name}'))
        latched[name] = probe.subscribe(InertiaStamped, f'{ns}/inertia', LATCHED)
    probe.spin_until(lambda: all(latched.values()), 60.0, 'every simulator to start')
    for name, msgs in latched.items():
        i = msgs[0].inertia
        assert [i.ixx, i.iyy, i.izz] == pytest.approx(list(presets.get(name).moments), rel=1e-15)
    for proc in procs:
        code, _ = proc.stop()
        assert code == 0, proc.output()
        assert 'cannot start' not in proc.output()


def _launch_nodes():
    """List (executable, package, parameter keys set in code) of each Node(...) launched."""
    tree = ast.parse(open(LAUNCH).read())
    found = []
    for call in ast.walk(tree):
        if isinstance(call, ast.Call) and getattr(call.func, 'id', '') == 'Node':
            kw = {k.arg: k.value for k in call.keywords}
            keys = set()
            for item in getattr(kw.get('parameters'), 'elts', []):
                if isinstance(item, ast.Dict):
                    keys |= {k.value for k in item.keys}
            found.append((kw['executable'].value, kw['package'].value, keys))
    return found


def test_launch_file_sets_only_declared_parameters_of_installed_executables():
    nodes = _launch_nodes()
    assert ('rviz2', 'rviz2', set()) in nodes     # rviz:=true; its config: test_rviz_config
    nodes = [n for n in nodes if n[1] != 'rviz2']
    assert {n[0] for n in nodes} == {'attitude_simulator', 'attitude_analyzer',
                                     'poinsot_visualizer', 'attitude_estimator'}
    setup = open(os.path.join(ROOT, 'setup.py')).read()
    declared = {'attitude_simulator': _declared(AttitudeSimulator),
                'attitude_analyzer': _declared(AttitudeAnalyzer),
                'poinsot_visualizer': _declared(PoinsotVisualizer),
                'attitude_estimator': _declared(AttitudeEstimator)}
    for executable, package, keys in nodes:
        assert package == 'rigid_body_dynamics'
        assert f"'{executable} = rigid_body_dynamics.nodes." in setup
        assert keys <= declared[executable], keys - declared[executable]
    assert "'config'" in open(LAUNCH).read()


def test_the_manual_lists_every_launch_argument():
    """The launch-argument table of howto/ros_install.md names exactly what the file declares."""
    import re
    tree = ast.parse(open(LAUNCH).read())
    declared = {call.args[0].value for call in ast.walk(tree) if isinstance(call, ast.Call)
                and getattr(call.func, 'id', '') == 'DeclareLaunchArgument'}
    page = open(os.path.join(ROOT, 'doc', 'howto', 'ros_install.md')).read()
    table = page.split('## The launch file', 1)[1].split('\n## ', 1)[0]
    listed = set(re.findall(r'^\| `(\w+)` \|', table, re.M))
    assert listed == declared, listed ^ declared
