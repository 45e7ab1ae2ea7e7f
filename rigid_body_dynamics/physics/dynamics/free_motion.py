"""
Exact torque-free motion of a rigid body at any time (Jacobi elliptic functions).

The body momentum m = I omega moves on the polhode; the attitude follows by
rotating about the fixed world-frame angular momentum L_w. For an asymmetric
body (I1 < I2 < I3 after sorting) with G = |m|, 2T = sum m_i^2 / I_i:

* invariants without cancellation:
  P = G^2 - 2 T I1, Q = 2 T I3 - G^2, S = G^2 - 2 T I2 (S > 0: polhode
  circles the max-inertia axis, family A; S < 0: the min-inertia axis,
  family B; S = 0: the separatrix L^2 = 2 T I2);
* m(t) = (a1 cn u, a2 sn u, a3 dn u) (A) or (a1 dn u, a2 sn u, a3 cn u) (B),
  u = lambda t + u0;
* q(t) = q0 (x) a(m0)* (x) z(psi(t)) (x) a(m(t)), where a(m) turns m onto the
  circled axis and psi is the angle about it, integrated in closed form with
  the incomplete elliptic integral of the third kind (Carlson R_F, R_J).

The recipe is re-derived here after Celledoni, Fasso, Safstrom & Zanna (SIAM
J. Sci. Comput. 30, 2008), with the corrections of its erratum (sign of
lambda, the value of n in Pi, the sign of the arctan term); the formulas are
in the functions below, and tests check them against DOP853 at rtol 1e-13.
Axisymmetric and spherical bodies use their elementary closed forms.

Near the separatrix (|S| / G^2 < SEPARATRIX_THRESHOLD) scipy's ``ellipj``,
which takes the parameter k^2 -> 1, loses accuracy (4e-8 rad after 20 s at
S/G^2 = 4e-10). There :class:`FreeFlow` marks itself ``near_separatrix`` and
evaluates the motion with scipy's DOP853 at rtol 1e-13 instead; the stepping
integrators use RK4 sub-steps for such a step (see ``integrators``).

Frames and units: moments kg m^2 in the order of the body principal axes;
m (kg m^2/s) and omega (rad/s) in the principal body frame; q (x, y, z, w)
body -> world; t in s from the state given.
"""

from dataclasses import dataclass
import math

import numpy as np
from scipy.integrate import solve_ivp
from scipy.special import ellipj, ellipkinc, ellipkm1, elliprf, elliprj

from .equations import state_rhs
from .. import quaternions
from ..inertia import as_inertia, AxisPermutation, EQUAL_MOMENT_RTOL

#: |S| / G^2 below which the elliptic solution is replaced by DOP853 / RK4.
SEPARATRIX_THRESHOLD = 1e-8


class _Math:
    """Elementary functions for one float: the per-step hot path."""

    sin, cos, sqrt, atan2 = math.sin, math.cos, math.sqrt, math.atan2
    nearest = staticmethod(round)

    @staticmethod
    def special(f, *args):
        return float(f(*args))

    @staticmethod
    def ellipj(u, m):
        sn, cn, dn, ph = ellipj(u, m)
        return float(sn), float(cn), float(dn), float(ph)


class _Numpy:
    """The same functions on arrays of times."""

    sin, cos, sqrt, atan2, nearest = np.sin, np.cos, np.sqrt, np.arctan2, np.round

    @staticmethod
    def special(f, *args):
        return f(*args)

    ellipj = staticmethod(ellipj)


def _xp(t):
    return _Math if isinstance(t, float) else _Numpy


_mul = quaternions.mul_components


@dataclass(slots=True)
class PolhodeParameters:
    """
    Elliptic-function description of one torque-free motion (asymmetric body).

    All quantities refer to the frame with ascending moments I1 < I2 < I3.
    ``family`` is 'A' (polhode circles the max-inertia axis, S > 0), 'B'
    (circles the min-inertia axis, S < 0) or 'separatrix' (S = 0 to within
    rounding). ``k2``/``kp2`` are the modulus squared and its complement,
    ``lam`` (1/s) the rate of the elliptic argument u, ``K`` the complete
    integral K(k2), ``alpha``, ``n``, ``c`` the constants of the angle integral
    and ``psi_coef`` (rad) its prefactor, ``psi_rate`` (rad/s) its linear rate.
    """

    moments: tuple
    G: float
    T: float
    P: float
    Q: float
    S: float
    family: str
    k2: float = math.nan
    kp2: float = math.nan
    lam: float = math.nan
    K: float = math.nan
    amplitudes: tuple = (math.nan, math.nan, math.nan)
    alpha: float = math.nan
    n: float = math.nan
    c: float = math.nan
    psi_rate: float = math.nan
    psi_coef: float = math.nan
    _pi_c: float = math.nan

    @property
    def separatrix_distance(self):
        """S / G^2: signed, dimensionless distance of the polhode from the separatrix."""
        return self.S / (self.G * self.G)

    @property
    def period(self):
        """Period of omega(t), 4 K / lambda (s)."""
        return 4.0 * self.K / self.lam

    @property
    def complete_pi(self):
        """Complete elliptic integral of the third kind Pi(n | k2), Carlson forms (DLMF 19.25)."""
        if self._pi_c != self._pi_c:  # NaN: not computed yet
            self._pi_c = float(elliprf(0.0, self.kp2, 1.0)
                               + self.n / 3.0 * elliprj(0.0, self.kp2, 1.0, 1.0 - self.n))
        return self._pi_c

    def _j_tilde(self, xp, sn, cn, dn2, r, j):
        """J~ at amplitude j pi + r from sn = sin r, cn = cos r, dn2 = 1 - k2 sn^2."""
        n, c = self.n, self.c
        cn2 = cn * cn
        pi_r = sn * xp.special(elliprf, cn2, dn2, 1.0) + n / 3.0 * sn ** 3 * xp.special(
            elliprj, cn2, dn2, 1.0, 1.0 - n * sn * sn)
        value = pi_r - (self.alpha / c) * (r + xp.atan2((c - 1.0) * sn * cn, cn2 + c * sn * sn))
        # (a numpy reduction on a float costs ~4 us a step: test a float as a float)
        if (np.any(j != 0.0) if isinstance(j, np.ndarray) else j != 0.0):
            value = value + j * (2.0 * self.complete_pi - self.alpha * math.pi / c)
        return value

    def angle_integral(self, u):
        """
        J~(u) = Pi(am u; n | k2) - (alpha / c) Theta(am u), continuous in u.

        ``psi(t) = psi_rate t +/- psi_coef (J~(u) - J~(u0))`` (+ in family A,
        - in B), where Theta is the continuous form of atan(c tan(am u)). The
        argument is reduced by multiples of 2K first (am(u + 2K) = am u + pi),
        so the Carlson forms only ever see |am| <= pi/2. Returns
        ``(J~, sn u, cn u, dn u)``; works on a float or an array of u.
        """
        xp = _xp(u)
        two_k = 2.0 * self.K
        j = xp.nearest(u / two_k)
        sn, cn, dn, ph = xp.ellipj(u - two_k * j, self.k2)
        value = self._j_tilde(xp, sn, cn, dn * dn, ph, j)
        parity = 1.0 - 2.0 * (j % 2.0)
        return value, sn * parity, cn * parity, dn

    @property
    def psi_per_period(self):
        """Rotation angle about L (rad) accumulated by the attitude over one period of omega."""
        sign = 1.0 if self.family == 'A' else -1.0
        # Over one period u advances by 4K: two reductions by 2K in angle_integral.
        jump = 2.0 * (2.0 * self.complete_pi - self.alpha * math.pi / self.c)
        return self.psi_rate * self.period + sign * self.psi_coef * jump


def polhode_parameters(sorted_moments, m):
    """
    Elliptic parameters of the torque-free motion with body momentum m.

    ``sorted_moments`` = (I1, I2, I3) ascending and pairwise distinct (kg m^2);
    ``m`` = (m1, m2, m3) body momentum in that frame (kg m^2/s), not zero.
    The sign convention of family A assumes m3 > 0 and of family B m1 > 0
    (the amplitudes are magnitudes); :class:`FreeFlow` arranges that.
    """
    i1, i2, i3 = sorted_moments
    m1, m2, m3 = m
    d21, d31, d32 = i2 - i1, i3 - i1, i3 - i2
    g2 = m1 * m1 + m2 * m2 + m3 * m3
    g = math.sqrt(g2)
    t = 0.5 * (m1 * m1 / i1 + m2 * m2 / i2 + m3 * m3 / i3)
    p = m2 * m2 * d21 / i2 + m3 * m3 * d31 / i3
    q = m1 * m1 * d31 / i1 + m2 * m2 * d32 / i2
    s = m3 * m3 * d32 / i3 - m1 * m1 * d21 / i1
    base = {'moments': (i1, i2, i3), 'G': g, 'T': t, 'P': p, 'Q': q, 'S': s}
    if abs(s) <= 4.0 * np.finfo(float).eps * g2 or p <= 0.0 or q <= 0.0:
        return PolhodeParameters(family='separatrix' if p > 0.0 and q > 0.0 else 'principal',
                                 **base)
    coef = d31 * g / (i1 * i3)
    if s > 0.0:
        a = (math.sqrt(i1 * q / d31), math.sqrt(i2 * q / d32), math.sqrt(i3 * p / d31))
        k2 = q * d21 / (p * d32)
        kp2 = s * d31 / (p * d32)
        lam = math.sqrt(p * d32 / (i1 * i2 * i3))
        alpha = a[2] / g
        n = -i3 * d21 / (i1 * d32)
        psi_rate = g / i3
        family = 'A'
    else:
        a = (math.sqrt(i1 * q / d31), math.sqrt(i2 * p / d21), math.sqrt(i3 * p / d31))
        k2 = p * d32 / (q * d21)
        kp2 = -s * d31 / (q * d21)
        lam = math.sqrt(q * d21 / (i1 * i2 * i3))
        alpha = a[0] / g
        n = -i1 * d32 / (i3 * d21)
        psi_rate = g / i1
        family = 'B'
    return PolhodeParameters(family=family, k2=k2, kp2=kp2, lam=lam, K=float(ellipkm1(kp2)),
                             amplitudes=a, alpha=alpha, n=n, c=math.sqrt(1.0 - n),
                             psi_rate=psi_rate, psi_coef=coef / lam, **base)


class BodyShape:
    """
    Per-body constants of the exact flow: symmetry and the ascending frame.

    ``moments`` (kg m^2) are principal moments in the order of the body axes.
    Build once per body; :meth:`flow` is then cheap enough to call every step.
    """

    def __init__(self, moments):
        self.moments = tuple(float(i) for i in moments)
        i_max = max(self.moments)
        tol = EQUAL_MOMENT_RTOL * i_max
        self.axis = None
        self.kind = 'asymmetric'
        if i_max - min(self.moments) <= tol:
            self.kind = 'spherical'
        else:
            for axis in range(3):
                a, b = self.moments[(axis + 1) % 3], self.moments[(axis + 2) % 3]
                if abs(a - b) <= tol:
                    self.kind, self.axis = 'axisymmetric', axis
        if self.kind == 'asymmetric':
            self.permutation = AxisPermutation.ascending(self.moments)
            self.sorted_moments = self.permutation.sorted_moments(self.moments)

    def flow(self, q0, m0):
        """Torque-free flow from attitude q0 (x, y, z, w) and momentum m0 (principal frame)."""
        return FreeFlow(self, q0, m0)


def _principal_spin(q0, m, moments):
    """Closure for a spin about one principal axis (or rest): uniform rotation."""
    rates = [mi / ii for mi, ii in zip(m, moments)]

    axis = max(range(3), key=lambda i: abs(rates[i]))

    def state(t):
        xp = _xp(t)
        s, c = xp.sin(0.5 * rates[axis] * t), xp.cos(0.5 * rates[axis] * t)
        z = [0.0 * s, 0.0 * s, 0.0 * s, c]
        z[axis] = s
        return _mul(q0, tuple(z)), tuple(mi + 0.0 * s for mi in m)
    return state


class FreeFlow:
    """
    The torque-free motion from one state, evaluated exactly at any time.

    Construct through :meth:`BodyShape.flow`. :meth:`state` takes t (s,
    float or array) and returns ``(q, m)`` as component tuples: q (x, y, z, w)
    body -> world and m the body momentum (kg m^2/s, principal frame). Rest and
    spins about a principal axis, spherical and axisymmetric bodies use
    elementary closed forms; asymmetric bodies the elliptic solution; near the
    separatrix ``near_separatrix`` is True and DOP853 (rtol 1e-13) is used.
    """

    def __init__(self, shape, q0, m0):
        self.shape = shape
        q0 = tuple(float(c) for c in q0)
        m0 = tuple(float(c) for c in m0)
        self.q0, self.m0 = q0, m0
        self.near_separatrix = False
        moments = shape.moments
        nonzero = sum(1 for c in m0 if c != 0.0)
        if nonzero <= 1:
            self._state = _principal_spin(q0, m0, moments)
        elif shape.kind != 'asymmetric':
            self._state = self._symmetric(q0, m0)
        else:
            self._state = self._asymmetric(q0, m0)

    def state(self, t):
        """(q, m) at time t (s) after the initial state; see the class docstring."""
        return self._state(t)

    def _symmetric(self, q0, m0):
        shape = self.shape
        g = math.sqrt(sum(c * c for c in m0))
        if shape.kind == 'spherical':
            i_perp = sum(shape.moments) / 3.0
            axis, beta = 2, 0.0
        else:
            axis = shape.axis
            i_s = shape.moments[axis]
            i_perp = 0.5 * (shape.moments[(axis + 1) % 3] + shape.moments[(axis + 2) % 3])
            beta = (1.0 / i_s - 1.0 / i_perp) * m0[axis]
        lw = quaternions.rotate_components(q0, m0)
        lhat = tuple(c / g for c in lw)
        rate_l = g / i_perp
        a1, a2 = (axis + 1) % 3, (axis + 2) % 3

        def state(t):
            xp = _xp(t)
            hl = 0.5 * rate_l * t
            sl = xp.sin(hl)
            left = (lhat[0] * sl, lhat[1] * sl, lhat[2] * sl, xp.cos(hl))
            hb = 0.5 * beta * t
            sb, cb = xp.sin(hb), xp.cos(hb)
            right = [0.0 * sb, 0.0 * sb, 0.0 * sb, cb]
            right[axis] = sb
            q = _mul(_mul(left, q0), tuple(right))
            # m(t) = Rot(e_axis, -beta t) m0
            ca, sa = xp.cos(beta * t), xp.sin(beta * t)
            m = [0.0, 0.0, 0.0]
            m[axis] = m0[axis] + 0.0 * sa
            m[a1] = ca * m0[a1] + sa * m0[a2]
            m[a2] = -sa * m0[a1] + ca * m0[a2]
            return q, tuple(m)
        return state

    def _asymmetric(self, q0, m0):
        perm = self.shape.permutation
        ms = perm.to_sorted(m0)
        par = polhode_parameters(self.shape.sorted_moments, ms)
        self.parameters = par
        if par.family in ('separatrix', 'principal') or \
                abs(par.S) < SEPARATRIX_THRESHOLD * par.G * par.G:
            self.near_separatrix = True
            return self._numerical(q0, m0)
        # Right factor f takes the working frame (sorted, with the dn
        # component positive) to the body frame: q_work = q (x) f.
        f = perm.quaternion
        m1, m2, m3 = ms
        if par.family == 'A' and m3 < 0.0:
            f = _mul(f, (1.0, 0.0, 0.0, 0.0))
            m2, m3 = -m2, -m3
        elif par.family == 'B' and m1 < 0.0:
            f = _mul(f, (0.0, 0.0, 1.0, 0.0))
            m1, m2 = -m1, -m2
        fc = (-f[0], -f[1], -f[2], f[3])
        a1, a2, a3 = par.amplitudes
        g = par.G
        if par.family == 'A':
            phi0 = math.atan2(m2 / a2, m1 / a1)
        else:
            phi0 = math.atan2(m2 / a2, m3 / a3)
        u0 = float(ellipkinc(phi0, par.k2))
        # J~ at u0 through ellipj, as at every later time: psi(0) = 0 exactly
        # even where the round trip am(F(phi0)) loses digits (k2 -> 1).
        j0 = par.angle_integral(u0)[0]
        base = _mul(_mul(q0, f), _conj(_align(par.family, (m1, m2, m3), g, _Math)))
        lam, family = par.lam, par.family
        sign = 1.0 if family == 'A' else -1.0

        def state(t):
            xp = _xp(t)
            jt, sn, cn, dn = par.angle_integral(lam * t + u0)
            psi = par.psi_rate * t + sign * par.psi_coef * (jt - j0)
            hs, hc = xp.sin(0.5 * psi), xp.cos(0.5 * psi)
            if family == 'A':
                mw = (a1 * cn, a2 * sn, a3 * dn)
                z = (0.0 * hs, 0.0 * hs, hs, hc)
            else:
                mw = (a1 * dn, a2 * sn, a3 * cn)
                z = (hs, 0.0 * hs, 0.0 * hs, hc)
            q = _mul(_mul(_mul(base, z), _align(family, mw, g, xp)), fc)
            # Body-frame momentum: the working-frame components rotated by f.
            return q, quaternions.rotate_components(f, mw)
        return state

    def _numerical(self, q0, m0):
        moments = self.shape.moments
        y0 = np.concatenate([np.divide(m0, moments), q0])
        scale = max(math.sqrt(sum(c * c for c in m0)) / min(moments), 1e-300)
        atol = np.array([1e-13 * scale] * 3 + [1e-13] * 4)
        solutions = []

        def solve(t_end):
            sol = solve_ivp(lambda _t, y: state_rhs(moments, y), (0.0, t_end), y0,
                            method='DOP853', rtol=1e-13, atol=atol, dense_output=True)
            solutions[:] = [(t_end, sol.sol)]

        def state(t):
            ta = np.asarray(t, dtype=float)
            t_end = float(np.max(np.abs(ta))) if ta.size else 0.0
            if t_end == 0.0:
                return q0, m0
            if not solutions or solutions[0][0] < t_end:
                solve(t_end * (1.0 if np.all(ta >= 0) else -1.0))
            y = solutions[0][1](ta)
            qn = quaternions.normalize(np.moveaxis(y[3:7], 0, -1))
            q = tuple(qn[..., i] for i in range(4))
            m = tuple(y[i] * moments[i] for i in range(3))
            return q, m
        return state


def _conj(q):
    return (-q[0], -q[1], -q[2], q[3])


def _align(family, m, g, xp):
    """
    Minimal rotation a(m) taking m / |m| onto e3 (family A) or e1 (family B).

    The dn component (m3 in A, m1 in B) is positive, so G + m_i has no
    cancellation.
    """
    m1, m2, m3 = m
    if family == 'A':
        d = xp.sqrt(2.0 * g * (g + m3))
        return (m2 / d, -m1 / d, 0.0 * d, xp.sqrt((g + m3) / (2.0 * g)))
    d = xp.sqrt(2.0 * g * (g + m1))
    return (0.0 * d, m3 / d, -m2 / d, xp.sqrt((g + m1) / (2.0 * g)))


class FreeRigidBody:
    """
    Exact torque-free motion of a rigid body, at any time.

    ``inertia``: an :class:`~rigid_body_dynamics.physics.inertia.Inertia` or
    three principal moments (kg m^2). ``omega0``: initial angular velocity
    (rad/s) in the body frame of ``inertia``. ``q0``: initial attitude
    (x, y, z, w), body -> world.
    """

    def __init__(self, inertia, omega0, q0=(0.0, 0.0, 0.0, 1.0)):
        self.inertia = as_inertia(inertia)
        omega0 = np.asarray(omega0, dtype=float)
        q0 = np.asarray(q0, dtype=float)
        if omega0.shape != (3,) or not np.all(np.isfinite(omega0)):
            raise ValueError(f'omega0 must be 3 finite numbers, got {omega0.tolist()}')
        if q0.shape != (4,) or not np.all(np.isfinite(q0)) or np.linalg.norm(q0) == 0.0:
            raise ValueError('q0 must be 4 finite numbers (x, y, z, w), not all zero, '
                             f'got {q0.tolist()}')
        self.omega0 = omega0
        self.q0 = q0 / np.linalg.norm(q0)
        moments = self.inertia.moments
        w_p = self.inertia.to_principal(omega0)
        q_p = self.inertia.attitude_to_principal(self.q0)
        self.shape = BodyShape(moments)
        self.flow = self.shape.flow(q_p, moments * w_p)

    def state_at(self, t):
        """
        Attitude and angular velocity at time(s) t (s) after the initial state.

        Returns ``(q, omega)``: shapes (4,) and (3,) for a scalar t, (N, 4) and
        (N, 3) for an array of N times. q (x, y, z, w) body -> world; omega in
        the body frame (rad/s).
        """
        scalar = np.ndim(t) == 0
        ta = np.atleast_1d(np.asarray(t, dtype=float))
        q, m = self.flow.state(ta)
        q = np.stack(np.broadcast_arrays(*q), axis=-1)
        w = np.stack(np.broadcast_arrays(*m), axis=-1) / self.inertia.moments
        q = quaternions.normalize(self.inertia.attitude_to_body(q))
        w = self.inertia.to_body(w)
        return (q[0], w[0]) if scalar else (q, w)
