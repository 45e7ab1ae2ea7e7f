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

import importlib.util
import json
import os
from pathlib import Path
import shutil
import sys

SOURCE = Path(__file__).resolve().parent / 'interfaces' / 'tf2_msgs'
#: Jazzy's type hash of tf2_msgs/msg/TFMessage (tf2_msgs 0.36, the ROS install's).
JAZZY_TYPE_HASH = 'RIHS01_e369d0f05a23ae52508854b66f6aa0437f3449d652e8cbf22d5abe85d020f087'

# interfaces/build.py, the repo's builder of interface packages (by path: "build" is a
# common module name)
_spec = importlib.util.spec_from_file_location(
    'rbd_interface_build', Path(__file__).resolve().parents[1] / 'interfaces' / 'build.py')
interface_build = importlib.util.module_from_spec(_spec)
_spec.loader.exec_module(interface_build)
#: The package could not be built here; the message says why.
BuildError = interface_build.BuildError


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
    venv = Path(venv).resolve()
    root = venv / 'tf2_msgs-build' / interface_build.source_key(SOURCE)
    prefix = root / 'install' / 'tf2_msgs'
    if (root / 'done').exists():
        return prefix
    shutil.rmtree(root, ignore_errors=True)
    root.mkdir(parents=True)
    seconds = interface_build.colcon_build(SOURCE, root, venv, root / 'install')
    found = type_hash(prefix)
    if found != JAZZY_TYPE_HASH:
        raise BuildError(f'built TFMessage has type hash {found}, Jazzy has {JAZZY_TYPE_HASH}')
    (root / 'done').write_text(f'{seconds:.1f} s\n')
    log(f'tf2_msgs interface built in {seconds:.1f} s under {root}')
    return prefix


if __name__ == '__main__':
    print(build())
