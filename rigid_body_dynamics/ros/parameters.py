"""
Declaring and validating node parameters: descriptors with units and ranges.

Numbers are declared with dynamic typing so that ``-p inertia:=[1,2,3]`` (an
integer array) is accepted and converted, instead of failing on
``INTEGER_ARRAY`` against ``DOUBLE_ARRAY`` (ros2/rclcpp#979); the values are
then checked here, with a reason for every refusal.
"""

from dataclasses import dataclass
import math

from rcl_interfaces.msg import FloatingPointRange, IntegerRange, ParameterDescriptor
from rcl_interfaces.msg import SetParametersResult


class ConfigurationError(ValueError):
    """A parameter value the node cannot run with; the message says why."""


def descriptor(description, read_only=False, low=None, high=None, constraints='',
               dynamic_typing=False, integer=False):
    """
    Build a ParameterDescriptor: description (with units), optional range, constraints.

    The range [low, high] is a floating-point one, or an integer one with
    ``integer=True``; rclpy refuses values outside it, also at start-up.
    """
    desc = ParameterDescriptor(description=description, read_only=read_only,
                               additional_constraints=constraints,
                               dynamic_typing=dynamic_typing)
    if low is not None and integer:
        desc.integer_range = [IntegerRange(from_value=int(low), to_value=int(high), step=1)]
    elif low is not None:
        desc.floating_point_range = [FloatingPointRange(from_value=float(low),
                                                        to_value=float(high), step=0.0)]
    return desc


def as_float(name, value, low=-math.inf, high=math.inf):
    """Return ``value`` as a finite float within [low, high], or raise ConfigurationError."""
    if isinstance(value, bool) or not isinstance(value, (int, float)):
        raise ConfigurationError(f'{name} must be a number, got {value!r}')
    value = float(value)
    if not math.isfinite(value):
        raise ConfigurationError(f'{name} must be finite, got {value!r}')
    if not low <= value <= high:
        raise ConfigurationError(f'{name} must be within [{low:g}, {high:g}], got {value:g}')
    return value


def as_vector(name, value, size):
    """Return ``value`` as a tuple of ``size`` finite floats, or raise ConfigurationError."""
    try:
        items = list(value)
    except TypeError:
        raise ConfigurationError(f'{name} must be a list of {size} numbers, got {value!r}') \
            from None
    if len(items) != size:
        raise ConfigurationError(f'{name} must have {size} numbers, got {len(items)}')
    return tuple(as_float(f'{name}[{i}]', v) for i, v in enumerate(items))


def as_strings(name, value, size):
    """Return ``value`` as a tuple of ``size`` strings, or raise ConfigurationError."""
    if isinstance(value, str) or not isinstance(value, (list, tuple)) or len(value) != size \
            or not all(isinstance(v, str) for v in value):
        raise ConfigurationError(f'{name} must be a list of {size} strings, got {value!r}')
    return tuple(value)


def number_list(name):
    """Return a converter of a list of any length into a tuple of finite floats ('double[]')."""
    def convert(value):
        try:
            items = list(value)
        except TypeError:
            raise ConfigurationError(f'{name} must be a list of numbers, got {value!r}') \
                from None
        return as_vector(name, items, len(items))
    return convert


def check_change(logger, validate, values):
    """
    Run ``validate(values)`` for an on-set-parameters callback, without side effects.

    Returns a successful SetParametersResult, or a refused one whose reason is
    the ConfigurationError's message (also logged as a warning).
    """
    try:
        validate(values)
    except ConfigurationError as err:
        logger.warn(f'parameter change refused: {err}')
        return SetParametersResult(successful=False, reason=str(err))
    return SetParametersResult(successful=True)


@dataclass(frozen=True)
class Param:
    """
    One node parameter: declaration, validation and its row in the manual from one place.

    ``kind``: 'double', 'double[N]', 'double[3|6]', 'int', 'bool', 'string' or
    'string[N]' (a list of N strings).
    ``default``: the value, or a callable of the node returning it (it may
    read parameters declared before it, e.g. the preset); None for an
    optional parameter that is unset.
    ``shown``: the default as the manual shows it (e.g. '1000.0 Hz', 'preset').
    ``text``: what it means, with units; the descriptor's description and the
    manual's text. ``low`` / ``high``: the inclusive range (rclpy enforces it
    for numbers); ``above_low``: ``low`` itself is refused too (a tolerance of 0
    would switch its check off; rclpy's ranges are inclusive, so the node
    refuses it with the reason); ``choices``: allowed strings; ``convert(value)``: a custom
    check returning the converted value (ConfigurationError with the reason).
    """

    name: str
    kind: str
    default: object
    shown: str
    text: str
    low: object = None
    high: object = None
    read_only: bool = False
    choices: tuple = ()
    convert: object = None
    above_low: bool = False

    def descriptor(self):
        """Build the ParameterDescriptor of this parameter."""
        constraints = f'one of: {", ".join(self.choices)}' if self.choices else ''
        # doubles take integers too (-p inertia:=[1,2,3]); an int stays strictly typed
        return descriptor(self.text, read_only=self.read_only, low=self.low, high=self.high,
                          constraints=constraints, integer=self.kind == 'int',
                          dynamic_typing=self.kind.startswith('double')
                          or self.default is None)

    def check(self, value):
        """Return the value converted, or raise ConfigurationError saying why."""
        if self.default is None and (value is None or (hasattr(value, '__len__')
                                                       and len(value) == 0)):
            return None
        if self.convert is not None:
            return self.convert(value)
        if self.kind == 'double':
            low = -math.inf if self.low is None else self.low
            high = math.inf if self.high is None else self.high
            value = as_float(self.name, value, low, high)
            if self.above_low and value == low:
                raise ConfigurationError(f'{self.name} must be greater than {low:g}, got '
                                         f'{value:g}')
            return value
        if self.kind.startswith('double['):
            return as_vector(self.name, value, int(self.kind[7:-1]))
        if self.kind.startswith('string['):
            return as_strings(self.name, value, int(self.kind[7:-1]))
        if self.kind == 'int':
            if isinstance(value, bool) or not isinstance(value, int):
                raise ConfigurationError(f'{self.name} must be an integer, got {value!r}')
            return value
        if self.kind == 'bool':
            return bool(value)
        if self.choices and value not in self.choices:
            raise ConfigurationError(f'{self.name} must be one of {", ".join(self.choices)}, '
                                     f'got {value!r}')
        return value

    def row(self):
        """Return this parameter's row of the manual's table (Markdown)."""
        limits = ''
        if self.low is not None and self.high is not None and self.kind in ('double', 'int'):
            limits = f'{self.low:g} .. {self.high:g}'
            if self.above_low:
                limits = f'> {self.low:g}, <= {self.high:g}'
        elif self.choices:
            limits = ', '.join(self.choices)
        cells = [f'`{self.name}`', self.kind, self.shown, limits,
                 'yes' if self.read_only else '', self.text]
        return '| ' + ' | '.join(c.replace('|', '\\|') for c in cells) + ' |'


class ParameterTable:
    """
    The parameters of one node: declare them all, validate a set of values, document them.

    ``cross_checks``: functions ``check(values, out)`` run after every value
    is converted (``out``), for rules between parameters; they may add
    derived entries to ``out`` and raise ConfigurationError.
    """

    def __init__(self, params, cross_checks=()):
        self.params = {p.name: p for p in params}
        self.cross_checks = tuple(cross_checks)

    def declare(self, node):
        """Declare every parameter on ``node`` in order; return their values."""
        for p in self.params.values():
            default = p.default(node) if callable(p.default) else p.default
            node.declare_parameter(p.name, default, p.descriptor())
        return self.values(node)

    def values(self, node):
        """Return the current raw values of the table's parameters on ``node``."""
        return {name: node.get_parameter(name).value for name in self.params}

    def resolve(self, given):
        """
        Return every parameter's raw value without a node: ``given``'s, else the default.

        ``given``: name -> value, as a parameters file sets them. Defaults that
        depend on another parameter (a preset's inertia) read the values resolved
        before them, in declaration order, as a node's declaration does. A name the
        table does not have is refused (ConfigurationError): a misspelt name must
        not leave the default in its place.
        """
        unknown = sorted(set(given) - set(self.params))
        if unknown:
            raise ConfigurationError(f'unknown parameter(s) {", ".join(unknown)}')
        values = {}
        source = _Resolved(values)
        for p in self.params.values():
            if p.name in given:
                values[p.name] = given[p.name]
            else:
                values[p.name] = p.default(source) if callable(p.default) else p.default
        return values

    def validate(self, values):
        """Convert and check ``values`` (name -> raw value); ConfigurationError says why."""
        out = {name: self.params[name].check(value) for name, value in values.items()
               if name in self.params}
        for check in self.cross_checks:
            check(values, out)
        return out

    def on_set(self, node, params):
        """Validate a change for an on-set-parameters callback (no side effects)."""
        values = self.values(node)
        values.update({p.name: p.value for p in params if p.name in self.params})
        return check_change(node.get_logger(), self.validate, values)

    def markdown(self):
        """Return the manual's parameter table (Markdown), in declaration order."""
        return '\n'.join(['| name | type | default | range | read-only | meaning |',
                          '| --- | --- | --- | --- | --- | --- |']
                         + [p.row() for p in self.params.values()])


class _Resolved:
    """The values resolved so far, read as a node's parameters (``get_parameter(name).value``)."""

    def __init__(self, values):
        self._values = values

    def get_parameter(self, name):
        """Return the resolved value of ``name`` as an object with ``value``."""
        return _Value(self._values[name])


@dataclass(frozen=True)
class _Value:
    value: object


def write_parameters_file(sections):
    """
    Write ``sections`` ({node key: {name: value}}) as a ROS parameters file; return its path.

    Each key ('/**', '/**/attitude_simulator', ...) gets its ``ros__parameters``; the
    file is a temporary one, for the caller to remove.
    """
    import tempfile

    import yaml
    with tempfile.NamedTemporaryFile('w', suffix='.yaml', delete=False) as f:
        yaml.safe_dump({key: {'ros__parameters': values} for key, values in sections.items()},
                       f)
    return f.name
