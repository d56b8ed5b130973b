"""Getting out of the way: the planned command checked against where the moving
obstacles will be, and replaced when it meets one.

The APF command (core/planner.py) only sees where things are. Each cycle this
layer rolls the command out for ``prediction_horizon`` seconds (a unicycle at
constant (v, w), core/rollout.py, in steps of the planning period or a whole fraction of
it: rollout_step; with ``escape_ramps``, reaching (v, w) from the last command under the
acceleration limits) against each moving track's constant-velocity
prediction (core/tracking.py): the gap between the footprint and the track's
disc must stay above ``moving_clearance``. When it does not, a small set of
escape manoeuvres is rolled out the same way (all at once, as arrays): forward,
slower, standing still and backing up at ``reverse_speed`` (the burger backs at
up to 0.22 m/s), each straight or turning, for the whole horizon or for a while
and then straight (stepping aside to pass). An escape's rollout halts where it
would come within ``robot_radius + STATIC_MARGIN`` of a laser point that is not a
moving track's (a robot that runs ahead of a walker into a wall stands there when
the walker arrives), and it is admissible only if it does not halt within its
first EVASION_COMMIT seconds and the safety corridor does not block its forward
speed. Among the admissible ones that keep the clearance, the one closest to the
planned command wins (the robot steps aside rather than turns back); when none
keeps it, one that never touches a predicted disc within the horizon, else the one
that touches latest, and among those the largest gap (it never stands still in an
obstacle's way while a way out exists). Gaps are time-weighted so that a meeting
soon counts more than one later. The chosen manoeuvre is committed: the next cycle
considers it again, one period on, and keeps it while it keeps the clearance (when
none does, while it touches no more than TOUCH_HYSTERESIS sooner than the best and its
gap is within HYSTERESIS: least_bad).
"""

from __future__ import annotations

from dataclasses import dataclass
import math

import numpy as np
from numpy.typing import NDArray
from scipy.spatial import cKDTree

from .config import PlannerConfig
from .rollout import ramped, rollouts, steps
from .tracking import Tracks

#: Longest rollout step [s]: the step divides the planning period, so a committed
#: escape advances by whole steps (at the default 5 Hz one step is one period).
MAX_ROLLOUT_STEP = 0.2
#: An escape must clear the static points for this long [s] (one second of braking
#: distance at any speed the robot drives) ...
EVASION_COMMIT = 1.0
#: ... by this much beyond the footprint [m] (the width of one map cell is too coarse).
STATIC_MARGIN = 0.02
#: A meeting t seconds ahead counts as a gap this much larger per second [m/s]
#: (soon matters more than later: a later meeting leaves time to change course).
TIME_DISCOUNT = 0.05
#: Angular rates of the escape candidates, as fractions of the top turn rate (five
#: keep the candidate set small enough to roll out every cycle).
TURN_FRACTIONS = (-0.6, -0.3, 0.0, 0.3, 0.6)
#: How long a turning candidate turns before it drives straight [s] (None: the whole
#: horizon, a constant arc). Turn-then-straight is how one steps aside to pass someone.
TURN_TIMES = (None, 0.6, 1.2)
#: When no escape keeps the clearance, the committed one stays while its gap is within
#: this of the largest [m] (no flipping between escapes of nearly the same gap).
HYSTERESIS = 0.02
#: ... and while it touches a predicted disc no more than this sooner than the latest [s]
#: (touch times come in rollout steps, and a walker's predicted path wavers with its
#: velocity estimate: beside slow walkers the choice flipped between driving on and
#: backing up, cycle after cycle).
TOUCH_HYSTERESIS = 0.4


def rollout_step(period: float) -> tuple[float, int]:
    """The evasion's rollout step [s] for a planning ``period`` [s], and how many of
    them make a period: the period itself, or a whole fraction of it no longer than
    MAX_ROLLOUT_STEP."""
    per = max(1, math.ceil(period / MAX_ROLLOUT_STEP - 1e-9))
    return period / per, per


@dataclass(frozen=True)
class Escape:
    """An escape manoeuvre: forward speed ``v`` [m/s] and the turn rate of each rollout
    step (k,) [rad/s], ``per_period`` steps to a planning period; the command now is
    (v, turn[0])."""

    v: float
    turn: tuple[float, ...]
    per_period: int = 1

    @property
    def command(self) -> tuple[float, float]:
        return (self.v, self.turn[0])

    def advanced(self) -> Escape:
        """The same manoeuvre one planning period later (its last turn rate held)."""
        m = min(self.per_period, len(self.turn))
        return Escape(self.v, self.turn[m:] + self.turn[-1:] * m, self.per_period)


def driven(pose: NDArray[np.float64], v: NDArray[np.float64], turn: NDArray[np.float64],
           previous: tuple[float, float], cfg: PlannerConfig,
           dt: float) -> NDArray[np.float64]:
    """Positions (c, k, 2) [m] of the robot from ``pose`` (x, y, yaw) commanded forward
    speeds v (c,) [m/s] and turn rates turn (c, k) [rad/s] in steps of ``dt`` [s]; with
    ``escape_ramps``, from the ``previous`` command (v, w) under the acceleration limits
    (a Jackal at 2 m/s brakes over 0.59 m at 3.4 m/s^2: standing still is not an escape
    it has at once), else at the commanded rates from the start."""
    speed = np.repeat(np.asarray(v, float)[:, None], turn.shape[1], axis=1)
    if cfg.escape_ramps:
        speed = ramped(previous[0], speed, cfg.max_linear_acceleration, dt)
        turn = ramped(previous[1], turn, cfg.max_angular_acceleration, dt)
    return rollouts(pose, speed, turn, dt)


def _gaps(paths: NDArray[np.float64], tracks: Tracks, robot_radius: float,
          dt: float) -> NDArray[np.float64]:
    """Gap [m] (c, k) at each rollout step between the footprint along each of the paths
    (c, k, 2) (one point per ``dt`` [s] from one step ahead) and the nearest moving
    track's predicted disc; inf with none."""
    m = tracks.moving
    if not np.any(m):
        return np.full(paths.shape[:2], math.inf)
    t = (np.arange(paths.shape[1]) + 1)[:, None] * dt                         # (k, 1)
    where = tracks.position[m][None] + t[..., None] * tracks.velocity[m][None]   # (k, n, 2)
    d = paths[:, :, None, :] - where[None]                                      # (c, k, n, 2)
    gap = np.hypot(d[..., 0], d[..., 1]) - tracks.radius[m] - robot_radius
    return gap.min(axis=2)


def _discounted(gaps: NDArray[np.float64], dt: float) -> NDArray[np.float64]:
    """The smallest time-discounted gap of each rollout (c,) [m] (steps of ``dt``)."""
    t = (np.arange(gaps.shape[1]) + 1) * dt
    return (gaps + TIME_DISCOUNT * t).min(axis=1)


def moving_gaps(paths: NDArray[np.float64], tracks: Tracks, robot_radius: float,
                dt: float) -> NDArray[np.float64]:
    """Smallest time-discounted gap [m] (c,) between the footprint along each of the
    paths (c, k, 2) (one point per ``dt`` [s] from one step ahead) and the moving
    tracks' predicted discs; inf with none."""
    return _discounted(_gaps(paths, tracks, robot_radius, dt), dt)


def moving_gap(path: NDArray[np.float64], tracks: Tracks, robot_radius: float,
               dt: float) -> float:
    """:func:`moving_gaps` of one path (k, 2)."""
    return float(moving_gaps(path[None], tracks, robot_radius, dt)[0])


def contact_time(gaps: NDArray[np.float64], dt: float) -> NDArray[np.float64]:
    """When each rollout (c, k gaps, steps of ``dt``) first touches a track's predicted
    disc [s]; inf for one that never does within the horizon."""
    touch = gaps < 0.0
    first = np.argmax(touch, axis=1)
    return np.where(touch.any(axis=1), (first + 1) * dt, math.inf)


def halted(pose: NDArray[np.float64], paths: NDArray[np.float64], static: NDArray,
           radius: float) -> tuple[NDArray[np.float64], NDArray[np.int64]]:
    """The paths (c, k, 2) from ``pose`` (x, y, yaw), each held from the first step that
    comes within radius + STATIC_MARGIN [m] of a static point (m, 2) at its last point
    before it (the start, for the first step): where the robot would stand, braked; and
    that step's index per path (c,; k for a path that never comes that close)."""
    c, k = paths.shape[:2]
    if len(static) == 0:
        return paths, np.full(c, k, np.int64)
    d, _ = cKDTree(static).query(paths.reshape(-1, 2), distance_upper_bound=radius
                                 + STATIC_MARGIN)
    near = np.isfinite(d).reshape(c, k)
    first = np.where(near.any(axis=1), np.argmax(near, axis=1), k)
    if np.all(first == k):
        return paths, first
    start = np.broadcast_to(pose[:2], (c, 1, 2))
    held = np.minimum(np.arange(k)[None], first[:, None] - 1) + 1   # index into start+paths
    return np.take_along_axis(np.concatenate((start, paths), axis=1), held[..., None],
                              axis=1), first


def candidates(cfg: PlannerConfig) -> list[Escape]:
    """The escape manoeuvres: each speed (top, half, standing, backing at reverse_speed)
    with each turn rate of TURN_FRACTIONS, turning for each of TURN_TIMES, in rollout
    steps of the planning period (rollout_step)."""
    dt, per = rollout_step(cfg.period)
    k = steps(cfg.prediction_horizon, dt)
    speeds = [cfg.max_linear_velocity, 0.5 * cfg.max_linear_velocity, 0.0]
    if cfg.reverse_speed > 0.0:
        speeds.append(-cfg.reverse_speed)
    out: list[Escape] = []
    for v in speeds:
        for f in TURN_FRACTIONS:
            w = f * cfg.max_angular_velocity
            for turning in (TURN_TIMES if f != 0.0 and v != 0.0 else (None,)):
                n = k if turning is None else min(k, steps(turning, dt))
                out.append(Escape(v, (w,) * n + (0.0,) * (k - n), per))
    return out


def evade(pose: NDArray[np.float64], planned: tuple[float, float], tracks: Tracks,
          static: NDArray[np.float64], cfg: PlannerConfig, blocked_ahead: bool,
          committed: Escape | None = None,
          previous: tuple[float, float] | None = None) -> Escape | None:
    """A replacement for the ``planned`` (v, w) when its rollout meets a moving track
    (see the module docstring), or None to keep it. ``static``: the laser points that
    are not moving tracks' (m, 2); ``blocked_ahead``: the safety corridor holds a point
    (forward candidates are then inadmissible); ``committed``: the escape of the last
    cycle, advanced one period, kept while it still keeps the clearance (no dithering
    between escapes); ``previous``: the last command (v, w), from which, with
    ``escape_ramps``, every rollout changes speed and turn rate under the acceleration
    limits (None: the planned one)."""
    v0, w0 = planned
    previous = planned if previous is None else previous
    dt, _ = rollout_step(cfg.period)
    k = steps(cfg.prediction_horizon, dt)
    if moving_gap(driven(pose, np.array([v0]), np.full((1, k), w0), previous, cfg, dt)[0],
                  tracks, cfg.robot_radius, dt) >= cfg.moving_clearance:
        return None
    options = candidates(cfg)
    if committed is not None and len(committed.turn) == k:
        options.append(committed)
    v = np.array([e.v for e in options])
    turn = np.array([e.turn for e in options])
    paths, halt = halted(pose, driven(pose, v, turn, previous, cfg, dt), static,
                         cfg.robot_radius)
    ok = ~((v > 0.0) & blocked_ahead)
    ok &= (v == 0.0) | (halt >= steps(EVASION_COMMIT, dt))
    if not np.any(ok):
        return None
    gaps = _gaps(paths, tracks, cfg.robot_radius, dt)
    gap = np.where(ok, _discounted(gaps, dt), -math.inf)
    touch = np.where(ok, contact_time(gaps, dt), -math.inf)
    kept = np.zeros(len(options), bool)
    if committed is not None and options[-1] is committed:
        kept[-1] = ok[-1]
    safe = ok & (gap >= cfg.moving_clearance)
    if np.any(safe):
        # the committed escape, else the one closest to the plan (then the larger gap)
        near = np.abs(v - v0) + cfg.escape_turn_weight * np.abs(turn[:, 0] - w0)
        score = np.where(kept, -1.0, near)
        return options[int(np.lexsort((-gap, np.where(safe, score, math.inf)))[0])]
    return options[least_bad(touch, gap, bool(kept[-1]))]


def least_bad(touch: NDArray[np.float64], gap: NDArray[np.float64], committed: bool) -> int:
    """Among escapes none of which keeps the clearance, with their contact times (c,)
    [s] (inf: never) and gaps (c,) [m] (-inf: inadmissible): the index of one that never
    touches, else of the latest touch, then of the largest gap; the last one instead
    if it is the ``committed`` escape and within TOUCH_HYSTERESIS and HYSTERESIS of
    that."""
    best = int(np.lexsort((-gap, -touch))[0])
    if committed and touch[-1] >= touch[best] - TOUCH_HYSTERESIS \
            and gap[-1] >= gap[best] - HYSTERESIS:
        return len(touch) - 1
    return best
