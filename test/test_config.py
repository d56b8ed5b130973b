"""Configuration: validation and the YAML documenting every parameter."""

import dataclasses

from conftest import PARAMS
import pytest
import yaml

from subapf_planner.core.config import ConfigError, PlannerConfig, from_mapping, load_config

pytestmark = pytest.mark.core


def test_yaml_lists_every_core_parameter_with_its_default():
    params = yaml.safe_load(PARAMS.read_text())['subapf_planner']['ros__parameters']
    for f in dataclasses.fields(PlannerConfig):
        assert f.name in params, f'{f.name} missing from config/planner.yaml'
        default = list(f.default) if isinstance(f.default, tuple) else f.default
        assert params[f.name] == default, f.name
    assert load_config(PARAMS) == PlannerConfig()


@pytest.mark.parametrize('changes, message', [
    ({'danger_distance': -1.0}, 'danger_distance'),
    ({'danger_distance': float('nan')}, 'danger_distance: must be finite'),
    ({'num_samples': 2}, 'num_samples'),
    ({'num_samples': 16.5}, 'num_samples: expected an integer'),
    ({'method': 'magic'}, "method: 'magic' is not one of"),
    ({'max_linear_velocity': 'fast'}, 'max_linear_velocity: expected a number'),
    ({'use_gpu': True}, 'unknown parameter'),
    ({'critics': ['progres']}, r"unknown critic 'progres' \(did you mean 'progress'\?\)"),
    ({'critics': ['no_such_module:Critic']}, "cannot load 'no_such_module:Critic'"),
    ({'critics': 'progress'}, 'critics: expected a list of strings'),
])
def test_bad_values_name_the_parameter(changes, message):
    with pytest.raises(ConfigError, match=message):
        from_mapping(changes)


def test_replace_validates_and_k_follows_d0():
    cfg = PlannerConfig().replace(danger_distance=0.2)
    assert cfg.k == pytest.approx(25.0)
    with pytest.raises(ConfigError):
        cfg.replace(sample_radius=-1.0)


def test_bad_params_file(tmp_path):
    bad = tmp_path / 'p.yaml'
    bad.write_text('other_node:\n  ros__parameters: {}\n')
    with pytest.raises(ConfigError, match='no "subapf_planner: ros__parameters:"'):
        load_config(bad)
    bad.write_text('subapf_planner:\n  ros__parameters:\n    goal_tolerance: -3\n')
    with pytest.raises(ConfigError, match='goal_tolerance'):
        load_config(bad)


def test_yaml_is_what_the_metadata_writes():
    """config/planner.yaml documents every parameter of both nodes, as the code declares
    them (regenerate: python -m subapf_planner.tools.paramdoc config/planner.yaml)."""
    from subapf_planner.tools.paramdoc import render
    assert PARAMS.read_text() == render()


def test_yaml_lists_every_node_parameter_with_its_default():
    from subapf_planner.ros.planner_node import GROUPS
    from subapf_planner.ros.sim_node import GROUPS as SIM_GROUPS
    doc = yaml.safe_load(PARAMS.read_text())
    for node, groups in (('subapf_planner', GROUPS), ('subapf_sim', SIM_GROUPS)):
        params = doc[node]['ros__parameters']
        fields = [f for g in groups for f in dataclasses.fields(g)]
        assert set(params) == {f.name for f in fields}
        for f in fields:
            default = list(f.default) if isinstance(f.default, tuple) else f.default
            assert params[f.name] == default and type(params[f.name]) is type(default), \
                f.name


def test_robot_files_are_what_the_robot_descriptions_write():
    from subapf_planner.core.robot import ROBOTS
    from subapf_planner.tools.paramdoc import render_robot
    folder = PARAMS.parent / 'robots'
    assert {p.stem for p in folder.glob('*.yaml')} == set(ROBOTS)
    for key in ROBOTS:
        assert (folder / f'{key}.yaml').read_text() == render_robot(key), key
