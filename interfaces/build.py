"""
Build ROS interface packages from their definitions into a venv of the registry's wheels.

There is no wheel of ``simulation_interfaces`` (ROS 2's standard simulator
interface): ``./dev`` builds the released definitions in
``interfaces/simulation_interfaces`` with the registry's rosidl and ament_cmake
wheels (requirements/common.txt) through colcon, once per venv and source
version, and installs them into the venv itself, beside the wheels' own
messages, so that every process of the venv imports them as it imports
geometry_msgs. About two minutes on two cores. On a ROS install the package
comes from apt (``<depend>simulation_interfaces</depend>``) and nothing is built.

``python interfaces/build.py VENV`` builds (or says it is already built);
where a tool is missing it says why and exits 0: the simulator then runs
without the interface and says so once. test/tf2_msgs_build.py uses
:func:`colcon_build` for the tests' tf2_msgs.
"""

import hashlib
import os
from pathlib import Path
import shutil
import subprocess
import sys
import time

HERE = Path(__file__).resolve().parent
#: The mend of the registry wheels' imported targets every package here includes.
MEND = HERE / 'registry_wheels.cmake'


class BuildError(RuntimeError):
    """The interface package could not be built here; the message says why."""


def source_key(source):
    """Return a short hash of every file under ``source`` (path and bytes) and of MEND."""
    digest = hashlib.sha256(MEND.read_bytes())
    for path in sorted(Path(source).rglob('*')):
        if path.is_file():
            digest.update(path.relative_to(source).as_posix().encode() + path.read_bytes())
    return digest.hexdigest()[:16]


def colcon_build(source, root, venv, install_base, merge=False):
    """
    Build the package in ``source`` with the venv's colcon; return the seconds it took.

    ``root`` holds the build and log folders; ``install_base`` is colcon's (with
    ``merge`` one prefix for all packages). Raises BuildError with the reason: a
    missing tool, or the end of the build log.
    """
    venv = Path(venv).resolve()
    colcon = venv / 'bin' / 'colcon'
    for tool in (str(colcon), 'cmake', 'c++'):
        if shutil.which(tool) is None:
            raise BuildError(f'cannot build {Path(source).name}: {tool} not found')
    env = dict(os.environ, PATH=os.pathsep.join((str(venv / 'bin'), os.environ['PATH'])),
               CMAKE_PREFIX_PATH=str(venv), AMENT_PREFIX_PATH=str(venv),
               PYTHONWARNINGS='ignore')
    t0 = time.monotonic()
    result = subprocess.run(
        [str(colcon), '--log-base', str(Path(root) / 'log'), 'build', '--base-paths',
         str(source), '--build-base', str(Path(root) / 'build'), '--install-base',
         str(install_base), '--event-handlers', 'console_direct-']
        + (['--merge-install'] if merge else []),
        cwd=root, env=env, capture_output=True, text=True, timeout=1800)
    if result.returncode != 0:
        tail = '\n'.join((result.stdout + result.stderr).splitlines()[-25:])
        raise BuildError(f'colcon build of {Path(source).name} failed '
                         f'({result.returncode}):\n{tail}')
    return time.monotonic() - t0


def build_into_venv(name, venv=sys.prefix, log=print):
    """
    Build ``interfaces/<name>`` into ``venv`` unless this source version is already there.

    Returns True when the package is there (built now or before); raises BuildError.
    """
    venv = Path(venv).resolve()
    source = HERE / name
    marker = venv / 'interfaces-build' / f'{name}-{source_key(source)}.done'
    if marker.exists():
        return True
    root = venv / 'interfaces-build' / name
    shutil.rmtree(root, ignore_errors=True)
    root.mkdir(parents=True)
    seconds = colcon_build(source, root, venv, venv, merge=True)
    shutil.rmtree(root / 'build', ignore_errors=True)       # (the objects: 100s of MB)
    marker.write_text(f'{seconds:.1f} s\n')
    log(f'{name} built in {seconds:.0f} s and installed into {venv}')
    return True


def main(argv):
    """Build simulation_interfaces into the venv ``argv[0]`` (default: this Python's)."""
    venv = argv[0] if argv else sys.prefix
    try:
        build_into_venv('simulation_interfaces', venv,
                        log=lambda text: print(f'dev: {text}', file=sys.stderr))
    except BuildError as err:
        print(f'dev: simulation_interfaces not built ({err}); attitude_simulator runs '
              'without the standard simulator services', file=sys.stderr)
    return 0


if __name__ == '__main__':
    sys.exit(main(sys.argv[1:]))
