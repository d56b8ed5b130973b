"""``python -m subapf_planner.tools.stress``: run tests beside busy processes, count passes.

    python -m subapf_planner.tools.stress --busy 2 --repeat 1 -- -m "node or dds" test

starts ``--busy`` busy-loop processes per core (pure Python spinning, each ending on
its own after ``--max-seconds`` or when this process is gone), runs pytest with the
arguments after ``--`` ``--repeat`` times (each run writes a JUnit XML file), stops
the busy processes, and prints how many times each test passed, e.g.
``test/test_process_faults.py::test_x[2]  20/20``. Exits 0 only when every run passed.

The pytest option ``--stress N`` (test/conftest.py) starts the same busy processes
for one pytest session instead.
"""

from __future__ import annotations

import argparse
from collections import Counter
import os
from pathlib import Path
import signal
import subprocess
import sys
import tempfile
import time
import xml.etree.ElementTree as ET

#: At most this many busy processes per core, whatever is asked.
MAX_PER_CORE = 8
#: A busy process ends on its own after this long [s] unless told otherwise.
DEFAULT_MAX_SECONDS = 3600.0

# The busy loop: spins until its deadline, or until its parent is gone (reparented).
_LOOP = """
import os, sys, time
end = time.monotonic() + float(sys.argv[1]); parent = int(sys.argv[2]); k = 0
while time.monotonic() < end:
    k += 1
    if k % 100000 == 0 and os.getppid() != parent:
        break
"""


def cores() -> int:
    try:
        return len(os.sched_getaffinity(0))
    except AttributeError:   # not Linux
        return os.cpu_count() or 1


class Busy:
    """``per_core`` busy-loop processes per core, bounded by ``max_seconds``; a context
    manager (or call ``stop``) that kills exactly the processes it started."""

    def __init__(self, per_core: int, max_seconds: float = DEFAULT_MAX_SECONDS) -> None:
        if not 0 <= per_core <= MAX_PER_CORE:
            raise ValueError(f'busy processes per core must be in [0, {MAX_PER_CORE}]')
        self.procs: list[subprocess.Popen] = []
        for _ in range(per_core * cores()):
            self.procs.append(subprocess.Popen(
                [sys.executable, '-c', _LOOP, str(max_seconds), str(os.getpid())],
                stdin=subprocess.DEVNULL, stdout=subprocess.DEVNULL,
                stderr=subprocess.DEVNULL))

    def stop(self) -> None:
        for p in self.procs:
            if p.poll() is None:
                p.send_signal(signal.SIGKILL)
        for p in self.procs:
            p.wait()
        self.procs = []

    def __enter__(self) -> Busy:
        return self

    def __exit__(self, *exc) -> None:
        self.stop()


def tally(xml_files: list[Path]) -> tuple[Counter, Counter]:
    """(passes, runs) per test id over the JUnit XML files pytest wrote."""
    passed, ran = Counter(), Counter()
    for f in xml_files:
        if not f.exists():
            continue
        for case in ET.parse(f).getroot().iter('testcase'):
            if case.find('skipped') is not None:
                continue
            path = case.get('classname', '').replace('.', '/')
            name = f'{path}.py::{case.get("name")}'
            ran[name] += 1
            if case.find('failure') is None and case.find('error') is None:
                passed[name] += 1
    return passed, ran


def parse_args(argv: list[str] | None) -> argparse.Namespace:
    p = argparse.ArgumentParser(prog='subapf-stress', description=__doc__.splitlines()[0])
    p.add_argument('--busy', type=int, default=2,
                   help=f'busy processes per core (0-{MAX_PER_CORE}, default 2)')
    p.add_argument('--repeat', type=int, default=1, help='pytest runs (default 1)')
    p.add_argument('--max-seconds', type=float, default=DEFAULT_MAX_SECONDS,
                   help='the busy processes end on their own after this long [s]')
    p.add_argument('pytest_args', nargs='*', help='after --: arguments for pytest')
    return p.parse_args(argv)


def main(argv: list[str] | None = None) -> int:
    args = parse_args(argv)
    if not 0 <= args.busy <= MAX_PER_CORE or args.repeat < 1:
        print(f'subapf-stress: --busy must be in [0, {MAX_PER_CORE}], --repeat >= 1',
              file=sys.stderr)
        return 2
    out = Path(tempfile.mkdtemp(prefix='subapf_stress_'))
    xml_files, codes = [], []
    started = time.monotonic()
    print(f'subapf-stress: {args.busy * cores()} busy processes ({args.busy} per core), '
          f'{args.repeat} run(s) of pytest {" ".join(args.pytest_args)}', flush=True)
    with Busy(args.busy, args.max_seconds):
        for k in range(args.repeat):
            xml = out / f'run{k}.xml'
            xml_files.append(xml)
            codes.append(subprocess.call([sys.executable, '-m', 'pytest', '-q',
                                          '-p', 'no:cacheprovider', f'--junitxml={xml}',
                                          *args.pytest_args]))
            print(f'subapf-stress: run {k + 1}/{args.repeat}: exit code {codes[-1]}',
                  flush=True)
    passed, ran = tally(xml_files)
    print(f'subapf-stress: pass counts ({args.busy} busy per core, '
          f'{time.monotonic() - started:.0f} s):')
    for name in sorted(ran):
        print(f'  {name}  {passed[name]}/{ran[name]}')
    print(f'subapf-stress: total {sum(passed.values())}/{sum(ran.values())}; '
          f'runs passed {codes.count(0)}/{len(codes)}; JUnit XML in {out}')
    return 0 if all(c == 0 for c in codes) else 1


if __name__ == '__main__':
    sys.exit(main())
