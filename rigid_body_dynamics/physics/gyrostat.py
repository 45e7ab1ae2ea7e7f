"""Old path of rigid_body_dynamics.physics.dynamics.gyrostat, kept for users' scripts."""

import sys

from .dynamics import gyrostat as _moved

sys.modules[__name__] = _moved
