"""``subapf-perf``: planning-cycle time of the core (a benchmark, not a test).

Feeds recorded-like 360-beam scans (from the simulator on a shipped world)
through ``Planner.step_scan`` and prints min / median / p99 per cycle in ms.
"""

from __future__ import annotations

import argparse
import sys
import time

import numpy as np

from ..core.config import METHODS, load_config
from ..core.planner import Planner
from ..sim.simulator import BurgerSim, SimConfig
from ..sim.world import load_world
from .paths import default_params_file, shipped_worlds_dir


def main(argv: list[str] | None = None) -> int:
    p = argparse.ArgumentParser(prog='subapf-perf', description=__doc__.splitlines()[0])
    p.add_argument('--cycles', type=int, default=5000)
    p.add_argument('--method', default='subharmonic_sampling', choices=METHODS)
    p.add_argument('--samples', type=int, default=16, help='num_samples')
    p.add_argument('--world', default=None, help='world file (default: cluttered_field)')
    args = p.parse_args(argv)
    cfg = load_config(default_params_file(), method=args.method, num_samples=args.samples)
    world = load_world(args.world or shipped_worlds_dir() / 'cluttered_field.yaml')
    with BurgerSim(world, SimConfig(range_noise=0.01)) as sim:
        scans, poses = [], []
        for _ in range(50):
            sim.set_command(0.15, 0.3)
            sim.step(0.2)
            scans.append(sim.scan())
            poses.append(sim.odometry()[0])
    planner = Planner(cfg)
    goal = np.asarray(world.goal)
    times = np.empty(args.cycles)
    for i in range(args.cycles):
        s, pose = scans[i % len(scans)], poses[i % len(poses)]
        t0 = time.perf_counter()
        planner.step_scan(pose, goal, s.ranges, s.angle_min, s.angle_increment,
                          s.range_min, s.range_max)
        times[i] = time.perf_counter() - t0
    ms = times * 1e3
    print(f'method={args.method} beams={scans[0].ranges.size} samples={cfg.num_samples} '
          f'cycles={args.cycles}')
    print(f'plan cycle ms: min {ms.min():.3f}  median {np.median(ms):.3f}  '
          f'p99 {np.percentile(ms, 99):.3f}')
    return 0


if __name__ == '__main__':
    sys.exit(main())
