"""
The field a magnetometer sees on the ISS's orbit: IGRF-14 to degree 13 against the dipoles.

One day from 2019-12-09T20:42:00Z on the ISS's TLE (SGP4), the Earth turned by the
sidereal time of that epoch, a sample a minute: how far the simulator's dipole
(``magnetic_field_model: dipole``, IGRF-13 at 2020.0 cut at degree 1) is from the
full field, in size and in direction.
"""

import numpy as np
from rigid_body_dynamics.physics.environment import (DipoleField, EARTH_RATE,
                                                     greenwich_mean_sidereal_time, IgrfField,
                                                     julian_date, TleOrbit, unix_time)

ISS = ('1 25544U 98067A   19343.69339541  .00001764  00000-0  38792-4 0  9991',
       '2 25544  51.6439 211.2001 0007417  17.6667  85.6398 15.50103472202482')
EPOCH = '2019-12-09T20:42:00Z'

orbit = TleOrbit(*ISS, epoch=EPOCH)
theta0 = greenwich_mean_sidereal_time(julian_date(EPOCH))
full = IgrfField(orbit, unix_time(EPOCH), 13, theta0, EARTH_RATE)
dipole = DipoleField(rotation_angle=theta0)
times = np.arange(0.0, 86400.0, 60.0)
b = np.array([full.world(t) for t in times])
size = np.linalg.norm(b, axis=1)
print(f'IGRF-14 to degree 13 along the orbit: |B| from {size.min() * 1e9:.0f} to '
      f'{size.max() * 1e9:.0f} nT')
d = np.array([dipole.world(t, orbit.position(t)) for t in times])
error = np.linalg.norm(d - b, axis=1)
cos = np.sum(d * b, axis=1) / (np.linalg.norm(d, axis=1) * size)
angle = np.degrees(np.arccos(np.clip(cos, -1.0, 1.0)))
print(f'the dipole: off by {np.mean(error / size):.1%} of |B| on average ({error.max() * 1e9:.0f} '
      f'nT at most), its direction by {angle.mean():.1f} deg on average, {angle.max():.1f} deg '
      'at most')
