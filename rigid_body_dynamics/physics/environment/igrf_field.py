"""
Earth's magnetic field by the IGRF-14, to degree 13, along an orbit (no ROS).

The International Geomagnetic Reference Field, 14th generation.

The coefficients are the ``ppigrf`` library's (its ``IGRF14.shc``: the models of
1900 to 2025 every five years, and 2030 from the secular variation), taken at
the date linearly in time, as ``ppigrf.igrf_gc`` takes them. The field is the
gradient of the potential

    V = R sum_{n=1..N} (R / r)^(n+1) sum_{m=0..n} (g_nm cos m phi + h_nm sin m phi) P_nm(cos theta)

(R = 6371.2 km, P_nm Schmidt semi-normalised, from ``ppigrf``'s
``get_legendre``; theta the geocentric colatitude, phi the east longitude in
the Earth-fixed frame), B = -grad V, as ``ppigrf.igrf_gc`` evaluates it.

The Earth-fixed frame is the world frame turned about z by theta(t) = theta0 +
rate t, as for the dipole (:mod:`.magnetic_field`); with a TLE orbit that is
TEME turned by the sidereal time into the pseudo-Earth-fixed frame (polar motion,
under 0.5 arcsec, neglected).

Along the orbit. The field at a stage is not evaluated there: a sum of degree
13 costs about a millisecond. The orbit's position is known at any time, so B
in the world frame is a smooth function of time alone, and it is interpolated:
the time is cut into segments of ``1 / segments`` of the orbit period, and on
each the field is a Chebyshev interpolant of degree ``order`` through the
Chebyshev points of the first kind (built the first time the segment is asked
for, with the coefficients at its middle; the secular variation over a segment
is under 1e-3 nT). The default 16 segments of degree 9 keep the
interpolant within 0.001 nT of the field from 300 to 2000 km (``test_igrf_field``
holds it to 0.003 nT at 600 times over 2025-2030, the worst 8.7e-4 nT, mostly the
secular variation; 0.01 nT is what the manual promises). A segment costs about
3 ms to build, an evaluation a few microseconds.
"""

from datetime import datetime, timezone
import math

import numpy as np

from .chebyshev import ChebyshevSegments
from ...optional import require_for

#: The IGRF reference radius (m), the same as the dipole's.
R_REF = 6371200.0
_SHC = {}


def _library():
    """Return ppigrf's module of its functions (ValueError naming the parameter if missing)."""
    require_for('magnetic_field_model igrf', 'ppigrf')
    from ppigrf import ppigrf
    return ppigrf


def igrf_table():
    """
    Return (times s, keys [(n, m)], g nT, h nT) of ppigrf's IGRF14.shc, read once.

    ``times``: the models' epochs as Unix times (s, UTC), shape (T,); ``g``, ``h``:
    shape (T, K), for the K keys (n, m), n = 1..13, m = 0..n (h_n0 = 0).
    """
    table = _SHC.get('igrf14')
    if table is None:
        library = _library()
        g, h = library.read_shc(library.shc_fn_igrf14)
        times = np.array([t.replace(tzinfo=timezone.utc).timestamp()
                          for t in g.index.to_pydatetime()])
        keys = [tuple(int(c) for c in key) for key in g.columns]
        table = _SHC['igrf14'] = (times, keys, g.to_numpy(float), h.to_numpy(float))
    return table


def igrf_coefficients(when, degree=13):
    """
    Return (keys, g nT, h nT) of IGRF-14 to ``degree`` at Unix time ``when`` (s, UTC).

    Linear in time between the tabulated models (as ``ppigrf.igrf_gc`` takes
    them); ValueError outside 1900-2030, the years the model covers.
    """
    times, keys, g, h = igrf_table()
    if not times[0] <= when <= times[-1]:
        raise ValueError('magnetic_field_model igrf: IGRF-14 covers 1900 to 2030; the date '
                         f'{datetime.fromtimestamp(when, timezone.utc):%Y-%m-%d} is outside')
    j = min(int(np.searchsorted(times, when, side='right')) - 1, len(times) - 2)
    w = (when - times[j]) / (times[j + 1] - times[j])
    use = [k for k, (n, _) in enumerate(keys) if n <= degree]
    gi = (1.0 - w) * g[j, use] + w * g[j + 1, use]
    hi = (1.0 - w) * h[j, use] + w * h[j + 1, use]
    return [keys[k] for k in use], gi, hi


def igrf_fixed(r_fixed, keys, g, h):
    """
    Return B (nT, Earth-fixed Cartesian, shape (N, 3)) at positions ``r_fixed`` (m, (N, 3)).

    The spherical-harmonic sum of the module docstring with ``keys`` (n, m) and
    their coefficients ``g``, ``h`` (nT), as ``ppigrf.igrf_gc`` sums it (its
    Legendre functions), turned from (B_r, B_theta, B_phi) into x, y, z.
    """
    library = _library()
    r_fixed = np.atleast_2d(np.asarray(r_fixed, float))
    rn = np.linalg.norm(r_fixed, axis=1)
    colat = np.arccos(np.clip(r_fixed[:, 2] / rn, -1.0, 1.0))
    lon = np.arctan2(r_fixed[:, 1], r_fixed[:, 0])
    p, dp = library.get_legendre(np.degrees(colat), keys)      # (N, K)
    n = np.array([k[0] for k in keys], float)
    m = np.array([k[1] for k in keys], float)
    ratio = (R_REF / rn)[:, None]
    cos_m, sin_m = np.cos(lon[:, None] * m), np.sin(lon[:, None] * m)
    a = g * cos_m + h * sin_m                                  # (N, K)
    b = -g * sin_m + h * cos_m
    radial = ratio ** (n + 2)
    b_r = np.sum(radial * (n + 1) * p * a, axis=1)
    b_theta = -np.sum(radial * dp * a, axis=1)
    st, ct = np.sin(colat), np.cos(colat)
    b_phi = -np.sum(radial * m * p * b, axis=1) / st
    cl, sl = np.cos(lon), np.sin(lon)
    horizontal = b_r * st + b_theta * ct
    return np.column_stack((horizontal * cl - b_phi * sl, horizontal * sl + b_phi * cl,
                            b_r * ct - b_theta * st))


class IgrfField:
    """
    IGRF-14 to ``degree`` (1..13) along ``orbit``, from Unix time ``start`` (s, UTC) at t = 0.

    ``rotation_angle`` theta0 (rad) and ``rotation_rate`` (rad/s) turn the
    Earth-fixed frame about the world z axis (as :class:`~.magnetic_field.DipoleField`).
    :meth:`world` (t s, r m) gives B (T) in the world frame, interpolated along
    the orbit (``r`` must be the orbit's position at t: the interpolant is of
    time); :meth:`exact` sums the harmonics at any (t, r). ``segments`` per orbit
    period and Chebyshev ``order``: the interpolation (module docstring).
    Refuses (ValueError naming the parameter) a degree outside 1..13 and a date
    outside the model.
    """

    def __init__(self, orbit, start, degree=13, rotation_angle=0.0, rotation_rate=0.0,
                 segments=16, order=9):
        if isinstance(degree, bool) or not isinstance(degree, int) or not 1 <= degree <= 13:
            raise ValueError(f'magnetic_field_degree must be an integer 1..13, got {degree!r}')
        for name, value in (('earth_rotation_angle', rotation_angle),
                            ('earth_rotation_rate', rotation_rate)):
            if not math.isfinite(value):
                raise ValueError(f'{name} must be finite, got {value!r}')
        self.orbit, self.start, self.degree = orbit, float(start), degree
        self.theta0, self.rate = float(rotation_angle), float(rotation_rate)
        igrf_coefficients(self.start, degree)          # refuses a date outside the model
        self.interpolant = ChebyshevSegments(self._sample, orbit.period / segments, order,
                                             name='igrf')
        self.span, self.order = self.interpolant.span, order
        self.segment, self.world_at = self.interpolant.segment, self.interpolant.value

    def _turn(self, t):
        theta = self.theta0 + self.rate * t
        return math.cos(theta), math.sin(theta)

    def exact(self, t, r):
        """Return B (T, world frame) at time t (s) and position r (m, world): the sum itself."""
        c, s = self._turn(t)
        x, y, z = r
        keys, g, h = igrf_coefficients(self.start + t, self.degree)
        bx, by, bz = igrf_fixed([(c * x + s * y, -s * x + c * y, z)], keys, g, h)[0] * 1e-9
        return (c * bx - s * by, s * bx + c * by, bz)

    def _sample(self, middle, times):
        """Return B (T, world frame, (N, 3)) on the orbit at ``times`` (s), IGRF of ``middle``."""
        r = np.array([self.orbit.position(t) for t in times])
        theta = self.theta0 + self.rate * times
        c, s = np.cos(theta), np.sin(theta)
        fixed = np.column_stack((c * r[:, 0] + s * r[:, 1], -s * r[:, 0] + c * r[:, 1], r[:, 2]))
        keys, g, h = igrf_coefficients(self.start + middle, self.degree)
        b = igrf_fixed(fixed, keys, g, h) * 1e-9
        return np.column_stack((c * b[:, 0] - s * b[:, 1], s * b[:, 0] + c * b[:, 1], b[:, 2]))

    def world(self, t, r=None):
        """Return B (T) in the world frame at time t (s) on the orbit, interpolated."""
        return self.world_at(t)

    def world_many(self, times, r=None):
        """Return B (T, world frame, (N, 3)) at ``times`` (s) on the orbit: :meth:`world`'s."""
        return self.interpolant.values(times)
