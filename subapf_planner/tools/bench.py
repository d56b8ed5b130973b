"""``subapf-bench``: the paper's ablation (Fig. 6) and the DWA baseline on many worlds.

Every (world, method) run steps the simulator and the planner in lockstep in
one process (episode.py); ``--jobs`` spreads runs over processes. Writes
``results.json``, ``summary.md`` and one Fig. 6-style PNG per world to --out.
One parameter file (default: the package's config/planner.yaml) for all worlds.
"""

from __future__ import annotations

import argparse
from concurrent.futures import ProcessPoolExecutor
import json
from pathlib import Path
import statistics
import sys
import time

import numpy as np
from tqdm import tqdm

from ..core.config import METHODS, ConfigError, PlannerConfig, load_config
from ..sim.episode import run_episode
from ..sim.faults import ScanFaults
from ..sim.simulator import SimConfig
from ..sim.world import WorldError, load_world, world_files
from .paths import default_params_file, shipped_worlds_dir
from .plots import plot_trajectories


def _run(job: tuple[str, str, PlannerConfig, SimConfig, ScanFaults]) -> tuple[dict, list]:
    path, method, cfg, sim_cfg, faults = job
    world = load_world(path)
    result = run_episode(world, cfg.replace(method=method), sim_cfg, faults=faults)
    return result.metrics(world), result.path[:, :2].round(4).tolist()


def summarise(runs: list[dict], methods: list[str]) -> str:
    """Markdown table per method, then an outcome matrix method x world."""
    lines = ['| method | runs | reached | collisions | timeouts | abandoned | median time [s] '
             '| median path [m] | min clearance [m] | median curvature [1/m] '
             '| plan ms (median) |', '|' + '---|' * 11]
    for m in methods:
        rs = [r for r in runs if r['method'] == m]
        if not rs:
            continue
        ok = [r for r in rs if r['outcome'] == 'reached']

        def med(key: str, rows: list[dict] = ok) -> str:
            return f'{statistics.median(r[key] for r in rows):.2f}' if rows else '-'
        lines.append(
            f'| {m} | {len(rs)} | {len(ok)}/{len(rs)} '
            f'| {sum(r["outcome"] == "collision" for r in rs)} '
            f'| {sum(r["outcome"] == "timeout" for r in rs)} '
            f'| {sum(r["outcome"] == "abandoned" for r in rs)} | {med("time_s")} '
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


def parse_args(argv: list[str] | None) -> argparse.Namespace:
    p = argparse.ArgumentParser(prog='subapf-bench', description=__doc__.splitlines()[0])
    p.add_argument('worlds', nargs='*', help='world files or directories (default: shipped)')
    p.add_argument('--methods', default=','.join(METHODS),
                   help=f'comma-separated, of {",".join(METHODS)}')
    p.add_argument('--out', required=True, help='output directory')
    p.add_argument('--params', default=None, help='ROS 2 params YAML (config/planner.yaml)')
    p.add_argument('--jobs', type=int, default=1, help='worker processes')
    p.add_argument('--seed', type=int, default=0, help='simulator seed (noise)')
    p.add_argument('--noise', type=float, default=0.01,
                   help='laser range noise sigma [m] (Gazebo TurtleBot3: 0.01)')
    p.add_argument('--beam-dropout', type=float, default=0.0, help='fraction of dropped beams')
    p.add_argument('--scan-dropout', type=float, default=0.0,
                   help='probability that a scan never reaches the planner')
    p.add_argument('--scan-latency', type=float, default=0.0,
                   help='seconds between a scan and its delivery to the planner')
    p.add_argument('--no-plots', action='store_true', help='skip the PNGs')
    return p.parse_args(argv)


def main(argv: list[str] | None = None) -> int:
    args = parse_args(argv)
    methods = [m.strip() for m in args.methods.split(',') if m.strip()]
    bad = [m for m in methods if m not in METHODS]
    if bad or not methods:
        print(f'subapf-bench: unknown method(s) {bad}; choose from {", ".join(METHODS)}',
              file=sys.stderr)
        return 2
    try:
        cfg = load_config(args.params or default_params_file())
        sim_cfg = SimConfig(seed=args.seed, range_noise=args.noise,
                            beam_dropout=args.beam_dropout)
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
    jobs = [(f, m, cfg, sim_cfg, faults) for f in worlds for m in methods]
    t0 = time.perf_counter()
    with ProcessPoolExecutor(max_workers=max(1, args.jobs)) as pool:
        results = list(tqdm(pool.map(_run, jobs), total=len(jobs), unit='run',
                            desc='subapf-bench', file=sys.stderr))
    wall = time.perf_counter() - t0
    runs = [r for r, _ in results]
    doc = {'runs': runs, 'methods': methods, 'seed': args.seed, 'noise': args.noise,
           'beam_dropout': args.beam_dropout, 'scan_dropout': args.scan_dropout,
           'scan_latency': args.scan_latency, 'wall_time_s': round(wall, 2),
           'params': {k: v for k, v in cfg.__dict__.items() if k != 'method'}}
    (out / 'results.json').write_text(json.dumps(doc, indent=1))
    (out / 'summary.md').write_text(summarise(runs, methods)
                                    + f'\n{len(runs)} runs in {wall:.1f} s wall time.\n')
    if not args.no_plots:
        for f, world in worlds.items():
            sel = [(job, res) for job, res in zip(jobs, results, strict=True) if job[0] == f]
            plot_trajectories(world, {j[1]: np.asarray(p) for j, (_, p) in sel},
                              {j[1]: r['outcome'] for j, (r, _) in sel},
                              out / f'{world.name}.png')
    print((out / 'summary.md').read_text())
    return 0


if __name__ == '__main__':
    sys.exit(main())
