"""
Build a tf2_msgs-compatible interface package for the tests (there is no tf2_msgs wheel).

The package in ``test/interfaces/tf2_msgs`` has Jazzy's one definition the
simulator needs, ``TFMessage.msg`` = ``geometry_msgs/TransformStamped[]
transforms``; rosidl generates its C, C++ and Python type support from it
with the registry's rosidl / ament_cmake wheels (requirements/common.txt), built by
colcon against the test venv. Its RIHS01 type hash depends only on the field
names and types, so it equals Jazzy's, which :func:`build` checks. Built once
per venv and source version, under ``<venv>/tf2_msgs-build/<key>`` (about 10 s).
"""

import hashlib
import json
import os
from pathlib import Path
import shutil
import subprocess
import sys
import time

SOURCE = Path(__file__).resolve().parent / 'interfaces' / 'tf2_msgs'
#: Jazzy's type hash of tf2_msgs/msg/TFMessage (tf2_msgs 0.36, the ROS install's).
JAZZY_TYPE_HASH = 'RIHS01_e369d0f05a23ae52508854b66f6aa0437f3449d652e8cbf22d5abe85d020f087'


class BuildError(RuntimeError):
    """The interface package could not be built here; the message says why."""


def _key():
    digest = hashlib.sha256()
    for path in sorted(SOURCE.rglob('*')):
        if path.is_file():
            digest.update(path.relative_to(SOURCE).as_posix().encode() + path.read_bytes())
    return digest.hexdigest()[:16]


def environment(prefix):
    """Return the variables a process needs to import the built tf2_msgs (prefix: its install)."""
    prefix = Path(prefix)
    site = prefix / 'lib' / f'python{sys.version_info.major}.{sys.version_info.minor}' / \
        'site-packages'

    def chain(name, value):
        return os.pathsep.join(p for p in (str(value), os.environ.get(name, '')) if p)
    return {'PYTHONPATH': chain('PYTHONPATH', site),
            'LD_LIBRARY_PATH': chain('LD_LIBRARY_PATH', prefix / 'lib'),
            'AMENT_PREFIX_PATH': chain('AMENT_PREFIX_PATH', prefix)}


def type_hash(prefix):
    """Return the RIHS01 hash rosidl wrote for the built TFMessage."""
    with open(Path(prefix) / 'share' / 'tf2_msgs' / 'msg' / 'TFMessage.json') as f:
        return json.load(f)['type_hashes'][0]['hash_string']


def build(venv=sys.prefix, log=print):
    """
    Return the install prefix of the built package, building it first if needed.

    Raises BuildError with the reason (a missing tool, the end of the build
    log, a type hash that differs from Jazzy's).
    """
    venv = Path(venv)
    root = venv / 'tf2_msgs-build' / _key()
    prefix = root / 'install' / 'tf2_msgs'
    if (root / 'done').exists():
        return prefix
    colcon = venv / 'bin' / 'colcon'
    for tool in (str(colcon), 'cmake', 'c++'):
        if shutil.which(tool) is None:
            raise BuildError(f'cannot build tf2_msgs: {tool} not found')
    shutil.rmtree(root, ignore_errors=True)
    root.mkdir(parents=True)
    env = dict(os.environ, PATH=os.pathsep.join((str(venv / 'bin'), os.environ['PATH'])),
               CMAKE_PREFIX_PATH=str(venv), AMENT_PREFIX_PATH=str(venv),
               PYTHONWARNINGS='ignore')
    t0 = time.monotonic()
    result = subprocess.run(
        [str(colcon), '--log-base', str(root / 'log'), 'build', '--base-paths', str(SOURCE),
         '--build-base', str(root / 'build'), '--install-base', str(root / 'install'),
         '--event-handlers', 'console_direct-'],
        cwd=root, env=env, capture_output=True, text=True, timeout=600)
    if result.returncode != 0:
        tail = '\n'.join((result.stdout + result.stderr).splitlines()[-25:])
        raise BuildError(f'colcon build of tf2_msgs failed ({result.returncode}):\n{tail}')
    found = type_hash(prefix)
    if found != JAZZY_TYPE_HASH:
        raise BuildError(f'built TFMessage has type hash {found}, Jazzy has {JAZZY_TYPE_HASH}')
    (root / 'done').write_text(f'{time.monotonic() - t0:.1f} s\n')
    log(f'tf2_msgs interface built in {time.monotonic() - t0:.1f} s under {root}')
    return prefix


if __name__ == '__main__':
    print(build())
