"""``subapf-bench``: the package's default, the paper's ablation (Fig. 6) and the DWA
baseline on many worlds, side by side.

Every (world, method) run steps the simulator and the node's decision loop in
lockstep in one process (sim/episode.py); ``--jobs`` spreads the worlds over
processes, each drawing its world's Fig. 6-style PNG, and ``--cluster`` over the
workers of a Dask distributed cluster (the same results.json but the timings).
Writes ``results.json``, ``summary.md`` and the PNGs to --out. One robot (``--robot``,
core/robot.py: the simulator's body, wheels and lidar) and one parameter file (default:
the package's config/planner.yaml with the robot's config/robots/ file on top) for all
worlds; a method may name its attraction field (``subharmonic_sampling:euclidean`` is
the paper's method exactly).
results.json's ``meta`` says how it was produced (command line, package version, git
commit, date): ``subapf-results`` puts it under the tables of docs/results.md.
"""

from __future__ import annotations

import argparse
from collections.abc import Iterator
from concurrent.futures import Executor, ProcessPoolExecutor
import contextlib
import dataclasses
import datetime
import functools
import importlib.metadata
import json
import math
from pathlib import Path
import re
import shlex
import statistics
import subprocess
import sys
import time

import numpy as np
from tqdm import tqdm

from ..core.config import METHODS, ConfigError, PlannerConfig, load_config, load_params_file
from ..core.robot import BURGER, ROBOTS, RobotDescription
from ..ros.paths import default_params_file, robot_params_file, shipped_worlds_dir
from ..sim.episode import run_episode
from ..sim.faults import ScanFaults
from ..sim.simulator import SimConfig
from ..sim.solvability import geodesic_length, world_map
from ..sim.world import World, WorldError, load_world, world_files
from .animation import animate_run
from .metrics import barn_score
from .plots import plot_trajectories
from .results import RunSet, perception_table, speed_table

#: The default comparison: the package's default, the paper's method and its ablations
#: (Euclidean attraction, eq. 21), and the DWA baseline, classic and on the same field
#: (Brock and Khatib's global dynamic window).
DEFAULT_METHODS = ('subharmonic_sampling:geodesic', 'subharmonic_sampling:euclidean',
                   'subharmonic:euclidean', 'traditional:euclidean', 'harmonic:euclidean',
                   'dwa:euclidean', 'dwa:geodesic')
FIELDS = ('geodesic', 'euclidean')
#: --faults: the four faults the bench has long had, on top of the sensor model.
FOUR_FAULTS = {'noise': 0.03, 'beam_dropout': 0.2, 'scan_dropout': 0.2, 'scan_latency': 0.1}
#: How long --cluster waits for its scheduler [s].
CLUSTER_CONNECT_TIMEOUT = 30.0
#: A suite's shortest paths, beside its world files (``../shared/dev_maps/index.json``:
#: per building, ``worlds`` by name, each with its ``smoothed`` shortest path [m]).
INDEX = 'index.json'


@functools.lru_cache(maxsize=8)
def _index(path: Path) -> dict[str, float]:
    """World name -> smoothed shortest path [m] from an INDEX file ({} when it is not
    one)."""
    try:
        doc = json.loads(path.read_text())
    except (OSError, ValueError):
        return {}
    found = {}
    for entry in doc.values() if isinstance(doc, dict) else ():
        worlds = entry.get('worlds') if isinstance(entry, dict) else None
        for name, task in (worlds.items() if isinstance(worlds, dict) else ()):
            length = task.get('smoothed') if isinstance(task, dict) else None
            if isinstance(length, (int, float)) and math.isfinite(length) and length > 0:
                found[name] = float(length)
    return found


def shortest_path(world: World, robot: RobotDescription = BURGER) -> float:
    """The world's shortest path from start to goal [m]: the smoothed length an INDEX
    beside its file gives, else the geodesic of sim/solvability.py (8-connected cells of
    5 cm, a disc of the robot's circumscribed radius plus margin: up to 8 % longer than
    the true shortest path, so the ratios below come out up to that much low); inf when
    there is no way."""
    index = Path(world.source).parent / INDEX
    if index.is_file():
        length = _index(index).get(world.name)
        if length is not None:
            return length
    return geodesic_length(world, robot.solve_radius)


def efficiency(record: dict, shortest: float, top_speed: float) -> dict:
    """The run's record with its world's ``shortest_path`` [m] and, when it reached,
    ``time_over_limit`` (its time over the physical limit: the shortest path at the
    robot's top speed) and ``path_over_shortest`` (its path over the shortest); None
    where they do not apply; and ``barn_score`` (:func:`barn_score`; None without a
    shortest path)."""
    known = math.isfinite(shortest) and shortest > 0.0 and top_speed > 0.0
    ok = known and record['outcome'] == 'reached'
    over = round(record['time_s'] * top_speed / shortest, 3) if ok else None
    return {**record, 'shortest_path': round(shortest, 3) if known else None,
            'time_over_limit': over,
            'path_over_shortest': round(record['path_length'] / shortest, 3) if ok else None,
            'barn_score': round(barn_score(ok, over), 4) if known else None}


def parse_method(spec: str) -> dict:
    """``method[:attraction_field]`` -> config changes; ValueError when unknown. Without a
    field the configuration's attraction_field applies."""
    name, _, field = spec.strip().partition(':')
    if name not in METHODS or (field and field not in FIELDS):
        raise ValueError(f'unknown method {spec!r}: use one of {", ".join(METHODS)}, '
                         f'optionally with :{" or :".join(FIELDS)}')
    changes = {'method': name}
    if field:
        changes['attraction_field'] = field
    return changes


def _run_world(job: tuple) -> list[tuple[dict, list]]:
    """All methods on one world (in a worker), and its plot when ``plot_dir`` is set."""
    world, methods, cfg, sim_cfg, faults, plot_dir, animate, known = job
    out = []
    shortest = shortest_path(world, sim_cfg.description)
    known_map = world_map(world) if known else None
    for spec in methods:
        run_cfg = cfg.replace(**parse_method(spec))
        label = f'{run_cfg.method}:{run_cfg.attraction_field}'
        result = run_episode(world, run_cfg, sim_cfg, faults=faults, label=label,
                             known_map=known_map)
        out.append((efficiency(result.metrics(world), shortest, run_cfg.max_linear_velocity),
                    result.path[:, :2].round(4).tolist()))
    if plot_dir is not None:
        _plot_world(world, out, Path(plot_dir), cfg.period, animate)
    return out


def _plot_world(world: World, out: list[tuple[dict, list]], plot_dir: Path, period: float,
                animate: bool) -> None:
    """The world's PNG (and GIF) of the runs ``out`` (metrics, path) of _run_world."""
    paths = {r['method']: np.asarray(p) for r, p in out}
    plot_trajectories(world, paths, {r['method']: r['outcome'] for r, _ in out},
                      plot_dir / f'{world.name}.png', period)
    if animate:
        animate_run(world, paths, plot_dir / f'{world.name}.gif', period)


@contextlib.contextmanager
def _executor(jobs: int, cluster: str | None) -> Iterator[Executor]:
    """Where the episodes run: ``jobs`` local processes, or the workers of the Dask
    distributed cluster whose scheduler is at ``cluster`` (its concurrent.futures
    executor: the same map, the same results)."""
    if cluster is None:
        with ProcessPoolExecutor(max_workers=max(1, jobs)) as pool:
            yield pool
        return
    from distributed import Client
    with Client(cluster, timeout=CLUSTER_CONNECT_TIMEOUT) as client:
        with client.get_executor() as pool:
            yield pool


def paired(runs: list[dict], methods: list[str]) -> str:
    """Each method against the first on the worlds both reach: mean curvature and time."""
    if len(methods) < 2:
        return ''
    reached = {(r['method'], r['world']): r for r in runs if r['outcome'] == 'reached'}
    ref = methods[0]
    lines = [f'| on worlds both reach | worlds | mean curvature [1/m] ({ref} / other) '
             f'| mean time [s] ({ref} / other) |', '|---|---|---|---|']
    for m in methods[1:]:
        both = sorted({w for (mm, w) in reached if mm == m} & {w for (mm, w) in reached
                                                                if mm == ref})
        if not both:
            lines.append(f'| {m} | 0 | - | - |')
            continue

        def mean(key: str, meth: str, both: list[str] = both) -> float:
            return statistics.fmean(reached[(meth, w)][key] for w in both)
        lines.append(f'| {m} | {len(both)} | {mean("mean_abs_curvature", ref):.2f} / '
                     f'{mean("mean_abs_curvature", m):.2f} | {mean("time_s", ref):.1f} / '
                     f'{mean("time_s", m):.1f} |')
    return '\n'.join(lines) + '\n'


def _collisions(runs: list[dict]) -> str:
    """Collision count, with how many hit a robot standing still."""
    hits = [r for r in runs if r['outcome'] == 'collision']
    stopped = sum(bool(r.get('hit_while_stopped')) for r in hits)
    return f'{len(hits)} ({stopped} stopped)' if stopped else str(len(hits))


def given_up(runs: list[dict]) -> str:
    """The runs the planner gave up (``unreachable``, ``abandoned``) and why, as the
    decision loop said it at the end (``final_state``); empty when there are none."""
    rows = [r for r in runs if r['outcome'] in ('unreachable', 'abandoned')]
    if not rows:
        return ''
    lines = ['| world | method | outcome | final state |', '|---|---|---|---|']
    lines += [f"| {r['world']} | {r['method']} | {r['outcome']} | {r.get('final_state', '')} |"
              for r in rows]
    return 'Runs given up:\n\n' + '\n'.join(lines) + '\n'


def family_of(world: str) -> str:
    """A generated world's family: its name without the index (``arena_007`` -> arena)."""
    head, _, tail = world.rpartition('_')
    return head if head and tail.isdigit() else world


def by_family(runs: list[dict], methods: list[str]) -> str:
    """Per family and method: reached, collisions (hit while stopped), timeouts,
    abandoned, unreachable, missed, median time of the reached runs and least
    clearance; '' for a single family."""
    families = sorted({family_of(r['world']) for r in runs})
    if len(families) < 2:
        return ''
    lines = ['| family | method | reached | collisions | timeouts | abandoned | unreachable '
             '| missed | median time [s] | min clearance [m] |', '|' + '---|' * 10]
    for fam in families:
        for m in methods:
            rs = [r for r in runs if r['method'] == m and family_of(r['world']) == fam]
            if not rs:
                continue
            ok = [r['time_s'] for r in rs if r['outcome'] == 'reached']
            lines.append(
                f'| {fam} | {m} | {len(ok)}/{len(rs)} | {_collisions(rs)} '
                f'| {sum(r["outcome"] == "timeout" for r in rs)} '
                f'| {sum(r["outcome"] == "abandoned" for r in rs)} '
                f'| {sum(r["outcome"] == "unreachable" for r in rs)} '
                f'| {sum(r["outcome"] == "missed" for r in rs)} '
                f'| {f"{statistics.median(ok):.1f}" if ok else "-"} '
                f'| {min(r["min_clearance"] for r in rs):.3f} |')
    return '\n'.join(lines) + '\n'


def _tables(runs: list[dict], methods: list[str]) -> str:
    """The pose error and evading table and the time, path and BARN score table, as
    docs/results.md has them (tools/results.py)."""
    rs = RunSet(name='', runs=runs, methods=methods)
    return ''.join(t + '\n' for t in (perception_table(rs), speed_table(rs)) if t)


def summarise(runs: list[dict], methods: list[str]) -> str:
    """Markdown table per method, then an outcome matrix method x world."""
    lines = ['| method | runs | reached | collisions | timeouts | abandoned | unreachable '
             '| missed | median time [s] | median path [m] | min clearance [m] '
             '| median curvature [1/m] | plan ms (median) |', '|' + '---|' * 13]
    for m in methods:
        rs = [r for r in runs if r['method'] == m]
        if not rs:
            continue
        ok = [r for r in rs if r['outcome'] == 'reached']

        def med(key: str, rows: list[dict] = ok) -> str:
            return f'{statistics.median(r[key] for r in rows):.2f}' if rows else '-'
        lines.append(
            f'| {m} | {len(rs)} | {len(ok)}/{len(rs)} '
            f'| {_collisions(rs)} '
            f'| {sum(r["outcome"] == "timeout" for r in rs)} '
            f'| {sum(r["outcome"] == "abandoned" for r in rs)} '
            f'| {sum(r["outcome"] == "unreachable" for r in rs)} '
            f'| {sum(r["outcome"] == "missed" for r in rs)} | {med("time_s")} '
            f'| {med("path_length")} | {min(r["min_clearance"] for r in rs):.3f} '
            f'| {med("mean_abs_curvature")} | {med("plan_ms_median", rs)} |')
    worlds = sorted({r['world'] for r in runs})
    lines += ['', '| world | ' + ' | '.join(methods) + ' |', '|' + '---|' * (len(methods) + 1)]
    for w in worlds:
        cells = []
        for m in methods:
            r = next((r for r in runs if r['world'] == w and r['method'] == m), None)
            cells.append('-' if r is None else
                         f'{r["outcome"]} ({r["time_s"]:.0f} s)' if r['outcome'] == 'reached'
                         else r['outcome'])
        lines.append(f'| {w} | ' + ' | '.join(cells) + ' |')
    return '\n'.join(lines) + '\n'


def _git(*args: str) -> str | None:
    """A git command's output in this package's directory; None when it fails."""
    try:
        done = subprocess.run(['git', *args], cwd=Path(__file__).resolve().parent,
                              capture_output=True, text=True, timeout=10, check=False)
    except (OSError, subprocess.SubprocessError):
        return None
    return done.stdout.strip() if done.returncode == 0 else None


def git_commit() -> str | None:
    """The short commit the package runs from, with ``-dirty`` when tracked files have
    changes; None when it is not run from a git checkout (an installed wheel, or a
    directory inside some other repository)."""
    top = _git('rev-parse', '--show-toplevel')
    if top is None or Path(top).resolve() != Path(__file__).resolve().parents[2]:
        return None
    commit = _git('rev-parse', '--short', 'HEAD')
    if commit is None:
        return None
    changes = _git('status', '--porcelain', '--untracked-files=no')
    return commit + '-dirty' if changes else commit


def package_version(checkout: bool) -> str | None:
    """The version of the code that runs: in a git checkout its setup.py's (an editable
    install's metadata keeps the version it was installed with), else the installed
    distribution's."""
    if checkout:
        setup_py = Path(__file__).resolve().parents[2] / 'setup.py'
        found = re.search(r"""^\s*version=['"]([^'"]+)['"]""", setup_py.read_text(), re.M)
        if found:
            return found.group(1)
    try:
        return importlib.metadata.version('subapf_planner')
    except importlib.metadata.PackageNotFoundError:
        return None


def provenance(argv: list[str]) -> dict:
    """results.json's ``meta``: how it was produced."""
    commit = git_commit()
    return {'command': 'subapf-bench ' + shlex.join(argv),
            'version': package_version(commit is not None), 'commit': commit,
            'date': datetime.date.today().isoformat()}


def bench_config(params: str | None, robot: str | None) -> tuple[str, PlannerConfig]:
    """The robot's key and the planner's configuration for the bench: the params file
    (default config/planner.yaml), with the robot's config/robots/ file on top unless the
    params file is written for that robot (its ``robot``); the robot: ``robot``, else the
    params file's, else the burger. ConfigError when a file cannot be read."""
    path = params or default_params_file()
    named = load_params_file(path).get('robot')
    key = robot or (named if named in ROBOTS else 'burger')
    if named == key:
        return key, load_config(path)
    return key, load_config(path, **load_params_file(robot_params_file(key)))


def parse_args(argv: list[str] | None) -> argparse.Namespace:
    p = argparse.ArgumentParser(prog='subapf-bench', description=__doc__.splitlines()[0])
    p.add_argument('worlds', nargs='*', help='world files or directories (default: shipped)')
    p.add_argument('--methods', default=','.join(DEFAULT_METHODS),
                   help='comma-separated method[:geodesic|:euclidean] (attraction field; '
                   f'default: the params file\'s), of {",".join(METHODS)}')
    p.add_argument('--out', required=True, help='output directory')
    p.add_argument('--robot', choices=sorted(ROBOTS), default=None,
                   help="the robot simulated and planned for (core/robot.py; default: the "
                   "params file's robot, else the burger); its config/robots/ file goes "
                   'on top of the params file unless that is written for it (robot: NAME)')
    p.add_argument('--params', default=None, help='ROS 2 params YAML (config/planner.yaml)')
    p.add_argument('--jobs', type=int, default=1, help='worker processes')
    p.add_argument('--cluster', default=None, metavar='ADDRESS',
                   help='run the episodes on a Dask distributed cluster instead: its '
                   "scheduler's address, e.g. tcp://scheduler:8786 (every worker needs "
                   'subapf_planner installed; --jobs is not used; plots are drawn here)')
    p.add_argument('--seed', type=int, default=0, help='simulator seed (noise)')
    p.add_argument('--sensor', choices=('ideal', 'realistic'), default='realistic',
                   help="the lidar: realistic (the default: the LDS-01's datasheet errors, "
                   'each beam at its own instant, latency and lost scans: sim/sensor.py) or '
                   'ideal (exact rays at one instant, delivered at once; add --noise 0.01 '
                   "for Gazebo's TurtleBot3)")
    p.add_argument('--noise', type=float, default=0.0,
                   help='laser range noise sigma on top of the sensor [m]')
    p.add_argument('--beam-dropout', type=float, default=0.0,
                   help='extra fraction of dropped beams on top of the sensor')
    p.add_argument('--odom-scale', type=float, default=1.0,
                   help='odometry distance scale (1.02: reports 2 %% too far)')
    p.add_argument('--odom-yaw-scale', type=float, default=1.0,
                   help='odometry turn-rate scale (1.03: reports 3 %% too much turn)')
    p.add_argument('--scan-dropout', type=float, default=0.0,
                   help='probability that a scan never reaches the planner')
    p.add_argument('--scan-latency', type=float, default=0.0,
                   help="extra seconds between a scan and its delivery, on top of the sensor's")
    p.add_argument('--faults', action='store_true',
                   help='the four faults on top of the sensor: --noise 0.03 --beam-dropout 0.2 '
                   '--scan-dropout 0.2 --scan-latency 0.1 (each still settable)')
    p.add_argument('--known-map', action='store_true',
                   help="start each run's memory from the world's map (its static "
                   'obstacles at 0.05 m, as map_server gives one; docs/nav2.md)')
    p.add_argument('--no-plots', action='store_true', help='skip the PNGs')
    p.add_argument('--animate', action='store_true',
                   help="also write an animated GIF of each world's runs")
    return p.parse_args(argv)


def main(argv: list[str] | None = None) -> int:
    argv = sys.argv[1:] if argv is None else list(argv)
    args = parse_args(argv)
    try:
        methods = [m.strip() for m in args.methods.split(',') if m.strip()]
        if not methods:
            raise ValueError('no method given')
        for m in methods:
            parse_method(m)
        robot, cfg = bench_config(args.params, args.robot)
        if args.faults:
            for name, value in FOUR_FAULTS.items():
                if getattr(args, name) == 0.0:
                    setattr(args, name, value)
        sim_cfg = SimConfig(robot=robot, seed=args.seed, sensor=args.sensor,
                            range_noise=args.noise,
                            beam_dropout=args.beam_dropout,
                            odom_distance_scale=args.odom_scale,
                            odom_yaw_scale=args.odom_yaw_scale,
                            scan_threads=1)   # one process per core already
        faults = ScanFaults(args.scan_dropout, args.scan_latency)
        files = world_files(args.worlds or [shipped_worlds_dir()])
        worlds = {str(f): load_world(f) for f in files}
    except (ConfigError, WorldError, ValueError) as exc:
        print(f'subapf-bench: {exc}', file=sys.stderr)
        return 2
    if not worlds:
        print('subapf-bench: no world files found', file=sys.stderr)
        return 2
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    plot_dir = None if args.no_plots else str(out)
    # on a cluster the workers' disks are not ours: the plots are drawn here
    worker_plots = None if args.cluster else plot_dir
    jobs = [(w, methods, cfg, sim_cfg, faults, worker_plots, args.animate, args.known_map)
            for w in worlds.values()]
    t0 = time.perf_counter()
    try:
        with _executor(args.jobs, args.cluster) as pool:
            per_world = list(tqdm(pool.map(_run_world, jobs), total=len(jobs), unit='world',
                                  desc='subapf-bench', file=sys.stderr))
    except OSError as exc:   # no scheduler at the address (distributed's timeout too)
        print(f'subapf-bench: cluster {args.cluster}: {exc}', file=sys.stderr)
        return 2
    if args.cluster and plot_dir is not None:
        for world, world_runs in zip(worlds.values(), per_world, strict=True):
            _plot_world(world, world_runs, Path(plot_dir), cfg.period, args.animate)
    wall = time.perf_counter() - t0
    runs = [r for world_runs in per_world for r, _ in world_runs]
    labels = list(dict.fromkeys(r['method'] for r in runs))
    doc = {'meta': provenance(argv),
           'runs': runs, 'methods': labels, 'robot': robot, 'seed': args.seed,
           'sensor': args.sensor,
           'noise': args.noise,
           'beam_dropout': args.beam_dropout, 'scan_dropout': args.scan_dropout,
           'scan_latency': args.scan_latency, 'odom_distance_scale': args.odom_scale,
           'odom_yaw_scale': args.odom_yaw_scale, 'wall_time_s': round(wall, 2),
           'params': dataclasses.asdict(cfg)}
    (out / 'results.json').write_text(json.dumps(doc, indent=1))
    (out / 'summary.md').write_text(summarise(runs, labels) + '\n' + by_family(runs, labels)
                                    + '\n' + _tables(runs, labels)
                                    + '\n' + given_up(runs)
                                    + '\n' + paired(runs, labels)
                                    + f'\n{len(runs)} runs in {wall:.1f} s wall time.\n')
    print((out / 'summary.md').read_text())
    return 0


if __name__ == '__main__':
    sys.exit(main())
