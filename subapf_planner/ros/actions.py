"""The planner node's Nav2 actions: ``navigate_to_pose`` (nav2_msgs/action/NavigateToPose)
and ``follow_path`` (nav2_msgs/action/FollowPath).

``navigate_to_pose`` is what a Nav2 script drives a robot with (``nav2_simple_commander``'s
``goToPose``, ``isTaskComplete``, ``getFeedback``, ``getResult``, ``cancelTask``), served
as Nav2's bt_navigator serves it; ``follow_path`` is what Nav2's controller server
serves: a ``nav_msgs/Path`` to its last pose, which the navigation field favours
(path_discount: the robot keeps to the path and leaves it where the scan shows it
blocked). One goal at a time for both:

* a goal (a pose or a path in odom_frame or map_frame) is accepted while the node is
  active (a managed node that is not: rejected) and becomes the planner's goal; a goal
  in another frame, not finite, or an empty path is accepted and aborted at once with
  the reason;
* a new goal, on either action or on ``goal_pose``, preempts the one running: that one
  ends ABORTED, "preempted by ...", as Nav2's simple action server ends it (a path sent
  again to the same goal, as Nav2's planner replans, only changes the path);
* feedback each planning cycle (navigate_to_pose: the robot's pose in odom_frame, the
  time since the goal was accepted, the distance left along the navigation field's
  descent (DecisionLoop.remaining) and the time that takes at the top speed, a lower
  bound, and the recoveries started; follow_path: the distance left and the commanded
  speed);
* the result: SUCCEEDED when the planner says ``reached``; ABORTED when it gives up,
  with the error code Nav2 Jazzy's servers give for the same failure (ERRORS) and the
  planner's reason; CANCELED on a cancel request, once the robot was sent a zero
  velocity and it was acknowledged (bounded, as on shutdown).

``nav2_msgs`` is not among the PyPI ROS wheels: without it the node runs without the
actions (navigation_actions returns None) and says so; a Jazzy install has it.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from functools import partial
import math

import numpy as np
from rclpy.action import ActionServer, CancelResponse, GoalResponse
from rclpy.duration import Duration
from rclpy.task import Future

from ..core.memory import SAME_GOAL
from ..core.status import State
from .conversions import pose_msg

#: Error codes of Nav2 Jazzy's action definitions, per action: the failure -> code.
#: navigate_to_pose gives what the bt_navigator passes on from the failing server
#: (FollowPath's FAILED_TO_MAKE_PROGRESS, ComputePathToPose's NO_VALID_PATH,
#: GOAL_OCCUPIED, TF_ERROR, UNKNOWN); follow_path its own (FAILED_TO_MAKE_PROGRESS,
#: NO_VALID_CONTROL, TF_ERROR, INVALID_PATH).
ERRORS = {
    'navigate_to_pose': {'stuck': 105, 'goal_unreachable': 208, 'goal_in_obstacle': 206,
                         'frame': 202, 'invalid': 200},
    'follow_path': {'stuck': 105, 'goal_unreachable': 106, 'goal_in_obstacle': 106,
                    'frame': 102, 'invalid': 103},
}
#: Aborted for no failure of its own (preempted, the node deactivated): NONE.
NONE = 0


@dataclass
class Run:
    """One accepted goal until its result."""

    #: The action's name (a key of ERRORS) and its goal handle.
    action: str
    handle: object
    #: Node clock at acceptance [s].
    started: float
    #: Set once with (status, error code, error message); status is one of
    #: 'succeeded', 'aborted', 'canceled'.
    finished: Future = field(default_factory=Future)

    def finish(self, status: str, code: int = NONE, message: str = '') -> None:
        if not self.finished.done():
            self.finished.set_result((status, code, message))


class NavigationActions:
    """The action servers on the planner node ``node`` (ros/planner_node.PlannerParts),
    which calls :meth:`before_tick` and :meth:`after_tick` around each planning cycle.
    ``types``: action name -> its nav2_msgs type."""

    def __init__(self, node, types: dict) -> None:
        self.node = node
        self.types = types
        self.run: Run | None = None
        #: Every accepted goal whose execution has not returned yet (goal id -> run).
        self._runs: dict[bytes, Run] = {}
        self.servers = [ActionServer(node, action_type, name, execute_callback=self._execute,
                                     goal_callback=partial(self._on_goal, name),
                                     handle_accepted_callback=partial(self._on_accepted, name),
                                     cancel_callback=lambda _: CancelResponse.ACCEPT)
                        for name, action_type in types.items()]

    def destroy(self) -> None:
        self.preempt('the planner is shutting down')
        for server in self.servers:
            server.destroy()

    # --- goals, as the action servers hand them over -----------------------------------
    def _on_goal(self, action: str, goal) -> GoalResponse:
        if not self.node.active:
            self.node.get_logger().warn(f'{action}: goal rejected: the planner is not active')
            return GoalResponse.REJECT
        return GoalResponse.ACCEPT

    def _on_accepted(self, action: str, handle) -> None:
        request = handle.request
        path = getattr(request, 'path', None)
        same = self.run is not None and path is not None and self.run.action == action \
            and self._same_goal(path)
        if not same:
            self.preempt(f'preempted by a new {action} goal')
        run = Run(action, handle, self.run.started if same else self.node.now_seconds())
        if same:   # the path to the same goal again (replanned): the old goal ends
            self._end(self.run, 'aborted', NONE, f'replaced by a new path ({action})')
        self.run = run
        self._runs[bytes(handle.goal_id.uuid)] = run
        handle.execute()
        refused = self._take(request, path)
        if refused:
            kind = 'frame' if 'in frame' in refused else 'invalid'
            self._end(run, 'aborted', ERRORS[action][kind], refused)

    def _take(self, request, path) -> str | None:
        """The goal of a request to the planner (PlannerParts.take_goal)."""
        return self.node.take_goal(request.pose if path is None else path)

    def _same_goal(self, path) -> bool:
        goal = self.node.ctl.goal
        if goal is None or not path.poses:
            return False
        end = path.poses[-1].pose.position
        return bool(np.hypot(end.x - goal[0], end.y - goal[1]) < SAME_GOAL)

    async def _execute(self, handle):
        key = bytes(handle.goal_id.uuid)
        run = self._runs[key]
        status, code, message = await run.finished
        del self._runs[key]
        if status == 'succeeded':
            handle.succeed()
        elif status == 'canceled' and handle.is_cancel_requested:
            handle.canceled()
        else:
            handle.abort()
        return self.types[run.action].Result(error_code=code, error_msg=message)

    def _end(self, run: Run, status: str, code: int = NONE, message: str = '') -> None:
        run.finish(status, code, message)
        if self.run is run:
            self.run = None
        text = f'{run.action}: {status}' + (f' ({code}: {message})' if message else '')
        if status == 'succeeded':
            self.node.get_logger().info(text)
        else:
            self.node.get_logger().warn(text)

    def preempt(self, why: str) -> None:
        """A new goal came, or the node stops (``why``): the running one ends ABORTED."""
        if self.run is not None:
            self._end(self.run, 'aborted', NONE, why)

    # --- the planning cycle ---------------------------------------------------------
    def before_tick(self) -> None:
        """A cancel request: the goal dropped, a zero velocity sent and acknowledged
        (bounded), then CANCELED."""
        run = self.run
        if run is not None and run.handle.is_cancel_requested:
            self.node.cancel_goal(f'goal canceled ({run.action})')
            self._end(run, 'canceled', NONE, 'canceled')

    def after_tick(self, decision, stamp) -> None:
        """The cycle's ``decision`` (core/loop.Decision) at ``stamp`` (builtin Time):
        the result if the planner reached a final state, else feedback."""
        run = self.run
        if run is None:
            return
        state = decision.state
        if state is State.REACHED:
            self._end(run, 'succeeded')
        elif state.final:
            cause = decision.result.command.status if decision.result is not None else ''
            codes = ERRORS[run.action]
            key = 'stuck' if state is State.STUCK else str(cause)
            self._end(run, 'aborted', codes.get(key, codes['goal_unreachable']),
                      f'{state}: {decision.reason}')
        else:
            run.handle.publish_feedback(self._feedback(run, decision, stamp))

    def _feedback(self, run: Run, decision, stamp):
        node, ctl = self.node, self.node.ctl
        fb = self.types[run.action].Feedback()
        left = ctl.remaining(decision.result)
        if run.action == 'follow_path':
            fb.distance_to_goal = float(left) if math.isfinite(left) else 0.0
            fb.speed = float(abs(decision.command[0])) if decision.command else 0.0
            return fb
        if ctl.pose is not None:
            fb.current_pose = pose_msg(ctl.pose, node.options.odom_frame, stamp)
        fb.navigation_time = Duration(
            seconds=max(0.0, node.now_seconds() - run.started)).to_msg()
        if math.isfinite(left):
            fb.distance_remaining = float(left)
            fb.estimated_time_remaining = Duration(
                seconds=left / ctl.cfg.max_linear_velocity).to_msg()
        fb.number_of_recoveries = int(ctl.recoveries.tried)
        return fb


def navigation_actions(node) -> NavigationActions | None:
    """The node's action servers, or None (logged) where nav2_msgs is not installed."""
    try:
        from nav2_msgs.action import FollowPath, NavigateToPose
    except ImportError:
        node.get_logger().info('navigate_to_pose and follow_path not served (nav2_msgs not '
                               'installed; a Jazzy install has it): goals on goal_pose')
        return None
    return NavigationActions(node, {'navigate_to_pose': NavigateToPose,
                                    'follow_path': FollowPath})
