"""The Jazzy main-function idiom for this package's nodes, written once."""

from __future__ import annotations

from collections.abc import Callable
import signal
import sys

import rclpy
from rclpy.executors import ExternalShutdownException
from rclpy.node import Node
from rclpy.signals import SignalHandlerOptions


def _interrupt(*_: object) -> None:
    raise KeyboardInterrupt


def spin_node(make_node: Callable[[], Node], prog: str,
              bad_input: tuple[type[BaseException], ...],
              on_shutdown: Callable[[Node], None] | None = None,
              args: list[str] | None = None) -> int:
    """init, build, spin; on Ctrl-C, SIGTERM or external shutdown: ``on_shutdown``
    (e.g. publish zero velocity), destroy_node, try_shutdown.

    rclpy's own signal handlers are not installed: they would shut the context down
    before ``on_shutdown`` could still publish. SIGINT and SIGTERM raise
    KeyboardInterrupt instead, so the context stays valid for the last message.
    A ``bad_input`` exception while building (bad parameter, bad world file) prints
    its message and returns 2.
    """
    rclpy.init(args=args, signal_handler_options=SignalHandlerOptions.NO)
    signal.signal(signal.SIGTERM, _interrupt)
    node = None
    try:
        node = make_node()
        rclpy.spin(node)
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
