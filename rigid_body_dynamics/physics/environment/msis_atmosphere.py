"""
The air's density by NRLMSIS 2.1 along an orbit, through the ``pymsis`` library (no ROS).

NRLMSIS 2.1 (Emmert et al., Earth and Space Science 9, 2022) is the US Naval
Research Laboratory's empirical model of the neutral atmosphere from the ground
to the exobase; ``pymsis`` wraps its Fortran. Unlike Vallado's table
(:mod:`.atmosphere`) it holds the Sun's activity, through the 10.7 cm solar flux
(the previous day's F10.7 and its 81-day mean F10.7a, in solar flux units,
1e-22 W m^-2 Hz^-1) and the geomagnetic index Ap (the daily value: the model's
default switch), and the air's bulge on the day side, by latitude, local time
and season. The activity is given, never downloaded: a test is repeatable, and
the model's own fetch of the indices needs the network.

``pymsis`` takes the geodetic latitude, longitude (the Earth-fixed frame: the
world frame turned about z by theta0 + rate t, as for the field) and height over
WGS-84 (:func:`.atmosphere.geodetic_latitude_height`), and the UTC date.

Along the orbit. A call of the model costs tens of microseconds and more, so
the density at a stage is not the model's: as for the IGRF field
(:mod:`.igrf_field`), the orbit's position is a function of time, and so is the
density on it; its logarithm is interpolated by Chebyshev polynomials of degree
``order`` on segments of about ``1 / segments`` of the orbit period
(:mod:`.chebyshev`). The model takes the day of the year as a whole number and
the time of day from 0 h, so its density steps at 0 h UTC (by 0.2 to 0.7 % on
the days measured); the segments meet there, so that the step falls between two
and neither is bent by it. The model computes in single precision (``pymsis``
returns float32) and its density is noisy at a few 1e-5 from one call to the
next; the default 16 segments of degree 9 follow it to within that noise:
``test_msis_atmosphere`` holds the interpolant to 1.5e-4 of the model at 600
times from 250 to 1000 km (the worst over twelve draws 8.4e-5; 32 segments are
no closer), far inside the model's own error against measured densities (of the
order of ten percent).
"""

import math

import numpy as np

from .atmosphere import air_flow, air_flows, geodetic_latitude_height
from .chebyshev import ChebyshevSegments
from ...optional import require_for

#: NRLMSIS's version that ``pymsis`` evaluates.
MSIS_VERSION = 2.1
#: A day (s): the model's day of the year changes at every multiple from 1970.
DAY = 86400.0


class MsisAtmosphere:
    """
    NRLMSIS 2.1's density (see the module) along ``orbit``, from Unix time ``start`` at t = 0.

    ``start`` (s, UTC) is the date at orbit time 0; ``f107`` and ``f107a`` (sfu),
    the previous day's 10.7 cm flux and its 81-day mean, and ``ap``, the daily
    geomagnetic index; ``rotation_angle`` theta0 (rad) and ``rotation_rate`` (rad/s)
    turn the Earth-fixed frame about the world z axis, and the air turns with it.
    :meth:`density` (t s, r m) is interpolated along the orbit (``r`` must be the
    orbit's position at t); :meth:`exact` calls the model at any (t, r). With
    ``orbit`` None there is no interpolant and :meth:`density` is :meth:`exact` (the
    density the orbit's own drag integrates through, :mod:`.zonal_orbit`). Refuses
    (ValueError naming the parameter) activity out of range and a missing pymsis.
    """

    name = 'nrlmsis'

    def __init__(self, orbit, start, f107=150.0, f107a=150.0, ap=4.0, rotation_angle=0.0,
                 rotation_rate=0.0, segments=16, order=9):
        require_for('atmosphere_model nrlmsis', 'pymsis')
        from pymsis import calculate
        self._calculate = calculate
        for key, value in (('solar_flux_f107', f107), ('solar_flux_f107a', f107a)):
            if not (math.isfinite(value) and 0.0 < value <= 1000.0):
                raise ValueError(f'{key} must be in (0, 1000] sfu, got {value!r}')
        if not (math.isfinite(ap) and 0.0 <= ap <= 400.0):
            raise ValueError(f'geomagnetic_ap must be in [0, 400], got {ap!r}')
        for key, value in (('earth_rotation_angle', rotation_angle),
                           ('earth_rotation_rate', rotation_rate)):
            if not math.isfinite(value):
                raise ValueError(f'{key} must be finite, got {value!r}')
        self.orbit, self.start = orbit, float(start)
        self.f107, self.f107a, self.ap = float(f107), float(f107a), float(ap)
        self.theta0, self.earth_rate = float(rotation_angle), float(rotation_rate)
        if orbit is None:
            self.density = self.exact
            return
        # segments that meet at every 0 h UTC, where the model's day of the year steps
        per_day = max(1, round(DAY / (orbit.period / segments)))
        self.interpolant = ChebyshevSegments(self._sample, DAY / per_day, order, name='nrlmsis',
                                             components=1, origin=-math.fmod(self.start, DAY))
        self._log_density = self.interpolant.value

    def model(self, times, positions):
        """
        Return NRLMSIS's density (kg/m^3, an array) at orbit ``times`` (s) and ``positions``.

        ``positions`` (m, world frame), one per time: one call of the model for all.
        """
        times = np.atleast_1d(np.asarray(times, float))
        lat, lon, height = [], [], []
        for t, r in zip(times, positions):
            phi, h = geodetic_latitude_height(r)
            lat.append(math.degrees(phi))
            lon.append(math.degrees(math.atan2(r[1], r[0]) - self.theta0 - self.earth_rate * t))
            height.append(1e-3 * h)
        dates = (np.round((self.start + times) * 1e6).astype(np.int64)).astype('datetime64[us]')
        n = len(times)
        out = self._calculate(dates, np.remainder(np.array(lon) + 180.0, 360.0) - 180.0,
                              np.array(lat), np.array(height), np.full(n, self.f107),
                              np.full(n, self.f107a), np.full((n, 7), self.ap),
                              version=MSIS_VERSION)
        return np.asarray(out)[:, 0]

    def exact(self, t, r):
        """Return the model's density (kg/m^3) at orbit time t (s) and ``r`` (m, world frame)."""
        return float(self.model([t], [r])[0])

    def _sample(self, middle, times):
        """Return log rho (rho in kg/m^3) on the orbit at ``times`` (s), shape (N, 1)."""
        rho = self.model(times, [self.orbit.position(t) for t in times])
        return np.log(rho)[:, None]

    def density(self, t, r):
        """Return rho (kg/m^3) at orbit time t (s) on the orbit, interpolated (``r`` unused)."""
        return math.exp(self._log_density(t))

    def densities(self, times, r):
        """Return :meth:`density` (kg/m^3, an (N,) array) at orbit ``times`` (s) on the orbit."""
        if self.orbit is None:
            return self.model(times, r)
        return np.exp(self.interpolant.values(times)[:, 0])

    def flow(self, r, v):
        """Return the velocity relative to the air (m/s, world frame): v - omega_E x r."""
        return air_flow(self.earth_rate, r, v)

    def flows(self, r, v):
        """Return :meth:`flow` at many places: ``r`` (m) and ``v`` (m/s), (N, 3) arrays."""
        return air_flows(self.earth_rate, r, v)

    def __str__(self):
        return (f'NRLMSIS {MSIS_VERSION} (F10.7 {self.f107:g} sfu, F10.7a {self.f107a:g} sfu, '
                f'Ap {self.ap:g})')
