"""
Findings of the analysis -> diagnostic_msgs/DiagnosticStatus (REP 107) for attitude_analyzer.

Status names are ``<node>: conservation``, ``<node>: precession`` and
``<node>: stability`` (and ``<node>: orbit`` with ``gravity_gradient``); their values are
:func:`~rigid_body_dynamics.physics.analysis.findings_render.key_values` (the one rendering
of findings to key/values, whose keys the manual's attitude_analyzer page lists),
and :func:`findings_from` reads them back with
:func:`~rigid_body_dynamics.physics.analysis.findings_render.from_key_values`.
``unavailable`` findings are level OK with the reason as the message.
"""

from diagnostic_msgs.msg import DiagnosticStatus

from ..physics.analysis import findings, findings_render
from ..ros.conversions import status

LEVELS = {findings.OK: DiagnosticStatus.OK, findings.WARN: DiagnosticStatus.WARN,
          findings.ERROR: DiagnosticStatus.ERROR, findings.UNAVAILABLE: DiagnosticStatus.OK}
#: The three checks, in the order they are published.
CHECKS = ('conservation', 'precession', 'stability')


def statuses(found, name, hardware_id, origin_ns):
    """
    Return the three DiagnosticStatus of ``found`` for node ``name``.

    ``origin_ns``: the trajectory's origin (int ns), which makes the baseline stamp absolute.
    """
    sections = findings_render.key_values(found, origin_ns)
    return [status(f'{name}: {check}', LEVELS[sections[check][0]], sections[check][1],
                   sections[check][2], hardware_id) for check in CHECKS + ('orbit',)
            if check in sections]


def estimation_status(found, name, hardware_id):
    """Return the ``estimation`` DiagnosticStatus of EstimationFindings ``found``."""
    level, message, values = findings_render.estimation_key_values(found)
    return status(f'{name}: estimation', LEVELS[level], message, values, hardware_id)


def findings_from(received):
    """
    Read an analyzer's statuses back into Findings.

    ``received``: {'conservation' | 'precession' | 'stability' | 'orbit': (level byte,
    message, {key: value text})}, e.g. from one DiagnosticArray.
    """
    status_of = {DiagnosticStatus.OK: findings.OK, DiagnosticStatus.WARN: findings.WARN,
                 DiagnosticStatus.ERROR: findings.ERROR}
    return findings_render.from_key_values(
        {check: (status_of.get(level, findings.ERROR), message, values)
         for check, (level, message, values) in received.items()})
