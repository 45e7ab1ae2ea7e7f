"""
attitude_simulator in orbit, over real topics (the node is its own process).

The orbit on odom against Kepler, the magnetometer against the dipole formula in
the Earth-fixed frame, magnetorquer commands (clipped, refused, counted) and the
attitude replayed offline from applied_dipole, and bad environment parameters
refused at start naming the parameter.
"""

from datetime import datetime, timezone
import math

from diagnostic_msgs.msg import DiagnosticArray, DiagnosticStatus
from geometry_msgs.msg import Vector3Stamped
from nav_msgs.msg import Odometry
import numpy as np
import pytest
from rigid_body_dynamics.physics import make_integrator
from rigid_body_dynamics.physics.environment import (DipoleField, GravityGradient, KeplerOrbit,
                                                     MagneticDipole, MU_EARTH, SpaceEnvironment)
from rigid_body_dynamics.ros.conversions import time_ns, vector_array
from ros_harness import odom_arrays
from scipy.spatial.transform import Rotation
from sensor_msgs.msg import MagneticField

SIM = 'rigid_body_dynamics.nodes.simulator'
ELEMENTS = [7.0e6, 0.01, 1.2, 0.4, 0.2, 0.1]
MOMENTS = (2.0, 3.0, 1.0)
RESIDUAL = (0.01, 0.0, -0.02)
BIAS = (1e-7, -2e-7, 3e-7)
ORBIT = ('-p', 'publish_clock:=true', '-p', f'inertia:={list(MOMENTS)}',
         '-p', 'initial_angular_velocity:=[0.3, -0.5, 0.8]', '-p', f'orbit_elements:={ELEMENTS}',
         '-p', 'gravity_gradient:=true', '-p', 'magnetic_field_model:=dipole',
         '-p', 'earth_rotation_angle:=0.3', '-p', f'residual_dipole:={list(RESIDUAL)}',
         '-p', 'magnetorquer_max_dipole:=[0.5, 0.0, 0.2]', '-p', 'magnetometer_rate:=100.0',
         '-p', f'magnetometer_bias:={list(BIAS)}', '-p', 'torque_timeout:=0.0',
         '-p', 'publish_rate:=1000.0')


def _dipole(k):
    return Vector3Stamped(vector=type(Vector3Stamped().vector)(
        x=0.7 * math.sin(k), y=2.0 * math.cos(k), z=0.3 + 0.01 * k))


def test_orbit_field_and_magnetorquers_over_topics(launch, probe):
    """
    Check the orbit, the field and the magnetorquers of a running simulator.

    Position on odom = Kepler (1e-12 relative), its velocity in the body frame; the
    magnetometer = the dipole formula at odom's attitude plus the bias (1e-12 of |B|); a
    schedule of magnetorquer_cmd (z over its limit, y unlimited, one NaN, one in the world
    frame) replayed offline from applied_dipole: q and omega within 1e-12.
    """
    proc = launch(SIM, *ORBIT, name='sim')
    odom = probe.subscribe(Odometry, 'odom')
    field = probe.subscribe(MagneticField, 'magnetic_field')
    applied = probe.subscribe(Vector3Stamped, 'applied_dipole')
    probe.subscribe(DiagnosticArray, '/diagnostics')
    probe.wait_for('odom', 5)
    pub = probe.publisher(Vector3Stamped, 'magnetorquer_cmd')
    probe.handshake(pub, _dipole(0), lambda: any(m.vector.y for m in applied))
    for k in range(1, 8):
        probe.spin_for(0.03)
        pub.publish(_dipole(k))
        if k == 3:
            bad = _dipole(k)
            bad.vector.x = math.nan
            pub.publish(bad)
            world = _dipole(k)
            world.header.frame_id = 'odom'
            pub.publish(world)
    probe.spin_for(0.1)
    orbit = KeplerOrbit(ELEMENTS)
    dipole_field = DipoleField(rotation_angle=0.3)
    by_stamp = {time_ns(m.header.stamp): m for m in odom}
    # the orbit and the velocity in the body frame
    worst_r = worst_v = 0.0
    for t_ns, msg in by_stamp.items():
        r, v = orbit.state(t_ns * 1e-9)
        p = msg.pose.pose.position
        worst_r = max(worst_r, np.linalg.norm(np.subtract((p.x, p.y, p.z), r)) / np.linalg.norm(r))
        q = odom_arrays([msg])[1][0]
        v_body = Rotation.from_quat(q).inv().apply(v)
        worst_v = max(worst_v, np.linalg.norm(vector_array(msg.twist.twist.linear) - v_body)
                      / np.linalg.norm(v))
    assert worst_r < 1e-12 and worst_v < 1e-12, (worst_r, worst_v)
    # the magnetometer against the formula in the Earth-fixed frame, at odom's attitude
    g10, g11, h11 = -29404.8e-9, -1450.9e-9, 4652.5e-9
    d = np.array([g11, h11, g10])
    checked = 0
    for m in field:
        t_ns = time_ns(m.header.stamp)
        if t_ns not in by_stamp:
            continue
        t = t_ns * 1e-9
        to_fixed = Rotation.from_euler('z', -(0.3 + 7.2921150e-5 * t))
        r_f = to_fixed.apply(orbit.position(t))
        rn = np.linalg.norm(r_f)
        b_w = to_fixed.inv().apply((6371.2e3 / rn) ** 3 * (3 * (d @ r_f) / rn ** 2 * r_f - d))
        q = odom_arrays([by_stamp[t_ns]])[1][0]
        expected = Rotation.from_quat(q).inv().apply(b_w) + BIAS
        assert np.linalg.norm(vector_array(m.magnetic_field) - expected) < 1e-12 * np.linalg.norm(
            b_w)
        assert m.header.frame_id == 'base_link' and m.magnetic_field_covariance[0] == 0.0
        checked += 1
    assert checked >= 20
    # the attitude replayed offline: each step under the dipole applied_dipole reports for it
    dipoles = {time_ns(m.header.stamp): tuple(vector_array(m.vector)) for m in applied}
    used = {u for u in dipoles.values() if any(u)}
    # x over its 0.5 limit (0.7 sin k) and z over its 0.2 are clipped to them, per axis
    assert all(abs(u[0]) <= 0.5 and abs(u[2]) <= 0.2 for u in used)
    assert any(abs(u[0]) == 0.5 for u in used) and any(abs(u[0]) < 0.5 for u in used)
    assert any(u[2] == 0.2 for u in used)
    assert any(abs(u[1]) > 1.0 for u in used)                 # 0 = no limit on y
    assert not any(map(math.isnan, (c for u in used for c in u)))
    first = min(t for t, u in dipoles.items() if any(u))
    start, end = first - 1_000_000, max(dipoles)
    _, q0, w0 = odom_arrays([by_stamp[start]])
    ref = make_integrator('exact', MOMENTS, 1e-3, q0[0], w0[0])
    static = [GravityGradient(MOMENTS, MU_EARTH), MagneticDipole(RESIDUAL)]
    worst = 0.0
    for k in range(1, (end - start) // 1_000_000 + 1):
        t = start + k * 1_000_000
        env = SpaceEnvironment(orbit, dipole_field, static + [MagneticDipole(dipoles[t])],
                               epoch=start * 1e-9)
        ref.step((0.0, 0.0, 0.0), None, env)
        if t in by_stamp:
            _, q, w = odom_arrays([by_stamp[t]])
            worst = max(worst, float(np.max(np.abs(q[0] - ref.q))),
                        float(np.max(np.abs(w[0] - ref.omega))))
    assert worst < 1e-12
    probe.spin_until(lambda: (probe.newest_status('magnetorquers') or (0, '', {}))[2].get(
        'rejected_frame') == '1', 10.0, 'the refused magnetorquer commands counted')
    _, message, values = probe.newest_status('magnetorquers')
    assert values['rejected_non_finite'] == '1' and int(values['clipped']) >= 1, values
    assert '2 rejected' in message
    code, _ = proc.stop()
    assert code == 0, proc.output()


#: The ISS (NORAD 25544) on 2019-12-09: the public TLE of the sgp4 library's README.
ISS = ('1 25544U 98067A   19343.69339541  .00001764  00000-0  38792-4 0  9991',
       '2 25544  51.6439 211.2001 0007417  17.6667  85.6398 15.50103472202482')


@pytest.mark.parametrize('model', ['dipole', 'igrf'])
def test_a_tle_orbit_and_the_earth_turned_by_its_epoch_over_topics(launch, probe, model):
    """
    orbit_tle with an epoch 4 h after the TLE's, the field with the Earth turned by it.

    Position on odom = the sgp4 library's propagation at the stamp's UTC (1e-10
    relative; the world frame is TEME); the magnetometer = the field in the
    Earth-fixed frame turned by the GMST of the epoch: the dipole formula (1e-12 of
    |B|) or ppigrf's IGRF-14 at the date (0.003 nT, the interpolation's bound).
    """
    pytest.importorskip('sgp4', reason='orbit_tle needs the sgp4 library')
    from sgp4.api import jday, Satrec, WGS72
    from rigid_body_dynamics.physics.environment import (greenwich_mean_sidereal_time,
                                                         julian_date)
    epoch = '2019-12-09T20:42:00Z'
    proc = launch(SIM, '-p', 'publish_clock:=true', '-p', f'orbit_tle:={list(ISS)}',
                  '-p', f'epoch:={epoch}', '-p', f'magnetic_field_model:={model}',
                  '-p', 'magnetometer_rate:=100.0', '-p', 'publish_rate:=100.0',
                  name=f'tle_{model}')
    odom = probe.subscribe(Odometry, 'odom')
    field = probe.subscribe(MagneticField, 'magnetic_field')
    probe.spin_until(lambda: len(odom) >= 30 and len(field) >= 30, 20.0,
                     '30 odom and magnetometer messages')
    satellite = Satrec.twoline2rv(*ISS, WGS72)
    whole, fraction = jday(2019, 12, 9, 20, 42, 0)      # (a Julian date split: exact)
    theta0 = greenwich_mean_sidereal_time(julian_date(epoch))
    by_stamp = {time_ns(m.header.stamp): m for m in odom}
    d = np.array([-1450.9e-9, 4652.5e-9, -29404.8e-9])
    stamps, fixed, measured, worst_r = [], [], [], 0.0
    for m in field:
        t_ns = time_ns(m.header.stamp)
        if t_ns not in by_stamp:
            continue
        error, r_km, _ = satellite.sgp4(whole, fraction + t_ns * 1e-9 / 86400.0)
        assert error == 0
        r = np.multiply(r_km, 1e3)
        p = by_stamp[t_ns].pose.pose.position
        worst_r = max(worst_r, np.linalg.norm(np.subtract((p.x, p.y, p.z), r)) / np.linalg.norm(r))
        to_fixed = Rotation.from_euler('z', -(theta0 + 7.2921150e-5 * t_ns * 1e-9))
        body_to_fixed = to_fixed * Rotation.from_quat(odom_arrays([by_stamp[t_ns]])[1][0])
        stamps.append(t_ns * 1e-9)
        fixed.append(to_fixed.apply((p.x, p.y, p.z)))
        measured.append(body_to_fixed.apply(vector_array(m.magnetic_field)))   # Earth-fixed, T
    assert worst_r < 1e-10 and len(stamps) >= 20, (worst_r, len(stamps))
    fixed, measured = np.array(fixed), np.array(measured)
    if model == 'dipole':
        rn = np.linalg.norm(fixed, axis=1)[:, None]
        expected = (6371.2e3 / rn) ** 3 * (3 * (fixed @ d)[:, None] / rn ** 2 * fixed - d)
        assert np.max(np.linalg.norm(measured - expected, axis=1)
                      / np.linalg.norm(expected, axis=1)) < 1e-12
    else:
        from test_igrf_field import library_field
        start = datetime(2019, 12, 9, 20, 42, tzinfo=timezone.utc).timestamp()
        expected = library_field(start + np.array(stamps), fixed) * 1e-9
        assert np.max(np.abs(measured - expected)) < 0.003e-9
    code, _ = proc.stop()
    assert code == 0, proc.output()
    assert 'SGP4 of the TLE of NORAD 25544' in proc.output()


def test_an_orbit_under_j2_to_j6_and_drag_over_topics(launch, probe):
    """
    orbit_zonal_degree 6 with drag: odom's position = a tight DOP853 of those equations.

    The reference integrates :func:`zonal_acceleration` (held to the J2 closed form and
    to the potential's gradient in test_zonal_orbit) plus the drag -1/2 rho |v_r| v_r / B
    written here (B = 50 kg/m^2, Vallado's table, the air turning with the Earth) from
    the elements' Kepler state at rtol 2.5e-14; 1e-10 of |r| over 400 s, where the orbit
    is 3e-5 of |r| off Kepler's and the drag has moved it about 2e-8 of |r|.
    """
    from rigid_body_dynamics.physics.environment import EARTH_RATE, ExponentialAtmosphere
    from rigid_body_dynamics.physics.environment.zonal_orbit import (EGM2008_RADIUS,
                                                                     zonal_acceleration,
                                                                     zonal_coefficients)
    from scipy.integrate import solve_ivp
    elements, ballistic = [6778137.0, 0.001, 0.9, 0.3, 0.5, 0.2], 50.0
    proc = launch(SIM, '-p', 'publish_clock:=true', '-p', f'orbit_elements:={elements}',
                  '-p', 'orbit_zonal_degree:=6', '-p', f'orbit_ballistic_coefficient:={ballistic}',
                  '-p', 'integration_rate:=10.0', '-p', 'publish_rate:=1.0',
                  '-p', 'real_time_factor:=200.0', name='zonal')
    odom = probe.subscribe(Odometry, 'odom')
    # At 200 times real time the probe may match the publisher a few hundred seconds of
    # simulated time late (seen in CI beside a CPU hog): what is compared is what arrived.
    probe.spin_until(lambda: len(odom) >= 100 and time_ns(odom[-1].header.stamp) >= 400e9,
                     30.0, '100 odom messages, the newest stamped 400 s or later')
    stamps = np.array([time_ns(m.header.stamp) * 1e-9 for m in odom])
    got = np.array([[m.pose.pose.position.x, m.pose.pose.position.y, m.pose.pose.position.z]
                    for m in odom])
    j = zonal_coefficients(6)
    r0, v0 = KeplerOrbit(elements).state(0.0)
    mu = KeplerOrbit(elements).mu
    air = ExponentialAtmosphere(EARTH_RATE)

    def rate(t, y, drag=True):
        a = np.array(zonal_acceleration(y[:3], mu, EGM2008_RADIUS, j))
        flow = y[3:] - np.cross([0.0, 0.0, EARTH_RATE], y[:3])
        if drag:
            a -= 0.5 * air.density(t, y[:3]) * np.linalg.norm(flow) * flow / ballistic
        return (*y[3:], *a)

    def reference(drag):
        found = solve_ivp(rate, (0.0, stamps[-1]), np.array(r0 + v0), method='DOP853',
                          rtol=2.5e-14, atol=1e-12, t_eval=stamps, args=(drag,))
        assert found.success
        return np.linalg.norm(got - found.y[:3].T, axis=1) / elements[0]
    assert len(stamps) >= 100, len(stamps)
    error, dragless = reference(True), reference(False)
    kepler = np.linalg.norm(got[-1] - KeplerOrbit(elements).position(stamps[-1])) / elements[0]
    assert error.max() < 1e-10 and dragless[-1] > 5e-9 and kepler > 1e-5, (
        error.max(), dragless[-1], kepler)
    code, _ = proc.stop()
    assert code == 0, proc.output()
    assert 'integrated under J2..J6 (EGM2008, DOP853), drag of B = 50 kg/m^2' in proc.output()


@pytest.mark.parametrize('args, reason', [
    (('-p', 'orbit_elements:=[7.0e6, 1.2, 0.0, 0.0, 0.0, 0.0]'), 'eccentricity'),
    (('-p', 'orbit_elements:=[6.0e6, 0.0, 0.0, 0.0, 0.0, 0.0]'), 'perigee radius'),
    (('-p', 'orbit_elements:=[7.0e6, 0.0, 0.0]'), 'orbit_elements must have 6 numbers'),
    (('-p', 'gravity_gradient:=true'),
     'gravity_gradient needs an orbit, orbit_elements or orbit_tle'),
    (('-p', 'magnetic_field_model:=dipole'), 'magnetic_field_model dipole needs an orbit'),
    (('-p', 'magnetometer_rate:=10.0'), 'magnetometer_rate > 0 needs a field'),
    (('-p', 'orbit_elements:=[7.0e6, 0.0, 0.0, 0.0, 0.0, 0.0]', '-p',
      'magnetic_field_model:=dipole', '-p', 'magnetorquer_max_dipole:=[0.1, -0.1, 0.1]'),
     'magnetorquer_max_dipole must be >= 0'),
    (('-p', 'magnetic_field_model:=wmm'), 'magnetic_field_model must be one of'),
    (('-p', 'orbit_elements:=[7.0e6, 0.0, 0.0, 0.0, 0.0, 0.0]', '-p',
      'magnetic_field_model:=igrf'), 'magnetic_field_model igrf needs epoch'),
    (('-p', 'orbit_elements:=[7.0e6, 0.0, 0.0, 0.0, 0.0, 0.0]', '-p',
      'magnetic_field_model:=igrf', '-p', 'epoch:=2031-01-01T00:00:00Z'), 'IGRF-14 covers'),
    (('-p', f'orbit_tle:={list(ISS)}', '-p', 'orbit_elements:=[7.0e6, 0.0, 0.0, 0.0, 0.0, 0.0]'),
     'orbit_elements and orbit_tle are both set'),
    (('-p', f'orbit_tle:={[ISS[0], ISS[0]]}'), 'orbit_tle: line 2 must be'),
    (('-p', "orbit_tle:=['1 25544U']"), 'orbit_tle must be a list of 2 strings'),
    (('-p', 'orbit_elements:=[7.0e6, 0.0, 0.0, 0.0, 0.0, 0.0]', '-p', 'orbit_zonal_degree:=1'),
     'orbit_zonal_degree must be 0 (Kepler) or an integer 2..6'),
    (('-p', f'orbit_tle:={list(ISS)}', '-p', 'orbit_zonal_degree:=2'),
     'orbit_zonal_degree 2 needs orbit_elements'),
    (('-p', 'orbit_elements:=[7.0e6, 0.0, 0.0, 0.0, 0.0, 0.0]', '-p', 'solar_pressure:=true'),
     'solar_pressure needs epoch (where the Sun is) and facets (the surface it pushes on)'),
    (('-p', 'solar_pressure:=true', '-p', 'epoch:=2026-03-20T12:00:00Z', '-p',
      'facets:=[0.01, 0.0, 0.0, 1.0, 0.05, 0.0, 0.0, 0.3, 0.2, 2.2]'),
     'solar_pressure needs an orbit (orbit_elements or orbit_tle)'),
    (('-p', 'facets:=[0.01, 0.0, 0.0, 1.0, 0.05, 0.0, 0.0]'),
     'facets must hold 10 numbers per facet'),
    (('-p', 'drag:=true'), 'drag needs an orbit (orbit_elements or orbit_tle) and facets'),
    (('-p', 'drag:=true', '-p', 'atmosphere_model:=msis'), 'atmosphere_model must be one of'),
    (('-p', 'orbit_elements:=[7.0e6, 0.0, 0.0, 0.0, 0.0, 0.0]', '-p', 'drag:=true', '-p',
      'facets:=[0.01, 0.0, 0.0, 1.0, 0.05, 0.0, 0.0, 0.3, 0.2, 2.2]', '-p',
      'atmosphere_model:=nrlmsis'), 'atmosphere_model nrlmsis needs epoch'),
    (('-p', 'solar_flux_f107:=0.0'), 'solar_flux_f107'),
    (('-p', 'orbit_elements:=[7.0e6, 0.0, 0.0, 0.0, 0.0, 0.0]', '-p',
      'orbit_ballistic_coefficient:=50.0'),
     'orbit_ballistic_coefficient needs orbit_zonal_degree'),
    (('-p', f'orbit_tle:={list(ISS)}', '-p', 'orbit_ballistic_coefficient:=50.0'),
     "SGP4 flies the TLE's own drag"),
    (('-p', 'orbit_elements:=[7.0e6, 0.0, 0.0, 0.0, 0.0, 0.0]', '-p', 'orbit_zonal_degree:=2',
      '-p', 'orbit_ballistic_coefficient:=50.0', '-p', 'atmosphere_model:=nrlmsis'),
     'atmosphere_model nrlmsis needs epoch'),
])
def test_bad_environment_parameters_are_refused_at_start_naming_them(launch, args, reason):
    proc = launch(SIM, *args, name='bad_environment')
    assert proc.wait(20.0) == 1
    assert reason in proc.output(), proc.output()


def test_libration_and_the_jacobi_integral_over_topics(launch, probe):
    """
    Check the analyzer's orbit status on a librating satellite: frequencies and Jacobi drift.

    A 500 km circular orbit, I = (2, 3, 1.2) kg m^2 (Lagrange region) 1-2 mrad off LVLH,
    turning with it, the gravity gradient alone, 1 s steps at 5000x (as fast as possible
    flooded the analyzer's best-effort input under a CPU hog: lost samples cost accuracy);
    attitude_analyzer with gravity_gradient over a 60000 s window (10.6 orbits) of 0.1 Hz
    odom: pitch and both roll-yaw libration frequencies within 1e-4 of the theory's
    (measured 1.6e-5 to 6.9e-5; over 20000 s they were 2e-4 to 8.7e-4), the stability
    region Lagrange and the Jacobi integral's drift under 1e-12 (measured 6e-15).
    """
    from rigid_body_dynamics.physics.environment import circular_elements, lvlh_quaternion
    from rigid_body_dynamics.physics.environment.libration import libration_modes
    elements = circular_elements(500e3, inclination=1.0, raan=0.3)
    orbit = KeplerOrbit(elements)
    r, v = orbit.state(0.0)
    lvlh = Rotation.from_quat(lvlh_quaternion(r, v))
    start = lvlh * Rotation.from_rotvec([0.001, 0.002, -0.0015])
    omega = start.inv().apply(lvlh.apply([0.0, -orbit.n, 0.0]))
    moments = [2.0, 3.0, 1.2]
    launch(SIM, '-p', 'publish_clock:=true', '-p', f'inertia:={moments}',
           '-p', f'orbit_elements:={elements}', '-p', 'gravity_gradient:=true',
           '-p', f'initial_orientation:={start.as_quat().tolist()}',
           '-p', f'initial_angular_velocity:={omega.tolist()}', '-p', 'integration_rate:=1.0',
           '-p', 'publish_rate:=0.1', '-p', 'real_time_factor:=5000.0',
           '-p', 'publish_imu:=false',
           name='sim')
    launch('rigid_body_dynamics.nodes.analyzer', '-p', 'gravity_gradient:=true',
           '-p', 'window:=60000.0', '-p', 'max_gap:=100.0', '-p', 'reset_jump:=100.0',
           name='analyzer')
    probe.subscribe(DiagnosticArray, '/diagnostics')
    theory = libration_modes(moments, orbit.n)

    odom = probe.subscribe(Odometry, 'odom')
    probe.spin_until(lambda: odom and time_ns(odom[-1].header.stamp) >= 60000 * 10 ** 9, 180.0,
                     '60000 s simulated')
    seen = len(probe.messages['/diagnostics'])
    probe.spin_until(lambda: any(s.name == 'attitude_analyzer: orbit' for a in
                                 probe.messages['/diagnostics'][seen:] for s in a.status),
                     30.0, 'an orbit status over the full window')
    level, message, values = probe.newest_status('attitude_analyzer: orbit')
    assert level == DiagnosticStatus.OK and 'stable (Lagrange region)' in message, message
    for key, expected in (('pitch libration frequency', theory.pitch),
                          ('roll-yaw libration frequency, slow', theory.roll_yaw[0]),
                          ('roll-yaw libration frequency, fast', theory.roll_yaw[1])):
        assert float(values[f'{key}, theory (rad/s)']) == pytest.approx(expected, rel=1e-9)
        assert float(values[f'{key}, measured (rad/s)']) == pytest.approx(expected, rel=1e-4)
    assert float(values['Jacobi integral drift (rel.)']) < 1e-12
    assert values['moments along roll, pitch, yaw (kg m^2)'] == '2 3 1.2'
