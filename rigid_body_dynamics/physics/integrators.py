"""Old path of rigid_body_dynamics.physics.dynamics.integrators, kept for users' scripts."""

import sys

from .dynamics import integrators as _moved

sys.modules[__name__] = _moved
