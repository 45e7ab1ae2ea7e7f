"""
The package's ROS nodes, each a thin layer over the engine and the physics.

``simulator`` (attitude_simulator), ``fleet`` (attitude_fleet), ``analyzer``
(attitude_analyzer), ``poinsot`` (poinsot_visualizer), ``controller``
(attitude_controller) and ``entry`` (their console entry points). The
plumbing they share is in :mod:`rigid_body_dynamics.ros`.
"""

import os

# One BLAS thread in a node process, unless the user chose otherwise. The nodes' numpy work
# is small arrays at a steady rate; OpenBLAS' worker threads gain nothing on them and spin
# after every call: attitude_analyzer at 1 kHz odom measured 26-28 % of a core with the
# default threads (one worker at 12 % in `blas_thread_server`), 13-15 % with one. Set here,
# before numpy is first imported by `python -m rigid_body_dynamics.nodes.<node>` or by a
# console entry point; a process that imported numpy earlier keeps its threads.
os.environ.setdefault('OPENBLAS_NUM_THREADS', '1')
