"""Trajectory plots in the style of the paper's Fig. 6 (matplotlib, headless Agg)."""

from __future__ import annotations

from pathlib import Path
from typing import Mapping

import matplotlib

matplotlib.use('Agg')
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

from ..sim.world import World, obstacle_outline  # noqa: E402

METHOD_STYLE = {
    'subharmonic_sampling': ('tab:red', 'subharmonic + sampling'),
    'subharmonic': ('tab:orange', 'subharmonic'),
    'traditional': ('tab:blue', 'traditional 1/r'),
    'harmonic': ('tab:green', 'harmonic log'),
    'dwa': ('tab:purple', 'DWA'),
}
#: Line style of each attraction field in a method label ``method[:field]``.
FIELD_STYLE = {'geodesic': ('-', 'geodesic'), 'euclidean': ('--', 'euclidean')}


def method_style(label: str) -> tuple[str, str, str]:
    """(colour, line style, legend text) of a benchmark method label: the colour says
    the method, the line style the attraction field (solid geodesic, dashed Euclidean)."""
    method, _, field = label.partition(':')
    color, text = METHOD_STYLE.get(method, ('k', method))
    style, field_text = FIELD_STYLE.get(field, ('-', field))
    return color, style, f'{text}, {field_text}' if field_text else text


def draw_world(ax: plt.Axes, world: World) -> None:
    """Obstacles (grey), start (black triangle) and goal (star with tolerance circle)."""
    for o in world.all_obstacles():
        outline = obstacle_outline(o)
        ax.fill(outline[:, 0], outline[:, 1], color='0.55', zorder=1)
    sx, sy, _ = world.start
    ax.plot(sx, sy, 'k^', ms=9, zorder=4)
    ax.plot(*world.goal, 'k*', ms=13, zorder=4)
    ax.add_patch(plt.Circle(world.goal, world.goal_tolerance, fill=False, ls=':', color='k'))
    ax.set_aspect('equal')
    ax.grid(True, alpha=0.3)
    ax.set_xlabel('x [m]')
    ax.set_ylabel('y [m]')


#: Instants at which a plot shows the moving obstacles and the robots.
MOVING_INSTANTS = 4
#: Colours of those instants (early -> late).
INSTANT_CMAP = 'plasma'


def draw_moving(ax: plt.Axes, world: World, instants: np.ndarray) -> list:
    """Each moving obstacle's path (dotted) and its outline at each of ``instants`` [s],
    coloured by time (INSTANT_CMAP, labelled t = ...); returns the instants' colours."""
    colors = [plt.get_cmap(INSTANT_CMAP)(0.85 * i / max(len(instants) - 1, 1))
              for i in range(len(instants))]
    for m in world.moving:
        horizon = m.period if m.loop else max(float(instants[-1]) if len(instants) else 0.0,
                                              m.period)
        track = m.position(np.linspace(0.0, horizon, 200))
        ax.plot(track[:, 0], track[:, 1], ':', color='0.35', lw=0.8, zorder=1)
    for t, color in zip(instants, colors, strict=True):
        for o in world.moving_at(float(t)):
            outline = obstacle_outline(o)
            ax.fill(outline[:, 0], outline[:, 1], color=color, alpha=0.35, zorder=2)
            ax.plot(outline[:, 0], outline[:, 1], color=color, lw=1.0, zorder=2)
        ax.plot([], [], 's', color=color, alpha=0.6, label=f't = {t:.0f} s')
    return colors


def plot_trajectories(world: World, paths: Mapping[str, np.ndarray],
                      outcomes: Mapping[str, str], out: str | Path,
                      period: float = 0.2) -> Path:
    """One PNG: the world and each method's driven path with its outcome. Paths hold one
    point per planning ``period`` [s] from t = 0; with moving obstacles they are drawn
    at MOVING_INSTANTS instants, and each robot where it was then (same colours)."""
    fig, ax = plt.subplots(figsize=(6.5, 6.5))
    draw_world(ax, world)
    longest = max((len(p) for p in paths.values()), default=1)
    instants = np.linspace(0.0, (longest - 1) * period, MOVING_INSTANTS) if world.moving \
        else np.zeros(0)
    colors = draw_moving(ax, world, instants) if world.moving else []
    for method, path in paths.items():
        color, style, label = method_style(method)
        if len(path):
            ax.plot(path[:, 0], path[:, 1], color=color, ls=style, lw=1.6,
                    label=f'{label}: {outcomes.get(method, "?")}', zorder=3)
            ax.plot(path[-1, 0], path[-1, 1], 'o', color=color, ms=4, zorder=3)
        for t, c in zip(instants, colors, strict=True):
            k = min(int(round(t / period)), len(path) - 1)
            ax.plot(path[k, 0], path[k, 1], 'o', mfc=c, mec=color, mew=1.5, ms=7, zorder=4)
    ax.set_title(world.name)
    ax.legend(loc='best', fontsize=8)
    out = Path(out)
    out.parent.mkdir(parents=True, exist_ok=True)
    fig.tight_layout()
    fig.savefig(out, dpi=110)
    plt.close(fig)
    return out
