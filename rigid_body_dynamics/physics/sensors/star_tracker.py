"""
A star tracker: the body's attitude with a small random rotation about the tracker's axes.

    R_m = R R_bt exp([a]x) exp([e]x) R_bt^T,   e ~ N(0, diag(noise^2))

R is the true body -> world rotation, R_bt the tracker's orientation in the
body (``star_tracker_orientation``, as TF gives base_link -> tracker), e a
rotation vector in the tracker frame (rad, 1 sigma about its x, y, z; z is
the boresight, about which a tracker is usually several times worse) and a the
fixed misalignment (``star_tracker_misalignment``, tracker frame): an error an
estimator must live with, not in the covariance. The covariance of a reading
is about the world's fixed axes, as ROS has it: R_m R_bt diag(noise^2) R_bt^T
R_m^T.

A reading is excluded (no message; the engine counts why) when the true
boresight is within ``sun_exclusion`` (rad) of the Sun (``'sun'``), or, with
an orbit, within ``earth_exclusion`` (rad) of the Earth's limb (``'earth'``):
the Earth's disc itself always blocks the view.
"""

import math
from typing import NamedTuple

import numpy as np

from .base import check_rate, check_scalar, check_vector
from .. import quaternions as quat


class StarTrackerReading(NamedTuple):
    """
    One star tracker reading: ``q`` (x, y, z, w, body -> world, measured).

    ``covariance``: the orientation covariance (rad^2, 3 x 3 row-major, about
    the world's fixed axes).
    """

    q: tuple
    covariance: tuple


def _unit_quaternion(name, q):
    """Return q (x, y, z, w) normalised, refusing one far from unit length (naming it)."""
    q = check_vector(name, q, 'x, y, z, w', 4)
    n = math.sqrt(sum(c * c for c in q))
    if abs(n - 1.0) > 1e-6:
        raise ValueError(f'{name} must be a unit quaternion (x, y, z, w), got {list(q)!r}')
    return tuple(c / n for c in q)


def _angle(a, b):
    """Return the angle (rad) between unit vectors a and b, accurate near 0 and pi."""
    cross = np.cross(a, b)
    return math.atan2(float(np.linalg.norm(cross)), float(np.dot(a, b)))


class StarTracker:
    """
    A star tracker at ``rate`` Hz (see the module docstring for the parameters).

    ``noise`` (3, rad, tracker axes), ``orientation`` (x, y, z, w, tracker in
    the body), ``misalignment`` (3, rad, tracker frame), ``sun_exclusion`` and
    ``earth_exclusion`` (rad, half-angles). Bad values raise ValueError naming
    the simulator's parameter.
    """

    name = 'star_tracker'
    stream = 2

    def __init__(self, rate, noise=(0.0, 0.0, 0.0), orientation=(0.0, 0.0, 0.0, 1.0),
                 misalignment=(0.0, 0.0, 0.0), sun_exclusion=0.0, earth_exclusion=0.0):
        self.rate = check_rate('star_tracker_rate', rate)
        self.noise = check_vector('star_tracker_noise', noise, 'rad')
        if any(c < 0.0 or c > 1.0 for c in self.noise):
            raise ValueError(f'star_tracker_noise must be in [0, 1] rad per axis, got {noise!r}')
        self.orientation = _unit_quaternion('star_tracker_orientation', orientation)
        self.misalignment = check_vector('star_tracker_misalignment', misalignment, 'rad')
        self.sun_exclusion = check_scalar('star_tracker_sun_exclusion', sun_exclusion, 'rad',
                                          math.pi)
        self.earth_exclusion = check_scalar('star_tracker_earth_exclusion', earth_exclusion,
                                            'rad', math.pi)
        self._offset = quat.from_rotation_vector(self.misalignment)
        x, y, z, w = self.orientation
        self._conj_bt = (-x, -y, -z, w)
        self._variance = np.diag([c * c for c in self.noise])

    def start(self, rng, rate):
        """Start (nothing to draw: the misalignment is a parameter)."""

    def boresight(self, q):
        """Return the tracker's z axis, its line of sight (unit, world), at body attitude q."""
        q_t = quat.mul_components(q, self.orientation)
        return np.array(quat.rotate_components(q_t, (0.0, 0.0, 1.0)))

    def excluded(self, state, t):
        """Return why the view is blocked at ``state`` and t (s): 'sun', 'earth' or None."""
        sky, r = state.sky, state.position
        looks_at_sun = self.sun_exclusion > 0.0 and sky.sun is not None
        if not looks_at_sun and r is None:
            return None
        boresight = self.boresight(state.q)
        if looks_at_sun and _angle(boresight, sky.sun_world(t)) < self.sun_exclusion:
            return 'sun'
        if r is not None:
            nadir = -np.asarray(r, dtype=float) / float(np.linalg.norm(r))
            if _angle(boresight, nadir) < sky.planet_angular_radius(r) + self.earth_exclusion:
                return 'earth'
        return None

    def sample(self, state, t, rng):
        """Return a :class:`StarTrackerReading` of ``state`` at t (s), or why there is none."""
        e = (rng.standard_normal(3) * self.noise).tolist()      # drawn whatever the view
        why = self.excluded(state, t)
        if why is not None:
            return why
        turn = quat.mul_components(self._offset, quat.from_rotation_vector(e))
        q_t = quat.mul_components(state.q, self.orientation)
        q_m = quat.mul_components(quat.mul_components(q_t, turn), self._conj_bt)
        n = math.sqrt(sum(c * c for c in q_m))
        q_m = tuple(c / n for c in q_m)
        a = quat.matrix(q_m) @ quat.matrix(self.orientation)
        cov = a @ self._variance @ a.T
        return StarTrackerReading(q_m, tuple(cov.ravel().tolist()))
