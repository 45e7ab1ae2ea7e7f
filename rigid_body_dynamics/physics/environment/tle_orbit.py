"""
An orbit from a two-line element set (TLE), propagated by SGP4 (the ``sgp4`` library).

SGP4 is the propagator TLEs are made for (Hoots and Roehrich, Spacetrack Report
No. 3, 1980, as revised by Vallado, Crawford, Hujsak and Kelso, "Revisiting
Spacetrack Report #3", AIAA 2006-6753). The ``sgp4`` library compiles Vallado's
C++ code; this module only reads its results. It uses the WGS-72 constants, as
the TLEs' producers do.

Frames and units. SGP4 gives the position and velocity in TEME, the frame of
the true equator and the mean equinox of date. Here TEME *is* the world frame
(no turn): z along the Earth's rotation axis, x towards the mean equinox of
date. It turns so slowly (precession and nutation, under 0.3 arcsec a day) that
it is taken as inertial over a run. The Almanac's Sun of :mod:`.sun` is of date
too (the two differ by the nutation in right ascension, under 0.005 deg, below
that formula's 0.01 deg), and the Earth's rotation angle of an epoch is the
Greenwich mean sidereal time (:func:`greenwich_mean_sidereal_time`), the angle
that turns TEME into the Earth-fixed frame (Vallado, Fundamentals of
Astrodynamics and Applications, 4th ed., section 3.7). Against J2000 / GCRF,
TEME of 2026 is turned by the precession since 2000, about 0.37 deg.
Positions in m, velocities in m/s, time t in s from simulated time 0, which is
``epoch`` when given, else the TLE's own epoch.
"""

from datetime import datetime, timezone
import math

import numpy as np

from .sun import JD_UNIX, unix_time
from ...optional import require_for

#: WGS-72's gravitational parameter (m^3/s^2), the one SGP4 flies TLEs with.
MU_WGS72 = 3.986008e14
_DAY = 86400.0
_TWO_PI = 2.0 * math.pi


def greenwich_mean_sidereal_time(jd_ut1):
    """
    Return the Greenwich mean sidereal time (rad, in [0, 2 pi)) at Julian date ``jd_ut1``.

    The IAU 1982 expression (Vallado, Fundamentals of Astrodynamics and
    Applications, eq. 3-47), as the ``sgp4`` library gives it: the angle about z
    from TEME's x axis (the mean equinox) to the Greenwich meridian. UTC is taken
    as UT1 (they differ by under 0.9 s, 6.6e-5 rad).
    """
    from sgp4.propagation import gstime
    return gstime(jd_ut1)


def _satrec(line1, line2):
    """Return sgp4's Satrec of the two lines; ValueError naming ``orbit_tle`` says why not."""
    require_for('orbit_tle', 'sgp4')
    from sgp4.api import Satrec, WGS72
    lines = []
    for number, line in ((1, line1), (2, line2)):
        if not isinstance(line, str):
            raise ValueError(f'orbit_tle: line {number} must be a string, got {line!r}')
        line = line.rstrip()
        if len(line) < 69 or not line.startswith(f'{number} '):
            raise ValueError(f'orbit_tle: line {number} must be the 69 columns of a TLE line '
                             f'starting "{number} ", got {line!r}')
        lines.append(line)
    try:
        satellite = Satrec.twoline2rv(lines[0], lines[1], WGS72)
    except (ValueError, IndexError) as err:
        raise ValueError(f'orbit_tle: the lines are not a TLE that SGP4 reads ({err})') \
            from None
    if satellite.error:
        raise ValueError(f'orbit_tle: SGP4 refuses the elements: {_error(satellite.error)}')
    return satellite


def _error(code):
    """Return the sgp4 library's text of its error ``code``."""
    from sgp4.api import SGP4_ERRORS
    return f'{SGP4_ERRORS.get(code, "unknown error")} (SGP4 error {code})'


class TleOrbit:
    """
    The orbit of a TLE (``line1``, ``line2``) by SGP4, in TEME (the world frame), m and m/s.

    ``epoch`` (ISO 8601 UTC, or None): the time of t = 0; None = the TLE's epoch.
    Refuses (ValueError naming ``orbit_tle``) lines that are not a TLE, elements
    SGP4 cannot fly, and an orbit SGP4 cannot reach at t = 0. :meth:`state`
    raises ValueError with SGP4's reason (e.g. the satellite has decayed) at a
    time it cannot reach. ``mu`` is WGS-72's (:data:`MU_WGS72`), the gravity of
    SGP4, which the gravity gradient uses too.
    """

    mu = MU_WGS72

    def __init__(self, line1, line2, epoch=None):
        self.satellite = s = _satrec(line1, line2)
        self.lines = (line1.rstrip(), line2.rstrip())
        #: the TLE's epoch as a Unix time (s, UTC): the day number is exact in a double
        self.tle_epoch = (s.jdsatepoch - JD_UNIX) * _DAY + s.jdsatepochF * _DAY
        #: the simulated time 0 as a Unix time (s, UTC)
        self.start = self.tle_epoch if epoch is None else unix_time(epoch)
        #: minutes from the TLE's epoch to t = 0 (SGP4's ``tsince`` at t = 0)
        self.tsince0 = (self.start - self.tle_epoch) / 60.0
        #: the mean elements of the TLE [a m, e, i, RAAN, argp, mean anomaly rad] (SGP4's
        #: Brouwer mean a from the un-Kozai'd mean motion; angles at the TLE's epoch)
        self.elements = (s.a * s.radiusearthkm * 1e3, s.ecco, s.inclo, s.nodeo, s.argpo, s.mo)
        self.state(0.0)                  # refuses an orbit SGP4 cannot fly at t = 0

    @property
    def period(self):
        """Return the period of the TLE's mean motion (s, from SGP4's no_kozai rad/min)."""
        return _TWO_PI / self.satellite.no_kozai * 60.0

    @property
    def start_text(self):
        """Return t = 0 as ISO 8601 UTC text (to the microsecond), e.g. for the Sun's epoch."""
        return f'{datetime.fromtimestamp(self.start, timezone.utc):%Y-%m-%dT%H:%M:%S.%f}Z'

    def state(self, t):
        """Return (r m, v m/s), tuples in the world frame (TEME), at time t (s)."""
        error, r, v = self.satellite.sgp4_tsince(self.tsince0 + t / 60.0)
        if error:
            when = datetime.fromtimestamp(self.start + t, timezone.utc)
            raise ValueError(f'orbit_tle: SGP4 cannot fly the orbit at t = {t:g} s '
                             f'({when:%Y-%m-%dT%H:%M:%SZ}): {_error(error)}')
        return ((r[0] * 1e3, r[1] * 1e3, r[2] * 1e3), (v[0] * 1e3, v[1] * 1e3, v[2] * 1e3))

    def position(self, t):
        """Return r (m, world frame: TEME) at time t (s)."""
        return self.state(t)[0]

    def states(self, times):
        """
        Return (r m, v m/s), (N, 3) arrays in TEME, at ``times`` (s): SGP4 over the array.

        ``Satrec.sgp4_array`` at the TLE's epoch day plus the fraction of the time: the
        same SGP4 as :meth:`state` at a time rounded to 1e-11 s (1e-14 of the position
        apart). Raises ValueError as :meth:`state` where SGP4 cannot fly.
        """
        s = self.satellite
        times = np.asarray(times, float)
        fraction = s.jdsatepochF + (self.tsince0 + times / 60.0) / 1440.0
        error, r, v = s.sgp4_array(np.full(times.size, s.jdsatepoch), fraction)
        if np.any(error):
            bad = int(np.argmax(error != 0))
            self.state(float(times[bad]))        # raises with SGP4's reason
        return r * 1e3, v * 1e3

    def positions(self, times):
        """Return r (m, TEME, (N, 3)) at ``times`` (s): :meth:`states`' positions."""
        return self.states(times)[0]

    def summary(self):
        """Return a line that says which orbit this is (for the node's log)."""
        a, e, inc = self.elements[:3]
        tle = datetime.fromtimestamp(self.tle_epoch, timezone.utc)
        return (f'SGP4 of the TLE of NORAD {self.satellite.satnum} (epoch '
                f'{tle:%Y-%m-%dT%H:%M:%S}Z, WGS-72, world frame TEME), t = 0 is '
                f'{self.tsince0 / 1440.0:+.4g} days from it: mean a = {a:.6g} m, e = {e:g}, '
                f'i = {inc:g} rad, period {self.period:.6g} s')
