"""World files v1: good files load, bad ones say file, field and problem."""

import pytest
import yaml

from subapf_planner.sim.world import Box, Circle, WorldError, load_world, world_files

pytestmark = pytest.mark.sim

GOOD = """
name: wall_demo
description: free text
start: [0.0, 0.0, 1.5708]
goal: [0.0, 4.0]
goal_tolerance: 0.15
time_limit: 120
bounds: [-3, -1, 3, 5]
obstacles:
  - circle: {center: [0.5, 2.0], radius: 0.3}
  - box: {center: [0.0, 2.0], size: [2.0, 0.15], yaw: 0.0}
"""


def write(tmp_path, text):
    p = tmp_path / 'w.yaml'
    p.write_text(text)
    return p


def test_issue_example_loads(tmp_path):
    w = load_world(write(tmp_path, GOOD))
    assert w.name == 'wall_demo' and w.goal == (0.0, 4.0) and w.bounds == (-3, -1, 3, 5)
    assert isinstance(w.obstacles[0], Circle) and isinstance(w.obstacles[1], Box)
    assert len(w.all_obstacles()) == 6
    assert w.clearance(0.0, 2.0) < 0 < w.clearance(0.0, 0.0)


def test_shipped_worlds_load(worlds_dir):
    files = world_files([worlds_dir])
    assert len(files) >= 8
    names = {load_world(f).name for f in files}
    assert {'fig3_narrowing_passage', 'fig6a_narrow_obstacles', 'fig6b_tight_space',
            'fig6c_circle_in_front', 'fig6d_big_wall', 'four_points', 'u_trap'} <= names


def mutate(**changes):
    doc = yaml.safe_load(GOOD)
    for k, v in changes.items():
        if v is None:
            doc.pop(k)
        else:
            doc[k] = v
    return yaml.safe_dump(doc)


@pytest.mark.parametrize('text, message', [
    (mutate(start=None), 'start: missing'),
    (mutate(start=[0, 0]), 'start: expected a list of 3 numbers'),
    (mutate(goal=['a', 1]), 'goal: expected finite numbers'),
    (mutate(obstacles=[{'circle': {'center': [2, 2], 'radius': -0.3}}]),
     r'obstacles\[0\].circle.radius: must be a positive number'),
    (mutate(obstacles=[{'box': {'center': [2, 2]}}]), r'obstacles\[0\].box: missing "size"'),
    (mutate(obstacles=[{'triangle': {}}]), 'unknown obstacle type'),
    (mutate(colour='red'), r"unknown key\(s\) \['colour'\]"),
    (mutate(start=[0.5, 2.0, 0.0]), 'start: .* inside or within'),
    (mutate(goal=[9.0, 9.0]), 'goal: .* outside bounds'),
    (mutate(goal_tolerance=0), 'goal_tolerance: must be a positive number'),
    ('name: [unclosed', 'not valid YAML'),
    ('- just\n- a list\n', 'top level: expected a mapping'),
])
def test_bad_files_give_clear_errors(tmp_path, text, message):
    p = write(tmp_path, text)
    with pytest.raises(WorldError, match=message) as info:
        load_world(p)
    assert str(p) in str(info.value)


def test_missing_file(tmp_path):
    with pytest.raises(WorldError, match='cannot read'):
        load_world(tmp_path / 'nope.yaml')
