"""
How large the Sun's pressure is on the CubeSat of satellite_srp.yaml, over a day of its orbit.

The facets, TLE and epoch are read from the file. The CubeSat holds one attitude in the
world frame (the body axes on TEME's); every 10 s of one day this prints the largest
solar-pressure torque, the share of the day in umbra, the penumbra's length per pass,
and the gravity gradient's largest torque at the same attitude for scale.
"""

from pathlib import Path

import numpy as np
from rigid_body_dynamics.physics.environment import (Facets, GravityGradient, MU_WGS72, R_EARTH,
                                                     SolarPressureTorque, SpaceEnvironment, Sun,
                                                     TleOrbit)
from rigid_body_dynamics.physics.environment.shadow import conical_shadow_fraction
import yaml

values = yaml.safe_load((Path(__file__).parent / 'satellite_srp.yaml').read_text())
values = values['/**']['ros__parameters']
facets = Facets(values['facets'])
orbit = TleOrbit(*values['orbit_tle'], epoch=values['epoch'])
sun = Sun(values['epoch'])
pressure = SpaceEnvironment(orbit, None, [SolarPressureTorque(facets)], sun=sun,
                            shadow='conical')
gravity = SpaceEnvironment(orbit, None, [GravityGradient((0.033, 0.033, 0.007), MU_WGS72)])
times = np.arange(0.0, 86400.0, 10.0)
srp = np.array([np.linalg.norm(pressure(t, 0.0, 0.0, 0.0, 1.0)) for t in times])
gg = np.array([np.linalg.norm(gravity(t, 0.0, 0.0, 0.0, 1.0)) for t in times])
light = np.array([conical_shadow_fraction(orbit.position(t), sun.position(t), R_EARTH)
                  for t in np.arange(0.0, 86400.0, 0.5)])
passes = np.count_nonzero(np.diff((light == 0.0).astype(int)) == 1)
penumbra = 0.5 * np.count_nonzero((light > 0.0) & (light < 1.0)) / (2 * passes)
print(f'solar pressure: up to {srp.max():.2e} N m in sunlight, none in umbra '
      f'({np.mean(light == 0.0):.1%} of the day, {passes} passes), '
      f'{penumbra:.1f} s of penumbra at each edge')
print(f'the gravity gradient at the same attitude: up to {gg.max():.2e} N m')
