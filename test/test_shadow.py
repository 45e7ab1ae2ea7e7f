"""
The conical shadow's sunlit fraction against a direct integration of the two discs' overlap.

The reference places the Sun's disc (angular radius a) and the planet's (b) at
centres c apart in a plane and integrates the length of their common chord
across the Sun's disc with scipy's quad (split where the circles cross), not
by the closed form's lens area. Geometries are drawn around the shadow's edge for a 400 km
orbit (a ~ 4.65e-3 rad, b ~ 1.22 rad) and for made-up radii where the planet
is smaller than the Sun (the annular case). Across the low orbit's penumbra the
closed form and the integration differ by 5.8e-9 at most (the planet's disc,
1.2 rad across, against the Sun's 0.005: the chords' kinks are sharp for quad),
in the annular case by 6.3e-13.
"""

import math

import numpy as np
import pytest
from rigid_body_dynamics.physics.environment import R_EARTH
from rigid_body_dynamics.physics.environment.shadow import conical_shadow_fraction, R_SUN
from scipy.integrate import quad
from scipy.optimize import brentq

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
    assert worst < 2e-8, worst           # delivered 5.8e-9 (the target was 1e-6)


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
