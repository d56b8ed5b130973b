"""``subapf-soak``: the full ROS graph over and over, with noise, dropouts and latency.

Runs the bringup (simulator and planner as processes over DDS) on the shipped
worlds in turn, for ``--runs`` runs or ``--minutes`` of wall time, whichever
ends first, with laser noise, dropped beams, dropped and late scans. Reports
outcomes and collisions (there must be none), each node's resident memory 5 s
into each run and at its end, the largest growth, and the error lines the
nodes logged. Exit 0 when there was no collision, no failed run and no error
line; writes ``DIR/soak.json`` and the nodes' logs under ``DIR/logs``.
"""

from __future__ import annotations

import argparse
import json
import math
from pathlib import Path
import random
import sys
import time

from ..ros.paths import default_params_file, shipped_worlds_dir
from ..sim.world import load_world, world_files
from .bringup import run_once

ERROR_MARKERS = ('[ERROR]', '[FATAL]', 'Traceback')
#: Memory samples (one a second) skipped at the start of each run.
WARM_UP = 5


def error_lines(log_dir: Path) -> list[str]:
    lines = []
    for log in sorted(log_dir.glob('*.log')):
        for line in log.read_text(errors='replace').splitlines():
            if any(m in line for m in ERROR_MARKERS):
                lines.append(f'{log.name}: {line.strip()}')
    return lines


def main(argv: list[str] | None = None) -> int:
    p = argparse.ArgumentParser(prog='subapf-soak', description=__doc__.splitlines()[0])
    p.add_argument('--runs', type=int, default=16, help='at most this many runs')
    p.add_argument('--minutes', type=float, default=20.0, help='at most this much wall time')
    p.add_argument('--rate', type=float, default=5.0, help='simulation speed-up')
    p.add_argument('--out', default='soak', help='output directory')
    p.add_argument('--seed', type=int, default=0)
    p.add_argument('--noise', type=float, default=0.01, help='laser range noise [m]')
    p.add_argument('--beam-dropout', type=float, default=0.05)
    p.add_argument('--scan-dropout', type=float, default=0.1)
    p.add_argument('--scan-latency', type=float, default=0.1, help='[s]')
    p.add_argument('--worlds', nargs='*', default=None, help='default: the shipped worlds')
    args = p.parse_args(argv)
    out = Path(args.out)
    files = world_files(args.worlds or [shipped_worlds_dir()])
    worlds = [(str(f.resolve()), load_world(f)) for f in files]
    params = str(default_params_file())
    domain_base = random.Random(args.seed).randint(1, 60)
    runs = []
    end = time.monotonic() + 60.0 * args.minutes
    for i in range(args.runs):
        if time.monotonic() >= end:
            break
        path, world = worlds[i % len(worlds)]
        log_dir = out / 'logs' / f'{i:03d}_{world.name}'
        log_dir.mkdir(parents=True, exist_ok=True)
        t0 = time.monotonic()
        result = run_once(world, path, params, domain_base + i % 40, rate=args.rate,
                          seed=args.seed + i, log_dir=log_dir, sim_params={
                              'range_noise': args.noise, 'beam_dropout': args.beam_dropout,
                              'scan_dropout': args.scan_dropout,
                              'scan_latency': args.scan_latency})
        # memory from WARM_UP seconds into the run (imports and first allocations done)
        rss = {name: [v for v in samples[WARM_UP:] if math.isfinite(v)]
               for name, samples in result.rss_mib.items()}
        runs.append({'run': i, 'world': world.name, 'outcome': result.outcome,
                     'sim_time_s': round(result.sim_time, 2),
                     'wall_time_s': round(time.monotonic() - t0, 2),
                     'rss_mib': {n: [round(v[0], 1), round(v[-1], 1)] for n, v in rss.items()
                                 if v},
                     'errors': error_lines(log_dir)})
        print(f'run {i:3d} {world.name:24s} {result.outcome:10s} '
              f'sim {result.sim_time:6.1f} s  ' + '  '.join(
                  f'{n} {v[0]:.1f}->{v[-1]:.1f} MiB' for n, v in rss.items() if v),
              flush=True)
    outcomes = {}
    for r in runs:
        outcomes[r['outcome']] = outcomes.get(r['outcome'], 0) + 1
    growth = {name: max((r['rss_mib'][name][1] - r['rss_mib'][name][0] for r in runs
                         if name in r['rss_mib']), default=0.0)
              for name in ('sim_node', 'planner_node')}
    errors = [e for r in runs for e in r['errors']]
    failed = sum(n for o, n in outcomes.items() if o.startswith(('failed', 'interrupted')))
    summary = {'runs': len(runs), 'outcomes': outcomes,
               'collisions': outcomes.get('collision', 0), 'failed_runs': failed,
               'max_rss_growth_mib': growth, 'error_lines': len(errors),
               'settings': vars(args)}
    out.mkdir(parents=True, exist_ok=True)
    (out / 'soak.json').write_text(json.dumps({'summary': summary, 'runs': runs}, indent=1))
    print(f'\n{len(runs)} runs: outcomes {outcomes}; collisions {summary["collisions"]}; '
          f'failed runs {failed}; largest RSS growth within a run: '
          + ', '.join(f'{n} {g:.1f} MiB' for n, g in growth.items())
          + f'; error lines {len(errors)}')
    for e in errors[:20]:
        print('  ' + e)
    return 0 if summary['collisions'] == 0 and failed == 0 and not errors else 1


if __name__ == '__main__':
    sys.exit(main())
