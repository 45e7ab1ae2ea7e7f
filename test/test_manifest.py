"""
package.xml declares what the code imports, and nothing it does not.

The imports are read with ast from the installed package and the launch file
(exec_depend) and from the tests (test_depend), and mapped to rosdep keys: a
ROS package's key is its name, a Python module's key is in PYTHON_KEYS. After
``rosdep install --from-paths src`` every import of an installed tool resolves,
except the optional modules without a rosdep key, which the tools name in one
line when missing (rigid_body_dynamics/optional.py).
"""

import ast
import glob
import os
import subprocess
import sys
import xml.etree.ElementTree as ElementTree

import pytest

from rigid_body_dynamics import optional

ROOT = os.path.join(os.path.dirname(__file__), '..')

#: Python module -> rosdep key (each checked in rosdistro's rosdep/python.yaml).
PYTHON_KEYS = {
    'numpy': 'python3-numpy',
    'scipy': 'python3-scipy',
    'matplotlib': 'python3-matplotlib',
    'rosbags': 'python3-rosbags-pip',
    'yaml': 'python3-yaml',
    'pandas': 'python3-pandas',
    'pytest': 'python3-pytest',
    'hypothesis': 'python3-hypothesis',
    'mcap_ros2': 'mcap-ros2-support',
}
#: Imported, with no rosdep key to declare (and why).
NO_KEY = {
    'plotly': "the report's page; optional.require names it when missing",
    'allantools': "tests only: the reference for the report's Allan deviation (pip)",
    'sgp4': 'orbit_tle only; optional.require names it when missing (apt python3-sgp4)',
    'ppigrf': 'magnetic_field_model igrf only; optional.require names it when missing (pip)',
    'pymsis': 'atmosphere_model nrlmsis only; optional.require names it when missing (pip)',
    'distributed': 'rigid_body_campaign on Dask only; optional.require names it when missing '
                   '(apt python3-distributed)',
}
#: Declared, though no Python file imports them (and where they are used).
NOT_IMPORTED = {
    'rviz2': 'started by launch/attitude.launch.py with rviz:=true',
}


def _imports(paths):
    """Return {top-level third-party module: first file importing it} for the files."""
    local = {os.path.splitext(os.path.basename(p))[0] for p in glob.glob(
        os.path.join(ROOT, 'test', '*.py'))} | {'rigid_body_dynamics'}
    found = {}
    for path in paths:
        with open(path) as f:
            tree = ast.parse(f.read(), path)
        for node in ast.walk(tree):
            if isinstance(node, ast.Import):
                names = [a.name for a in node.names]
            elif isinstance(node, ast.ImportFrom) and node.level == 0:
                names = [node.module]
            else:
                continue
            for name in names:
                top = name.split('.')[0]
                if top not in sys.stdlib_module_names and top not in local:
                    found.setdefault(top, os.path.relpath(path, ROOT))
    return found


def _declared(*tags):
    root = ElementTree.parse(os.path.join(ROOT, 'package.xml')).getroot()
    return {e.text.strip() for tag in tags for e in root.findall(tag)}


def _key(module):
    return PYTHON_KEYS.get(module, module)


PACKAGE = _imports(glob.glob(os.path.join(ROOT, 'rigid_body_dynamics', '**', '*.py'),
                             recursive=True) + glob.glob(os.path.join(ROOT, 'launch', '*.py')))
TESTS = _imports(glob.glob(os.path.join(ROOT, 'test', '*.py')))
EXEC = _declared('exec_depend', 'depend')
TEST = _declared('test_depend', 'depend')


def test_every_import_of_the_installed_package_is_declared():
    # pytest: only rigid_body_dynamics.testing imports it, the plugin pytest itself loads.
    missing = {m: f for m, f in PACKAGE.items()
               if _key(m) not in EXEC and m not in NO_KEY
               and not (m == 'pytest' and _key(m) in TEST)}
    assert not missing, f'imported but not an exec_depend of package.xml: {missing}'


def test_every_exec_depend_is_imported_or_said_where_it_is_used():
    used = {_key(m) for m in PACKAGE} | set(NOT_IMPORTED)
    assert EXEC <= used, f'exec_depend never imported: {sorted(EXEC - used)}'


def test_every_test_import_is_declared():
    missing = {m: f for m, f in TESTS.items()
               if _key(m) not in EXEC | TEST and m not in NO_KEY}
    assert not missing, f'imported by the tests but not declared: {missing}'


def test_every_test_depend_is_imported():
    used = {_key(m) for m in TESTS} | {_key(m) for m in PACKAGE}
    assert TEST <= used, f'test_depend never imported: {sorted(TEST - used)}'


def test_optional_modules_agree_with_the_manifest():
    for module, (_apt, _pip, key) in optional.OPTIONAL.items():
        assert module in PACKAGE, f'{module} is listed optional but never imported'
        if key is None:
            assert module in NO_KEY and _key(module) not in EXEC
        else:
            assert key == _key(module) and key in EXEC, module


def test_rviz2_is_what_the_launch_file_starts():
    with open(os.path.join(ROOT, 'launch', 'attitude.launch.py')) as f:
        assert "package='rviz2'" in f.read()


@pytest.mark.parametrize('tool, args, hidden', [
    ('report', ['--preset', 'sphere', '--duration', '0.1'], 'plotly'),
    ('report', ['--preset', 'sphere', '--duration', '0.1'], 'matplotlib'),
    ('analyze', ['no-such-bag'], 'rosbags'),
])
def test_a_tool_without_an_optional_module_says_what_to_install(tmp_path, tool, args, hidden):
    # the module is made unimportable in the tool's own process (None in sys.modules)
    code = (f'import sys; sys.modules[{hidden!r}] = None; '
            f'from rigid_body_dynamics.tools.{tool} import main; sys.exit(main(sys.argv[1:]))')
    run = subprocess.run([sys.executable, '-c', code, *args, '--out', str(tmp_path)]
                         if tool == 'report' else [sys.executable, '-c', code, *args],
                         capture_output=True, text=True, timeout=60, cwd=tmp_path)
    assert run.returncode == 2, run.stderr
    lines = run.stderr.strip().splitlines()
    assert len(lines) == 1 and 'Traceback' not in run.stderr, run.stderr
    apt, pip, _key = optional.OPTIONAL[hidden]
    assert lines[0].startswith(f'rigid_body_{tool}: {hidden} is not installed; install with')
    assert pip in lines[0] and (apt is None or apt in lines[0])
    assert not os.listdir(tmp_path)                  # refused before any work


def test_setup_py_and_the_manual_have_package_xml_s_version():
    version = ElementTree.parse(os.path.join(ROOT, 'package.xml')).findtext('version')
    assert f"version='{version}'" in open(os.path.join(ROOT, 'setup.py')).read()
    assert "findtext('version')" in open(os.path.join(ROOT, 'doc', 'conf.py')).read()
    assert f'{version} (unreleased)' in open(os.path.join(ROOT, 'CHANGELOG.rst')).read() or \
        f'\n{version}\n' in open(os.path.join(ROOT, 'CHANGELOG.rst')).read()
