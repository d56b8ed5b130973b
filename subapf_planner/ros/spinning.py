"""The Jazzy main-function idiom for this package's nodes, written once."""

from __future__ import annotations

from collections.abc import Callable
import signal
import sys
import threading

import rclpy
from rclpy.executors import ExternalShutdownException, SingleThreadedExecutor
from rclpy.node import Node
from rclpy.signals import SignalHandlerOptions

#: How often the spin loop looks at the stop request [s].
STOP_POLL = 0.1


def stop_on_signals() -> threading.Event:
    """An event set by SIGINT or SIGTERM (instead of an exception, see spin_node)."""
    stop = threading.Event()
    for sig in (signal.SIGINT, signal.SIGTERM):
        signal.signal(sig, lambda *_: stop.set())
    return stop


def spin_node(make_node: Callable[[], Node], prog: str,
              bad_input: tuple[type[BaseException], ...],
              on_shutdown: Callable[[Node], None] | None = None,
              args: list[str] | None = None) -> int:
    """init, build, spin; on SIGINT, SIGTERM or external shutdown: ``on_shutdown``
    (e.g. publish zero velocity), destroy_node, try_shutdown.

    rclpy's own signal handlers are not installed: they shut the context down before
    ``on_shutdown`` could still publish. Nor does a signal raise KeyboardInterrupt,
    which, landing inside rclpy's C++ message conversion, comes out as a RuntimeError
    (seen under load). SIGINT and SIGTERM only set a flag that the spin loop checks
    every STOP_POLL seconds. A ``bad_input`` exception while building (bad parameter,
    bad world file) prints its message and returns 2.
    """
    rclpy.init(args=args, signal_handler_options=SignalHandlerOptions.NO)
    stop = stop_on_signals()
    node = None
    try:
        node = make_node()
        executor = SingleThreadedExecutor()
        executor.add_node(node)
        while not stop.is_set() and rclpy.ok():
            executor.spin_once(timeout_sec=STOP_POLL)
    except (KeyboardInterrupt, ExternalShutdownException):
        pass
    except bad_input as exc:
        print(f'{prog}: {exc}', file=sys.stderr)
        return 2
    finally:
        if node is not None:
            if on_shutdown is not None and rclpy.ok():
                on_shutdown(node)
            node.destroy_node()
        rclpy.try_shutdown()
    return 0
