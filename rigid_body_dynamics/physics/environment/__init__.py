"""
The space environment (no ROS): the orbit, Earth's dipole field, and torque models.

:mod:`.orbit` (two-body orbit, LVLH frame), :mod:`.tle_orbit` (a TLE's orbit by
SGP4, the Greenwich mean sidereal time), :mod:`.igrf_field` (the IGRF-14 along
the orbit), :mod:`.magnetic_field` (the
centred tilted dipole), :mod:`.torque_models` (the torque-model protocol:
gravity gradient, magnetic dipoles, magnetorquers) and :mod:`.space`
(:class:`SpaceEnvironment`: what the integrators evaluate at every stage),
:mod:`.sun` (the Sun's direction and the Earth's cylindrical shadow) and
:mod:`.shadow` (the conical shadow with its penumbra); :mod:`.zonal_orbit` (the
orbit integrated under J2..J6) and :mod:`.chebyshev` (the interpolants both it and
the IGRF field use along the orbit); :mod:`.facets` (a faceted surface's solar
radiation pressure and drag), :mod:`.atmosphere` (Vallado's density for drag) and
:mod:`.msis_atmosphere` (NRLMSIS 2.1's along the orbit).
"""

from .atmosphere import ExponentialAtmosphere, geodetic_altitude
from .facets import Facets, solar_pressure_at
from .igrf_field import igrf_coefficients, igrf_fixed, IgrfField
from .magnetic_field import DipoleField, EARTH_RATE, IGRF13_2020, R_REF
from .msis_atmosphere import MsisAtmosphere
from .orbit import circular_elements, KeplerOrbit, lvlh_axes, lvlh_quaternion, MU_EARTH, R_EARTH
from .shadow import conical_shadow_fraction, R_SUN
from .space import Disturbances, SpaceEnvironment, Surroundings
from .sun import in_shadow, julian_date, Sun, sun_direction_almanac, unix_time
from .tle_orbit import greenwich_mean_sidereal_time, MU_WGS72, TleOrbit
from .torque_models import (DragTorque, GravityGradient, MagneticDipole, Magnetorquers,
                            SolarPressureTorque)
from .zonal_orbit import ZonalOrbit

__all__ = ['circular_elements', 'conical_shadow_fraction', 'DipoleField', 'Disturbances',
           'DragTorque', 'EARTH_RATE', 'ExponentialAtmosphere', 'Facets', 'geodetic_altitude',
           'GravityGradient',
           'greenwich_mean_sidereal_time', 'IGRF13_2020', 'igrf_coefficients', 'igrf_fixed',
           'IgrfField', 'in_shadow', 'julian_date',
           'KeplerOrbit', 'lvlh_axes', 'lvlh_quaternion', 'MagneticDipole', 'Magnetorquers',
           'MsisAtmosphere',
           'MU_EARTH', 'MU_WGS72', 'R_EARTH', 'R_REF', 'R_SUN', 'solar_pressure_at',
           'SolarPressureTorque', 'SpaceEnvironment', 'Sun',
           'sun_direction_almanac', 'Surroundings', 'TleOrbit', 'unix_time',
           'ZonalOrbit']
