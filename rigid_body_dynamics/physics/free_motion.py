"""Old path of rigid_body_dynamics.physics.dynamics.free_motion, kept for users' scripts."""

import sys

from .dynamics import free_motion as _moved

sys.modules[__name__] = _moved
