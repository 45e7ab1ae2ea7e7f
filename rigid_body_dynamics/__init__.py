"""
Rigid-body attitude simulation and analysis for ROS 2.

The physics lives in :mod:`rigid_body_dynamics.physics` (numpy/scipy only);
the ROS nodes in :mod:`rigid_body_dynamics.nodes` are thin layers over it.
"""
