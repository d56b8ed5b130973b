"""The cycle's stages and critics: chosen by configuration alone, each scoring term one
class. A toy critic defined here (not in the package) is named in a params file and
changes the sample the planner chooses; the shipped critics sum to Algorithm 1's score
with the Fig. 5 bonus."""

import numpy as np
import pytest

from subapf_planner.core.config import PlannerConfig, load_config
from subapf_planner.core.critics import Samples
from subapf_planner.core.pipeline import stage_names
from subapf_planner.core.planner import plan
from subapf_planner.core.sampling import sample_and_choose

pytestmark = pytest.mark.core


class TowardsLeft:
    """A toy critic: the farther left (+y) a sample, the cheaper (10 m per metre)."""

    name = 'towards_left'

    def __init__(self, cfg: PlannerConfig) -> None:
        self.weight = 10.0

    def cost(self, samples: Samples) -> np.ndarray:
        return -self.weight * samples.points[:, 1]


def test_a_critic_named_in_a_params_file_changes_the_choice(tmp_path):
    params = tmp_path / 'params.yaml'
    params.write_text('subapf_planner:\n  ros__parameters:\n'
                      "    attraction_field: euclidean\n"
                      "    critics: [progress, priority, 'test_critics:TowardsLeft']\n")
    toy = load_config(params)
    plain = PlannerConfig(attraction_field='euclidean')
    pose, goal = np.zeros(3), np.array([3.0, 0.0])
    base = plan(plain, pose, goal, np.zeros((0, 2)))
    steered = plan(toy, pose, goal, np.zeros((0, 2)))
    assert base.sampling.chosen_index == 0                 # in the open: towards the goal
    assert set(steered.sampling.costs) == {'progress', 'priority', 'towards_left'}
    assert steered.sampling.chosen_index != 0 and steered.chosen_point[1] > 0.04
    assert steered.command.w > 0.0 and base.command.w == pytest.approx(0.0)   # it turns left


def test_the_shipped_critics_sum_to_the_distance_to_go_and_the_bonus():
    """Beside a wall in the way, the score of each sample is the progress cost, the
    priority sample's lowered by priority_bonus, and the chosen one has the lowest."""
    cfg = PlannerConfig(attraction_field='euclidean')
    wall = np.column_stack((np.full(41, 0.5), np.linspace(-1.0, 1.0, 41)))
    res = sample_and_choose([0.05, 0.0], [0.0, 0.0], [3.0, 0.0], wall, wall, cfg)
    progress, bonus = res.costs['progress'], res.costs['priority']
    assert res.priority_index >= 0 and bonus[res.priority_index] == -cfg.priority_bonus
    assert np.count_nonzero(bonus) == 1
    finite = np.isfinite(res.scores)
    np.testing.assert_array_equal(res.scores[finite], (progress + bonus)[finite])
    assert res.chosen_index == int(np.argmin(res.scores))


def test_only_progress_ignores_the_priority():
    cfg = PlannerConfig(attraction_field='euclidean', critics=('progress',))
    wall = np.column_stack((np.full(41, 0.5), np.linspace(-1.0, 1.0, 41)))
    res = sample_and_choose([0.05, 0.0], [0.0, 0.0], [3.0, 0.0], wall, wall, cfg)
    assert res.priority_index == -1 and set(res.costs) == {'progress'}


@pytest.mark.parametrize('changes, gates, proposer, filters', [
    ({}, ('goal', 'mapping', 'reachability'), 'apf_sampling',
     ('final_approach', 'evasion', 'contact_check')),
    ({'scan_alignment': False}, ('goal', 'reachability'), 'apf_sampling',
     ('final_approach', 'evasion', 'contact_check')),
    ({'track_moving': False}, ('goal', 'mapping', 'reachability'), 'apf_sampling',
     ('final_approach', 'contact_check')),
    ({'final_approach': False}, ('goal', 'mapping', 'reachability'), 'apf_sampling',
     ('evasion', 'contact_check')),
    ({'contact_time': 0.0}, ('goal', 'mapping', 'reachability'), 'apf_sampling',
     ('final_approach', 'evasion')),
    ({'attraction_field': 'euclidean'}, ('goal',), 'apf_sampling', ()),
    ({'attraction_field': 'euclidean', 'method': 'harmonic'}, ('goal',), 'apf', ()),
    ({'method': 'dwa'}, ('goal', 'mapping', 'reachability'), 'dwa', ('final_approach',)),
])
def test_the_parameters_choose_the_stages(changes, gates, proposer, filters):
    names = stage_names(PlannerConfig(**changes))
    assert (names.gates, names.proposer, names.filters) == (gates, proposer, filters)
