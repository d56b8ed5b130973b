"""``subapf-bringup``: simulator + planner as two processes, headless, on a private domain.

Starts ``sim_node`` and ``planner_node`` with localhost-only discovery and a
ROS_DOMAIN_ID of their own, sends the world's goal on ``goal_pose``, waits for
the simulator's outcome, stops both (also on Ctrl-C or when a child dies),
prints the outcome, simulated time and path length, writes a trajectory PNG,
and exits 0 only when the goal was reached.
"""

from __future__ import annotations

import argparse
import os
from pathlib import Path
import random
import signal
import subprocess
import sys

import numpy as np

from .config import METHODS, load_config
from .episode import path_length
from .paths import default_params_file
from .processes import ros_env, start, stop
from .world import WorldError, load_world


def parse_args(argv: list[str] | None) -> argparse.Namespace:
    p = argparse.ArgumentParser(prog='subapf-bringup', description=__doc__.splitlines()[0])
    p.add_argument('--world', required=True, help='world file')
    p.add_argument('--method', default=None, choices=METHODS, help='override the params file')
    p.add_argument('--params', default=None, help='planner params YAML')
    p.add_argument('--rate', type=float, default=1.0, help='simulation speed-up (1 = real time)')
    p.add_argument('--record', default=None, help='write an MCAP bag of the run')
    p.add_argument('--record-topics', nargs='+', default=None, metavar='TOPIC',
                   help='topics to record (default: all of supervisor.RECORDED)')
    p.add_argument('--png', default=None, help='trajectory plot (default: WORLD_NAME.png)')
    p.add_argument('--domain-id', type=int, default=None, help='ROS_DOMAIN_ID (default: random)')
    p.add_argument('--seed', type=int, default=0, help='simulator seed')
    p.add_argument('--noise', type=float, default=0.01, help='laser range noise [m]')
    p.add_argument('--timeout', type=float, default=None,
                   help='wall-clock limit [s] (default: 2 x time_limit / rate + 30)')
    return p.parse_args(argv)


def main(argv: list[str] | None = None) -> int:
    args = parse_args(argv)
    try:
        world = load_world(args.world)
    except WorldError as exc:
        print(f'subapf-bringup: {exc}', file=sys.stderr)
        return 2
    if not 0.1 <= args.rate <= 100.0:
        print('subapf-bringup: --rate must be in [0.1, 100]', file=sys.stderr)
        return 2
    domain = args.domain_id if args.domain_id is not None else random.randint(1, 100)
    env = ros_env(domain)
    os.environ.update({k: env[k] for k in ('ROS_AUTOMATIC_DISCOVERY_RANGE', 'ROS_DOMAIN_ID')})
    params = str(Path(args.params or default_params_file()).resolve())
    world_path = str(Path(args.world).resolve())
    planner_args = ['--params-file', params, '-p', 'use_sim_time:=true']
    if args.method:
        planner_args += ['-p', f'method:={args.method}']
    sim_args = ['-p', f'world:={world_path}', '-p', f'rate:={args.rate}',
                '-p', f'seed:={args.seed}', '-p', f'range_noise:={args.noise}']
    timeout = args.timeout or 2.0 * world.time_limit / args.rate + 30.0
    print(f'subapf-bringup: world {world.name}, domain {domain}, rate {args.rate}x',
          flush=True)

    from .supervisor import Supervisor  # rclpy only after the environment is set
    children: list[subprocess.Popen] = []
    sup = None
    previous = signal.signal(signal.SIGTERM, lambda *_: (_ for _ in ()).throw(
        KeyboardInterrupt()))
    try:
        children = [start('sim_node', sim_args, env), start('planner_node', planner_args, env)]
        sup = Supervisor(world, args.record, args.method or load_config(params).method,
                         args.record_topics)
        outcome = sup.run(children, timeout)
    except KeyboardInterrupt:
        outcome = 'interrupted'
    finally:
        stop(children)
        signal.signal(signal.SIGTERM, previous)
        if sup is not None:
            sup.close()
    path = np.asarray(sup.path) if sup is not None and sup.path else np.zeros((0, 3))
    sim_time = sup.sim_time if sup is not None else 0.0
    print(f'subapf-bringup: outcome {outcome}, simulated time {sim_time:.1f} s, '
          f'path length {path_length(path):.2f} m', flush=True)
    if len(path):
        from .plots import plot_trajectories
        png = plot_trajectories(world, {sup.method or 'planner': path},
                                {sup.method or 'planner': outcome},
                                args.png or f'{world.name}.png')
        print(f'subapf-bringup: trajectory plot {png}')
    if args.record:
        print(f'subapf-bringup: recorded {args.record}')
    return 0 if outcome == 'reached' else 1


if __name__ == '__main__':
    sys.exit(main())
