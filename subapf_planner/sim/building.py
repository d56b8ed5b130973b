"""The ``building`` family: a floor of an office building, to measure getting there
through rooms and doors without real maps (sizes in m).

A corridor 1.2-2.0 wide and 12-20 long runs along x; rooms 3-5 wide and 3-4.5
deep line both of its sides. Each room opens on the corridor by a door 0.6-0.9
wide (at least DOOR_MARGIN from the room's corners); neighbouring rooms share a
second door with probability ``side_door``. Rooms hold 1-5 pieces of furniture:
tables and cupboards (boxes 0.4-1.6 x 0.4-1.0, any yaw) and chairs or bins
(discs of radius 0.15-0.3), kept DOOR_CLEAR from the inside of the doors so that
a door is not walled up (the world's solvability check rejects the rest). The
start is in one room and the goal in another at least MIN_SEPARATION away (on
either side). As for every family, ``sim/worldgen.py`` turns, shifts and checks
the layout.
"""

from __future__ import annotations

from dataclasses import dataclass
import math

import numpy as np

from .families import Layout, box, circle, door, draw, on_grid, solid

BUILDING_FAMILIES = ('building',)
#: Least distance from a door to a room's corner [m].
DOOR_MARGIN = 0.3
#: No furniture within this of the inside middle of a door [m].
DOOR_CLEAR = 0.8
#: The start and goal are at least this far from a room's walls [m] ...
ENDPOINT_MARGIN = 0.6
#: ... and their rooms' centres at least this far apart (the farthest room if none is).
MIN_SEPARATION = 6.0


@dataclass(frozen=True)
class BuildingRanges:
    """Ranges (lo, hi) the building family draws from [m], counts as (lo, hi)."""

    corridor_width: tuple[float, float] = (1.2, 2.0)
    corridor_length: tuple[float, float] = (12.0, 20.0)
    room_width: tuple[float, float] = (3.0, 5.0)
    room_depth: tuple[float, float] = (3.0, 4.5)
    door_width: tuple[float, float] = (0.6, 0.9)
    wall_thickness: tuple[float, float] = (0.1, 0.15)
    furniture: tuple[int, int] = (1, 5)
    table_size: tuple[float, float] = (0.4, 1.6)
    table_depth: tuple[float, float] = (0.4, 1.0)
    chair_radius: tuple[float, float] = (0.15, 0.3)
    side_door: float = 0.3


BUILDING_RANGES = BuildingRanges()


def _room_edges(rng: np.random.Generator, length: float,
                widths: tuple[float, float]) -> list[float]:
    """x of the walls between rooms along a corridor side, 0 and ``length`` included."""
    xs = [0.0]
    while length - xs[-1] > widths[1]:
        xs.append(on_grid(xs[-1] + draw(rng, *widths)))
    if length - xs[-1] < widths[0] and len(xs) > 1:
        xs.pop()
    return xs + [length]


def _furniture(rng: np.random.Generator, r: BuildingRanges, room: tuple[float, ...],
               doors: list[tuple[float, float]]) -> list[dict]:
    """Furniture inside ``room`` (x0, y0, x1, y1), clear of the door points ``doors``."""
    x0, y0, x1, y1 = room
    out = []
    for _ in range(int(rng.integers(r.furniture[0], r.furniture[1] + 1))):
        if rng.random() < 0.5:
            a, b = draw(rng, *r.table_size), draw(rng, *r.table_depth)
            reach = 0.5 * math.hypot(a, b)
            piece = 'table'
        else:
            reach = draw(rng, *r.chair_radius)
            piece = 'chair'
        if x1 - x0 < 2 * reach + 0.2 or y1 - y0 < 2 * reach + 0.2:
            continue
        cx, cy = draw(rng, x0 + reach, x1 - reach), draw(rng, y0 + reach, y1 - reach)
        if any(math.hypot(cx - dx, cy - dy) < DOOR_CLEAR + reach for dx, dy in doors):
            continue
        if piece == 'table':
            yaw = round(float(rng.uniform(-math.pi / 2, math.pi / 2)), 3)
            out.append({'box': {'center': [cx, cy], 'size': [a, b], 'yaw': yaw}})
        else:
            out.append(circle(cx, cy, reach))
    return out


def building(rng: np.random.Generator, r: BuildingRanges = BUILDING_RANGES) -> Layout:
    """One building floor (module docstring)."""
    cw, length = draw(rng, *r.corridor_width), draw(rng, *r.corridor_length)
    t = draw(rng, *r.wall_thickness)
    walls: list[dict] = []
    rooms: list[tuple[float, float, float, float]] = []   # inner extents
    depth = {side: draw(rng, *r.room_depth) for side in (-1, 1)}
    for side in (-1, 1):
        xs = _room_edges(rng, length, r.room_width)
        wall_y = 0.0 if side < 0 else cw                 # the corridor wall of this side
        far = wall_y + side * depth[side]
        ylo, yhi = sorted((wall_y, far))
        doors = []
        side_rooms = []
        for k in range(len(xs) - 1):
            a, b = door(rng, xs[k], xs[k + 1], r.door_width, DOOR_MARGIN + t)
            doors.append((a, b))
            inner = (xs[k] + t / 2 if k else 0.0, ylo + (t / 2 if side > 0 else 0.0),
                     xs[k + 1] - t / 2 if k + 1 < len(xs) - 1 else length,
                     yhi - (t / 2 if side < 0 else 0.0))
            side_rooms.append((inner, [((a + b) / 2, wall_y + side * t)]))
        walls += [box(a, wall_y - t / 2, b, wall_y + t / 2) for a, b in solid(0.0, length, doors)]
        for k in range(1, len(xs) - 1):   # the walls between rooms, some with a door
            gaps = []
            if rng.random() < r.side_door:
                gaps.append(door(rng, ylo, yhi, r.door_width, DOOR_MARGIN + t))
                mid = (gaps[0][0] + gaps[0][1]) / 2
                side_rooms[k - 1][1].append((xs[k] - t, mid))
                side_rooms[k][1].append((xs[k] + t, mid))
            walls += [box(xs[k] - t / 2, a, xs[k] + t / 2, b) for a, b in solid(ylo, yhi, gaps)]
        for inner, room_doors in side_rooms:
            walls += _furniture(rng, r, inner, room_doors)
            rooms.append(inner)
    centre = np.array([[(x0 + x1) / 2, (y0 + y1) / 2] for x0, y0, x1, y1 in rooms])
    i = int(rng.integers(len(rooms)))
    far = np.flatnonzero(np.hypot(*(centre - centre[i]).T) >= MIN_SEPARATION)
    j = int(rng.choice(far)) if far.size else int(np.argmax(np.hypot(*(centre - centre[i]).T)))

    def spot(room: tuple[float, float, float, float]) -> tuple[float, float]:
        x0, y0, x1, y1 = room
        return (draw(rng, x0 + ENDPOINT_MARGIN, x1 - ENDPOINT_MARGIN),
                draw(rng, y0 + ENDPOINT_MARGIN, y1 - ENDPOINT_MARGIN))
    bounds = (0.0, -depth[-1], length, cw + depth[1])
    return Layout(spot(rooms[i]), spot(rooms[j]), bounds, tuple(walls),
                  f'corridor {length:.2f} x {cw:.2f} m, {len(rooms)} rooms, walls {t:.2f} m')


BUILDING_BUILDERS = {'building': building}
