"""
The third-party modules that only some tools need, and the one-line error when one is missing.

The nodes and the physics need numpy, scipy and the ROS messages only. The
report needs matplotlib and plotly, the bag tools rosbags, an orbit from a TLE
(``orbit_tle``) sgp4, the IGRF field ppigrf, the NRLMSIS density pymsis, a campaign on
Dask distributed; a ROS
user who never runs them may not have them (plotly has no rosdep key, so ``rosdep install``
cannot bring it). A tool calls :func:`require` first, before any work, and a
missing module ends it with one line saying what to install and exit status 2,
never with a traceback.
"""

import importlib

#: module -> (what to install with apt on Ubuntu 24.04, with pip; rosdep key or None).
#: package.xml declares each module that has a rosdep key (test_manifest checks it).
OPTIONAL = {
    'matplotlib': ('sudo apt install python3-matplotlib', 'pip install matplotlib',
                   'python3-matplotlib'),
    'plotly': ('sudo apt install python3-plotly', 'pip install plotly', None),
    'rosbags': (None, 'pip install rosbags', 'python3-rosbags-pip'),
    'ppigrf': (None, 'pip install ppigrf', None),
    'sgp4': ('sudo apt install python3-sgp4', 'pip install sgp4', None),
    'pymsis': (None, 'pip install pymsis', None),
    'distributed': ('sudo apt install python3-distributed', 'pip install distributed', None),
}


class MissingDependency(ImportError):
    """An optional module a tool needs is not installed; the text says what to install."""


def require(*modules):
    """
    Import ``modules`` (names in :data:`OPTIONAL`) or raise MissingDependency naming all missing.

    The message is one line: what is missing and the command that installs it.
    """
    missing = []
    for name in modules:
        try:
            importlib.import_module(name)
        except ImportError:
            missing.append(name)
    if missing:
        how = []
        for name in missing:
            apt, pip, _key = OPTIONAL[name]
            how.append(f'{apt} (or {pip})' if apt else pip)
        verb = 'is' if len(missing) == 1 else 'are'
        raise MissingDependency(f'{" and ".join(missing)} {verb} not installed; install with '
                                + '; '.join(how))


def require_for(setting, module):
    """
    Check that ``module`` imports, for a parameter's ``setting`` (e.g. 'orbit_tle').

    Else raise ValueError naming the setting and what to install, in one line: the node
    that validates the setting refuses it with that reason.
    """
    try:
        require(module)
    except MissingDependency as err:
        raise ValueError(f'{setting} needs the {module} library: {err}') from None
