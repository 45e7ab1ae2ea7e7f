"""
The environment's torque as straight-line statements, for the generated Runge-Kutta stages.

The integrators' kernels (:mod:`~rigid_body_dynamics.physics.dynamics.rk_kernels`,
:mod:`~rigid_body_dynamics.physics.dynamics.gyrostat_kernels`) are generated as
scalar statements, because in pure Python a step then costs what its arithmetic
costs. A torque model called at every stage (``torque(t, r, q, omega, env)``)
costs a call, the shared quantities' call and a tuple per stage, several times its
arithmetic. :class:`StageCode` puts the models' arithmetic into the stage instead:

- at the step's start, one call ``field.world_nodes(t, h, nodes)``
  (:meth:`SpaceEnvironment.world_nodes <.space.SpaceEnvironment.world_nodes>`) gives
  at each distinct node t + c h of the step the world-frame position r (m), its
  squared norm, the field B (T), the Sun and the air: they depend on time alone;
- at each stage, r and B are turned into the principal frame of the stage's
  attitude (not quite unit inside a step: the rotation of q / norm(q), as
  :func:`.space._to_body`), and each model's statements give its torque (N m,
  principal frame), summed into ``fx, fy, fz``.

A model takes part by a method ``stage_source(prefix)`` returning
``(constants, lines, torque)``: ``constants`` a dict of its parameters by name
(each name starting with ``prefix``), read when the environment is made;
``lines`` statements that may read ``r_bx, r_by, r_bz`` (position, principal
frame, m), ``r_rr`` (its squared norm, m^2), ``b_bx, b_by, b_bz`` (field,
principal frame, T), ``s_bx, s_by, s_bz`` (the unit direction from the body to the
Sun, principal frame) and ``s_p`` (the solar radiation pressure there, N/m^2, the
shadow's fraction included; the model's ``needs`` has 'sun'), ``f_bx, f_by, f_bz``
(the body's velocity relative to the air, principal frame, m/s) and ``f_rho`` (the
density, kg/m^3; the model's ``needs`` has 'flow'), ``o_x, o_y, o_z``
(the stage's angular velocity, rad/s, principal frame; the model's ``needs`` has
'rate'), ``sqrt`` and its constants,
and set names starting with ``prefix``; ``torque`` three expressions of its torque
components. The model's ``torque()`` stays its definition (tests hold the two to
round-off). An environment with a model that has no ``stage_source`` (one that
needs the time, say) is evaluated through the models' ``torque()`` at every stage,
as before: slower, never different.
"""

_STAGE_NAMES = ('r_bx', 'r_by', 'r_bz', 'r_rr', 'b_bx', 'b_by', 'b_bz', 's_bx', 's_by', 's_bz',
                's_p', 'f_bx', 'f_by', 'f_bz', 'f_rho')


class StageCode:
    """
    The statements of an environment's summed torque at one stage, and their constants.

    ``models`` (each with ``stage_source``, see the module docstring),
    ``position``, ``field``, ``rate``, ``sun`` and ``flow``: whether the stages need the
    position, the field, the angular velocity, the Sun and the air. ``key`` identifies the
    generated source (the same key, the same statements: one compiled kernel serves
    every environment of that shape); ``names`` and ``values`` the constants, which
    a kernel unpacks from the environment's ``constants`` at each step.
    """

    def __init__(self, models, position, field, rate=False, sun=False, flow=False):
        constants, lines, sums = {}, [], ([], [], [])
        for n, model in enumerate(models):
            prefix = f'm{n}_'
            values, statements, torque = model.stage_source(prefix)
            for name in values:
                if not name.startswith(prefix):
                    raise ValueError(f'{type(model).__name__}.stage_source: constant {name!r} '
                                     f'does not start with {prefix!r}')
            constants.update(values)
            lines += statements
            for total, term in zip(sums, torque):
                total.append(f'({term})')
        self.position, self.field, self.rate = bool(position), bool(field), bool(rate)
        self.sun, self.flow = bool(sun), bool(flow)
        self.names = tuple(constants)
        self.values = tuple(float(v) for v in constants.values())
        self.lines = tuple(lines)
        self.torque = tuple(' + '.join(terms) or '0.0' for terms in sums)
        self.key = (self.position, self.field, self.rate, self.sun, self.flow, self.names,
                    self.lines, self.torque)

    def world_names(self, j):
        """Names of node j's world quantities: r (m), its squared norm, B (T), Sun, air."""
        names = [f'r_wx{j}', f'r_wy{j}', f'r_wz{j}', f'r_rr{j}'] if self.position else []
        names += [f'b_wx{j}', f'b_wy{j}', f'b_wz{j}'] if self.field else []
        names += [f's_wx{j}', f's_wy{j}', f's_wz{j}', f's_pp{j}'] if self.sun else []
        return names + ([f'f_wx{j}', f'f_wy{j}', f'f_wz{j}', f'f_rr{j}'] if self.flow else [])

    def prologue(self, indent='    '):
        """Statements once per step: ``world`` and the constants from the environment ``field``."""
        lines = [f'{indent}world = field.world_at']
        if self.names:
            comma = ',' if len(self.names) == 1 else ''
            lines.append(f'{indent}{", ".join(self.names)}{comma} = field.constants')
        return lines

    def nodes_lines(self, nodes, indent='    '):
        """
        Statements once per step: the world quantities of every node, in one call.

        ``nodes`` the step's distinct nodes c (in the order of their index j); the call is
        ``field.world_nodes(t, h, nodes)`` (:meth:`.space.SpaceEnvironment.world_nodes`).
        """
        names = [name for j in range(len(nodes)) for name in self.world_names(j)]
        if not names:
            return []
        literals = ''.join(f'{float(c)!r}, ' for c in nodes)
        return [f'{indent}{", ".join(names)}, = field.world_nodes(t, h, ({literals.strip()}))']

    def node_lines(self, j, time, indent='    '):
        """Statements for node j at time expression ``time``: its world quantities."""
        names = self.world_names(j)
        if not names:
            return []
        comma = ',' if len(names) == 1 else ''
        return [f'{indent}{", ".join(names)}{comma} = world({time})']

    def stage_lines(self, j, q, w, indent='    '):
        """
        Statements setting ``fx, fy, fz`` (N m, principal frame) at a stage of node j.

        ``q``: the names of the stage's attitude (x, y, z, w; need not be unit), ``w``
        of its angular velocity.
        """
        qx, qy, qz, qw = q
        lines = [f'o_x, o_y, o_z = {", ".join(w)}'] if self.rate else []
        if self.position or self.field or self.sun or self.flow:
            lines.append(f's_q = 2.0 / ({qx} * {qx} + {qy} * {qy} + {qz} * {qz} + {qw} * {qw})')
        for kind, on in (('r', self.position), ('b', self.field), ('s', self.sun),
                         ('f', self.flow)):
            if not on:
                continue
            vx, vy, vz = f'{kind}_wx{j}', f'{kind}_wy{j}', f'{kind}_wz{j}'
            # R(q)^T v for q / norm(q): v + qw u - qv x u, u = 2 (v x qv) / norm(q)^2
            lines += [f's_ux = s_q * ({vy} * {qz} - {vz} * {qy})',
                      f's_uy = s_q * ({vz} * {qx} - {vx} * {qz})',
                      f's_uz = s_q * ({vx} * {qy} - {vy} * {qx})',
                      f'{kind}_bx = {vx} + {qw} * s_ux - ({qy} * s_uz - {qz} * s_uy)',
                      f'{kind}_by = {vy} + {qw} * s_uy - ({qz} * s_ux - {qx} * s_uz)',
                      f'{kind}_bz = {vz} + {qw} * s_uz - ({qx} * s_uy - {qy} * s_ux)']
        if self.position:
            lines.append(f'r_rr = r_rr{j}')
        if self.sun:
            lines.append(f's_p = s_pp{j}')
        if self.flow:
            lines.append(f'f_rho = f_rr{j}')
        lines += list(self.lines)
        lines += [f'fx = {self.torque[0]}', f'fy = {self.torque[1]}', f'fz = {self.torque[2]}']
        return [indent + line for line in lines]


def stage_code(models, position, field):
    """Return the :class:`StageCode` of ``models``, or None when one has no ``stage_source``."""
    if not all(hasattr(model, 'stage_source') for model in models):
        return None
    return StageCode(models, position, field, *(any(need in model.needs for model in models)
                                                for need in ('rate', 'sun', 'flow')))


def torque_source(code, name='torque'):
    """
    Source of ``name(field, t, qx, qy, qz, qw, wx, wy, wz)``: the summed torque at one state.

    The same statements as a stage (``field`` the environment, t its integrator time, s),
    so that the torque at a step's start, which sets the step's order, costs one node.
    """
    lines = [f'def {name}(field, t, qx, qy, qz, qw, wx=0.0, wy=0.0, wz=0.0):',
             *code.prologue(), *code.node_lines(0, 't'),
             *code.stage_lines(0, ('qx', 'qy', 'qz', 'qw'), ('wx', 'wy', 'wz')),
             '    return fx, fy, fz']
    return '\n'.join(lines) + '\n'
