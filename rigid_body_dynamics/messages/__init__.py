"""
Messages as data, without rclpy: the wire format and bags <-> the physics layer's samples.

:mod:`.cdr` reads the few fields the analysis needs from batches of serialised
messages straight into numpy; :mod:`.samples` turns messages (or their
batches) into stamped samples (:class:`~rigid_body_dynamics.physics.analysis.Trajectory`
rows); :mod:`.bags` reads and writes rosbag2 bags (MCAP or SQLite 3) with the
``rosbags`` library. The nodes, the tools and the tests use them; nothing here
needs a ROS install.
"""
