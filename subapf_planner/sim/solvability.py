"""Solvability of a world for a disc robot, on a grid: the checks of the world generator.

The obstacles' exact signed distance is sampled at the centres of a
GRID_RESOLUTION m grid; a cell is free when that distance is at least the
disc's radius (SOLVE_RADIUS: RobotDescription.solve_radius of the burger, its
0.105 m plus 0.05 m). A world is
solvable when the start's cell reaches the goal's through 4-connected free
cells; its geodesic length is the shortest 8-connected path through them
(scipy's Dijkstra; at most 8 % longer than the true shortest path). Pure numpy
and scipy: no ROS, no simulator.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np
from scipy import ndimage
from scipy.sparse import coo_matrix
from scipy.sparse.csgraph import dijkstra

from ..core.known_map import KnownMap
from ..core.robot import BURGER
from .world import Box, Circle, Obstacle, World, parse_world

#: Radius of the disc that must fit through every world [m] (the burger's footprint plus
#: core.robot.SOLVE_MARGIN).
SOLVE_RADIUS = BURGER.solve_radius
#: Cell size of the solvability and geodesic grid [m].
GRID_RESOLUTION = 0.05


def _as_world(world: World | dict[str, Any]) -> World:
    return world if isinstance(world, World) else parse_world(world)


def _extent(o: Obstacle) -> tuple[float, float, float, float]:
    """Axis-aligned bounding box (xmin, ymin, xmax, ymax) of an obstacle [m]."""
    if isinstance(o, Circle):
        (x, y), r = o.center, o.radius
        return x - r, y - r, x + r, y + r
    c, s = abs(math.cos(o.yaw)), abs(math.sin(o.yaw))
    hx, hy = o.size[0] / 2, o.size[1] / 2
    ex, ey = c * hx + s * hy, s * hx + c * hy
    return o.center[0] - ex, o.center[1] - ey, o.center[0] + ex, o.center[1] + ey


def _signed_distance(o: Obstacle, x: np.ndarray, y: np.ndarray) -> np.ndarray:
    """``o.distance`` on arrays (broadcast) [m]."""
    dx, dy = x - o.center[0], y - o.center[1]
    if isinstance(o, Circle):
        return np.hypot(dx, dy) - o.radius
    assert isinstance(o, Box)
    c, s = math.cos(o.yaw), math.sin(o.yaw)
    qx = np.abs(c * dx + s * dy) - o.size[0] / 2
    qy = np.abs(-s * dx + c * dy) - o.size[1] / 2
    return np.hypot(np.maximum(qx, 0.0), np.maximum(qy, 0.0)) \
        + np.minimum(np.maximum(qx, qy), 0.0)


def distance_field(world: World, resolution: float = GRID_RESOLUTION,
                   cap: float = math.inf) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Signed distance to the nearest obstacle (walls included) at the cell centres
    of a ``resolution`` m grid over the bounds (without bounds: the obstacles, start
    and goal plus 1 m); values above ``cap`` may be left at ``cap`` [m].

    Returns (dist[row = y, column = x], x of the columns, y of the rows)."""
    if world.bounds is not None:
        x0, y0, x1, y1 = world.bounds
    else:
        ext = [_extent(o) for o in world.obstacles] \
            + [(*world.start[:2], *world.start[:2]), (*world.goal, *world.goal)]
        x0, y0 = min(e[0] for e in ext) - 1.0, min(e[1] for e in ext) - 1.0
        x1, y1 = max(e[2] for e in ext) + 1.0, max(e[3] for e in ext) + 1.0
    xs = x0 + (np.arange(max(1, math.ceil((x1 - x0) / resolution - 1e-9))) + 0.5) * resolution
    ys = y0 + (np.arange(max(1, math.ceil((y1 - y0) / resolution - 1e-9))) + 0.5) * resolution
    dist = np.full((ys.size, xs.size), cap if math.isfinite(cap) else np.inf)
    for o in world.all_obstacles():
        if math.isfinite(cap):
            ex0, ey0, ex1, ey1 = _extent(o)
            i0, i1 = np.searchsorted(xs, [ex0 - cap, ex1 + cap])
            j0, j1 = np.searchsorted(ys, [ey0 - cap, ey1 + cap])
        else:
            i0, i1, j0, j1 = 0, xs.size, 0, ys.size
        if i0 >= i1 or j0 >= j1:
            continue
        window = dist[j0:j1, i0:i1]
        np.minimum(window, _signed_distance(o, xs[None, i0:i1], ys[j0:j1, None]), out=window)
    return dist, xs, ys


def _cell(xs: np.ndarray, ys: np.ndarray, x: float, y: float) -> tuple[int, int]:
    """(row, column) of the cell holding (x, y), clipped to the grid."""
    res = xs[1] - xs[0] if xs.size > 1 else ys[1] - ys[0] if ys.size > 1 else 1.0
    i = int(np.clip(math.floor((x - xs[0]) / res + 0.5), 0, xs.size - 1))
    j = int(np.clip(math.floor((y - ys[0]) / res + 0.5), 0, ys.size - 1))
    return j, i


def geodesic_length(world: World | dict[str, Any], radius: float = SOLVE_RADIUS,
                    resolution: float = GRID_RESOLUTION) -> float:
    """Length of the shortest path from start to goal for a disc of ``radius`` [m]
    (8-connected on the free cells of the module docstring's grid, plus the steps
    from start and goal to their cells' centres); ``math.inf`` when the goal's cell
    cannot be reached through 4-connected free cells (unsolvable)."""
    world = _as_world(world)
    dist, xs, ys = distance_field(world, resolution, cap=radius + 2 * resolution)
    free = dist >= radius
    s, g = _cell(xs, ys, *world.start[:2]), _cell(xs, ys, *world.goal)
    if not (free[s] and free[g]):
        return math.inf
    labels, _ = ndimage.label(free)
    if labels[s] != labels[g]:
        return math.inf
    comp = labels == labels[s]
    n = int(comp.sum())
    index = np.full(comp.shape, -1, np.int64)
    index[comp] = np.arange(n)
    h, w = comp.shape
    pad, pidx = np.pad(comp, 1), np.pad(index, 1, constant_values=-1)

    def shifted(a: np.ndarray, dj: int, di: int) -> np.ndarray:
        return a[1 + dj:h + 1 + dj, 1 + di:w + 1 + di]
    rows, cols, weights = [], [], []
    for dj, di in ((0, 1), (1, 0), (1, 1), (1, -1)):
        ok = comp & shifted(pad, dj, di)
        if dj and di:   # a diagonal step needs both cells beside it free
            ok &= shifted(pad, 0, di) & shifted(pad, dj, 0)
        rows.append(index[ok])
        cols.append(shifted(pidx, dj, di)[ok])
        weights.append(np.full(int(ok.sum()), resolution * math.hypot(dj, di)))
    graph = coo_matrix((np.concatenate(weights), (np.concatenate(rows), np.concatenate(cols))),
                       shape=(n, n)).tocsr()
    d = dijkstra(graph, directed=False, indices=int(index[s]))
    ends = (math.hypot(world.start[0] - xs[s[1]], world.start[1] - ys[s[0]])
            + math.hypot(world.goal[0] - xs[g[1]], world.goal[1] - ys[g[0]]))
    return float(d[index[g]]) + ends


def is_solvable(world: World | dict[str, Any], radius: float = SOLVE_RADIUS,
                resolution: float = GRID_RESOLUTION) -> bool:
    """True when a disc of ``radius`` [m] can go from start to goal (grid check of
    the module docstring)."""
    return math.isfinite(geodesic_length(world, radius, resolution))


def bottleneck_width(world: World | dict[str, Any], resolution: float = 0.02) -> float:
    """Twice the largest clearance kept along the best start-goal path: the width of
    the narrowest gap the robot must pass [m] (0 when none), to within ``resolution``
    (4-connected paths of ``resolution`` m cell centres; start and goal count too)."""
    world = _as_world(world)
    dist, xs, ys = distance_field(world, resolution)
    s, g = _cell(xs, ys, *world.start[:2]), _cell(xs, ys, *world.goal)
    levels = np.unique(dist[dist > 0.0])

    def joined(c: float) -> bool:
        free = dist >= c
        if not (free[s] and free[g]):
            return False
        labels, _ = ndimage.label(free)
        return bool(labels[s] == labels[g])
    lo, hi = -1, levels.size - 1   # joined(levels[lo]) holds, levels past hi fail
    while lo < hi:
        mid = (lo + hi + 1) // 2
        if joined(float(levels[mid])):
            lo = mid
        else:
            hi = mid - 1
    return 2.0 * float(levels[lo]) if lo >= 0 else 0.0


#: Cell of a world's map (map_server's usual 0.05 m) [m].
MAP_RESOLUTION = 0.05


def world_map(world: World, resolution: float = MAP_RESOLUTION) -> KnownMap:
    """The world's static obstacles as a map the robot already has (what SLAM or
    map_server would give; core/known_map.py): cells whose centre is within half a cell
    of an obstacle occupied (100), the rest of the bounds (without bounds: the
    obstacles, start and goal plus 1 m) free (0), in the world's frame, placed at the
    memory's origin (the memory's frame is odom at the start, which the simulator puts
    at the world's origin)."""
    dist, xs, ys = distance_field(world, resolution, cap=resolution)
    cells = np.where(dist < 0.5 * resolution, 100, 0).astype(np.int8)
    return KnownMap(cells, (float(xs[0] - 0.5 * resolution), float(ys[0] - 0.5 * resolution)),
                    resolution)
