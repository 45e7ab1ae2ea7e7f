"""Old path of rigid_body_dynamics.physics.analysis.theory, kept for users' scripts."""

import sys

from .analysis import theory as _moved

sys.modules[__name__] = _moved
