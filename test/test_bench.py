"""Benchmark: results.json keys and consistency; the paper's qualitative claims."""

import json

import pytest

from subapf_planner.core.config import PlannerConfig
from subapf_planner.sim.episode import run_episode
from subapf_planner.sim.simulator import SimConfig
from subapf_planner.sim.world import load_world
from subapf_planner.tools.bench import DEFAULT_METHODS, given_up, main
from subapf_planner.tools.plots import method_style

pytestmark = pytest.mark.sim

#: The paper's method exactly: Euclidean attraction (eq. 21), samples discarded within d0.
PAPER = PlannerConfig(attraction_field='euclidean')
KEYS = {'world', 'method', 'outcome', 'time_s', 'path_length', 'min_clearance',
        'mean_abs_curvature', 'plan_ms_median', 'plan_ms_p99', 'cycles', 'shortest_path',
        'time_over_limit', 'path_over_shortest', 'final_state'}


def test_short_bench_writes_consistent_results(tmp_path, worlds_dir):
    out = tmp_path / 'out'
    worlds = [str(worlds_dir / 'four_points.yaml'),
              str(worlds_dir / 'fig6c_circle_in_front.yaml')]
    rc = main(worlds + ['--methods', 'subharmonic_sampling,dwa:euclidean', '--out', str(out)])
    assert rc == 0
    doc = json.loads((out / 'results.json').read_text())
    runs = doc['runs']
    assert len(runs) == 4
    # the attraction field is part of each method's name (the params file's by default)
    assert doc['methods'] == ['subharmonic_sampling:geodesic', 'dwa:euclidean']
    for r in runs:
        assert KEYS <= set(r)
        # both planners pass both open worlds (docs/results.md, the shipped worlds), without
        # touching anything, and the run's record agrees with itself
        assert r['outcome'] == 'reached', r
        assert r['final_state'] == 'reached: goal within tolerance'
        assert r['final_distance'] <= r['goal_tolerance']
        straight = 5.0 if r['world'] == 'four_points' else 4.0
        assert r['path_length'] >= straight - r['goal_tolerance'] - 0.05
        assert r['min_clearance'] > 0.1
        # one cycle per scan delivered: one per sweep but the lidar's lost scans (1 %)
        sweeps = r['time_s'] / PAPER.period
        assert 0.95 * sweeps - 1 <= r['cycles'] <= sweeps + 1
        assert r['cycles'] >= 1 and r['plan_ms_p99'] >= r['plan_ms_median'] > 0
        # no faster than the shortest path at top speed (the grid's geodesic is up to
        # 8 % long), and that path no longer than the straight line plus a detour
        assert straight - 0.05 <= r['shortest_path'] <= 1.3 * straight
        assert r['time_over_limit'] >= 0.9 and r['path_over_shortest'] >= 0.9
    assert (out / 'summary.md').read_text().startswith('| method |')
    assert (out / 'four_points.png').stat().st_size > 10_000


def test_the_summary_lists_the_runs_given_up_with_why():
    runs = [{'world': 'a', 'method': 'm', 'outcome': 'reached', 'final_state': 'reached: x'},
            {'world': 'b', 'method': 'm', 'outcome': 'unreachable',
             'final_state': 'unreachable: no way to the goal for 30 s (the walls in the '
                            'memory close every way), goal abandoned'}]
    table = given_up(runs)
    assert '| b | m | unreachable | unreachable: no way to the goal for 30 s (the walls' in table
    assert '| a |' not in table and given_up(runs[:1]) == ''


def test_bench_rejects_unknown_method_and_bad_world(tmp_path, capsys):
    assert main(['--methods', 'magic', '--out', str(tmp_path)]) == 2
    assert 'unknown method' in capsys.readouterr().err
    assert main(['--methods', 'dwa:straight', '--out', str(tmp_path)]) == 2
    assert 'unknown method' in capsys.readouterr().err
    bad = tmp_path / 'bad.yaml'
    bad.write_text('name: x\n')
    assert main([str(bad), '--out', str(tmp_path)]) == 2
    assert 'start: missing' in capsys.readouterr().err


# The paper's Fig. 6 claims, asserted where they hold with one parameter set
# (config/planner.yaml defaults) on the shipped worlds. See docs/results.md.
@pytest.mark.parametrize('name', ['fig6c_circle_in_front', 'fig6d_big_wall'])
def test_only_sampling_passes_the_local_minima(worlds_dir, name):
    world = load_world(worlds_dir / f'{name}.yaml')
    quiet = SimConfig(sensor='ideal')   # with noise, 6c's symmetric minimum breaks by luck
    outcomes = {m: run_episode(world, PAPER.replace(method=m), quiet).outcome
                for m in ('subharmonic_sampling', 'subharmonic', 'traditional', 'harmonic')}
    assert outcomes['subharmonic_sampling'] == 'reached'
    assert all(outcomes[m] != 'reached' for m in ('subharmonic', 'traditional', 'harmonic'))


def test_full_method_passes_narrow_and_tight_worlds_without_collision(worlds_dir):
    for name in ('fig6a_narrow_obstacles', 'fig6b_tight_space', 'fig3_narrowing_passage'):
        world = load_world(worlds_dir / f'{name}.yaml')
        assert run_episode(world, PAPER).outcome == 'reached', name


def test_every_default_method_is_drawn_its_own_way():
    """Plots tell the methods apart: colour by method, line style by attraction field."""
    styles = [method_style(m) for m in DEFAULT_METHODS]
    assert len({(color, style) for color, style, _ in styles}) == len(DEFAULT_METHODS)
    assert len({text for _, _, text in styles}) == len(DEFAULT_METHODS)
    assert method_style('subharmonic_sampling:geodesic')[1] == '-'
    assert method_style('subharmonic_sampling:euclidean')[1] == '--'


#: What results.json may differ in between two runs of the same bench: wall-clock times
#: and how it was produced (``meta``: the command line, the date).
TIMING = {'wall_time_s', 'plan_ms_median', 'plan_ms_p99', 'meta'}


def without_timing(doc: dict) -> dict:
    return {k: ([{f: v for f, v in r.items() if f not in TIMING} for r in doc['runs']]
                if k == 'runs' else v) for k, v in doc.items() if k not in TIMING}


def test_a_bench_on_a_dask_cluster_gives_the_results_of_local_jobs(tmp_path, worlds_dir):
    """--cluster (a local 2-worker Dask cluster here; a scheduler on another machine is
    the same) writes the results.json of --jobs 2, field for field but the timings,
    and draws the plots here."""
    from distributed import LocalCluster
    worlds = [str(worlds_dir / name) for name in ('four_points.yaml',
                                                   'fig6c_circle_in_front.yaml',
                                                   'fig6d_big_wall.yaml')]
    methods = ['--methods', 'subharmonic_sampling,subharmonic_sampling:euclidean,'
               'dwa:euclidean', '--seed', '3', '--odom-scale', '1.01']
    assert main(worlds + methods + ['--jobs', '2', '--no-plots',
                                    '--out', str(tmp_path / 'jobs')]) == 0
    with LocalCluster(n_workers=2, threads_per_worker=1, processes=True,
                      dashboard_address=None) as cluster:
        assert main(worlds + methods + ['--cluster', cluster.scheduler_address,
                                        '--out', str(tmp_path / 'cluster')]) == 0
    jobs, on_cluster = (json.loads((tmp_path / d / 'results.json').read_text())
                        for d in ('jobs', 'cluster'))
    assert len(jobs['runs']) == 9
    assert without_timing(on_cluster) == without_timing(jobs)
    assert (tmp_path / 'cluster' / 'fig6d_big_wall.png').stat().st_size > 10_000


def test_a_cluster_that_is_not_there_is_a_clear_error(tmp_path, capsys, worlds_dir,
                                                      monkeypatch):
    import subapf_planner.tools.bench as bench
    monkeypatch.setattr(bench, 'CLUSTER_CONNECT_TIMEOUT', 2.0)
    rc = main([str(worlds_dir / 'four_points.yaml'), '--cluster', 'tcp://127.0.0.1:9',
               '--out', str(tmp_path / 'x'), '--no-plots'])
    assert rc == 2 and 'cluster tcp://127.0.0.1:9' in capsys.readouterr().err


def test_nodeperf_times_the_nodes_loop_in_process():
    """subapf-nodeperf's in-process figure: the decision loop on the node's inputs, a
    cycle timed back to back and after an idle period (a figure, not a target)."""
    from subapf_planner.tools.nodeperf import loop_cycle_ms
    warm, idle = loop_cycle_ms(cycles=3), loop_cycle_ms(cycles=3, idle=0.01)
    assert 0.0 < warm < 1e3 and 0.0 < idle < 1e3
