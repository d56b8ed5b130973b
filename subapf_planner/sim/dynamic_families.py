"""World families with moving obstacles: seeded layouts before the symmetry and the
checks of ``sim/worldgen.py`` (sizes in m, times in s, speeds as a fraction of the
robot's top speed, MAX_SPEED).

* ``crossing``: 1-3 people (discs of radius 0.25) walking to and fro across the
  start-goal line at right angles in an open room, each timed to cross about when
  the robot gets there (+-4 s).
* ``head_on``: a corridor 1.2-2.0 wide, 7-10 long; someone walks from its far end
  towards the robot, the length of the corridor.
* ``overtake``: a corridor 1.2-2.0 wide, 8-12 long; a slower walker (0.25-0.6)
  starts 1.2-2.0 ahead of the robot, going the same way to the far end.
* ``doorway_walker``: a wall across the room with a door 0.8-1.2 wide; someone
  walks through it towards the robot's side about when the robot reaches it.
* ``clutter_walkers``: a room with discs (as ``forest``) and 2-4 walkers going to
  and fro on random straight lines across it.
* ``arena``: a 20 x 20 square closed on three sides; the robot starts 1 m outside
  the open side, the goal is 20 m away across it; 5-25 cylinders of radius 0.5,
  each on a random smooth path from the border to the border and back (looping),
  segment speeds 0.25-1.0.
* ``fast_crossing``: as ``crossing`` with people at 1.0-1.5 of the robot's top
  speed: where the limit is.

Walkers follow their paths whatever is in the way (they may overlap walls); each
builder draws from the given random generator only.
"""

from __future__ import annotations

from dataclasses import dataclass
import math
from typing import Any, Callable

import numpy as np

from ..core.robot import BURGER
from .families import Layout, box, circle, draw, on_grid

DYNAMIC_FAMILIES = ('crossing', 'head_on', 'overtake', 'doorway_walker', 'clutter_walkers',
                    'arena', 'fast_crossing')
#: Top speed of the robot the speeds are fractions of [m/s].
MAX_SPEED = BURGER.max_linear_velocity
#: Speed the robot is assumed to make when walkers are timed to meet it [m/s].
TIMING_SPEED = 0.2


@dataclass(frozen=True)
class DynamicRanges:
    """Parameter ranges of the dynamic families, (low, high) drawn uniformly."""

    person_radius: float = 0.25
    walker_speed: tuple[float, float] = (0.3, 1.0)
    fast_speed: tuple[float, float] = (1.0, 1.5)
    crossing_room: tuple[tuple[float, float], tuple[float, float]] = ((6.0, 9.0), (4.0, 6.0))
    crossing_walkers: tuple[int, int] = (1, 3)
    #: Spread of a crossing's time around the robot's arrival [s].
    crossing_jitter: float = 4.0
    corridor_width: tuple[float, float] = (1.2, 2.0)
    head_on_length: tuple[float, float] = (7.0, 10.0)
    overtake_length: tuple[float, float] = (8.0, 12.0)
    overtake_speed: tuple[float, float] = (0.25, 0.6)
    overtake_lead: tuple[float, float] = (1.2, 2.0)
    doorway_room: tuple[tuple[float, float], tuple[float, float]] = ((6.0, 8.0), (4.0, 6.0))
    doorway_width: tuple[float, float] = (0.8, 1.2)
    clutter_room: tuple[tuple[float, float], tuple[float, float]] = ((6.0, 8.0), (4.0, 6.0))
    clutter_discs: tuple[int, int] = (6, 14)
    clutter_walkers: tuple[int, int] = (2, 4)
    arena_side: float = 20.0
    arena_radius: float = 0.5
    arena_walkers: tuple[int, int] = (5, 25)
    arena_speed: tuple[float, float] = (0.25, 1.0)


DYNAMIC_RANGES = DynamicRanges()


def walker(points: list[tuple[float, float]], speeds: list[float], radius: float,
           to_and_fro: bool = False, offset: float = 0.0) -> dict[str, Any]:
    """A moving disc through ``points`` [m], segment k at ``speeds[k]`` [m/s]; with
    ``to_and_fro`` it walks back the same way and loops. ``offset``: its path time at
    the run's start [s]."""
    pts = list(points)
    v = list(speeds)
    if to_and_fro:
        pts += pts[-2::-1]
        v += v[::-1]
    t, keys = 0.0, [[0.0, *pts[0]]]
    for (x0, y0), (x1, y1), s in zip(pts, pts[1:], v, strict=False):
        t += max(math.hypot(x1 - x0, y1 - y0), 1e-3) / s
        keys.append([round(t, 3), x1, y1])
    doc = {'circle': {'radius': radius}, 'path': keys}
    if to_and_fro:
        doc['loop'] = True
    if offset:
        doc['offset'] = round(offset, 3)
    return doc


def _speed(rng: np.random.Generator, lo_hi: tuple[float, float]) -> float:
    return round(float(rng.uniform(*lo_hi)) * MAX_SPEED, 4)


def _crossing_walkers(rng: np.random.Generator, r: DynamicRanges, length: float,
                      width: float, speeds: tuple[float, float]) -> tuple[dict, ...]:
    """Walkers to and fro across the line y = 0 at x in [1.5, length - 2.5], each at y = 0
    about when a robot from x = 0 at TIMING_SPEED gets there."""
    out = []
    for _ in range(int(rng.integers(r.crossing_walkers[0], r.crossing_walkers[1] + 1))):
        x = draw(rng, 1.5, length - 2.5)
        side = width / 2 - 0.4
        s = _speed(rng, speeds)
        ends = [(x, -side), (x, side)] if rng.random() < 0.5 else [(x, side), (x, -side)]
        arrive = x / TIMING_SPEED + rng.uniform(-r.crossing_jitter, r.crossing_jitter)
        out.append(walker(ends, [s], r.person_radius, True, side / s - arrive))
    return tuple(out)


def _crossing(rng: np.random.Generator, r: DynamicRanges, speeds=None) -> Layout:
    length, width = draw(rng, *r.crossing_room[0]), draw(rng, *r.crossing_room[1])
    moving = _crossing_walkers(rng, r, length, width, speeds or r.walker_speed)
    return Layout((0.0, 0.0), (length - 1.0, 0.0), (-1.0, -width / 2, length, width / 2), (),
                  f'{len(moving)} people crossing, room {length + 1:.2f} x {width:.2f} m',
                  moving=moving)


def _fast_crossing(rng: np.random.Generator, r: DynamicRanges) -> Layout:
    return _crossing(rng, r, r.fast_speed)


def _head_on(rng: np.random.Generator, r: DynamicRanges) -> Layout:
    length, width = draw(rng, *r.head_on_length), draw(rng, *r.corridor_width)
    lane = width / 2 - r.person_radius - 0.05
    y = draw(rng, -lane, lane)
    s = _speed(rng, r.walker_speed)
    person = walker([(length - 0.4, y), (-0.3, y)], [s], r.person_radius)
    return Layout((0.0, draw(rng, -0.2, 0.2)), (length - 1.2, draw(rng, -0.2, 0.2)),
                  (-0.6, -width / 2, length, width / 2), (),
                  f'corridor {length:.2f} x {width:.2f} m, walker at {s:.3f} m/s head-on',
                  moving=(person,))


def _overtake(rng: np.random.Generator, r: DynamicRanges) -> Layout:
    length, width = draw(rng, *r.overtake_length), draw(rng, *r.corridor_width)
    lane = width / 2 - r.person_radius - 0.05
    y = draw(rng, -lane, lane)
    s = _speed(rng, r.overtake_speed)
    lead = draw(rng, *r.overtake_lead)
    person = walker([(lead, y), (length - 0.35, y)], [s], r.person_radius)
    return Layout((0.0, 0.0), (length - 1.6, draw(rng, -0.2, 0.2)),
                  (-0.6, -width / 2, length, width / 2), (),
                  f'corridor {length:.2f} x {width:.2f} m, slower walker {lead:.2f} m ahead '
                  f'at {s:.3f} m/s', moving=(person,))


def _doorway_walker(rng: np.random.Generator, r: DynamicRanges) -> Layout:
    length, width = draw(rng, *r.doorway_room[0]), draw(rng, *r.doorway_room[1])
    wall_x, t = on_grid(length * 0.45), 0.15
    door = draw(rng, *r.doorway_width)
    c = draw(rng, -width / 2 + 0.4 + door / 2, width / 2 - 0.4 - door / 2)
    walls = (box(wall_x - t / 2, -width / 2, wall_x + t / 2, c - door / 2),
             box(wall_x - t / 2, c + door / 2, wall_x + t / 2, width / 2))
    s = _speed(rng, r.walker_speed)
    away = on_grid(min(max(c + (1.5 if rng.random() < 0.5 else -1.5), -width / 2 + 0.4),
                        width / 2 - 0.4))
    path = [(wall_x + 2.0, c), (wall_x, c), (wall_x - 1.2, c), (wall_x - 2.2, away)]
    arrive = wall_x / TIMING_SPEED + rng.uniform(-r.crossing_jitter, r.crossing_jitter)
    person = walker(path, [s] * 3, r.person_radius, offset=2.0 / s - arrive)
    return Layout((0.0, 0.0), (length - 1.0, draw(rng, -width / 2 + 0.6, width / 2 - 0.6)),
                  (-1.0, -width / 2, length, width / 2), walls,
                  f'door {door:.2f} m, walker through it at {s:.3f} m/s', moving=(person,))


def _clutter_walkers(rng: np.random.Generator, r: DynamicRanges) -> Layout:
    length, width = draw(rng, *r.clutter_room[0]), draw(rng, *r.clutter_room[1])
    discs = []
    for _ in range(int(rng.integers(r.clutter_discs[0], r.clutter_discs[1] + 1))):
        discs.append(circle(draw(rng, 1.0, length - 2.0), draw(rng, -width / 2 + 0.3,
                                                                  width / 2 - 0.3),
                            draw(rng, 0.1, 0.3)))
    moving = []
    for _ in range(int(rng.integers(r.clutter_walkers[0], r.clutter_walkers[1] + 1))):
        a = (draw(rng, 0.5, length - 1.5), -width / 2 + 0.3)
        b = (draw(rng, 0.5, length - 1.5), width / 2 - 0.3)
        ends = [a, b] if rng.random() < 0.5 else [b, a]
        moving.append(walker(ends, [_speed(rng, r.walker_speed)], r.person_radius, True,
                             float(rng.uniform(0.0, 60.0))))
    return Layout((0.0, 0.0), (length - 1.0, draw(rng, -width / 2 + 0.6, width / 2 - 0.6)),
                  (-1.0, -width / 2, length, width / 2), tuple(discs),
                  f'{len(discs)} discs, {len(moving)} walkers', moving=tuple(moving))


def _border_point(rng: np.random.Generator, side: float, edge: int) -> tuple[float, float]:
    """A point on edge ``edge`` (0: x = 0, the open side; 1: y = side/2; 2: x = side;
    3: y = -side/2) of the arena [m]."""
    u = draw(rng, -side / 2 + 1.0, side / 2 - 1.0)
    return [(0.0, u), (u + side / 2, side / 2), (side, u), (u + side / 2, -side / 2)][edge]


def _arena(rng: np.random.Generator, r: DynamicRanges) -> Layout:
    side = r.arena_side
    moving = []
    for _ in range(int(rng.integers(r.arena_walkers[0], r.arena_walkers[1] + 1))):
        a = int(rng.integers(4))
        b = (a + int(rng.integers(1, 4))) % 4
        inner = [(draw(rng, 3.0, side - 3.0), draw(rng, -side / 2 + 3.0, side / 2 - 3.0))
                 for _ in range(int(rng.integers(1, 3)))]
        pts = [_border_point(rng, side, a), *inner, _border_point(rng, side, b)]
        speeds = [_speed(rng, r.arena_speed) for _ in range(len(pts) - 1)]
        moving.append(walker(pts, speeds, r.arena_radius, True, float(rng.uniform(0, 200))))
    # the bounds' walls close three sides of the square, and 3 m behind its open side
    return Layout((-1.0, 0.0), (19.0, draw(rng, -1.0, 1.0)), (-3.0, -side / 2, side, side / 2),
                  (), f'arena {side:.0f} m, {len(moving)} cylinders', moving=tuple(moving))


DYNAMIC_BUILDERS: dict[str, Callable[[np.random.Generator, DynamicRanges], Layout]] = {
    'crossing': _crossing, 'head_on': _head_on, 'overtake': _overtake,
    'doorway_walker': _doorway_walker, 'clutter_walkers': _clutter_walkers,
    'arena': _arena, 'fast_crossing': _fast_crossing}
