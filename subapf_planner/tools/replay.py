"""``subapf-replay``: feed a recorded run through the planner and compare its cmd_vel.

In process (ros/replay.py: the node's input checks and decision loop over the
bag's events) or, with ``--through-node``, through a planner_node process over
DDS (ros/replay_dds.py). Prints count, max and mean |dv| and |dw| and the first
divergence; exit 0 when max |dv| and |dw| are within ``--tolerance``, 1 when not,
2 for an unusable bag or parameters.
"""

from __future__ import annotations

import argparse
import random
import sys

import numpy as np

from ..bag.comparison import Comparison
from ..bag.events import STAMPED_CMD, TAKEN_TOPIC
from ..bag.reader import BagError
from ..bag.writer import McapRecorder
from ..core.config import METHODS, ConfigError, load_config, load_params_file
from ..core.loop import Supervision
from ..core.params import build
from ..ros.conversions import cmd_to_msg, seconds_to_stamp
from ..ros.intake import Intake
from ..ros.paths import default_params_file
from ..ros.planner_node import NodeOptions
from ..ros.replay import replay


def write_commands(out: str, comparison: Comparison) -> None:
    """The replayed commands as /cmd_vel (TwistStamped) in an MCAP file."""
    from rclpy.serialization import serialize_message

    rec = McapRecorder(out)
    try:
        rec.add_topic('/cmd_vel', STAMPED_CMD)
        for t, (v, w) in zip(comparison.times, comparison.replayed, strict=True):
            if np.isfinite(v):
                msg = cmd_to_msg(v, w, True, seconds_to_stamp(t))
                rec.write('/cmd_vel', serialize_message(msg), int(t * 1e9))
    finally:
        rec.close()


def main(argv: list[str] | None = None) -> int:
    p = argparse.ArgumentParser(prog='subapf-replay', description=__doc__.splitlines()[0])
    p.add_argument('bag', help='MCAP file recorded by subapf-bringup --record or subapf-record')
    p.add_argument('--params', default=None, help='planner params YAML')
    p.add_argument('--method', default=None, choices=METHODS)
    p.add_argument('-o', '--output', default=None, help='write the replayed cmd_vel here')
    p.add_argument('--tolerance', type=float, default=1e-3,
                   help='max |dv| [m/s] and |dw| [rad/s] accepted (default 1e-3)')
    p.add_argument('--through-node', action='store_true',
                   help='replay through a planner_node process over DDS instead of in-process')
    p.add_argument('--domain-id', type=int, default=None,
                   help='ROS_DOMAIN_ID for --through-node (default: random)')
    p.add_argument('--scan-topic', default='/scan')
    p.add_argument('--odom-topic', default='/odom')
    p.add_argument('--goal-topic', default='/goal_pose')
    p.add_argument('--cmd-topic', default='/cmd_vel')
    p.add_argument('--taken-topic', default=TAKEN_TOPIC,
                   help="the planner node's ~/taken: when the bag has it, each input is "
                        'replayed at the tick the node took it')
    args = p.parse_args(argv)
    try:
        params = args.params or default_params_file()
        cfg = load_config(params, method=args.method)
        values = load_params_file(params)
        limits = build(Supervision, values, ignore_unknown=True)
        options = build(NodeOptions, values, ignore_unknown=True)
        names = {'scan': args.scan_topic, 'odom': args.odom_topic, 'goal': args.goal_topic,
                 'cmd_vel': args.cmd_topic, 'taken': args.taken_topic}
        if args.through_node:
            from ..ros.replay_dds import replay_through_node
            domain = args.domain_id if args.domain_id is not None else random.randint(1, 100)
            comparison = replay_through_node(args.bag, str(params), names, args.method, domain)
        else:
            comparison = replay(args.bag, cfg, limits, names,
                                Intake(options.laser_frame, options.odom_frame,
                                       options.map_frame))
    except (BagError, ConfigError) as exc:
        print(f'subapf-replay: {exc}', file=sys.stderr)
        return 2
    n = len(comparison.times)
    if n == comparison.skipped:
        print(f'subapf-replay: {args.bag}: no {args.cmd_topic} messages to compare',
              file=sys.stderr)
        return 2
    d = comparison.diff[comparison.skipped:]
    finite = np.isfinite(d).all(axis=1)
    first = comparison.first_divergence(args.tolerance, args.tolerance)
    print(f'commands compared: {len(d)} (replay silent on {len(d) - int(finite.sum())}; '
          f'{comparison.skipped} before the bag had scan, odom and goal, not replayable)')
    if finite.any():
        print(f'|dv| max {d[finite, 0].max():.6f} mean {d[finite, 0].mean():.6f} m/s; '
              f'|dw| max {d[finite, 1].max():.6f} mean {d[finite, 1].mean():.6f} rad/s')
    within = int(np.sum((d[:, 0] <= args.tolerance) & (d[:, 1] <= args.tolerance)))
    print(f'within tolerance: {within} of {len(d)}')
    print('first divergence: ' + ('none' if first is None else f't = {first:.3f} s'))
    if args.output:
        write_commands(args.output, comparison)
        print(f'replayed commands written to {args.output}')
    return 0 if first is None else 1


if __name__ == '__main__':
    sys.exit(main())
