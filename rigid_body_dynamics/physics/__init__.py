"""
Physics of the free and torqued rigid body: numpy/scipy only, never ROS.

Public API (stable): :class:`Inertia`, :class:`FreeRigidBody`,
:func:`simulate`, the modules :mod:`analysis` (the one analysis),
:mod:`theory`, :mod:`estimators`, :mod:`presets`, :mod:`control`, and
:data:`INTEGRATORS` / :func:`make_integrator`.
"""

from . import analysis, control, estimators, momentum_sphere, presets, sensors, theory
from .free_motion import FreeRigidBody
from .inertia import Inertia
from .integrators import INTEGRATORS, make_integrator
from .simulation import simulate, SimulationResult

__all__ = ['analysis', 'control', 'estimators', 'FreeRigidBody', 'Inertia', 'INTEGRATORS',
           'make_integrator', 'momentum_sphere', 'presets', 'sensors', 'simulate',
           'SimulationResult', 'theory']
