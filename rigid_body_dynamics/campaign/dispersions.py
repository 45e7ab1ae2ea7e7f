"""
Dispersions: how each run draws a parameter's value, and the check that the value took.

Each dispersed parameter draws from a random stream of its own, seeded by the
campaign's ``seed``, the run's index and the parameter's name (and node), so a
run's values do not depend on which other runs or parameters there are, on the
order the runs go in, or on the process that runs them.

Kinds (``distribution:``):

- ``normal``: ``mean`` (default the scenario's value) plus ``sigma`` times a
  standard normal, per element.
- ``uniform``: between ``low`` and ``high``, per element.
- ``rotation``: an attitude (x, y, z, w). With ``sigma`` (rad) a small rotation
  of N(0, sigma^2) per axis applied to the scenario's attitude (a misalignment
  or an initial attitude error: q_nominal (x) exp(delta)); without it, uniform
  on the rotation group (scipy's ``Rotation.random``).
- ``direction``: a vector of the scenario's length (or ``norm``) along a
  direction uniform on the sphere.
- ``seed``: an integer in [0, 2^31 - 1] (the simulator's ``noise_seed``).
"""

import math
import zlib

import numpy as np
from scipy.spatial.transform import Rotation

from ..physics import quaternions as quat
from ..ros.parameters import ConfigurationError

#: The kinds of dispersion and the keys each takes (besides ``distribution`` and ``node``).
KINDS = {'normal': ('mean', 'sigma'), 'uniform': ('low', 'high'), 'rotation': ('sigma',),
         'direction': ('norm',), 'seed': ()}
#: The largest seed drawn (the simulator's noise_seed range).
SEED_MAX = 2 ** 31 - 1


def _vector(name, key, value, size):
    """Return ``value`` as a float array of ``size`` (a scalar is repeated for a vector)."""
    array = np.atleast_1d(np.asarray(value, dtype=float))
    if size is not None and array.size == 1 and size > 1:
        array = np.repeat(array, size)
    if not np.all(np.isfinite(array)) or (size is not None and array.size != size):
        raise ConfigurationError(f'dispersion of {name}: {key} must be {size or 1} finite '
                                 f'number(s), got {value!r}')
    return array


class Dispersion:
    """
    One parameter's dispersion: ``name``, ``spec`` (the config's mapping), ``nominal``.

    ``nominal``: the scenario's value (a number or a list), for the defaults.
    ``node``: the node it applies to, or None for every node that declares it.
    """

    def __init__(self, name, spec, nominal):
        if not isinstance(spec, dict) or spec.get('distribution') not in KINDS:
            raise ConfigurationError(f'dispersion of {name} needs distribution: one of '
                                     f'{", ".join(KINDS)}, got {spec!r}')
        self.name, self.kind = name, spec['distribution']
        self.node = spec.get('node')
        extra = sorted(set(spec) - {'distribution', 'node'} - set(KINDS[self.kind]))
        if extra:
            raise ConfigurationError(f'dispersion of {name} ({self.kind}) does not take '
                                     f'{", ".join(extra)}; it takes '
                                     f'{", ".join(KINDS[self.kind]) or "nothing more"}')
        self.vector = isinstance(nominal, (list, tuple))
        size = len(nominal) if self.vector else None
        k = self.kind
        if k == 'normal':
            if 'sigma' not in spec:
                raise ConfigurationError(f'dispersion of {name} (normal) needs sigma')
            self.mean = _vector(name, 'mean', spec.get('mean', nominal), size)
            self.sigma = _vector(name, 'sigma', spec['sigma'], size)
            if np.any(self.sigma < 0.0):
                raise ConfigurationError(f'dispersion of {name}: sigma must be >= 0')
        elif k == 'uniform':
            if 'low' not in spec or 'high' not in spec:
                raise ConfigurationError(f'dispersion of {name} (uniform) needs low and high')
            self.low = _vector(name, 'low', spec['low'], size)
            self.high = _vector(name, 'high', spec['high'], size)
            if np.any(self.high < self.low):
                raise ConfigurationError(f'dispersion of {name}: high must be >= low')
        elif k == 'rotation':
            if size != 4:
                raise ConfigurationError(f'dispersion of {name}: rotation is for a quaternion '
                                         'parameter (x, y, z, w)')
            self.nominal = np.asarray(quat.normalize(np.asarray(nominal, dtype=float)))
            self.sigma = None if 'sigma' not in spec else float(
                _vector(name, 'sigma', spec['sigma'], 1)[0])
        elif k == 'direction':
            if size != 3:
                raise ConfigurationError(f'dispersion of {name}: direction is for a 3-vector')
            self.norm = float(_vector(name, 'norm', spec.get('norm', math.sqrt(
                sum(float(c) ** 2 for c in nominal))), 1)[0])
        elif self.vector or not isinstance(nominal, int) or isinstance(nominal, bool):
            raise ConfigurationError(f'dispersion of {name}: seed is for an integer parameter')

    def stream(self, seed, run):
        """Return the generator of run ``run``'s draw (numpy's PCG64 from a SeedSequence)."""
        key = zlib.crc32(f'{self.node or ""}/{self.name}'.encode())
        return np.random.default_rng(np.random.SeedSequence([int(seed), int(run), key]))

    def draw(self, seed, run):
        """Return run ``run``'s value: a float, an int (seed) or a list of floats."""
        rng = self.stream(seed, run)
        k = self.kind
        if k == 'seed':
            return int(rng.integers(0, SEED_MAX, endpoint=True))
        if k == 'normal':
            value = self.mean + self.sigma * rng.standard_normal(self.mean.size)
        elif k == 'uniform':
            value = rng.uniform(self.low, self.high)
        elif k == 'rotation':
            if self.sigma is None:
                value = Rotation.random(random_state=rng).as_quat()
            else:
                turn = quat.from_rotation_vector(rng.standard_normal(3) * self.sigma)
                value = np.asarray(quat.normalize(quat.multiply(self.nominal, np.array(turn))))
        else:
            v = rng.standard_normal(3)
            value = self.norm * v / np.linalg.norm(v)
        value = [float(c) for c in np.atleast_1d(value)]
        return value if self.vector else value[0]


def same_value(drawn, applied, rtol=1e-12):
    """
    Whether the engine's value ``applied`` is the ``drawn`` one.

    Integers exactly; floats to ``rtol`` of the largest element (the engine
    normalises a quaternion, which can move its last bits).
    """
    if isinstance(drawn, int):
        return isinstance(applied, (int, np.integer)) and int(applied) == drawn
    a = np.atleast_1d(np.asarray(applied, dtype=float))
    d = np.atleast_1d(np.asarray(drawn, dtype=float))
    scale = float(np.max(np.abs(d))) if d.size else 0.0
    return a.shape == d.shape and bool(np.all(np.abs(a - d) <= rtol * scale))
