"""A polygon footprint: where a robot that is not a disc collides.

Nav2's ``footprint`` (a convex polygon in the base frame, written ``[[x, y], ...]``)
in place of the circumscribed disc wherever a disc is wrong: a 0.43 m wide Jackal
described as its 0.67 m circle cannot pass a 0.6 m door it fits through. The planner
keeps its disc (``robot_radius``, the circumscribed one) where orientation does not
matter or is not known (moving obstacles' predictions, DWA's arcs) and checks the
polygon where it is (core/sampling.py: a sample with the robot placed on it, facing
the way it drives there; core/command.py: the corridor ahead and turning on the spot).

A point is in contact with the polygon inflated by a margin when its signed distance to
every edge's line is at most the margin: the polygon grown by the margin along each
edge's normal (at the corners a little more than the margin: on the safe side).
"""

from __future__ import annotations

from dataclasses import dataclass
import json
import math

import numpy as np
from numpy.typing import ArrayLike, NDArray

from .params import ConfigError

#: Turning on the spot is checked at headings this far apart [rad] ...
SWEEP_STEP = 0.1
#: ... and refused when a corner would come within this of an obstacle point [m]: less
#: than the sampling's margin, so a robot that stopped near a wall may still turn away.
TURN_MARGIN = 0.01


@dataclass(frozen=True, eq=False)
class Footprint:
    """A convex polygon (k, 2) [m] in the base frame, counter-clockwise."""

    vertices: NDArray[np.float64]

    def __post_init__(self) -> None:
        v = self.vertices
        if v.ndim != 2 or v.shape[1] != 2 or len(v) < 3 or not np.all(np.isfinite(v)):
            raise ConfigError(f'footprint: needs three or more [x, y] vertices, got {v.tolist()}')
        edges = np.roll(v, -1, axis=0) - v
        turn = edges[:, 0] * np.roll(edges, -1, axis=0)[:, 1] \
            - edges[:, 1] * np.roll(edges, -1, axis=0)[:, 0]
        if not np.all(turn > 0.0):
            raise ConfigError('footprint: must be a convex polygon with its vertices '
                              f'counter-clockwise, got {v.tolist()}')
        if self.inscribed <= 0.0:
            raise ConfigError("footprint: the base frame's origin must lie inside it, got "
                              f'{v.tolist()}')

    @property
    def _normals(self) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        """Each edge's outward unit normal (k, 2) and its line's offset (k,): a point p is
        ``normals @ p - offsets`` outside each edge's line [m]."""
        v = self.vertices
        edges = np.roll(v, -1, axis=0) - v
        normals = np.column_stack((edges[:, 1], -edges[:, 0])) / np.hypot(
            edges[:, 0], edges[:, 1])[:, None]
        return normals, np.einsum('ij,ij->i', normals, v)

    @property
    def circumscribed(self) -> float:
        """Distance from the base frame's origin to the farthest vertex [m]."""
        return float(np.hypot(self.vertices[:, 0], self.vertices[:, 1]).max())

    @property
    def inscribed(self) -> float:
        """Distance from the base frame's origin to the nearest edge's line [m]."""
        _, offsets = self._normals
        return float(offsets.min())

    @property
    def half_width(self) -> float:
        """Half the width across the direction of travel (the largest |y|) [m]: what a
        gap the robot drives straight through must leave it each side."""
        return float(np.abs(self.vertices[:, 1]).max())

    @property
    def front(self) -> float:
        """How far the footprint reaches ahead of the base frame's origin (largest x) [m]."""
        return float(self.vertices[:, 0].max())

    def _in_frames(self, poses: NDArray[np.float64],
                   points: NDArray[np.float64]) -> tuple[NDArray[np.float64], ...]:
        """The points (m, 2) in each pose's (n, 3) frame: x and y (n, m) [m]."""
        c, s = np.cos(poses[:, 2]), np.sin(poses[:, 2])
        dx = points[None, :, 0] - poses[:, None, 0]
        dy = points[None, :, 1] - poses[:, None, 1]
        return c[:, None] * dx + s[:, None] * dy, -s[:, None] * dx + c[:, None] * dy

    def _outside(self, fx: NDArray[np.float64], fy: NDArray[np.float64]) -> NDArray[np.float64]:
        """How far points in the footprint's frame lie outside each edge's line (..., k)
        [m]: inside the footprint where all are <= 0."""
        normals, offsets = self._normals
        return fx[..., None] * normals[:, 0] + fy[..., None] * normals[:, 1] - offsets

    def contact(self, poses: ArrayLike, points: ArrayLike, margin: float) -> NDArray[np.bool_]:
        """For each pose (n, 3) (x, y, yaw), whether a point (m, 2) lies within ``margin``
        [m] of the footprint placed there (or inside it)."""
        p = np.atleast_2d(np.asarray(poses, float))
        pts = np.asarray(points, float).reshape(-1, 2)
        if pts.shape[0] == 0:
            return np.zeros(p.shape[0], bool)
        fx, fy = self._in_frames(p, pts)
        reach = self.circumscribed + margin
        near = fx * fx + fy * fy <= reach * reach
        if not near.any():
            return np.zeros(p.shape[0], bool)
        return np.any(near & np.all(self._outside(fx, fy) <= margin, axis=-1), axis=1)

    def corridor(self, poses: ArrayLike, points: ArrayLike, reach: float) -> NDArray[np.bool_]:
        """For each pose (n, 3), whether a point (m, 2) lies ahead of it within the
        footprint's half-width and closer than ``reach`` [m] (the command's forward
        check, core/command.py forward_blocked, for each pose)."""
        p = np.atleast_2d(np.asarray(poses, float))
        pts = np.asarray(points, float).reshape(-1, 2)
        if pts.shape[0] == 0:
            return np.zeros(p.shape[0], bool)
        fx, fy = self._in_frames(p, pts)
        return np.any((fx > 0.0) & (np.abs(fy) <= self.half_width) & (fx < reach), axis=1)

    def gaps(self, poses: ArrayLike, points: ArrayLike) -> NDArray[np.float64]:
        """How far each point (m, 2) lies outside the footprint placed at each pose (n, 3)
        (n, m) [m]: the largest of its distances outside the edges' lines, which is the
        distance where it faces an edge and less by a corner (on the safe side); <= 0
        inside."""
        p = np.atleast_2d(np.asarray(poses, float))
        fx, fy = self._in_frames(p, np.asarray(points, float).reshape(-1, 2))
        return np.max(self._outside(fx, fy), axis=-1)

    def covers(self, pose: ArrayLike, points: ArrayLike) -> NDArray[np.bool_]:
        """Per point (m, 2), whether it lies inside the footprint placed at ``pose``
        (x, y, yaw)."""
        p = np.asarray(pose, float).ravel()[:3].reshape(1, 3)
        fx, fy = self._in_frames(p, np.asarray(points, float).reshape(-1, 2))
        return np.all(self._outside(fx[0], fy[0]) <= 0.0, axis=-1)

    def turn_contact(self, pose: ArrayLike, turn: float, points: ArrayLike,
                     margin: float) -> bool:
        """Whether turning on the spot from ``pose`` by ``turn`` [rad] brings a point
        within ``margin`` of the footprint (headings SWEEP_STEP apart)."""
        x, y, yaw = (float(v) for v in pose)
        n = max(1, math.ceil(abs(turn) / SWEEP_STEP))
        yaws = yaw + turn * np.arange(1, n + 1) / n
        poses = np.column_stack((np.full(n, x), np.full(n, y), yaws))
        return bool(self.contact(poses, points, margin).any())


def parse_footprint(text: str) -> Footprint | None:
    """The footprint of a ``footprint`` parameter: Nav2's ``[[x, y], [x, y], ...]`` (in
    the base frame [m], counter-clockwise; clockwise is reversed); '' or '[]': None (a
    disc). ConfigError for anything else."""
    if not text.strip():
        return None
    try:
        value = json.loads(text)
    except ValueError as exc:
        raise ConfigError(f'footprint: not a list of [x, y] points: {text!r}') from exc
    if value == []:
        return None
    try:
        vertices = np.array(value, dtype=float)
    except (TypeError, ValueError) as exc:
        raise ConfigError(f'footprint: not a list of [x, y] points: {text!r}') from exc
    if vertices.ndim == 2 and vertices.shape[1] == 2 and len(vertices) >= 3:
        x, y = vertices[:, 0], vertices[:, 1]
        if float(np.dot(x, np.roll(y, -1)) - np.dot(y, np.roll(x, -1))) < 0.0:
            vertices = vertices[::-1].copy()   # clockwise, as Nav2 also takes it
    return Footprint(vertices)


def format_footprint(vertices: ArrayLike) -> str:
    """A polygon (k, 2) [m] as the ``footprint`` parameter writes it."""
    return '[' + ', '.join(f'[{x:g}, {y:g}]' for x, y in np.asarray(vertices, float)) + ']'
