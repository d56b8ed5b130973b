"""Moving obstacles: the world format, interpolation and loops, the simulator's moving
bodies and collision judgement (hit while stopped), clearance at each instant, the
dynamic world families, plots and animations."""

import math

import numpy as np
import pytest

from subapf_planner.core.config import PlannerConfig
from subapf_planner.sim.episode import run_episode
from subapf_planner.sim.faults import ScanFaults
from subapf_planner.sim.metrics import min_clearance
from subapf_planner.sim.simulator import RobotSim, SimConfig
from subapf_planner.sim.world import FOOTPRINT_RADIUS, WorldError, parse_world
from subapf_planner.sim.worldgen import DYNAMIC_FAMILIES, START_MARGIN, generate_world
from subapf_planner.tools.animation import animate_run
from subapf_planner.tools.plots import plot_trajectories

pytestmark = pytest.mark.sim


def doc(*moving, start=(0.0, 0.0, 0.0), goal=(4.0, 0.0), **extra):
    return {'name': 'm', 'start': list(start), 'goal': list(goal), 'moving': list(moving),
            **extra}


WALKER = {'circle': {'radius': 0.3}, 'path': [[0, 2.0, -2.0], [4, 2.0, 2.0]]}


@pytest.mark.parametrize('entry, where, what', [
    ({'path': [[0, 1, 1]]}, 'moving[0]', 'exactly one of circle or box'),
    ({'circle': {'radius': 0.3}, 'box': {'size': [1, 1]}, 'path': [[0, 1, 1]]}, 'moving[0]',
     'exactly one'),
    ({'circle': {'radius': -1}, 'path': [[0, 1, 1]]}, 'moving[0].circle.radius', 'positive'),
    ({'circle': {'radius': 0.3, 'center': [0, 0]}, 'path': [[0, 1, 1]]}, 'moving[0].circle',
     'unknown key'),
    ({'box': {'size': [0, 1]}, 'path': [[0, 1, 1]]}, 'moving[0].box.size', 'positive'),
    ({'circle': {'radius': 0.3}}, 'moving[0].path', 'keyframes'),
    ({'circle': {'radius': 0.3}, 'path': [[1, 1, 1]]}, 'moving[0].path[0]', 'must be 0'),
    ({'circle': {'radius': 0.3}, 'path': [[0, 1, 1], [0, 2, 2]]}, 'moving[0].path[1]',
     'strictly increase'),
    ({'circle': {'radius': 0.3}, 'path': [[0, 1, 1], [1, 2]]}, 'moving[0].path[1]',
     '3 numbers'),
    ({'circle': {'radius': 0.3}, 'path': [[0, 1, 1], [1, 2, math.nan]]}, 'moving[0].path[1]',
     'finite'),
    ({'circle': {'radius': 0.3}, 'path': [[0, 1, 1]], 'loop': 'yes'}, 'moving[0].loop',
     'true or false'),
    ({'circle': {'radius': 0.3}, 'path': [[0, 1, 1]], 'offset': 'x'}, 'moving[0].offset',
     'finite'),
    ({'circle': {'radius': 0.3}, 'path': [[0, 1, 1]], 'speed': 1}, 'moving[0]', 'unknown'),
    ({'circle': {'radius': 0.5}, 'path': [[0, 0.2, 0.0], [5, 3, 3]]}, 'start', 'at t = 0'),
])
def test_bad_moving_entries_name_the_field(entry, where, what):
    with pytest.raises(WorldError) as e:
        parse_world(doc(entry), 'w.yaml')
    assert f'w.yaml: {where}:' in str(e.value) and what in str(e.value)


def test_a_walker_may_cross_the_goal_and_a_static_world_stays_valid():
    w = parse_world(doc({'circle': {'radius': 0.3}, 'path': [[0, 4.0, -2.0], [8, 4.0, 2.0]]}))
    assert w.clearance(4.0, 0.0, 4.0) < 0 < w.clearance(4.0, 0.0)
    assert parse_world({'name': 's', 'start': [0, 0, 0], 'goal': [1, 0]}).moving == ()


def test_interpolation_hold_loop_and_offset():
    hold = parse_world(doc(WALKER)).moving[0]
    np.testing.assert_allclose(hold.position([0.0, 1.0, 4.0, 9.0]),
                               [[2, -2], [2, -1], [2, 2], [2, 2]])
    np.testing.assert_allclose(hold.velocity(1.0), [0.0, 1.0])
    assert np.all(hold.velocity(5.0) == 0.0)
    loop = parse_world(doc({**WALKER, 'loop': True, 'offset': 1.0})).moving[0]
    # path time = (t + 1) mod 4: t = 0 -> 1, t = 3 -> 0 (jumped back), t = 5 -> 2
    np.testing.assert_allclose(loop.position([0.0, 3.0, 5.0]), [[2, -1], [2, -2], [2, 0]])
    three = parse_world(doc({'box': {'size': [0.2, 0.4], 'yaw': 0.5},
                             'path': [[0, 3, 3], [2, 5, 3], [6, 5, -1]]})).moving[0]
    np.testing.assert_allclose(three.position(4.0), [5.0, 1.0])
    np.testing.assert_allclose(three.velocity(4.0), [0.0, -1.0])
    placed = three.at(1.0)
    assert placed.center == (4.0, 3.0) and placed.yaw == 0.5


def test_the_laser_sees_a_walker_where_its_path_puts_it():
    w = parse_world(doc({'circle': {'radius': 0.3}, 'path': [[0, 2.0, -3.0], [6, 2.0, 3.0]]},
                        goal=(0.0, 3.0)))
    with RobotSim(w, SimConfig(sensor='ideal')) as sim:
        sim.step(3.0)   # the walker is at (2, 0), straight ahead of the laser
        scan = sim.scan()
    assert scan.ranges[0] == pytest.approx(2.0 - 0.3 + 0.032, abs=0.01)


def run(world_doc, cfg, **kw):
    return run_episode(parse_world(world_doc), cfg, SimConfig(seed=0), **kw)


def test_walker_into_a_standing_robot_is_a_collision_hit_while_stopped():
    """A walker coming at a robot whose goal is where it stands: the robot never moves
    (reached at once), the walker hits it; the collision says it stood still."""
    w = doc({'circle': {'radius': 0.3}, 'path': [[0, 2.0, 0.0], [4, -2.0, 0.0]]},
            goal=(0.05, 0.0), time_limit=10)
    with RobotSim(parse_world(w), SimConfig()) as sim:
        sim.set_command(0.0, 0.0)
        for _ in range(20):
            sim.step(0.2)
        assert sim.collided and sim.hit_while_stopped
    # a moving robot hit from behind is not "stopped"
    w2 = doc({'circle': {'radius': 0.3}, 'path': [[0, -1.5, 0.0], [3, 3.5, 0.0]]},
             goal=(6.0, 0.0))
    with RobotSim(parse_world(w2), SimConfig()) as sim:
        for _ in range(20):
            sim.set_command(0.1, 0.0)
            sim.step(0.2)
        assert sim.collided and not sim.hit_while_stopped


def test_clearance_is_measured_where_the_walker_was_at_each_instant():
    w = parse_world(doc({'circle': {'radius': 0.3}, 'path': [[0, 0.0, 3.0], [10, 0.0, 13.0]]}))
    path = np.array([[0.0, 0.0, 0.0], [0.0, 2.0, 0.0]])
    # at t = 0 the walker is 3 m away, at t = 10 s 11 m from (0, 2)
    assert min_clearance(w, path, np.array([0.0, 10.0])) == pytest.approx(3 - 0.3 - 0.105)
    # had both points been at t = 0, (0, 2) would be 1 m from it
    assert min_clearance(w, path, np.array([0.0, 0.0])) == pytest.approx(1 - 0.3 - 0.105)


#: Walkers for the results record: one crossing the start while the robot, with no
#: scan for its first 5 s (scan_latency), stands there waiting; one running at 4 m/s into
#: the back of the robot driving to its goal; one that crosses ahead and stops aside.
STANDING_HIT = (doc({'circle': {'radius': 0.3}, 'path': [[0, 0.0, 3.0], [4, 0.0, -1.0]]},
                    goal=(3.0, 0.0), time_limit=20), ScanFaults(scan_latency=5.0))
DRIVING_HIT = (doc({'circle': {'radius': 0.3}, 'path': [[0, -8.0, 0.0], [4, 8.0, 0.0]]},
                   goal=(6.0, 0.0), time_limit=20), None)
NO_HIT = (doc({'circle': {'radius': 0.4}, 'path': [[0, 1.5, 2.0], [2, 1.5, 0.0], [60, 1.5, 0.0]]},
              goal=(3.0, 0.0), time_limit=40), None)


@pytest.mark.parametrize('case, outcome, stopped', [
    (STANDING_HIT, 'collision', True), (DRIVING_HIT, 'collision', False),
    (NO_HIT, 'reached', False)], ids=['hit-standing', 'hit-driving', 'no-hit'])
def test_results_record_says_hit_while_stopped(case, outcome, stopped):
    """The record's outcome and hit_while_stopped against the ground truth of the run:
    where the walker was (its path) and how the robot moved (the true poses)."""
    w, faults = case
    world = parse_world(w)
    r = run_episode(world, PlannerConfig(), SimConfig(seed=0), faults=faults)
    rec = r.metrics(world)
    assert (rec['outcome'], rec['hit_while_stopped']) == (outcome, stopped), rec
    assert len(r.times) == len(r.path) and r.times[1] == pytest.approx(0.2)
    # the gap between the footprint and the walker at each recorded instant
    gap = np.array([world.clearance(x, y, t) - FOOTPRINT_RADIUS
                    for (x, y, _), t in zip(r.path, r.times, strict=True)])
    moved = np.hypot(*np.diff(r.path[:, :2], axis=0).T)   # true motion per cycle [m]
    if outcome == 'collision':
        # in contact at the end, clear at every instant before: the first contact ended it
        assert gap[-1] < 0.01 and gap[:-1].min() > 0.05, gap
        if stopped:
            assert moved[:-1].max() < 1e-3, moved   # stood at the start until hit
        else:
            assert moved[-2] > 0.02, moved          # drove into the last cycle
    else:
        assert gap.min() > 0.0 and np.hypot(*(r.path[-1, :2] - world.goal)) \
            <= world.goal_tolerance, (gap.min(), r.path[-1])


@pytest.mark.parametrize('family', DYNAMIC_FAMILIES)
def test_dynamic_families_are_seeded_and_start_clear(family):
    a = generate_world(family, 7)
    assert a.doc == generate_world(family, 7).doc
    w = parse_world(a.doc)
    assert w.moving
    x, y = w.start[:2]
    for t in np.arange(0.0, 3.0, 0.1):
        assert min(o.distance(x, y) for o in w.moving_at(t)) >= 0.105 + START_MARGIN - 1e-9


def test_moving_plot_and_animation(tmp_path, monkeypatch):
    """The PNG shows, where the plot's axes put them: the driven path in its method's
    colour, the goal, and the walker at the MOVING_INSTANTS instants, where its path had
    it then, in the instants' colours (early -> late)."""
    from matplotlib import colors, pyplot
    from PIL import Image

    from subapf_planner.tools.plots import INSTANT_CMAP, METHOD_STYLE, MOVING_INSTANTS
    w = parse_world(doc({**WALKER, 'loop': True}, time_limit=20))
    label = 'subharmonic_sampling:geodesic'
    paths = {label: np.column_stack((np.linspace(0, 3, 30), np.zeros(30), np.zeros(30)))}
    figures = []
    with monkeypatch.context() as m:
        m.setattr(pyplot, 'close', figures.append)   # kept open: its axes place the points
        png = plot_trajectories(w, paths, {label: 'reached'}, tmp_path / 'm.png')
    fig, = figures
    ax = fig.axes[0]
    with Image.open(png) as im:
        rgb = np.asarray(im.convert('RGB'), float)
    pyplot.close(fig)
    scale = rgb.shape[0] / fig.bbox.height   # saved at another dpi than the figure's

    def assert_drawn(x, y, colour, what, alpha=1.0, r=2, tol=30):
        """A pixel within ``r`` of the data point (x, y) has ``colour`` (with ``alpha``
        over the white background)."""
        px, py = ax.transData.transform((x, y)) * scale
        col, row = int(round(px)), int(round(rgb.shape[0] - py))
        want = 255 * (alpha * np.array(colors.to_rgb(colour)) + (1 - alpha))
        patch = rgb[row - r:row + r + 1, col - r:col + r + 1].reshape(-1, 3)
        off = np.abs(patch - want).max(axis=1)
        assert off.min() < tol, f'{what} at ({x}, {y}): {patch[off.argmin()]} != {want}'

    path_colour = METHOD_STYLE['subharmonic_sampling'][0]
    for x in (0.5, 1.5, 2.5):   # between the robot's markers at the instants
        assert_drawn(x, 0.0, path_colour, 'the path')
    assert_drawn(*w.goal, 'black', 'the goal')
    instants = np.linspace(0.0, 29 * 0.2, MOVING_INSTANTS)
    cmap = pyplot.get_cmap(INSTANT_CMAP)
    # (the walker at t = 0, at (2, -2), is under the legend in this plot); a point of
    # each other instant's outline that the other outlines and the path leave free
    for i, (dx, dy) in ((1, (0.1, 0.22)), (2, (0.1, 0.0)), (3, (0.1, -0.25))):
        cx, cy = w.moving[0].position(instants[i])
        assert_drawn(cx + dx, cy + dy, cmap(0.85 * i / (MOVING_INSTANTS - 1)),
                     f'the walker at t = {instants[i]:.1f} s', alpha=0.35)
    gif = animate_run(w, paths, tmp_path / 'm.gif')
    with Image.open(gif) as im:
        assert im.n_frames == len(np.arange(0.0, 29 * 0.2 + 1e-9, 0.5))


def dev_world(family: str, index: int):
    """World ``index`` of ``family`` in the dynamic dev suite (docs/worlds.md: seed 2026)."""
    from subapf_planner.sim.worldgen import generate, sub_seed
    name = f'{family}_{index:03d}'
    return parse_world(generate(family, sub_seed(2026, family, index), name), name)


@pytest.mark.parametrize('family, index', [('crossing', 0), ('crossing', 3), ('head_on', 0)])
def test_default_gets_past_walkers_that_hit_the_planner_without_tracking(family, index):
    """Someone crossing the robot's way, and someone walking at it down a corridor: the
    default reaches the goal without touching anyone; the same planner without tracking
    (the previous default) is hit in both crossings."""
    w = dev_world(family, index)
    r = run_episode(w, PlannerConfig(), SimConfig(seed=0))
    assert r.outcome == 'reached' and r.metrics(w)['min_clearance'] > 0.0, r.statuses
    if family == 'crossing':
        blind = run_episode(w, PlannerConfig(track_moving=False), SimConfig(seed=0))
        assert blind.outcome == 'collision'
