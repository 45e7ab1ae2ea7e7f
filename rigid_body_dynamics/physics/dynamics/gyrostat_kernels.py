"""
Explicit Runge-Kutta steps of the gyrostat, unrolled for a given number of wheels.

The system is :mod:`.gyrostat`'s: omega (rad/s, principal frame), q (x, y, z, w,
principal frame -> world) and n reaction wheels, the motor torques u held over
the step. As :mod:`.rk_kernels` does for the plain body, every stage is written
out as scalar statements generated from the tableau and compiled once (here once
per wheel count, on first use), because a step in pure Python then costs what its
arithmetic costs.

The stages carry the wheels' absolute momenta p_i = J_i (Omega_i + g_i . omega)
instead of the relative speeds Omega_i: a constant linear change of variables,
under which an explicit Runge-Kutta step is the same step (the same numbers up to
round-off), and in which the equations are cheaper:

- dp_i/dt = u_i - f_i(Omega_i), so without friction p_i is linear in time and is
  not a stage variable at all (the kernel is then Euler's equations with a known
  rotor momentum);
- H = I omega + sum_i J_i Omega_i g_i, omega_dot = A^-1 (tau - sum_i g_i (u_i - f_i)
  - omega x H) with A = I - sum_i J_i g_i g_i^T;
- the wheel angles (d theta_i/dt = Omega_i) never feed back, so they are the
  method's quadrature of the stage speeds.

Each kernel is ``step(k, q, w, speeds, angles, h, u, tau, tau_world, field=None,
t=0.0)`` with ``k`` the constants of :func:`constants`, ``tau`` the body torque and
``tau_world`` the world torque (N m, held; the latter rotated into the body at every
stage), ``field(t_stage, qx, qy, qz, qw, wx, wy, wz)`` -> body torque (N m) evaluated at
every stage. It returns (q renormalised, omega, speeds, angles, work, motor work,
friction loss, impulse): work = int omega . tau_ext dt (J), motor work = int sum_i
Omega_i u_i dt (J), friction loss = int sum_i Omega_i f_i dt (J) and impulse = int R
tau_ext dt (N m s, world), each by the method's own quadrature of the stage values.
Modes: ``free`` (no external torque: work and impulse zero), ``body``, ``world``
(body plus world torque), ``field`` (both plus ``field``) and ``environment`` (``field``
with the environment's statements in the stages, :func:`environment_kernel`);
``friction`` False when every wheel's Coulomb and viscous coefficients are zero.
"""

import functools
import math

import numpy as np

from .rk_kernels import BUTCHER6, compile_source, DOP853, environment_lines, literal, RK4

#: Tableaux by order.
TABLEAUX = {4: RK4, 6: BUTCHER6, 8: DOP853}

_OMEGA = ('wx', 'wy', 'wz')
_QUAT = ('qx', 'qy', 'qz', 'qw')
_MATRIX = tuple(f'a{r}{c}' for r in range(1, 4) for c in range(1, 4))
#: The modes whose torque depends on time and state at every stage.
_STATE_MODES = ('field', 'environment')


def _wheel_names(i, friction):
    names = [f'gx{i}', f'gy{i}', f'gz{i}', f'jx{i}', f'jy{i}', f'jz{i}', f'j{i}', f'ij{i}']
    return names + ([f'co{i}', f'vi{i}'] if friction else [])


def constants(moments, wheels, friction, smoothing):
    """
    Return (the flat tuple ``k`` a kernel unpacks, the smallest eigenvalue of A in kg m^2).

    ``moments`` principal (kg m^2, the wheels locked in), ``wheels`` a
    :class:`~.gyrostat.Wheels` with axes in that frame, ``friction`` whether the
    kernel models friction, ``smoothing`` the Coulomb tanh width (rad/s).
    ValueError when A = I - sum J g g^T is not positive definite.
    """
    i1, i2, i3 = (float(m) for m in moments)
    g = np.array(wheels.axes, dtype=float).reshape(-1, 3)
    j = np.array(wheels.inertia, dtype=float)
    a = np.diag([i1, i2, i3]) - (g.T * j) @ g
    smallest = float(np.linalg.eigvalsh(a).min())
    if smallest <= 0.0:
        raise ValueError('the body without its wheels spinning has no positive-definite '
                         'inertia (I - sum J g g^T): the wheels are too heavy for the body')
    out = [i1, i2, i3] + [float(v) for v in np.linalg.inv(a).ravel()]
    for i in range(wheels.count):
        gi, ji = [float(c) for c in g[i]], float(j[i])
        out += gi + [ji * c for c in gi] + [ji, 1.0 / ji]
        if friction:
            out += [float(wheels.coulomb[i]), float(wheels.viscous[i])]
    return tuple(out) + (1.0 / smoothing,), smallest


def _rotate(qx, qy, qz, qw, vx, vy, vz, out, conjugate=False):
    """Statements out{x,y,z} = R(q) v, or R(q)^T v: v + qw u + qv x u, u = 2 qv x v."""
    two, turn = ('-2.0', '-') if conjugate else ('2.0', '+')   # R(q)^T = R(-qv, qw)
    return [f'    ux = {two} * ({qy} * {vz} - {qz} * {vy})',
            f'    uy = {two} * ({qz} * {vx} - {qx} * {vz})',
            f'    uz = {two} * ({qx} * {vy} - {qy} * {vx})',
            f'    {out}x = {vx} + {qw} * ux {turn} ({qy} * uz - {qz} * uy)',
            f'    {out}y = {vy} + {qw} * uy {turn} ({qz} * ux - {qx} * uz)',
            f'    {out}z = {vz} + {qw} * uz {turn} ({qx} * uy - {qy} * ux)']


def _stage_lines(i, node, n, mode, friction, code=None, nodes=None, world=True):
    """Stage i's derivatives times h: dwx{i} .. dqw{i}, dp{k}_{i}, and its speeds s{k}_{i}."""
    wx, wy, wz, qx, qy, qz, qw = (f'{v}{i}' for v in _OMEGA + _QUAT)
    wheels = range(n)
    lines = []
    for k in wheels:
        if i == 0:
            lines.append(f'    s{k}_0 = so{k}')
        else:
            base = f'p{k}_{i} * ij{k}' if friction else f'e{k} + {literal(node)} * r{k}'
            lines.append(f'    s{k}_{i} = {base} - (gx{k} * {wx} + gy{k} * {wy} + gz{k} * {wz})')
    if friction:
        for k in wheels:
            lines += [f'    f{k}_{i} = co{k} * tanh(s{k}_{i} * ism) + vi{k} * s{k}_{i}',
                      f'    n{k} = u{k} - f{k}_{i}',
                      f'    dp{k}_{i} = h * n{k}']
        for c in 'xyz':
            lines.append(f'    m{c} = ' + _sum(f'g{c}{k} * n{k}' for k in wheels))
        lines.append(f'    lo{i} = ' + _sum(f's{k}_{i} * f{k}_{i}' for k in wheels))
    # the external torque (body frame) at this stage
    if mode != 'free':
        if mode == 'field':
            lines.append(f'    fx, fy, fz = field(t + {literal(node)} * h, {qx}, {qy}, {qz}, '
                         f'{qw}, {wx}, {wy}, {wz})')
        elif mode == 'environment':
            lines += environment_lines(code, node, nodes, (qx, qy, qz, qw), (wx, wy, wz))
        extra = ('', '', '')
        if mode == 'world' or (mode in _STATE_MODES and world):
            lines += _rotate(qx, qy, qz, qw, 'gwx', 'gwy', 'gwz', 'v', conjugate=True)
            extra = (' + vx', ' + vy', ' + vz')
        if mode in _STATE_MODES:
            extra = tuple(e + f' + f{c}' for e, c in zip(extra, 'xyz'))
        lines += [f'    tx{i} = tbx{extra[0]}', f'    ty{i} = tby{extra[1]}',
                  f'    tz{i} = tbz{extra[2]}']
    for c, i_c in zip('xyz', ('i1', 'i2', 'i3')):
        terms = [f'{i_c} * w{c}{i}'] + [f'j{c}{k} * s{k}_{i}' for k in wheels]
        lines.append(f'    H{c} = ' + _sum(terms))
    ext = (f'tx{i} - ', f'ty{i} - ', f'tz{i} - ') if mode != 'free' else ('-', '-', '-')
    lines += [f'    rx = {ext[0]}mx - ({wy} * Hz - {wz} * Hy)',
              f'    ry = {ext[1]}my - ({wz} * Hx - {wx} * Hz)',
              f'    rz = {ext[2]}mz - ({wx} * Hy - {wy} * Hx)',
              f'    dwx{i} = ha11 * rx + ha12 * ry + ha13 * rz',
              f'    dwy{i} = ha21 * rx + ha22 * ry + ha23 * rz',
              f'    dwz{i} = ha31 * rx + ha32 * ry + ha33 * rz',
              f'    dqx{i} = hh * ({qw} * {wx} + {qy} * {wz} - {qz} * {wy})',
              f'    dqy{i} = hh * ({qw} * {wy} + {qz} * {wx} - {qx} * {wz})',
              f'    dqz{i} = hh * ({qw} * {wz} + {qx} * {wy} - {qy} * {wx})',
              f'    dqw{i} = -hh * ({qx} * {wx} + {qy} * {wy} + {qz} * {wz})']
    return lines


def _unpack(names, source):
    """One unpacking statement as a list (a one-name tuple gets its comma; none: no statement)."""
    return [f'    {", ".join(names)}{"," if len(names) == 1 else ""} = {source}'] if names else []


def _sum(terms):
    """Return the source of a sum of ``terms`` (0.0 when there are none)."""
    return ' + '.join(terms) or '0.0'


def _tuple(items):
    """Return the source of a tuple of ``items``."""
    return '(' + ''.join(f'{item}, ' for item in items) + ')'


def kernel_source(tableau, n, mode, friction, name='step', code=None, world=True):
    """
    Python source of one unrolled gyrostat step: ``tableau`` (A rows, b[, c]), n wheels.

    Mode ``environment`` takes ``code``, the environment's
    :class:`~rigid_body_dynamics.physics.environment.stage_code.StageCode`, and
    ``world``: whether a world torque is held (False: ``tau_world`` is not read).
    """
    rows, weights = tableau[:2]
    seen = {}
    nodes = tableau[2] if len(tableau) > 2 else [sum(row) for row in rows]
    wheels = range(n)
    names = ['i1', 'i2', 'i3', *_MATRIX]
    for k in wheels:
        names += _wheel_names(k, friction)
    # (tanh a default argument: a local name, not a global looked up at every stage)
    lines = [f'def {name}(k, q, w, speeds, angles, h, u, tau, tau_world, field=None, t=0.0, '
             f'tanh=tanh):',
             *_unpack(names + ['ism'], 'k'),
             '    qx0, qy0, qz0, qw0 = q',
             '    wx0, wy0, wz0 = w',
             *_unpack([f'so{k}' for k in wheels], 'speeds'),
             *_unpack([f'u{k}' for k in wheels], 'u'),
             '    hh = 0.5 * h',
             '    ' + ', '.join(f'h{a}' for a in _MATRIX) + ' = '
             + ', '.join(f'h * {a}' for a in _MATRIX)]
    if mode != 'free':
        lines.append('    tbx, tby, tbz = tau')
    if mode == 'world' or (mode in _STATE_MODES and world):
        lines.append('    gwx, gwy, gwz = tau_world')
    if mode == 'environment':
        lines += code.prologue()
    at = len(lines)
    for k in wheels:
        absolute = f'so{k} + gx{k} * wx0 + gy{k} * wy0 + gz{k} * wz0'
        if friction:        # p_k = J_k (Omega_k + g_k . omega), a stage variable
            lines.append(f'    p{k}_0 = j{k} * ({absolute})')
        else:               # p_k / J_k = e_k + (t - t0) r_k exactly
            lines += [f'    e{k} = {absolute}', f'    r{k} = h * u{k} * ij{k}']
    if not friction:        # sum_k g_k u_k, the motors' reaction, held
        for c in 'xyz':
            lines.append(f'    m{c} = ' + _sum(f'g{c}{k} * u{k}' for k in wheels))
    for i, row in enumerate(rows):
        if i > 0:
            stage_vars = _OMEGA + _QUAT + (tuple(f'p{k}_' for k in wheels) if friction else ())
            for var in stage_vars:
                terms = ' + '.join(f'{literal(a)} * d{var}{j}'
                                   for j, a in enumerate(row) if a != 0)
                lines.append(f'    {var}{i} = {var}0 + {terms}' if terms else
                             f'    {var}{i} = {var}0')
        lines += _stage_lines(i, nodes[i], n, mode, friction, code, seen, world)
    if mode == 'environment':
        lines[at:at] = code.nodes_lines(tuple(seen))
    used = [(j, b) for j, b in enumerate(weights) if b != 0]
    # (each new value is its start plus the step's increment, so that the speeds are
    # rounded once per step as in the relative variables, not through p and back)
    for var in _OMEGA:
        terms = ' + '.join(f'{literal(b)} * d{var}{j}' for j, b in used)
        lines += [f'    i{var} = {terms}', f'    {var} = {var}0 + i{var}']
    for var in _QUAT:
        terms = ' + '.join(f'{literal(b)} * d{var}{j}' for j, b in used)
        lines.append(f'    {var} = {var}0 + ({terms})')
    for k in wheels:
        terms = ' + '.join(f'{literal(b)} * s{k}_{j}' for j, b in used)
        lines.append(f'    th{k} = h * ({terms})')
        turn = f'(gx{k} * iwx + gy{k} * iwy + gz{k} * iwz)'
        if friction:
            terms = ' + '.join(f'{literal(b)} * dp{k}_{j}' for j, b in used)
            lines.append(f'    s{k} = so{k} + (({terms}) * ij{k} - {turn})')
        else:
            lines.append(f'    s{k} = so{k} + (r{k} - {turn})')
    lines += _unpack([f'an{k}' for k in wheels], 'angles')
    lines.append('    motor = ' + _sum(f'u{k} * th{k}' for k in wheels))
    lines.append('    loss = h * (' + ' + '.join(f'{literal(b)} * lo{j}' for j, b in used) + ')'
                 if friction else '    loss = 0.0')
    if mode == 'free':
        lines += ['    work = 0.0', '    impulse = (0.0, 0.0, 0.0)']
    else:
        lines.append('    work = h * (' + ' + '.join(
            f'{literal(b)} * (wx{j} * tx{j} + wy{j} * ty{j} + wz{j} * tz{j})' for j, b in used)
            + ')')
        for j, _ in used:   # the stage torques in the world frame
            lines += _rotate(f'qx{j}', f'qy{j}', f'qz{j}', f'qw{j}', f'tx{j}', f'ty{j}',
                             f'tz{j}', f'o{j}')
        lines.append('    impulse = (' + ', '.join(
            'h * (' + ' + '.join(f'{literal(b)} * o{j}{c}' for j, b in used) + ')'
            for c in 'xyz') + ')')
    lines += ['    nrm = (qx * qx + qy * qy + qz * qz + qw * qw) ** -0.5',
              '    return ((qx * nrm, qy * nrm, qz * nrm, qw * nrm), (wx, wy, wz), '
              + _tuple(f's{k}' for k in wheels) + ', '
              + _tuple(f'an{k} + th{k}' for k in wheels) + ', work, motor, loss, impulse)']
    return '\n'.join(lines) + '\n'


@functools.lru_cache(maxsize=None)
def kernel(order, n, mode, friction):
    """Return the compiled step of ``order`` (4, 6 or 8) for n wheels, a mode and friction."""
    source = kernel_source(TABLEAUX[order], n, mode, friction)
    label = f'<gyrostat kernel order {order} {n} wheels {mode}{" friction" if friction else ""}>'
    return compile_source(source, label, {'tanh': math.tanh})


_ENVIRONMENT_KERNELS = {}


def environment_kernel(order, n, friction, code, world=True):
    """
    Return the step of ``order`` for n wheels with the environment ``code`` in its stages.

    ``world``: whether it holds a world torque too. Compiled on first use, one per
    order, wheel count, friction, environment shape and ``world``.
    """
    key = (order, n, friction, code.key, world)
    step = _ENVIRONMENT_KERNELS.get(key)
    if step is None:
        source = kernel_source(TABLEAUX[order], n, 'environment', friction, code=code,
                               world=world)
        label = (f'<gyrostat kernel order {order} {n} wheels environment '
                 f'{len(_ENVIRONMENT_KERNELS)}{" friction" if friction else ""}>')
        step = _ENVIRONMENT_KERNELS[key] = compile_source(
            source, label, {'tanh': math.tanh, 'sqrt': math.sqrt})
    return step
