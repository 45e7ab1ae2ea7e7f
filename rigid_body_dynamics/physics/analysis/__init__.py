"""
The analysis of an attitude trajectory, written once and used by every door.

:mod:`.motion` computes the findings of a :class:`Trajectory` (conservation,
precession, stability, the orbit's libration, an estimator's consistency);
:mod:`.findings` is their data model, :mod:`.tolerances` what counts as
agreement, :mod:`.findings_render` their text, table and diagnostics forms.
The closed forms they are measured against are :mod:`.theory`; the estimates
from sampled data :mod:`.estimators`; the pictures' geometry
:mod:`.momentum_sphere` and :mod:`.poinsot`. The names of :mod:`.motion`
(:func:`analyse`, :class:`Trajectory`, :func:`estimation`, ...) are
importable from here, as they were from ``physics/analysis.py``.
"""

from . import (estimators, findings, findings_render, momentum_sphere, motion, poinsot, theory,
               tolerances)
from .motion import (analyse, autocorrelation_time, compare, ConservationFindings, ERROR,
                     estimation, EstimationFindings, Findings, OK, OrbitFindings,
                     PrecessionFindings, Quantity, quantity_lines, StabilityFindings, Tolerances,
                     Trajectory, UNAVAILABLE, unavailable, WARN)

__all__ = ['analyse', 'autocorrelation_time', 'compare', 'ConservationFindings', 'ERROR',
           'estimation', 'EstimationFindings', 'estimators', 'Findings', 'findings',
           'findings_render', 'momentum_sphere', 'motion', 'OK', 'OrbitFindings', 'poinsot',
           'PrecessionFindings', 'Quantity', 'quantity_lines', 'StabilityFindings', 'theory',
           'Tolerances', 'tolerances', 'Trajectory', 'UNAVAILABLE', 'unavailable', 'WARN']
