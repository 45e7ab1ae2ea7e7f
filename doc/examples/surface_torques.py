"""
How large the Sun's pressure and the air's drag are on the CubeSat of satellite_surface.yaml.

The facets, TLE and epoch are read from the file. The CubeSat holds one attitude in the
world frame (the body axes on TEME's); every 10 s of one day this prints the largest
solar-pressure torque, the share of the day in umbra and the penumbra's length per pass,
the drag torque's largest and mean (Vallado's table, then NRLMSIS 2.1 at a quiet, a
moderate and an active Sun), and the gravity gradient's largest torque at the same
attitude for scale.
"""

from pathlib import Path

import numpy as np
from rigid_body_dynamics.physics.environment import (DragTorque, EARTH_RATE,
                                                     ExponentialAtmosphere, Facets,
                                                     GravityGradient,
                                                     greenwich_mean_sidereal_time, julian_date,
                                                     MsisAtmosphere, MU_WGS72, R_EARTH,
                                                     SolarPressureTorque, SpaceEnvironment, Sun,
                                                     TleOrbit, unix_time)
from rigid_body_dynamics.physics.environment.shadow import conical_shadow_fraction
import yaml

values = yaml.safe_load((Path(__file__).parent / 'satellite_surface.yaml').read_text())
values = values['/**']['ros__parameters']
facets = Facets(values['facets'])
orbit = TleOrbit(*values['orbit_tle'], epoch=values['epoch'])
sun = Sun(values['epoch'])
environments = {
    'pressure': SpaceEnvironment(orbit, None, [SolarPressureTorque(facets)], sun=sun,
                                 shadow='conical'),
    'drag': SpaceEnvironment(orbit, None, [DragTorque(facets)],
                             atmosphere=ExponentialAtmosphere(EARTH_RATE)),
    'gravity': SpaceEnvironment(orbit, None, [GravityGradient((0.033, 0.033, 0.007),
                                                              MU_WGS72)])}
theta0 = greenwich_mean_sidereal_time(julian_date(values['epoch']))
for f107 in (70.0, 150.0, 250.0):       # sfu: solar minimum (as in December 2019) to maximum
    air = MsisAtmosphere(orbit, unix_time(values['epoch']), f107, f107, 4.0, theta0, EARTH_RATE)
    environments[f107] = SpaceEnvironment(orbit, None, [DragTorque(facets)], atmosphere=air)
times = np.arange(0.0, 86400.0, 10.0)
size = {name: np.array([np.linalg.norm(env(t, 0.0, 0.0, 0.0, 1.0)) for t in times])
        for name, env in environments.items()}
light = np.array([conical_shadow_fraction(orbit.position(t), sun.position(t), R_EARTH)
                  for t in np.arange(0.0, 86400.0, 0.5)])
passes = np.count_nonzero(np.diff((light == 0.0).astype(int)) == 1)
penumbra = 0.5 * np.count_nonzero((light > 0.0) & (light < 1.0)) / (2 * passes)
print(f'solar pressure: up to {size["pressure"].max():.2e} N m in sunlight, none in umbra '
      f'({np.mean(light == 0.0):.1%} of the day, {passes} passes), '
      f'{penumbra:.1f} s of penumbra at each edge')
print(f'drag: up to {size["drag"].max():.2e} N m, {size["drag"].mean():.2e} N m on average')
print('drag with NRLMSIS 2.1 (Ap 4), on average: ' + ', '.join(
    f'{size[f107].mean():.2e} N m at F10.7 {f107:.0f}' for f107 in (70.0, 150.0, 250.0)))
print(f'the gravity gradient at the same attitude: up to {size["gravity"].max():.2e} N m')
