"""
The conical shadow's sunlit fraction against a direct integration of the two discs' overlap.

The reference places the Sun's disc (angular radius a) and the planet's (b) at
centres c apart in a plane and integrates the length of their common chord
across the Sun's disc with scipy's quad (split where the circles cross), not
by the closed form's lens area. Geometries are drawn around the shadow's edge for a 400 km
orbit (a ~ 4.65e-3 rad, b ~ 1.22 rad) and for made-up radii where the planet
is smaller than the Sun (the annular case). Across the low orbit's penumbra the
closed form and the integration differ by 1.2e-13 at most (the closed form's
angles by atan2: by acos, as Montenbruck and Gill write them, the planet's angle
lost seven digits and the two differed by 5.8e-9), in the annular case by 6.3e-13.

The sun sensor in the conical shadow is held to the cones' own geometry: the
umbra and penumbra cones tangent to the Sun and the Earth, crossed by a circular
orbit, found by brentq (a reference that shares no code with the disc overlap).
"""

import math

import numpy as np
import pytest
from rigid_body_dynamics.engine import BodySimulation, Disturbances
from rigid_body_dynamics.physics import Inertia
from rigid_body_dynamics.physics.environment import (circular_elements, julian_date, KeplerOrbit,
                                                     R_EARTH, Sun)
from rigid_body_dynamics.physics.environment.shadow import conical_shadow_fraction, R_SUN
from rigid_body_dynamics.physics.environment.sun import sun_distance_almanac
from rigid_body_dynamics.physics.sensors import Sky, SunSensor
from scipy.integrate import quad
from scipy.optimize import brentq

#: The astronomical unit (m; IAU 2012 Resolution B2), written here apart from the package's.
AU = 149597870700.0


def _uncovered(a, b, c):
    """Return 1 - (overlap of discs a and b, c apart) / (pi a^2), by quad over the chords."""
    def chord(y):
        half_sun = math.sqrt(max(0.0, a * a - y * y))
        if abs(y) >= b:
            return 0.0
        half_planet = math.sqrt(b * b - y * y)
        return max(0.0, min(half_sun, c + half_planet) - max(-half_sun, c - half_planet))
    edge = min(a, b)
    # the chord's length has kinks where the two circles cross: found by brentq on
    # the difference of the circles' equations, x^2 + y^2 = a^2 and (x - c)^2 + y^2 = b^2
    points = []
    crossing = lambda x: (a * a - x * x) - (b * b - (x - c) ** 2)  # noqa: E731
    if crossing(-a) * crossing(a) < 0.0:
        x = brentq(crossing, -a, a, xtol=a * 1e-15)
        points = [-math.sqrt(a * a - x * x), math.sqrt(a * a - x * x)]
    overlap, _ = quad(chord, -edge, edge, points=points or None, epsabs=1e-16, epsrel=1e-13,
                      limit=200)
    return 1.0 - overlap / (math.pi * a * a)


def _geometry(a, b, c, sun_distance):
    """Return (r, sun position) with the Sun's and the planet's angular radii a, b, c apart."""
    body = R_EARTH / math.sin(b)
    sun_radius = math.sin(a) * sun_distance
    r = np.array([body, 0.0, 0.0])
    # the planet's centre seen from r is along -x; the Sun at angle c from it
    sun = r + sun_distance * np.array([-math.cos(c), math.sin(c), 0.0])
    return r, sun, sun_radius


def test_the_penumbra_of_a_low_orbit_equals_the_discs_overlap():
    rng = np.random.default_rng(7)
    a = math.asin(R_SUN / AU)
    b = math.asin(R_EARTH / (R_EARTH + 400e3))
    worst = 0.0
    for c in np.concatenate([rng.uniform(b - a, b + a, 300), [b - a * 0.999, b + a * 0.999]]):
        r, sun, sun_radius = _geometry(a, b, c, AU)
        got = conical_shadow_fraction(r, sun, R_EARTH, sun_radius)
        worst = max(worst, abs(got - _uncovered(a, b, c)))
    assert worst < 3e-13, worst          # delivered 1.2e-13 (the target was 1e-6)


def test_an_annular_eclipse_and_its_partial_phases_equal_the_discs_overlap():
    rng = np.random.default_rng(8)
    a, b = 0.01, 0.004
    for c in rng.uniform(0.0, a + b, 200):
        r, sun, sun_radius = _geometry(a, b, c, AU)
        got = conical_shadow_fraction(r, sun, R_EARTH, sun_radius)
        assert got == pytest.approx(_uncovered(a, b, c), abs=1e-11)   # delivered 6.3e-13
    r, sun, sun_radius = _geometry(a, b, 0.5 * (a - b), AU)
    assert conical_shadow_fraction(r, sun, R_EARTH, sun_radius) == pytest.approx(
        1.0 - (b / a) ** 2, abs=1e-15)


def test_full_sunlight_and_umbra_agree_with_the_cylinder_away_from_the_edge():
    sun = np.array([AU, 0.0, 0.0])
    day = np.array([R_EARTH + 400e3, 0.0, 0.0])
    night = -day
    assert conical_shadow_fraction(day, sun, R_EARTH) == 1.0
    assert conical_shadow_fraction(night, sun, R_EARTH) == 0.0
    # beside the Earth, 2 % of its radius outside the cylinder's edge: sunlit
    side = np.array([-1e6, R_EARTH * 1.02, 0.0])
    assert conical_shadow_fraction(side, sun, R_EARTH) == 1.0


def test_on_the_sunward_side_the_discs_never_meet():
    """
    Where the Sun is 90 deg or more from the Earth's centre, the fraction is 1 at once.

    At 2000 random places with r . (sun - r) >= 0 from 100 km to 40 000 km up, many just
    on the terminator's plane: the angle between the two discs' centres, computed here,
    exceeds the sum of their angular radii, so the whole Sun shows.
    """
    rng = np.random.default_rng(8)
    sun = np.array([AU, 0.0, 0.0])
    for _ in range(2000):
        u = rng.normal(size=3)
        u /= np.linalg.norm(u)
        u[0] = abs(u[0]) * rng.choice([1e-9, 1e-3, 1.0])
        r = (R_EARTH + rng.uniform(1e5, 4e7)) * u / np.linalg.norm(u)
        d = sun - r
        if r @ d < 0.0:
            continue
        apart = math.acos(np.clip(-(r @ d) / (np.linalg.norm(r) * np.linalg.norm(d)), -1, 1))
        assert apart > math.asin(R_SUN / np.linalg.norm(d)) + math.asin(R_EARTH /
                                                                        np.linalg.norm(r))
        assert conical_shadow_fraction(r, sun, R_EARTH) == 1.0


def test_the_suns_position_is_its_direction_times_its_distance():
    """sun_position_almanac (one evaluation) against the two formulas, 1950-2050, to 1e-15."""
    from rigid_body_dynamics.physics.environment.sun import (sun_direction_almanac,
                                                             sun_position_almanac)
    for jd in np.linspace(julian_date('1950-01-01T00:00:00Z'),
                          julian_date('2050-01-01T00:00:00Z'), 2001):
        expected = np.array(sun_direction_almanac(jd)) * sun_distance_almanac(jd)
        got = np.array(sun_position_almanac(jd))
        assert np.linalg.norm(got - expected) < 1e-15 * np.linalg.norm(expected), jd


def test_the_fraction_rises_monotonically_across_the_edge_in_about_eight_seconds():
    # a circular 400 km orbit in the ecliptic's plane with the Sun along x: the exit
    # from the shadow, sampled every 10 ms
    radius = R_EARTH + 400e3
    n = math.sqrt(3.986004418e14 / radius ** 3)
    sun = np.array([AU, 0.0, 0.0])
    exit_angle = math.pi + math.asin(R_EARTH / radius)       # the cylinder's edge
    t = np.arange(-30.0, 30.0, 0.01)
    u = exit_angle + n * t
    fractions = np.array([conical_shadow_fraction(
        (radius * math.cos(x), radius * math.sin(x), 0.0), sun, R_EARTH) for x in u])
    assert np.all(np.diff(fractions) >= -1e-15)
    partial = t[(fractions > 0.0) & (fractions < 1.0)]
    assert 5.0 < partial[-1] - partial[0] < 12.0


def test_a_body_inside_the_planet_is_refused():
    with pytest.raises(ValueError, match='outside the planet'):
        conical_shadow_fraction((1e6, 0.0, 0.0), (AU, 0.0, 0.0), R_EARTH)


def test_the_suns_distance_at_the_2025_perihelion_and_aphelion():
    """
    The almanac's distance against the 2025 apsides: 147 103 686 km and 152 087 738 km.

    Perihelion 2025-01-04 13:28 UTC, aphelion 2025-07-03 19:55 UTC (the Earth's centre,
    as published from JPL's ephemeris). Delivered 3.5e-5 and 6.2e-5 au; the Moon moves the
    Earth's centre up to 3e-5 au about the barycentre the formula follows.
    """
    for when, km in (('2025-01-04T13:28:00Z', 147_103_686.0),
                     ('2025-07-03T19:55:00Z', 152_087_738.0)):
        assert abs(sun_distance_almanac(julian_date(when)) - km * 1e3) < 1e-4 * AU, when
    position = Sun('2025-07-03T00:00:00Z').position(19.0 * 3600.0 + 55.0 * 60.0)
    assert abs(math.dist(position, (0.0, 0.0, 0.0)) - 152_087_738e3) < 1e-4 * AU
    assert Sun(fixed=(0.0, 0.0, 2.0)).position(5.0) == (0.0, 0.0, AU)


def _cone_crossings(radius, mu):
    """
    Return when a circular orbit in the Sun's plane meets the cones (s from the cylinder's edge).

    The Sun 1 au along +x, the body at angle u from +x: the penumbra's cone (internal
    tangents, half-angle asin((R_sun + R) / D), vertex R / sin of it towards the Sun) and the
    umbra's (external tangents, asin((R_sun - R) / D), vertex behind the Earth).
    Returns (penumbra entry, umbra entry); the exit mirrors them.
    """
    def outside(u, half_angle, apex):
        behind = -radius * math.cos(u)                     # distance behind the Earth
        cone = abs(behind - apex) * math.tan(half_angle)   # apex: behind (> 0) or sunwards
        return abs(radius * math.sin(u)) - cone
    penumbra = math.asin((R_SUN + R_EARTH) / AU)
    umbra = math.asin((R_SUN - R_EARTH) / AU)
    edge = math.pi - math.asin(R_EARTH / radius)
    n = math.sqrt(mu / radius ** 3)
    u_p = brentq(outside, edge - 0.05, edge, args=(penumbra, -R_EARTH / math.sin(penumbra)),
                 xtol=1e-15)
    u_u = brentq(outside, edge, edge + 0.05, args=(umbra, R_EARTH / math.sin(umbra)),
                 xtol=1e-15)
    return (u_p - edge) / n, (u_u - edge) / n


@pytest.mark.parametrize('min_light, model',
                         [(1.0, 'conical'), (1e-12, 'conical'), (0.5, 'cylindrical')])
def test_the_sun_sensor_reads_while_enough_of_the_sun_shows(min_light, model):
    """
    shadow_model conical: the sun sensor stops reading where the cones say, at every tick.

    A 400 km circular orbit with the Sun in its plane, readings at 10 Hz over the whole
    eclipse. With min_light 1 the last reading before the shadow and the first after it
    bracket the penumbra's cone (4.15 s before the cylinder's edge; the penumbra lasts
    8.22 s), with min_light 1e-12 the umbra's; the cylinder at its own edge. Each missing
    tick is counted as an eclipse.
    """
    radius = R_EARTH + 400e3
    orbit = KeplerOrbit(circular_elements(400e3))
    edge = (math.pi - math.asin(R_EARTH / radius)) / math.sqrt(orbit.mu / radius ** 3)
    start = edge - 20.0                                    # the body's first tick
    elements = circular_elements(400e3, anomaly=math.sqrt(orbit.mu / radius ** 3) * start)
    sun = Sun(fixed=(1.0, 0.0, 0.0))
    body = BodySimulation(Inertia((1.0, 2.0, 3.0)), 'exact', 10.0,
                          ((0.0, 0.0, 0.0, 1.0), (0.0, 0.0, 0.0)), publish_every=10,
                          sensors=[SunSensor(10.0, min_light=min_light)], seed=1,
                          disturbances=Disturbances(orbit=KeplerOrbit(elements), sun=sun,
                                                    shadow_model=model))
    out = []
    eclipse = 2.0 * math.asin(R_EARTH / radius) * math.sqrt(radius ** 3 / orbit.mu)
    with body.lock:
        for _ in range(int((eclipse + 40.0) * 10.0)):
            body.advance(0, out)
    read = np.array([s.stamp_ns for s in out if getattr(s, 'sensor', None) == 'sun_sensor'])
    read = read * 1e-9 + start
    ticks = start + 0.1 * np.arange(1, int((eclipse + 40.0) * 10.0) + 1)
    gap = np.diff(read).argmax()
    entry, leave = read[gap] - edge, read[gap + 1] - edge - eclipse  # (the exit mirrors)
    if model == 'cylindrical':
        expected = 0.0
    else:
        penumbra, umbra = _cone_crossings(radius, orbit.mu)
        expected = penumbra if min_light == 1.0 else umbra
        assert umbra - penumbra == pytest.approx(8.22, abs=0.01)
    assert entry <= expected < entry + 0.1 + 1e-6, (entry, expected)
    assert leave - 0.1 - 1e-6 < -expected <= leave, (leave, expected)
    assert body.sensor_health()['sun_sensor'] == {
        'valid': len(read), 'eclipse': len(ticks) - len(read)}


def test_the_sky_refuses_an_unknown_shadow_model_and_the_sensor_a_fraction_above_1():
    with pytest.raises(ValueError, match='shadow_model must be one of cylindrical, conical'):
        Sky(shadow='cone')
    with pytest.raises(ValueError, match='sun_sensor_min_light'):
        SunSensor(1.0, min_light=1.5)
