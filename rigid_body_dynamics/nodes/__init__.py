"""Thin rclpy nodes over :mod:`rigid_body_dynamics.physics`."""
