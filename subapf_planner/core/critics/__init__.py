"""Critics: the scoring terms of the circular sampling, one module each.

As the critics of Nav2's DWB and MPPI controllers, each term of a sample's score is a
critic with a name, its own parameters and a cost per sample; the sampling step
(core/sampling.py) sums the costs of the critics the ``critics`` parameter lists, in
that order, and the lowest total wins (ties to the lowest index: towards the goal,
then clockwise). Algorithm 1's discard (a sample closer than ``discard_distance`` to an
obstacle point) comes before any critic: a discarded sample's score is inf whatever
the critics say, and critics need not score it.

Shipped critics (``REGISTRY``): ``progress`` (Algorithm 1's score: the distance to the
goal of the next APF step from the sample, through the navigation field when there is
one) and ``priority`` (the Fig. 5 priority sample's bonus). A critic of one's own is a
class with a ``name``, a constructor taking the PlannerConfig and a ``cost(samples)``
method, listed in ``critics`` as ``module:Class`` (imported when the configuration is
built); nothing else changes.
"""

from __future__ import annotations

from dataclasses import dataclass
import difflib
import importlib
from typing import TYPE_CHECKING, Protocol

import numpy as np
from numpy.typing import NDArray

from ..navigation import NavigationField
from ..params import ConfigError

if TYPE_CHECKING:   # (the config imports this module to check its critics' names)
    from ..config import PlannerConfig


@dataclass(frozen=True)
class Samples:
    """One cycle's sampling circle, what every critic scores (metres, the memory's
    frame)."""

    #: The samples (N, 2), sample 0 towards the goal (or the field's descent), then
    #: clockwise.
    points: NDArray[np.float64]
    #: Each sample's distance to the nearest obstacle point (N,).
    clearance: NDArray[np.float64]
    #: Whether each sample survived Algorithm 1's discard (N,); the others score inf.
    safe: NDArray[np.bool_]
    #: The raw next move point the circle is around (2,), and the robot's position.
    raw: NDArray[np.float64]
    position: NDArray[np.float64]
    goal: NDArray[np.float64]
    #: Every valid obstacle point near the robot (m, 2), and the voxel-downsampled ones
    #: the APF step is repelled by.
    obstacles: NDArray[np.float64]
    repulsors: NDArray[np.float64]
    #: The navigation field (None: the Euclidean attraction of eq. 21).
    field: NavigationField | None


class Critic(Protocol):
    """A scoring term: ``cost(samples)`` (N,) is added to each sample's score [m of
    distance to go; inf vetoes]. Built once per configuration from the PlannerConfig."""

    name: str

    def cost(self, samples: Samples) -> NDArray[np.float64]:
        ...


def _registry() -> dict[str, type]:
    from .priority import Priority
    from .progress import Progress
    return {Progress.name: Progress, Priority.name: Priority}


def critic_class(name: str) -> type:
    """The class of critic ``name``: a shipped one, or ``module:Class`` imported;
    ConfigError naming the closest shipped name when there is none."""
    shipped = _registry()
    if name in shipped:
        return shipped[name]
    module, _, cls = name.partition(':')
    if cls:
        try:
            return getattr(importlib.import_module(module), cls)
        except (ImportError, AttributeError) as exc:
            raise ConfigError(f'critics: cannot load {name!r}: {exc}') from exc
    close = difflib.get_close_matches(name, shipped, n=1)
    hint = f' (did you mean {close[0]!r}?)' if close else ''
    raise ConfigError(f'critics: unknown critic {name!r}{hint}; shipped: '
                      f'{", ".join(shipped)}, or module:Class')


def make_critics(cfg: 'PlannerConfig') -> tuple[Critic, ...]:
    """The critics ``cfg.critics`` lists, in order, built from ``cfg``."""
    return tuple(critic_class(name)(cfg) for name in cfg.critics)
