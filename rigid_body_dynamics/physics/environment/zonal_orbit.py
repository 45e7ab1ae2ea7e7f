"""
An orbit integrated numerically under the planet's zonal harmonics J2..J6 (no ROS).

The gravitational potential of an axially symmetric planet (Vallado,
Fundamentals of Astrodynamics and Applications, 4th ed., section 8.6.1) is

    V(r) = mu / r (1 - sum_{n=2..N} J_n (R / r)^n P_n(u)),   u = z / r,

with P_n the Legendre polynomials and z along the rotation axis; the
acceleration is its gradient,

    a = -mu r_hat / r^2
        + mu / r^2 sum_n J_n (R / r)^n [((n + 1) P_n(u) + u P_n'(u)) r_hat - P_n'(u) z_hat],

P_n and P_n' by the recurrences (n + 1) P_{n+1} = (2n + 1) u P_n - n P_{n-1} and
P_{n+1}' = P_{n-1}' + (2n + 1) P_n (:func:`zonal_acceleration`). J2..J6 and R
are EGM2008's (Pavlis, Holmes, Kenyon and Factor, J. Geophys. Res. 117, B04406,
2012: J_n = -sqrt(2n + 1) C_n0 of its normalised coefficients). The potential
is axially symmetric and constant in time, so the energy v^2 / 2 - V and the
angular momentum's z component are constants of the motion (the tests hold
the integration to them).

Frames and units: the world frame of :mod:`.orbit` (inertial, z the rotation
axis); the elements at t = 0 are osculating (the Kepler orbit's state at t = 0
is the initial state). Positions m, velocities m/s, time s.

Drag on the orbit (optional): the air slows the centre of mass by

    a_D = -1/2 rho |v_r| v_r / B,   v_r = v - omega_E x r,

with B = m / (C_D A) the ballistic coefficient (kg/m^2: the mass over the drag
coefficient times the area the flow meets, taken constant, the cannonball
model; the attitude's own drag torque sees the facets as they turn), rho the
density of an atmosphere (:mod:`.atmosphere`, :mod:`.msis_atmosphere`) at the
time and place and v_r the velocity relative to the air turning with the Earth
(Montenbruck and Gill, *Satellite Orbits*, section 3.5). The energy then falls
at the drag's power a_D . v (the test holds the integration to that work).

Integration: scipy's DOP853 (Hairer, Norsett and Wanner's eighth-order pair) at
a relative tolerance of 1e-13 over chunks of one Kepler period, each started
from the state the chunk before ended with (so a chunk built again is the same
to the bit); the position and velocity are then Chebyshev interpolants on 16
segments per period (:mod:`.chebyshev`), so a stage's position costs a Horner
sum, not an integration. Times before 0 integrate backwards from 0 the same way.
"""

import math

import numpy as np

from .chebyshev import ChebyshevSegments
from .orbit import KeplerOrbit, MU_EARTH, R_EARTH

#: EGM2008's zonal coefficients J2..J6 (unnormalised: -sqrt(2n + 1) C_n0), index n.
EGM2008_J = (0.0, 0.0, -math.sqrt(5.0) * -0.484165143790815e-3,
             -math.sqrt(7.0) * 0.957161207093473e-6, -3.0 * 0.539965866638991e-6,
             -math.sqrt(11.0) * 0.686702913736681e-7, -math.sqrt(13.0) * -0.149953927978527e-6)
#: EGM2008's reference radius (m), the R of the J_n.
EGM2008_RADIUS = 6378136.3
#: The DOP853 tolerances of the orbit's integration (relative; absolute m and m/s).
RTOL, ATOL_POSITION, ATOL_VELOCITY = 1e-13, 1e-7, 1e-10


def zonal_acceleration(r, mu, radius, j):
    """
    Return the gravitational acceleration (m/s^2, world frame) at position r (m, world frame).

    ``mu`` (m^3/s^2), ``radius`` R (m) and ``j`` the coefficients J_n indexed by n
    (j[0], j[1] unused): the gradient of the module docstring's potential, the
    central term included.
    """
    x, y, z = r
    r2 = x * x + y * y + z * z
    rn = math.sqrt(r2)
    u = z / rn
    ratio = radius / rn
    # P_{n-1}, P_n and their derivatives, from n = 1
    p_before, p, d_before, d = 1.0, u, 0.0, 1.0
    power = ratio
    radial = along_z = 0.0
    for n in range(1, len(j) - 1):
        p_before, p = p, ((2 * n + 1) * u * p - n * p_before) / (n + 1)
        d_before, d = d, d_before + (2 * n + 1) * p_before
        power *= ratio
        jn = j[n + 1]
        if jn:
            radial += jn * power * ((n + 2) * p + u * d)
            along_z += jn * power * d
    k = mu / r2
    central = (radial - 1.0) * k / rn
    return (central * x, central * y, central * z - k * along_z)


def zonal_potential(r, mu, radius, j):
    """Return V (m^2/s^2) of the module docstring at r (m, world frame): a = grad V."""
    x, y, z = r
    rn = math.sqrt(x * x + y * y + z * z)
    u, ratio = z / rn, radius / rn
    total, p_before, p, power = 0.0, 1.0, u, ratio
    for n in range(1, len(j) - 1):
        p_before, p = p, ((2 * n + 1) * u * p - n * p_before) / (n + 1)
        power *= ratio
        total += j[n + 1] * power * p
    return mu / rn * (1.0 - total)


def zonal_coefficients(degree):
    """
    Return EGM2008's (J_0 .. J_degree) for ``orbit_zonal_degree`` 2..6.

    ValueError naming the parameter for anything else (0 is the Kepler orbit,
    which has none; J1 = 0 with the origin at the centre of mass).
    """
    if isinstance(degree, bool) or not isinstance(degree, int) or not 2 <= degree <= 6:
        raise ValueError(f'orbit_zonal_degree must be 0 (Kepler) or an integer 2..6 (J2 to '
                         f'J6), got {degree!r}')
    return EGM2008_J[:degree + 1]


class ZonalOrbit:
    """
    The orbit from osculating ``elements`` [a m, e, i, RAAN, argp, nu0 rad] under J2..J``degree``.

    ``mu`` (m^3/s^2), ``planet_radius`` (m: the perigee of the elements must be
    above it, and :meth:`state` raises ValueError once the orbit comes below it),
    ``coefficients`` (J_n by n; default EGM2008's to ``degree``) and their
    ``reference_radius`` (m). ``ballistic_coefficient`` B (kg/m^2, 0 = none) with
    ``atmosphere`` (its ``density(t, r)`` at any time and place, kg/m^3, and its
    ``flow(r, v)``) adds the drag of the module docstring. :meth:`state` gives
    (r, v) in the world frame at any t (s), :meth:`position` r alone; both
    interpolated (module docstring).
    """

    def __init__(self, elements, degree=2, mu=MU_EARTH, planet_radius=R_EARTH,
                 coefficients=None, reference_radius=EGM2008_RADIUS, segments=16, order=9,
                 ballistic_coefficient=0.0, atmosphere=None):
        kepler = KeplerOrbit(elements, mu, planet_radius)
        self.ballistic = float(ballistic_coefficient)
        if not (math.isfinite(self.ballistic) and self.ballistic >= 0.0):
            raise ValueError('orbit_ballistic_coefficient must be >= 0 kg/m^2 (0 = no drag on '
                             f'the orbit), got {ballistic_coefficient!r}')
        if self.ballistic and atmosphere is None:
            raise ValueError('orbit_ballistic_coefficient needs an atmosphere (the density '
                             'of the drag on the orbit)')
        self.atmosphere = atmosphere if self.ballistic else None
        self.j = tuple(float(c) for c in (zonal_coefficients(degree) if coefficients is None
                                          else coefficients))
        self.degree = degree
        self.elements, self.a, self.e, self.mu = kepler.elements, kepler.a, kepler.e, kepler.mu
        self.planet_radius, self.reference_radius = float(planet_radius), float(reference_radius)
        #: the Kepler period of the osculating a at t = 0 (s): one chunk of the integration
        self.period = kepler.period
        r0, v0 = kepler.state(0.0)
        self._starts = {0: np.array(r0 + v0)}        # chunk k's state at k * period
        self._chunk = (None, None)                   # (k, its dense solution): the last one
        self._position = ChebyshevSegments(lambda m, t: self._sample(t)[:, :3],
                                           self.period / segments, order, name='zonal r')
        self._velocity = ChebyshevSegments(lambda m, t: self._sample(t)[:, 3:],
                                           self.period / segments, order, name='zonal v')
        self.position = self._position.value
        self.velocity = self._velocity.value

    def summary(self):
        """Return a line that says which orbit this is (for the node's log)."""
        a, e, inc = self.elements[:3]
        drag = (f', drag of B = {self.ballistic:g} kg/m^2 in the {self.atmosphere}'
                if self.ballistic else '')
        return (f'integrated under J2..J{self.degree} (EGM2008, DOP853){drag}: osculating '
                f'a = {a:.6g} m, e = {e:g}, i = {inc:g} rad at t = 0, period '
                f'{self.period:.6g} s')

    def drag_acceleration(self, t, r, v):
        """Return a_D (m/s^2, world frame) at time t (s), r (m), v (m/s): zero without drag."""
        if not self.ballistic:
            return (0.0, 0.0, 0.0)
        flow = self.atmosphere.flow(r, v)
        k = -0.5 * self.atmosphere.density(t, r) * math.sqrt(
            flow[0] * flow[0] + flow[1] * flow[1] + flow[2] * flow[2]) / self.ballistic
        return (k * flow[0], k * flow[1], k * flow[2])

    def rate(self, t, y):
        """Return dy/dt of y = (r m, v m/s), world frame, at time t (s): the equations flown."""
        r = (y[0], y[1], y[2])
        a = zonal_acceleration(r, self.mu, self.reference_radius, self.j)
        if self.ballistic:
            d = self.drag_acceleration(t, r, (y[3], y[4], y[5]))
            a = (a[0] + d[0], a[1] + d[1], a[2] + d[2])
        return (y[3], y[4], y[5], a[0], a[1], a[2])

    def _dense(self, k):
        """Return the DOP853 dense solution over chunk k (k * period to (k + 1) * period)."""
        if self._chunk[0] == k:
            return self._chunk[1]
        from scipy.integrate import solve_ivp
        step = 1 if k >= 0 else -1
        j = max(i for i in self._starts if i <= k) if k >= 0 else \
            min(i for i in self._starts if i >= k + 1)
        while True:                                # chunks integrated from the nearest start
            begin = j if step > 0 else j - 1
            span = (j * self.period, (j + step) * self.period)
            solution = solve_ivp(self.rate, span, self._starts[j], method='DOP853',
                                 rtol=RTOL, atol=[ATOL_POSITION] * 3 + [ATOL_VELOCITY] * 3,
                                 dense_output=True)
            if not solution.success:
                raise ValueError(f'orbit_zonal_degree: the orbit cannot be integrated over '
                                 f'{span[0]:g} to {span[1]:g} s: {solution.message}')
            if np.min(np.linalg.norm(solution.y[:3], axis=0)) <= self.planet_radius:
                raise ValueError(f'orbit_zonal_degree: the orbit comes below planet_radius '
                                 f'between t = {span[0]:g} and {span[1]:g} s')
            self._starts.setdefault(j + step, solution.y[:, -1].copy())
            j += step
            if begin == k:
                break
        self._chunk = (k, solution.sol)
        return solution.sol

    def _sample(self, times):
        """Return the states (N, 6) at ``times`` (s, within one segment) from their chunk."""
        k = math.floor(float(np.mean(times)) / self.period)
        return self._dense(k)(times).T

    def state(self, t):
        """Return (r m, v m/s), tuples in the world frame, at time t (s)."""
        return self.position(t), self.velocity(t)

    def positions(self, times):
        """Return r (m, world frame) at ``times`` (s, an array), (N, 3): :meth:`position`'s."""
        return self._position.values(times)

    def states(self, times):
        """Return (r m, v m/s), (N, 3) arrays in the world frame, at ``times`` (s)."""
        return self._position.values(times), self._velocity.values(times)
