"""
A vector function of time interpolated on segments by Chebyshev polynomials (no ROS).

Used where a quantity along the orbit is dear to evaluate and smooth in time (the
IGRF field, the integrated orbit, the NRLMSIS density) but is asked for at every
integrator stage: the time axis is cut into segments of ``span`` s; on segment
k = floor(t / span) the components (three, or ``components``) are each a polynomial
of degree ``order`` in
x = (t - middle) / half-width, interpolating the function at the Chebyshev points
of the first kind (Trefethen, Approximation Theory and Approximation Practice,
chapter 4). A segment is built the first time it is asked for and kept (the last
``keep`` of them); an evaluation is an unrolled Horner sum (a few microseconds), and
:meth:`ChebyshevSegments.values` is the same sum over an array of times (numpy, the
same operations in the same order: equal to the bit).
"""

import math

import numpy as np

from ..dynamics.rk_kernels import compile_source


class ChebyshevSegments:
    """
    ``sample(middle, times)`` -> (order + 1, n) values interpolated on segments of ``span`` s.

    ``sample`` gets the segment's middle (s) and its order + 1 Chebyshev nodes
    ``times`` (s, an array) and returns the function's n = ``components`` components
    there (any unit: the interpolant has the same). :attr:`value` (t s) is the
    interpolant at t, an n-tuple, or a float when n is 1 (compiled: what a stage
    calls). ``keep``: segments kept before the cache is emptied. ``origin`` (s): a
    time where segments meet (segment k is origin + [k, k + 1) span), so that a step
    of the function there falls between two.
    """

    def __init__(self, sample, span, order, keep=16, name='chebyshev', components=3,
                 origin=0.0):
        if not (math.isfinite(span) and span > 0.0):
            raise ValueError(f'the segment length must be positive and finite, got {span!r} s')
        self.sample, self.span, self.order, self.keep = sample, float(span), int(order), keep
        self.origin = math.fmod(float(origin), self.span)
        self._nodes = np.cos(math.pi * (np.arange(order + 1) + 0.5) / (order + 1))
        # the monomials in x of the interpolant at the nodes: coefficients = fit @ values
        self._fit = np.linalg.inv(np.vander(self._nodes, order + 1, increasing=True))
        self._segments = {}
        self.components = int(components)
        self.value = compile_source(horner_source(order, components),
                                    f'<{name} horner {order}>', {
            'segments': self._segments, 'build': self.segment, 'floor': math.floor,
            'inverse_span': 1.0 / self.span, 'origin': self.origin})

    def segment(self, k):
        """
        Return segment k: (middle s, 1 / half-width 1/s, then the coefficients).

        The coefficients: per component the order + 1 monomial coefficients in
        x = (t - middle) / half-width (x^0 first).
        """
        found = self._segments.get(k)
        if found is None:
            half = 0.5 * self.span
            middle = self.origin + (k + 0.5) * self.span
            values = np.asarray(self.sample(middle, middle + half * self._nodes), float)
            values = values.reshape(self.order + 1, -1)
            coefficients = (self._fit @ values).T               # (n, order + 1), x^0 first
            if len(self._segments) > self.keep:
                self._segments.clear()
            found = self._segments[k] = (middle, 1.0 / half, *coefficients.ravel().tolist())
        return found

    def values(self, times):
        """
        Return the interpolant at ``times`` (s, an array): an (N, n) array.

        :attr:`value` at each time, to the bit (the same Horner sum, by numpy).
        """
        times = np.asarray(times, float)
        k = np.floor((times - self.origin) * (1.0 / self.span))
        out = np.empty((times.size, self.components))
        for key in (k[0],) if k.min() == k.max() else np.unique(k):
            mask = slice(None) if k.min() == k.max() else k == key
            found = self.segment(int(key))
            coefficients = np.array(found[2:]).reshape(self.components, self.order + 1, 1)
            x = (times[mask] - found[0]) * found[1]
            total = np.repeat(coefficients[:, self.order], x.size, axis=1)   # (n, M)
            for j in range(self.order - 1, -1, -1):
                total *= x
                total += coefficients[:, j]
            out[mask] = total.T
        return out


def horner_source(order, components=3):
    """
    Source of ``value(t)``: the segment of t's interpolant by Horner's rule, unrolled.

    Its names: ``segments`` (the dict of segments), ``build`` (makes a missing one),
    ``floor``, ``inverse_span`` (1 / segment length, 1/s) and ``origin`` (s, where
    segments meet). It returns a ``components``-tuple, or a float for one component.
    """
    letters = 'abcdefgh'[:components]
    names = [f'{c}{j}' for c in letters for j in range(order + 1)]

    def horner(c):
        text = f'{c}{order}'
        for j in range(order - 1, -1, -1):
            text = f'{c}{j} + x * ({text})'
        return text
    return '\n'.join([
        'def value(t):',
        '    k = floor((t - origin) * inverse_span)',
        '    found = segments.get(k)',
        '    if found is None:',
        '        found = build(k)',
        f'    middle, inverse_half, {", ".join(names)} = found',
        '    x = (t - middle) * inverse_half',
        '    return ' + (horner('a') if components == 1 else
                         '(' + ',\n            '.join(horner(c) for c in letters) + ')'),
        ''])
