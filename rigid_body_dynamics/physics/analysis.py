"""
The one analysis of an attitude trajectory: what the motion does, and whether physics holds.

Every door uses it: the ``attitude_analyzer`` node (live topics), the report,
the demo and ``rigid_body_analyze`` (bags). A :class:`Trajectory` holds the
samples (integer-ns stamps relative to a stated origin, so no precision is
lost to seconds since 1970); :func:`analyse` returns :class:`Findings`:
conservation, precession and stability, every measured number beside its
theory value with a status that says whether they agree within a stated
tolerance (``OK``, ``WARN`` above the tolerance, ``ERROR`` above 100 times
it), or ``unavailable`` with the reason (never a made-up number).

Frames: q (x, y, z, w) rotates the body frame of ``inertia`` into the world
frame; omega (rad/s) and torque (N m) are in that body frame. Axis indices in
the findings are 0-based body axes (the JSON form adds 1).
"""

from dataclasses import dataclass
import math

import numpy as np

from . import equations, estimators, theory
from .inertia import as_inertia

OK, WARN, ERROR, UNAVAILABLE = 'OK', 'WARN', 'ERROR', 'unavailable'
_RANK = {UNAVAILABLE: -1, OK: 0, WARN: 1, ERROR: 2}


@dataclass(frozen=True)
class Trajectory:
    """
    Attitude samples of one body, sorted by stamp, no duplicated stamps.

    ``t_ns`` (N,) int64 ns since ``origin_ns`` (an absolute stamp, e.g. the
    first sample's header stamp, or 0 for simulated time); ``q`` (N, 4) unit
    x-y-z-w body -> world; ``omega`` (N, 3) rad/s body frame; ``torque`` (N, 3)
    N m body frame, the torque acting at each sample (zeros if none); the
    ``inertia`` whose body frame these are in. Build with :meth:`from_samples`
    (sorts, drops duplicates and non-finite samples) or :meth:`from_simulation`.
    """

    t_ns: np.ndarray
    q: np.ndarray
    omega: np.ndarray
    torque: np.ndarray
    inertia: object
    origin_ns: int = 0
    title: str = ''
    dropped: int = 0

    @classmethod
    def from_samples(cls, t_ns, q, omega, inertia, torque=None, origin_ns=None, title=''):
        """
        Sort by stamp, keep the first of a duplicated stamp, drop non-finite samples.

        ``t_ns`` are absolute integer ns stamps; ``origin_ns`` defaults to the
        earliest. ``q`` is normalised (a zero or non-finite quaternion drops
        the sample; ``dropped`` counts those).
        """
        t_ns = np.asarray(t_ns, dtype=np.int64).reshape(-1)
        q = np.asarray(q, dtype=float).reshape(-1, 4)
        w = np.asarray(omega, dtype=float).reshape(-1, 3)
        tau = np.zeros_like(w) if torque is None else np.asarray(torque, float).reshape(-1, 3)
        if not (t_ns.size == len(q) == len(w) == len(tau)):
            raise ValueError('t_ns, q, omega and torque must have one row per sample')
        norm = np.linalg.norm(q, axis=1) if len(q) else np.zeros(0)
        good = (np.isfinite(norm) & (norm > 0.5) & np.all(np.isfinite(w), axis=1)
                & np.all(np.isfinite(tau), axis=1))
        dropped = int(np.count_nonzero(~good))
        t_ns, q, w, tau, norm = t_ns[good], q[good], w[good], tau[good], norm[good]
        order = np.argsort(t_ns, kind='stable')
        keep = np.ones(order.size, dtype=bool)
        keep[1:] = np.diff(t_ns[order]) > 0
        idx = order[keep]
        if origin_ns is None:
            origin_ns = int(t_ns[idx[0]]) if idx.size else 0
        return cls(t_ns[idx] - int(origin_ns), q[idx] / norm[idx, None], w[idx], tau[idx],
                   as_inertia(inertia), int(origin_ns), title, dropped)

    @classmethod
    def from_seconds(cls, t, q, omega, inertia, torque=None, title=''):
        """Build from float stamps (s since an origin at 0), e.g. offline simulation times."""
        t_ns = np.round(np.asarray(t, dtype=float) * 1e9).astype(np.int64)
        return cls.from_samples(t_ns, q, omega, inertia, torque, origin_ns=0, title=title)

    @classmethod
    def from_simulation(cls, result, title=''):
        """Build from a :class:`~rigid_body_dynamics.physics.simulation.SimulationResult`."""
        return cls.from_seconds(result.t, result.q, result.omega, result.inertia, result.torque,
                                title=title or f'{result.integrator} simulation')

    def __len__(self):
        """Return the number of samples."""
        return int(self.t_ns.size)

    @property
    def t(self):
        """Stamps (s) since ``origin_ns``, from the integer ns (exact to double precision)."""
        return self.t_ns.astype(float) / 1e9

    @property
    def span(self):
        """Seconds between the first and the last sample (0 for fewer than two)."""
        return float(self.t_ns[-1] - self.t_ns[0]) / 1e9 if len(self) > 1 else 0.0

    def between(self, start=None, end=None):
        """Keep the samples with start <= t - t_first <= end (s from the first stamp)."""
        if not len(self):
            return self
        rel = (self.t_ns - self.t_ns[0]).astype(float) / 1e9
        keep = np.ones(len(self), dtype=bool)
        if start is not None:
            keep &= rel >= start
        if end is not None:
            keep &= rel <= end
        return Trajectory(self.t_ns[keep], self.q[keep], self.omega[keep], self.torque[keep],
                          self.inertia, self.origin_ns, self.title, self.dropped)

    def principal(self):
        """(moments, q, omega, torque) in the principal frame of the inertia."""
        body = self.inertia
        return (np.asarray(body.moments, dtype=float), body.attitude_to_principal(self.q),
                body.to_principal(self.omega), body.to_principal(self.torque))


@dataclass(frozen=True)
class Tolerances:
    """
    What counts as agreement. Relative unless said; WARN above, ERROR above 100 times.

    ``energy``, ``momentum``: free-motion drift of T, and of |L| and the L
    direction (rad). ``balance``: work-energy and impulse-momentum residuals
    under torque (sampled torque costs an O(dt) quadrature error at each
    change). ``rate``: measured against predicted rates and periods of the
    free motion. ``growth``: the measured growth rate near the intermediate
    axis against the linearised prediction (finite amplitudes differ by
    about 1e-4). ``min_samples``: fewer samples give no estimate.
    """

    energy: float = 1e-6
    momentum: float = 1e-6
    balance: float = 1e-2
    rate: float = 1e-6
    growth: float = 1e-2
    min_samples: int = 20

    def __post_init__(self):
        """Refuse a tolerance that is not a positive number: 0 switched its check off."""
        for name in ('energy', 'momentum', 'balance', 'rate', 'growth'):
            value = getattr(self, name)
            if isinstance(value, bool) or not isinstance(value, (int, float)) \
                    or not math.isfinite(value) or value <= 0.0:
                raise ValueError(f'the {name} tolerance must be a finite number > 0, got '
                                 f'{value!r}')
        if isinstance(self.min_samples, bool) or not isinstance(self.min_samples, int) \
                or self.min_samples < 2:
            raise ValueError(f'min_samples must be an integer >= 2, got {self.min_samples!r}')


@dataclass(frozen=True)
class Quantity:
    """
    A measured number beside its prediction, and whether they agree.

    ``measured`` and ``theory`` are floats or None (None: not available,
    ``why`` says why); ``status`` is OK / WARN / ERROR against ``tolerance``
    (relative), or ``unavailable``; ``unit`` as in the labels.
    """

    measured: object
    theory: object
    status: str
    unit: str = ''
    tolerance: float = math.nan
    why: str = ''

    @property
    def relative_error(self):
        """|measured - theory| / |theory|, or None when either is missing or theory is 0."""
        if self.measured is None or self.theory is None or not self.theory:
            return None
        return abs(self.measured - self.theory) / abs(self.theory)


def _level(worst):
    """Status of a ratio error / tolerance."""
    return OK if worst <= 1.0 else (WARN if worst <= 100.0 else ERROR)


def compare(measured, predicted, tolerance, unit=''):
    """
    Make a :class:`Quantity` of a measurement and its prediction at a relative tolerance.

    ``tolerance`` must be > 0 (ValueError). Without a measurement or without a
    prediction the quantity is ``unavailable``, saying which is missing; a
    prediction of exactly 0 has no relative scale, so the measurement is
    compared on an absolute one: ``|measured|`` against ``tolerance`` (in ``unit``).
    """
    if not tolerance > 0.0:
        raise ValueError(f'a tolerance must be > 0, got {tolerance!r}')
    measured = None if measured is None or not math.isfinite(measured) else float(measured)
    predicted = None if predicted is None or not math.isfinite(predicted) else float(predicted)
    if measured is None:
        return Quantity(None, predicted, UNAVAILABLE, unit, tolerance, 'no measurement')
    if predicted is None:
        return Quantity(measured, None, UNAVAILABLE, unit, tolerance, 'no prediction')
    if predicted == 0.0:
        return Quantity(measured, predicted, _level(abs(measured) / tolerance), unit, tolerance,
                        'compared on an absolute scale: the prediction is 0')
    rel = abs(measured - predicted) / abs(predicted)
    return Quantity(measured, predicted, _level(rel / tolerance), unit, tolerance)


def unavailable(why, predicted=None, unit=''):
    """Make a :class:`Quantity` without a measurement, saying why (a prediction may exist)."""
    predicted = None if predicted is None or not math.isfinite(predicted) else float(predicted)
    return Quantity(None, predicted, UNAVAILABLE, unit, math.nan, why)


def _worst(*statuses):
    known = [s for s in statuses if s != UNAVAILABLE]
    return max(known, key=_RANK.get) if known else UNAVAILABLE


@dataclass(frozen=True)
class ConservationFindings:
    """
    Free motion: largest drift from the baseline; under torque: balance-law residuals.

    ``mode``: 'free motion' or 'balance laws' (torque in the window) or
    'unavailable'. Free: ``energy_drift`` |T/T0 - 1|, ``momentum_drift``
    ||L|/|L0| - 1|, ``direction_drift`` angle(L_w, L_w0) rad, the largest over
    the samples; ``baseline_ns`` the baseline's stamp (ns since origin).
    Balance: ``energy_residual``, ``momentum_residual`` (estimators.balance) and
    the ``work`` (J) over the window.
    """

    status: str
    message: str
    mode: str
    energy_drift: object = None
    momentum_drift: object = None
    direction_drift: object = None
    baseline_ns: object = None
    energy_residual: object = None
    momentum_residual: object = None
    work: object = None
    energy_tolerance: float = math.nan
    momentum_tolerance: float = math.nan


@dataclass(frozen=True)
class PrecessionFindings:
    """
    Precession of the free motion.

    ``kind``: 'axisymmetric', 'asymmetric', 'spherical', 'principal spin' or
    'unavailable'. Axisymmetric: ``body_rate`` (omega about the symmetry axis
    in the body frame, the seed's Omega), ``lab_rate`` (the symmetry axis
    about L), the cone angles (rad). Asymmetric: ``omega_period`` (s) and
    ``mean_precession`` of the ``circled_axis`` about L (rad/s), measured over
    a whole number of periods of omega.
    """

    status: str
    message: str
    kind: str
    body_rate: Quantity = None
    lab_rate: Quantity = None
    omega_period: Quantity = None
    mean_precession: Quantity = None
    cones: object = None
    symmetry_axis: object = None
    circled_axis: object = None
    polhode_family: str = ''


@dataclass(frozen=True)
class StabilityFindings:
    """
    The spin about the principal axis the motion stays nearest over the window.

    ``axis`` (0-based), ``kind`` ('stable', 'unstable', 'marginal', 'rest'),
    ``family`` and ``separatrix_distance`` of the polhode; stable:
    ``wobble_frequency`` (rad/s, 2 pi / period of omega: the same frequency as
    the precession's body rate for a top); unstable: ``growth_rate`` (1/s)
    and ``flip_interval`` (s). Status WARN while unstable.
    """

    status: str
    message: str
    axis: object = None
    kind: str = ''
    family: str = ''
    separatrix_distance: float = math.nan
    wobble_frequency: Quantity = None
    growth_rate: Quantity = None
    flip_interval: Quantity = None


@dataclass(frozen=True)
class Findings:
    """Everything :func:`analyse` says about a trajectory."""

    samples: int
    span: float
    conservation: ConservationFindings
    precession: PrecessionFindings
    stability: StabilityFindings
    kinetic_energy: object = None
    angular_momentum_norm: object = None
    under_torque: bool = False

    def to_dict(self):
        """Return the JSON form (``rigid_body_analyze --json``): numbers, None where n/a."""
        def num(x):
            return None if x is None or not math.isfinite(x) else float(x)

        def quantity(prefix, qty):
            if qty is None:
                return {prefix: None, f'{prefix}_theory': None}
            return {prefix: num(qty.measured), f'{prefix}_theory': num(qty.theory)}
        c, p, s = self.conservation, self.precession, self.stability
        out = {'samples': self.samples, 'span_s': self.span,
               'kinetic_energy': num(self.kinetic_energy),
               'angular_momentum_norm': num(self.angular_momentum_norm),
               'conservation': {'status': c.status, 'mode': c.mode,
                                'energy_drift': num(c.energy_drift),
                                'momentum_drift': num(c.momentum_drift),
                                'direction_drift': num(c.direction_drift),
                                'energy_residual': num(c.energy_residual),
                                'momentum_residual': num(c.momentum_residual),
                                'message': c.message},
               'precession': {'status': p.status, 'kind': p.kind, 'message': p.message,
                              **quantity('body_rate', p.body_rate),
                              **quantity('lab_rate', p.lab_rate if p.lab_rate is not None
                                         else p.mean_precession),
                              **quantity('omega_period', p.omega_period)},
               'stability': {'status': s.status, 'message': s.message,
                             'axis': None if s.axis is None else int(s.axis) + 1,
                             'class': s.kind or None, 'family': s.family or None,
                             'separatrix_distance': num(s.separatrix_distance),
                             **quantity('growth_rate', s.growth_rate),
                             **quantity('flip_interval', s.flip_interval),
                             **quantity('wobble_frequency', s.wobble_frequency)}}
        return out

    def lines(self):
        """Readable lines: each measured number beside theory, statuses and reasons."""
        c, p, s = self.conservation, self.precession, self.stability
        out = [f'  {self.samples} samples over {self.span:.6g} s']
        if p.kind == 'axisymmetric':
            out += quantity_lines('body precession Omega (rad/s)', p.body_rate)
            out += quantity_lines('lab precession |L|/I_perp (rad/s)', p.lab_rate)
        elif p.kind == 'asymmetric':
            out += quantity_lines('period of omega (s)', p.omega_period)
            if p.circled_axis is not None:
                out += quantity_lines(f'mean precession of axis {p.circled_axis + 1} (rad/s)',
                                      p.mean_precession)
        else:
            out.append(f'  precession: {p.message}')
        out.append(f'  stability: {s.message}')
        out += quantity_lines('growth rate (1/s)', s.growth_rate)
        out += quantity_lines('flip interval (s)', s.flip_interval)
        if p.body_rate is None:            # a top's wobble is its Omega, printed above
            out += quantity_lines('wobble frequency (rad/s)', s.wobble_frequency)
        out.append(conservation_line(c))
        return out


def quantity_lines(label, qty):
    """One aligned line for a :class:`Quantity` (none when there is nothing to say)."""
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
    """One line for :class:`ConservationFindings`."""
    if c.mode == 'free motion':
        return (f'  conservation: {c.message} (energy drift {c.energy_drift:.1e}, |L| drift '
                f'{c.momentum_drift:.1e}, L direction drift {c.direction_drift:.1e} rad)')
    if c.mode == 'balance laws':
        return (f'  conservation under torque: {c.message} (work-energy residual '
                f'{c.energy_residual:.1e}, impulse-momentum {c.momentum_residual:.1e})')
    return f'  conservation: {c.message}'


def analyse(trajectory, baseline=None, tolerances=Tolerances()):
    """
    Analyse ``trajectory``: conservation, precession, stability against theory.

    ``baseline`` (optional) is the (t_ns, q, omega) sample free-motion drift
    is measured from, in the trajectory's frames and time origin: the first
    sample by stamp of the current torque-free segment, which a live window
    may already have dropped. Default: the trajectory's first sample. With a
    non-zero torque anywhere in the trajectory the balance laws are checked
    instead, and the free-motion theory (precession, flips) is not applied.
    """
    n, tol = len(trajectory), tolerances
    if n < tol.min_samples:
        why = f'not enough data yet ({n} of {tol.min_samples} samples)'
        return Findings(n, trajectory.span,
                        ConservationFindings(UNAVAILABLE, why, UNAVAILABLE),
                        PrecessionFindings(UNAVAILABLE, why, UNAVAILABLE),
                        StabilityFindings(UNAVAILABLE, why))
    moments, q, w, tau = trajectory.principal()
    t = trajectory.t
    under_torque = bool(np.any(tau != 0.0))
    if baseline is None:
        baseline = (int(trajectory.t_ns[0]), q[0], w[0])
    else:
        b_t, b_q, b_w = baseline
        baseline = (int(b_t),
                    trajectory.inertia.attitude_to_principal(np.asarray(b_q, dtype=float)),
                    trajectory.inertia.to_principal(np.asarray(b_w, dtype=float)))
    conservation = _conservation(t, q, w, tau, moments, baseline, under_torque, tol)
    if under_torque:
        why = 'torque applied in the window: the free-motion theory does not apply'
        precession = PrecessionFindings(UNAVAILABLE, why, UNAVAILABLE)
        stability = _stability(t, w, moments, trajectory.inertia, tol, torque_why=why)
    else:
        precession = _precession(t, q, w, moments, trajectory.inertia, tol)
        stability = _stability(t, w, moments, trajectory.inertia, tol, precession=precession)
    return Findings(n, trajectory.span, conservation, precession, stability,
                    kinetic_energy=float(equations.kinetic_energy(moments, w[-1])),
                    angular_momentum_norm=float(np.linalg.norm(moments * w[-1])),
                    under_torque=under_torque)


def _conservation(t, q, w, tau, moments, baseline, under_torque, tol):
    if under_torque:
        bal = estimators.balance(t, q, w, tau, moments)
        worst = max(bal.energy, bal.momentum) / tol.balance if tol.balance else 0.0
        level = _level(worst)
        message = ('balance laws hold under torque' if level == OK else
                   f'{"energy" if bal.energy >= bal.momentum else "angular momentum"} balance '
                   f'off by {worst:.3g} x tolerance')
        return ConservationFindings(level, message, 'balance laws', energy_residual=bal.energy,
                                    momentum_residual=bal.momentum, work=bal.work,
                                    energy_tolerance=tol.balance, momentum_tolerance=tol.balance)
    b_t, b_q, b_w = baseline
    energy, norm, direction = estimators.drift_series(moments, q, w, b_q, b_w)
    e_err, l_err, d_err = float(energy.max()), float(norm.max()), float(direction.max())
    worst_e = e_err / tol.energy if tol.energy else 0.0
    worst_l = max(l_err, d_err) / tol.momentum if tol.momentum else 0.0
    worst = max(worst_e, worst_l)
    level = _level(worst)
    message = 'conserved' if level == OK else (
        f'{"energy" if worst_e >= worst_l else "angular momentum"} off by {worst:.3g} x '
        'tolerance')
    return ConservationFindings(level, message, 'free motion', e_err, l_err, d_err, int(b_t),
                                energy_tolerance=tol.energy, momentum_tolerance=tol.momentum)


def _precession(t, q, w, moments, inertia, tol):
    axis = inertia.symmetry_axis
    if axis is None and inertia.kind == 'spherical':
        return PrecessionFindings(OK, 'a spherical body does not precess', 'spherical')
    if axis is None:
        return _asymmetric_precession(t, q, w, moments, tol)
    others = [(axis + 1) % 3, (axis + 2) % 3]
    # equal within EQUAL_MOMENT_RTOL; the mean is the best single I_perp
    i_perp = float(np.mean(moments[others]))
    w_axis = float(w[-1, axis])
    w_perp = float(math.hypot(w[-1, others[0]], w[-1, others[1]]))
    g = float(np.linalg.norm(moments * w[-1]))
    body_theory = theory.body_precession_rate(i_perp, moments[axis], w_axis)
    lab_theory = theory.lab_precession_rate(i_perp, g)
    cones = theory.cone_angles(i_perp, moments[axis], w_perp, w_axis)
    if w_perp <= 1e-12 * max(abs(w_axis), 1e-300):
        return PrecessionFindings(OK, f'spin about the symmetry axis {axis + 1}: no precession',
                                  'principal spin', symmetry_axis=axis, cones=cones)
    body = compare(estimators.body_precession_rate(t, w, axis).rate, body_theory, tol.rate,
                   'rad/s')
    lab = compare(estimators.lab_precession_rate(t, q, w, moments, axis).rate, lab_theory,
                  tol.rate, 'rad/s')
    status = _worst(body.status, lab.status)
    message = (f'body {body.measured:.6g} rad/s (theory {body_theory:.6g}), '
               f'lab {lab.measured:.6g} rad/s (theory {lab_theory:.6g})')
    if status != OK:
        message += f': off by more than the tolerance {tol.rate:g}'
    return PrecessionFindings(status, message, 'axisymmetric', body_rate=body, lab_rate=lab,
                              cones=cones, symmetry_axis=axis, polhode_family='symmetric')


def _asymmetric_precession(t, q, w, moments, tol):
    period = theory.omega_period(moments, w[-1])
    pol = theory.polhode(moments, w[-1])
    if not math.isfinite(period) or pol.circled_axis is None:
        return PrecessionFindings(OK, f'no periodic precession ({pol.family})', 'principal spin'
                                  if pol.family != 'separatrix' else 'asymmetric',
                                  polhode_family=pol.family)
    axis = pol.circled_axis
    mean_theory = theory.mean_precession_rate(moments, w[-1], axis)
    span = float(t[-1] - t[0])
    if span < period:
        why = (f'window ({span:.3g} s) shorter than a period of omega ({period:.6g} s): no '
               'measurement yet')
        return PrecessionFindings(
            UNAVAILABLE, why, 'asymmetric',
            omega_period=unavailable(why, period, 's'),
            mean_precession=unavailable(why, mean_theory, 'rad/s'),
            circled_axis=axis, polhode_family=pol.family)
    # omega about the middle axis is a2 sn(u) in both families: its zero crossings
    # are exactly half a period apart (no mean to remove)
    mid = int(np.argsort(moments)[1])
    try:
        omega_period = compare(estimators.crossing_period(t, w[:, mid], 0), period, tol.rate, 's')
    except ValueError as err:
        omega_period = unavailable(str(err), period, 's')
    rate, periods = estimators.mean_rate_over_periods(
        t, estimators.lab_precession_angle(q, w, moments, axis), period)
    mean = compare(rate, mean_theory, tol.rate, 'rad/s')
    status = _worst(omega_period.status, mean.status)
    measured = 'n/a' if omega_period.measured is None else f'{omega_period.measured:.6g}'
    message = (f'omega period {measured} s (theory {period:.6g}), axis {axis + 1} precesses '
               f'about L at {rate:.6g} rad/s '
               f'over {periods} period{"s" if periods > 1 else ""} (theory {mean_theory:.6g})')
    if status != OK:
        message += f': off by more than the tolerance {tol.rate:g}'
    return PrecessionFindings(status, message, 'asymmetric', omega_period=omega_period,
                              mean_precession=mean, circled_axis=axis, polhode_family=pol.family)


def _stability(t, w, moments, inertia, tol, precession=None, torque_why=None):
    """
    Classify the spin about the principal axis the motion stays nearest over the window.

    (During a tennis-racket flip omega passes other axes for a moment; the
    window average does not.) The spin about that axis is |L| / I_axis.
    """
    omega = w[-1]
    axis = int(np.argmax(np.mean(np.abs(w), axis=0)))
    spin = math.copysign(float(np.linalg.norm(moments * omega)) / moments[axis],
                         omega[axis] if omega[axis] else 1.0)
    st = theory.axis_stability(moments, axis, spin)
    pol = theory.polhode(moments, omega)
    common = {'axis': st.axis, 'kind': st.kind, 'family': pol.family,
              'separatrix_distance': pol.separatrix_distance}
    if st.kind == 'unstable':
        flip = theory.flip_interval(moments, omega)
        message = f'spin about axis {st.axis + 1} is unstable: growth rate {st.rate:.6g} 1/s'
        if torque_why:
            return StabilityFindings(WARN, message, growth_rate=unavailable(torque_why, st.rate),
                                     flip_interval=unavailable(torque_why, flip, 's'), **common)
        try:
            growth = compare(estimators.separatrix_growth_rate(t, w, moments), st.rate,
                             tol.growth, '1/s')
        except ValueError as err:
            growth = unavailable(str(err), st.rate, '1/s')
        try:
            flips = compare(estimators.flip_interval(t, w, st.axis), flip, tol.rate, 's')
        except ValueError as err:
            flips = unavailable(str(err), flip, 's')
        return StabilityFindings(WARN, message, growth_rate=growth, flip_interval=flips,
                                 **common)
    if inertia.kind == 'spherical':
        return StabilityFindings(OK, 'a spherical body spins stably about any axis', **common)
    period = theory.omega_period(moments, omega)
    wobble_theory = 2.0 * math.pi / period if math.isfinite(period) else 0.0
    if torque_why:
        wobble = unavailable(torque_why, wobble_theory, 'rad/s')
    elif precession is not None and precession.body_rate is not None:
        # a top: the wobble is the body-frame precession Omega (one frequency, one number)
        wobble = compare(abs(precession.body_rate.measured), abs(precession.body_rate.theory),
                         tol.rate, 'rad/s')
    elif precession is not None and precession.omega_period is not None \
            and precession.omega_period.measured is not None:
        wobble = compare(2.0 * math.pi / precession.omega_period.measured, wobble_theory,
                         tol.rate, 'rad/s')
    else:
        wobble = unavailable('no periodic wobble measured' if precession is None or
                             precession.omega_period is None else precession.omega_period.why,
                             wobble_theory, 'rad/s')
    return StabilityFindings(OK, f'spin about axis {st.axis + 1} is {st.kind}',
                             wobble_frequency=wobble, **common)
