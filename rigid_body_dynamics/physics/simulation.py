"""
Offline simulation: run an integrator over a time span and keep every step.

For users who script without ROS, for the report and the benchmarks. Inputs
and outputs are in the user's body frame (the frame of ``inertia``); the
integration itself runs in the principal frame.
"""

from dataclasses import dataclass
import math

import numpy as np

from . import quaternions
from .dynamics import equations
from .dynamics.plant import Plant, UserFrame
from .inertia import as_inertia


@dataclass
class ImuStream:
    """
    A gyro's readings over a run (``simulate(..., gyro=...)``), user's body frame.

    ``t`` (M,) s (every ``every``-th step from 0); ``q`` (M, 4) the reported
    attitude (with orientation noise); ``omega`` (M, 3) the measured rate
    (rad/s); ``bias`` (M, 3) the true bias in it (rad/s); ``rate`` Hz.
    """

    t: np.ndarray
    q: np.ndarray
    omega: np.ndarray
    bias: np.ndarray
    rate: float


@dataclass
class SimulationResult:
    """
    Sampled trajectory of one run.

    ``t`` (N,) s; ``q`` (N, 4) x-y-z-w body -> world; ``omega`` (N, 3) rad/s
    body frame; ``torque`` (N, 3) N m body frame, the torque held over the
    step that starts at each sample (last row repeats); ``work`` (N,) J and
    ``impulse`` (N, 3) N m s world frame, accumulated by the integrator;
    ``imu`` an :class:`ImuStream` when a gyro was given, else None.
    """

    t: np.ndarray
    q: np.ndarray
    omega: np.ndarray
    torque: np.ndarray
    work: np.ndarray
    impulse: np.ndarray
    inertia: object
    integrator: str
    imu: object = None

    @property
    def kinetic_energy(self):
        """T(t) = 1/2 omega . I omega (J)."""
        principal = self.inertia.to_principal(self.omega)
        return equations.kinetic_energy(self.inertia.moments, principal)

    @property
    def angular_momentum_body(self):
        """L in the body frame (N, 3), kg m^2/s."""
        return self.omega @ self.inertia.tensor.T

    @property
    def angular_momentum_world(self):
        """L in the world frame (N, 3), kg m^2/s; constant when torque-free."""
        return quaternions.rotate(self.q, self.angular_momentum_body)


def simulate(inertia, omega0, q0=(0.0, 0.0, 0.0, 1.0), duration=10.0, dt=1e-3,
             integrator='exact', torque=None, every=1, progress=None, gyro=None,
             torque_every=1, disturbances=None):
    """
    Integrate the rigid body for ``duration`` s with fixed steps ``dt`` s.

    ``inertia``: Inertia or three principal moments (kg m^2). ``omega0``
    (rad/s) and ``torque`` in the body frame of ``inertia``; ``q0`` (x, y, z,
    w) body -> world. ``torque`` is None (free), a constant 3-vector (N m) or
    a callable ``torque(t, q, omega)`` -> 3-vector evaluated at the start of
    each step and held over it (the last row repeats the last torque); with
    ``torque_every`` = m it is evaluated every m-th step and held over m steps
    (a controller's period, as attitude_simulator's lockstep holds it).
    ``integrator`` is a name from INTEGRATORS.
    ``every``: keep every n-th step. ``progress(fraction)``, if given, is
    called about a hundred times as the run goes (for long runs). ``gyro``: a
    :class:`~rigid_body_dynamics.physics.sensors.GyroModel` whose rate is a
    whole fraction of 1 / dt, read at every one of its samples from t = 0 (its
    stream is the one attitude_simulator publishes on ``imu`` with the same
    seed and parameters). ``disturbances``: a
    :class:`~rigid_body_dynamics.physics.environment.Disturbances` (constant
    torques, an orbit with its gravity gradient, field and residual dipole), as
    attitude_simulator takes them from its parameters; their torque is not in
    ``torque`` (the commanded part) but in ``work`` and ``impulse``. The run
    steps on the one stepping core (:class:`~.dynamics.plant.Plant`), as the
    simulator's does: the same schedule gives the same states, bit for bit.
    Returns a :class:`SimulationResult` including t = 0.
    """
    inertia = as_inertia(inertia)
    if not (math.isfinite(duration) and duration >= 0.0):
        raise ValueError(f'duration must be finite and >= 0, got {duration!r}')
    if not (math.isfinite(dt) and dt > 0.0):
        raise ValueError(f'dt must be positive and finite, got {dt!r}')
    n = int(round(duration / dt))
    if not (isinstance(torque_every, int) and torque_every >= 1):
        raise ValueError(f'torque_every must be an integer >= 1, got {torque_every!r}')
    imu_every = _imu_every(gyro, dt)
    imu = ([], [], [], [])
    q0 = np.asarray(q0, dtype=float)
    plant = Plant(inertia, integrator, dt, q0 / np.linalg.norm(q0),
                  np.asarray(omega0, dtype=float), disturbances)
    stepper = plant.stepper
    frame = UserFrame(inertia)
    if callable(torque):
        user_torque = torque
    else:
        body_const = np.zeros(3) if torque is None else np.asarray(torque, dtype=float).reshape(3)
        principal_const = tuple(float(c) for c in inertia.to_principal(body_const))
    report_every = max(1, n // 100)
    t, q, w, tau, work, imp = [], [], [], [], [], []
    step = plant.step
    for k in range(n + 1):
        if callable(torque) and (k < n or k == 0) and k % torque_every == 0:
            # (the last row repeats the last torque: no step starts there)
            tb = user_torque(stepper.time, *frame.state(stepper))
            tp = frame.torque_principal(tb, stepper.time)
        elif not callable(torque):
            tb, tp = body_const, principal_const
        if k % every == 0:
            t.append(stepper.time)
            q.append(stepper.q)
            w.append(stepper.omega)
            tau.append(tb)
            work.append(stepper.work)
            imp.append(stepper.impulse)
        if imu_every and k % imu_every == 0:
            for column, value in zip(imu, (stepper.time, *gyro.read(
                    *frame.state(stepper)))):
                column.append(value)
        if k < n:
            try:
                step(tp)
            except ValueError as err:     # the integrator refuses a non-finite torque
                raise ValueError(f'torque at t={stepper.time!r} s: {err}') from None
        if progress is not None and (k % report_every == 0 or k == n):
            progress(k / max(n, 1))
    tau = np.array(tau, dtype=float).reshape(-1, 3)
    return SimulationResult(t=np.array(t), q=inertia.attitude_to_body(np.array(q)),
                            omega=inertia.to_body(np.array(w)), torque=tau,
                            work=np.array(work), impulse=np.array(imp).reshape(-1, 3),
                            inertia=inertia, integrator=integrator,
                            imu=ImuStream(np.array(imu[0]), np.array(imu[1]).reshape(-1, 4),
                                          np.array(imu[2]).reshape(-1, 3),
                                          np.array(imu[3]).reshape(-1, 3), gyro.rate)
                            if imu_every else None)


def _imu_every(gyro, dt):
    """Return the steps per gyro sample (0 without a gyro); ValueError unless whole."""
    if gyro is None:
        return 0
    every = round(1.0 / (gyro.rate * dt))
    if every < 1 or abs(every * gyro.rate * dt - 1.0) > 1e-9:
        raise ValueError(f'the gyro rate ({gyro.rate:g} Hz) must be a whole fraction of the '
                         f'step rate 1 / dt = {1.0 / dt:g} Hz')
    return every
