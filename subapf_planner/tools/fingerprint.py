"""``subapf-fingerprint``: fingerprints of a fixed set of benchmark runs, to prove that a
change of structure changed no decision.

Each run (sim/episode.py, the bench's loop) is summed up by its outcome, its number of
cycles, its status counts and a SHA-256 of its ground-truth trajectory (every pose of
every cycle, bit for bit): two versions of the planner that make the same decisions in
every cycle give the same fingerprint. The set covers what the planner does: the
shipped worlds (static), generated static and moving worlds, building floors with
drifting wheel odometry, real-building maps when ``--dev-maps`` names them, and the
paper's method and DWA as ablations.

``subapf-fingerprint --out before.json`` on one commit, ``subapf-fingerprint --compare
before.json`` on the next prints each run that differs and exits 1 if any does.
"""

from __future__ import annotations

import argparse
from concurrent.futures import ProcessPoolExecutor
import hashlib
import json
from pathlib import Path
import sys

import numpy as np

from ..core.config import load_config
from ..ros.paths import default_params_file, shipped_worlds_dir
from ..sim.episode import run_episode
from ..sim.simulator import SimConfig
from ..sim.world import World, load_world, parse_world
from ..sim.worldgen import generate_world, sub_seed
from .bench import parse_method

PROG = 'subapf-fingerprint'
#: Generated worlds of the set: (family, index) in the suite of seed 2026.
GENERATED = (('barn', 0), ('maze', 0), ('doorway', 1), ('c_trap', 0),
             ('crossing', 0), ('head_on', 0), ('clutter_walkers', 1), ('fast_crossing', 0),
             ('building', 0), ('building', 1))
#: Drifting wheel odometry: +2 % distance, +3 % turn rate.
DRIFT = {'odom_distance_scale': 1.02, 'odom_yaw_scale': 1.03}
#: Real-building tasks taken from --dev-maps, with and without drift.
DEV_MAPS = ('aces_000', 'csail_003', 'fr101_005', 'orebro_007', 'seattle_009')


def _generated(family: str, index: int) -> World:
    return parse_world(generate_world(family, sub_seed(2026, family, index),
                                      f'{family}_{index:03d}').doc)


def run_set(dev_maps: Path | None) -> list[tuple[str, World, str, dict]]:
    """(name, world, method spec, SimConfig changes) of every run of the set."""
    out = []
    for path in sorted(shipped_worlds_dir().glob('*.yaml')):
        out.append((path.stem, load_world(path), 'subharmonic_sampling:geodesic', {}))
    for family, index in GENERATED:
        world = _generated(family, index)
        out.append((world.name, world, 'subharmonic_sampling:geodesic', {}))
        if family == 'building':
            out.append((world.name + '+drift', world, 'subharmonic_sampling:geodesic', DRIFT))
    for spec in ('subharmonic_sampling:euclidean', 'dwa:euclidean', 'dwa:geodesic'):
        for family, index in (('barn', 0), ('crossing', 0)):
            world = _generated(family, index)
            out.append((f'{world.name}@{spec}', world, spec, {}))
    if dev_maps is not None:
        for name in DEV_MAPS:
            world = load_world(dev_maps / f'{name}.yaml')
            out.append((name, world, 'subharmonic_sampling:geodesic', {}))
            out.append((name + '+drift', world, 'subharmonic_sampling:geodesic', DRIFT))
    return out


def fingerprint(job: tuple) -> tuple[str, dict]:
    """One run's fingerprint (in a worker process)."""
    name, world, spec, sim_changes, params = job
    cfg = load_config(params).replace(**parse_method(spec))
    result = run_episode(world, cfg, SimConfig(**sim_changes))
    path = np.ascontiguousarray(result.path, dtype=np.float64)
    return name, {'outcome': str(result.outcome), 'cycles': result.cycles,
                  'statuses': dict(sorted(result.statuses.items())),
                  'trajectory_sha256': hashlib.sha256(path.tobytes()).hexdigest()}


def compare(before: dict, after: dict) -> list[str]:
    """One line per run that differs (or is in one set only)."""
    lines = []
    for name in sorted(set(before) | set(after)):
        a, b = before.get(name), after.get(name)
        if a == b:
            continue
        if a is None or b is None:
            lines.append(f'{name}: only in {"after" if a is None else "before"}')
            continue
        what = [k for k in a if a[k] != b.get(k)]
        lines.append(f'{name}: {", ".join(what)} differ ({a["outcome"]}, {a["cycles"]} cycles '
                     f'-> {b["outcome"]}, {b["cycles"]} cycles)')
    return lines


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(prog=PROG, description=__doc__.split('\n\n')[0])
    ap.add_argument('--out', type=Path, help='write the fingerprints to this JSON file')
    ap.add_argument('--compare', type=Path, help='compare with fingerprints written before; '
                    'exit 1 when any run differs')
    ap.add_argument('--dev-maps', type=Path, help='directory of the real-building tasks '
                    '(../shared/dev_maps) to include')
    ap.add_argument('--params', default=None, help='parameter file (default: the '
                    "package's config/planner.yaml)")
    ap.add_argument('--jobs', type=int, default=2, help='worker processes (default 2)')
    args = ap.parse_args(argv)
    params = args.params or default_params_file()
    jobs = [(*run, params) for run in run_set(args.dev_maps)]
    with ProcessPoolExecutor(max(1, args.jobs)) as pool:
        prints = dict(pool.map(fingerprint, jobs))
    for name, fp in prints.items():
        print(f'{name:32s} {fp["outcome"]:12s} {fp["cycles"]:5d} {fp["trajectory_sha256"][:16]}')
    if args.out:
        args.out.write_text(json.dumps(prints, indent=1, sort_keys=True) + '\n')
    if args.compare:
        diff = compare(json.loads(args.compare.read_text()), prints)
        print('\n'.join(diff) if diff else f'all {len(prints)} runs identical')
        return 1 if diff else 0
    return 0


if __name__ == '__main__':
    sys.exit(main())
