"""
The space-environment parameters (orbit, field, magnetorquers, magnetometer), defined once.

attitude_simulator flies them all; attitude_analyzer reads the orbit and the
gravity gradient (for the libration theory) under the same names, so one
parameters file (``/**:``) serves both. :func:`environment_from` turns validated
values into the engine's
:class:`~rigid_body_dynamics.engine.body.Disturbances`, refusing with a reason
that names the parameter.
"""

from .sensor_parameters import epoch_of, sun_from
from ..engine import Disturbances
from ..physics.environment import (DipoleField, EARTH_RATE, ExponentialAtmosphere, Facets,
                                   greenwich_mean_sidereal_time, IGRF13_2020, IgrfField,
                                   julian_date, KeplerOrbit, MsisAtmosphere, MU_EARTH,
                                   R_EARTH, TleOrbit, unix_time, ZonalOrbit)
from ..physics.environment.atmosphere import ATMOSPHERE_MODELS
from ..physics.environment.facets import FACET_FIELDS
from ..ros.parameters import ConfigurationError, number_list, Param

_IGRF = [float(c) for c in IGRF13_2020]

#: Every environment parameter, by name, in the order the manual lists them.
ENVIRONMENT_PARAMS = {p.name: p for p in (
    Param('orbit_elements', 'double[6]', None, 'unset (no orbit)',
          'Two-body orbit [a (m), e, i, RAAN, argument of perigee, true anomaly at t = 0 '
          "(rad)] in the world frame (inertial, z the planet's rotation axis), solved from "
          "Kepler's equation at every step (or integrated under J2..J6: orbit_zonal_degree); "
          '0 <= e < 1 and the perigee above planet_radius. '
          'Unset = no orbit (a free body, unless orbit_tle is set).', read_only=True),
    Param('orbit_tle', 'string[2]', None, 'unset (no TLE)',
          'The two lines of a TLE (NORAD two-line element set), flown by SGP4 (the sgp4 '
          'library, WGS-72): the world frame is then TEME (true equator, mean equinox of '
          "date), and simulated time 0 is epoch, or the TLE's epoch when epoch is unset. "
          "Instead of orbit_elements (set one); orbit_mu is then WGS-72's 3.986008e14 "
          'm^3/s^2.', read_only=True),
    Param('orbit_zonal_degree', 'int', 0, '0 (Kepler)',
          'With orbit_elements: 0 flies the two-body Kepler orbit; 2..6 integrates the orbit '
          "under the planet's zonal harmonics J2 to J<degree> (EGM2008's, reference radius "
          '6378136.3 m; DOP853 at rtol 1e-13), the elements then osculating at t = 0, the '
          'world frame the same. Not with orbit_tle (SGP4 has its own J2 to J4).',
          low=0, high=6, read_only=True),
    Param('orbit_ballistic_coefficient', 'double', 0.0, '0.0 kg/m^2 (no drag on the orbit)',
          'With orbit_zonal_degree 2..6: the drag of the air on the orbit, '
          '-1/2 rho |v_r| v_r / B, B = m / (C_D A) this ballistic coefficient (kg/m^2: the mass '
          'over the drag coefficient times the area facing the flow, taken constant), rho '
          'from atmosphere_model, v_r the velocity relative to the air turning with the '
          'Earth. 0 = none. With nrlmsis every step of the orbit calls the model (a tenth of '
          'a second per orbit, once). Not with orbit_tle (SGP4 has its own drag, the B* of '
          'the TLE).', low=0.0, high=1e6, read_only=True),
    Param('orbit_mu', 'double', MU_EARTH, '3.986004418e14 m^3/s^2',
          "The planet's gravitational parameter mu (m^3/s^2).", low=1e-30, high=1e30,
          read_only=True),
    Param('planet_radius', 'double', R_EARTH, '6378137.0 m',
          'Planet radius (m): the perigee must be above it.', low=0.0, high=1e12,
          read_only=True),
    Param('gravity_gradient', 'bool', False, 'false',
          'The gravity-gradient torque 3 mu / |r|^5 (r_B x I r_B) on the orbit (needs '
          'orbit_elements or orbit_tle), evaluated at every integrator stage.', read_only=True),
    Param('magnetic_field_model', 'string', 'none', '`none`',
          "The planet's magnetic field (needs orbit_elements or orbit_tle): none; dipole, the "
          'centred tilted dipole of magnetic_dipole_coefficients; or igrf, the IGRF-14 to '
          "magnetic_field_degree at the epoch's date (the ppigrf library's coefficients; "
          'needs an epoch, 1900-2030), interpolated along the orbit within 0.01 nT of the '
          'sum. With a field the node takes magnetorquer_cmd.',
          read_only=True, choices=('dipole', 'igrf', 'none')),
    Param('magnetic_field_degree', 'int', 13, '13',
          'The highest degree of the IGRF-14 sum (magnetic_field_model igrf); 1 is the tilted '
          'dipole of the date.', low=1, high=13, read_only=True),
    Param('magnetic_dipole_coefficients', 'double[3]', _IGRF,
          '[-29404.8, -1450.9, 4652.5] nT (IGRF-13, 2020.0)',
          'Gauss coefficients [g10, g11, h11] (nT) of the dipole field, reference radius '
          '6371.2 km.', read_only=True),
    Param('earth_rotation_angle', 'double', None, 'unset (from the epoch)',
          'Angle of the Earth-fixed frame about the world z axis at t = 0 (rad). Unset: the '
          "Greenwich mean sidereal time (IAU 1982) of epoch (or of the TLE's epoch), 0.0 "
          'without either.', low=-1e6, high=1e6, read_only=True),
    Param('earth_rotation_rate', 'double', EARTH_RATE, '7.292115e-05 rad/s',
          "The planet's rotation rate about z (rad/s): the field turns with it.",
          low=-1.0, high=1.0, read_only=True),
    Param('residual_dipole', 'double[3]', [0.0, 0.0, 0.0], '[0, 0, 0] A m^2',
          "The spacecraft's residual magnetic dipole (A m^2, body frame): torque m x B "
          '(needs the field).', read_only=True),
    Param('magnetorquer_max_dipole', 'double[3]', [0.0, 0.0, 0.0], '[0, 0, 0] A m^2',
          'Limit of each magnetorquer (rods along the body x, y, z; A m^2, 0 = none): '
          'magnetorquer_cmd components beyond it are clipped and counted.', read_only=True),
    Param('magnetometer_rate', 'double', 0.0, '0.0 Hz',
          'Magnetometer samples per simulated second on magnetic_field (Hz, 0 = off; needs '
          'the field); at most integration_rate, rounded to a whole number of steps.',
          low=0.0, high=1e5, read_only=True),
    Param('magnetometer_noise', 'double', 0.0, '0.0 T',
          'White noise of the magnetometer (T, 1 sigma per axis); its covariance is '
          'noise^2 on the diagonal.', low=0.0, high=1.0, read_only=True),
    Param('magnetometer_bias', 'double[3]', [0.0, 0.0, 0.0], '[0, 0, 0] T',
          'Constant bias of the magnetometer (T, body frame); not in the covariance.',
          read_only=True),
    Param('facets', 'double[]', None, '[] (none)',
          f"The body's surface as flat facets, {len(FACET_FIELDS)} numbers per facet: area "
          '(m^2), outward normal nx, ny, nz (body frame; normalised), centre of pressure '
          'cx, cy, cz (m, body frame, from the centre of mass), specular and diffuse '
          'reflection coefficients (each >= 0, their sum <= 1; the rest is absorbed) and the '
          'drag coefficient. Self-shadowing is not modelled (exact for a convex body). For '
          'solar_pressure and drag.', read_only=True, convert=number_list('facets')),
    Param('solar_pressure', 'bool', False, 'false',
          "The torque of the Sun's light on the facets (Montenbruck and Gill's absorbed, "
          'specular and diffuse parts; 1361 W/m^2 / c at 1 au, scaled by the inverse square '
          "of the Sun's distance and by shadow_model's sunlit fraction), evaluated at every "
          'integrator stage. Needs an orbit, epoch and facets.', read_only=True),
    Param('drag', 'bool', False, 'false',
          'The torque of the air on the facets (each facet facing the flow: '
          '-1/2 rho C_D A (n . v) v, the flat-plate free-molecular model), v the velocity '
          'relative to the air turning with the Earth (earth_rotation_rate), rho from '
          'atmosphere_model at the height above the WGS-84 ellipsoid; evaluated at every '
          'integrator stage. Needs an orbit and facets.', read_only=True),
    Param('atmosphere_model', 'string', 'exponential', '`exponential`',
          "The air's density for drag: exponential, Vallado's table 8-4 (Fundamentals of "
          'Astrodynamics and Applications, 4th ed.; US Standard Atmosphere 1976 and '
          'CIRA-72), without solar activity (the real density at 400 km moves 5 to 10 '
          'times over the solar cycle); or nrlmsis, NRLMSIS 2.1 (the pymsis library) at '
          "the epoch's date with solar_flux_f107, solar_flux_f107a and geomagnetic_ap, "
          'interpolated along the orbit within 1.5e-4 of the model, which computes in single '
          'precision (needs an epoch).',
          choices=ATMOSPHERE_MODELS, read_only=True),
    Param('solar_flux_f107', 'double', 150.0, '150.0 sfu',
          "The previous day's 10.7 cm solar radio flux F10.7 (solar flux units, 1e-22 "
          'W m^-2 Hz^-1) for atmosphere_model nrlmsis: 70 at solar minimum, 150 moderate, '
          '250 and more at maximum.', low=1.0, high=1000.0, read_only=True),
    Param('solar_flux_f107a', 'double', 150.0, '150.0 sfu',
          'The 81-day mean of F10.7 (sfu) centred on the date, for atmosphere_model nrlmsis.',
          low=1.0, high=1000.0, read_only=True),
    Param('geomagnetic_ap', 'double', 4.0, '4.0',
          'The daily geomagnetic index Ap for atmosphere_model nrlmsis: 4 quiet, 15 to 30 '
          'active, 100 and more a storm.', low=0.0, high=400.0, read_only=True),
    Param('lvlh_frame', 'string', 'lvlh', '`lvlh`',
          "Frame id of the orbit's LVLH frame (z nadir, y minus the orbit normal), "
          'broadcast as world_frame -> lvlh_frame on /tf with an orbit.', read_only=True),
)}


def environment_params(*names):
    """Return the Params called ``names`` (all when none is named), for a ParameterTable."""
    return [ENVIRONMENT_PARAMS[n] for n in (names or ENVIRONMENT_PARAMS)]


def orbit_from(out):
    """
    Return the orbit of validated values ``out``: Kepler, zonal, TLE or None (unset).

    A :class:`KeplerOrbit`, a :class:`ZonalOrbit` (``orbit_zonal_degree`` > 0) or
    a :class:`TleOrbit`. Refusals (ConfigurationError) name the parameter: both
    orbits set, a zonal degree without elements or with a TLE, elements or lines
    that do not make an orbit.
    """
    elements, tle = out.get('orbit_elements'), out.get('orbit_tle')
    degree = out.get('orbit_zonal_degree') or 0
    ballistic = out.get('orbit_ballistic_coefficient') or 0.0
    if ballistic and tle is not None:
        raise ConfigurationError('orbit_ballistic_coefficient is not for orbit_tle: SGP4 flies '
                                 "the TLE's own drag (its B*)")
    if ballistic and not degree:
        raise ConfigurationError('orbit_ballistic_coefficient needs orbit_zonal_degree 2..6 '
                                 '(the drag acts on the integrated orbit, not on the Kepler '
                                 'one)')
    if elements is not None and tle is not None:
        raise ConfigurationError('orbit_elements and orbit_tle are both set: set one (the '
                                 'Kepler orbit or the TLE)')
    if degree and elements is None:
        raise ConfigurationError(f'orbit_zonal_degree {degree} needs orbit_elements (the '
                                 'osculating elements at t = 0)' + (
                                     '; SGP4 flies orbit_tle with its own J2 to J4'
                                     if tle is not None else ''))
    try:
        if tle is not None:
            return TleOrbit(*tle, epoch=out.get('epoch') or None)
        if degree:
            air = atmosphere_from(out, None) if ballistic else None
            return ZonalOrbit(elements, degree, out['orbit_mu'], out['planet_radius'],
                              ballistic_coefficient=ballistic, atmosphere=air)
        if elements is not None:
            return KeplerOrbit(elements, out['orbit_mu'], out['planet_radius'])
    except ValueError as err:
        raise ConfigurationError(str(err)) from None
    return None


def earth_rotation_angle(out, orbit):
    """
    Return the Earth's rotation angle at t = 0 (rad) of validated values ``out``.

    ``earth_rotation_angle`` when set; else the Greenwich mean sidereal time of
    ``epoch`` (or of a TLE orbit's epoch, its t = 0); else 0.
    """
    if out.get('earth_rotation_angle') is not None:
        return out['earth_rotation_angle']
    epoch = epoch_of(out, orbit)
    return greenwich_mean_sidereal_time(julian_date(epoch)) if epoch else 0.0


def field_from(out, orbit):
    """
    Return the magnetic field model of validated values ``out`` on ``orbit`` (None: none).

    Refuses (ConfigurationError, naming the parameter) a field without an orbit
    and coefficients that do not make one.
    """
    if out['magnetic_field_model'] == 'none':
        return None
    if orbit is None:
        raise ConfigurationError(f'magnetic_field_model {out["magnetic_field_model"]} needs '
                                 'an orbit, orbit_elements or orbit_tle (the field depends '
                                 'on the position)')
    angle = earth_rotation_angle(out, orbit)
    try:
        if out['magnetic_field_model'] == 'dipole':
            return DipoleField(out['magnetic_dipole_coefficients'], angle,
                               out['earth_rotation_rate'])
        epoch = epoch_of(out, orbit)
        if not epoch:
            raise ConfigurationError('magnetic_field_model igrf needs epoch (the date of the '
                                     "field's coefficients)")
        return IgrfField(orbit, unix_time(epoch), out['magnetic_field_degree'], angle,
                         out['earth_rotation_rate'])
    except ConfigurationError:
        raise
    except ValueError as err:
        raise ConfigurationError(str(err)) from None


def environment_from(out):
    """
    Return the engine's Disturbances of a simulator's validated values ``out``.

    Reads disturbance_torque_body / _world, every environment parameter and the
    Sun's (epoch, sun_direction: :func:`.sensor_parameters.sun_from`); refuses
    (ConfigurationError, naming the parameter) a gravity gradient, field or
    magnetometer without what it needs.
    """
    orbit = orbit_from(out)
    field = field_from(out, orbit)
    if out['gravity_gradient'] and orbit is None:
        raise ConfigurationError('gravity_gradient needs an orbit, orbit_elements or orbit_tle '
                                 '(the torque depends on the position)')
    for name in ('residual_dipole', 'magnetometer_bias'):
        if any(out[name]) and field is None:
            raise ConfigurationError(f'{name} needs a field: magnetic_field_model dipole or igrf')
    if out['magnetometer_rate'] > 0.0 and field is None:
        raise ConfigurationError('magnetometer_rate > 0 needs a field: magnetic_field_model '
                                 'dipole or igrf')
    if any(c < 0.0 for c in out['magnetorquer_max_dipole']):
        raise ConfigurationError('magnetorquer_max_dipole must be >= 0 per axis (0 = no limit), '
                                 f'got {list(out["magnetorquer_max_dipole"])}')
    sun = sun_from(out, orbit) if 'epoch' in out else None
    facets = facets_from(out)
    if out['drag']:
        missing = [what for what, absent in (
            ('an orbit (orbit_elements or orbit_tle)', orbit is None),
            ('facets (the surface it pushes on)', facets is None)) if absent]
        if missing:
            raise ConfigurationError(f'drag needs {" and ".join(missing)}')
    atmosphere = atmosphere_from(out, orbit) if out['drag'] else None
    if out['solar_pressure']:
        missing = [what for what, absent in (
            ('an orbit (orbit_elements or orbit_tle)', orbit is None),
            ('epoch (where the Sun is)', sun is None),
            ('facets (the surface it pushes on)', facets is None)) if absent]
        if missing:
            raise ConfigurationError(f'solar_pressure needs {" and ".join(missing)}')
    return Disturbances(out['disturbance_torque_body'], out['disturbance_torque_world'], orbit,
                        field, out['gravity_gradient'], out['residual_dipole'], sun,
                        out['planet_radius'], out['shadow_model'], facets,
                        out['solar_pressure'], atmosphere, out['drag'])


def atmosphere_from(out, orbit):
    """
    Return the atmosphere of validated values ``out`` on ``orbit`` (refusing with the reason).

    ``exponential``: Vallado's table; ``nrlmsis``: NRLMSIS 2.1 along the orbit from the
    epoch's date, with the solar and geomagnetic activity, the Earth turned as for the field;
    with ``orbit`` None, the model itself at any time and place (the orbit's own drag).
    """
    if out['atmosphere_model'] == 'exponential':
        return ExponentialAtmosphere(out['earth_rotation_rate'])
    epoch = epoch_of(out, orbit)
    if not epoch:
        raise ConfigurationError("atmosphere_model nrlmsis needs epoch (the date of the air's "
                                 'season and local time)')
    try:
        return MsisAtmosphere(orbit, unix_time(epoch), out['solar_flux_f107'],
                              out['solar_flux_f107a'], out['geomagnetic_ap'],
                              earth_rotation_angle(out, orbit), out['earth_rotation_rate'])
    except ValueError as err:
        raise ConfigurationError(str(err)) from None


def facets_from(out):
    """Return the :class:`Facets` of validated values ``out`` (None when facets is unset)."""
    if not out.get('facets'):
        return None
    try:
        return Facets(out['facets'])
    except ValueError as err:
        raise ConfigurationError(str(err)) from None
