"""
ROS plumbing shared by the nodes and tools: helpers that take a node, no node of their own.

:mod:`.parameters` (one declarative table per node: declaration, validation,
the manual's table), :mod:`.state_publisher` (a body's state topics from an engine
snapshot, TF and IMU included), :mod:`.intake` (taking messages without an
executor callback each), :mod:`.conversions` (messages <-> numpy),
:mod:`.command_decoder` (torque_cmd messages into the engine's command values),
:mod:`.throttle` (throttled warnings), :mod:`.runner` (a node's life: signals,
bad configuration, clean shutdown) and :mod:`.client` (a private context and
node for tools and tests; starting and interrupting node processes).
"""
