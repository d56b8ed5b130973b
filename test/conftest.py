"""Shared fixtures and the test tiers.

DDS: every process a test starts talks over loopback only
(ROS_AUTOMATIC_DISCOVERY_RANGE=LOCALHOST) and in a ROS_DOMAIN_ID of its own. A
domain is leased with an exclusive lock on a file in LEASE_DIR, held until it is
released (or its pytest process ends, when the kernel drops the lock), and is
skipped while any process on the machine has it in its environment
(domain_processes). So tests of one run, concurrent pytest runs, and manual runs
on the machine (that set ROS_DOMAIN_ID) do not share a domain. The in-process node
tests run in the session's own leased domain; each DDS test gets another one from
``ros_env`` (or ``bringup_env``).

Tiers: every test carries at least one of the TIERS markers (registered in
pyproject.toml), usually as its module's ``pytestmark``.
"""

from __future__ import annotations

import fcntl
import itertools
import os
from pathlib import Path
import tempfile
import time
from typing import IO, Callable, TypeVar
import warnings

import pytest

REPO = Path(__file__).resolve().parents[1]
WORLDS = REPO / 'sim' / 'worlds'
PARAMS = REPO / 'config' / 'planner.yaml'

TIERS = ('core', 'sim', 'node', 'dds', 'slow')
#: A test without a tier marker fails collection (pytest.UsageError) when True, only
#: warns when False; SUBAPF_REQUIRE_TIERS=1 or =0 in the environment overrides it.
REQUIRE_TIERS = True

#: Domains leased to DDS tests and the session: above the 1-100 that subapf-bringup,
#: subapf-replay and subapf-nodeperf pick at random when given no --domain-id, and at
#: most 232, the largest domain Fast DDS's default port mapping allows.
DOMAINS = range(102, 231)
#: subapf-bringup accepts --domain-id in [0, 101] only (tools/bringup.py).
BRINGUP_DOMAINS = range(1, 102)
LEASE_DIR = Path(tempfile.gettempdir()) / 'subapf_planner_domains'

_next = itertools.count()
_T = TypeVar('_T')


class DomainLease:
    """An exclusive lock on one domain id; ``release`` (or process exit) frees it."""

    def __init__(self, domain: int, lock: IO) -> None:
        self.domain = domain
        self._lock = lock

    def release(self) -> None:
        if self._lock is not None:
            self._lock.close()   # closing the descriptor drops the flock
            self._lock = None


def domain_processes() -> dict[int, int]:
    """pid -> ROS_DOMAIN_ID of every other process on the machine that has one in its
    environment (Linux /proc)."""
    found = {}
    for proc in Path('/proc').iterdir():
        if not proc.name.isdigit() or int(proc.name) == os.getpid():
            continue
        try:
            env = (proc / 'environ').read_bytes().split(b'\0')
        except OSError:
            continue
        for var in env:
            if var.startswith(b'ROS_DOMAIN_ID='):
                try:
                    found[int(proc.name)] = int(var.split(b'=', 1)[1])
                except ValueError:
                    pass
    return found


def lease_domain(pool: range = DOMAINS) -> DomainLease:
    """A domain of ``pool`` that no other lease holds and no process uses."""
    LEASE_DIR.mkdir(mode=0o777, exist_ok=True)
    busy = set(domain_processes().values())
    start = (os.getpid() * 7 + next(_next)) % len(pool)   # spread runs and tests
    for k in range(len(pool)):
        domain = pool[(start + k) % len(pool)]
        if domain in busy:
            continue
        lock = open(LEASE_DIR / f'{domain}.lock', 'a')
        try:
            fcntl.flock(lock, fcntl.LOCK_EX | fcntl.LOCK_NB)
        except OSError:
            lock.close()
            continue
        return DomainLease(domain, lock)
    raise RuntimeError(f'no free ROS domain in {pool} (leases in {LEASE_DIR})')


# The session's own domain, for the nodes the tests create in this process.
_SESSION = lease_domain()
os.environ['ROS_AUTOMATIC_DISCOVERY_RANGE'] = 'LOCALHOST'
os.environ['ROS_DOMAIN_ID'] = str(_SESSION.domain)


def _env_fixture(pool: range, monkeypatch: pytest.MonkeyPatch):
    lease = lease_domain(pool)
    # monkeypatch restores the session's values afterwards, also when the test
    # changed them itself (processes.join_domain sets os.environ)
    monkeypatch.setenv('ROS_AUTOMATIC_DISCOVERY_RANGE', 'LOCALHOST')
    monkeypatch.setenv('ROS_DOMAIN_ID', str(lease.domain))
    try:
        yield dict(os.environ, PYTHONUNBUFFERED='1')
    finally:
        lease.release()


@pytest.fixture
def ros_env(monkeypatch):
    """Environment for a DDS test's processes: a leased ROS_DOMAIN_ID (also set in
    this process for the test's duration, for its own nodes) and LOCALHOST discovery.
    ``int(ros_env['ROS_DOMAIN_ID'])`` is the domain."""
    yield from _env_fixture(DOMAINS, monkeypatch)


@pytest.fixture
def bringup_env(monkeypatch):
    """As ros_env, with a domain subapf-bringup accepts as --domain-id ([0, 101])."""
    yield from _env_fixture(BRINGUP_DOMAINS, monkeypatch)


def pytest_addoption(parser):
    parser.addoption('--stress', type=int, default=0, metavar='N',
                     help='stress mode: run the tests beside N busy-loop processes per '
                          'core (ended with the session, each after at most an hour); '
                          'python -m subapf_planner.tools.stress also counts passes')


@pytest.fixture(scope='session', autouse=True)
def stress(request):
    """The busy processes of --stress N (none without it); yields N."""
    per_core = request.config.getoption('--stress')
    if not per_core:
        yield 0
        return
    from subapf_planner.tools.stress import Busy
    with Busy(per_core):
        yield per_core


@pytest.fixture
def worlds_dir() -> Path:
    return WORLDS


def pytest_collection_modifyitems(config, items):
    """Every test must carry a tier marker (TIERS); see REQUIRE_TIERS."""
    untiered = sorted({Path(str(item.fspath)).name for item in items
                       if not any(item.get_closest_marker(t) for t in TIERS)})
    if not untiered:
        return
    required = {'1': True, '0': False}.get(os.environ.get('SUBAPF_REQUIRE_TIERS', ''),
                                           REQUIRE_TIERS)
    message = (f'tests without a tier marker ({", ".join(TIERS)}) in: '
               f'{", ".join(untiered)}; add e.g. `pytestmark = pytest.mark.core` at the '
               'top of each')
    if required:
        raise pytest.UsageError(message)
    warnings.warn(pytest.PytestWarning(message), stacklevel=1)


def _interfaces(name: str, probe: str) -> dict[str, str]:
    """PYTHONPATH, LD_LIBRARY_PATH and AMENT_PREFIX_PATH for a process to import the
    interface package ``name`` and find its definitions: the ROS install's (none needed)
    when there is one (``probe`` imports), else the package test/interfaces_build.py
    builds once."""
    try:
        __import__(probe)
        return {}
    except ImportError:
        from interfaces_build import interface_paths
        return interface_paths(name)


@pytest.fixture(scope='session')
def tf2_msgs_built() -> dict[str, str]:
    """What a process needs to import tf2_msgs (_interfaces)."""
    return _interfaces('tf2_msgs', 'tf2_msgs.msg')


@pytest.fixture(scope='session')
def nav2_msgs_built() -> dict[str, str]:
    """What a process needs to import nav2_msgs' NavigateToPose and FollowPath
    (_interfaces)."""
    return _interfaces('nav2_msgs', 'nav2_msgs.action')


def with_paths(env: dict[str, str], paths: dict[str, str]) -> dict[str, str]:
    """``env`` with ``paths`` (PYTHONPATH-like variables) put in front."""
    out = dict(env)
    for k, v in paths.items():
        out[k] = os.pathsep.join(filter(None, [v, env.get(k)]))
    return out


def wait_for(predicate: Callable[[], _T], timeout: float, what: str | Callable[[], str],
             interval: float = 0.05) -> _T:
    """Call ``predicate`` until it returns something true, and return that. After
    ``timeout`` seconds (monotonic) fail: AssertionError "timed out after T s waiting
    for WHAT", ``what`` a text or a callable giving one (called then only: a log, say).
    A predicate that blocks itself (an executor's spin_once) can take ``interval`` 0."""
    end = time.monotonic() + timeout
    while True:
        value = predicate()
        if value:
            return value
        if time.monotonic() >= end:
            text = what() if callable(what) else what
            raise AssertionError(f'timed out after {timeout:g} s waiting for {text}')
        time.sleep(interval)


class ChildGraph:
    """A test's own node, spun on ``ex``, beside child processes ``children`` whose
    logs are the *.log files of ``log_dir``: what the DDS tests' graphs share."""

    ex: object
    children: list
    log_dir: Path

    def logs(self) -> str:
        """The end of each child's log."""
        return '\n'.join(f'--- {f.name}\n' + f.read_text()[-3000:]
                         for f in sorted(self.log_dir.glob('*.log')))

    def until(self, predicate, timeout: float, what: str):
        """Spin until ``predicate`` holds (wait_for), failing with the logs, or at once
        when a child has died."""
        def spun():
            self.ex.spin_once(timeout_sec=0.05)
            assert all(c.poll() is None for c in self.children), self.logs()
            return predicate()
        return wait_for(spun, timeout, lambda: f'{what}\n{self.logs()}', interval=0.0)


def colour_pixels(png: Path, colour: str, tol: float = 30.0) -> int:
    """How many pixels of the image ``png`` have the matplotlib ``colour`` (each RGB
    channel within ``tol`` of it, on 0-255)."""
    from matplotlib import colors
    import numpy as np
    from PIL import Image
    with Image.open(png) as im:
        rgb = np.asarray(im.convert('RGB'), float)
    want = 255 * np.array(colors.to_rgb(colour))
    return int((np.abs(rgb - want).max(axis=-1) < tol).sum())


def marked_processes(marker: str) -> list[int]:
    """Processes on the machine whose environment holds SUBAPF_TEST_MARKER=marker."""
    found = []
    needle = f'SUBAPF_TEST_MARKER={marker}'.encode()
    for proc in Path('/proc').iterdir():
        if proc.name.isdigit():
            try:
                if needle in (proc / 'environ').read_bytes().split(b'\0'):
                    found.append(int(proc.name))
            except OSError:
                pass
    return found
