"""The Jazzy main-function idiom for this package's nodes, written once."""

from __future__ import annotations

from collections.abc import Callable
import signal
import sys
import threading
import time

import rclpy
from rclpy.callback_groups import CallbackGroup
from rclpy.duration import Duration
from rclpy.executors import ExternalShutdownException, SingleThreadedExecutor
from rclpy.node import Node
from rclpy.signals import SignalHandlerOptions

from .processes import use_package_profile

#: How often the spin loop looks at the stop request [s].
STOP_POLL = 0.1
#: Bound of the wait after ``on_shutdown`` for every matched reliable subscriber of
#: the node to acknowledge its last messages (the zero velocity) [s]. Destroying a
#: writer before that can lose them: a subscriber that had not yet received a message
#: of a writer that is gone drops it (seen under load in test_process_faults.py).
#: Prompt acknowledgements need the package's Fast DDS profile (config/fastdds.xml:
#: heartbeats every 0.1 s; with Fast DDS's default of 3 s, a wait of 1 s times out).
SHUTDOWN_ACK_TIMEOUT = 1.0


class PolledGroup(CallbackGroup):
    """A callback group the executor never waits on or runs: its subscriptions are taken
    by the node itself (``sub.handle.take_message``) when it wants them, e.g. at its
    planning tick, so 20 Hz odometry does not wake the process (each executor wake
    rebuilds the wait set in Python: about 0.7 ms of CPU here, 2.8 ms per 5 Hz cycle).
    Messages queue in the subscription (its QoS depth) until taken."""

    def can_execute(self, entity) -> bool:
        return False

    def beginning_execution(self, entity) -> bool:
        return False

    def ending_execution(self, entity) -> None:
        pass


def stop_on_signals() -> threading.Event:
    """An event set by SIGINT or SIGTERM (instead of an exception, see spin_node)."""
    stop = threading.Event()
    for sig in (signal.SIGINT, signal.SIGTERM):
        signal.signal(sig, lambda *_: stop.set())
    return stop


def wait_for_acks(node: Node, timeout: float = SHUTDOWN_ACK_TIMEOUT) -> bool:
    """Wait until every matched reliable subscriber of each of ``node``'s publishers
    has acknowledged all it was sent, ``timeout`` [s] in all; True if they all did.

    Publishers are waited for in the order they were created (the planner's cmd_vel
    first). Best-effort subscribers acknowledge nothing and are not waited for; a
    subscriber whose process is gone but not yet out of the graph (its lease still
    running, after a SIGKILL) never acknowledges, and the wait ends at ``timeout``.
    """
    deadline = time.monotonic() + timeout
    acked = True
    for pub in list(node.publishers):
        left = max(0.0, deadline - time.monotonic())
        acked = pub.wait_for_all_acked(Duration(nanoseconds=int(left * 1e9))) and acked
    return acked


def spin_node(make_node: Callable[[], Node], prog: str,
              bad_input: tuple[type[BaseException], ...],
              on_shutdown: Callable[[Node], None] | None = None,
              args: list[str] | None = None) -> int:
    """init, build, spin; on SIGINT, SIGTERM or external shutdown: ``on_shutdown``
    (e.g. publish zero velocity), destroy_node, try_shutdown, and return 0.

    rclpy's own signal handlers are not installed: they shut the context down before
    ``on_shutdown`` could still publish. Nor does a signal raise KeyboardInterrupt,
    which, landing inside rclpy's C++ message conversion, comes out as a RuntimeError
    (seen under load). SIGINT and SIGTERM only set a flag that the spin loop checks
    every STOP_POLL seconds. After ``on_shutdown`` the node waits, at most
    SHUTDOWN_ACK_TIMEOUT, until its reliable subscribers have acknowledged its last
    messages (wait_for_acks; a warning if some did not), so that they are delivered.
    The process uses the package's Fast DDS profile unless the user set another
    (processes.use_package_profile).

    Errors: a ``bad_input`` exception raised while *building* the node (bad
    parameter, bad world file) prints its message, no traceback, and returns 2. Any
    other exception, and any exception at all while spinning (a bug, even if it is
    of a ``bad_input`` type), propagates with its traceback (exit code 1 from the
    console script) after the same shutdown sequence (``on_shutdown`` first, so
    the robot is stopped).
    """
    use_package_profile()
    rclpy.init(args=args, signal_handler_options=SignalHandlerOptions.NO)
    stop = stop_on_signals()
    node = None
    try:
        try:
            node = make_node()
        except bad_input as exc:
            print(f'{prog}: {exc}', file=sys.stderr)
            return 2
        executor = SingleThreadedExecutor()
        executor.add_node(node)
        while not stop.is_set() and rclpy.ok():
            executor.spin_once(timeout_sec=STOP_POLL)
    except (KeyboardInterrupt, ExternalShutdownException):
        pass
    finally:
        try:
            if node is not None:
                try:
                    if on_shutdown is not None and rclpy.ok():
                        on_shutdown(node)
                        if not wait_for_acks(node):
                            node.get_logger().warning(
                                'shutdown: not every subscriber acknowledged the last '
                                f'messages within {SHUTDOWN_ACK_TIMEOUT} s')
                finally:
                    node.destroy_node()
        finally:
            rclpy.try_shutdown()
    return 0
