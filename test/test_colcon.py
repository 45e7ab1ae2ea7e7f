"""
The package builds with colcon and its executables resolve the way `ros2 run` finds them.

``ros2 run PKG EXE`` (ros2cli, not installable here) looks up PKG's prefix in
the ament index (AMENT_PREFIX_PATH) and runs ``<prefix>/lib/PKG/EXE``. This
test does exactly that after a colcon build of a copy of the sources, starts
the executable with the environment ``source install/setup.bash`` would give
it, and sees it publish.
"""

import os
import shutil
import signal
import subprocess
import sys
import sysconfig

from ament_index_python.packages import get_package_prefix
from geometry_msgs.msg import InertiaStamped
from ros_harness import LATCHED

ROOT = os.path.join(os.path.dirname(os.path.abspath(__file__)), '..')
IGNORE = shutil.ignore_patterns('.venv', '.git', 'build', 'install', 'log', '__pycache__',
                                '*.egg-info', '.pytest_cache', '.hypothesis')


def test_colcon_build_and_ros2_run_lookup(tmp_path, probe, monkeypatch):
    src = tmp_path / 'src' / 'rigid_body_dynamics'
    shutil.copytree(ROOT, src, ignore=IGNORE)
    colcon = os.path.join(os.path.dirname(sys.executable), 'colcon')
    build = subprocess.run(
        [colcon, '--log-base', str(tmp_path / 'log'), 'build', '--base-paths', str(src),
         '--build-base', str(tmp_path / 'build'), '--install-base', str(tmp_path / 'install')],
        cwd=tmp_path, capture_output=True, text=True, timeout=300)
    assert build.returncode == 0, build.stdout + build.stderr
    assert 'Finished <<< rigid_body_dynamics' in build.stdout

    prefix_dir = tmp_path / 'install' / 'rigid_body_dynamics'
    monkeypatch.setenv('AMENT_PREFIX_PATH', str(prefix_dir))
    prefix = get_package_prefix('rigid_body_dynamics')      # what ros2 run asks the index
    assert os.path.realpath(prefix) == os.path.realpath(prefix_dir)
    lib = os.path.join(prefix, 'lib', 'rigid_body_dynamics')
    assert {'attitude_simulator', 'attitude_analyzer'} <= set(os.listdir(lib))
    share = os.path.join(prefix, 'share', 'rigid_body_dynamics')
    assert os.path.exists(os.path.join(share, 'launch', 'attitude.launch.py'))
    assert os.path.exists(os.path.join(share, 'config', 'tennis_racket.yaml'))
    assert os.path.exists(os.path.join(share, 'rviz', 'attitude.rviz'))

    site = os.path.relpath(sysconfig.get_paths()['purelib'], sys.prefix)
    assert os.path.isdir(os.path.join(prefix, site, 'rigid_body_dynamics'))
    env = dict(os.environ, PYTHONPATH=os.pathsep.join(
        [os.path.join(prefix, site)] + os.environ.get('PYTHONPATH', '').split(os.pathsep)))
    inertia = probe.subscribe(InertiaStamped, '/colcon/inertia', LATCHED)
    proc = subprocess.Popen(
        [os.path.join(lib, 'attitude_simulator'), '--ros-args', '-r', '__ns:=/colcon',
         '--params-file', os.path.join(share, 'config', 'tennis_racket.yaml')],
        cwd=tmp_path, env=env, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
    try:
        probe.spin_until(lambda: inertia, 30.0, 'the colcon-installed simulator to publish')
        assert inertia[0].inertia.izz == 3.0
    finally:
        proc.send_signal(signal.SIGINT)
        out, _ = proc.communicate(timeout=10)
    assert proc.returncode == 0, out
    # the executable ran the installed package, not the sources or the editable copy
    where = subprocess.run([sys.executable, '-c', 'import rigid_body_dynamics as m; '
                            'print(m.__file__)'], cwd=tmp_path, env=env, capture_output=True,
                           text=True)
    assert os.path.realpath(where.stdout.strip()).startswith(os.path.realpath(prefix))
