"""
Physics of the free and torqued rigid body: numpy/scipy only, never ROS.

Sub-packages: :mod:`.dynamics` (the equations, the exact flow, the
integrators, the gyrostat and the one stepping core), :mod:`.environment`
(orbit, field, Sun, torque models), :mod:`.sensors` and :mod:`.analysis` (the
one analysis, the closed forms it measures against, its findings).

Public API (stable): :class:`Inertia`, :class:`FreeRigidBody`,
:func:`simulate`, the modules :mod:`analysis` (the one analysis),
:mod:`theory`, :mod:`estimators`, :mod:`presets`, :mod:`control`, and
:data:`INTEGRATORS` / :func:`make_integrator`. The modules that moved into the
sub-packages keep their old import paths where the manual used them
(``physics.integrators``, ``physics.gyrostat``, ``physics.free_motion``,
``physics.theory``, ``physics.estimators``, ``physics.findings``,
``physics.findings_render``).
"""

from . import analysis, control, dynamics, environment, presets, sensors
from .analysis import estimators, momentum_sphere, theory
from .dynamics.free_motion import FreeRigidBody
from .dynamics.integrators import INTEGRATORS, make_integrator
from .inertia import Inertia
from .simulation import simulate, SimulationResult

__all__ = ['analysis', 'control', 'dynamics', 'environment', 'estimators', 'FreeRigidBody',
           'Inertia', 'INTEGRATORS', 'make_integrator', 'momentum_sphere', 'presets', 'sensors',
           'simulate', 'SimulationResult', 'theory']
