"""An animated GIF of a run: the world, the moving obstacles and each robot over time
(matplotlib's FuncAnimation with the Pillow writer; headless Agg)."""

from __future__ import annotations

from pathlib import Path
from typing import Mapping

import matplotlib

matplotlib.use('Agg')
from matplotlib.animation import FuncAnimation, PillowWriter  # noqa: E402
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

from ..core.robot import BURGER  # noqa: E402
from ..sim.world import World, obstacle_outline  # noqa: E402
from .plots import draw_world, method_style  # noqa: E402

#: Simulated time between two frames [s], and frames shown per second.
FRAME_STEP = 0.5
FPS = 8


def animate_run(world: World, paths: Mapping[str, np.ndarray], out: str | Path,
                period: float = 0.2) -> Path:
    """A GIF of each method's robot (its footprint and the path so far) and the moving
    obstacles where they were, a frame every FRAME_STEP s of simulated time. ``paths``
    hold one (x, y[, yaw]) point per planning ``period`` [s] from t = 0."""
    longest = max((len(p) for p in paths.values()), default=1)
    times = np.arange(0.0, (longest - 1) * period + 1e-9, FRAME_STEP)
    fig, ax = plt.subplots(figsize=(5.0, 5.0))
    draw_world(ax, world)
    movers = [ax.fill([], [], color='tab:orange', alpha=0.6, zorder=2)[0]
              for _ in world.moving]
    robots = {}
    for method, path in paths.items():
        color, style, label = method_style(method)
        trail, = ax.plot([], [], color=color, ls=style, lw=1.4, label=label, zorder=3)
        body = plt.Circle((np.nan, np.nan), BURGER.radius, color=color, zorder=4)
        ax.add_patch(body)
        robots[method] = (np.asarray(path, float), trail, body)
    title = ax.set_title(world.name)
    ax.legend(loc='upper left', fontsize=7)

    def frame(i: int) -> list:
        t = float(times[i])
        for patch, o in zip(movers, world.moving_at(t), strict=True):
            patch.set_xy(obstacle_outline(o))
        for path, trail, body in robots.values():
            k = min(int(round(t / period)), len(path) - 1)
            trail.set_data(path[:k + 1, 0], path[:k + 1, 1])
            body.center = (path[k, 0], path[k, 1])
        title.set_text(f'{world.name}   t = {t:5.1f} s')
        return movers + [title]

    anim = FuncAnimation(fig, frame, frames=len(times), blit=False)
    out = Path(out)
    out.parent.mkdir(parents=True, exist_ok=True)
    anim.save(out, writer=PillowWriter(fps=FPS), dpi=70)
    plt.close(fig)
    return out
