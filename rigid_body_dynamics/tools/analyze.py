"""
rigid_body_analyze: the analyzer's findings from a recorded bag.

    rigid_body_analyze run/                      # a rosbag2 folder (MCAP or sqlite3)
    rigid_body_analyze run.mcap --json           # a bare MCAP file; one JSON object
    rigid_body_analyze run/ --odom-topic /sat1/odom --inertia 1 2 3 --start 5 --end 25

The same :func:`~rigid_body_dynamics.physics.analysis.analyse` as the live
``attitude_analyzer``, on the samples read exactly as it reads them (frames
honoured, integer-ns stamps, the last segment after a reset). Exit 0 with
findings, 2 with a one-line error (unreadable bag, missing or wrong topic, no
inertia, no sample).
"""

import argparse
import json
import sys

from .. import optional
from ..messages.bags import BagError, read_trajectory
from ..physics.analysis import analyse, Tolerances


def main(argv=None):
    """Console entry point."""
    parser = argparse.ArgumentParser(
        prog='rigid_body_analyze', description='Findings of attitude_analyzer from a bag.')
    parser.add_argument('path', help='rosbag2 folder, .mcap or .db3 file')
    parser.add_argument('--odom-topic', help='nav_msgs/Odometry topic (default: the only one)')
    parser.add_argument('--torque-topic', help='geometry_msgs/WrenchStamped topic of the applied '
                        'torque (default: applied_torque beside the odom topic, if any)')
    parser.add_argument('--inertia', type=float, nargs='+', metavar='I',
                        help='3 principal moments or 6 tensor elements Ixx Iyy Izz Ixy Ixz Iyz '
                        '(kg m^2; default: the latched InertiaStamped in the bag)')
    parser.add_argument('--start', type=float, help="s from the first sample's stamp")
    parser.add_argument('--end', type=float, help="s from the first sample's stamp")
    parser.add_argument('--json', action='store_true', help='one JSON object on stdout')
    for name, default, text in (('energy-tolerance', 1e-6, 'relative drift of T'),
                                ('momentum-tolerance', 1e-6, 'drift of |L| and L direction'),
                                ('balance-tolerance', 1e-2, 'balance residual under torque'),
                                ('rate-tolerance', 1e-6, 'measured against predicted rates')):
        parser.add_argument(f'--{name}', type=float, default=default,
                            help=f'{text} (default {default:g})')
    args = parser.parse_args(argv)
    if args.inertia is not None and len(args.inertia) not in (3, 6):
        parser.error('--inertia takes 3 moments or 6 tensor elements')
    try:
        tolerances = Tolerances(energy=args.energy_tolerance, momentum=args.momentum_tolerance,
                                balance=args.balance_tolerance, rate=args.rate_tolerance)
    except ValueError as err:             # a tolerance <= 0: the reason, one line
        parser.error(str(err))
    try:
        optional.require('rosbags')
        traj, info = read_trajectory(args.path, args.odom_topic, args.torque_topic,
                                     args.inertia, args.start, args.end)
    except (BagError, optional.MissingDependency) as err:
        print(f'rigid_body_analyze: {err}', file=sys.stderr)
        return 2
    found = analyse(traj, tolerances=tolerances)
    dropped = {k: v for k, v in info.dropped.items() if v}
    if args.json:
        out = found.to_dict()
        out['bag'] = {'path': info.path, 'odom_topic': info.odom_topic,
                      'torque_topic': info.torque_topic, 'inertia': info.inertia_source,
                      'odom_messages': info.odom_messages, 'segments': info.segments,
                      'dropped': dropped,
                      'first_stamp_ns': int(traj.origin_ns + traj.t_ns[0])}
        print(json.dumps(out, allow_nan=False))
        return 0
    print(f'{info.path}: {info.odom_topic} ({info.odom_messages} messages'
          + (f', torque from {info.torque_topic}' if info.torque_topic else ', no torque topic')
          + f', inertia from {info.inertia_source}'
          + (f', {info.segments} segments after resets or gaps: the last analysed'
             if info.segments > 1 else '')
          + (f'; dropped: {", ".join(f"{v} {k}" for k, v in dropped.items())}' if dropped else '')
          + ')')
    print('\n'.join(found.lines()))
    return 0


if __name__ == '__main__':
    sys.exit(main())
