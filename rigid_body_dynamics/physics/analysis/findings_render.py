"""
The findings in words and as key/values: one rendering for every door, and its reader.

:func:`text_lines` (``rigid_body_analyze``, the demo, ``Findings.lines()``) and
:func:`table_rows` (the report) write the same labels; :func:`key_values` writes
the analyzer's diagnostics values (no ROS here:
:mod:`rigid_body_dynamics.nodes.analyzer_diagnostics` wraps them in DiagnosticStatus),
and :func:`from_key_values` reads them back into :class:`~.findings.Findings`, from
the same tables, so a renamed key changes both
sides (the demo prints what the analyzer found with :func:`text_lines`). The keys
are an interface users parse, listed in the manual's attitude_analyzer page.

A measured quantity gives the keys ``<label>, measured (<unit>)``,
``<label>, theory (<unit>)``, ``<label> error (rel.)`` and ``<label> status``; one
that is not available ``<label>, measured (<unit>)`` = ``not available: <why>``.
"""

import math

from .findings import (ConservationFindings, Findings, OK, OrbitFindings, PrecessionFindings,
                       Quantity, StabilityFindings, UNAVAILABLE)

#: The quantities of the findings: (section, field, diagnostics label, text label). The unit
#: is the quantity's own; ``{axis}`` is the circled axis (1-based).
QUANTITIES = (
    ('precession', 'body_rate', 'body rate', 'body precession Omega'),
    ('precession', 'lab_rate', 'lab rate', 'lab precession |L|/I_perp'),
    ('precession', 'omega_period', 'omega period', 'period of omega'),
    ('precession', 'mean_precession', 'mean precession of axis {axis} about L',
     'mean precession of axis {axis}'),
    ('stability', 'growth_rate', 'growth rate', 'growth rate'),
    ('stability', 'flip_interval', 'flip interval', 'flip interval'),
    ('stability', 'wobble_frequency', 'wobble frequency', 'wobble frequency'),
    ('orbit', 'pitch', 'pitch libration frequency', 'pitch libration'),
    ('orbit', 'roll_yaw_slow', 'roll-yaw libration frequency, slow', 'roll-yaw libration, slow'),
    ('orbit', 'roll_yaw_fast', 'roll-yaw libration frequency, fast', 'roll-yaw libration, fast'),
)
#: The unit each quantity is written with.
UNITS = {'body_rate': 'rad/s', 'lab_rate': 'rad/s', 'omega_period': 's',
         'mean_precession': 'rad/s', 'growth_rate': '1/s', 'flip_interval': 's',
         'wobble_frequency': 'rad/s', 'pitch': 'rad/s', 'roll_yaw_slow': 'rad/s',
         'roll_yaw_fast': 'rad/s'}
#: Conservation values: (mode, field, key).
CONSERVATION = (
    ('free motion', 'energy_drift', 'energy drift since baseline (rel.)'),
    ('free motion', 'momentum_drift', '|L| drift since baseline (rel.)'),
    ('free motion', 'direction_drift', 'L direction drift since baseline (rad)'),
    ('balance laws', 'energy_residual', 'work-energy residual (rel.)'),
    ('balance laws', 'momentum_residual', 'impulse-momentum residual (rel.)'),
    ('balance laws', 'work', 'work over the window (J)'),
    ('momentum exchange', 'momentum_drift', 'total H drift since window start (rel.)'),
    ('momentum exchange', 'direction_drift', 'total H direction drift since window start (rad)'),
    ('momentum exchange', 'energy_residual', 'work-energy residual with motor work (rel.)'),
    ('momentum exchange', 'work', 'motor work less friction over the window (J)'),
)
_MODES = {'free motion': 'free motion',
          'balance laws': 'balance laws (torque applied in the window)',
          'momentum exchange': 'momentum exchange (reaction wheels)'}
#: The other keys, for the manual (generated from here; the suite checks that every key
#: the analyzer writes is listed): (status, key, meaning).
OTHER_KEYS = (
    ('conservation', 'mode', '`free motion`, `balance laws (torque applied in the window)` or '
     '`momentum exchange (reaction wheels)`'),
    ('conservation', 'baseline stamp (s)', 'stamp of the drift baseline (free motion)'),
    ('conservation', 'energy tolerance', 'the tolerance the energy was checked against'),
    ('conservation', 'momentum tolerance', 'the tolerance the momentum was checked against'),
    ('precession', 'kind', '`axisymmetric`, `asymmetric`, `gyrostat` (spinning wheels), '
     '`spherical`, `principal spin` or `unavailable`'),
    ('precession', 'polhode family', 'which axis the polhode circles, or separatrix'),
    ('precession', 'circled axis', 'the principal axis (1-3) the polhode circles'),
    ('precession', 'body cone half-angle (rad)', 'axisymmetric: omega about the symmetry axis'),
    ('precession', 'lab cone half-angle (rad)', 'axisymmetric: omega about L'),
    ('precession', 'nutation angle (rad)', 'axisymmetric: symmetry axis to L'),
    ('stability', 'nearest principal axis', 'the axis (1-3) the motion stays nearest'),
    ('stability', 'class', '`stable`, `unstable`, `marginal` or `rest`'),
    ('stability', 'polhode family', 'as in precession'),
    ('stability', 'separatrix distance (S/G^2)', 'distance of the polhode from the separatrix'),
    ('stability', 'wobble frequency (rad/s)', "the wobble frequency's theory (older key)"),
    ('orbit', 'kind', '`libration` (gravity gradient, circular orbit) or `unavailable`'),
    ('orbit', 'orbit rate (rad/s)', "n, from the odometry's position and velocity"),
    ('orbit', 'moments along roll, pitch, yaw (kg m^2)', 'the principal moments along LVLH '
     "x, y, z at the window's start: I_x, I_y, I_z of the theory"),
    ('orbit', 'stability region', "`Lagrange`, `DeBra-Delp` or `unstable` (the theory's "
     'verdict)'),
    ('orbit', 'largest angle from LVLH (rad)', 'over the window'),
    ('orbit', 'Jacobi integral drift (rel.)', 'largest |E - E0| / |E0| over the window'),
    ('orbit', 'Jacobi tolerance', 'the tolerance it was checked against (the energy one)'),
) + tuple(('estimation', key, meaning) for key, meaning in (
    ('verdict', '`consistent`, `overconfident` (NEES above its interval), `pessimistic` '
     '(below) or `unavailable`'),
    ('estimates matched', 'attitude_estimate samples in the window with an odom of the same '
     'stamp'),
    ('attitude error RMS (rad)', 'the angle of q_est q_true^-1, RMS over the window'),
    ('attitude error max (rad)', 'its largest value'),
    ('attitude error RMS per world axis (rad)', 'the rotation vector of the error, per axis'),
    ('attitude error max per world axis (rad)', 'its largest magnitude per axis'),
    ('fraction inside 3 sigma', "the share of errors inside the covariance's 99.73 % "
     'ellipsoid'),
    ('mean NEES', 'e^T P^-1 e averaged over the window (3 when consistent)'),
    ('NEES interval', 'the chi-square interval of the mean NEES for the independent '
     'samples'),
    ('NEES interval confidence', 'its confidence (`estimation_confidence`): the share of runs '
     'of a consistent estimator it holds'),
    ('correlation time (samples)', "the integrated autocorrelation time of the NEES (Geyer's "
     'initial monotone sequence)'),
    ('independent samples', 'estimates matched / correlation time: what the interval counts'),
    ('gyro bias error RMS per body axis (rad/s)', 'the bias estimate against the true bias, '
     "when both are published at the estimates' stamps"),
))
#: What each quantity is, for the manual.
MEANINGS = {
    'body_rate': "axisymmetric: omega turning about the symmetry axis in the body (Shapiro's "
                 'Omega)',
    'lab_rate': 'axisymmetric: the symmetry axis turning about L, |L|/I_perp',
    'omega_period': 'asymmetric: the period of omega(t), fitted to the sign changes of its '
                    'middle-axis component (one across a gap in the samples left out)',
    'mean_precession': "asymmetric: the circled axis's mean precession about L",
    'growth_rate': 'unstable spin: growth rate of a small departure',
    'flip_interval': 'unstable spin: time between flips (fitted as the omega period)',
    'wobble_frequency': 'stable spin: 2 pi / period of omega',
    'pitch': 'gravity-gradient pitch libration about LVLH, n sqrt(3 (Ix - Iz) / Iy) by theory',
    'roll_yaw_slow': 'the slower root of the roll-yaw libration (Wie, section 6.3)',
    'roll_yaw_fast': 'the faster root of the roll-yaw libration',
}


def reference_rows():
    """
    Return the analyzer's diagnostics keys for the manual: (status, key, meaning) rows.

    ``<axis>`` stands for the circled axis (1-3).
    """
    rows = [(sec, key, meaning) for sec, key, meaning in OTHER_KEYS
            if sec == 'conservation' and key in ('mode', 'baseline stamp (s)')]
    rows += [('conservation', key, f'{mode}: {field.replace("_", " ")}')
             for mode, field, key in CONSERVATION]
    rows += [(sec, key, meaning) for sec, key, meaning in OTHER_KEYS
             if sec == 'conservation' and key not in ('mode', 'baseline stamp (s)')]
    for section in ('precession', 'stability', 'orbit', 'estimation'):
        rows += [(sec, key, meaning) for sec, key, meaning in OTHER_KEYS if sec == section]
        for sec, field, key, _text in QUANTITIES:
            if sec != section:
                continue
            key, unit = key.format(axis='<axis>'), UNITS[field]
            rows += [(sec, f'{key}, measured ({unit})', MEANINGS[field] +
                      ', measured (or `not available: <why>`)'),
                     (sec, f'{key}, theory ({unit})', 'its prediction'),
                     (sec, f'{key} error (rel.)', '|measured - theory| / |theory|'),
                     (sec, f'{key} status', '`OK`, `WARN`, `ERROR` against the tolerance')]
    return rows


def _labels(section, field, found_section):
    """(diagnostics label, text label with unit) of one quantity of ``found_section``."""
    for sec, name, key, text in QUANTITIES:
        if (sec, name) == (section, field):
            axis = getattr(found_section, 'circled_axis', None)
            axis = '' if axis is None else axis + 1
            return key.format(axis=axis), f'{text.format(axis=axis)} ({UNITS[field]})'
    raise KeyError(field)


def _shown(found):
    """Return the (section, field, Quantity) entries a rendering shows, in order."""
    p, s = found.precession, found.stability
    out = []
    if p.kind in ('axisymmetric', 'gyrostat'):
        out += [('precession', 'body_rate', p.body_rate), ('precession', 'lab_rate', p.lab_rate)]
    elif p.kind == 'asymmetric':
        out.append(('precession', 'omega_period', p.omega_period))
        if p.circled_axis is not None:
            out.append(('precession', 'mean_precession', p.mean_precession))
    out += [('stability', 'growth_rate', s.growth_rate),
            ('stability', 'flip_interval', s.flip_interval)]
    if p.body_rate is None:               # a top's wobble is its Omega, shown above
        out.append(('stability', 'wobble_frequency', s.wobble_frequency))
    return [(sec, field, qty) for sec, field, qty in out if qty is not None]


# ---------------------------------------------------------------------------------- text
def quantity_lines(label, qty):
    """One aligned line for a :class:`~.findings.Quantity` (none when there is nothing to say)."""
    if qty is None or (qty.measured is None and qty.theory is None):
        return []
    if qty.measured is None:
        theory_text = '' if qty.theory is None else f' (theory {qty.theory:.10g})'
        return [f'  {label:<36} not available: {qty.why}{theory_text}']
    if qty.theory is None:
        return [f'  {label:<36} {qty.measured:>+.10f}']
    rel = qty.relative_error
    rel_text = '' if rel is None else f'  (rel. {rel:.1e}, {qty.status})'
    return [f'  {label:<36} {qty.measured:>+.10f}  theory {qty.theory:>+.10f}{rel_text}']


def conservation_line(c):
    """One line for :class:`~.findings.ConservationFindings`."""
    if c.mode == 'free motion':
        return (f'  conservation: {c.message} (energy drift {c.energy_drift:.1e}, |L| drift '
                f'{c.momentum_drift:.1e}, L direction drift {c.direction_drift:.1e} rad)')
    if c.mode == 'balance laws':
        return (f'  conservation under torque: {c.message} (work-energy residual '
                f'{c.energy_residual:.1e}, impulse-momentum {c.momentum_residual:.1e})')
    if c.mode == 'momentum exchange':
        return (f'  conservation with wheels: {c.message} (total H drift {c.momentum_drift:.1e}, '
                f'direction {c.direction_drift:.1e} rad, work-energy residual '
                f'{c.energy_residual:.1e})')
    return f'  conservation: {c.message}'


def text_lines(found):
    """Readable lines of :class:`~.findings.Findings`: each number beside theory, statuses."""
    p = found.precession
    out = [f'  {found.samples} samples over {found.span:.6g} s']
    if p.kind not in ('axisymmetric', 'asymmetric'):
        out.append(f'  precession: {p.message}')
    shown = _shown(found)
    for wanted in ('precession', 'stability'):
        if wanted == 'stability':
            out.append(f'  stability: {found.stability.message}')
        for section, field, qty in shown:
            if section == wanted:
                out += quantity_lines(_labels(section, field, getattr(found, section))[1], qty)
    out.append(conservation_line(found.conservation))
    if found.orbit is not None:
        out += orbit_lines(found.orbit)
    return out


def orbit_lines(o):
    """Readable lines of :class:`~.findings.OrbitFindings`: its message, each frequency."""
    out = [f'  orbit: {o.message}']
    for field, qty in _orbit_quantities(o):
        out += quantity_lines(_labels('orbit', field, o)[1], qty)
    return out


def _orbit_quantities(o):
    """Return the (field, Quantity) entries of :class:`~.findings.OrbitFindings` it has."""
    return [(field, getattr(o, field)) for field in ('pitch', 'roll_yaw_slow', 'roll_yaw_fast')
            if getattr(o, field) is not None]


def table_rows(found):
    """Rows (what, measured, theory) of the findings as text, for the report's table."""
    def text(x, fmt='.10g'):
        return 'n/a' if x is None else format(x, fmt)

    c, s = found.conservation, found.stability
    rows = []
    if c.mode == 'free motion':
        rows += [('largest energy drift (rel.)', f'{c.energy_drift:.2e}', '0'),
                 ('largest |L| drift (rel.)', f'{c.momentum_drift:.2e}', '0'),
                 ('largest L direction drift (rad)', f'{c.direction_drift:.2e}', '0')]
    elif c.mode == 'balance laws':
        rows += [('work-energy residual (rel.)', f'{c.energy_residual:.2e}', '0'),
                 ('impulse-momentum residual (rel.)', f'{c.momentum_residual:.2e}', '0')]
    elif c.mode == 'momentum exchange':
        rows += [('largest total H drift (rel.)', f'{c.momentum_drift:.2e}', '0'),
                 ('largest total H direction drift (rad)', f'{c.direction_drift:.2e}', '0'),
                 ('work-energy residual with motor work (rel.)', f'{c.energy_residual:.2e}',
                  '0')]

    def row(section, field, qty):
        measured = text(qty.measured) if qty.measured is not None else \
            f'not available: {qty.why}'
        return _labels(section, field, getattr(found, section))[1], measured, text(qty.theory)

    shown = _shown_all(found)
    rows += [row(*e) for e in shown if e[0] == 'precession']
    if s.axis is not None:
        rows.append(('stability of the spin', s.kind, f'axis {s.axis + 1}'))
    rows += [row(*e) for e in shown if e[0] == 'stability']
    o = found.orbit
    if o is not None and o.kind != UNAVAILABLE:
        rows.append(('Jacobi integral drift (rel.)', f'{o.jacobi_drift:.2e}', '0'))
        rows += [row('orbit', field, qty) for field, qty in _orbit_quantities(o)]
    return rows


# ---------------------------------------------------------------------------------- key/values
def quantity_values(label, qty):
    """Key/value pairs of one :class:`~.findings.Quantity` under ``label``."""
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


def estimation_key_values(e):
    """Return (status, message, [(key, value)]) of EstimationFindings ``e`` (keys as listed)."""
    values = [('verdict', e.verdict), ('estimates matched', e.samples)]
    if e.verdict != 'unavailable':
        values += [('attitude error RMS (rad)', e.rms_total),
                   ('attitude error max (rad)', e.largest_total),
                   ('attitude error RMS per world axis (rad)', [float(c) for c in e.rms]),
                   ('attitude error max per world axis (rad)',
                    [float(c) for c in e.largest]),
                   ('fraction inside 3 sigma', e.inside_3_sigma), ('mean NEES', e.nees),
                   ('NEES interval', list(e.bounds)),
                   ('NEES interval confidence', e.level),
                   ('correlation time (samples)', e.correlation),
                   ('independent samples', e.independent)]
        if e.bias_rms is not None:
            values.append(('gyro bias error RMS per body axis (rad/s)',
                           [float(c) for c in e.bias_rms]))
    return e.status, e.message, values


def key_values(found, origin_ns=0):
    """
    Return {'conservation' | 'precession' | 'stability': (status, message, [(key, value)])}.

    ``origin_ns``: the trajectory's origin (int ns), which makes the baseline's stamp
    absolute (s).
    """
    c, p, s = found.conservation, found.precession, found.stability
    cons = []
    if c.mode in _MODES:
        cons.append(('mode', _MODES[c.mode]))
        if c.mode == 'free motion':
            cons.append(('baseline stamp (s)', (origin_ns + c.baseline_ns) * 1e-9))
        cons += [(key, getattr(c, field)) for mode, field, key in CONSERVATION if mode == c.mode]
        cons += [('energy tolerance', c.energy_tolerance),
                 ('momentum tolerance', c.momentum_tolerance)]
    pre = [('kind', p.kind)]
    if p.kind == 'asymmetric' or (p.kind != 'axisymmetric' and p.polhode_family):
        pre.append(('polhode family', p.polhode_family))
    if p.kind == 'asymmetric' and p.circled_axis is not None:
        pre.append(('circled axis', p.circled_axis + 1))
    stab = []
    if s.axis is not None:
        stab = [('nearest principal axis', s.axis + 1), ('class', s.kind),
                ('polhode family', s.family),
                ('separatrix distance (S/G^2)', s.separatrix_distance)]
    for section, field, qty in _shown_all(found):
        values = pre if section == 'precession' else stab
        if field == 'wobble_frequency':   # the theory value kept under its old key too
            values.append(('wobble frequency (rad/s)', qty.theory))
        values += quantity_values(_labels(section, field, getattr(found, section))[0], qty)
        if field == 'lab_rate':
            values += [('body cone half-angle (rad)', p.cones.body),
                       ('lab cone half-angle (rad)', p.cones.lab),
                       ('nutation angle (rad)', p.cones.nutation)]
    out = {'conservation': (c.status, c.message, cons),
           'precession': (p.status, p.message, pre),
           'stability': (s.status, s.message, stab if s.axis is not None else [])}
    o = found.orbit
    if o is not None:
        values = [('kind', o.kind)]
        if o.kind != UNAVAILABLE:
            values += [('orbit rate (rad/s)', o.orbit_rate),
                       ('moments along roll, pitch, yaw (kg m^2)', ' '.join(
                           f'{m:.10g}' for m in o.moments)),
                       ('stability region', o.region),
                       ('largest angle from LVLH (rad)', o.largest_angle),
                       ('Jacobi integral drift (rel.)', o.jacobi_drift),
                       ('Jacobi tolerance', o.jacobi_tolerance)]
            for field, qty in _orbit_quantities(o):
                values += quantity_values(_labels('orbit', field, o)[0], qty)
        out['orbit'] = (o.status, o.message, values)
    return out


def _shown_all(found):
    """As :func:`_shown`, with the wobble frequency whenever the stability has one."""
    out = [e for e in _shown(found) if e[1] != 'wobble_frequency']
    if found.stability.axis is not None and found.stability.wobble_frequency is not None:
        out.append(('stability', 'wobble_frequency', found.stability.wobble_frequency))
    return out


def _number(text):
    try:
        return float(text)
    except (TypeError, ValueError):
        return None


def _quantity_from(values, label, unit):
    suffix = f' ({unit})' if unit else ''
    measured = values.get(f'{label}, measured{suffix}')
    if measured is None:
        return None
    number = _number(measured)
    why = '' if number is not None else str(measured).replace('not available: ', '', 1)
    return Quantity(number, _number(values.get(f'{label}, theory{suffix}')),
                    values.get(f'{label} status', OK if number is not None else UNAVAILABLE),
                    unit, why=why)


def _or_nan(x):
    return math.nan if x is None else x


def from_key_values(sections, samples=0, span=math.nan):
    """
    Read :func:`key_values`' output back into :class:`~.findings.Findings`.

    ``sections``: {'conservation' | 'precession' | 'stability': (status, message,
    {key: value})}, values as numbers or their text (a diagnostics message carries
    strings); absent sections are ``unavailable``. What the keys do not carry (the
    cones' angles, tolerances) is left out.
    """
    def section(name):
        status, message, values = sections.get(name, (UNAVAILABLE, 'no report', {}))
        return status, message, dict(values)
    c_status, c_message, cv = section('conservation')
    mode = next((m for m, text in _MODES.items() if cv.get('mode') == text), UNAVAILABLE)
    numbers = {field: _number(cv.get(key)) for m, field, key in CONSERVATION if m == mode}
    conservation = ConservationFindings(c_status, c_message, mode, **numbers)
    p_status, p_message, pv = section('precession')
    axis = _number(pv.get('circled axis'))
    circled = None if axis is None else int(axis) - 1
    found = {}
    probe = PrecessionFindings(p_status, p_message, '', circled_axis=circled)
    for sec, field, _key, _text in QUANTITIES:
        label = _labels(sec, field, probe)[0]
        values = pv if sec == 'precession' else section('stability')[2]
        found[field] = _quantity_from(values, label, UNITS[field])
    kind = pv.get('kind') or ('axisymmetric' if found['body_rate'] is not None else (
        'asymmetric' if found['omega_period'] is not None else UNAVAILABLE))
    precession = PrecessionFindings(
        p_status, p_message, kind, body_rate=found['body_rate'], lab_rate=found['lab_rate'],
        omega_period=found['omega_period'], mean_precession=found['mean_precession'],
        circled_axis=circled, polhode_family=pv.get('polhode family', ''))
    s_status, s_message, sv = section('stability')
    nearest = _number(sv.get('nearest principal axis'))
    stability = StabilityFindings(
        s_status, s_message, axis=None if nearest is None else int(nearest) - 1,
        kind=sv.get('class', ''), family=sv.get('polhode family', ''),
        separatrix_distance=_or_nan(_number(sv.get('separatrix distance (S/G^2)'))),
        wobble_frequency=found['wobble_frequency'], growth_rate=found['growth_rate'],
        flip_interval=found['flip_interval'])
    orbit = None
    if 'orbit' in sections:
        o_status, o_message, ov = section('orbit')
        quantities = {field: _quantity_from(ov, _labels('orbit', field, None)[0], 'rad/s')
                      for field in ('pitch', 'roll_yaw_slow', 'roll_yaw_fast')}
        along = ov.get('moments along roll, pitch, yaw (kg m^2)')
        orbit = OrbitFindings(
            o_status, o_message, ov.get('kind', UNAVAILABLE),
            orbit_rate=_number(ov.get('orbit rate (rad/s)')),
            moments=None if not along else tuple(float(m) for m in str(along).split()),
            region=ov.get('stability region', ''),
            largest_angle=_number(ov.get('largest angle from LVLH (rad)')),
            jacobi_drift=_number(ov.get('Jacobi integral drift (rel.)')),
            jacobi_tolerance=_or_nan(_number(ov.get('Jacobi tolerance'))), **quantities)
    return Findings(samples, span, conservation, precession, stability, orbit=orbit)
