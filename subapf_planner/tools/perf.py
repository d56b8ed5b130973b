"""``subapf-perf``: planning-cycle time of the decision loop (a benchmark, not a test).

Drives closed-loop episodes (sim/episode.py: the node's controller, 360-beam
scans from the simulator) on the given worlds and prints min / median / p99 /
max of the time per planning cycle in ms: the whole tick, i.e. with the
geodesic default the tracking, the navigation field when it is
recomputed in the cycle (a new goal, the robot off the field's patch; a field that
only brings the map's changes in is marched between cycles: core/memory.py), the
APF step, the sampling and the command; the time of the work after each tick's
command (DecisionLoop.after_tick: the scan matched to the memory and written into
it, which the next tick plans with); and the time of each field computation,
wherever it ran. Also prints the memory the occupancy window and the largest field
hold.
"""

from __future__ import annotations

import argparse
import sys
import time

import numpy as np

from ..core.config import METHODS
from ..core.occupancy import OccupancyGrid
from ..core.robot import ROBOTS
from ..ros.paths import shipped_worlds_dir
from ..sim.episode import run_episode
from ..sim.simulator import SimConfig
from ..sim.world import load_world, world_files
from .bench import bench_config

#: Bytes a field holds per block it is marched on: values, their padded copy and the
#: downhill index for ~/plan (8 bytes each); and per map cell: passable (bool).
FIELD_BYTES_PER_BLOCK = 3 * 8
FIELD_BYTES_PER_MAP_CELL = 1


def main(argv: list[str] | None = None) -> int:
    p = argparse.ArgumentParser(prog='subapf-perf', description=__doc__.splitlines()[0])
    p.add_argument('worlds', nargs='*', help='world files or folders (default: shipped)')
    p.add_argument('--method', default='subharmonic_sampling', choices=METHODS)
    p.add_argument('--field', default=None, choices=('geodesic', 'euclidean'),
                   help="attraction field (default: the params file's)")
    p.add_argument('--params', default=None, help='params YAML (default: config/planner.yaml)')
    p.add_argument('--robot', default=None, choices=sorted(ROBOTS),
                   help="the robot simulated and planned for, at its planning rate (as "
                   "subapf-bench --robot; default: the params file's, else the burger)")
    p.add_argument('--repeat', type=int, default=1,
                   help='drive the worlds this many times and pool the cycles (a shared '
                   'machine is faster and slower by turns; each pass prints its median)')
    args = p.parse_args(argv)
    if args.repeat < 1:
        p.error('--repeat must be at least 1')
    changes = {'method': args.method}
    if args.field:
        changes['attraction_field'] = args.field
    robot, cfg = bench_config(args.params, args.robot)
    cfg = cfg.replace(**changes)
    files = world_files(args.worlds or [shipped_worlds_dir()])
    t0 = time.perf_counter()
    worlds = [load_world(f) for f in files]
    runs = []
    for k in range(args.repeat):
        runs_k = [run_episode(w, cfg, SimConfig(robot=robot, range_noise=0.01))
                  for w in worlds]
        if args.repeat > 1:
            pass_ms = np.concatenate([r.plan_ms for r in runs_k])
            print(f'pass {k + 1}: median {np.median(pass_ms):.3f} ms  '
                  f'p99 {np.percentile(pass_ms, 99):.3f} ms')
        runs += runs_k
    ms = np.concatenate([r.plan_ms for r in runs])
    recomputed = np.concatenate([r.field_recomputed for r in runs])
    cells = int(np.ceil(cfg.map_size / cfg.map_resolution)) ** 2
    print(f'method={cfg.method} attraction_field={cfg.attraction_field} '
          f'map={cfg.map_size:g} m at {cfg.map_resolution:g} m ({cells} cells) '
          f'field_period={cfg.field_period:g} s worlds={len(files)} x {args.repeat} '
          f'cycles={ms.size} '
          f'({time.perf_counter() - t0:.0f} s)')
    print(f'plan cycle ms: {_figures(ms)}')
    budget = 1e3 * cfg.period
    print(f'robot {robot} at {cfg.planning_frequency:g} Hz: a cycle has {budget:g} ms; the '
          f'tick and the work after it, p99 {np.percentile(ms, 99):.1f} + '
          f'{np.percentile(np.concatenate([r.after_ms for r in runs]), 99):.1f} ms')
    if recomputed.any():
        print(f'  {recomputed.sum()} cycles with a new field ({recomputed.mean():.0%}): '
              f'{_figures(ms[recomputed])}')
        print(f'  {(~recomputed).sum()} cycles without: {_figures(ms[~recomputed])}')
        marched = np.concatenate([r.field_ms for r in runs])
        where = ("; those that only bring the map's changes in ran on the memory's worker "
                 'thread between cycles') if cfg.field_worker else ', all in their cycle'
        print(f'field computations ms (wall{where}): {_figures(marched)}')
    after = np.concatenate([r.after_ms for r in runs])
    if after.size and cfg.geodesic:
        print(f'after the command ms (the scan matched to and written into the memory, '
              f'and a field due handed to the worker): {_figures(after)}')
    if cfg.geodesic:
        field_bytes = cells * (FIELD_BYTES_PER_BLOCK / cfg.field_coarsening ** 2
                               + FIELD_BYTES_PER_MAP_CELL)
        grid_bytes = OccupancyGrid(cfg.map_resolution, cfg.map_size, cfg.scan_alignment).nbytes
        print(f'memory: occupancy window {grid_bytes / 2**20:.2f} MiB (log odds, and with '
              f"scan_alignment the returns' mean place per cell), field at most "
              f'{field_bytes / 2**20:.2f} MiB (the whole window)')
    return 0


def _figures(ms: np.ndarray) -> str:
    return (f'min {ms.min():.3f}  median {np.median(ms):.3f}  p99 {np.percentile(ms, 99):.3f}'
            f'  max {ms.max():.3f}')


if __name__ == '__main__':
    sys.exit(main())
