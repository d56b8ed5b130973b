"""``subapf-worlds``: write a seeded suite of procedural worlds (format v1 YAML).

``subapf-worlds --out DIR [--count 210] [--seed 2026] [--families barn,maze,...]
[--robot NAME]``
(``--families dynamic``: every family with moving obstacles; ``--families
building``: office floors, sim/building.py) writes
DIR/<family>_<index>.yaml for each world of ``sim.worldgen.suite`` (the families
take turns; the same seed writes the same files) and prints, per family,
the number of worlds, their mean obstacle count and mean geodesic length.
"""

from __future__ import annotations

import argparse
from pathlib import Path
import statistics
import sys
import time
from typing import Any

import yaml

from ..core.robot import ROBOTS
from ..sim.worldgen import ALL_FAMILIES, DYNAMIC_FAMILIES, FAMILIES, suite_worlds

PROG = 'subapf-worlds'


class _Dumper(yaml.SafeDumper):
    """Block style for the document, flow style for points and obstacle specs."""


class _Flow(dict):
    pass


class _FlowList(list):
    pass


_Dumper.add_representer(_Flow, lambda d, data: d.represent_mapping(
    'tag:yaml.org,2002:map', data.items(), flow_style=True))
_Dumper.add_representer(_FlowList, lambda d, data: d.represent_sequence(
    'tag:yaml.org,2002:seq', data, flow_style=True))


def world_yaml(doc: dict[str, Any]) -> str:
    """A world document as YAML text (what ``sim.world.load_world`` reads)."""
    out: dict[str, Any] = {}
    for key, value in doc.items():
        if key == 'obstacles':
            out[key] = [{kind: _Flow({k: _FlowList(v) if isinstance(v, list) else v
                                      for k, v in spec.items()})
                         for kind, spec in o.items()} for o in value]
        elif key == 'moving':
            out[key] = [{k: _FlowList([_FlowList(p) for p in v]) if k == 'path' else
                         _Flow(v) if isinstance(v, dict) else v for k, v in m.items()}
                        for m in value]
        else:
            out[key] = _FlowList(value) if isinstance(value, list) else value
    return yaml.dump(out, Dumper=_Dumper, sort_keys=False, width=1000)


def parse_args(argv: list[str] | None) -> argparse.Namespace:
    p = argparse.ArgumentParser(prog=PROG, description=__doc__.splitlines()[0])
    p.add_argument('--out', required=True, help='output directory (created if missing)')
    p.add_argument('--count', type=int, default=210, help='number of worlds (default 210)')
    p.add_argument('--seed', type=int, default=2026, help='suite seed (default 2026)')
    p.add_argument('--families', default=','.join(FAMILIES),
                   help=f'comma-separated, of {",".join(ALL_FAMILIES)}; "dynamic" for '
                   f'{",".join(DYNAMIC_FAMILIES)} (default: the static {",".join(FAMILIES)})')
    p.add_argument('--robot', default='burger', choices=sorted(ROBOTS),
                   help="the robot the worlds are for: the burger's worlds scaled to its "
                   "size and speed (sim/worldgen.py scale_world; default: the burger)")
    return p.parse_args(argv)


def main(argv: list[str] | None = None) -> int:
    try:
        args = parse_args(argv)
    except SystemExit as exc:   # argparse's usage errors (code 2) and --help (0)
        return int(exc.code or 0) if not isinstance(exc.code, str) else 2
    families = tuple(f.strip() for f in args.families.split(',') if f.strip())
    if families == ('dynamic',):
        families = DYNAMIC_FAMILIES
    bad = [f for f in families if f not in ALL_FAMILIES]
    if bad or not families:
        print(f'{PROG}: unknown world family {bad or args.families!r}; choose from '
              f'{",".join(ALL_FAMILIES)}', file=sys.stderr)
        return 2
    if len(set(families)) != len(families):
        print(f'{PROG}: family listed twice in {args.families!r}', file=sys.stderr)
        return 2
    if args.count < 1:
        print(f'{PROG}: --count must be at least 1, got {args.count}', file=sys.stderr)
        return 2
    if args.seed < 0:
        print(f'{PROG}: --seed must be non-negative, got {args.seed}', file=sys.stderr)
        return 2
    out = Path(args.out)
    try:
        out.mkdir(parents=True, exist_ok=True)
    except OSError as exc:
        print(f'{PROG}: cannot create {out}: {exc.strerror or exc}', file=sys.stderr)
        return 2
    t0 = time.perf_counter()
    worlds = suite_worlds(args.count, args.seed, families, ROBOTS[args.robot])
    for w in worlds:
        (out / f'{w.doc["name"]}.yaml').write_text(world_yaml(w.doc))
    wall = time.perf_counter() - t0
    for family in families:
        sel = [w for w in worlds if w.family == family]
        if not sel:
            continue
        print(f'{family:15s} {len(sel):4d} worlds, '
              f'{statistics.mean(len(w.doc["obstacles"]) for w in sel):6.1f} obstacles, '
              f'{statistics.mean(len(w.doc.get("moving", ())) for w in sel):5.1f} moving, '
              f'geodesic {statistics.mean(w.geodesic_length for w in sel):5.1f} m (mean), '
              f'time limit {statistics.mean(w.doc["time_limit"] for w in sel):5.0f} s (mean)')
    print(f'{len(worlds)} worlds written to {out} in {wall:.1f} s (seed {args.seed})')
    return 0


if __name__ == '__main__':
    sys.exit(main())
