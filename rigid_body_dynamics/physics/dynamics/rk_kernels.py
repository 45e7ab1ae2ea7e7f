"""
Explicit Runge-Kutta steps of the rigid body, unrolled from Butcher tableaux.

The system is Euler's equations (4.26) with a torque held over the step and
the quaternion kinematics dq/dt = q (x) (omega, 0) / 2, seven float states
(omega body rad/s, q x-y-z-w body -> world). A step in pure Python costs what
its arithmetic costs only when every stage is written out as scalar
statements; writing them by hand for a 12-stage tableau invites typos, so the
statements are generated here from the tableau (as ``collections.namedtuple``
generates its class) and compiled once at import. The tableaux:

- ``RK4``: the classic fourth-order method (4 stages).
- ``BUTCHER6``: Butcher's 7-stage method of order 6 (rational coefficients;
  J. C. Butcher, Numerical Methods for ODEs, 2nd ed., section 325).
- ``DOP853``: the 12-stage order-8 formula of Dormand and Prince's DOP853
  (:mod:`.dop853_tableau`, with its source), without the error estimator or
  dense output.

Each kernel's source is registered with :mod:`linecache` under the file name
``<rk kernel ORDER MODE>``, so a traceback through a kernel shows the stage's
statement.

Each kernel is ``step(inv, q, w, h, tau, tau_world, field=None, t=0.0)`` with
``inv`` = (c1, c2, c3, 1/I1, 1/I2, 1/I3), c1 = (I2 - I3) / I1 and cyclic,
``tau`` the body torque (N m) and ``tau_world`` the world torque (N m) held
fixed in the world frame (rotated into the body at every stage). It returns
(q, omega, work): q renormalised, and the step's work int omega . tau dt (J)
by the method's own quadrature of the stage values, so it is accurate to the
method's order. Four variants: ``free`` (no torque; work 0), ``body`` (tau
only), ``world`` (tau plus tau_world) and ``field`` (tau plus tau_world plus
a torque that depends on time and state, ``field(t_stage, qx, qy, qz, qw, wx, wy,
wz)`` -> body torque (N m), evaluated at every stage at t_stage = t + c_i h, so a
gravity-gradient or magnetic torque is integrated to the method's order, not
held; :class:`~.environment.SpaceEnvironment` is one). A fifth,
``environment`` (:func:`environment_kernel`), is ``field`` with the environment's
torque written into each stage as statements
(:mod:`~rigid_body_dynamics.physics.environment.stage_code`) instead of called:
one kernel per environment shape, compiled on first use.
"""

from fractions import Fraction as F
import linecache
import math

from . import dop853_tableau

#: The classic RK4 tableau (A lower triangular rows, b).
RK4 = (((), (F(1, 2),), (F(0), F(1, 2)), (F(0), F(0), F(1))),
       (F(1, 6), F(1, 3), F(1, 3), F(1, 6)))

#: Butcher's order-6 tableau (A lower triangular rows, b).
BUTCHER6 = (
    ((),
     (F(1, 3),),
     (F(0), F(2, 3)),
     (F(1, 12), F(1, 3), F(-1, 12)),
     (F(-1, 16), F(9, 8), F(-3, 16), F(-3, 8)),
     (F(0), F(9, 8), F(-3, 8), F(-3, 4), F(1, 2)),
     (F(9, 44), F(-9, 11), F(63, 44), F(18, 11), F(0), F(-16, 11))),
    (F(11, 120), F(0), F(27, 40), F(27, 40), F(-4, 15), F(-4, 15), F(11, 120)),
)

#: DOP853's order-8 tableau (12 stages) as floats, with its nodes c (the float rows of A
#: sum to them only within round-off).
DOP853 = (dop853_tableau.A, dop853_tableau.B, dop853_tableau.C)

_OMEGA = ('wx', 'wy', 'wz')
_QUAT = ('qx', 'qy', 'qz', 'qw')
#: The modes whose torque depends on time and state at every stage.
_STATE_MODES = ('field', 'environment')


def literal(coefficient):
    """Return a coefficient as a float literal of the generated source."""
    return repr(float(coefficient))


def environment_lines(code, node, nodes, q, w):
    """
    Statements of the environment ``code`` (a StageCode) at a stage of ``node``: fx, fy, fz.

    ``nodes`` maps the nodes seen so far in the step to their index j (updated here):
    the kernel unpacks every node's world quantities once, at its start
    (``StageCode.nodes_lines``). ``q``, ``w``: the stage's attitude and angular
    velocity names.
    """
    j = nodes.get(node)
    if j is None:
        j = nodes[node] = len(nodes)
    return code.stage_lines(j, q, w)


def _derivative_lines(i, mode, node, code=None, nodes=None, world=True):
    """
    Scaled derivatives h f(stage i at time node c_i): dwx{i} ... dqw{i}, the torque.

    ``world`` False: mode ``environment`` without a world torque (none to rotate).
    """
    wx, wy, wz, qx, qy, qz, qw = (f'{n}{i}' for n in _OMEGA + _QUAT)
    fx, fy, fz = (' + fx', ' + fy', ' + fz') if mode in _STATE_MODES else ('', '', '')
    lines = []
    if mode == 'field':
        lines.append(f'    fx, fy, fz = field(t + {literal(node)} * h, {qx}, {qy}, {qz}, {qw}, '
                     f'{wx}, {wy}, {wz})')
    elif mode == 'environment':
        lines += environment_lines(code, node, nodes, (qx, qy, qz, qw), (wx, wy, wz))
    if mode == 'environment' and not world:
        lines += [f'    tx{i} = tbx + fx', f'    ty{i} = tby + fy', f'    tz{i} = tbz + fz',
                  f'    dwx{i} = hc1 * {wy} * {wz} + hj1 * tx{i}',
                  f'    dwy{i} = hc2 * {wz} * {wx} + hj2 * ty{i}',
                  f'    dwz{i} = hc3 * {wx} * {wy} + hj3 * tz{i}']
    elif mode in ('world', *_STATE_MODES):
        # tau_b = tau + R(q)^T tau_world: rotate by the conjugate (-qx, -qy, -qz, qw)
        lines += [
            f'    ux = 2.0 * (-{qy} * gz + {qz} * gy)',
            f'    uy = 2.0 * (-{qz} * gx + {qx} * gz)',
            f'    uz = 2.0 * (-{qx} * gy + {qy} * gx)',
            f'    tx{i} = tbx{fx} + gx + {qw} * ux - {qy} * uz + {qz} * uy',
            f'    ty{i} = tby{fy} + gy + {qw} * uy - {qz} * ux + {qx} * uz',
            f'    tz{i} = tbz{fz} + gz + {qw} * uz - {qx} * uy + {qy} * ux',
            f'    dwx{i} = hc1 * {wy} * {wz} + hj1 * tx{i}',
            f'    dwy{i} = hc2 * {wz} * {wx} + hj2 * ty{i}',
            f'    dwz{i} = hc3 * {wx} * {wy} + hj3 * tz{i}',
        ]
    elif mode == 'body':
        lines += [f'    dwx{i} = hc1 * {wy} * {wz} + ht1',
                  f'    dwy{i} = hc2 * {wz} * {wx} + ht2',
                  f'    dwz{i} = hc3 * {wx} * {wy} + ht3']
    else:
        lines += [f'    dwx{i} = hc1 * {wy} * {wz}',
                  f'    dwy{i} = hc2 * {wz} * {wx}',
                  f'    dwz{i} = hc3 * {wx} * {wy}']
    lines += [
        f'    dqx{i} = hh * ({qw} * {wx} + {qy} * {wz} - {qz} * {wy})',
        f'    dqy{i} = hh * ({qw} * {wy} + {qz} * {wx} - {qx} * {wz})',
        f'    dqz{i} = hh * ({qw} * {wz} + {qx} * {wy} - {qy} * {wx})',
        f'    dqw{i} = -hh * ({qx} * {wx} + {qy} * {wy} + {qz} * {wz})',
    ]
    return lines


def kernel_source(tableau, mode, name='step', code=None, world=True):
    """
    Python source of one unrolled step for ``tableau`` = (A rows, b[, c]) and ``mode``.

    Mode ``environment`` takes ``code``, the environment's
    :class:`~rigid_body_dynamics.physics.environment.stage_code.StageCode`, and
    ``world``: whether a world torque is held (False: ``tau_world`` is not read).
    """
    rows, weights = tableau[:2]
    nodes = tableau[2] if len(tableau) > 2 else [sum(row) for row in rows]
    seen = {}
    lines = [f'def {name}(inv, q, w, h, tau, tau_world, field=None, t=0.0):',
             '    c1, c2, c3, j1, j2, j3 = inv',
             '    qx0, qy0, qz0, qw0 = q',
             '    wx0, wy0, wz0 = w',
             '    hh = 0.5 * h',
             '    hc1, hc2, hc3 = h * c1, h * c2, h * c3']
    if mode == 'body':
        lines += ['    tbx, tby, tbz = tau',
                  '    ht1, ht2, ht3 = h * tbx * j1, h * tby * j2, h * tbz * j3']
    elif mode in ('world', *_STATE_MODES):
        lines += ['    tbx, tby, tbz = tau',
                  *(['    gx, gy, gz = tau_world'] if world or mode != 'environment' else []),
                  '    hj1, hj2, hj3 = h * j1, h * j2, h * j3']
    if mode == 'environment':
        lines += code.prologue()
    at = len(lines)
    for i, row in enumerate(rows):
        if i > 0:
            for var in _OMEGA + _QUAT:
                terms = ' + '.join(f'{literal(a)} * d{var}{j}'
                                   for j, a in enumerate(row) if a != 0)
                lines.append(f'    {var}{i} = {var}0 + {terms}' if terms else
                             f'    {var}{i} = {var}0')
        lines += _derivative_lines(i, mode, nodes[i], code, seen, world)
    if mode == 'environment':
        lines[at:at] = code.nodes_lines(tuple(seen))
    used = [(j, b) for j, b in enumerate(weights) if b != 0]
    for var in _OMEGA + _QUAT:
        terms = ' + '.join(f'{literal(b)} * d{var}{j}' for j, b in used)
        lines.append(f'    {var} = {var}0 + ({terms})')
    lines.append('    r = (qx * qx + qy * qy + qz * qz + qw * qw) ** -0.5')
    if mode == 'free':
        lines.append('    work = 0.0')
    else:
        # work = h sum_i b_i omega_i . tau_i
        if mode == 'body':
            power = [f'{literal(b)} * (wx{j} * tbx + wy{j} * tby + wz{j} * tbz)' for j, b in used]
        else:
            power = [f'{literal(b)} * (wx{j} * tx{j} + wy{j} * ty{j} + wz{j} * tz{j})'
                     for j, b in used]
        lines.append('    work = h * (' + ' + '.join(power) + ')')
    lines.append('    return (qx * r, qy * r, qz * r, qw * r), (wx, wy, wz), work')
    return '\n'.join(lines) + '\n'


def compile_source(source, filename, namespace=None):
    """
    Compile generated ``source`` and return its one function.

    The source goes to :mod:`linecache` under ``filename`` so that a traceback shows
    the generated statement; ``namespace`` holds the names the source uses (e.g. tanh).
    """
    # (size, mtime None: never checked against a file, lines, name), as for code without a file
    linecache.cache[filename] = (len(source), None, source.splitlines(True), filename)
    namespace = dict(namespace or {})
    exec(compile(source, filename, 'exec'), namespace)  # noqa: S102 (generated from a tableau)
    name = source.split('(', 1)[0].split()[-1]
    return namespace[name]


def compile_kernel(tableau, mode, label=''):
    """Compile :func:`kernel_source` into a function; its source goes to linecache."""
    return compile_source(kernel_source(tableau, mode), f'<rk kernel {label} {mode}>')


_ENVIRONMENT_KERNELS = {}


def environment_kernel(order, code, world=True):
    """
    Return the step of ``order`` (4, 6 or 8) with the environment ``code`` in its stages.

    ``world``: whether it holds a world torque too. Compiled on first use, one per
    order, environment shape (``code.key``) and ``world``.
    """
    key = (order, code.key, world)
    step = _ENVIRONMENT_KERNELS.get(key)
    if step is None:
        tableau = {4: RK4, 6: BUTCHER6, 8: DOP853}[order]
        step = _ENVIRONMENT_KERNELS[key] = compile_source(
            kernel_source(tableau, 'environment', code=code, world=world),
            f'<rk kernel order {order} environment {len(_ENVIRONMENT_KERNELS)}>',
            {'sqrt': math.sqrt})
    return step


#: Kernels by (order, mode).
KERNELS = {(order, mode): compile_kernel(tableau, mode, f'order {order}')
           for order, tableau in ((4, RK4), (6, BUTCHER6), (8, DOP853))
           for mode in ('free', 'body', 'world', 'field')}
