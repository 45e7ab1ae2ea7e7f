"""Old path of rigid_body_dynamics.physics.analysis.estimators, kept for users' scripts."""

import sys

from .analysis import estimators as _moved

sys.modules[__name__] = _moved
