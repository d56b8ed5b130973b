"""World files, format v1 (YAML): loading, validation and geometry.

A world is a start pose, a goal and static obstacles 0.5 m tall (circles and
yawed boxes), optionally closed by four walls from ``bounds``, and optionally
obstacles that move (``moving``: a circle or a box driven along keyframes
[t s, x m, y m], linearly interpolated, optionally looping; they follow their
paths whatever is in the way, and only the robot collides). Coordinates are
metres in the world frame, which the simulator also uses as ``odom``. Every
error names the file, the field and what was wrong.
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import cached_property
import math
from pathlib import Path
from typing import Any

import numpy as np
import yaml

from ..core.robot import BURGER

FORMAT_KEYS = {'name', 'description', 'start', 'goal', 'goal_tolerance', 'time_limit',
               'bounds', 'obstacles', 'moving'}
MOVING_KEYS = {'circle', 'box', 'path', 'loop', 'offset'}
REQUIRED_KEYS = ('name', 'start', 'goal')
#: Thickness of the walls made from ``bounds`` [m].
WALL_THICKNESS = 0.1
#: Footprint radius used to reject a start or goal inside an obstacle [m].
FOOTPRINT_RADIUS = BURGER.radius


class WorldError(ValueError):
    """A world file cannot be read or is invalid."""


@dataclass(frozen=True)
class Circle:
    center: tuple[float, float]
    radius: float

    def distance(self, x: float, y: float) -> float:
        """Signed distance from (x, y) to the circle's boundary (negative inside) [m]."""
        return math.hypot(x - self.center[0], y - self.center[1]) - self.radius


@dataclass(frozen=True)
class Box:
    center: tuple[float, float]
    size: tuple[float, float]
    yaw: float = 0.0

    def distance(self, x: float, y: float) -> float:
        """Signed distance from (x, y) to the box's boundary (negative inside) [m]."""
        c, s = math.cos(self.yaw), math.sin(self.yaw)
        dx, dy = x - self.center[0], y - self.center[1]
        lx, ly = c * dx + s * dy, -s * dx + c * dy
        qx, qy = abs(lx) - self.size[0] / 2, abs(ly) - self.size[1] / 2
        outside = math.hypot(max(qx, 0.0), max(qy, 0.0))
        return outside + min(max(qx, qy), 0.0)


Obstacle = Circle | Box


@dataclass(frozen=True)
class MovingObstacle:
    """A circle or box (``shape``, centred at the origin; a box keeps its yaw) driven
    through ``keyframes`` (t [s], x [m], y [m]), times from 0 strictly increasing,
    positions interpolated linearly. ``offset`` [s] is the path's time at the run's
    start; after the last keyframe it stays there, or with ``loop`` starts again from
    the first (period: the last keyframe's time)."""

    shape: Obstacle
    keyframes: tuple[tuple[float, float, float], ...]
    loop: bool = False
    offset: float = 0.0

    @cached_property
    def _keys(self) -> np.ndarray:
        """The keyframes as one (k, 3) array, made once (positions are asked for at every
        physics step)."""
        return np.asarray(self.keyframes, float)

    @property
    def period(self) -> float:
        """Time of the last keyframe [s]."""
        return self.keyframes[-1][0]

    def path_time(self, t: float | np.ndarray) -> np.ndarray:
        """The time along the keyframes at run time ``t`` [s]."""
        tau = np.asarray(t, float) + self.offset
        if self.loop and self.period > 0.0:
            return np.remainder(tau, self.period)
        return np.clip(tau, 0.0, self.period)

    def position(self, t: float | np.ndarray) -> np.ndarray:
        """Centre (x, y) at run time ``t`` [s]; (n, 2) for n times."""
        k = self._keys
        tau = self.path_time(t)
        return np.stack((np.interp(tau, k[:, 0], k[:, 1]), np.interp(tau, k[:, 0], k[:, 2])),
                        axis=-1)

    def velocity(self, t: float) -> np.ndarray:
        """Velocity (vx, vy) at run time ``t`` [m/s] (that of the segment it is on)."""
        k = self._keys
        tau = float(self.path_time(t))
        if len(k) < 2 or (not self.loop and (tau >= self.period or t + self.offset < 0.0)):
            return np.zeros(2)
        i = min(int(np.searchsorted(k[:, 0], tau, side='right')) - 1, len(k) - 2)
        return (k[i + 1, 1:] - k[i, 1:]) / (k[i + 1, 0] - k[i, 0])

    def at(self, t: float) -> Obstacle:
        """The shape placed where it is at run time ``t`` [s]."""
        x, y = (float(v) for v in self.position(t))
        if isinstance(self.shape, Circle):
            return Circle((x, y), self.shape.radius)
        return Box((x, y), self.shape.size, self.shape.yaw)

    @property
    def extent(self) -> float:
        """Radius of the circle that holds the shape [m]."""
        if isinstance(self.shape, Circle):
            return self.shape.radius
        return 0.5 * math.hypot(*self.shape.size)


@dataclass(frozen=True)
class World:
    name: str
    start: tuple[float, float, float]
    goal: tuple[float, float]
    obstacles: tuple[Obstacle, ...]
    goal_tolerance: float = 0.15
    time_limit: float = 120.0
    bounds: tuple[float, float, float, float] | None = None
    description: str = ''
    source: str = '<memory>'
    moving: tuple[MovingObstacle, ...] = ()

    def all_obstacles(self) -> tuple[Obstacle, ...]:
        """Obstacles plus the four boundary walls, if ``bounds`` is set."""
        if self.bounds is None:
            return self.obstacles
        x0, y0, x1, y1 = self.bounds
        t = WALL_THICKNESS
        w, h = x1 - x0, y1 - y0
        walls = (Box(((x0 + x1) / 2, y0 - t / 2), (w + 2 * t, t)),
                 Box(((x0 + x1) / 2, y1 + t / 2), (w + 2 * t, t)),
                 Box((x0 - t / 2, (y0 + y1) / 2), (t, h)),
                 Box((x1 + t / 2, (y0 + y1) / 2), (t, h)))
        return self.obstacles + walls

    def moving_at(self, t: float) -> tuple[Obstacle, ...]:
        """The moving obstacles placed where they are at run time ``t`` [s]."""
        return tuple(m.at(t) for m in self.moving)

    def clearance(self, x: float, y: float, t: float | None = None) -> float:
        """Distance from (x, y) to the nearest obstacle surface (negative inside) [m]: the
        static ones, and with a time ``t`` [s] the moving ones where they are then."""
        obs = self.all_obstacles() + (() if t is None else self.moving_at(t))
        return min((o.distance(x, y) for o in obs), default=math.inf)


def _fail(src: str, where: str, what: str) -> WorldError:
    return WorldError(f'{src}: {where}: {what}')


def _numbers(src: str, where: str, value: Any, n: int) -> tuple[float, ...]:
    if not isinstance(value, (list, tuple)) or len(value) != n:
        raise _fail(src, where, f'expected a list of {n} numbers, got {value!r}')
    out = []
    for v in value:
        if isinstance(v, bool) or not isinstance(v, (int, float)) or not math.isfinite(v):
            raise _fail(src, where, f'expected finite numbers, got {value!r}')
        out.append(float(v))
    return tuple(out)


def _positive(src: str, where: str, value: Any) -> float:
    if isinstance(value, bool) or not isinstance(value, (int, float)) \
            or not math.isfinite(value) or value <= 0:
        raise _fail(src, where, f'must be a positive number, got {value!r}')
    return float(value)


def _shape(src: str, where: str, kind: str, spec: Any, placed: bool = True) -> Obstacle:
    """A circle or box from its mapping; ``placed`` False: no center (a moving shape)."""
    if not isinstance(spec, dict):
        raise _fail(src, f'{where}.{kind}', 'expected a mapping')
    center = ('center',) if placed else ()
    keys = {'circle': center + ('radius',), 'box': center + ('size',)}[kind]
    extra = set(spec) - set(keys) - ({'yaw'} if kind == 'box' else set())
    if extra:
        raise _fail(src, f'{where}.{kind}', f'unknown key(s) {sorted(extra)}')
    for key in keys:
        if key not in spec:
            raise _fail(src, f'{where}.{kind}', f'missing "{key}"')
    c = _numbers(src, f'{where}.{kind}.center', spec['center'], 2) if placed else (0.0, 0.0)
    if kind == 'circle':
        return Circle(c, _positive(src, f'{where}.circle.radius', spec['radius']))
    size = _numbers(src, f'{where}.box.size', spec['size'], 2)
    if min(size) <= 0:
        raise _fail(src, f'{where}.box.size', f'must be positive, got {list(size)}')
    yaw = _numbers(src, f'{where}.box.yaw', [spec.get('yaw', 0.0)], 1)[0]
    return Box(c, size, yaw)


def _obstacle(src: str, i: int, item: Any) -> Obstacle:
    where = f'obstacles[{i}]'
    if not isinstance(item, dict) or len(item) != 1:
        raise _fail(src, where, 'expected one of {circle: {...}} or {box: {...}}')
    kind, spec = next(iter(item.items()))
    if kind not in ('circle', 'box'):
        raise _fail(src, where, f'unknown obstacle type {kind!r} (circle or box)')
    return _shape(src, where, kind, spec)


def _moving(src: str, i: int, item: Any) -> MovingObstacle:
    where = f'moving[{i}]'
    if not isinstance(item, dict):
        raise _fail(src, where, 'expected a mapping with circle or box, and path')
    unknown = set(item) - MOVING_KEYS
    if unknown:
        raise _fail(src, where, f'unknown key(s) {sorted(unknown)}')
    kinds = [k for k in ('circle', 'box') if k in item]
    if len(kinds) != 1:
        raise _fail(src, where, 'needs exactly one of circle or box')
    shape = _shape(src, where, kinds[0], item[kinds[0]], placed=False)
    path = item.get('path')
    if not isinstance(path, list) or not path:
        raise _fail(src, f'{where}.path', 'expected a list of [t, x, y] keyframes')
    keys = tuple(_numbers(src, f'{where}.path[{j}]', p, 3) for j, p in enumerate(path))
    if keys[0][0] != 0.0:
        raise _fail(src, f'{where}.path[0]', f'the first keyframe time must be 0, got '
                    f'{keys[0][0]}')
    for j in range(1, len(keys)):
        if keys[j][0] <= keys[j - 1][0]:
            raise _fail(src, f'{where}.path[{j}]', 'keyframe times must strictly increase '
                        f'({keys[j][0]} after {keys[j - 1][0]})')
    loop = item.get('loop', False)
    if not isinstance(loop, bool):
        raise _fail(src, f'{where}.loop', f'must be true or false, got {loop!r}')
    offset = _numbers(src, f'{where}.offset', [item.get('offset', 0.0)], 1)[0]
    return MovingObstacle(shape, keys, loop, offset)


def parse_world(doc: Any, source: str = '<memory>') -> World:
    """Validate a parsed YAML document and build the World."""
    src = source
    if not isinstance(doc, dict):
        raise _fail(src, 'top level', 'expected a mapping')
    unknown = set(doc) - FORMAT_KEYS
    if unknown:
        raise _fail(src, 'top level', f'unknown key(s) {sorted(unknown)}')
    for key in REQUIRED_KEYS:
        if key not in doc:
            raise _fail(src, key, 'missing')
    if not isinstance(doc['name'], str) or not doc['name']:
        raise _fail(src, 'name', 'must be a non-empty string')
    start = _numbers(src, 'start', doc['start'], 3)
    goal = _numbers(src, 'goal', doc['goal'], 2)
    tol = _positive(src, 'goal_tolerance', doc.get('goal_tolerance', 0.15))
    limit = _positive(src, 'time_limit', doc.get('time_limit', 120.0))
    bounds = None
    if doc.get('bounds') is not None:
        bounds = _numbers(src, 'bounds', doc['bounds'], 4)
        if bounds[0] >= bounds[2] or bounds[1] >= bounds[3]:
            raise _fail(src, 'bounds', 'need xmin < xmax and ymin < ymax')
    items = doc.get('obstacles') or []
    if not isinstance(items, list):
        raise _fail(src, 'obstacles', 'expected a list')
    moving = doc.get('moving') or []
    if not isinstance(moving, list):
        raise _fail(src, 'moving', 'expected a list')
    description = doc.get('description', '')
    if not isinstance(description, str):
        raise _fail(src, 'description', 'must be a string')
    world = World(doc['name'], start, goal, tuple(_obstacle(src, i, o) for i, o in
                                                  enumerate(items)),
                  tol, limit, bounds, description, src,
                  tuple(_moving(src, i, m) for i, m in enumerate(moving)))
    # the start must be clear of everything at t = 0; moving obstacles may cross the goal
    for key, (x, y), t in (('start', start[:2], 0.0), ('goal', goal, None)):
        if world.clearance(x, y, t) < FOOTPRINT_RADIUS:
            raise _fail(src, key, f'({x}, {y}) is inside or within {FOOTPRINT_RADIUS} m '
                        'of an obstacle' + (' at t = 0' if t is not None else ''))
        if bounds is not None and not (bounds[0] < x < bounds[2] and bounds[1] < y < bounds[3]):
            raise _fail(src, key, f'({x}, {y}) is outside bounds {list(bounds)}')
    return world


def load_world(path: str | Path) -> World:
    """Read and validate a world file."""
    path = Path(path)
    try:
        text = path.read_text()
    except OSError as exc:
        raise WorldError(f'{path}: cannot read: {exc.strerror or exc}') from exc
    try:
        doc = yaml.safe_load(text)
    except yaml.YAMLError as exc:
        raise WorldError(f'{path}: not valid YAML: {exc}') from exc
    return parse_world(doc, str(path))


def world_files(paths: list[str | Path]) -> list[Path]:
    """Expand directories to their *.yaml files (sorted); keep files as given."""
    out: list[Path] = []
    for p in map(Path, paths):
        if p.is_dir():
            out.extend(sorted(p.glob('*.yaml')))
        else:
            out.append(p)
    return out


def obstacle_outline(o: Obstacle, n: int = 48) -> np.ndarray:
    """Closed outline (k, 2) of an obstacle, for plotting."""
    if isinstance(o, Circle):
        a = np.linspace(0, 2 * math.pi, n)
        return np.column_stack((o.center[0] + o.radius * np.cos(a),
                                o.center[1] + o.radius * np.sin(a)))
    hx, hy = o.size[0] / 2, o.size[1] / 2
    corners = np.array([[-hx, -hy], [hx, -hy], [hx, hy], [-hx, hy], [-hx, -hy]])
    c, s = math.cos(o.yaw), math.sin(o.yaw)
    return corners @ np.array([[c, s], [-s, c]]) + np.asarray(o.center)
