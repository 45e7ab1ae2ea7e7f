"""
The one analysis of an attitude trajectory: what the motion does, and whether physics holds.

This module computes; the findings' data model is :mod:`.findings`, what counts
as agreement :mod:`.tolerances`, and their text, table and diagnostics forms
:mod:`.findings_render` (the package :mod:`rigid_body_dynamics.physics.analysis`
re-exports their names and this module's).

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

from . import estimators, theory
from .findings import (ConservationFindings, ERROR, EstimationFindings, Findings, OK,
                       OrbitFindings, PrecessionFindings, Quantity, StabilityFindings,
                       UNAVAILABLE, WARN)
from .findings_render import quantity_lines
from .tolerances import compare, level, Tolerances, unavailable, worst
from .. import quaternions
from ..dynamics import equations
from ..environment.libration import jacobi_integral, libration_modes, oscillation_frequencies
from ..inertia import as_inertia

__all__ = ['analyse', 'autocorrelation_time', 'compare', 'ConservationFindings', 'ERROR',
           'estimation', 'EstimationFindings', 'Findings', 'OK', 'OrbitFindings',
           'PrecessionFindings', 'Quantity', 'quantity_lines', 'StabilityFindings', 'Tolerances',
           'Trajectory', 'UNAVAILABLE', 'unavailable', 'WARN']


@dataclass(frozen=True)
class Trajectory:
    """
    Attitude samples of one body, sorted by stamp, no duplicated stamps.

    ``t_ns`` (N,) int64 ns since ``origin_ns`` (an absolute stamp, e.g. the
    first sample's header stamp, or 0 for simulated time); ``q`` (N, 4) unit
    x-y-z-w body -> world; ``omega`` (N, 3) rad/s body frame; ``torque`` (N, 3)
    N m body frame, the external torque acting at each sample (zeros if none); the
    ``inertia`` whose body frame these are in. A body with reaction wheels also has
    ``wheels`` (a :class:`~.gyrostat.Wheels`, body frame), ``wheel_speeds`` (N, n)
    rad/s relative to the body and ``motor_torques`` (N, n) N m (the torques applied
    over the step ending at each sample). A body in orbit also has ``position``
    (N, 3) m and ``velocity`` (N, 3) m/s, both in the world frame (None without).
    Build with :meth:`from_samples` (sorts, drops duplicates and non-finite samples)
    or :meth:`from_simulation`.
    """

    t_ns: np.ndarray
    q: np.ndarray
    omega: np.ndarray
    torque: np.ndarray
    inertia: object
    origin_ns: int = 0
    title: str = ''
    dropped: int = 0
    wheels: object = None
    wheel_speeds: object = None
    motor_torques: object = None
    position: object = None
    velocity: object = None

    @classmethod
    def from_samples(cls, t_ns, q, omega, inertia, torque=None, origin_ns=None, title='',
                     wheels=None, wheel_speeds=None, motor_torques=None, position=None,
                     velocity=None):
        """
        Sort by stamp, keep the first of a duplicated stamp, drop non-finite samples.

        ``t_ns`` are absolute integer ns stamps; ``origin_ns`` defaults to the
        earliest. ``q`` is normalised (a zero or non-finite quaternion drops
        the sample; ``dropped`` counts those). ``wheels``, ``wheel_speeds`` and
        ``motor_torques``, ``position`` and ``velocity``: see the class (one row per
        sample, or None).
        """
        t_ns = np.asarray(t_ns, dtype=np.int64).reshape(-1)
        q = np.asarray(q, dtype=float).reshape(-1, 4)
        w = np.asarray(omega, dtype=float).reshape(-1, 3)
        tau = np.zeros_like(w) if torque is None else np.asarray(torque, float).reshape(-1, 3)
        if not (t_ns.size == len(q) == len(w) == len(tau)):
            raise ValueError('t_ns, q, omega and torque must have one row per sample')
        n = wheels.count if wheels is not None else 0
        speeds = np.zeros((len(w), n)) if wheel_speeds is None else \
            np.asarray(wheel_speeds, dtype=float).reshape(len(w), n)
        motors = np.zeros((len(w), n)) if motor_torques is None else \
            np.asarray(motor_torques, dtype=float).reshape(len(w), n)
        orbit = position is not None and velocity is not None
        r = np.asarray(position, dtype=float).reshape(len(w), 3) if orbit else \
            np.zeros((len(w), 3))
        v = np.asarray(velocity, dtype=float).reshape(len(w), 3) if orbit else r
        norm = np.linalg.norm(q, axis=1) if len(q) else np.zeros(0)
        good = (np.isfinite(norm) & (norm > 0.5) & np.all(np.isfinite(w), axis=1)
                & np.all(np.isfinite(tau), axis=1) & np.all(np.isfinite(speeds), axis=1)
                & np.all(np.isfinite(motors), axis=1) & np.all(np.isfinite(r), axis=1)
                & np.all(np.isfinite(v), axis=1))
        dropped = int(np.count_nonzero(~good))
        t_ns, q, w, tau, norm = t_ns[good], q[good], w[good], tau[good], norm[good]
        speeds, motors, r, v = speeds[good], motors[good], r[good], v[good]
        order = np.argsort(t_ns, kind='stable')
        keep = np.ones(order.size, dtype=bool)
        keep[1:] = np.diff(t_ns[order]) > 0
        idx = order[keep]
        if origin_ns is None:
            origin_ns = int(t_ns[idx[0]]) if idx.size else 0
        has = wheels is not None and n > 0
        return cls(t_ns[idx] - int(origin_ns), q[idx] / norm[idx, None], w[idx], tau[idx],
                   as_inertia(inertia), int(origin_ns), title, dropped,
                   wheels if has else None, speeds[idx] if has else None,
                   motors[idx] if has else None, r[idx] if orbit else None,
                   v[idx] if orbit else None)

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
                          self.inertia, self.origin_ns, self.title, self.dropped, self.wheels,
                          None if self.wheels is None else self.wheel_speeds[keep],
                          None if self.wheels is None else self.motor_torques[keep],
                          None if self.position is None else self.position[keep],
                          None if self.velocity is None else self.velocity[keep])

    def principal(self):
        """(moments, q, omega, torque) in the principal frame of the inertia."""
        body = self.inertia
        return (np.asarray(body.moments, dtype=float), body.attitude_to_principal(self.q),
                body.to_principal(self.omega), body.to_principal(self.torque))


def analyse(trajectory, baseline=None, tolerances=Tolerances(), gravity_gradient=False):
    """
    Analyse ``trajectory``: conservation, precession, stability against theory.

    With ``gravity_gradient`` and the trajectory's position and velocity, also the
    libration about LVLH and the Jacobi integral of a circular orbit (``orbit``).

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
    spinning = trajectory.wheels is not None and bool(
        np.any(trajectory.wheel_speeds != 0.0) or np.any(trajectory.motor_torques != 0.0))
    if spinning:
        conservation = _momentum_exchange(trajectory, q, w, under_torque, tol)
    else:
        conservation = _conservation(t, q, w, tau, moments, baseline, under_torque, tol)
    if spinning:
        precession, stability = _gyrostat(trajectory, t, w, under_torque, tol)
    elif under_torque:
        why = 'torque applied in the window: the free-motion theory does not apply'
        precession = PrecessionFindings(UNAVAILABLE, why, UNAVAILABLE)
        stability = _stability(t, w, moments, trajectory.inertia, tol, torque_why=why)
    else:
        precession = _precession(t, q, w, moments, trajectory.inertia, tol)
        stability = _stability(t, w, moments, trajectory.inertia, tol, precession=precession)
    orbit = None
    if gravity_gradient and trajectory.position is not None:
        orbit = _orbit(trajectory, moments, q, w, tol)
    return Findings(n, trajectory.span, conservation, precession, stability,
                    kinetic_energy=float(equations.kinetic_energy(moments, w[-1])),
                    angular_momentum_norm=float(np.linalg.norm(moments * w[-1])),
                    under_torque=under_torque, orbit=orbit)


#: Largest angle (rad) from LVLH for which the libration frequencies are measured.
LIBRATION_ANGLE = 0.2
#: Largest |r . v| / (|r| |v|) of an orbit taken as circular.
CIRCULAR = 1e-6
#: At most this many samples go into the frequency estimate (the window is decimated).
LIBRATION_SAMPLES = 3000


def _orbit(trajectory, moments, q, w, tol):
    """
    Libration about LVLH and the Jacobi integral of a circular orbit (principal-frame q, w).

    The principal axes are matched to LVLH roll, pitch and yaw by the axis permutation
    nearest the attitude at the window's start, so any principal axis may be the one
    along nadir (the theory takes the moments along roll, pitch, yaw); the frequencies
    are measured by ESPRIT on the angles from LVLH.
    """
    from scipy.spatial.transform import Rotation
    r, v = trajectory.position, trajectory.velocity
    rn, vn = np.linalg.norm(r, axis=1), np.linalg.norm(v, axis=1)
    if not (np.all(rn > 0.0) and np.all(vn > 0.0)):
        return OrbitFindings(UNAVAILABLE, 'no orbit in the odometry (position or velocity 0)',
                             UNAVAILABLE)
    radial = float(np.max(np.abs(np.sum(r * v, axis=1)) / (rn * vn)))
    if radial > CIRCULAR:
        return OrbitFindings(UNAVAILABLE, f'the orbit is not circular (radial velocity up to '
                             f'{radial:.1e} of the speed): the libration theory and the Jacobi '
                             'integral are for a circular orbit', UNAVAILABLE)
    h = np.cross(r, v)
    hn = np.linalg.norm(h, axis=1)
    n = float(np.mean(hn / (rn * rn)))
    lvlh = Rotation.from_matrix(np.stack([np.cross(-h / hn[:, None], -r / rn[:, None]),
                                          -h / hn[:, None], -r / rn[:, None]], axis=2))
    body = Rotation.from_quat(q)
    # the Jacobi integral, in the principal frame
    energy = jacobi_integral(moments, n, w, body.inv().apply(h / hn[:, None]),
                             body.inv().apply(r / rn[:, None]))
    scale = max(abs(energy[0]), 1e-300)
    drift = float(np.max(np.abs(energy - energy[0])) / scale)
    jacobi_status = level(drift / tol.energy)
    # the axis permutation P nearest the start: LVLH axis i = principal axis axes[i]
    rel = lvlh.inv() * body
    cube = Rotation.create_group('O')
    p = cube[int(np.argmin((cube * rel[0].inv()).magnitude()))]
    along = tuple(float(m) for m in np.abs(np.rint(p.as_matrix())) @ moments)  # I_x, I_y, I_z
    angles = (rel * p.inv()).as_rotvec()           # roll, pitch, yaw from LVLH (rad)
    largest = float(np.max(np.abs(angles)))
    theory = libration_modes(along, n)
    slow, fast = theory.roll_yaw if theory.roll_yaw is not None else (None, None)
    t = trajectory.t
    span = t[-1] - t[0] if t.size > 1 else 0.0
    known = [f for f in (theory.pitch, slow) if f]
    need = 1.5 * 2 * math.pi / min(known) if known else math.inf
    why = ''
    if largest > LIBRATION_ANGLE:
        why = (f'{largest:.3g} rad from LVLH (beyond {LIBRATION_ANGLE:g}): the small-angle '
               'theory does not apply')
    elif span < need:
        why = f'need {need:.6g} s of data (1.5 periods of the slowest libration), have {span:.6g}'
    if why:
        pitch = unavailable(why, theory.pitch, 'rad/s')
        roll_slow, roll_fast = unavailable(why, slow, 'rad/s'), unavailable(why, fast, 'rad/s')
    else:
        grid = np.linspace(t[0], t[-1], min(t.size, LIBRATION_SAMPLES))
        uniform = np.stack([np.interp(grid, t, angles[:, k]) for k in range(3)])
        measured_pitch = oscillation_frequencies(grid, uniform[1], 1)
        measured_roll = oscillation_frequencies(grid, uniform[[0, 2]], 2)
        pitch = compare(None if measured_pitch is None else measured_pitch[0], theory.pitch,
                        tol.libration, 'rad/s')
        roll_slow, roll_fast = (compare(None if measured_roll is None else measured_roll[k],
                                        mode, tol.libration, 'rad/s')
                                for k, mode in enumerate((slow, fast)))
    status = worst(jacobi_status, pitch.status, roll_slow.status, roll_fast.status)
    verdict = ('stable' if theory.stable else 'unstable') + f' ({theory.region} region)'
    message = (f'gravity-gradient libration about LVLH, {verdict}; Jacobi integral drift '
               f'{drift:.1e}')
    return OrbitFindings(status, message, 'libration', n, along, pitch, roll_slow, roll_fast,
                         theory.region, largest, drift, tol.energy)


def _gyrostat(trajectory, t, w, under_torque, tol):
    """
    Precession and stability of a torque-free gyrostat (principal-frame omega ``w``).

    Only with no external and no motor torque in the window, and the wheels' momentum
    h along a principal axis (relative off-axis part under 1e-6): the precession of an
    axisymmetric body with h on its symmetry axis, lambda = ((I3 - I1) omega3 + h) / I1,
    measured as :func:`~.estimators.body_precession_rate`; the stability of the spin
    about the axis the motion stays nearest, with h along it (:func:`~.gyrostat.spin_stability`;
    the growth rate is the theory's, not measured yet).
    """
    from ..dynamics.gyrostat import precession_rate, spin_stability
    if under_torque or np.any(trajectory.motor_torques != 0.0):
        why = ("motor or external torque in the window: the torque-free gyrostat's theory "
               'does not apply')
        return PrecessionFindings(UNAVAILABLE, why, UNAVAILABLE), StabilityFindings(
            UNAVAILABLE, why)
    body, wheels = trajectory.inertia, trajectory.wheels
    moments = np.asarray(body.moments, dtype=float)
    axes = body.to_principal(np.array(wheels.axes))
    h = np.mean((trajectory.wheel_speeds * np.array(wheels.inertia)) @ axes, axis=0)
    size = float(np.linalg.norm(h))
    spin_axis = int(np.argmax(np.mean(np.abs(w), axis=0)))
    symmetric = body.symmetry_axis

    def along(k):
        return size == 0.0 or math.hypot(*(h[i] for i in range(3) if i != k)) <= 1e-6 * size
    if symmetric is not None and along(symmetric):
        theory_rate = precession_rate(moments, float(np.mean(w[:, symmetric])),
                                      float(h[symmetric]), symmetric)
        try:
            measured = estimators.body_precession_rate(t, w, symmetric).rate
        except ValueError as err:
            body_rate = unavailable(str(err), theory_rate, 'rad/s')
        else:
            body_rate = compare(measured, theory_rate, tol.rate, 'rad/s')
        precession = PrecessionFindings(
            body_rate.status, f'gyrostat: omega turns about axis {symmetric + 1} at ((I3 - '
            f'I1) omega3 + h) / I1, h = {h[symmetric]:.6g} kg m^2/s', 'gyrostat',
            body_rate=body_rate, symmetry_axis=symmetric)
    else:
        precession = PrecessionFindings(
            UNAVAILABLE, "the wheels' momentum is not along a symmetry axis: no closed form "
            'for the gyrostat here', UNAVAILABLE)
    if not along(spin_axis):
        return precession, StabilityFindings(
            UNAVAILABLE, f"the wheels' momentum is not along the spin axis {spin_axis + 1}")
    omega_k = float(np.mean(w[:, spin_axis]))
    stable, growth = spin_stability(moments, spin_axis, omega_k, float(h[spin_axis]))
    kind = 'stable' if stable else 'unstable'
    message = (f'spin about axis {spin_axis + 1} with rotor momentum {h[spin_axis]:.6g} kg m^2/s '
               f'is {kind} (gyrostat theory)')
    return precession, StabilityFindings(
        OK if stable else WARN, message, axis=spin_axis, kind=kind,
        growth_rate=None if stable else unavailable('not measured for a gyrostat yet', growth,
                                                    '1/s'))


def _momentum_exchange(trajectory, q, w, under_torque, tol):
    """
    Conservation of a body with spinning wheels: total H constant, T by the motor work.

    With no external torque in the window: the drift of the total H = I omega +
    sum J Omega g (world frame) from the window's first sample, max |H - H0| over
    the largest of |H0|, |I omega| and |h_w| in the window (a body at rest with its
    wheels has H = 0), and the angle of H from H0 (0 when H0 is 0), against the
    momentum tolerance; and the work-energy residual
    max |T - T0 - int sum Omega (u - f) dt| over the largest T or |work| in the
    window (trapezoid over the samples, u the motor torques, f the wheels'
    friction), against the balance tolerance.
    """
    if under_torque:
        return ConservationFindings(
            UNAVAILABLE, 'external torque and spinning wheels in the window: the balance '
            'with wheels under external torque is not checked yet', UNAVAILABLE)
    body, wheels = trajectory.inertia, trajectory.wheels
    moments = np.asarray(body.moments, dtype=float)
    axes = body.to_principal(np.array(wheels.axes))               # (n, 3) principal frame
    j = np.array(wheels.inertia)
    speeds, motors = trajectory.wheel_speeds, trajectory.motor_torques
    h_body = moments * w + (speeds * j) @ axes                    # principal frame
    h_world = quaternions.rotate(q, h_body)
    h0 = h_world[0]
    # on the scale of the momentum in play: a body at rest with its wheels has H = 0
    scale = max(float(np.linalg.norm(h0)),
                float(np.max(np.linalg.norm(moments * w, axis=1))),
                float(np.max(np.linalg.norm((speeds * j) @ axes, axis=1))))
    momentum = float(np.max(np.linalg.norm(h_world - h0, axis=1)) / scale) if scale else 0.0
    direction = float(np.max(np.arctan2(np.linalg.norm(np.cross(h_world, h0), axis=1),
                                        h_world @ h0))) \
        if np.linalg.norm(h0) > 1e-9 * scale else 0.0
    energy = (0.5 * np.sum(moments * w * w, axis=1) + np.sum(j * speeds * (w @ axes.T), axis=1)
              + 0.5 * np.sum(j * speeds * speeds, axis=1))
    friction = np.array([wheels.friction(row) for row in speeds]).reshape(speeds.shape)
    power = np.sum(speeds * (motors - friction), axis=1)
    t = trajectory.t
    work = np.concatenate([[0.0], np.cumsum(0.5 * (power[1:] + power[:-1]) * np.diff(t))])
    # on the scale of the energy in play (a body at rest with its wheels has T0 = 0)
    scale = max(float(np.max(np.abs(energy))), float(np.max(np.abs(work))))
    residual = float(np.max(np.abs(energy - energy[0] - work)) / scale) if scale else 0.0
    ratio_l, ratio_e = max(momentum, direction) / tol.momentum, residual / tol.balance
    status = level(max(ratio_l, ratio_e))
    message = 'momentum exchanged, total H conserved' if status == OK else (
        f'{"total H" if ratio_l >= ratio_e else "energy balance"} off by '
        f'{max(ratio_l, ratio_e):.3g} x tolerance')
    return ConservationFindings(status, message, 'momentum exchange', momentum_drift=momentum,
                                direction_drift=direction, energy_residual=residual,
                                work=float(work[-1]), energy_tolerance=tol.balance,
                                momentum_tolerance=tol.momentum)


def _conservation(t, q, w, tau, moments, baseline, under_torque, tol):
    if under_torque:
        bal = estimators.balance(t, q, w, tau, moments)
        ratio = max(bal.energy, bal.momentum) / tol.balance
        status = level(ratio)
        message = ('balance laws hold under torque' if status == OK else
                   f'{"energy" if bal.energy >= bal.momentum else "angular momentum"} balance '
                   f'off by {ratio:.3g} x tolerance')
        return ConservationFindings(status, message, 'balance laws', energy_residual=bal.energy,
                                    momentum_residual=bal.momentum, work=bal.work,
                                    energy_tolerance=tol.balance, momentum_tolerance=tol.balance)
    b_t, b_q, b_w = baseline
    energy, norm, direction = estimators.drift_series(moments, q, w, b_q, b_w)
    e_err, l_err, d_err = float(energy.max()), float(norm.max()), float(direction.max())
    ratio_e, ratio_l = e_err / tol.energy, max(l_err, d_err) / tol.momentum
    ratio = max(ratio_e, ratio_l)
    status = level(ratio)
    message = 'conserved' if status == OK else (
        f'{"energy" if ratio_e >= ratio_l else "angular momentum"} off by {ratio:.3g} x '
        'tolerance')
    return ConservationFindings(status, message, 'free motion', e_err, l_err, d_err, int(b_t),
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
    status = worst(body.status, lab.status)
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
    status = worst(omega_period.status, mean.status)
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
            return StabilityFindings(WARN, message,
                                     growth_rate=unavailable(torque_why, st.rate, '1/s'),
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


#: Fewer matched estimates than this and the estimation check is unavailable.
MIN_ESTIMATES = 30


def autocorrelation_time(x):
    """
    Return the integrated autocorrelation time (samples) of the series x (N,) or (N, m).

    tau = 1 + 2 sum_k rho_k, the variance of the mean of N correlated samples over
    that of N independent ones (1 for white noise; (1 + phi) / (1 - phi) for an
    AR(1) of coefficient phi). Estimated by Geyer's initial monotone sequence
    (C. J. Geyer, "Practical Markov chain Monte Carlo", Statistical Science 7(4),
    1992, section 3.3; the estimator Stan and ArviZ use for the effective sample
    size): the sums of adjacent autocorrelations Gamma_j = rho_2j + rho_2j+1 are
    summed while they are positive, each capped by the one before, tau = 2 sum
    Gamma_j - 1. It reads the autocorrelation as far as it is positive, so a long
    excursion (an estimator coasting without measurements) is seen as well as the
    steady state, and it adds no bias of its own on white noise (a maximum of two
    estimates did: 1.19 on average). Columns' autocorrelations are averaged. At
    least 1.
    """
    x = np.asarray(x, dtype=float)
    x = x.reshape(len(x), -1) - x.reshape(len(x), -1).mean(axis=0)
    n = len(x)
    size = 1 << (2 * n - 1).bit_length()
    f = np.fft.rfft(x, size, axis=0)
    acf = np.fft.irfft((f * np.conj(f)).real, size, axis=0)[:n].mean(axis=1)
    if n < 2 or acf[0] <= 0.0:
        return 1.0
    rho = acf / acf[0]
    pairs = rho[:2 * (n // 2)].reshape(-1, 2).sum(axis=1)
    stop = np.flatnonzero(pairs <= 0.0)
    positive = pairs[:stop[0] if stop.size else len(pairs)]
    tau = 2.0 * float(np.sum(np.minimum.accumulate(positive))) - 1.0
    return max(1.0, tau)


def attitude_nees(q_true, q_est, covariances):
    """
    Return the attitude errors (..., 3; rad, world frame) and their NEES (...,).

    ``q_true``, ``q_est`` (..., 4) x, y, z, w body -> world; ``covariances``
    (..., 3, 3) rad^2 about the world's fixed axes. The error is the rotation
    vector of q_est q_true^-1; NEES = e^T P^-1 e (whitened by P's Cholesky factor).
    """
    q_t = np.asarray(q_true, dtype=float)
    q_e = np.asarray(q_est, dtype=float)
    errors = quaternions.to_rotation_vector(quaternions.multiply(q_e, quaternions.conjugate(q_t)))
    chol = np.linalg.cholesky(np.asarray(covariances, dtype=float))
    white = np.linalg.solve(chol, errors[..., None])[..., 0]
    return errors, np.sum(white * white, axis=-1)


def estimation(q_true, q_est, covariances, bias_true=None, bias_est=None, level=0.95):
    """
    Judge attitude estimates against the truth: errors, 3-sigma share, NEES and its verdict.

    ``q_true``, ``q_est`` (N, 4) x, y, z, w body -> world at the same stamps;
    ``covariances`` (N, 3, 3) the estimates' attitude covariances (rad^2) about
    the world's fixed axes (as ROS messages have them). The error is the
    rotation vector of q_est q_true^-1 (world frame). NEES_k = e_k^T P_k^-1 e_k;
    its mean over N samples of a consistent estimator is chi-square with 3 N
    degrees of freedom over N, if the samples are independent. Successive
    estimates are not: the bounds count N / tau independent samples, tau the
    integrated autocorrelation time of the NEES series itself
    (:func:`autocorrelation_time`), so that chi-square with 3 N / tau degrees of
    freedom over N / tau has the variance of the correlated mean, 6 tau / N. (The
    whitened errors' own tau is larger, up to twice for an AR(1): rho_k^2 decays
    faster than rho_k, and an interval from it is too wide.) ``level`` is the
    interval's confidence: a consistent estimator is called inconsistent in a
    share 1 - level of runs. "Inside 3 sigma": inside the ellipsoid of the
    covariance that holds 99.73 % (the share of 3 sigma in one dimension; for
    three dimensions chi-square(3) <= 14.16).
    ``bias_true`` and ``bias_est`` (M, 3) rad/s, at M stamps of their own (the same for
    both), add the bias error's RMS.
    Returns :class:`EstimationFindings`.
    """
    from scipy.stats import chi2
    if not 0.0 < level < 1.0:
        raise ValueError(f'level must be inside (0, 1), not {level!r}')
    n = len(q_true)
    if n < MIN_ESTIMATES:
        return EstimationFindings(OK, f'{n} estimates matched to the truth so far (needs '
                                      f'{MIN_ESTIMATES})', 'unavailable', samples=n)
    errors, nees_k = attitude_nees(q_true, q_est, covariances)
    tau = autocorrelation_time(nees_k)
    independent = n / tau
    low = chi2.ppf((1.0 - level) / 2.0, 3.0 * independent) / independent
    high = chi2.ppf((1.0 + level) / 2.0, 3.0 * independent) / independent
    nees = float(np.mean(nees_k))
    verdict = ('overconfident' if nees > high else 'pessimistic' if nees < low else
               'consistent')
    angles = np.linalg.norm(errors, axis=1)
    bias_rms = None
    if bias_true is not None and bias_est is not None:
        d = np.asarray(bias_est, dtype=float) - np.asarray(bias_true, dtype=float)
        bias_rms = np.sqrt(np.mean(d * d, axis=0))
    inside = float(np.mean(nees_k <= chi2.ppf(chi2.cdf(9.0, 1), 3)))
    message = (f'{verdict}: mean NEES {nees:.3g} for 3 expected ({100.0 * level:.4g} % interval '
               f'{low:.3g} to {high:.3g} over {independent:.0f} independent samples of {n}); '
               'attitude '
               f'error {math.sqrt(np.mean(angles ** 2)):.3g} rad RMS')
    return EstimationFindings(
        OK if verdict == 'consistent' else WARN, message, verdict, n,
        np.sqrt(np.mean(errors ** 2, axis=0)), np.max(np.abs(errors), axis=0),
        float(math.sqrt(np.mean(angles ** 2))), float(np.max(angles)), inside, nees, tau,
        independent, (float(low), float(high)), bias_rms, level)
