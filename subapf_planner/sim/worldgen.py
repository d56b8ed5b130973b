"""Seeded procedural worlds (format v1): the families of the benchmark's dev suite.

``generate(family, seed)`` draws one world document of a family;
``suite(count, seed)`` spreads ``count`` worlds over the families round-robin,
each from a sub-seed of (seed, family, index) (numpy ``SeedSequence``), so the
same seed gives the same documents (for a given numpy and scipy: their random
streams and filters are stable in practice, not by contract). The families and
their parameter ranges are in ``sim/families.py``.

Every world is closed by ``bounds``, turned by one of the 8 symmetries of the
square and moved so that its start is at the origin; its start faces the goal
(+-30 deg). Before it is returned it is checked: it parses (``parse_world``),
start and goal are ENDPOINT_CLEARANCE m clear of obstacles, and it is solvable
for a disc of SOLVE_RADIUS m (the burger's 0.105 m plus 0.05 m): the
obstacles' exact signed distance is sampled at the centres of a GRID_RESOLUTION
m grid, a cell is free when that distance is at least SOLVE_RADIUS, and the
start's cell must reach the goal's through 4-connected free cells. A gap
narrower than 2 x SOLVE_RADIUS (0.31 m) never passes; one up to a grid cell
wider may not, depending on how the grid falls on it. A world that fails is
drawn again from the next sub-seed, at most MAX_ATTEMPTS times. The time limit
is BASE_TIME + TIME_FACTOR x geodesic length / MAX_SPEED [s], the geodesic being
the shortest 8-connected path through the free cells (at most 8 % longer than
the true shortest path).

For another robot (``robot``, core/robot.py) each world is the burger's, scaled
(``scale_world``): every length by the ratio of the robot's solve radius (its
circumscribed radius plus SOLVE_MARGIN) to the burger's, so a gap the burger's disc just
passes is one the robot's circumscribed disc just passes; the moving obstacles' speeds
by the ratio of the top speeds (as DynaBARN scales its movers to the Jackal's); the time
limit from the scaled geodesic at the robot's top speed. The goal tolerance stays.

The building family (sim/building.py) is a suite of its own (``--families
building``). The dynamic families (sim/dynamic_families.py) are checked the same way on their
static obstacles (moving ones are not walls: they pass); in addition no moving
obstacle may come within START_MARGIN m of the start's footprint in the first
START_GRACE s, and its paths go through the same symmetry and shift.

Pure numpy and scipy: no ROS, no simulator.
"""

from __future__ import annotations

from dataclasses import dataclass
import math
from typing import Any
import zlib

import numpy as np

from ..core.robot import BURGER, RobotDescription
from .building import BUILDING_BUILDERS, BUILDING_FAMILIES, BUILDING_RANGES
from .dynamic_families import DYNAMIC_BUILDERS, DYNAMIC_FAMILIES, DYNAMIC_RANGES
from .families import BUILDERS, FAMILIES, RANGES, FamilyRanges, Layout, circle
from .solvability import geodesic_length
from .world import FOOTPRINT_RADIUS, World, WorldError, parse_world

__all__ = ['ALL_FAMILIES', 'BUILDING_FAMILIES', 'DYNAMIC_FAMILIES', 'FAMILIES', 'RANGES',
           'FamilyRanges', 'GeneratedWorld', 'generate', 'generate_world', 'sub_seed', 'suite',
           'suite_worlds', 'time_limit']

#: Every family: the static ones of the dev suite (the default), the dynamic ones, the
#: building floors (a suite of their own).
ALL_FAMILIES = FAMILIES + DYNAMIC_FAMILIES + BUILDING_FAMILIES
#: No moving obstacle within this gap of the start's footprint [m] ...
START_MARGIN = 0.5
#: ... during the first seconds of the run [s].
START_GRACE = 3.0

#: Least distance from the start and the goal to any obstacle surface [m].
ENDPOINT_CLEARANCE = 0.3
#: Time limit = BASE_TIME [s] + TIME_FACTOR x geodesic length [m] / MAX_SPEED [m/s].
BASE_TIME = 60.0
TIME_FACTOR = 4.0
MAX_SPEED = 0.22
GOAL_TOLERANCE = 0.15
#: Draws per world before ``generate`` gives up.
MAX_ATTEMPTS = 200


@dataclass(frozen=True)
class GeneratedWorld:
    """A generated world document and what its checks measured."""

    doc: dict[str, Any]
    family: str
    seed: int
    attempt: int
    geodesic_length: float   # [m]


# --------------------------------------------------------------- symmetry, document


def _turn(x: float, y: float, k: int, flip: bool) -> tuple[float, float]:
    """(x, y) mirrored in the x axis when ``flip``, then turned by k quarter turns."""
    if flip:
        y = -y
    for _ in range(k):
        x, y = -y, x
    return x, y


def _as_written(v: float) -> float:
    """A coordinate as written [m or rad]: 4 decimals, no -0.0."""
    return round(float(v), 4) + 0.0


def _document(layout: Layout, rng: np.random.Generator, name: str) -> dict[str, Any]:
    """The world document of ``layout`` after a random symmetry of the square and a
    shift that puts its start at the origin."""
    k, flip = int(rng.integers(4)), bool(rng.integers(2))
    sx, sy = _turn(*layout.start, k, flip)

    def point(x: float, y: float) -> list[float]:
        px, py = _turn(x, y, k, flip)
        return [_as_written(px - sx), _as_written(py - sy)]
    obstacles = []
    for o in layout.obstacles:
        if 'circle' in o:
            c = o['circle']
            obstacles.append(circle(*point(*c['center']), _as_written(c['radius'])))
            continue
        b = o['box']
        size, yaw = list(b['size']), float(b.get('yaw', 0.0))
        if yaw == 0.0:
            if k % 2:
                size.reverse()
            spec = {'center': point(*b['center']), 'size': [_as_written(v) for v in size]}
        else:
            yaw = (-yaw if flip else yaw) + k * math.pi / 2
            yaw = math.atan2(math.sin(yaw), math.cos(yaw))
            spec = {'center': point(*b['center']), 'size': [_as_written(v) for v in size],
                    'yaw': _as_written(yaw)}
        obstacles.append({'box': spec})
    x0, y0, x1, y1 = layout.bounds
    corners = np.array([point(x0, y0), point(x1, y1)])
    goal = point(*layout.goal)
    heading = math.atan2(goal[1], goal[0]) + rng.uniform(-math.pi / 6, math.pi / 6)
    heading = math.atan2(math.sin(heading), math.cos(heading))
    doc = {'name': name, 'description': layout.note, 'start': [0.0, 0.0, _as_written(heading)],
           'goal': goal, 'goal_tolerance': GOAL_TOLERANCE, 'time_limit': BASE_TIME,
           'bounds': [_as_written(v) for v in (*corners.min(axis=0), *corners.max(axis=0))],
           'obstacles': obstacles}
    if layout.moving:
        doc['moving'] = [{**m, 'path': [[t, *point(x, y)] for t, x, y in m['path']]}
                         for m in layout.moving]
    return doc


def _start_crowded(world: World) -> bool:
    """A moving obstacle comes within START_MARGIN of the start's footprint in the
    first START_GRACE seconds."""
    x, y = world.start[:2]
    return any(o.distance(x, y) < FOOTPRINT_RADIUS + START_MARGIN
               for t in np.arange(0.0, START_GRACE + 1e-9, 0.1)
               for o in world.moving_at(float(t)))


def _line_blocked(world: World, step: float = 0.02) -> bool:
    """True when the straight start-goal segment crosses an obstacle."""
    (x0, y0), (x1, y1) = world.start[:2], world.goal
    n = max(2, math.ceil(math.hypot(x1 - x0, y1 - y0) / step))
    return any(world.clearance(x0 + (x1 - x0) * s, y0 + (y1 - y0) * s) < 0.0
               for s in np.linspace(0.0, 1.0, n + 1))


def _family_key(family: str) -> int:
    return zlib.crc32(family.encode())


def _check_family(family: str) -> None:
    if family not in ALL_FAMILIES:
        raise ValueError(f'unknown world family {family!r}; choose from '
                         f'{", ".join(ALL_FAMILIES)}')


def _layout(family: str, rng: np.random.Generator, ranges: FamilyRanges) -> Layout:
    """One draw of ``family`` (``ranges``: those of the static families)."""
    if family in BUILDERS:
        return BUILDERS[family](rng, ranges)
    if family in DYNAMIC_BUILDERS:
        return DYNAMIC_BUILDERS[family](rng, DYNAMIC_RANGES)
    return BUILDING_BUILDERS[family](rng, BUILDING_RANGES)


def time_limit(geodesic: float, top_speed: float = MAX_SPEED) -> int:
    """Simulated time allowed for a world whose geodesic is ``geodesic`` m long, for a
    robot of ``top_speed`` [m/s] [s]."""
    return math.ceil(BASE_TIME + TIME_FACTOR * geodesic / top_speed)


def scale_world(world: GeneratedWorld, robot: RobotDescription) -> GeneratedWorld:
    """The burger's ``world`` for ``robot`` (module docstring): lengths times the ratio
    of solve radii, moving obstacles' speeds times the ratio of top speeds. The burger's
    world is returned as it is."""
    if robot == BURGER:
        return world
    size = robot.solve_radius / BURGER.solve_radius
    pace = robot.max_linear_velocity / BURGER.max_linear_velocity

    def length(v: float) -> float:
        return _as_written(v * size)

    def points(values: list[float]) -> list[float]:
        return [length(v) for v in values]

    doc = dict(world.doc)
    doc['start'] = [*points(doc['start'][:2]), doc['start'][2]]
    doc['goal'] = points(doc['goal'])
    doc['bounds'] = points(doc['bounds'])
    obstacles = []
    for o in doc['obstacles']:
        if 'circle' in o:
            c = o['circle']
            obstacles.append(circle(*points(c['center']), length(c['radius'])))
        else:
            b = o['box']
            obstacles.append({'box': {**b, 'center': points(b['center']),
                                      'size': points(b['size'])}})
    doc['obstacles'] = obstacles
    if 'moving' in doc:
        moving = []
        for m in doc['moving']:
            shape = 'circle' if 'circle' in m else 'box'
            spec = dict(m[shape])
            if shape == 'circle':
                spec['radius'] = length(spec['radius'])
            else:
                spec['size'] = points(spec['size'])
            # lengths times size and speeds times pace: times times size / pace
            moving.append({**m, shape: spec,
                           'path': [[_as_written(t * size / pace), *points([x, y])]
                                    for t, x, y in m['path']],
                           **({'offset': _as_written(m['offset'] * size / pace)}
                              if 'offset' in m else {})})
        doc['moving'] = moving
    geodesic = world.geodesic_length * size
    doc['time_limit'] = time_limit(geodesic, robot.max_linear_velocity)
    doc['description'] = (f'{doc["description"]}; scaled x{size:.3f} in length and '
                          f'x{pace:.3f} in speed for the {robot.name}')
    return GeneratedWorld(doc, world.family, world.seed, world.attempt, geodesic)


def generate_world(family: str, seed: int, name: str | None = None,
                   ranges: FamilyRanges = RANGES) -> GeneratedWorld:
    """One checked world of ``family`` from ``seed`` (a non-negative int), named
    ``name`` (default ``<family>_s<seed>``). Attempt k draws from the sub-seed
    (seed, family, k) until one passes the checks (module docstring).

    Raises ValueError for an unknown family or a negative seed, RuntimeError when
    MAX_ATTEMPTS draws all fail."""
    _check_family(family)
    if isinstance(seed, bool) or not isinstance(seed, (int, np.integer)) or seed < 0:
        raise ValueError(f'seed must be a non-negative integer, got {seed!r}')
    name = name or f'{family}_s{seed}'
    for attempt in range(MAX_ATTEMPTS):
        rng = np.random.default_rng(np.random.SeedSequence([int(seed), _family_key(family),
                                                            attempt]))
        layout = _layout(family, rng, ranges)
        doc = _document(layout, rng, name)
        try:
            world = parse_world(doc, name)
        except WorldError:
            continue
        if min(world.clearance(*world.start[:2]), world.clearance(*world.goal)) \
                < ENDPOINT_CLEARANCE:
            continue
        if layout.blocked and not _line_blocked(world):
            continue
        if world.moving and _start_crowded(world):
            continue
        length = geodesic_length(world)
        if not math.isfinite(length):
            continue
        doc['time_limit'] = time_limit(length)
        doc['description'] = (f'{family}: {layout.note}; geodesic {length:.2f} m; seed {seed}'
                              f', attempt {attempt} (subapf_planner.sim.worldgen)')
        return GeneratedWorld(doc, family, int(seed), attempt, length)
    raise RuntimeError(f'{family}: no solvable world in {MAX_ATTEMPTS} attempts from seed '
                       f'{seed}')


def generate(family: str, seed: int, name: str | None = None) -> dict[str, Any]:
    """One world document (format v1) of ``family`` from ``seed``; see generate_world."""
    return generate_world(family, seed, name).doc


def sub_seed(seed: int, family: str, index: int) -> int:
    """The seed of world ``index`` of ``family`` in the suite of ``seed``."""
    ss = np.random.SeedSequence([int(seed), _family_key(family), int(index)])
    return int(ss.generate_state(1, np.uint32)[0])


def suite_worlds(count: int, seed: int, families: tuple[str, ...] = FAMILIES,
                 robot: RobotDescription = BURGER) -> list[GeneratedWorld]:
    """``count`` worlds, world i of family ``families[i % len(families)]``, named
    ``<family>_<index in the family, 3 digits>`` and drawn from
    ``sub_seed(seed, family, index)``: a world depends on (seed, family, index) only;
    for another ``robot`` than the burger, scaled for it (scale_world)."""
    if count < 1:
        raise ValueError(f'count must be at least 1, got {count}')
    if not families:
        raise ValueError('no families')
    for f in families:
        _check_family(f)
    out = []
    for i in range(count):
        family, index = families[i % len(families)], i // len(families)
        out.append(scale_world(generate_world(family, sub_seed(seed, family, index),
                                              f'{family}_{index:03d}'), robot))
    return out


def suite(count: int, seed: int, families: tuple[str, ...] = FAMILIES) -> list[dict[str, Any]]:
    """The documents of ``suite_worlds(count, seed, families)``."""
    return [w.doc for w in suite_worlds(count, seed, families)]
