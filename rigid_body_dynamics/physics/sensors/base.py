"""
The sensor protocol (no ROS): what a sensor is given, and what it returns.

A sensor is an object with

- ``name``: the kind of its readings (``'gyro'``, ``'magnetometer'``,
  ``'star_tracker'``, ``'sun_sensor'``); a node publishes a reading by this
  name, from one table;
- ``rate`` (Hz): samples per simulated second;
- ``stream``: its random stream's second seed word (the generator is
  ``numpy.random.default_rng([seed, stream])``; the gyro's is None, the seed
  alone, as before the protocol), so turning one sensor on leaves every other
  sensor's noise unchanged;
- ``start(rng)``: back to the sensor's state at time 0 (draws the turn-on errors,
  if any); called whenever the body starts or is reset;
- ``sample(state, t, rng)``: one reading of the :class:`BodyTruth` ``state`` at
  simulated time t (s), drawing its noise from ``rng``; a NamedTuple of the
  sensor's values, or a string that says why there is no reading now (e.g.
  ``'sun'``: the Sun is in the star tracker's exclusion cone). The noise is drawn
  whether or not the reading is excluded, so an exclusion does not shift the
  noise of the readings after it.

The engine (:class:`~rigid_body_dynamics.engine.body.BodySimulation`) samples
every sensor on one tick schedule and counts the readings and the exclusions
by reason; a new sensor is one file here and one row in a node's publisher
table.
"""

import math
from typing import NamedTuple

import numpy as np

from ..environment.orbit import R_EARTH
from ..environment.shadow import SHADOW_MODELS, sunlit_fraction


class Sky:
    """
    What the sensors see besides the body: the field, the Sun and the planet.

    ``field``: a :class:`~..environment.magnetic_field.DipoleField` (None =
    none); ``sun``: a :class:`~..environment.sun.Sun` (None = none);
    ``planet_radius`` (m) for eclipses and the Earth's disc; ``shadow``: one of
    :data:`SHADOW_MODELS` (ValueError naming ``shadow_model`` otherwise).
    """

    def __init__(self, field=None, sun=None, planet_radius=R_EARTH, shadow='cylindrical'):
        if shadow not in SHADOW_MODELS:
            raise ValueError(f'shadow_model must be one of {", ".join(SHADOW_MODELS)}, '
                             f'got {shadow!r}')
        self.field, self.sun, self.planet_radius = field, sun, float(planet_radius)
        self.shadow = shadow

    def field_world(self, t, r):
        """Return the magnetic field (T, world) at time t (s) and position r (m, world)."""
        return self.field.world(t, r)

    def sun_world(self, t):
        """Return the unit vector to the Sun (world) at time t (s)."""
        return self.sun.direction(t)

    def light(self, t, r):
        """
        Return the fraction of the Sun's disc seen from r (m, world; None = no orbit) at t (s).

        1 in full sunlight (and without an orbit), 0 in umbra; with the cylindrical
        shadow nothing between, with the conical one the penumbra's fraction.
        """
        if r is None:
            return 1.0
        return sunlit_fraction(r, self.sun.position(t), self.planet_radius, self.shadow)

    def planet_angular_radius(self, r):
        """Return the angular radius (rad) of the planet's disc seen from r (m, world)."""
        distance = math.sqrt(r[0] * r[0] + r[1] * r[1] + r[2] * r[2])
        return math.asin(min(1.0, self.planet_radius / distance))


class BodyTruth(NamedTuple):
    """
    The true state a sensor reads, in the user's body frame.

    ``q`` (x, y, z, w: body -> world), ``omega`` (rad/s, body), ``position`` r
    (m, world; None without an orbit) and the :class:`Sky`.
    """

    q: tuple
    omega: tuple
    position: object
    sky: Sky


def stream_rng(seed, stream):
    """Return the seeded generator of one sensor: ``[seed, stream]``, or ``seed`` for None."""
    return np.random.default_rng(int(seed) if stream is None else [int(seed), int(stream)])


def check_rate(name, rate):
    """Return ``rate`` (Hz) as a float if it is finite and > 0; else ValueError naming it."""
    rate = float(rate)
    if not (math.isfinite(rate) and rate > 0.0):
        raise ValueError(f'{name} must be a finite number > 0 (Hz), got {rate!r}')
    return rate


def check_vector(name, value, unit, count=3):
    """Return ``value`` as a tuple of ``count`` finite floats; else ValueError naming it."""
    try:
        v = tuple(float(c) for c in value)
    except (TypeError, ValueError):
        v = ()
    if len(v) != count or not all(math.isfinite(c) for c in v):
        raise ValueError(f'{name} must be {count} finite numbers ({unit}), got {value!r}')
    return v


def check_scalar(name, value, unit, high=math.inf):
    """Return ``value`` as a float in [0, high]; else ValueError naming it."""
    try:
        v = float(value)
    except (TypeError, ValueError):
        v = math.nan
    if not (math.isfinite(v) and 0.0 <= v <= high):
        raise ValueError(f'{name} must be a finite number in [0, {high:g}] ({unit}), '
                         f'got {value!r}')
    return v
