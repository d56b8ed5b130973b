"""subapf-results on tiny synthetic results files: the tables, the provenance line,
the README's headline block, --check; and subapf-bench's record of how it ran."""

import json
import math
from pathlib import Path
import re
import shlex

from conftest import REPO
import pytest

from subapf_planner.tools import results
from subapf_planner.tools.results import BEGIN, END, main

core = pytest.mark.core

SUITES = """\
headline:
  - method: a:geodesic
    title: the default
  - method: b:euclidean
    title: the baseline
suites:
  - name: tiny
    title: 'Tiny suite: five worlds'
    worlds: '`subapf-worlds --out /tmp/tiny --count 5`'
    description: Five worlds.
    bench: subapf-bench /tmp/tiny --out /tmp/t
    notes: A note after the tables.
  - name: empty
    title: Nothing yet
"""

README = f"""# pkg

## Results

{BEGIN}
stale
{END}

## Layout
"""

META = {'command': 'subapf-bench /tmp/tiny --out /tmp/t --odom-scale 1.02',
        'version': '9.9.9', 'commit': 'abc1234-dirty', 'date': '2030-01-02'}


def run(world: str, method: str, outcome: str, time_s: float = 10.0, path: float = 5.0,
        clearance: float = 0.2, stopped: bool = False) -> dict:
    return {'world': world, 'method': method, 'outcome': outcome, 'time_s': time_s,
            'path_length': path, 'min_clearance': clearance, 'hit_while_stopped': stopped}


RUNS = [run('barn_000', 'a:geodesic', 'reached', 10.0, 4.0),
        run('barn_001', 'a:geodesic', 'reached', 20.0, 5.0),
        run('maze_000', 'a:geodesic', 'reached', 30.0, 6.0, 0.05),
        run('maze_001', 'a:geodesic', 'collision', 7.0, 2.0, -0.004, stopped=True),
        run('maze_002', 'a:geodesic', 'missed', 12.0, 4.5),
        run('barn_000', 'b:euclidean', 'abandoned'),
        run('barn_001', 'b:euclidean', 'unreachable'),
        run('maze_000', 'b:euclidean', 'timeout'),
        run('maze_001', 'b:euclidean', 'reached', 40.0, 7.0),
        run('maze_002', 'b:euclidean', 'collision', 3.0, 1.0, -0.01)]


def setup_dir(tmp_path: Path, files: dict[str, object]) -> tuple[Path, Path, Path]:
    data = tmp_path / 'data'
    data.mkdir()
    (data / 'suites.yaml').write_text(SUITES)
    for name, doc in files.items():
        (data / name).write_text(json.dumps(doc))
    readme = tmp_path / 'README.md'
    readme.write_text(README)
    return data, tmp_path / 'results.md', readme


def args(data: Path, out: Path, readme: Path, *extra: str) -> list[str]:
    return ['--data', str(data), '--out', str(out), '--readme', str(readme), *extra]


def bench_doc(runs: list[dict], meta: dict | None = META, **conditions) -> dict:
    doc = {'runs': runs, 'methods': list(dict.fromkeys(r['method'] for r in runs)),
           'seed': 0, 'sensor': 'realistic', 'noise': 0.0, 'odom_distance_scale': 1.0,
           'odom_yaw_scale': 1.0,
           'wall_time_s': 12.3, **conditions}
    if meta is not None:
        doc['meta'] = meta
    return doc


def row(page: str, method: str) -> list[str]:
    line = next(x for x in page.splitlines() if x.startswith(f'| `{method}` |'))
    return [c.strip() for c in line.strip('|').split('|')]


@core
def test_without_results_files_every_suite_says_nothing_is_recorded(tmp_path):
    data, out, readme = setup_dir(tmp_path, {})
    assert main(args(data, out, readme, '--check')) == 1   # nothing written yet
    assert main(args(data, out, readme)) == 0
    page = out.read_text()
    assert page.count('No results are recorded yet for this suite') == 2
    assert '`subapf-worlds --out /tmp/tiny --count 5`' in page
    assert 'Bench: `subapf-bench /tmp/tiny --out /tmp/t`.' in page
    block = readme.read_text().split(BEGIN)[1].split(END)[0]
    assert 'stale' not in block and block.count('not recorded yet') == 2
    assert '](docs/results.md#tiny-suite-five-worlds)' in block
    assert main(args(data, out, readme, '--check')) == 0


@core
def test_a_results_file_gives_a_row_per_method_with_its_provenance(tmp_path, monkeypatch):
    monkeypatch.setattr(results, 'MAX_WORLD_ROWS', 2)   # five worlds: a table per family
    doc = bench_doc(RUNS, odom_distance_scale=1.02)
    data, out, readme = setup_dir(tmp_path, {'tiny.json': doc})
    assert main(args(data, out, readme)) == 0
    page = out.read_text()
    # method | runs | reached | success | collisions | missed | abandoned | unreachable
    # | timeout | median time | p90 time | median path | least clearance
    assert row(page, 'a:geodesic') == ['`a:geodesic`', '5', '3', '60.0 %', '1 (1 stopped)',
                                       '1', '0', '0', '0', '20.0', '28.0', '5.00', '-0.004']
    assert row(page, 'b:euclidean') == ['`b:euclidean`', '5', '1', '20.0 %', '1', '0', '1',
                                        '1', '1', '40.0', '40.0', '7.00', '-0.010']
    line = next(x for x in page.splitlines() if x.startswith('Produced by'))
    for part in (META['command'], 'version 9.9.9', 'commit abc1234-dirty', '2030-01-02',
                 'odometry distance scale 1.02', '10 runs in 12 s wall time',
                 '[tiny.json](results/data/tiny.json)'):
        assert part in line, part
    assert 'noise' not in line and 'sensor' not in line   # the defaults are not repeated
    # two families: reached per family and method
    assert '| barn (2) | 2 | 0 |' in page and '| maze (3) | 1 | 1 |' in page
    assert page.index('A note after the tables.') > page.index('Produced by')
    block = readme.read_text().split(BEGIN)[1].split(END)[0]
    assert '| 3/5, 1 collision | 1/5, 1 collision |' in block
    assert main(args(data, out, readme, '--check')) == 0


@core
def test_a_suite_kept_out_of_the_readme_is_in_the_pages_headline_only(tmp_path):
    data, out, readme = setup_dir(tmp_path, {'tiny.json': bench_doc(RUNS)})
    (data / 'suites.yaml').write_text(SUITES + '    readme: false\n')   # the empty one
    assert main(args(data, out, readme)) == 0
    block = readme.read_text().split(BEGIN)[1].split(END)[0]
    assert 'Tiny suite' in block and 'Nothing yet' not in block
    page_headline = out.read_text().split('## Headline')[1].split('\n## ')[0]
    assert 'Tiny suite' in page_headline and 'Nothing yet' in page_headline


@core
def test_a_small_suite_gets_its_outcome_per_world(tmp_path):
    runs = [run('u_trap', 'a:geodesic', 'reached', 26.6), run('u_trap', 'b:euclidean',
                                                               'abandoned')]
    data, out, readme = setup_dir(tmp_path, {'tiny.json': bench_doc(runs)})
    assert main(args(data, out, readme)) == 0
    assert '| u_trap | reached (27 s) | abandoned |' in out.read_text()


@core
def test_a_bare_list_of_runs_without_meta_is_read(tmp_path):
    data, out, readme = setup_dir(tmp_path, {'tiny.json': RUNS})
    assert main(args(data, out, readme)) == 0
    page = out.read_text()
    assert 'Command, version and commit not recorded' in page
    assert row(page, 'a:geodesic')[2] == '3'


@core
def test_several_runs_of_a_suite_each_get_their_table(tmp_path):
    first = bench_doc([r for r in RUNS if r['method'] == 'a:geodesic'])
    second = bench_doc(RUNS, meta={**META, 'command': 'subapf-bench again'})
    data, out, readme = setup_dir(tmp_path, {'tiny.a.json': first, 'tiny.b.json': second})
    assert main(args(data, out, readme)) == 0
    page = out.read_text()
    assert '### tiny.a.json' in page and '### tiny.b.json' in page
    assert page.count('Produced by') == 2 and 'subapf-bench again' in page


@core
def test_check_fails_on_a_hand_edit_of_either_file(tmp_path):
    data, out, readme = setup_dir(tmp_path, {'tiny.json': bench_doc(RUNS)})
    assert main(args(data, out, readme)) == 0
    assert main(args(data, out, readme, '--check')) == 0
    written = out.read_text()
    out.write_text(written.replace('60.0 %', '80.0 %'))
    assert main(args(data, out, readme, '--check')) == 1
    out.write_text(written)
    text = readme.read_text()
    readme.write_text(text.replace('3/5', '5/5'))
    assert main(args(data, out, readme, '--check')) == 1
    assert main(args(data, out, readme)) == 0
    assert readme.read_text() == text   # the text outside the markers is kept


@core
def test_bad_inputs_are_clear_errors(tmp_path, capsys):
    data, out, readme = setup_dir(tmp_path, {'other.json': bench_doc(RUNS)})
    assert main(args(data, out, readme)) == 2
    assert 'no suite in suites.yaml for other.json' in capsys.readouterr().err
    (data / 'other.json').unlink()
    readme.write_text('# no markers\n')
    assert main(args(data, out, readme)) == 2
    assert 'results:headline' in capsys.readouterr().err
    (data / 'tiny.json').write_text('{"no": "runs"}')
    assert main(args(data, out, readme)) == 2
    assert 'not a results.json' in capsys.readouterr().err


@core
def test_slugs_are_githubs():
    assert results.slug("The paper's ablation (Fig. 6) on the shipped worlds") == \
        'the-papers-ablation-fig-6-on-the-shipped-worlds'
    assert results.family_of('arena_007') == 'arena' and results.family_of('u_trap') == 'u_trap'


@pytest.mark.sim
def test_bench_records_how_its_results_were_produced():
    """results.json's meta: the command as typed, the version, the commit of this
    checkout (with -dirty when it has changes), the date."""
    from test_docs import setup_version

    from subapf_planner.tools.bench import provenance
    meta = provenance(['/tmp/my worlds', '--out', 'x', '--jobs', '2'])
    assert meta['command'] == 'subapf-bench ' + shlex.join(['/tmp/my worlds', '--out', 'x',
                                                            '--jobs', '2'])
    assert meta['command'] == "subapf-bench '/tmp/my worlds' --out x --jobs 2"
    assert re.fullmatch(r'\d{4}-\d{2}-\d{2}', meta['date'])
    if (REPO / '.git').exists():
        assert re.fullmatch(r'[0-9a-f]{7,40}(-dirty)?', meta['commit'])
        assert meta['version'] == setup_version()


@core
def test_the_pose_error_and_the_ghosts_are_reported_where_recorded():
    """The perception table: per method that records a pose error, its median, p95 and
    share within 0.10 m at arrival, and the evading cycles of runs in worlds where
    nothing moves (a moving world's evading is not counted); nothing for a method that
    plans in odom (pose error 0) or for files from before the bench recorded it."""
    seen = [dict(r, pose_error_final=e, cycles=100, evading_cycles=k, moving_world=mv)
            for r, e, k, mv in zip(RUNS[:5], (0.02, 0.04, 0.06, 0.2, 0.08),
                                   (0, 3, 0, 50, 1), (False, False, False, True, False),
                                   strict=True)]
    blind = [dict(r, pose_error_final=0.0, cycles=100, evading_cycles=0, moving_world=False)
             for r in RUNS[5:]]
    rs = results.load_runset_doc(bench_doc(seen + blind), 'x.json')
    table = results.perception_table(rs)
    rows = [x for x in table.splitlines() if x.startswith('| `')]
    assert len(rows) == 1 and rows[0].startswith('| `a:geodesic` | 0.060 | ')
    assert '| 80 % |' in rows[0] and '1.00 % (most 3)' in rows[0]   # 4 of 5; 4 in 400
    plain = results.load_runset_doc(bench_doc(RUNS), 'y.json')
    assert results.perception_table(plain) == ''


@core
def test_time_and_path_against_the_shortest_are_reported_where_recorded():
    """The speed table: per method, over its runs that reached, the time over the
    physical limit and the path over the shortest path (median, p90), and over its runs
    with a shortest path the BARN score's mean; nothing for files from before the bench
    recorded them."""
    timed = [dict(r, time_over_limit=t, path_over_shortest=p, shortest_path=5.0)
             for r, t, p in zip(RUNS[:3], (1.0, 1.2, 4.0), (1.0, 1.1, 1.5), strict=True)]
    failed = [dict(r, shortest_path=5.0) for r in RUNS[3:5]]   # collision, missed: 0
    rs = results.load_runset_doc(bench_doc(timed + failed + RUNS[5:]), 'x.json')
    cells = row(results.speed_table(rs), 'a:geodesic')
    # p90 interpolated; BARN score (0.5 + 0.5 + 1 / 4 + 0 + 0) / 5
    assert cells[1:] == ['3', '1.20', '3.44', '1.10', '1.42', '0.250']
    assert results.speed_table(results.load_runset_doc(bench_doc(RUNS), 'y.json')) == ''


@core
def test_the_shortest_path_comes_from_the_suites_index_or_the_geodesic(tmp_path):
    """bench.shortest_path: a world with an entry in the index.json beside it (the
    real-building tasks') takes its smoothed length; one without, the geodesic of
    sim/solvability.py (round a wall: longer than the straight line); efficiency()
    divides by it, for reached runs only."""
    from subapf_planner.sim.world import load_world
    from subapf_planner.tools.bench import efficiency, shortest_path
    text = ('name: {}\nstart: [0.0, 0.0, 0.0]\ngoal: [4.0, 0.0]\nbounds: [-2, -3, 6, 3]\n'
            'obstacles:\n- box: {{center: [2.0, 0.0], size: [0.2, 3.0]}}\n')
    for name in ('listed', 'unlisted'):
        (tmp_path / f'{name}.yaml').write_text(text.format(name))
    (tmp_path / 'index.json').write_text(json.dumps(
        {'hall': {'source': 'x', 'worlds': {'listed': {'smoothed': 7.25}}}}))
    assert shortest_path(load_world(tmp_path / 'listed.yaml')) == 7.25
    round_wall = shortest_path(load_world(tmp_path / 'unlisted.yaml'))
    assert 5.0 < round_wall < 7.0          # 4 m straight, the wall is 3 m tall
    record = {'outcome': 'reached', 'time_s': 40.0, 'path_length': 8.0}
    e = efficiency(record, 7.25, 0.22)
    assert e['shortest_path'] == 7.25
    assert e['time_over_limit'] == pytest.approx(40.0 * 0.22 / 7.25, abs=1e-3)
    assert e['path_over_shortest'] == pytest.approx(8.0 / 7.25, abs=1e-3)
    missed = efficiency(dict(record, outcome='missed'), 7.25, 0.22)
    assert missed['time_over_limit'] is None and missed['path_over_shortest'] is None
    assert efficiency(record, math.inf, 0.22)['shortest_path'] is None
    assert e['barn_score'] == pytest.approx(0.5) and missed['barn_score'] == 0.0


@core
def test_the_barn_score_is_the_challenges():
    """tools/metrics.barn_score: success x optimal time / clip(actual, 2 x optimal,
    8 x optimal), as the BARN Challenge's run.py computes it (optimal: the path at the
    robot's top speed). A 10 m path at 2 m/s: optimal 5 s."""
    from subapf_planner.tools.metrics import barn_score

    def score(actual, success=True):
        optimal = 10.0 / 2.0
        return barn_score(success, actual / optimal)
    assert score(8.0) == pytest.approx(5.0 / 10.0)      # faster than 2x optimal: 0.5
    assert score(20.0) == pytest.approx(5.0 / 20.0)
    assert score(50.0) == pytest.approx(5.0 / 40.0)     # slower than 8x optimal: 1/8
    assert score(20.0, success=False) == 0.0
    assert barn_score(True, None) == 0.0
