"""``subapf-results``: docs/results.md and the README's headline table, written from
the benchmark's results files.

``subapf-results [--data docs/results/data] [--out docs/results.md] [--readme README.md]
[--check]``, run in the repository's root. The data directory holds ``suites.yaml``
(the suites in the order the page shows them: name, title, worlds, description, notes;
and the headline's methods) and, per suite, the ``results.json`` of its bench runs,
copied as ``<name>.json`` or, for several runs of one suite, ``<name>.<part>.json``.
Per results file the page gets a table with a row per method, with the command, the
version and the commit that produced it (results.json's ``meta``, written by
``subapf-bench``) under it; a suite without a file says that nothing is recorded yet.
The headline table (one row per suite, a column per headline method) goes into
results.md and between the README's ``<!-- results:headline -->`` and
``<!-- /results:headline -->`` markers. ``--check`` writes nothing and exits 1 when
either file differs from what it would write (a hand edit, or data not yet rendered).
"""

from __future__ import annotations

import argparse
from dataclasses import dataclass, field
import json
from pathlib import Path
import statistics
import sys

import numpy as np
import yaml

from .metrics import barn_score

PROG = 'subapf-results'
DATA = Path('docs/results/data')
OUT = Path('docs/results.md')
README = Path('README.md')
SUITES_FILE = 'suites.yaml'
BEGIN = '<!-- results:headline -->'
END = '<!-- /results:headline -->'
#: Outcomes counted in a column of their own (collisions have theirs, reached too).
FAILURES = ('missed', 'abandoned', 'unreachable', 'timeout')
#: A suite's per-world outcome table is drawn up to this many worlds.
MAX_WORLD_ROWS = 12
#: The headline's methods when suites.yaml names none: (results.json label, column title).
DEFAULT_HEADLINE = (('subharmonic_sampling:geodesic', 'the default'),
                    ('subharmonic_sampling:euclidean', "the paper's method"),
                    ('dwa:euclidean', 'DWA'))
#: results.json's simulator settings and their defaults (printed when not the default).
CONDITIONS = (('seed', 0, 'simulator seed {}'), ('sensor', 'realistic', 'the {} sensor'),
              ('noise', 0.0, 'extra laser noise {} m'),
              ('beam_dropout', 0.0, 'beams dropped {}'),
              ('scan_dropout', 0.0, 'scans lost {}'),
              ('scan_latency', 0.0, 'scans {} s late'),
              ('odom_distance_scale', 1.0, 'odometry distance scale {}'),
              ('odom_yaw_scale', 1.0, 'odometry turn scale {}'))

HEADER = """# Results

<!-- Written by `subapf-results` from docs/results/data/: edit those files (or the
tool), not this page; `subapf-results --check` fails when the two disagree. -->

Benchmark results of the package, one section per suite of worlds. Every run steps
the simulator and the node's decision loop in one process on simulated time
(`subapf-bench`, [sim/episode.py](../subapf_planner/sim/episode.py)) through the
realistic lidar (the LDS-01's datasheet noise, dropped beams, mixed pixels, sweeps
over 0.2 s, latency and lost scans: [worlds.md](worlds.md#simulator)), simulator seed
0, unless a table says otherwise. Each table names the command that produced it, the
package version and the git commit (`-dirty`: with changes not committed), and the
date.

Methods carry their attraction: `subharmonic_sampling:geodesic` is the package's
default (memory and navigation field, [design](design.md)),
`subharmonic_sampling:euclidean` the paper's method exactly (eq. 21),
`subharmonic`, `traditional` and `harmonic` the paper's ablations without circular
sampling, `dwa:euclidean` the Dynamic Window baseline and `dwa:geodesic` DWA on the
default's memory and field.

Outcomes: *reached* (the planner stopped at the goal by its own estimate and the
truth is inside the world's tolerance), *collision*, *missed* (stopped at the goal
by its estimate, outside the tolerance in truth), *abandoned* (the progress checker
gave the goal up after its recoveries), *unreachable* (no way through the memory
for `unreachable_timeout`), *timeout* (the world's time limit). Columns: success is
reached / runs; times and path lengths are over the reached runs (p90: 90th
percentile); least clearance is the smallest gap between the robot's footprint and an
obstacle's surface over all runs (negative: a collision); "stopped" counts collisions
with the robot commanded to stand still. Time over the physical limit: a run's time
over its world's shortest path at the robot's top speed; path over the shortest: its
path length over that path (both over the reached runs; the shortest path is the
smoothed one of the suite's `index.json` where there is one, as for the real-building
tasks, else the 5 cm grid's geodesic for a disc of the burger's footprint plus margin,
up to 8 % longer than the true one).

To add or refresh a suite: run the bench, copy its `results.json` to
`docs/results/data/<suite>.json` (name and text in `suites.yaml` there), then
`subapf-results`, in the repository's root, rewrites this page and the README's
headline table.
"""


@dataclass
class RunSet:
    """One results file: its runs and how they were produced."""

    name: str
    runs: list[dict]
    methods: list[str]
    meta: dict = field(default_factory=dict)
    conditions: dict = field(default_factory=dict)
    wall_time_s: float | None = None


@dataclass
class Suite:
    name: str
    title: str
    worlds: str = ''
    description: str = ''
    bench: str = ''
    notes: str = ''
    runsets: list[RunSet] = field(default_factory=list)
    #: Whether the README's headline shows it (results.md's shows every suite).
    readme: bool = True


def load_runset(path: Path) -> RunSet:
    """A bench's results.json: the object ``subapf-bench`` writes (``meta``, ``runs``,
    ``methods``, the simulator settings), or a bare list of run records."""
    return load_runset_doc(json.loads(path.read_text()), path)


def load_runset_doc(doc: object, path: Path | str) -> RunSet:
    """load_runset of a results file's parsed ``doc`` (``path``: its name)."""
    path = Path(path)
    if isinstance(doc, list):
        doc = {'runs': doc}
    if not isinstance(doc, dict) or not isinstance(doc.get('runs'), list):
        raise ValueError(f'{path}: not a results.json (no list of runs)')
    runs = doc['runs']
    methods = doc.get('methods') or list(dict.fromkeys(r['method'] for r in runs))
    return RunSet(name=path.name, runs=runs, methods=list(methods),
                  meta=doc.get('meta') or {},
                  # a bench's file from before the sensor was recorded: the ideal one
                  conditions={k: doc[k] for k, _, _ in CONDITIONS if k in doc}
                  | ({'sensor': doc.get('sensor', 'ideal')} if 'noise' in doc else {}),
                  wall_time_s=doc.get('wall_time_s'))


def load(data: Path) -> tuple[list[Suite], list[tuple[str, str]]]:
    """The suites of ``data/suites.yaml`` with their results files, and the headline's
    (method, column title) pairs. A results file no suite names is an error."""
    spec = yaml.safe_load((data / SUITES_FILE).read_text()) or {}
    suites = []
    for entry in spec.get('suites') or []:
        suite = Suite(**{k: str(entry.get(k) or '').strip()
                         for k in ('name', 'title', 'worlds', 'description', 'bench',
                                   'notes')})
        suite.readme = entry.get('readme', True) is not False
        if not suite.name or not suite.title:
            raise ValueError(f'{data / SUITES_FILE}: every suite needs a name and a title')
        files = sorted({*data.glob(f'{suite.name}.json'), *data.glob(f'{suite.name}.*.json')})
        suite.runsets = [load_runset(f) for f in files]
        suites.append(suite)
    known = {rs.name for s in suites for rs in s.runsets}
    stray = sorted(p.name for p in data.glob('*.json') if p.name not in known)
    if stray:
        raise ValueError(f'{data}: no suite in {SUITES_FILE} for {", ".join(stray)}')
    headline = [(h['method'], h.get('title', h['method'])) for h in spec.get('headline') or []]
    return suites, headline or list(DEFAULT_HEADLINE)


def family_of(world: str) -> str:
    """A generated world's family: its name without the index (``arena_007`` -> arena)."""
    head, _, tail = world.rpartition('_')
    return head if head and tail.isdigit() else world


def _num(value: float | None, digits: int) -> str:
    return '-' if value is None else f'{value:.{digits}f}'


def _median(values: list[float]) -> float | None:
    return statistics.median(values) if values else None


def _p90(values: list[float]) -> float | None:
    return float(np.percentile(values, 90)) if values else None


def method_row(method: str, runs: list[dict]) -> str:
    """One method's row of a suite's table."""
    ok = [r for r in runs if r['outcome'] == 'reached']
    hits = [r for r in runs if r['outcome'] == 'collision']
    stopped = sum(bool(r.get('hit_while_stopped')) for r in hits)
    times = [r['time_s'] for r in ok]
    cells = [f'`{method}`', str(len(runs)), str(len(ok)),
             f'{100.0 * len(ok) / len(runs):.1f} %',
             f'{len(hits)} ({stopped} stopped)' if stopped else str(len(hits)),
             *(str(sum(r['outcome'] == o for r in runs)) for o in FAILURES),
             _num(_median(times), 1), _num(_p90(times), 1),
             _num(_median([r['path_length'] for r in ok]), 2),
             _num(min((r['min_clearance'] for r in runs), default=None), 3)]
    return '| ' + ' | '.join(cells) + ' |'


def methods_table(rs: RunSet) -> str:
    lines = ['| method | runs | reached | success | collisions | missed | abandoned '
             '| unreachable | timeout | median time [s] | p90 time [s] | median path [m] '
             '| least clearance [m] |', '|' + '---|' * 13]
    for m in rs.methods:
        runs = [r for r in rs.runs if r['method'] == m]
        if runs:
            lines.append(method_row(m, runs))
    return '\n'.join(lines)


def perception_table(rs: RunSet) -> str:
    """Per method that uses the memory's frame (a pose error recorded), the planned-from
    pose against the truth at arrival (median, p95, within 0.10 m) and the cycles spent
    evading in worlds where nothing moves (share, most in a run); '' when no run records
    them (results files from before the bench did)."""
    lines = []
    for m in rs.methods:
        runs = [r for r in rs.runs if r['method'] == m]
        err = [r['pose_error_final'] for r in runs if r.get('pose_error_final') is not None]
        if not err or max(err) == 0.0:
            continue
        still = [r for r in runs if not r.get('moving_world') and 'evading_cycles' in r]
        evading = [r['evading_cycles'] for r in still]
        cycles = sum(r['cycles'] for r in still)
        share = '-' if not cycles else \
            f'{100.0 * sum(evading) / cycles:.2f} % (most {max(evading)})'
        lines.append(f'| `{m}` | {_median(err):.3f} | {np.percentile(err, 95):.3f} | '
                     f'{100.0 * np.mean(np.asarray(err) <= 0.10):.0f} % | {share} |')
    if not lines:
        return ''
    return '\n'.join(['| method | pose error at arrival, median [m] | p95 [m] | within '
                      '0.10 m | evading cycles where nothing moves |', '|' + '---|' * 5,
                      *lines])


def speed_table(rs: RunSet) -> str:
    """Per method, over its runs that reached: time over the physical limit (the shortest
    path at the robot's top speed) and path over the shortest path, median and p90; and
    over all its runs with a shortest path, the BARN Challenge's score (tools/metrics.py,
    mean; 0.5 at most); '' when no run records them (results files from before the
    bench did)."""
    lines = []
    for m in rs.methods:
        ok = [r for r in rs.runs if r['method'] == m and r.get('time_over_limit') is not None]
        if not ok:
            continue
        t = [r['time_over_limit'] for r in ok]
        p = [r['path_over_shortest'] for r in ok]
        scored = [barn_score(r['outcome'] == 'reached', r.get('time_over_limit'))
                  for r in rs.runs if r['method'] == m and r.get('shortest_path') is not None]
        lines.append(f'| `{m}` | {len(ok)} | {_num(_median(t), 2)} | {_num(_p90(t), 2)} '
                     f'| {_num(_median(p), 2)} | {_num(_p90(p), 2)} '
                     f'| {_num(float(np.mean(scored)) if scored else None, 3)} |')
    if not lines:
        return ''
    return '\n'.join(['| method | reached | time over the physical limit, median | p90 '
                      '| path over the shortest, median | p90 | BARN score, mean |',
                      '|' + '---|' * 7, *lines])


def worlds_table(rs: RunSet) -> str:
    """Outcome per world and method (small suites), or reached per family (generated
    suites of several families); '' otherwise."""
    worlds = sorted({r['world'] for r in rs.runs})
    by = {(r['world'], r['method']): r for r in rs.runs}
    head = '| {} | ' + ' | '.join(f'`{m}`' for m in rs.methods) + ' |'
    rule = '|' + '---|' * (len(rs.methods) + 1)
    if len(worlds) <= MAX_WORLD_ROWS:
        lines = [head.format('world'), rule]
        for w in worlds:
            cells = []
            for m in rs.methods:
                r = by.get((w, m))
                cells.append('-' if r is None else f'reached ({r["time_s"]:.0f} s)'
                             if r['outcome'] == 'reached' else r['outcome'])
            lines.append(f'| {w} | ' + ' | '.join(cells) + ' |')
        return '\n'.join(lines)
    families = sorted({family_of(w) for w in worlds})
    if len(families) < 2:
        return ''
    lines = [head.format('family (worlds): reached'), rule]
    for fam in families:
        members = [w for w in worlds if family_of(w) == fam]
        cells = []
        for m in rs.methods:
            runs = [by[(w, m)] for w in members if (w, m) in by]
            cells.append(str(sum(r['outcome'] == 'reached' for r in runs)) if runs else '-')
        lines.append(f'| {fam} ({len(members)}) | ' + ' | '.join(cells) + ' |')
    return '\n'.join(lines)


def provenance(rs: RunSet) -> str:
    """The line under a table: command, version, commit, date, conditions, wall time."""
    meta = rs.meta
    if meta.get('command'):
        text = f'Produced by `{meta["command"]}`'
        made = [f'version {meta["version"]}' if meta.get('version') else '',
                f'commit {meta["commit"]}' if meta.get('commit') else 'no git commit',
                meta.get('date') or '']
        text += ' (' + ', '.join(m for m in made if m) + ')'
    else:
        text = 'Command, version and commit not recorded (a results.json written before ' \
               'subapf-bench recorded them)'
    conditions = [fmt.format(rs.conditions[k]) for k, default, fmt in CONDITIONS
                  if k in rs.conditions and rs.conditions[k] != default]
    if conditions:
        text += '; ' + ', '.join(conditions)
    if rs.wall_time_s is not None:
        text += f'; {len(rs.runs)} runs in {rs.wall_time_s:.0f} s wall time'
    return text + f'. Data: [{rs.name}](results/data/{rs.name}).'


def headline_cell(suite: Suite, method: str) -> str:
    """``reached/runs, k collisions`` of ``method`` in the suite's newest file that ran it."""
    for rs in reversed(suite.runsets):
        runs = [r for r in rs.runs if r['method'] == method]
        if runs:
            ok = sum(r['outcome'] == 'reached' for r in runs)
            hits = sum(r['outcome'] == 'collision' for r in runs)
            return f'{ok}/{len(runs)}, {hits} collision{"" if hits == 1 else "s"}'
    return '-'


def headline(suites: list[Suite], methods: list[tuple[str, str]], docs: str | None) -> str:
    """The headline table; ``docs`` is the path from the page it goes into to docs/
    (None: it goes into results.md itself)."""
    lines = ['| suite | ' + ' | '.join(title for _, title in methods) + ' |',
             '|' + '---|' * (len(methods) + 1)]
    page = f'{docs}results.md' if docs is not None else ''
    for s in suites:
        if docs is not None and not s.readme:
            continue   # results.md's headline only
        anchor = f'{page}#{slug(s.title)}'
        cells = ([headline_cell(s, m) for m, _ in methods] if s.runsets
                 else ['not recorded yet'] + [''] * (len(methods) - 1))
        lines.append(f'| [{s.title}]({anchor}) | ' + ' | '.join(cells) + ' |')
    legend = ', '.join(f'{title} `{m}`' for m, title in methods)
    where = (f'; commands, commits and the other outcomes in [{page}]({page})' if page
             else "; the command and commit of each figure are under its suite's table")
    return '\n'.join(lines) + f'\n\nReached / runs and collisions per method ({legend}){where}.'


def slug(title: str) -> str:
    """GitHub's anchor for a heading."""
    kept = ''.join(c for c in title.lower() if c.isalnum() or c in ' -_')
    return kept.replace(' ', '-')


def render_page(suites: list[Suite], methods: list[tuple[str, str]]) -> str:
    parts = [HEADER, '## Headline\n', headline(suites, methods, docs=None) + '\n']
    for s in suites:
        parts.append(f'## {s.title}\n')
        if s.description:
            parts.append(s.description + '\n')
        if s.worlds:
            parts.append(f'Worlds: {s.worlds.rstrip(".")}.\n')
        if s.bench:
            parts.append(f'Bench: `{s.bench}`.\n')
        if not s.runsets:
            parts.append(f'No results are recorded yet for this suite: no `{s.name}.json` '
                         f'in [results/data](results/data/).\n')
        for rs in s.runsets:
            if len(s.runsets) > 1:
                parts.append(f'### {rs.name}\n')
            parts.append(methods_table(rs) + '\n')
            parts.append(provenance(rs) + '\n')
            for extra in (perception_table(rs), speed_table(rs)):
                if extra:
                    parts.append(extra + '\n')
            extra = worlds_table(rs)
            if extra:
                parts.append(extra + '\n')
        if s.notes:
            parts.append(s.notes + '\n')
    return '\n'.join(parts)


def with_headline(readme: str, table: str) -> str:
    """``readme`` with the text between the markers replaced by ``table``."""
    if readme.count(BEGIN) != 1 or readme.count(END) != 1 \
            or readme.index(BEGIN) > readme.index(END):
        raise ValueError(f'the README needs one {BEGIN} ... {END} block')
    head, rest = readme.split(BEGIN)
    _, tail = rest.split(END)
    return f'{head}{BEGIN}\n{table}\n{END}{tail}'


def outputs(data: Path, out: Path, readme: Path) -> dict[Path, str]:
    """What the files should hold."""
    suites, methods = load(data)
    return {out: render_page(suites, methods),
            readme: with_headline(readme.read_text(), headline(suites, methods, 'docs/'))}


def parse_args(argv: list[str] | None) -> argparse.Namespace:
    p = argparse.ArgumentParser(prog=PROG, description=__doc__.splitlines()[0])
    p.add_argument('--data', type=Path, default=DATA,
                   help=f'results files and {SUITES_FILE} (default: {DATA})')
    p.add_argument('--out', type=Path, default=OUT, help=f'page to write (default: {OUT})')
    p.add_argument('--readme', type=Path, default=README,
                   help=f'README with the headline markers (default: {README})')
    p.add_argument('--check', action='store_true',
                   help='write nothing; exit 1 when a file differs from what it would write')
    return p.parse_args(argv)


def main(argv: list[str] | None = None) -> int:
    args = parse_args(argv)
    try:
        wanted = outputs(args.data, args.out, args.readme)
    except (OSError, ValueError, KeyError, yaml.YAMLError) as exc:
        print(f'{PROG}: {exc}', file=sys.stderr)
        return 2
    stale = [p for p, text in wanted.items() if not p.is_file() or p.read_text() != text]
    if args.check:
        for p in stale:
            print(f'{PROG}: {p} is not what {PROG} writes from {args.data}: run {PROG}',
                  file=sys.stderr)
        return 1 if stale else 0
    for p in stale:
        p.write_text(wanted[p])
        print(f'{PROG}: wrote {p}')
    return 0


if __name__ == '__main__':
    sys.exit(main())
