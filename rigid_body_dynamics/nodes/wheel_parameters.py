"""
The reaction-wheel parameters, one definition for every node that takes them.

attitude_simulator flies the wheels (all seven), attitude_analyzer counts their
momentum (axes, inertia, friction) and attitude_controller allocates to them
(axes, inertia, limits): the same names and meanings, so one parameters file
(``/**:``) serves all three. :func:`wheels_from` turns a node's validated values
into a :class:`~rigid_body_dynamics.physics.dynamics.gyrostat.Wheels`, with the reason when
refused.
"""

from ..physics.dynamics.gyrostat import MAX_WHEELS, Wheels
from ..ros.parameters import ConfigurationError, number_list, Param


def _param(name, shown, text):
    return Param(name, 'double[]', None, shown, text, read_only=True, convert=number_list(name))


#: Every wheel parameter, by name, in the order the manual lists them.
WHEEL_PARAMS = {p.name: p for p in (
    _param('wheel_axes', '[] (no wheels)',
           f'Reaction wheels: spin axis of each, 3 numbers per wheel (body frame, unit '
           f'vectors), at most {MAX_WHEELS} wheels; [] = none. The inertia is the whole body '
           'with the wheels locked.'),
    _param('wheel_inertia', '[]', 'Spin-axis moment J of each wheel (kg m^2, > 0).'),
    _param('wheel_max_torque', '[] (no limit)',
           'Motor torque limit of each wheel (N m; 0 = none): larger commands are clipped '
           '(the simulator counts them; the controller scales its torques down together).'),
    _param('wheel_max_speed', '[] (no limit)',
           'Speed limit of each wheel (rad/s relative to the body; 0 = none): at or beyond it '
           'a command that would speed the wheel up is cut to 0 and counted.'),
    _param('wheel_friction_coulomb', '[] (none)',
           'Coulomb friction of each wheel (N m), c tanh(Omega / 0.1 rad/s): smoothed near '
           'rest so it does not chatter.'),
    _param('wheel_friction_viscous', '[] (none)', 'Viscous friction of each wheel (N m s).'),
    _param('initial_wheel_speed', '[] (all 0)',
           'Wheel speeds (rad/s relative to the body) at start and on ~/reset.'),
)}
#: The Wheels field each parameter besides wheel_axes fills.
_FIELDS = {'wheel_inertia': 'inertia', 'wheel_max_torque': 'max_torque',
           'wheel_max_speed': 'max_speed', 'wheel_friction_coulomb': 'coulomb',
           'wheel_friction_viscous': 'viscous'}


def wheel_params(*names):
    """Return the Params called ``names`` (for a node's ParameterTable)."""
    return [WHEEL_PARAMS[name] for name in names]


def wheels_from(out):
    """
    Return the Wheels of a node's validated values ``out``, or None without wheel_axes.

    Only the wheel parameters the node declares are read. Wheel parameters set
    without wheel_axes, wrong lengths, zero or non-unit axes and negative values
    raise ConfigurationError with the reason.
    """
    given = [name for name in WHEEL_PARAMS if name != 'wheel_axes' and out.get(name)]
    if not out.get('wheel_axes'):
        if given:
            raise ConfigurationError(f'{", ".join(given)} set but wheel_axes is empty: declare '
                                     'the wheels with wheel_axes (3 numbers per wheel)')
        return None
    try:
        return Wheels(out['wheel_axes'], **{field: out.get(name) or () for name, field in
                                            _FIELDS.items()})
    except ValueError as err:
        raise ConfigurationError(str(err)) from None
