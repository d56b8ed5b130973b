"""``subapf-bringup``: simulator + planner as two processes, headless, on a private domain.

Starts ``sim_node`` and ``planner_node`` with localhost-only discovery and a
ROS_DOMAIN_ID of their own, sends the world's goal on ``goal_pose``, waits for
the simulator's outcome, stops both (also on Ctrl-C or when a child dies),
prints the outcome, simulated time and path length, writes a trajectory PNG,
and exits 0 only when the goal was reached. ``--foxglove [PORT]`` also starts
``foxglove_node``, which serves the run live to Foxglove on ws://127.0.0.1:PORT.
"""

from __future__ import annotations

import argparse
from dataclasses import dataclass, field
from pathlib import Path
import random
import subprocess
import sys

import numpy as np

from ..core.config import METHODS, load_config
from ..ros.paths import default_params_file
from ..ros.processes import join_domain, start, stop
from ..sim.metrics import path_length
from ..sim.world import World, WorldError, load_world


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
    p.add_argument('--foxglove', type=int, nargs='?', const=8765, default=None, metavar='PORT',
                   help='serve the run live to Foxglove on ws://127.0.0.1:PORT (default '
                        'port 8765; foxglove_node)')
    p.add_argument('--timeout', type=float, default=None,
                   help='wall-clock limit [s] (default: 2 x time_limit / rate + 30)')
    return p.parse_args(argv)


@dataclass(frozen=True)
class RunResult:
    """One bringup run: outcome, simulated time [s], ground-truth path (k, 3) and the
    resident memory samples [MiB] of each node, taken once a second."""

    outcome: str
    sim_time: float
    path: np.ndarray
    method: str
    rss_mib: dict[str, list[float]] = field(default_factory=dict)


def run_once(world: World, world_path: str, params: str, domain: int, *,
             method: str | None = None, rate: float = 1.0, seed: int = 0,
             sim_params: dict[str, float] | None = None, record: str | None = None,
             record_topics: list[str] | None = None, timeout: float | None = None,
             log_dir: Path | None = None, foxglove_port: int | None = None) -> RunResult:
    """Start both nodes on ``domain`` (and foxglove_node serving on ``foxglove_port``),
    send the goal, wait for the outcome, stop them.

    The nodes' output goes to the terminal, or to ``log_dir``/{sim,planner,foxglove}.log.
    """
    env = join_domain(domain)
    planner_args = ['--params-file', params, '-p', 'use_sim_time:=true']
    if method:
        planner_args += ['-p', f'method:={method}']
    sim_args = ['-p', f'world:={world_path}', '-p', f'rate:={rate}', '-p', f'seed:={seed}']
    for name, value in (sim_params or {}).items():
        sim_args += ['-p', f'{name}:={value}']
    timeout = timeout or 2.0 * world.time_limit / rate + 30.0

    from ..ros.supervisor import Supervisor  # rclpy only after the environment is set
    children: list[subprocess.Popen] = []
    sup = None
    nodes = {'sim_node': sim_args, 'planner_node': planner_args}
    if foxglove_port is not None:
        nodes['foxglove_node'] = ['-p', f'port:={foxglove_port}']
    try:
        children = [start(node, node_args, env, log=log_dir / f'{node.split("_")[0]}.log'
                          if log_dir else None) for node, node_args in nodes.items()]
        sup = Supervisor(world, record, method or load_config(params).method, record_topics)
        outcome = sup.run(children, timeout, names=tuple(nodes))
    except KeyboardInterrupt:   # before the supervisor took over the signals
        outcome = 'interrupted'
    finally:
        # the planner first: its zero velocity, acknowledged by the simulator's reliable
        # cmd_vel subscription before the planner exits (ros/spinning.py), stops the
        # robot; then the simulator
        for child in reversed(children):
            stop([child])
        if sup is not None:
            sup.close()
    if sup is None:
        return RunResult(outcome, 0.0, np.zeros((0, 3)), method or '')
    path = np.asarray(sup.path) if sup.path else np.zeros((0, 3))
    return RunResult(outcome, sup.sim_time, path, sup.method, sup.rss_mib)


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
    if args.foxglove is not None and not 0 <= args.foxglove <= 65535:
        print('subapf-bringup: --foxglove PORT must be in [0, 65535]', file=sys.stderr)
        return 2
    if args.domain_id is not None and not 0 <= args.domain_id <= 101:
        print('subapf-bringup: --domain-id must be in [0, 101]', file=sys.stderr)
        return 2
    from ..ros.supervisor import RECORDED
    unknown = sorted(set(args.record_topics or ()) - set(RECORDED))
    if unknown:
        print(f'subapf-bringup: cannot record {unknown}; choose from {list(RECORDED)}',
              file=sys.stderr)
        return 2
    domain = args.domain_id if args.domain_id is not None else random.randint(1, 100)
    params = str(Path(args.params or default_params_file()).resolve())
    print(f'subapf-bringup: world {world.name}, domain {domain}, rate {args.rate}x',
          flush=True)
    result = run_once(world, str(Path(args.world).resolve()), params, domain,
                      method=args.method, rate=args.rate, seed=args.seed,
                      sim_params={'range_noise': args.noise}, record=args.record,
                      record_topics=args.record_topics, timeout=args.timeout,
                      foxglove_port=args.foxglove)
    print(f'subapf-bringup: outcome {result.outcome}, simulated time {result.sim_time:.1f} s, '
          f'path length {path_length(result.path):.2f} m', flush=True)
    if len(result.path):
        from ..ros.sim_node import TICK
        from .plots import plot_trajectories
        png = plot_trajectories(world, {result.method: result.path},
                                {result.method: result.outcome},
                                args.png or f'{world.name}.png', period=TICK)
        print(f'subapf-bringup: trajectory plot {png}')
    if args.record:
        print(f'subapf-bringup: recorded {args.record}')
    return 0 if result.outcome == 'reached' else 1


if __name__ == '__main__':
    sys.exit(main())
