"""Proposers: the stage that turns a cycle no gate stopped into a command
(core/cycle.py). One per ``method``:

* ``apf_sampling`` (``subharmonic_sampling``, the paper's full method and the
  default's local layer): the raw next move point of the APF step, eq. (23)
  (core/apf.py), circular sampling scored by the critics (core/sampling.py,
  core/critics/), the chosen point -> (v, w) (core/command.py);
* ``apf`` (``subharmonic``, ``traditional``, ``harmonic``: the paper's ablations):
  the same without the sampling, steering to the raw point;
* ``dwa``: the Dynamic Window baseline (core/dwa.py).

With the memory the attraction is the navigation field the reachability gate found
(``cycle.field``); without it, eq. (21).
"""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import NDArray

from .apf import apf_step
from .command import Command, forward_blocked, shape_command
from .config import PlannerConfig
from .critics import Critic, make_critics
from .cycle import Cycle, PlanResult, Stage
from .dwa import dwa_command
from .sampling import sample_and_choose
from .scan import voxel_downsample
from .status import Status


def local_radius(cfg: PlannerConfig) -> float:
    """Obstacle points farther than this from the robot cannot change a planning cycle of
    the APF methods [m]: the raw point and the samples lie within ``max_step + 2 *
    sample_radius`` of it, and no term looks farther than the repulsion's influence (a
    voxel's centroid may lie up to a voxel diagonal from its points), the Fig. 5
    priority distance, the discard distance or the safety corridor."""
    return (max(cfg.influence_distance + math.sqrt(2.0) * cfg.voxel_size,
                cfg.priority_distance, cfg.discard_distance, cfg.safety_distance)
            + cfg.max_step + 2.0 * cfg.sample_radius)


def _near(cycle: Cycle) -> NDArray[np.float64]:
    """The obstacle points within local_radius of the robot."""
    obs, position = cycle.obstacles, cycle.pose[:2]
    offset = obs - position
    return obs[offset[:, 0] ** 2 + offset[:, 1] ** 2 <= local_radius(cycle.cfg) ** 2]


class Apf(Stage):
    """Steer to the raw next move point of the APF step (the paper's ablations)."""

    name = 'apf'

    def run(self, cycle: Cycle) -> Cycle:
        cfg, pose = cycle.cfg, cycle.pose
        near = _near(cycle)
        raw = apf_step(pose[:2], cycle.goal, voxel_downsample(near, cfg.voxel_size), cfg,
                       cycle.field)[0]
        cmd = shape_command(pose, raw, cycle.goal, cycle.previous, near, cfg)
        return cycle.with_(result=PlanResult(cmd, raw, raw, **cycle.seen()))


class ApfSampling(Stage):
    """The APF step, then circular sampling around its raw point scored by the critics
    of ``critics`` (built once per configuration), steering to the chosen sample."""

    name = 'apf_sampling'

    def __init__(self) -> None:
        self._critics: tuple[PlannerConfig, tuple[Critic, ...]] | None = None

    def critics(self, cfg: PlannerConfig) -> tuple[Critic, ...]:
        """The critics of ``cfg`` (built at the first cycle with it)."""
        if self._critics is None or self._critics[0] is not cfg:
            self._critics = (cfg, make_critics(cfg))
        return self._critics[1]

    def run(self, cycle: Cycle) -> Cycle:
        cfg, pose = cycle.cfg, cycle.pose
        near = _near(cycle)
        repulsors = voxel_downsample(near, cfg.voxel_size)
        raw = apf_step(pose[:2], cycle.goal, repulsors, cfg, cycle.field)[0]
        sampling = sample_and_choose(raw, pose[:2], cycle.goal, near, repulsors, cfg,
                                     cycle.field, self.critics(cfg))
        target = sampling.chosen
        cmd = shape_command(pose, target, cycle.goal, cycle.previous, near, cfg)
        return cycle.with_(result=PlanResult(cmd, raw, target, sampling, **cycle.seen()))


class Dwa(Stage):
    """The Dynamic Window Approach (core/dwa.py); forward speed zeroed while the safety
    corridor holds a point; ``no_safe_move`` when no arc is admissible."""

    name = 'dwa'

    def run(self, cycle: Cycle) -> Cycle:
        cfg, pose = cycle.cfg, cycle.pose
        res = dwa_command(pose, cycle.goal, cycle.previous,
                          voxel_downsample(cycle.obstacles, cfg.voxel_size), cfg, cycle.field)
        if not res.admissible:
            return cycle.with_(status=Status.NO_SAFE_MOVE).stopped()
        v, status = res.v, Status.DRIVING if res.v > 0.0 else Status.TURNING
        if v > 0.0 and forward_blocked(pose, cycle.obstacles, cfg):
            v, status = 0.0, Status.BLOCKED_AHEAD
        return cycle.with_(result=PlanResult(Command(v, res.w, status), None,
                                             res.trajectory[-1].copy(), **cycle.seen()))
