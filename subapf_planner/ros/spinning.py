"""The Jazzy main-function idiom for this package's nodes, written once."""

from __future__ import annotations

from collections.abc import Callable, Iterator
import contextlib
import signal
import socket
import sys
import threading
import time

import rclpy
from rclpy.callback_groups import CallbackGroup
from rclpy.duration import Duration
from rclpy.executors import ExternalShutdownException, SingleThreadedExecutor
from rclpy.node import Node
from rclpy.signals import SignalHandlerOptions
from rclpy.utilities import remove_ros_args

from .processes import use_package_profile

#: How often the spin loop looks at the stop request when it cannot be woken by it
#: (spin_node called off the main thread, where signals cannot be routed) [s].
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
    Messages queue in the subscription (its QoS depth) until taken. Nor are their QoS
    event handlers waited on: with rmw_fastrtps_cpp a subscription's events wake the
    wait set while it holds unread messages, so the executor would spin without rest
    (measured: a whole core) between ticks. The node looks for publishers its polled
    subscriptions cannot hear itself (planner_node, qos.unheard_publishers)."""

    def can_execute(self, entity) -> bool:
        return False

    def beginning_execution(self, entity) -> bool:
        return False

    def ending_execution(self, entity) -> None:
        pass


def taken(sub) -> Iterator:
    """The messages queued in subscription ``sub`` of a PolledGroup, oldest first, each
    taken from the queue as it is yielded."""
    with sub.handle:
        while (msg := sub.handle.take_message(sub.msg_type, sub.raw)) is not None:
            yield msg[0]


def stop_on_signals() -> threading.Event:
    """An event set by SIGINT or SIGTERM (instead of an exception, see spin_node)."""
    stop = threading.Event()
    for sig in (signal.SIGINT, signal.SIGTERM):
        signal.signal(sig, lambda *_: stop.set())
    return stop


@contextlib.contextmanager
def woken_by_signals(node: Node, stop: threading.Event) -> Iterator[bool]:
    """While in the block, a SIGINT or SIGTERM (``stop``'s handlers, stop_on_signals)
    also wakes the executor spinning ``node`` from its wait: the C-level handler writes
    the signal to a socket (signal.set_wakeup_fd) that a thread reads, sets ``stop`` and
    triggers a guard condition of the node (whose callback, doing nothing, ends the
    executor's spin_once). So the spin loop can wait without a timeout: it
    wakes for its timers and messages only, not every STOP_POLL to look at ``stop``
    (each wake rebuilds the wait set in Python: about 0.5 ms of CPU). Yields False, and
    does nothing, off the main thread (set_wakeup_fd works only there)."""
    if threading.current_thread() is not threading.main_thread():
        yield False
        return
    guard = node.create_guard_condition(lambda: None)
    reader, writer = socket.socketpair()
    writer.setblocking(False)

    def relay() -> None:
        try:
            while data := reader.recv(1):
                if data[0] in (signal.SIGINT, signal.SIGTERM):
                    stop.set()
                    guard.trigger()
        except OSError:   # closed at the end of the block
            pass
    previous = signal.set_wakeup_fd(writer.fileno(), warn_on_full_buffer=False)
    thread = threading.Thread(target=relay, name='signal-relay', daemon=True)
    thread.start()
    try:
        yield True
    finally:
        signal.set_wakeup_fd(previous)
        writer.close()   # recv returns b'': the relay ends
        thread.join(timeout=1.0)
        reader.close()
        node.destroy_guard_condition(guard)


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


def command_line(args: list[str] | None, usage: Callable[[], str] | None,
                 prog: str) -> int | None:
    """The arguments before (and around) ``--ros-args``, looked at before rclpy starts:
    ``-h`` or ``--help`` prints ``usage()`` and gives 0; any other gives 2 with a one-line
    error (a ROS argument belongs after ``--ros-args``); None: nothing of the sort, go
    on. ``args`` as rclpy.init takes them (None: sys.argv, the program first)."""
    if usage is None:
        return None
    argv = list(sys.argv if args is None else args)
    try:
        extra = remove_ros_args(argv)[1:]
    except Exception:   # noqa: BLE001 (a malformed --ros-args: rclpy.init says what)
        return None
    if '-h' in extra or '--help' in extra:
        sys.stdout.write(usage())
        return 0
    if extra:
        print(f'{prog}: error: unrecognized arguments: {" ".join(extra)} (ROS arguments '
              'go after --ros-args, e.g. --ros-args -p NAME:=VALUE; see --help)',
              file=sys.stderr)
        return 2
    return None


def spin_node(make_node: Callable[[], Node], prog: str,
              bad_input: tuple[type[BaseException], ...],
              on_shutdown: Callable[[Node], None] | None = None,
              args: list[str] | None = None,
              usage: Callable[[], str] | None = None) -> int:
    """init, build, spin; on SIGINT, SIGTERM or external shutdown: ``on_shutdown``
    (e.g. publish zero velocity), destroy_node, try_shutdown, and return 0.

    rclpy's own signal handlers are not installed: they shut the context down before
    ``on_shutdown`` could still publish. Nor does a signal raise KeyboardInterrupt,
    which, landing inside rclpy's C++ message conversion, comes out as a RuntimeError
    (seen under load). SIGINT and SIGTERM only set a flag, and wake the spin loop
    (woken_by_signals), which otherwise waits for its timers and messages alone.
    After ``on_shutdown`` the node waits, at most
    SHUTDOWN_ACK_TIMEOUT, until its reliable subscribers have acknowledged its last
    messages (wait_for_acks; a warning if some did not), so that they are delivered.
    The process uses the package's Fast DDS profile unless the user set another
    (processes.use_package_profile).

    With ``usage``, the command line is looked at first (command_line): ``--help``
    prints it and returns 0, an argument that is not a ROS one returns 2; in both
    cases before rclpy is initialised, so nothing is started.

    Errors: a ``bad_input`` exception raised while *building* the node (bad
    parameter, bad world file) prints its message, no traceback, and returns 2. Any
    other exception, and any exception at all while spinning (a bug, even if it is
    of a ``bad_input`` type), propagates with its traceback (exit code 1 from the
    console script) after the same shutdown sequence (``on_shutdown`` first, so
    the robot is stopped).
    """
    done = command_line(args, usage, prog.split(':')[0])
    if done is not None:
        return done
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
        with woken_by_signals(node, stop) as woken:
            while not stop.is_set() and rclpy.ok():
                executor.spin_once(timeout_sec=None if woken else STOP_POLL)
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
