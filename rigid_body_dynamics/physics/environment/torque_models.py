"""
Torque models: one protocol, evaluated at every stage of the integrator (no ROS).

A torque model is an object with

    torque(t, r, q, omega, env) -> (tx, ty, tz)

returning the torque (N m) in the principal frame of the body's inertia (the
frame the integrators keep their state in) at simulated time t (s), position r
(m, world frame; None without an orbit), attitude q (x, y, z, w, principal ->
world; at RK stages q need not be exactly unit), angular velocity omega (rad/s,
principal frame), and ``env`` the quantities several models share at that
stage, computed once by :class:`~.space.SpaceEnvironment`: ``env.r_body`` (the
position in the principal frame, m) and ``env.b_body`` (the magnetic field in
the principal frame, T). A model says which of them it reads in ``needs``
(a set of 'position', 'field'). Its vectors are given in the principal frame
when it is built (``Inertia.to_principal`` turns a body-frame vector).

Adding a model is one class here (or in a file of its own) and one entry in
the simulator's parameter table: :class:`~.space.SpaceEnvironment` sums
whatever models it is given and knows none by name (as Basilisk's hub sums its
dynamic effectors). A model may also give its torque as statements for the
generated integrator stages (``stage_source(prefix)``, see :mod:`.stage_code`),
which makes it cost its arithmetic; without that it is called at every stage.

The commanded torque and the constant disturbances are held over a step (a
zero-order hold), so the integrators take them as their held body and world
torques, not through this protocol (see ``integrators``); the models here are
those that change within a step.
"""

import math


class GravityGradient:
    """
    The gravity-gradient torque 3 mu / norm(r)^5 (r_B x I r_B) of a point-mass planet.

    ``moments`` (principal, kg m^2), ``mu`` (m^3/s^2). r_B is the position in the
    principal frame (Wie, Space Vehicle Dynamics and Control, section 6.3;
    Basilisk's GravityGradientEffector). Zero when a principal axis points at
    the planet.
    """

    needs = frozenset({'position'})

    def __init__(self, moments, mu):
        self.moments = tuple(float(i) for i in moments)
        self.mu = float(mu)

    def torque(self, t, r, q, omega, env):
        """Return 3 mu / norm(r)^5 (r_B x I r_B) (N m, principal frame)."""
        rx, ry, rz = env.r_body
        r2 = rx * rx + ry * ry + rz * rz
        k = 3.0 * self.mu / (r2 * r2 * math.sqrt(r2))
        i1, i2, i3 = self.moments
        return (k * (i3 - i2) * ry * rz, k * (i1 - i3) * rz * rx, k * (i2 - i1) * rx * ry)

    def stage_source(self, p):
        """Return the torque as stage statements (:mod:`.stage_code`): constants, lines, torque."""
        i1, i2, i3 = self.moments
        constants = {f'{p}mu3': 3.0 * self.mu, f'{p}d1': i3 - i2, f'{p}d2': i1 - i3,
                     f'{p}d3': i2 - i1}
        lines = [f'{p}k = {p}mu3 / (r_rr * r_rr * sqrt(r_rr))']
        return constants, lines, (f'{p}k * {p}d1 * r_by * r_bz', f'{p}k * {p}d2 * r_bz * r_bx',
                                  f'{p}k * {p}d3 * r_bx * r_by')


class MagneticDipole:
    """
    The torque m x B of a magnetic dipole m fixed in the body, in the planet's field.

    ``dipole`` (A m^2, principal frame). The residual dipole of a spacecraft
    (``residual_dipole``) is one; the magnetorquers are another, whose dipole
    the commands change (:class:`Magnetorquers`).
    """

    needs = frozenset({'field'})

    def __init__(self, dipole):
        self.dipole = tuple(float(c) for c in dipole)

    def torque(self, t, r, q, omega, env):
        """Return m x B_body (N m, principal frame)."""
        mx, my, mz = self.dipole
        bx, by, bz = env.b_body
        return (my * bz - mz * by, mz * bx - mx * bz, mx * by - my * bx)

    def stage_source(self, p):
        """Return the torque as stage statements (:mod:`.stage_code`): constants, lines, torque."""
        mx, my, mz = self.dipole
        return ({f'{p}x': mx, f'{p}y': my, f'{p}z': mz}, [],
                (f'{p}y * b_bz - {p}z * b_by', f'{p}z * b_bx - {p}x * b_bz',
                 f'{p}x * b_by - {p}y * b_bx'))


class Magnetorquers(MagneticDipole):
    """
    Three magnetic torque rods along the body axes: the commanded dipole m, torque m x B.

    The dipole is held over the step (``set_dipole``, principal frame, A m^2,
    already within ``magnetorquer_max_dipole``: the engine clips it per body axis
    when the command arrives); its torque changes within the step as B does.
    Basilisk's MtbEffector computes the same tau = -[B x] G m.
    """

    def __init__(self):
        super().__init__((0.0, 0.0, 0.0))

    def set_dipole(self, dipole):
        """Hold ``dipole`` (A m^2, principal frame) from the next step on."""
        self.dipole = dipole


class SolarPressureTorque:
    """
    The torque of solar radiation pressure on flat facets (:class:`~.facets.Facets`).

    ``facets`` in the principal frame (``Facets.turned``). At each stage the Sun's
    direction from the body and the pressure there, the shadow's sunlit fraction
    included, come from the environment (``needs`` 'sun'); each facet facing the Sun
    pushes with Montenbruck and Gill's absorbed, specular and diffuse parts
    (:mod:`.facets`), and the torque is the sum of c x F. A facet's turn from lit to
    unlit (cos theta through 0) is a kink in the torque: a step across it is of
    lower order there (the torque is 1e-7 N m on a CubeSat).
    """

    needs = frozenset({'position', 'sun'})

    def __init__(self, facets):
        self.facets = facets

    def torque(self, t, r, q, omega, env):
        """Return the sum of c x F over the sunlit facets (N m, principal frame)."""
        return tuple(float(c) for c in self.facets.solar_pressure(env.s_body, env.pressure)[1])

    def stage_source(self, p):
        """
        Return the torque as stage statements (:mod:`.stage_code`): constants, lines, torque.

        Summed as -P (a x s + b) with a = sum (1 - rho_s) A cos c and b = sum 2 A cos
        (rho_s cos + rho_d / 3) (c x n) over the lit facets, each facet's terms only when
        it faces the Sun (:func:`_facet_lines`).
        """
        f = self.facets

        def constants(k):
            n, c = f.normal[k], f.centre[k]
            cn = (c[1] * n[2] - c[2] * n[1], c[2] * n[0] - c[0] * n[2], c[0] * n[1] - c[1] * n[0])
            ka, kb = f.area[k] * (1.0 - f.specular[k]), 2.0 * f.area[k]
            return {'kx': ka * c[0], 'ky': ka * c[1], 'kz': ka * c[2], 'lx': kb * cn[0],
                    'ly': kb * cn[1], 'lz': kb * cn[2], 'ks': f.specular[k],
                    'kd': f.diffuse[k] / 3.0}

        def terms(v):
            lines = _sums(p, 'a', v, 'k', f'{p}c')
            sums = _sums(p, 'b', v, 'l', f'{p}e')
            inner = ' + '.join(term for term in (v['ks'] and f'{v["ks"]} * {p}c', v['kd'])
                               if term)
            return lines + ([f'{p}e = {p}c * ({inner})'] + sums if sums and inner else [])
        values, lines = _facet_lines(p, f, ('s_bx', 's_by', 's_bz'), constants, terms)
        lines.insert(0, f'{p}ax = {p}ay = {p}az = {p}bx = {p}by = {p}bz = 0.0')
        return values, lines, (f'-s_p * ({p}ay * s_bz - {p}az * s_by + {p}bx)',
                               f'-s_p * ({p}az * s_bx - {p}ax * s_bz + {p}by)',
                               f'-s_p * ({p}ax * s_by - {p}ay * s_bx + {p}bz)')


class DragTorque:
    """
    The torque of aerodynamic drag on flat facets (:class:`~.facets.Facets`).

    ``facets`` in the principal frame (``Facets.turned``). At each stage the body's
    velocity v relative to the air and the density rho come from the environment
    (``needs`` 'flow'); each facet facing the flow feels
    ``F = -1/2 rho C_D A max(0, n . v) v`` (the flat-plate free-molecular model of
    :mod:`.facets`, with ``|v|^2 cos theta v / |v|`` written as ``(n . v) v``), and the torque
    is the sum of c x F. As with the Sun's light, a facet's turn into the flow is a
    kink in the torque.
    """

    needs = frozenset({'position', 'flow'})

    def __init__(self, facets):
        self.facets = facets

    def torque(self, t, r, q, omega, env):
        """Return the sum of c x F over the facets facing the flow (N m, principal frame)."""
        return tuple(float(c) for c in self.facets.drag_force(env.f_body, env.density)[1])

    def stage_source(self, p):
        """
        Return the torque as stage statements (:mod:`.stage_code`): constants, lines, torque.

        Summed as -rho (a x v) with a = sum 1/2 C_D A (n . v) c over the facets facing
        the flow, each facet's terms only when it does (:func:`_facet_lines`).
        """
        f = self.facets

        def constants(k):
            half = 0.5 * f.drag[k] * f.area[k]
            return {'kx': half * f.centre[k][0], 'ky': half * f.centre[k][1],
                    'kz': half * f.centre[k][2]}

        def terms(v):
            return _sums(p, 'a', v, 'k', f'{p}c')
        values, lines = _facet_lines(p, f, ('f_bx', 'f_by', 'f_bz'), constants, terms)
        lines.insert(0, f'{p}ax = {p}ay = {p}az = 0.0')
        return values, lines, (f'-f_rho * ({p}ay * f_bz - {p}az * f_by)',
                               f'-f_rho * ({p}az * f_bx - {p}ax * f_bz)',
                               f'-f_rho * ({p}ax * f_by - {p}ay * f_bx)')


def _facet_lines(p, facets, along, constants, terms):
    """
    Return (constants, lines): per facet, ``terms`` when its normal's dot with ``along`` > 0.

    ``along``: the names of the stage's vector (the Sun's direction, the flow);
    ``constants(k)``: facet k's constants by short name; ``terms(names)``: the
    statements of a facet facing it, reading ``{p}c`` (the dot) and the facet's
    constants by those names (None for a constant that is exactly zero: its terms are
    left out, as they add nothing). Two facets whose normals are exact opposites (a
    box's faces) share one dot: at most one of them faces the vector.
    """
    normals = [tuple(float(c) for c in n) for n in facets.normal]
    values, lines, done = {}, [], set()

    def names(k):
        mine = {name: value for name, value in constants(k).items() if value != 0.0}
        values.update({f'{p}{name}{k}': value for name, value in mine.items()})
        return {name: f'{p}{name}{k}' if name in mine else None
                for name in constants(k)}
    for k, n in enumerate(normals):
        if k in done:
            continue
        dot = [(f'{p}n{axis}{k}', value, name)
               for axis, value, name in zip('xyz', n, along) if value != 0.0]
        values.update({variable: value for variable, value, _ in dot})
        lines.append(f'{p}c = ' + ' + '.join(
            f'{variable} * {name}' for variable, _, name in dot))
        lines += [f'if {p}c > 0.0:'] + ['    ' + line for line in terms(names(k)) or ['pass']]
        back = next((j for j in range(k + 1, len(normals)) if j not in done
                     and normals[j] == (-n[0], -n[1], -n[2])), None)
        if back is not None:
            done.add(back)
            lines += [f'elif {p}c < 0.0:', f'    {p}c = -{p}c']
            lines += ['    ' + line for line in terms(names(back)) or ['pass']]
    return values, lines


def _sums(p, total, names, letter, factor):
    """Return the statements ``{p}{total}x += {constant} * {factor}`` (x, y, z) of nonzero ones."""
    return [f'{p}{total}{axis} += {names[letter + axis]} * {factor}'
            for axis in 'xyz' if names[letter + axis] is not None]
