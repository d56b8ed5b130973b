"""Scores of one bench run that others define: kept apart from the bench so that
``subapf-results`` computes them from recorded runs without loading the simulator."""

from __future__ import annotations


def barn_score(reached: bool, time_over_limit: float | None) -> float:
    """The BARN Challenge's navigation metric of one run: success x optimal time /
    clip(actual time, 2 x optimal, 8 x optimal), the optimal time being the shortest
    path at the robot's top speed (the challenge's ``run.py``: its path length at the
    Jackal's 2 m/s), so 0.5 at most; ``time_over_limit`` is actual over optimal time
    (None when unknown: no score but 0)."""
    if not reached or time_over_limit is None:
        return 0.0
    return 1.0 / min(max(time_over_limit, 2.0), 8.0)
