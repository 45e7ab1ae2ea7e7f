"""
Declaring and validating node parameters: descriptors with units and ranges.

Numbers are declared with dynamic typing so that ``-p inertia:=[1,2,3]`` (an
integer array) is accepted and converted, instead of failing on
``INTEGER_ARRAY`` against ``DOUBLE_ARRAY`` (ros2/rclcpp#979); the values are
then checked here, with a reason for every refusal.
"""

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
