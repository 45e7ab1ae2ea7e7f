"""
Monte Carlo campaigns: many dispersed runs of the offline engine, judged as an ensemble.

``rigid_body_campaign CONFIG.yaml`` (:mod:`rigid_body_dynamics.tools.campaign`)
and the Python API: :func:`load` a campaign file, :func:`run_campaign` its
missing runs on Dask (or in this process), :func:`gather` the records and
:func:`judge` them. Modules: :mod:`.config` (the file's keys),
:mod:`.dispersions` (the draws), :mod:`.scenario` (one run: the nodes'
parameters on the engine, the MEKF and the law), :mod:`.runner` (tasks,
records, resuming), :mod:`.results` (tables and the report page).
"""

from .config import build, Campaign, KEYS, load
from .results import gather, judge, summary_lines, write
from .runner import run_campaign, run_one

__all__ = ['build', 'Campaign', 'gather', 'judge', 'KEYS', 'load', 'run_campaign', 'run_one',
           'summary_lines', 'write']
