"""Faults: lost and late scans in the loop, and input streams that stop and resume."""

import math
import time

from conftest import WORLDS
import numpy as np
import pytest
import rclpy
from rclpy.executors import SingleThreadedExecutor
from rclpy.parameter import Parameter

from subapf_planner.core.config import PlannerConfig
from subapf_planner.core.scan import Scan
from subapf_planner.ros.conversions import odom_to_msg, scan_to_msg
from subapf_planner.ros.planner_node import PlannerNode
from subapf_planner.sim.episode import run_episode
from subapf_planner.sim.faults import ScanDelivery, ScanFaults
from subapf_planner.sim.simulator import SimConfig
from subapf_planner.sim.world import load_world, world_files

pytestmark = [pytest.mark.sim, pytest.mark.node]

FIG6 = ('fig6a_narrow_obstacles', 'fig6b_tight_space', 'fig6c_circle_in_front',
        'fig6d_big_wall')


@pytest.mark.parametrize('path', world_files([WORLDS]), ids=lambda p: p.stem)
def test_lost_and_late_scans_never_cause_a_collision(path):
    world = load_world(path)
    result = run_episode(world, PlannerConfig(),
                         SimConfig(range_noise=0.01, beam_dropout=0.05, seed=5),
                         faults=ScanFaults(scan_dropout=0.3, scan_latency=0.4))
    assert result.outcome != 'collision'
    if world.name in FIG6:
        assert result.outcome == 'reached'


def test_bad_fault_values():
    with pytest.raises(ValueError, match='scan_dropout'):
        ScanFaults(scan_dropout=1.0)
    with pytest.raises(ValueError, match='scan_latency'):
        ScanFaults(scan_latency=-0.1)


def test_scan_delivery_loses_and_delays_as_configured():
    late = ScanDelivery(ScanFaults(scan_latency=0.4), seed=1)
    for k in range(5):
        late.capture(k, 0.2 * k)
    assert late.due(0.39) == [] and late.due(0.4) == [0] and late.due(1.2) == [1, 2, 3, 4]
    lossy = ScanDelivery(ScanFaults(scan_dropout=0.3), seed=2)
    for k in range(2000):
        lossy.capture(k, 0.0)
    kept = len(lossy.due(0.0))
    assert 0.65 * 2000 < kept < 0.75 * 2000   # binomial sd ~ 20


@pytest.fixture
def node_and_clock():
    context = rclpy.Context()
    rclpy.init(context=context)
    node = PlannerNode(context=context, parameter_overrides=[
        Parameter('scan_timeout', value=0.5), Parameter('odom_timeout', value=0.5)])
    ex = SingleThreadedExecutor(context=context)
    ex.add_node(node)
    yield node, ex
    ex.shutdown()
    node.destroy_node()
    rclpy.try_shutdown(context=context)


@pytest.mark.parametrize('stream', ['scan', 'odom'])
def test_stale_input_stops_within_one_period_of_its_timeout(stream):
    """The controller on a 5 Hz tick: zero velocity at the first tick past the timeout."""
    from subapf_planner.core.loop import DecisionLoop, Supervision
    ctl = DecisionLoop(PlannerConfig(), Supervision(scan_timeout=0.5, odom_timeout=0.5))
    ctl.set_goal(np.array([3.0, 0.0]))
    scan = Scan(np.full(360, np.inf), 0.0, math.pi / 180, 0.12, 3.5, 0.0)
    last_input, first_stop = 1.0, None
    for k in range(1, 20):
        t = 0.2 * k
        if t <= last_input or stream != 'scan':
            ctl.update_scan(scan, t)
        if t <= last_input or stream != 'odom':
            ctl.update_odom(t, np.zeros(3), t)
        d = ctl.tick(t)
        if t <= last_input:
            assert d.command[0] > 0.0 or d.reason == 'mapping'   # the first scans: standing
        elif first_stop is None and d.command == (0.0, 0.0):
            first_stop = t
    assert first_stop is not None
    assert 0.5 < first_stop - last_input <= 0.5 + 0.2 + 1e-9


@pytest.mark.parametrize('stream', ['scan', 'odom'])
def test_stream_stops_then_resumes(node_and_clock, stream):
    """The node over wall time: stops after the timeout (the bound is loose, this is a
    loaded 2-core machine; the exact bound is tested on the controller above), then
    drives again when the stream resumes, without a restart."""
    node, ex = node_and_clock
    sent = []
    node._publish_cmd = lambda v, w, stamp=None: sent.append((time.monotonic(), v, w))
    node._set_goal(np.array([3.0, 0.0]))
    scan = scan_to_msg(Scan(np.full(360, np.inf), 0.0, math.pi / 180, 0.12, 3.5, 0.0), 'base_scan')
    last_input = {'t': 0.0}

    def feed(scan_on=True, odom_on=True):
        now = node.get_clock().now()
        if scan_on:
            scan.header.stamp = now.to_msg()
            node._on_scan(scan)
        if odom_on:
            node._on_odom(odom_to_msg(np.zeros(3), (0.0, 0.0), now.nanoseconds * 1e-9))
        if (stream == 'scan' and scan_on) or (stream == 'odom' and odom_on):
            last_input['t'] = time.monotonic()

    def run(seconds, **on):
        end = time.monotonic() + seconds
        while time.monotonic() < end:
            feed(**on)
            ex.spin_once(timeout_sec=0.02)

    run(1.0)
    assert sent and sent[-1][1] > 0.0                       # driving
    off = {'scan_on': stream != 'scan', 'odom_on': stream != 'odom'}
    run(1.5, **off)
    stops = [t for t, v, w in sent if t > last_input['t'] and v == 0.0 and w == 0.0]
    assert stops, 'no zero command after the stream stopped'
    assert stops[0] - last_input['t'] <= 0.5 + 3 * node.ctl.cfg.period
    assert node.ctl.text == f'stopped: {"scan" if stream == "scan" else "odometry"} is stale'
    assert all(v == 0.0 for t, v, _ in sent if t > stops[0])
    run(1.0)
    assert sent[-1][1] > 0.0 and node.ctl.text.startswith('driving')   # no restart needed


def test_clock_jump_resets_inputs_but_keeps_the_goal():
    from subapf_planner.core.loop import DecisionLoop
    ctl = DecisionLoop(PlannerConfig())
    ctl.set_goal(np.array([3.0, 0.0]))
    for t in (50.0, 50.2, 50.4, 50.6):   # past the first scans (mapping)
        ctl.update_scan(Scan(np.full(360, np.inf), 0.0, math.pi / 180, 0.12, 3.5, t), t)
        ctl.update_odom(t, np.zeros(3), t)
        d = ctl.tick(t)
    assert d.command[0] > 0
    ctl.clock_jumped()
    d = ctl.tick(0.2)
    assert d.command is None and d.text == 'waiting: no scan yet'
    assert ctl.goal is not None
