"""
The package's ROS nodes, each a thin layer over the engine and the physics.

``simulator`` (attitude_simulator), ``fleet`` (attitude_fleet), ``analyzer``
(attitude_analyzer), ``poinsot`` (poinsot_visualizer), ``controller``
(attitude_controller) and ``entry`` (their console entry points). The
plumbing they share is in :mod:`rigid_body_dynamics.ros`.
"""
