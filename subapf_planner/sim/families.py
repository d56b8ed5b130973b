"""The world families of the dev suite: seeded layouts before the symmetry and the
checks of ``sim/worldgen.py`` (sizes in m).

* ``barn``: BARN-like, a 33 x 33 grid of 0.15 m cells (4.95 m square) filled
  10-35 % by thresholding smoothed noise, each filled cell an axis-aligned box
  (runs of cells merged into rectangles); start and goal in 1 m free margins on
  opposite sides.
* ``forest``: discs of radius 0.1-0.4 covering 8-20 % of a 5-8 x 4-6 room.
* ``doorway``: a wall across the room with one doorway 0.35-0.8 wide at a
  random offset, on the straight start-goal line about a third of the time.
* ``zigzag``: one corridor 0.5-1.0 wide with 2-4 right-angle turns (up and down
  in turn), a 1 m square chamber at each end for the start and the goal.
* ``u_trap`` / ``c_trap``: a U (three walls) or C (an elliptic arc) 0.8-2.5
  deep and 1.0-3.0 wide, open away from the goal; the robot starts inside or in
  front of it, so the straight line to the goal crosses it.
* ``maze``: 2x2 to 3x3 rooms of 2-3 m; the rooms of a random spanning tree
  (plus a few extra pairs) share a door 0.6-1.0 wide.
* ``long_walk``: a 15-25 m walk through 4-7 rooms in a row, each wall with one
  door 0.6-1.0 wide at a random offset.

Each builder draws from the given random generator only, on the STEP grid.
"""

from __future__ import annotations

from dataclasses import dataclass
import math
from typing import Any, Callable

import numpy as np
from scipy import ndimage

FAMILIES = ('barn', 'forest', 'doorway', 'zigzag', 'u_trap', 'c_trap', 'maze', 'long_walk')
#: Step of the random draws (positions, sizes) [m]: keeps the files short and the
#: widths exact (a door drawn 0.42 m wide is 0.42 m between its wall ends).
STEP = 0.01


@dataclass(frozen=True)
class FamilyRanges:
    """Parameter ranges of the families, (low, high) drawn uniformly. Lengths in m."""

    wall_thickness: tuple[float, float] = (0.1, 0.2)
    barn_cell: float = 0.15
    barn_cells: int = 33
    barn_fill: tuple[float, float] = (0.10, 0.35)
    #: Smoothing of the noise behind the fill [cells]: larger makes bigger clumps.
    barn_smoothing: tuple[float, float] = (0.6, 1.5)
    barn_margin: float = 1.0
    forest_size: tuple[tuple[float, float], tuple[float, float]] = ((5.0, 8.0), (4.0, 6.0))
    forest_radius: tuple[float, float] = (0.1, 0.4)
    #: Fraction of the room's area the discs cover (overlaps counted twice).
    forest_cover: tuple[float, float] = (0.08, 0.20)
    doorway_room: tuple[tuple[float, float], tuple[float, float]] = ((4.0, 7.0), (3.0, 5.0))
    doorway_width: tuple[float, float] = (0.35, 0.8)
    #: Probability that the doorway is centred on the straight start-goal line.
    doorway_on_line: float = 0.35
    corridor_width: tuple[float, float] = (0.5, 1.0)
    zigzag_turns: tuple[int, int] = (2, 4)
    #: Centre-line length of a corridor leg between two turns.
    zigzag_leg: tuple[float, float] = (1.5, 3.0)
    #: Side of the square chambers at the corridor's ends.
    zigzag_chamber: float = 1.0
    trap_depth: tuple[float, float] = (0.8, 2.5)
    trap_width: tuple[float, float] = (1.0, 3.0)
    #: Probability that the robot starts inside the trap (else in front of its mouth).
    trap_inside: float = 0.5
    #: Half-angle of the C's arc seen from its centre, from the goal's direction [deg].
    c_trap_arc: tuple[float, float] = (110.0, 150.0)
    #: Length of the boxes the C's arc is made of.
    c_trap_segment: float = 0.4
    maze_rooms: tuple[int, int] = (2, 3)
    room_size: tuple[float, float] = (2.0, 3.0)
    door_width: tuple[float, float] = (0.6, 1.0)
    #: Least wall left between a door and a wall junction.
    door_margin: float = 0.35
    #: Probability of a door between two rooms the spanning tree does not join.
    maze_loop: float = 0.2
    walk_length: tuple[float, float] = (15.0, 25.0)
    walk_width: tuple[float, float] = (2.5, 4.0)
    #: Longest room of a long walk.
    walk_room: float = 4.0
    #: Distance from the start (goal) to the end wall behind it.
    walk_end: float = 0.6


RANGES = FamilyRanges()


@dataclass(frozen=True)
class Layout:
    """A family's drawing before the symmetry, the shift and the checks."""

    start: tuple[float, float]
    goal: tuple[float, float]
    bounds: tuple[float, float, float, float]
    obstacles: tuple[dict[str, Any], ...]
    note: str
    blocked: bool = False   # the straight start-goal line must cross an obstacle
    #: Moving obstacles as the world format writes them (sim/dynamic_families.py).
    moving: tuple[dict[str, Any], ...] = ()


# --------------------------------------------------------------------------- draws


def on_grid(v: float) -> float:
    """``v`` on the STEP grid [m]."""
    return round(round(v / STEP) * STEP, 4) + 0.0


def draw(rng: np.random.Generator, lo: float, hi: float) -> float:
    """Uniform draw on the STEP grid in [lo, hi]; the grid point nearest the middle
    when the interval holds none."""
    a, b = math.ceil(lo / STEP - 1e-9), math.floor(hi / STEP + 1e-9)
    if a > b:
        return on_grid((lo + hi) / 2)
    return round(int(rng.integers(a, b + 1)) * STEP, 4) + 0.0


def box(x0: float, y0: float, x1: float, y1: float) -> dict[str, Any]:
    """Axis-aligned box from its edges [m]."""
    return {'box': {'center': [(x0 + x1) / 2, (y0 + y1) / 2], 'size': [x1 - x0, y1 - y0]}}


def _yawed_box(cx: float, cy: float, length: float, thickness: float,
               yaw: float) -> dict[str, Any]:
    """Box of ``length`` along ``yaw`` [rad] and ``thickness`` across it [m]."""
    return {'box': {'center': [cx, cy], 'size': [length, thickness], 'yaw': yaw}}


def circle(cx: float, cy: float, r: float) -> dict[str, Any]:
    return {'circle': {'center': [cx, cy], 'radius': r}}


def _runs(row: np.ndarray) -> list[tuple[int, int]]:
    """Half-open [start, end) runs of True in a 1-D boolean array."""
    d = np.diff(np.concatenate(([0], row.astype(np.int8), [0])))
    return list(zip(np.flatnonzero(d == 1).tolist(), np.flatnonzero(d == -1).tolist(),
                    strict=True))


def _rectangles(occ: np.ndarray) -> list[tuple[int, int, int, int]]:
    """Rectangles (row0, row1, col0, col1), half-open, that cover the True cells of
    ``occ`` exactly: the runs of each row, a run continued in the next rows when
    they have the same run."""
    out: list[tuple[int, int, int, int]] = []
    open_runs: dict[tuple[int, int], int] = {}
    for j in range(occ.shape[0] + 1):
        runs = set(_runs(occ[j])) if j < occ.shape[0] else set()
        for run in [r for r in open_runs if r not in runs]:
            out.append((open_runs.pop(run), j, *run))
        for run in runs:
            open_runs.setdefault(run, j)
    return sorted(out)


def _carve(bounds: tuple[float, float, float, float],
           free: list[tuple[float, float, float, float]]) -> list[dict[str, Any]]:
    """Boxes filling ``bounds`` except the union of the ``free`` rectangles
    (x0, y0, x1, y1) [m]: the complement on the grid of all their edges, merged."""
    x0, y0, x1, y1 = bounds
    xs = np.unique(np.round([x0, x1] + [min(max(v, x0), x1) for f in free
                                        for v in (f[0], f[2])], 4))
    ys = np.unique(np.round([y0, y1] + [min(max(v, y0), y1) for f in free
                                        for v in (f[1], f[3])], 4))
    cx, cy = (xs[:-1] + xs[1:]) / 2, (ys[:-1] + ys[1:]) / 2
    occ = np.ones((cy.size, cx.size), bool)
    for fx0, fy0, fx1, fy1 in free:
        occ[np.ix_((cy > fy0) & (cy < fy1), (cx > fx0) & (cx < fx1))] = False
    return [box(float(xs[c0]), float(ys[r0]), float(xs[c1]), float(ys[r1]))
            for r0, r1, c0, c1 in _rectangles(occ)]


def solid(lo: float, hi: float, gaps: list[tuple[float, float]]) -> list[tuple[float, float]]:
    """[lo, hi] minus the ``gaps`` (sorted, disjoint, inside it)."""
    out, at = [], lo
    for a, b in sorted(gaps):
        if a > at:
            out.append((at, a))
        at = max(at, b)
    if hi > at:
        out.append((at, hi))
    return out


def door(rng: np.random.Generator, lo: float, hi: float, width: tuple[float, float],
          margin: float) -> tuple[float, float]:
    """A door (a, b) of a width drawn in ``width`` on the wall [lo, hi], at least
    ``margin`` from both ends [m]."""
    w = draw(rng, *width)
    c = draw(rng, lo + margin + w / 2, hi - margin - w / 2)
    return c - w / 2, c + w / 2


# ------------------------------------------------------------------------ families


def _barn(rng: np.random.Generator, r: FamilyRanges) -> Layout:
    n, cell = r.barn_cells, r.barn_cell
    side = n * cell
    fill = draw(rng, *r.barn_fill)
    sigma = draw(rng, *r.barn_smoothing)
    noise = ndimage.gaussian_filter(rng.standard_normal((n, n)), sigma, mode='reflect')
    filled = np.argsort(noise, axis=None, kind='stable')[::-1][:round(fill * n * n)]
    occ = np.zeros(n * n, bool)
    occ[filled] = True
    occ = occ.reshape(n, n)          # row = y, column = x
    boxes = tuple(box(c0 * cell, r0 * cell, c1 * cell, r1 * cell)
                  for r0, r1, c0, c1 in _rectangles(occ))
    m = r.barn_margin
    return Layout((-m / 2, draw(rng, 0.5, side - 0.5)),
                  (side + m / 2, draw(rng, 0.5, side - 0.5)),
                  (-m, 0.0, side + m, side), boxes,
                  f'{n}x{n} cells of {cell} m, fill {fill:.2f}, smoothing {sigma:.2f} cells')


def _forest(rng: np.random.Generator, r: FamilyRanges) -> Layout:
    lx, ly = draw(rng, *r.forest_size[0]), draw(rng, *r.forest_size[1])
    cover = draw(rng, *r.forest_cover)
    start, goal = (0.5, draw(rng, 0.5, ly - 0.5)), (lx - 0.5, draw(rng, 0.5, ly - 0.5))
    discs, area = [], 0.0
    for _ in range(1000):
        if area >= cover * lx * ly:
            break
        rad = draw(rng, *r.forest_radius)
        x, y = draw(rng, 0.0, lx), draw(rng, 0.0, ly)
        if min(math.dist((x, y), start), math.dist((x, y), goal)) < rad + 0.5:
            continue
        discs.append(circle(x, y, rad))
        area += math.pi * rad * rad
    return Layout(start, goal, (0.0, 0.0, lx, ly), tuple(discs),
                   f'{len(discs)} discs covering {area / (lx * ly):.2f} of {lx} x {ly} m')


def _doorway(rng: np.random.Generator, r: FamilyRanges) -> Layout:
    lx, ly = draw(rng, *r.doorway_room[0]), draw(rng, *r.doorway_room[1])
    t = draw(rng, *r.wall_thickness)
    xw = draw(rng, 0.4 * lx, 0.6 * lx)
    w = draw(rng, *r.doorway_width)
    start, goal = (0.6, draw(rng, 0.6, ly - 0.6)), (lx - 0.6, draw(rng, 0.6, ly - 0.6))
    lo, hi = 0.3 + w / 2, ly - 0.3 - w / 2
    if rng.random() < r.doorway_on_line:
        on_line = start[1] + (goal[1] - start[1]) * (xw - start[0]) / (goal[0] - start[0])
        c = min(max(on_grid(on_line), on_grid(lo + STEP / 2)), on_grid(hi - STEP / 2))
    else:
        c = draw(rng, lo, hi)
    walls = (box(xw - t / 2, 0.0, xw + t / 2, c - w / 2),
             box(xw - t / 2, c + w / 2, xw + t / 2, ly))
    return Layout(start, goal, (0.0, 0.0, lx, ly), walls,
                   f'doorway {w:.2f} m wide in a {t:.2f} m wall, room {lx} x {ly} m')


def _zigzag(rng: np.random.Generator, r: FamilyRanges) -> Layout:
    w = draw(rng, *r.corridor_width)
    turns = int(rng.integers(r.zigzag_turns[0], r.zigzag_turns[1] + 1))
    side = 1.0 if rng.random() < 0.5 else -1.0
    pts = [(0.0, 0.0)]
    for k in range(turns + 1):
        x, y = pts[-1]
        leg = draw(rng, *r.zigzag_leg)
        if k % 2 == 0:
            pts.append((x + leg, y))
        else:
            pts.append((x, y + side * leg))
            side = -side
    h, s = w / 2, r.zigzag_chamber
    free = [(min(a[0], b[0]) - h, min(a[1], b[1]) - h, max(a[0], b[0]) + h,
             max(a[1], b[1]) + h) for a, b in zip(pts, pts[1:], strict=False)]
    (ax, ay), (bx, by) = pts[-2], pts[-1]
    d = (np.sign(bx - ax), np.sign(by - ay))
    goal = (bx + d[0] * s / 2, by + d[1] * s / 2)
    start = (-s / 2, 0.0)
    free += [(start[0] - s / 2, -s / 2, start[0] + s / 2, s / 2),
             (goal[0] - s / 2, goal[1] - s / 2, goal[0] + s / 2, goal[1] + s / 2)]
    wall = 0.3
    bounds = (min(f[0] for f in free) - wall, min(f[1] for f in free) - wall,
              max(f[2] for f in free) + wall, max(f[3] for f in free) + wall)
    return Layout(start, goal, bounds, tuple(_carve(bounds, free)),
                   f'corridor {w:.2f} m wide, {turns} turns')


def _trap_ends(rng: np.random.Generator, r: FamilyRanges, mouth: float, bottom: float,
               half: float) -> tuple[tuple[float, float], tuple[float, float], str]:
    """Start inside (between ``mouth`` and ``bottom`` x) or in front of the trap's
    mouth, goal behind its bottom, both within ``half`` of the axis [m]."""
    inside = rng.random() < r.trap_inside
    if inside:
        x = draw(rng, mouth + 0.35, bottom - 0.35)
    else:
        x = draw(rng, mouth - 1.5, mouth - 0.5)
    start = (x, draw(rng, -half, half))
    goal = (bottom + draw(rng, 0.6, 1.8), draw(rng, -half, half))
    return start, goal, 'inside' if inside else 'in front'


def _trap_bounds(rng: np.random.Generator, start: tuple[float, float],
                 goal: tuple[float, float], mouth: float,
                 half_width: float) -> tuple[float, float, float, float]:
    side = half_width + draw(rng, 1.0, 1.8)
    return (on_grid(min(start[0], mouth) - draw(rng, 0.8, 1.5)), -side,
            on_grid(goal[0] + 0.6), side)


def _u_trap(rng: np.random.Generator, r: FamilyRanges) -> Layout:
    depth, width = draw(rng, *r.trap_depth), draw(rng, *r.trap_width)
    t = draw(rng, *r.wall_thickness)
    hw = width / 2
    walls = (box(-t / 2, -hw - t / 2, t / 2, hw + t / 2),
             box(-depth, -hw - t / 2, 0.0, -hw + t / 2),
             box(-depth, hw - t / 2, 0.0, hw + t / 2))
    start, goal, where = _trap_ends(rng, r, -depth, -t / 2, max(0.0, hw - t / 2 - 0.35))
    return Layout(start, goal, _trap_bounds(rng, start, goal, -depth, hw + t / 2), walls,
                   f'U {depth:.2f} m deep, {width:.2f} m wide, start {where}', blocked=True)


def _c_trap(rng: np.random.Generator, r: FamilyRanges) -> Layout:
    depth, width = draw(rng, *r.trap_depth), draw(rng, *r.trap_width)
    t = draw(rng, *r.wall_thickness)
    phi = math.radians(draw(rng, *r.c_trap_arc))
    a, b = depth / (1.0 - math.cos(phi)), width / 2
    theta = np.linspace(-phi, phi, 721)
    xy = np.column_stack((a * np.cos(theta), b * np.sin(theta)))
    arc = np.concatenate(([0.0], np.cumsum(np.hypot(*np.diff(xy, axis=0).T))))
    n = max(6, math.ceil(arc[-1] / r.c_trap_segment))
    at = np.linspace(0.0, arc[-1], n + 1)
    knots = np.column_stack((np.interp(at, arc, xy[:, 0]), np.interp(at, arc, xy[:, 1])))
    walls = []
    for p, q in zip(knots[:-1], knots[1:], strict=True):
        d = q - p
        walls.append(_yawed_box(float((p[0] + q[0]) / 2), float((p[1] + q[1]) / 2),
                                float(np.hypot(*d)) + t, t, math.atan2(d[1], d[0])))
    mouth = a * math.cos(phi)
    start, goal, where = _trap_ends(rng, r, mouth, a - t / 2, 0.3 * b)
    return Layout(start, goal, _trap_bounds(rng, start, goal, mouth, b + t / 2), tuple(walls),
                   f'C {depth:.2f} m deep, {width:.2f} m wide, arc +-{math.degrees(phi):.0f} '
                   f'deg, start {where}', blocked=True)


def _maze(rng: np.random.Generator, r: FamilyRanges) -> Layout:
    rows, cols = (int(v) for v in rng.integers(r.maze_rooms[0], r.maze_rooms[1] + 1, size=2))
    xs = np.concatenate(([0.0], np.cumsum([draw(rng, *r.room_size) for _ in range(cols)])))
    ys = np.concatenate(([0.0], np.cumsum([draw(rng, *r.room_size) for _ in range(rows)])))
    xs, ys = [on_grid(v) for v in xs], [on_grid(v) for v in ys]
    t = draw(rng, *r.wall_thickness)
    edges = [((j, i), (j, i + 1)) for j in range(rows) for i in range(cols - 1)] \
        + [((j, i), (j + 1, i)) for j in range(rows - 1) for i in range(cols)]
    parent = {(j, i): (j, i) for j in range(rows) for i in range(cols)}

    def root(c: tuple[int, int]) -> tuple[int, int]:
        while parent[c] != c:
            c = parent[c]
        return c
    doors: dict[tuple[str, int], list[tuple[float, float]]] = {}
    n_doors = 0
    for k in rng.permutation(len(edges)).tolist():
        (j, i), (j2, i2) = edges[k]
        ra, rb = root((j, i)), root((j2, i2))
        if ra == rb and rng.random() >= r.maze_loop:
            continue
        parent[ra] = rb
        if j == j2:   # side by side: door in the vertical wall x = xs[i + 1]
            line, lo, hi = ('v', i + 1), ys[j], ys[j + 1]
        else:
            line, lo, hi = ('h', j + 1), xs[i], xs[i + 1]
        doors.setdefault(line, []).append(door(rng, lo, hi, r.door_width, r.door_margin))
        n_doors += 1
    walls = []
    for k in range(1, cols):
        walls += [box(xs[k] - t / 2, a, xs[k] + t / 2, b)
                  for a, b in solid(ys[0], ys[-1], doors.get(('v', k), []))]
    for k in range(1, rows):
        walls += [box(a, ys[k] - t / 2, b, ys[k] + t / 2)
                  for a, b in solid(xs[0], xs[-1], doors.get(('h', k), []))]

    def spot(lo: float, hi: float) -> float:
        return draw(rng, lo + 0.5, hi - 0.5)
    start = (spot(xs[0], xs[1]), spot(ys[0], ys[1]))
    goal = (spot(xs[-2], xs[-1]), spot(ys[-2], ys[-1]))
    return Layout(start, goal, (xs[0], ys[0], xs[-1], ys[-1]), tuple(walls),
                   f'{cols}x{rows} rooms, {n_doors} doors, walls {t:.2f} m')


def _long_walk(rng: np.random.Generator, r: FamilyRanges) -> Layout:
    walk, ly = draw(rng, *r.walk_length), draw(rng, *r.walk_width)
    t = draw(rng, *r.wall_thickness)
    end = r.walk_end
    total = on_grid(walk + 2 * end)
    n = max(2, math.ceil(total / r.walk_room))
    xs = [on_grid(k * total / n + rng.uniform(-0.3, 0.3)) for k in range(1, n)]
    walls = []
    for x in xs:
        for a, b in solid(0.0, ly, [door(rng, 0.0, ly, r.door_width, r.door_margin)]):
            walls.append(box(x - t / 2, a, x + t / 2, b))
    start, goal = (end, draw(rng, 0.5, ly - 0.5)), (total - end, draw(rng, 0.5, ly - 0.5))
    return Layout(start, goal, (0.0, 0.0, total, ly), tuple(walls),
                   f'{n} rooms in a row, {total:.2f} x {ly:.2f} m')


BUILDERS: dict[str, Callable[[np.random.Generator, FamilyRanges], Layout]] = {
    'barn': _barn, 'forest': _forest, 'doorway': _doorway, 'zigzag': _zigzag,
    'u_trap': _u_trap, 'c_trap': _c_trap, 'maze': _maze, 'long_walk': _long_walk}
