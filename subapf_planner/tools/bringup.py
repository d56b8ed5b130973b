"""``subapf-bringup``: simulator + planner as two processes, headless, on your ROS domain.

Checks its arguments first (the world file, the planner's params file and its values,
that the simulator can be the robot the params describe, the output paths, the
domain): an error is one line, ``subapf-bringup: error: ...``, and exit code 2,
before any process is started. Then starts ``sim_node`` and ``planner_node`` with
localhost-only discovery in ROS_DOMAIN_ID (0, ROS's default, when unset;
``--domain-id N``, or ``--private-domain`` for a free one of their own), sends the
world's goal on ``goal_pose``, waits for the simulator's outcome, stops both (also on
Ctrl-C or when a child dies: a node that fails to start is named, exit code 2),
prints the outcome, simulated time and path length, writes a trajectory PNG, and
exits 0 only when the goal was reached. One goal, one run: for more goals, start
``sim_node`` and ``planner_node`` yourself (the simulator serves one goal after
another). ``--foxglove [PORT]`` also starts ``foxglove_node``, which serves the run
live to Foxglove on ws://127.0.0.1:PORT.
"""

from __future__ import annotations

import argparse
from collections.abc import Iterator
import contextlib
from dataclasses import dataclass, field
import os
from pathlib import Path
import subprocess
import sys
from typing import Mapping

import numpy as np

from ..core.config import METHODS, ConfigError, load_params_file
from ..core.params import build
from ..core.robot import ROBOTS
from ..ros.paths import default_params_file, robot_params_file
from ..ros.processes import free_domain, join_domain, start, stop
from ..sim.metrics import path_length
from ..sim.world import World, WorldError, load_world

PROG = 'subapf-bringup'
#: --domain-id takes these (the tests lease domains above them: test/conftest.py).
DOMAIN_IDS = range(0, 102)
#: ROS_DOMAIN_ID may be any domain Fast DDS's default port mapping allows.
ENV_DOMAIN_IDS = range(0, 233)
#: The robot simulated when neither --robot nor the params file names one.
SIM_ROBOT = 'burger'


class BringupError(Exception):
    """An argument the run cannot start with: one line, exit code 2."""


def parse_args(argv: list[str] | None) -> argparse.Namespace:
    p = argparse.ArgumentParser(
        prog=PROG, description=' '.join(__doc__.split('\n\n')[1].replace('``', '').split()),
        epilog="Defaults: the planner's parameters are the package's config/planner.yaml "
        f'({_default_params()}) unless --params names another file (its '
        '"subapf_planner:" section, checked before anything starts), with the robot\'s '
        'config/robots/ file on top unless the params file is written for it (robot: '
        "NAME); the simulator is that robot, with the code's parameters (subapf-sim "
        '--help), --rate, --seed and --noise. Example: subapf-bringup --world '
        'sim/worlds/fig6d_big_wall.yaml --rate 5')
    p.add_argument('--world', required=True, help='world file (format v1, docs/worlds.md)')
    p.add_argument('--method', default=None, choices=METHODS,
                   help="override the params file's method")
    p.add_argument('--params', default=None,
                   help="planner params YAML (default: the package's config/planner.yaml)")
    p.add_argument('--robot', default=None, choices=sorted(ROBOTS),
                   help="the robot simulated and planned for (default: the params file's "
                   'robot, else the burger)')
    p.add_argument('--rate', type=float, default=1.0,
                   help='simulation speed-up, in [0.1, 100] (default: 1, real time)')
    p.add_argument('--record', default=None, help='write an MCAP bag of the run')
    p.add_argument('--record-topics', nargs='+', default=None, metavar='TOPIC',
                   help='topics to record (default: all of supervisor.RECORDED but the map)')
    p.add_argument('--png', default=None, help='trajectory plot (default: WORLD_NAME.png)')
    domain = p.add_mutually_exclusive_group()
    domain.add_argument('--domain-id', type=int, default=None,
                        help='ROS_DOMAIN_ID of the run, in [0, 101] (default: the '
                             "environment's ROS_DOMAIN_ID, 0 when unset)")
    domain.add_argument('--private-domain', action='store_true',
                        help='run in a domain no process on this machine uses (from 1-100): '
                             'RViz or Foxglove on your own domain will not see it')
    p.add_argument('--seed', type=int, default=0, help='simulator seed (default: 0)')
    p.add_argument('--noise', type=float, default=0.01,
                   help='laser range noise [m] (default: 0.01)')
    p.add_argument('--foxglove', type=int, nargs='?', const=8765, default=None, metavar='PORT',
                   help='serve the run live to Foxglove on ws://127.0.0.1:PORT (port 8765 '
                        'without a number; foxglove_node)')
    p.add_argument('--timeout', type=float, default=None,
                   help='wall-clock limit [s] (default: 2 x time_limit / rate + 30)')
    return p.parse_args(argv)


def _default_params() -> str:
    try:
        return str(default_params_file())
    except FileNotFoundError:
        return 'not found in this install'


def one_line(exc: BaseException) -> str:
    """An exception's message on one line (a YAML error spans several)."""
    return ' '.join(str(exc).split())


def check_params(path: str, robot: str | None = None) -> tuple[dict, str, tuple[str, ...]]:
    """The planner's values from the params file ``path`` and, unless it is written for
    the robot (its ``robot``), the robot's config/robots/ file on top, checked as the
    planner would check them; the robot simulated (``robot``, else the params file's,
    else the burger) and the params files in the order the planner loads them
    (BringupError, one line, when they cannot serve that robot)."""
    from ..ros.planner_node import GROUPS, OTHER_ROBOT
    try:
        values = load_params_file(path, 'subapf_planner')
        named = values.get('robot', SIM_ROBOT)
        if robot is None and named == OTHER_ROBOT:
            raise BringupError(f'{path} is for a robot of your own (robot: {OTHER_ROBOT}), '
                               'which the simulator cannot be; give --robot (one of '
                               f'{", ".join(ROBOTS)})')
        key = robot or (named if named in ROBOTS else SIM_ROBOT)
        files: tuple[str, ...] = (path,)
        if named != key:
            files = (path, str(robot_params_file(key)))
            values = {**values, **load_params_file(files[1], 'subapf_planner')}
        for cls in GROUPS:
            build(cls, values, ignore_unknown=True)
    except ConfigError as exc:
        text = one_line(exc)
        raise BringupError(text if text.startswith(str(path)) else f'{path}: {text}') from exc
    laser, frame = values.get('laser_frame', ROBOTS[key].laser_frame), ROBOTS[key].laser_frame
    if laser not in (frame, ''):
        raise BringupError(
            f'{path}: laser_frame is {laser}, but the simulator (the {key}) sends its '
            f'scans in {frame}: the planner would drop every one; set laser_frame: {frame}')
    return values, key, files


def choose_domain(args: argparse.Namespace, environ: Mapping[str, str]) -> tuple[int, str]:
    """The run's domain and where it comes from: --domain-id, --private-domain, else the
    environment's ROS_DOMAIN_ID, else 0 (ROS's default)."""
    if args.domain_id is not None:
        if args.domain_id not in DOMAIN_IDS:
            raise BringupError(f'--domain-id must be in [0, {DOMAIN_IDS[-1]}]')
        return args.domain_id, '--domain-id'
    if args.private_domain:
        return free_domain(), 'private: --private-domain'
    text = environ.get('ROS_DOMAIN_ID', '').strip()
    if not text:
        return 0, "ROS_DOMAIN_ID unset: ROS's default"
    try:
        domain = int(text)
    except ValueError:
        domain = -1
    if domain not in ENV_DOMAIN_IDS:
        raise BringupError(f'ROS_DOMAIN_ID={text!r} is not a domain id in [0, '
                           f'{ENV_DOMAIN_IDS[-1]}]')
    return domain, 'ROS_DOMAIN_ID'


@contextlib.contextmanager
def _stderr_silenced() -> Iterator[None]:
    """File descriptor 2 to /dev/null while in the block (a C library's own output)."""
    sys.stderr.flush()
    saved = os.dup(2)
    with open(os.devnull, 'w') as null:
        os.dup2(null.fileno(), 2)
    try:
        yield
    finally:
        os.dup2(saved, 2)
        os.close(saved)


def _writable_folder(path: str, option: str) -> None:
    folder = Path(path).resolve().parent
    if not folder.is_dir() or not os.access(folder, os.W_OK):
        raise BringupError(f'{option} {path}: cannot write in {folder}')


@dataclass(frozen=True)
class Plan:
    """A run, every argument checked."""

    world: World
    world_path: str
    #: The planner's params files, in the order it loads them.
    params: tuple[str, ...]
    method: str
    domain: int
    domain_source: str
    #: The robot simulated (core/robot.py ROBOTS).
    robot: str = SIM_ROBOT


def prepare(args: argparse.Namespace, environ: Mapping[str, str]) -> Plan:
    """Every check before a process starts (BringupError, one line, for the first
    problem)."""
    try:
        world = load_world(args.world)
    except WorldError as exc:
        raise BringupError(one_line(exc)) from exc
    if not 0.1 <= args.rate <= 100.0:
        raise BringupError('--rate must be in [0.1, 100]')
    if args.foxglove is not None and not 0 <= args.foxglove <= 65535:
        raise BringupError('--foxglove PORT must be in [0, 65535]')
    with _stderr_silenced():   # pybullet prints its build time when imported
        from ..ros.sim_node import GROUPS as SIM_GROUPS
    from ..ros.supervisor import RECORDED
    unknown = sorted(set(args.record_topics or ()) - set(RECORDED))
    if unknown:
        raise BringupError(f'cannot record {unknown}; choose from {list(RECORDED)}')
    sim = {'world': str(Path(args.world).resolve()), 'rate': args.rate, 'seed': args.seed,
           'range_noise': args.noise}
    try:
        for cls in SIM_GROUPS:
            build(cls, sim, ignore_unknown=True)
    except ConfigError as exc:
        raise BringupError(f'simulator: {one_line(exc)}') from exc
    for path, option in ((args.record, '--record'), (args.png or f'{world.name}.png', '--png')):
        if path:
            _writable_folder(path, option)
    params = str(Path(args.params).resolve()) if args.params else _default_params()
    if args.params and not Path(params).exists():
        raise BringupError(f'--params {args.params}: no such file')
    if args.params and not Path(params).is_file():
        raise BringupError(f'--params {args.params}: not a file')
    values, robot, files = check_params(params, args.robot)
    domain, source = choose_domain(args, environ)
    method = args.method or values.get('method', METHODS[0])
    return Plan(world, sim['world'], files, method, domain, source, robot)


@dataclass(frozen=True)
class RunResult:
    """One bringup run: outcome, simulated time [s], ground-truth path (k, 3) and the
    resident memory samples [MiB] of each node, taken once a second."""

    outcome: str
    sim_time: float
    path: np.ndarray
    method: str
    rss_mib: dict[str, list[float]] = field(default_factory=dict)


def run_once(world: World, world_path: str, params: str | tuple[str, ...], domain: int, *,
             method: str | None = None, rate: float = 1.0, seed: int = 0,
             sim_params: dict[str, float] | None = None, record: str | None = None,
             record_topics: list[str] | None = None, timeout: float | None = None,
             log_dir: Path | None = None, foxglove_port: int | None = None,
             robot: str = SIM_ROBOT) -> RunResult:
    """Start both nodes on ``domain`` (and foxglove_node serving on ``foxglove_port``),
    send the goal, wait for the outcome, stop them. ``params``: the planner's params
    file, or files in the order it loads them; ``robot``: the robot simulated.

    The nodes' output goes to the terminal, or to ``log_dir``/{sim,planner,foxglove}.log.
    """
    env = join_domain(domain)
    from ..ros import supervisor  # rclpy only after join_domain
    files = (params,) if isinstance(params, str) else tuple(params)
    planner_args = [arg for f in files for arg in ('--params-file', f)]
    planner_args += ['-p', 'use_sim_time:=true']
    if method:
        planner_args += ['-p', f'method:={method}']
    stamped = str(ROBOTS[robot].stamped_cmd_vel).lower()   # the base takes what it takes
    sim_args = ['-p', f'world:={world_path}', '-p', f'rate:={rate}', '-p', f'seed:={seed}',
                '-p', f'robot:={robot}', '-p', f'enable_stamped_cmd_vel:={stamped}',
                '-p', f'start_subscribers:={supervisor.START_SUBSCRIBERS}']
    for name, value in (sim_params or {}).items():
        sim_args += ['-p', f'{name}:={value}']
    timeout = timeout or 2.0 * world.time_limit / rate + 30.0 + supervisor.LISTEN_TIMEOUT
    if method is None:
        method = load_params_file(files[0]).get('method', METHODS[0])

    children: list[subprocess.Popen] = []
    sup = None
    nodes = {'sim_node': sim_args, 'planner_node': planner_args}
    if foxglove_port is not None:
        nodes['foxglove_node'] = ['-p', f'port:={foxglove_port}']
    try:
        children = [start(node, node_args, env, log=log_dir / f'{node.split("_")[0]}.log'
                          if log_dir else None) for node, node_args in nodes.items()]
        sup = supervisor.Supervisor(world, record, method, record_topics)
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
    sim_time = sup.outcome_time if sup.outcome_time is not None else sup.sim_time
    return RunResult(outcome, sim_time, path, sup.method, sup.rss_mib)


def main(argv: list[str] | None = None) -> int:
    args = parse_args(argv)
    try:
        plan = prepare(args, os.environ)
    except BringupError as exc:
        print(f'{PROG}: error: {exc}', file=sys.stderr)
        return 2
    world = plan.world
    print(f'{PROG}: world {world.name}, robot {plan.robot}, domain {plan.domain} '
          f'({plan.domain_source}), rate {args.rate}x', flush=True)
    result = run_once(world, plan.world_path, plan.params, plan.domain,
                      method=args.method, rate=args.rate, seed=args.seed,
                      sim_params={'range_noise': args.noise}, record=args.record,
                      record_topics=args.record_topics, timeout=args.timeout,
                      foxglove_port=args.foxglove, robot=plan.robot)
    if result.outcome.startswith('failed: ') and 'did not start' in result.outcome:
        print(f'{PROG}: error: {result.outcome[len("failed: "):]}; its own message is '
              'above', file=sys.stderr)
        return 2
    print(f'{PROG}: outcome {result.outcome}, simulated time {result.sim_time:.1f} s, '
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
