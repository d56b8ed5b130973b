"""Procedural worlds (sim/worldgen.py, sim/solvability.py) and ``subapf-worlds``
(tools/worlds.py)."""

import math
import re

import pytest
import yaml

from subapf_planner.core.config import PlannerConfig
from subapf_planner.sim import solvability, worldgen
from subapf_planner.sim.episode import run_episode
from subapf_planner.sim.world import Box, load_world, parse_world, world_files
from subapf_planner.tools.worlds import main

pytestmark = pytest.mark.sim

SEEDS = (0, 1, 2)


def walled(gap):
    """A 4 x 3 m room cut by a wall at x = 2 with a ``gap`` m opening (none if 0)."""
    obstacles = [{'box': {'center': [2.0, (3.0 - gap) / 4], 'size': [0.1, (3.0 - gap) / 2]}},
                 {'box': {'center': [2.0, 3.0 - (3.0 - gap) / 4],
                          'size': [0.1, (3.0 - gap) / 2]}}]
    return {'name': 'walled', 'start': [0.5, 1.5, 0.0], 'goal': [3.5, 1.5],
            'bounds': [0.0, 0.0, 4.0, 3.0], 'obstacles': obstacles}


def box_gap(a, b):
    """Distance between the surfaces of two axis-aligned boxes [m]."""
    dx = abs(a.center[0] - b.center[0]) - (a.size[0] + b.size[0]) / 2
    dy = abs(a.center[1] - b.center[1]) - (a.size[1] + b.size[1]) / 2
    return math.hypot(max(dx, 0.0), max(dy, 0.0))


def test_same_seed_same_docs_other_seed_other_docs():
    n = len(worldgen.FAMILIES)
    first = worldgen.suite(n, 11)
    assert worldgen.suite(n, 11) == first
    other = worldgen.suite(n, 12)
    assert all(a != b for a, b in zip(first, other, strict=True))
    assert worldgen.generate('maze', 5) == worldgen.generate('maze', 5)
    assert worldgen.generate('maze', 5) != worldgen.generate('maze', 6)


def test_suite_round_robin_names_and_sub_seeds():
    docs = worldgen.suite(10, 3, ('doorway', 'u_trap', 'forest'))
    assert [d['name'] for d in docs] == [
        'doorway_000', 'u_trap_000', 'forest_000', 'doorway_001', 'u_trap_001', 'forest_001',
        'doorway_002', 'u_trap_002', 'forest_002', 'doorway_003']
    # a world depends on (seed, family, index) only, not on the other families asked for
    assert worldgen.suite(1, 3, ('forest',))[0]['obstacles'] == docs[2]['obstacles']
    with pytest.raises(ValueError, match='unknown world family'):
        worldgen.suite(3, 0, ('barn', 'castle'))
    with pytest.raises(ValueError, match='at least 1'):
        worldgen.suite(0, 0)


@pytest.mark.parametrize('family', worldgen.FAMILIES + worldgen.BUILDING_FAMILIES)
def test_every_family_parses_and_is_solvable(family):
    for seed in SEEDS:
        g = worldgen.generate_world(family, seed, f'{family}_{seed:03d}')
        world = parse_world(g.doc)
        assert re.fullmatch(rf'{family}_\d{{3}}', world.name)
        assert world.bounds is not None and world.goal_tolerance == 0.15
        assert world.start[:2] == (0.0, 0.0)
        for x, y in (world.start[:2], world.goal):
            assert world.clearance(x, y) >= worldgen.ENDPOINT_CLEARANCE
        assert solvability.is_solvable(world)
        length = solvability.geodesic_length(world)
        assert length == pytest.approx(g.geodesic_length)
        assert length >= math.dist(world.start[:2], world.goal) - 0.1
        assert world.time_limit == math.ceil(60 + 4 * length / 0.22)
        assert 1 <= len(world.obstacles) <= 150
        # written and read back unchanged
        assert yaml.safe_load(yaml.safe_dump(g.doc)) == g.doc


def test_solvability_check_rejects_closed_and_too_narrow_walls():
    closed = walled(0.0)
    closed['obstacles'] = [{'box': {'center': [2.0, 1.5], 'size': [0.1, 3.0]}}]
    assert not solvability.is_solvable(closed)
    assert solvability.geodesic_length(closed) == math.inf
    assert not solvability.is_solvable(walled(0.28))       # < 2 x 0.155 m
    assert solvability.is_solvable(walled(0.45))
    assert solvability.geodesic_length(walled(0.45)) == pytest.approx(3.0, abs=0.1)
    assert solvability.bottleneck_width(walled(0.45)) == pytest.approx(0.45, abs=0.03)
    # the robot itself (0.105 m) would pass 0.28 m: the check keeps the margin
    assert solvability.is_solvable(walled(0.28), radius=0.105)


def test_doorway_width_from_geometry():
    for seed in range(8):
        world = parse_world(worldgen.generate('doorway', seed))
        a, b = world.obstacles
        assert isinstance(a, Box) and isinstance(b, Box) and a.yaw == b.yaw == 0.0
        width = box_gap(a, b)
        assert 0.35 - 1e-6 <= width <= 0.8 + 1e-6
        assert solvability.bottleneck_width(world) == pytest.approx(width, abs=0.03)


def test_zigzag_corridor_width_from_geometry():
    for seed in range(6):
        world = parse_world(worldgen.generate('zigzag', seed))
        width = solvability.bottleneck_width(world)   # one width per world
        assert 0.5 - 0.03 <= width <= 1.0 + 1e-6
        # walls close the corridor: no straight way and a longer geodesic
        assert solvability.geodesic_length(world) > math.dist(world.start[:2], world.goal) + 0.5


def test_building_goes_from_room_to_room_through_doors():
    """Start and goal in different rooms: every way passes a door (0.6-0.9 m; furniture
    may narrow it further, never below the solvability margin) and is a walk of metres."""
    for seed in range(6):
        world = parse_world(worldgen.generate('building', seed))
        assert 0.31 - 0.03 <= solvability.bottleneck_width(world) <= 0.9 + 0.03
        assert solvability.geodesic_length(world) >= 5.0
        assert len(world.obstacles) >= 10


@pytest.mark.parametrize('family', ['u_trap', 'c_trap'])
def test_traps_block_the_straight_line(family):
    for seed in SEEDS:
        world = parse_world(worldgen.generate(family, seed))
        (x0, y0), (x1, y1) = world.start[:2], world.goal
        assert min(world.clearance(x0 + (x1 - x0) * s / 200, y0 + (y1 - y0) * s / 200)
                   for s in range(201)) < 0.0


def test_command_writes_loadable_files(tmp_path, capsys):
    out = tmp_path / 'suite'
    assert main(['--out', str(out), '--count', '10', '--seed', '4']) == 0
    files = world_files([out])
    assert len(files) == 10
    docs = {d['name']: d for d in worldgen.suite(10, 4)}
    for f in files:
        world = load_world(f)
        assert f.stem == world.name
        assert yaml.safe_load(f.read_text()) == docs[world.name]
    text = capsys.readouterr().out
    for family in worldgen.FAMILIES:
        assert re.search(rf'^{family} +\d+ worlds, +[\d.]+ obstacles, +[\d.]+ moving, '
                         'geodesic', text, re.M)
    assert main(['--out', str(tmp_path / 'two'), '--count', '3', '--families',
                 'maze,doorway']) == 0
    assert sorted(p.stem for p in (tmp_path / 'two').glob('*.yaml')) == [
        'doorway_000', 'maze_000', 'maze_001']


@pytest.mark.parametrize('args, message', [
    (['--families', 'barn,castle'], 'unknown world family'),
    (['--families', ','], 'unknown world family'),
    (['--count', '0'], '--count must be at least 1'),
    (['--count', 'many'], 'invalid int value'),
    (['--seed', '-1'], '--seed must be non-negative'),
])
def test_command_rejects_bad_arguments(tmp_path, capsys, args, message):
    assert main(['--out', str(tmp_path / 'x')] + args) == 2
    assert message in capsys.readouterr().err
    assert not list(tmp_path.glob('x/*.yaml'))


def test_command_needs_out(capsys):
    assert main([]) == 2
    assert '--out' in capsys.readouterr().err


def test_doorway_episode_has_no_collision():
    world = parse_world(worldgen.generate('doorway', 0))
    result = run_episode(world, PlannerConfig(), time_limit=min(world.time_limit, 90.0))
    assert str(result.outcome) != 'collision'
