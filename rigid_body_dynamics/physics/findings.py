"""Old path of rigid_body_dynamics.physics.analysis.findings, kept for users' scripts."""

import sys

from .analysis import findings as _moved

sys.modules[__name__] = _moved
