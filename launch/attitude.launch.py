"""
Start the simulator, the analyzer and the Poinsot markers on a preset (full ROS 2 install).

    ros2 launch rigid_body_dynamics attitude.launch.py preset:=tennis_racket
    ros2 launch rigid_body_dynamics attitude.launch.py namespace:=sat1 real_time_factor:=4.0
    ros2 launch rigid_body_dynamics attitude.launch.py preset:=tennis_racket rviz:=true
    ros2 launch rigid_body_dynamics attitude.launch.py estimator:=true publish_clock:=true \
        real_time_factor:=20.0 params_file:=$(ros2 pkg prefix \
        rigid_body_dynamics)/share/rigid_body_dynamics/examples/estimator.yaml

Parameters come from config/<preset>.yaml (shared values under /**), or from
``params_file``; the arguments below override them. ``rviz:=true`` also starts
RViz with the package's rviz/attitude.rviz (TF, the odom pose, the applied
torque, the Poinsot and momentum-sphere markers) in the same namespace;
``estimator:=true`` the example attitude_estimator. With ``publish_clock:=true``
every node but the simulator runs on its /clock (``use_sim_time``).
"""

from launch import LaunchDescription
from launch.actions import DeclareLaunchArgument
from launch.conditions import IfCondition
from launch.substitutions import LaunchConfiguration, PathJoinSubstitution, PythonExpression
from launch_ros.actions import Node
from launch_ros.substitutions import FindPackageShare


def generate_launch_description():
    """Launch description: the three nodes, one config file, a few overrides, RViz."""
    preset = LaunchConfiguration('preset')
    namespace = LaunchConfiguration('namespace')
    share = FindPackageShare('rigid_body_dynamics')
    config = LaunchConfiguration('params_file')
    return LaunchDescription([
        DeclareLaunchArgument('preset', default_value='symmetric_top',
                              description='config/<preset>.yaml to load'),
        DeclareLaunchArgument('params_file',
                              default_value=PathJoinSubstitution([share, 'config',
                                                                  [preset, '.yaml']]),
                              description='the parameters file of every node (default: the '
                                          "preset's)"),
        DeclareLaunchArgument('estimator', default_value='false',
                              description='also start the example attitude_estimator'),
        DeclareLaunchArgument('namespace', default_value='',
                              description='namespace for both nodes (one body per namespace)'),
        DeclareLaunchArgument('frame_prefix',
                              default_value=PythonExpression(
                                  ["'", namespace, "/' if '", namespace, "' else ''"]),
                              description="prefix of the simulator's frame ids (default: "
                                          '<namespace>/, so bodies give distinct TF trees)'),
        DeclareLaunchArgument('real_time_factor', default_value='1.0',
                              description='simulated seconds per wall second; 0 = as fast '
                                          'as possible'),
        DeclareLaunchArgument('integrator', default_value='exact',
                              description='exact or rk4'),
        DeclareLaunchArgument('publish_clock', default_value='false',
                              description='publish /clock from the simulator'),
        DeclareLaunchArgument('marker_scale', default_value='1.0',
                              description='Poinsot markers: m per rad/s'),
        DeclareLaunchArgument('rviz', default_value='false',
                              description='also start rviz2 with rviz/attitude.rviz'),
        Node(package='rigid_body_dynamics', executable='attitude_simulator',
             name='attitude_simulator', namespace=namespace, output='screen',
             parameters=[config, {
                 'real_time_factor': LaunchConfiguration('real_time_factor'),
                 'integrator': LaunchConfiguration('integrator'),
                 'publish_clock': LaunchConfiguration('publish_clock'),
                 'frame_prefix': LaunchConfiguration('frame_prefix'),
             }]),
        Node(package='rigid_body_dynamics', executable='attitude_analyzer',
             name='attitude_analyzer', namespace=namespace, output='screen',
             parameters=[config, {'use_sim_time': LaunchConfiguration('publish_clock')}]),
        Node(package='rigid_body_dynamics', executable='attitude_estimator',
             name='attitude_estimator', namespace=namespace, output='screen',
             parameters=[config, {'use_sim_time': LaunchConfiguration('publish_clock')}],
             condition=IfCondition(LaunchConfiguration('estimator'))),
        Node(package='rigid_body_dynamics', executable='poinsot_visualizer',
             name='poinsot_visualizer', namespace=namespace, output='screen',
             parameters=[{'scale': LaunchConfiguration('marker_scale'),
                          'use_sim_time': LaunchConfiguration('publish_clock')}]),
        Node(package='rviz2', executable='rviz2', name='rviz2', namespace=namespace,
             arguments=['-d', PathJoinSubstitution([share, 'rviz', 'attitude.rviz'])],
             condition=IfCondition(LaunchConfiguration('rviz'))),
    ])
