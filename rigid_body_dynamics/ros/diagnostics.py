"""
Findings of the analysis -> diagnostic_msgs/DiagnosticStatus (REP 107) for attitude_analyzer.

Status names are ``<node>: conservation``, ``<node>: precession`` and
``<node>: stability``; the keys are an interface users parse, listed in the
manual's attitude_analyzer page. A measured quantity gives three keys,
``<label>, measured (<unit>)``, ``<label>, theory (<unit>)`` and
``<label> error (rel.)``; one that is not available gives
``<label>, measured (<unit>)`` = ``not available: <why>``.
``unavailable`` findings are level OK with the reason as the message.
"""

from diagnostic_msgs.msg import DiagnosticStatus

from .conversions import status
from ..physics import analysis

LEVELS = {analysis.OK: DiagnosticStatus.OK, analysis.WARN: DiagnosticStatus.WARN,
          analysis.ERROR: DiagnosticStatus.ERROR, analysis.UNAVAILABLE: DiagnosticStatus.OK}


def quantity(label, qty):
    """Key-value pairs of one :class:`~rigid_body_dynamics.physics.analysis.Quantity`."""
    if qty is None:
        return []
    unit = f' ({qty.unit})' if qty.unit else ''
    out = []
    if qty.measured is None:
        out.append((f'{label}, measured{unit}', f'not available: {qty.why}'))
    else:
        out.append((f'{label}, measured{unit}', qty.measured))
    if qty.theory is not None:
        out.append((f'{label}, theory{unit}', qty.theory))
    if qty.relative_error is not None:
        out += [(f'{label} error (rel.)', qty.relative_error), (f'{label} status', qty.status)]
    return out


def conservation(found, name, hardware_id, origin_ns):
    """Status ``<name>: conservation``; ``origin_ns`` turns the baseline stamp into seconds."""
    values = []
    if found.mode == 'free motion':
        values = [('mode', 'free motion'),
                  ('baseline stamp (s)', (origin_ns + found.baseline_ns) * 1e-9),
                  ('energy drift since baseline (rel.)', found.energy_drift),
                  ('|L| drift since baseline (rel.)', found.momentum_drift),
                  ('L direction drift since baseline (rad)', found.direction_drift)]
    elif found.mode == 'balance laws':
        values = [('mode', 'balance laws (torque applied in the window)'),
                  ('work-energy residual (rel.)', found.energy_residual),
                  ('impulse-momentum residual (rel.)', found.momentum_residual),
                  ('work over the window (J)', found.work)]
    if found.mode != analysis.UNAVAILABLE:
        values += [('energy tolerance', found.energy_tolerance),
                   ('momentum tolerance', found.momentum_tolerance)]
    return status(f'{name}: conservation', LEVELS[found.status], found.message, values,
                  hardware_id)


def precession(found, name, hardware_id):
    """Status ``<name>: precession``."""
    values = []
    if found.kind == 'axisymmetric':
        values += quantity('body rate', found.body_rate) + quantity('lab rate', found.lab_rate)
        values += [('body cone half-angle (rad)', found.cones.body),
                   ('lab cone half-angle (rad)', found.cones.lab),
                   ('nutation angle (rad)', found.cones.nutation)]
    elif found.kind == 'asymmetric':
        values.append(('polhode family', found.polhode_family))
        values += quantity('omega period', found.omega_period)
        if found.circled_axis is not None:
            values += quantity(f'mean precession of axis {found.circled_axis + 1} about L',
                               found.mean_precession)
    elif found.polhode_family:
        values.append(('polhode family', found.polhode_family))
    return status(f'{name}: precession', LEVELS[found.status], found.message, values,
                  hardware_id)


def stability(found, name, hardware_id):
    """Status ``<name>: stability``."""
    values = []
    if found.axis is not None:
        values = [('nearest principal axis', found.axis + 1), ('class', found.kind),
                  ('polhode family', found.family),
                  ('separatrix distance (S/G^2)', found.separatrix_distance)]
        values += quantity('growth rate', found.growth_rate)
        values += quantity('flip interval', found.flip_interval)
        if found.wobble_frequency is not None:
            # the theory value kept under its old key too
            values.append(('wobble frequency (rad/s)', found.wobble_frequency.theory))
            values += quantity('wobble frequency', found.wobble_frequency)
    return status(f'{name}: stability', LEVELS[found.status], found.message, values,
                  hardware_id)


def _number(text):
    try:
        return float(text)
    except (TypeError, ValueError):
        return None


def quantity_from(values, label, unit):
    """
    Read back the :class:`~rigid_body_dynamics.physics.analysis.Quantity` that quantity() wrote.

    ``values`` is a status' key -> string mapping; None when the label is absent.
    """
    suffix = f' ({unit})' if unit else ''
    measured = values.get(f'{label}, measured{suffix}')
    if measured is None:
        return None
    number = _number(measured)
    why = '' if number is not None else str(measured).replace('not available: ', '', 1)
    return analysis.Quantity(number, _number(values.get(f'{label}, theory{suffix}')),
                             values.get(f'{label} status', analysis.OK if number is not None
                                        else analysis.UNAVAILABLE), unit, why=why)
