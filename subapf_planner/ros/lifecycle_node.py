"""``lifecycle_planner_node`` (``subapf-planner-lifecycle``): the planner as a managed node.

The same node as ``planner_node`` (same name, topics, parameters and action), brought
up the way Nav2's servers are, by ``nav2_lifecycle_manager`` or anyone calling its
lifecycle services (``~/change_state``, ``~/get_state``, lifecycle_msgs):

* constructed: parameters declared, nothing else (unconfigured);
* configure: parameters read (a bad value fails the transition, with the reason in
  the log, and the node stays unconfigured), the decision loop built, publishers,
  subscriptions and the action server made; inactive: nothing is published, goals
  are refused;
* activate: publishers on, the planning timer started;
* deactivate: a goal being driven to is dropped (an action's goal aborted), a zero
  velocity sent and acknowledged (bounded), publishers off, the timer stopped;
* cleanup: all of it taken down (unconfigured again); shutdown: deactivate and
  cleanup as needed (finalized).

Nav2's lifecycle manager also watches its servers through a bond (the ``bond``
package, not on PyPI): give it ``bond_timeout: 0.0`` for this node.
"""

from __future__ import annotations

import functools
import sys
import traceback

from rclpy.exceptions import ParameterException
from rclpy.lifecycle import LifecycleNode, LifecycleState, TransitionCallbackReturn

from ..core.config import ConfigError
from .planner_node import NODE_NAME, PlannerParts, usage
from .spinning import spin_node


def _logged(transition):
    """A transition callback whose exception (a bug) is logged with its traceback and
    fails the transition with ERROR (rclpy would say ERROR without the why)."""
    @functools.wraps(transition)
    def run(self, state: LifecycleState) -> TransitionCallbackReturn:
        try:
            return transition(self, state)
        except Exception:   # noqa: BLE001 (any bug: said, and the transition fails)
            self.get_logger().error(f'{transition.__name__}: {traceback.format_exc()}')
            return TransitionCallbackReturn.ERROR
    return run


class LifecyclePlannerNode(PlannerParts, LifecycleNode):
    """The planner node, configured and activated on its lifecycle transitions."""

    def __init__(self, **kwargs) -> None:
        super().__init__(NODE_NAME, **kwargs)
        self._declare_parameters()

    def _make_publisher(self, msg_type, topic: str, qos):
        return self.create_lifecycle_publisher(msg_type, topic, qos)

    def _destroy_publisher(self, pub) -> None:
        self.destroy_lifecycle_publisher(pub)

    @_logged
    def on_configure(self, state: LifecycleState) -> TransitionCallbackReturn:
        try:
            self._configure()
        except (ConfigError, ParameterException) as exc:
            self.get_logger().error(f'configure failed: {exc}')
            self._cleanup()
            return TransitionCallbackReturn.FAILURE
        return TransitionCallbackReturn.SUCCESS

    @_logged
    def on_activate(self, state: LifecycleState) -> TransitionCallbackReturn:
        result = super().on_activate(state)   # the lifecycle publishers on
        self._activate()
        return result

    @_logged
    def on_deactivate(self, state: LifecycleState) -> TransitionCallbackReturn:
        self._deactivate('the planner was deactivated')   # the zero while publishers are on
        return super().on_deactivate(state)

    @_logged
    def on_cleanup(self, state: LifecycleState) -> TransitionCallbackReturn:
        self._cleanup()
        return TransitionCallbackReturn.SUCCESS

    @_logged
    def on_shutdown(self, state: LifecycleState) -> TransitionCallbackReturn:
        if self.active:
            self._deactivate('the planner was shut down')
        if self.configured:
            self._cleanup()
        return TransitionCallbackReturn.SUCCESS

    def on_error(self, state: LifecycleState) -> TransitionCallbackReturn:
        self.get_logger().error('error in a transition: planner stopped and cleaned up')
        return self.on_shutdown(state)


def lifecycle_usage() -> str:
    """``subapf-planner-lifecycle --help``: planner_node's, as a managed node."""
    return usage().replace('subapf-planner ', 'subapf-planner-lifecycle ', 1).replace(
        'The subapf_planner local planner node:',
        'The subapf_planner local planner as a managed (lifecycle) node, configured and '
        'activated through its ~/change_state service (nav2_lifecycle_manager):', 1)


def main(args: list[str] | None = None) -> int:
    return spin_node(LifecyclePlannerNode, 'subapf-planner-lifecycle: bad parameter',
                     (ConfigError, ParameterException), LifecyclePlannerNode.stop_robot, args,
                     usage=lifecycle_usage)


if __name__ == '__main__':
    sys.exit(main())
