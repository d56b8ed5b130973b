"""World files, format v1 (YAML): loading, validation and geometry.

A world is a start pose, a goal and static obstacles 0.5 m tall (circles and
yawed boxes), optionally closed by four walls from ``bounds``. Coordinates
are metres in the world frame, which the simulator also uses as ``odom``.
Every error names the file, the field and what was wrong.
"""

from __future__ import annotations

from dataclasses import dataclass
import math
from pathlib import Path
from typing import Any

import numpy as np
import yaml

from ..core.robot import BURGER

FORMAT_KEYS = {'name', 'description', 'start', 'goal', 'goal_tolerance', 'time_limit',
               'bounds', 'obstacles'}
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

    def clearance(self, x: float, y: float) -> float:
        """Distance from (x, y) to the nearest obstacle surface (negative inside) [m]."""
        obs = self.all_obstacles()
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


def _obstacle(src: str, i: int, item: Any) -> Obstacle:
    where = f'obstacles[{i}]'
    if not isinstance(item, dict) or len(item) != 1:
        raise _fail(src, where, 'expected one of {circle: {...}} or {box: {...}}')
    kind, spec = next(iter(item.items()))
    if not isinstance(spec, dict):
        raise _fail(src, f'{where}.{kind}', 'expected a mapping')
    if kind == 'circle':
        extra = set(spec) - {'center', 'radius'}
        if extra:
            raise _fail(src, f'{where}.circle', f'unknown key(s) {sorted(extra)}')
        for key in ('center', 'radius'):
            if key not in spec:
                raise _fail(src, f'{where}.circle', f'missing "{key}"')
        return Circle(_numbers(src, f'{where}.circle.center', spec['center'], 2),
                      _positive(src, f'{where}.circle.radius', spec['radius']))
    if kind == 'box':
        extra = set(spec) - {'center', 'size', 'yaw'}
        if extra:
            raise _fail(src, f'{where}.box', f'unknown key(s) {sorted(extra)}')
        for key in ('center', 'size'):
            if key not in spec:
                raise _fail(src, f'{where}.box', f'missing "{key}"')
        size = _numbers(src, f'{where}.box.size', spec['size'], 2)
        if min(size) <= 0:
            raise _fail(src, f'{where}.box.size', f'must be positive, got {list(size)}')
        yaw = _numbers(src, f'{where}.box.yaw', [spec.get('yaw', 0.0)], 1)[0]
        return Box(_numbers(src, f'{where}.box.center', spec['center'], 2), size, yaw)
    raise _fail(src, where, f'unknown obstacle type {kind!r} (circle or box)')


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
    description = doc.get('description', '')
    if not isinstance(description, str):
        raise _fail(src, 'description', 'must be a string')
    world = World(doc['name'], start, goal, tuple(_obstacle(src, i, o) for i, o in
                                                  enumerate(items)),
                  tol, limit, bounds, description, src)
    for key, (x, y) in (('start', start[:2]), ('goal', goal)):
        if world.clearance(x, y) < FOOTPRINT_RADIUS:
            raise _fail(src, key, f'({x}, {y}) is inside or within {FOOTPRINT_RADIUS} m '
                        'of an obstacle')
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
