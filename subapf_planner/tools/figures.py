"""``subapf-figures``: the paper's Fig. 1-3 redrawn from the core code (PNG).

Fig. 1: potential of four point obstacles at (+-1, +-1), ``+sum 1/r`` (a strict
local minimum at the origin) against ``-sum log10 r`` (a saddle), plus the
exponential sum, which also has a local minimum there (docs/paper_notes.md section 3).
Fig. 2: |d phi/d r| of the three repulsions against distance.
Fig. 3: raw APF iterations (no robot dynamics, no sampling) in the narrowing
passage world, one trajectory per repulsion.
"""

from __future__ import annotations

import argparse
from pathlib import Path
import sys

import matplotlib

matplotlib.use('Agg')
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

from ..core.apf import apf_step  # noqa: E402
from ..core.config import PlannerConfig, load_config  # noqa: E402
from ..core.potentials import repulsive_dr, repulsive_field  # noqa: E402
from ..ros.paths import default_params_file, shipped_worlds_dir  # noqa: E402
from ..sim.world import World, load_world, obstacle_outline  # noqa: E402
from .plots import METHOD_STYLE, draw_world  # noqa: E402

FOUR_POINTS = np.array([[1.0, 1.0], [-1.0, -1.0], [-1.0, 1.0], [1.0, -1.0]])


def four_point_potential(kind: str, xy: np.ndarray, k: float = 4.0) -> np.ndarray:
    """Sum of one repulsion over the four points, gain 1, at points (n, 2)."""
    values, _ = repulsive_field(kind, xy, FOUR_POINTS, 1.0, k)
    return values


def world_points(world: World, spacing: float = 0.05) -> np.ndarray:
    """Point obstacles every ``spacing`` metres along every obstacle's outline."""
    pts = []
    for o in world.all_obstacles():
        outline = obstacle_outline(o, n=max(8, int(60 * spacing ** -0.5)))
        for a, b in zip(outline[:-1], outline[1:], strict=True):
            n = max(1, int(np.ceil(np.hypot(*(b - a)) / spacing)))
            pts.append(a + (b - a) * (np.arange(n)[:, None] / n))
    return np.vstack(pts) if pts else np.zeros((0, 2))


def apf_trajectory(cfg: PlannerConfig, start: np.ndarray, goal: np.ndarray,
                   obstacles: np.ndarray, steps: int = 400) -> np.ndarray:
    """Iterate the raw APF step (eq. 23) from start; stop at the goal tolerance."""
    path = [np.asarray(start, float)]
    for _ in range(steps):
        if np.hypot(*(path[-1] - goal)) <= cfg.goal_tolerance:
            break
        path.append(apf_step(path[-1], goal, obstacles, cfg)[0])
    return np.asarray(path)


def fig1(out: Path) -> Path:
    xs = np.linspace(-1.6, 1.6, 161)
    gx, gy = np.meshgrid(xs, xs)
    xy = np.column_stack((gx.ravel(), gy.ravel()))
    fig, axes = plt.subplots(1, 3, figsize=(14, 4.4), subplot_kw={'projection': '3d'})
    for ax, kind, title in zip(axes, ('harmonic', 'traditional', 'subharmonic'),  # noqa: B905
                               ('-sum log10 r (harmonic): saddle at 0',
                                '+sum 1/r (traditional): minimum at 0',
                                '+sum exp(-4 r^2): also a minimum at 0')):
        z = four_point_potential(kind, xy).reshape(gx.shape)
        z = np.clip(z, None, np.percentile(z, 97))
        ax.plot_surface(gx, gy, z, cmap='viridis', linewidth=0, antialiased=True)
        ax.set_title(title, fontsize=10)
        ax.set_xlabel('x [m]')
        ax.set_ylabel('y [m]')
    return _save(fig, out / 'fig1_four_point_potentials.png')


def fig2(out: Path, cfg: PlannerConfig) -> Path:
    r = np.linspace(0.02, 1.5, 400)
    fig, ax = plt.subplots(figsize=(6.5, 4.5))
    for kind, method in (('traditional', 'traditional'), ('harmonic', 'harmonic'),
                         ('subharmonic', 'subharmonic')):
        color, label = METHOD_STYLE[method]
        ax.plot(r, np.abs(repulsive_dr(kind, r, cfg.repulsion_gain, cfg.k)), color=color,
                label=label)
    ax.axvline(cfg.danger_distance, color='k', ls=':', label='danger distance d0')
    ax.set_yscale('log')
    ax.set_xlabel('distance to obstacle r [m]')
    ax.set_ylabel('|d phi / d r|')
    ax.set_title(f'Repulsion slope, gain {cfg.repulsion_gain}, k = {cfg.k:.0f} 1/m^2')
    ax.legend()
    ax.grid(True, alpha=0.3)
    return _save(fig, out / 'fig2_derivatives.png')


def fig3(out: Path, cfg: PlannerConfig, world: World) -> Path:
    obstacles = world_points(world)
    start, goal = np.asarray(world.start[:2]), np.asarray(world.goal)
    fig, ax = plt.subplots(figsize=(9, 3.8))
    draw_world(ax, world)
    for method in ('traditional', 'harmonic', 'subharmonic'):
        path = apf_trajectory(cfg.replace(method=method), start, goal, obstacles)
        color, label = METHOD_STYLE[method]
        ax.plot(path[:, 0], path[:, 1], '.-', color=color, ms=2, lw=1, label=label)
    ax.set_title('Raw APF steps in a narrowing passage (no dynamics, no sampling)')
    ax.legend(fontsize=8)
    return _save(fig, out / 'fig3_narrowing_passage.png')


def _save(fig: plt.Figure, path: Path) -> Path:
    path.parent.mkdir(parents=True, exist_ok=True)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)
    return path


def main(argv: list[str] | None = None) -> int:
    p = argparse.ArgumentParser(prog='subapf-figures', description=__doc__.splitlines()[0])
    p.add_argument('--out', required=True, help='output directory')
    p.add_argument('--params', default=None, help='params YAML (default: config/planner.yaml)')
    args = p.parse_args(argv)
    out = Path(args.out)
    cfg = load_config(args.params or default_params_file())
    world = load_world(shipped_worlds_dir() / 'fig3_narrowing_passage.yaml')
    for path in (fig1(out), fig2(out, cfg), fig3(out, cfg, world)):
        print(path)
    return 0


if __name__ == '__main__':
    sys.exit(main())
