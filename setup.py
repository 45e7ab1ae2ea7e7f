"""Build script for the rigid_body_dynamics ament_python package."""

from glob import glob

from setuptools import find_packages, setup

package_name = 'rigid_body_dynamics'

setup(
    name=package_name,
    version='0.2.0',
    packages=find_packages(exclude=['test', 'test.*', 'benchmarks']),
    data_files=[
        ('share/ament_index/resource_index/packages', ['resource/' + package_name]),
        ('share/' + package_name, ['package.xml']),
        ('share/' + package_name + '/config', glob('config/*.yaml')),
        ('share/' + package_name + '/examples', glob('doc/examples/*.yaml')),
        ('share/' + package_name + '/launch', glob('launch/*.py')),
        ('share/' + package_name + '/rviz', glob('rviz/*.rviz')),
    ],
    install_requires=['setuptools'],
    zip_safe=True,
    maintainer='rigid_body_dynamics maintainers',
    maintainer_email='maintainers@rigid-body-dynamics.invalid',
    description='Rigid-body attitude simulator and motion analyser (Euler equations).',
    license='Apache-2.0',
    tests_require=['pytest'],
    entry_points={
        'console_scripts': [
            'rigid_body_demo = rigid_body_dynamics.tools.demo:main',
            'attitude_simulator = rigid_body_dynamics.nodes.entry:simulator',
            'attitude_analyzer = rigid_body_dynamics.nodes.entry:analyzer',
            'poinsot_visualizer = rigid_body_dynamics.nodes.entry:poinsot',
            'attitude_fleet = rigid_body_dynamics.nodes.entry:fleet',
            'attitude_controller = rigid_body_dynamics.nodes.entry:controller',
            'attitude_estimator = rigid_body_dynamics.nodes.entry:estimator',
            'rigid_body_report = rigid_body_dynamics.tools.report:main',
            'rigid_body_analyze = rigid_body_dynamics.tools.analyze:main',
            'rigid_body_campaign = rigid_body_dynamics.tools.campaign:main',
        ],
        # fixtures for users' topic-based tests; inert unless a test asks for them
        'pytest11': ['rigid_body_dynamics = rigid_body_dynamics.testing'],
    },
)
