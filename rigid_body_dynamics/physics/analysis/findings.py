"""
The findings of the analysis, as data: measured numbers beside theory, and their statuses.

:func:`~.analysis.analyse` makes them, :mod:`.tolerances` decides their statuses,
:mod:`.findings_render` turns them into text, table rows and diagnostics key/values
(and reads those back). A status is ``OK``, ``WARN`` (above the tolerance),
``ERROR`` (above 100 times it) or ``unavailable`` (with the reason, never a
made-up number). Axis indices are 0-based body axes (the JSON form adds 1).
"""

from dataclasses import dataclass
import math

OK, WARN, ERROR, UNAVAILABLE = 'OK', 'WARN', 'ERROR', 'unavailable'
RANK = {UNAVAILABLE: -1, OK: 0, WARN: 1, ERROR: 2}


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
        """Return ``abs(measured - theory) / abs(theory)``, or None (either missing, theory 0)."""
        if self.measured is None or self.theory is None or not self.theory:
            return None
        return abs(self.measured - self.theory) / abs(self.theory)


@dataclass(frozen=True)
class ConservationFindings:
    """
    Free motion: largest drift from the baseline; under torque: balance-law residuals.

    ``mode``: 'free motion' or 'balance laws' (torque in the window) or
    'unavailable'. Free: ``energy_drift`` ``abs(T/T0 - 1)``, ``momentum_drift``
    ``abs(norm(L)/norm(L0) - 1)``, ``direction_drift`` angle(L_w, L_w0) rad, the largest over
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
    in the body frame, Shapiro's Omega), ``lab_rate`` (the symmetry axis
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
class OrbitFindings:
    """
    A body under the gravity gradient in a circular orbit: libration about LVLH, Jacobi drift.

    ``kind``: 'libration' or 'unavailable'. ``orbit_rate`` n (rad/s, from the odometry's
    position and velocity); ``moments`` the principal moments (kg m^2) along LVLH roll,
    pitch and yaw (I_x, I_y, I_z of the theory); ``pitch``, ``roll_yaw_slow``,
    ``roll_yaw_fast`` (Quantity, rad/s): the measured
    libration frequencies against the theory of
    :func:`~.environment.libration.libration_modes`; ``region`` 'Lagrange',
    'DeBra-Delp' or 'unstable'; ``largest_angle`` (rad) from LVLH over the window;
    ``jacobi_drift`` the largest |E - E0| / |E0| of the Jacobi integral.
    """

    status: str
    message: str
    kind: str
    orbit_rate: object = None
    moments: object = None
    pitch: Quantity = None
    roll_yaw_slow: Quantity = None
    roll_yaw_fast: Quantity = None
    region: str = ''
    largest_angle: object = None
    jacobi_drift: object = None
    jacobi_tolerance: float = math.nan


@dataclass(frozen=True)
class EstimationFindings:
    """
    An attitude estimate judged against the truth over a window of matched stamps.

    ``samples`` the estimates matched to a true attitude; ``rms`` and ``largest``
    (3,) the attitude error per world axis (rad) and ``rms_total``, ``largest_total``
    its angle; ``inside_3_sigma`` the fraction of samples whose error is inside the
    3-sigma ellipsoid of the reported covariance; ``nees`` the mean normalised
    estimation error squared (3 for a consistent estimator); ``correlation`` the
    integrated autocorrelation time (samples) of the NEES, and
    ``independent`` = samples / correlation, the independent samples the bounds
    count; ``bounds`` the two-sided chi-square interval of confidence ``level``
    (0.95 unless asked) of the mean NEES for 3 ``independent`` degrees of freedom;
    ``verdict`` 'consistent', 'overconfident'
    (NEES above the interval), 'pessimistic' (below) or 'unavailable'. With a
    bias estimate and the true bias: ``bias_rms`` (3,) rad/s.
    """

    status: str
    message: str
    verdict: str
    samples: int = 0
    rms: object = None
    largest: object = None
    rms_total: float = math.nan
    largest_total: float = math.nan
    inside_3_sigma: float = math.nan
    nees: float = math.nan
    correlation: float = math.nan
    independent: float = math.nan
    bounds: tuple = (math.nan, math.nan)
    bias_rms: object = None
    level: float = 0.95


@dataclass(frozen=True)
class Findings:
    """Everything :func:`analyse` says about a trajectory (``orbit`` with an orbit)."""

    samples: int
    span: float
    conservation: ConservationFindings
    precession: PrecessionFindings
    stability: StabilityFindings
    kinetic_energy: object = None
    angular_momentum_norm: object = None
    under_torque: bool = False
    orbit: object = None

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
        o = self.orbit
        if o is not None:
            out['orbit'] = {'status': o.status, 'kind': o.kind, 'message': o.message,
                            'orbit_rate': num(o.orbit_rate), 'region': o.region or None,
                            'moments': None if o.moments is None else list(o.moments),
                            'largest_angle': num(o.largest_angle),
                            'jacobi_drift': num(o.jacobi_drift),
                            **quantity('pitch', o.pitch),
                            **quantity('roll_yaw_slow', o.roll_yaw_slow),
                            **quantity('roll_yaw_fast', o.roll_yaw_fast)}
        return out

    def lines(self):
        """Return readable lines: each number beside theory (see findings_render)."""
        from .findings_render import text_lines
        return text_lines(self)
