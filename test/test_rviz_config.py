"""
rviz/attitude.rviz names only what the nodes publish (RViz itself cannot run here).

The file is read as YAML, as RViz reads it; its topics (relative, resolved in
the nodes' namespace), their message types, the fixed frame and the marker
namespaces are compared with what a running attitude_simulator and
poinsot_visualizer publish over real topics.
"""

import os

from nav_msgs.msg import Odometry
from visualization_msgs.msg import MarkerArray
import yaml

ROOT = os.path.join(os.path.dirname(__file__), '..')
RVIZ = os.path.join(ROOT, 'rviz', 'attitude.rviz')

#: RViz display class -> the message type it subscribes to.
DISPLAY_TYPES = {
    'rviz_default_plugins/Odometry': 'nav_msgs/msg/Odometry',
    'rviz_default_plugins/Wrench': 'geometry_msgs/msg/WrenchStamped',
    'rviz_default_plugins/MarkerArray': 'visualization_msgs/msg/MarkerArray',
}


def _config():
    with open(RVIZ) as f:
        return yaml.safe_load(f)


def test_the_config_shows_tf_the_pose_and_the_markers():
    manager = _config()['Visualization Manager']
    classes = [d['Class'] for d in manager['Displays']]
    for wanted in ('rviz_default_plugins/TF', 'rviz_default_plugins/Odometry',
                   'rviz_default_plugins/MarkerArray'):
        assert wanted in classes
    assert all(d['Enabled'] for d in manager['Displays'])


def test_topics_frames_and_namespaces_are_what_the_nodes_publish(launch, probe):
    launch('rigid_body_dynamics.nodes.simulator', '-p', 'preset:=tennis_racket',
           '-r', '__node:=attitude_simulator', name='sim')
    launch('rigid_body_dynamics.nodes.poinsot', '-r', '__node:=poinsot_visualizer', name='viz')
    odom = probe.subscribe(Odometry, 'odom')
    arrays = probe.subscribe(MarkerArray, 'poinsot_markers')
    probe.spin_until(lambda: odom and len(arrays) >= 3, 30.0, 'odom and 3 marker arrays')
    published = {}
    for node in ('attitude_simulator', 'poinsot_visualizer'):
        probe.spin_until(lambda: probe.endpoints('pub', node), 20.0, f'the publishers of {node}')
        published.update(probe.endpoints('pub', node))

    manager = _config()['Visualization Manager']
    world = odom[-1].header.frame_id
    assert manager['Global Options']['Fixed Frame'] == world == 'odom'
    assert manager['Views']['Current']['Target Frame'] == world
    namespaces = {m.ns for m in arrays[-1].markers}
    assert {m.header.frame_id for m in arrays[-1].markers} == {world}
    shown = 0
    for display in manager['Displays']:
        if 'Reference Frame' in display:
            assert display['Reference Frame'] == world
        if 'Topic' not in display:
            continue
        topic = '/' + display['Topic']['Value']      # relative: the nodes' namespace, here /
        assert topic in published, f'{display["Name"]}: nobody publishes {topic}'
        assert published[topic] == DISPLAY_TYPES[display['Class']]
        if 'Namespaces' in display:
            assert set(display['Namespaces']) == namespaces
        shown += 1
    assert shown == 3
