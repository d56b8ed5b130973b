"""Child processes of the bringup and the DDS replay: environment, start, stop."""

from __future__ import annotations

import ctypes
import os
from pathlib import Path
import random
import signal
import subprocess
import sys
import time

from .paths import fastdds_profile_file

CHILD_STOP_TIMEOUT = 5.0
#: The environment variables Fast DDS reads its XML profiles file from (2.x, 3.x).
PROFILE_VARS = ('FASTRTPS_DEFAULT_PROFILES_FILE', 'FASTDDS_DEFAULT_PROFILES_FILE')
#: The package's Fast DDS profile, relative to share/subapf_planner or the checkout.


def use_package_profile() -> str | None:
    """Make this process (and the children it starts with os.environ) load the package's
    Fast DDS profile, config/fastdds.xml, unless the user chose a profiles file
    (FASTRTPS_DEFAULT_PROFILES_FILE or FASTDDS_DEFAULT_PROFILES_FILE set, even empty).
    Call it before the process's first rclpy node: Fast DDS reads the file once.
    Returns the profiles file in use, or None."""
    for var in PROFILE_VARS:
        if var in os.environ:
            return os.environ[var] or None
    try:
        path = str(fastdds_profile_file())
    except FileNotFoundError:
        return None
    os.environ['FASTRTPS_DEFAULT_PROFILES_FILE'] = path
    return path


#: Domains a private run picks from (tests lease theirs above: test/conftest.py).
PRIVATE_DOMAINS = range(1, 101)


def domains_in_use() -> set[int]:
    """The ROS_DOMAIN_ID of every other process on this machine that has one in its
    environment (Linux /proc; elsewhere, and for processes not readable, none)."""
    found = set()
    proc = Path('/proc')
    if not proc.is_dir():
        return found
    for entry in proc.iterdir():
        if not entry.name.isdigit() or int(entry.name) == os.getpid():
            continue
        try:
            env = (entry / 'environ').read_bytes().split(b'\0')
        except OSError:
            continue
        for var in env:
            if var.startswith(b'ROS_DOMAIN_ID='):
                try:
                    found.add(int(var.split(b'=', 1)[1]))
                except ValueError:
                    pass
    return found


def free_domain(rng: random.Random | None = None) -> int:
    """A domain of PRIVATE_DOMAINS that no process on this machine has in its
    environment (at random among them; any of them when all are taken)."""
    rng = rng or random.Random()
    busy = domains_in_use()
    free = [d for d in PRIVATE_DOMAINS if d not in busy]
    return rng.choice(free or list(PRIVATE_DOMAINS))


def join_domain(domain_id: int) -> dict[str, str]:
    """Put this process on DDS over loopback in its own domain with the package's Fast
    DDS profile (set before its rclpy init), and return the environment for the child
    processes that share the domain."""
    os.environ['ROS_AUTOMATIC_DISCOVERY_RANGE'] = 'LOCALHOST'
    os.environ['ROS_DOMAIN_ID'] = str(domain_id)
    use_package_profile()
    return dict(os.environ, PYTHONUNBUFFERED='1')


#: Linux prctl(2) option: the signal a process gets when the thread that started it ends.
PR_SET_PDEATHSIG = 1


def _stop_with_parent() -> None:
    """In a child, before exec: SIGTERM when its parent dies, SIGKILL included (Linux's
    PR_SET_PDEATHSIG; elsewhere nothing), so that no node outlives a killed bringup on
    its domain; SIGTERM stops a node cleanly (zero velocity first)."""
    try:
        ctypes.CDLL(None, use_errno=True).prctl(PR_SET_PDEATHSIG, int(signal.SIGTERM))
    except (OSError, AttributeError):
        pass


def start(module: str, ros_args: list[str], env: dict[str, str], quiet: bool = False,
          log: Path | None = None) -> subprocess.Popen:
    """A node as a child process in its own process group (so it can be stopped whole),
    stopped by SIGTERM if this process dies first (call it from the thread that lives
    as long as the node should: the signal comes when that thread ends).

    ``quiet`` discards its output (its exit code still tells failure); ``log`` sends
    stdout and stderr to that file instead.
    """
    if log is not None:
        out = open(log, 'w')   # the child keeps its own descriptor; ours closes below
        pipes = dict(stdout=out, stderr=subprocess.STDOUT)
    else:
        out = None
        pipes = dict(stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL) if quiet else {}
    try:
        return subprocess.Popen([sys.executable, '-m', f'subapf_planner.ros.{module}',
                                 '--ros-args', *ros_args], env=env, start_new_session=True,
                                preexec_fn=_stop_with_parent, **pipes)
    finally:
        if out is not None:
            out.close()


def rss_mib(pid: int) -> float:
    """Resident memory of a process [MiB] (Linux /proc); NaN once it is gone."""
    try:
        for line in Path(f'/proc/{pid}/status').read_text().splitlines():
            if line.startswith('VmRSS:'):
                return int(line.split()[1]) / 1024.0
    except OSError:
        pass
    return float('nan')


def stop(children: list[subprocess.Popen]) -> None:
    """SIGTERM, then SIGKILL, to each child's process group. A node that runs stops
    cleanly on SIGTERM as on SIGINT (ros/spinning.py: zero velocity first); one still
    starting (importing, before its handlers) ends at once and silently, where SIGINT
    would print a KeyboardInterrupt traceback from inside some import."""
    for sig, wait in ((signal.SIGTERM, CHILD_STOP_TIMEOUT), (signal.SIGKILL, 2.0)):
        alive = [c for c in children if c.poll() is None]
        if not alive:
            return
        for c in alive:
            try:
                os.killpg(c.pid, sig)
            except ProcessLookupError:
                pass
        deadline = time.monotonic() + wait
        for c in alive:
            try:
                c.wait(timeout=max(0.0, deadline - time.monotonic()))
            except subprocess.TimeoutExpired:
                pass
