"""Which stages a cycle runs, from the parameters, and the registry of stages.

A stage is registered here by name, in one of three kinds (core/cycle.py): gates
(core/gates.py), proposers (core/proposers.py), filters (core/approach.py,
core/filters.py, core/contact_check.py). The parameters choose them
(:func:`stage_names`); the sampling's scoring terms are chosen by ``critics``
(core/critics/). A new stage is one module and a line here.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

from .approach import FinalApproach
from .config import PlannerConfig
from .contact_check import ContactCheck
from .cycle import Stage
from .filters import Evasion
from .gates import Goal, Mapping, Reachability
from .memory import NavigationMemory
from .proposers import Apf, ApfSampling, Dwa

#: Stage name -> how to build it (from the planner's memory).
STAGES: dict[str, Callable[[NavigationMemory], Stage]] = {
    'goal': lambda memory: Goal(),
    'mapping': lambda memory: Mapping(),
    'reachability': Reachability,
    'apf_sampling': lambda memory: ApfSampling(),
    'apf': lambda memory: Apf(),
    'dwa': lambda memory: Dwa(),
    'final_approach': lambda memory: FinalApproach(),
    'evasion': lambda memory: Evasion(),
    'contact_check': lambda memory: ContactCheck(),
}


@dataclass(frozen=True)
class StageNames:
    """The stages of a configuration, by kind, in the order they run."""

    gates: tuple[str, ...]
    proposer: str
    filters: tuple[str, ...]

    @property
    def all(self) -> tuple[str, ...]:
        return (*self.gates, self.proposer, *self.filters)


def stage_names(cfg: PlannerConfig) -> StageNames:
    """The stages ``cfg`` asks for: the goal gate; with the memory (``attraction_field:
    geodesic``) the mapping stand (with ``scan_alignment``) and the reachability gate;
    the proposer of ``method``; with the memory and ``final_approach`` the final
    approach filter (core/approach.py); the evasion filter with the tracker (not for
    DWA, which does without); last, with the memory and ``contact_time``, the contact
    check (core/contact_check.py; not for DWA, whose arcs keep their own clearance)."""
    gates = ['goal']
    if cfg.geodesic and cfg.scan_alignment:
        gates.append('mapping')
    if cfg.geodesic:
        gates.append('reachability')
    proposer = {'subharmonic_sampling': 'apf_sampling', 'dwa': 'dwa'}.get(cfg.method, 'apf')
    filters = ('final_approach',) if cfg.geodesic and cfg.final_approach else ()
    if cfg.tracks_moving and cfg.method != 'dwa':
        filters += ('evasion',)
    if cfg.geodesic and cfg.contact_time > 0.0 and cfg.method != 'dwa':
        filters += ('contact_check',)
    return StageNames(tuple(gates), proposer, filters)


class Pipeline:
    """The stages of a configuration, built once each and kept (with what they remember)
    across configurations."""

    def __init__(self, cfg: PlannerConfig, memory: NavigationMemory) -> None:
        self._memory = memory
        self._built: dict[str, Stage] = {}
        self.configure(cfg)

    def _stage(self, name: str) -> Stage:
        if name not in self._built:
            self._built[name] = STAGES[name](self._memory)
        return self._built[name]

    def configure(self, cfg: PlannerConfig) -> None:
        """The stages ``cfg`` asks for (stage_names)."""
        self.names = stage_names(cfg)
        self.gates = [self._stage(n) for n in self.names.gates]
        self.proposer = self._stage(self.names.proposer)
        self.filters = [self._stage(n) for n in self.names.filters]

    def reset(self) -> None:
        for stage in self._built.values():
            stage.reset()

    def forget(self) -> None:
        for stage in self._built.values():
            stage.forget()
