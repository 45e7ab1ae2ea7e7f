"""Old path of rigid_body_dynamics.physics.analysis.findings_render, kept for users' scripts."""

import sys

from .analysis import findings_render as _moved

sys.modules[__name__] = _moved
