"""Odometry calibration: the wheels' systematic error, a scale of the distance and one
of the turn, learnt while the robot drives, from scan-to-scan registration.

Most of a differential drive's odometry error is systematic (Borenstein and Feng,
UMBmark, 1996): the wheels' mean radius scales every distance, the effective wheel
separation every turn. The scan alignment (core/alignment.py) corrects the pose where
walls are in reach, but where the lidar sees little (an open hall through a 3.5 m
lidar) the prediction it starts from is odometry's, and a match to the memory sees
only part of the drift: the walls near the robot were drawn with the pose as it
drifted. A registration of two scans alone does not share that: it measures how far
the robot really moved between them.

So, between a keyframe scan and the first scan KEY_DISTANCE driven or KEY_TURN turned
later, the relative pose is found by point-to-line ICP (:func:`register`: the returns
of the new scan on the lines through the keyframe's, Gauss-Newton from odometry's
guess, returns within MAX_RANGE, a Cauchy weight against what moved or was seen
once). Each registration is

* a sample of both scales: the registered turn against odometry's, the registered
  displacement along odometry's direction of motion against odometry's distance, each
  with the variance the returns' information gives that direction (INFLATION for
  their errors being correlated, floored). The scales are the weighted least-squares
  fit of all samples and a prior of 1 (PRIOR_SIGMA), each taken once it rests on
  MIN_SAMPLES samples (1 before: one registration among people can be 1.5 % off); a
  sample more than OUTLIER from 1 is a failed registration, not a wheel. A corridor,
  which fixes a registration across it and not along it, gives a turn sample and
  hardly a distance one;
* a correction of the pose predicted for that scan (:meth:`OdometryCalibration.correct`):
  where the registration puts it from the keyframe's place, fused with the prediction
  by their covariances. Before anything is learnt, a robot's first turn (3 % of a
  half-turn is 0.05 rad, a metre across at 20 m) is measured by the scans rather than
  the wheels.

:class:`OdometryCalibration` keeps the keyframe and the fit; :func:`scaled` applies
the scales to an odometry motion. Pure numpy/scipy; the planner calls observe,
correct and place per scan (core/planner.py ``_align``).
"""

from __future__ import annotations

from dataclasses import dataclass
import math

import numpy as np
from numpy.typing import ArrayLike, NDArray
from scipy.spatial import cKDTree

from .robot import compose, invert, to_parent

#: A new sample once odometry has driven this far [m] or turned this much [rad] since
#: the keyframe.
KEY_DISTANCE = 0.5
KEY_TURN = 0.5
#: Returns farther than this take no part (a 3.5 m lidar's far returns are its
#: noisiest) [m].
MAX_RANGE = 3.0
#: Neighbours (within NEIGHBOUR_RADIUS [m]) that give a keyframe return its line, and
#: the most the line's smaller spread may be of its larger for the return to count.
NEIGHBOURS = 7
NEIGHBOUR_RADIUS = 0.25
LINE_RATIO = 0.05
#: Correspondences farther than this from their keyframe return are left out [m].
GATE = 0.2
#: Cauchy weight's scale [m]: a residual this big counts half.
CAUCHY = 0.03
#: Gauss-Newton iterations at most, and the step below which it stops [m, rad].
ITERATIONS = 15
CONVERGED = 1e-4
#: Fewest returns on lines a registration needs, and the most its RMS residual may be
#: [m].
MIN_MATCHED = 60
MAX_RMS = 0.04
#: The standard deviation of one return's residual [m] (the lidar's noise after
#: core/scan.py denoise, and the lines' own).
RETURN_SIGMA = 0.02
#: The registration's covariance times this (neighbouring returns' errors are not
#: independent: denoise averages them), and at least FLOOR_XY, FLOOR_YAW [m], [rad].
INFLATION = 25.0
FLOOR_XY = 0.005
FLOOR_YAW = 0.005
#: Odometry's own error over a keyframe's motion, besides its scales' [m], [rad].
ODOMETRY_FLOOR = 0.002
#: A registration that disagrees with the prediction by more than this (chi-square,
#: 3 degrees of freedom, 0.99) corrects nothing.
GATE_CHI2 = 11.3
#: The prior of each scale: 1, with this standard deviation.
PRIOR_SIGMA = 0.05
#: A scale is taken (else 1) once this many samples of it have been (2 m driven, 2 rad
#: turned): one registration among people set the distance's to 1.0155 in the arena,
#: where nothing is matched after it (docs/alignment.md).
MIN_SAMPLES = 4
#: A sample farther than this from 1 is a failed registration; and the scales stay
#: within 1 +- LIMIT.
OUTLIER = 0.15
LIMIT = 0.1


@dataclass(frozen=True)
class Registration:
    """Where the new scan's base_footprint is in the keyframe's (x, y, yaw), the
    information of that estimate (3 x 3, the returns' J^T W J), how many returns took
    part and their RMS residual [m]."""

    pose: NDArray[np.float64]
    information: NDArray[np.float64]
    matched: int
    rms: float


def _lines(points: NDArray[np.float64], tree: cKDTree
           ) -> tuple[NDArray[np.float64], NDArray[np.bool_]]:
    """Per point (n, 2): the unit normal of the line through it and its neighbours
    (n, 2), and whether they make one (n,)."""
    n = len(points)
    dist, idx = tree.query(points, k=NEIGHBOURS, distance_upper_bound=NEIGHBOUR_RADIUS)
    ok = np.isfinite(dist)
    nb = points[np.minimum(idx, n - 1)]
    count = ok.sum(axis=1)
    mean = np.where(ok[..., None], nb, 0.0).sum(axis=1) / np.maximum(count, 1)[:, None]
    d = np.where(ok[..., None], nb - mean[:, None, :], 0.0)
    sxx, syy = (d[..., 0] ** 2).sum(axis=1), (d[..., 1] ** 2).sum(axis=1)
    sxy = (d[..., 0] * d[..., 1]).sum(axis=1)
    angle = 0.5 * np.arctan2(2.0 * sxy, sxx - syy)   # of the line's direction
    half = 0.5 * (sxx + syy)
    root = np.hypot(0.5 * (sxx - syy), sxy)
    lo, hi = half - root, half + root
    line = (count >= 4) & (lo <= LINE_RATIO * hi) & (hi > 0.0)
    return np.column_stack((-np.sin(angle), np.cos(angle))), line


def register(keyframe: NDArray[np.float64], scan: NDArray[np.float64],
             guess: ArrayLike) -> Registration | None:
    """The pose (x, y, yaw) of the frame of ``scan`` (m, 2) in the frame of ``keyframe``
    (n, 2) that puts the scan's returns on the keyframe's lines, from ``guess``; None
    when too few returns lie on lines or the fit is poor (module docstring)."""
    keyframe = keyframe[np.hypot(*keyframe.T) <= MAX_RANGE] if len(keyframe) else keyframe
    scan = scan[np.hypot(*scan.T) <= MAX_RANGE] if len(scan) else scan
    if len(keyframe) < MIN_MATCHED or len(scan) < MIN_MATCHED:
        return None
    tree = cKDTree(keyframe)
    normal, line = _lines(keyframe, tree)
    pose = np.asarray(guess, float).copy()
    for _ in range(ITERATIONS):
        world = to_parent(pose, scan)
        dist, idx = tree.query(world, distance_upper_bound=GATE)
        use = np.isfinite(dist)
        use[use] = line[idx[use]]
        if np.count_nonzero(use) < MIN_MATCHED:
            return None
        c, s = math.cos(pose[2]), math.sin(pose[2])
        p, n = scan[use], normal[idx[use]]
        res = np.einsum('ij,ij->i', n, world[use] - keyframe[idx[use]])
        dyaw = np.column_stack((-s * p[:, 0] - c * p[:, 1], c * p[:, 0] - s * p[:, 1]))
        jac = np.column_stack((n[:, 0], n[:, 1], np.einsum('ij,ij->i', n, dyaw)))
        w = 1.0 / (1.0 + (res / CAUCHY) ** 2) / RETURN_SIGMA ** 2
        info = (jac.T * w) @ jac
        step = -np.linalg.solve(info + 1e-9 * np.eye(3), (jac.T * w) @ res)
        pose = pose + step
        if math.hypot(step[0], step[1]) < CONVERGED and abs(step[2]) < CONVERGED:
            break
    rms = float(np.sqrt(np.mean(res ** 2)))
    if rms > MAX_RMS:
        return None
    return Registration(pose, info, int(np.count_nonzero(use)), rms)


def scaled(motion: ArrayLike, scales: tuple[float, float]) -> tuple[float, float, float]:
    """An odometry motion (x, y, yaw in the frame it starts from) with its distance
    scaled by ``scales[0]`` and its turn by ``scales[1]``: the motion along the arc
    odometry reports, its length and angle scaled."""
    x, y, yaw = (float(v) for v in motion)
    k_d, k_y = scales
    chord = math.hypot(x, y)
    if chord == 0.0:
        return 0.0, 0.0, k_y * yaw
    # the chord of an arc leaves at half the arc's turn: keep it at half the new turn
    bearing = math.atan2(y, x) + 0.5 * (k_y - 1.0) * yaw
    return k_d * chord * math.cos(bearing), k_d * chord * math.sin(bearing), k_y * yaw


class OdometryCalibration:
    """The scales (distance, turn) by which odometry's motion is multiplied to be the
    robot's, learnt from the scans (module docstring)."""

    def __init__(self) -> None:
        self.reset()

    def reset(self) -> None:
        """Forget the samples and the keyframe: scales 1."""
        prior = PRIOR_SIGMA ** -2
        #: Per scale (distance, turn): the weighted sums of x * y and x * x, the prior
        #: in them.
        self._xy = np.array([prior, prior])
        self._xx = np.array([prior, prior])
        #: The keyframe: its returns, odometry's pose and the memory's (place) then.
        self._key: tuple[NDArray[np.float64], NDArray[np.float64]] | None = None
        self._key_map: NDArray[np.float64] | None = None
        self._placing = False
        #: The last registration: the motion since the keyframe and odometry's (x, y,
        #: yaw), the registration's covariance (3 x 3), the scales' standard deviations
        #: before its samples.
        self._measured: tuple[NDArray, NDArray, NDArray, NDArray] | None = None
        #: Samples taken (distance, turn).
        self.samples = [0, 0]

    @property
    def scales(self) -> tuple[float, float]:
        """(distance, turn): odometry's motion times these is the robot's."""
        k = np.clip(self._xy / self._xx, 1.0 - LIMIT, 1.0 + LIMIT)
        k = np.where(np.asarray(self.samples) >= MIN_SAMPLES, k, 1.0)
        return float(k[0]), float(k[1])

    def observe(self, points: NDArray[np.float64], odom: ArrayLike) -> None:
        """A scan's returns ``points`` (m, 2) in base_footprint and odometry's pose of
        base_footprint then (x, y, yaw in odom): once it is KEY_DISTANCE or KEY_TURN from
        the keyframe, register it there, take the samples, and make it the keyframe
        (``points`` without what moves). Then
        :meth:`correct` the scan's predicted pose and :meth:`place` it."""
        odom = np.asarray(odom, float)
        self._measured, self._placing = None, False
        if self._key is None:
            self._key, self._placing = (np.asarray(points, float), odom), True
            return
        key_points, key_odom = self._key
        motion = np.array(compose(invert(key_odom), odom))
        distance, turn = math.hypot(motion[0], motion[1]), abs(motion[2])
        if distance < KEY_DISTANCE and turn < KEY_TURN:
            if len(key_points) < MIN_MATCHED <= len(points):   # a keyframe with too little
                self._key, self._placing = (np.asarray(points, float), odom), True
            return
        self._key, self._placing = (np.asarray(points, float), odom), True
        found = register(key_points, np.asarray(points, float), motion)
        if found is None:
            return
        cov = np.linalg.inv(found.information + 1e-9 * np.eye(3)) * INFLATION \
            + np.diag([FLOOR_XY ** 2, FLOOR_XY ** 2, FLOOR_YAW ** 2])
        sd_scales = self._xx ** -0.5   # what the prediction (made before) knew
        if distance >= KEY_DISTANCE / 2:
            along = motion[:2] / distance
            self._sample(0, distance, float(along @ found.pose[:2]),
                         float(along @ cov[:2, :2] @ along))
        if turn >= KEY_TURN / 2:
            self._sample(1, float(motion[2]), float(found.pose[2]), float(cov[2, 2]))
        self._measured = (found.pose, motion, cov, sd_scales)

    def correct(self, predicted: ArrayLike) -> NDArray[np.float64]:
        """The pose ``predicted`` for the scan just observed (x, y, yaw in the memory's
        frame; with the scales as they were before it was observed) fused with where its
        registration puts it from the keyframe's place, by their covariances: the
        prediction's is the scales' uncertainty then times odometry's motion since the
        keyframe. Unchanged without a registration, or when the two
        disagree beyond GATE_CHI2."""
        predicted = np.asarray(predicted, float)
        if self._measured is None or self._key_map is None:
            return predicted
        measured, motion, cov_m, (sd_d, sd_y) = self._measured
        own = np.array(compose(invert(self._key_map), predicted))
        distance, turn = math.hypot(motion[0], motion[1]), abs(motion[2])
        sd_yaw = sd_y * turn + ODOMETRY_FLOOR
        sd_xy = sd_d * distance + 0.5 * distance * sd_yaw + ODOMETRY_FLOOR
        cov_p = np.diag([sd_xy ** 2, sd_xy ** 2, sd_yaw ** 2])
        off = measured - own
        off[2] = math.remainder(off[2], 2 * math.pi)
        if off @ np.linalg.solve(cov_p + cov_m, off) > GATE_CHI2:
            return predicted
        gain = cov_p @ np.linalg.inv(cov_p + cov_m)
        return np.array(compose(self._key_map, own + gain @ off))

    def place(self, pose: ArrayLike) -> None:
        """Where the scan just observed is in the memory's frame, as the alignment
        finally put it (x, y, yaw): the keyframe's place, if it became the keyframe."""
        if self._placing:
            self._key_map = np.asarray(pose, float).copy()
            self._placing = False

    def _sample(self, which: int, odometry: float, registered: float, var: float) -> None:
        if abs(registered / odometry - 1.0) > OUTLIER:
            return
        self._xy[which] += odometry * registered / var
        self._xx[which] += odometry * odometry / var
        self.samples[which] += 1
