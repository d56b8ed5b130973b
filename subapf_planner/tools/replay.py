"""``subapf-replay``: feed a recorded run through the planner and compare its cmd_vel.

The recorded ``scan``, ``odom`` and ``goal_pose`` go through the same
``PlannerController`` the node runs, in recorded order and simulated time (as
fast as possible); at each recorded ``cmd_vel`` stamp the controller ticks,
as the node's timer did. Prints count, max and mean |dv| and |dw| and the
first divergence; exit 0 when max |dv| and |dw| are within ``--tolerance``,
1 when not, 2 for an unusable bag or parameters.
"""

from __future__ import annotations

import argparse
from dataclasses import dataclass
import math
import random
import sys

import numpy as np

from ..bag.reader import BagError, read, topics
from ..bag.writer import McapRecorder
from ..core.config import METHODS, ConfigError, PlannerConfig, load_config, load_params_file
from ..core.controller import PlannerController, Supervision
from ..ros.conversions import (
    cmd_from_msg,
    cmd_to_msg,
    pose_from_odom,
    scan_from_msg,
    stamp_to_seconds,
)
from .paths import default_params_file

INPUTS = {'scan': 'sensor_msgs/msg/LaserScan', 'odom': 'nav_msgs/msg/Odometry',
          'goal': 'geometry_msgs/msg/PoseStamped'}
CMD_TYPES = ('geometry_msgs/msg/TwistStamped', 'geometry_msgs/msg/Twist')


@dataclass(frozen=True)
class Comparison:
    """Recorded vs replayed commands: times [s], (v, w) arrays (n, 2), NaN = none.

    ``skipped`` leading commands were published before the bag holds a scan, an
    odometry message and a goal (the recording started after the node did):
    they cannot be replayed and are left out of the comparison.
    """

    times: np.ndarray
    recorded: np.ndarray
    replayed: np.ndarray
    skipped: int = 0

    @property
    def diff(self) -> np.ndarray:
        d = np.abs(self.replayed - self.recorded)
        d = np.where(np.isnan(d), np.inf, d)
        d[:self.skipped] = 0.0
        return d

    def first_divergence(self, tol_v: float, tol_w: float) -> float | None:
        bad = (self.diff[:, 0] > tol_v) | (self.diff[:, 1] > tol_w)
        return float(self.times[np.argmax(bad)]) if np.any(bad) else None


def check_topics(path: str, names: dict[str, str]) -> None:
    """BagError naming what is missing or of the wrong type."""
    found = topics(path)
    for role, topic in names.items():
        want = CMD_TYPES if role == 'cmd_vel' else (INPUTS[role],)
        if topic not in found:
            raise BagError(f'{path}: no {topic} topic ({role}); topics: '
                           f'{", ".join(sorted(found)) or "none"}')
        if found[topic] not in want:
            raise BagError(f'{path}: {topic} is {found[topic]}, expected {" or ".join(want)}')


def replay(path: str, cfg: PlannerConfig, limits: Supervision,
           names: dict[str, str]) -> Comparison:
    """Run the controller over the bag; see the module docstring."""
    check_topics(path, names)
    role = {topic: r for r, topic in names.items()}
    events = []   # (sim time, order, role, payload)
    sim_now = 0.0
    for m in read(path, set(names.values())):
        r = role[m.topic]
        if r == 'scan':
            scan = scan_from_msg(m.message)
            sim_now = max(sim_now, scan.stamp)
            events.append((scan.stamp, 0, r, scan))
        elif r == 'odom':
            t = stamp_to_seconds(m.message.header.stamp)
            sim_now = max(sim_now, t)
            events.append((t, 0, r, (t, pose_from_odom(m.message))))
        elif r == 'goal':
            p = m.message.pose.position
            events.append((sim_now, 1, r, np.array([p.x, p.y], float)))
        else:
            t = stamp_to_seconds(m.message.header.stamp) if hasattr(m.message, 'header') \
                else sim_now
            events.append((t, 2, r, cmd_from_msg(m.message)))
    events.sort(key=lambda e: (e[0], e[1]))
    ctl = PlannerController(cfg, limits)
    times, recorded, replayed = [], [], []
    skipped = 0
    for t, _, r, payload in events:
        if r == 'scan':
            ctl.update_scan(payload, t)
        elif r == 'odom':
            if np.all(np.isfinite(payload[1])):
                ctl.update_odom(payload[0], payload[1], t)
        elif r == 'goal':
            if np.all(np.isfinite(payload)):
                ctl.set_goal(payload)
        else:
            leading = skipped == len(replayed) and (ctl.scan is None or ctl.pose is None
                                                    or ctl.goal is None)
            decision = ctl.tick(t)
            if leading:
                skipped += 1
                ctl.planner.previous = payload   # the node's state after what it published
            times.append(t)
            recorded.append(payload)
            replayed.append(decision.command if decision.command is not None
                            else (math.nan, math.nan))
    return Comparison(np.asarray(times), np.asarray(recorded, float).reshape(-1, 2),
                      np.asarray(replayed, float).reshape(-1, 2), skipped)


def write_commands(out: str, comparison: Comparison) -> None:
    """The replayed commands as /cmd_vel (TwistStamped) in an MCAP file."""
    from rclpy.serialization import serialize_message

    from ..ros.conversions import seconds_to_stamp
    rec = McapRecorder(out)
    try:
        rec.add_topic('/cmd_vel', CMD_TYPES[0])
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
    args = p.parse_args(argv)
    try:
        params = args.params or default_params_file()
        cfg = load_config(params, method=args.method)
        node = load_params_file(params)
        limits = Supervision(**{k: float(node.get(k, getattr(Supervision(), k)))
                                for k in Supervision.__dataclass_fields__})
        names = {'scan': args.scan_topic, 'odom': args.odom_topic, 'goal': args.goal_topic,
                 'cmd_vel': args.cmd_topic}
        if args.through_node:
            from ..ros.replay_dds import replay_through_node
            domain = args.domain_id if args.domain_id is not None else random.randint(1, 100)
            comparison = replay_through_node(args.bag, str(params), names, args.method, domain)
        else:
            comparison = replay(args.bag, cfg, limits, names)
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
