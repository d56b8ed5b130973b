"""Headless PyBullet simulator of one robot of core/robot.py (ROS-free, seeded, fixed dt).

The robot (``robot``: the burger by default) is a real multibody built from its
description (sim/body.py: its footprint, wheels, casters, mass) whose two wheels are
velocity-controlled from (v, w): slip and acceleration are what PyBullet's
contact model gives. The lidar is a 2-D scanner made with ``rayTestBatch`` at the
description's mounting, with its lidar's beams, field of view and ranges (the
burger's LDS-01: 360 beams from angle 0, 0.12 to 3.5 m) and, by
default, as imperfect as the datasheet of the robot's lidar says (sim/sensor.py):
range noise growing with range, beams dropped at random and in runs, mixed
pixels at depth edges, and each beam cast at its own instant of the sweep from
where the laser is then (``sweeps``: the timed sweeps, as a driver publishes
them); ``sensor: ideal`` casts exact rays at one instant. Odometry
is the base's motion, optionally with the systematic error of wheel odometry
(distance and turn-rate scales) and noise; the ground truth is kept apart for
scoring. The simulator's odom frame is the world frame at the start.

Like a real base, a command older than ``cmd_timeout`` of simulated time is
replaced by zero velocity (the watchdog).

Moving obstacles (world ``moving``) are kinematic bodies placed where their
paths put them at every physics step: the laser sees them and any contact with
them is a collision, whoever moved; ``hit_while_stopped`` records whether the
base was commanded to stand still (v = w = 0) at the first contact.
"""

from __future__ import annotations

from collections.abc import Iterator
import contextlib
from dataclasses import dataclass
import math
import os
import sys

import numpy as np
import pybullet
from pybullet_utils.bullet_client import BulletClient

from ..core.params import ConfigError, check_fields, param
from ..core.robot import ROBOTS, RobotDescription
from ..core.scan import Scan
from .body import urdf_file, wheel_speeds
from .sensor import LIDARS, Lidar, corrupt
from .world import Box, Circle, World

OBSTACLE_HEIGHT = 0.5


@contextlib.contextmanager
def _quiet_stdout() -> Iterator[None]:
    """Silence the C-level banner PyBullet prints to stdout on connect."""
    sys.stdout.flush()
    saved = os.dup(1)
    try:
        with open(os.devnull, 'w') as null:
            os.dup2(null.fileno(), 1)
            yield
    finally:
        os.dup2(saved, 1)
        os.close(saved)


@dataclass(frozen=True)
class SimConfig:
    """Simulator settings (SI units). Defaults: the burger and its LDS-01; a setting at 0
    (or '') is the robot's or its lidar's own."""

    robot: str = param('burger', 'The robot simulated (core/robot.py ROBOTS: its footprint, '
                       'wheels, lidar and limits; config/robots/ has its planner parameters)',
                       choices=tuple(ROBOTS), read_only=True)
    physics_dt: float = param(0.005, 'Physics time step', 's', 1e-4, 0.05, read_only=True)
    solver_iterations: int = param(50, "PyBullet's constraint-solver iterations per physics "
                                   'step (its default, 50; fewer is faster and the wheels '
                                   'slip differently: docs/performance.md)', '', 1, 500,
                                   read_only=True)
    scan_threads: int = param(0, "Threads PyBullet's rayTestBatch casts a sweep's beams on "
                              '(0: all cores; the ranges are the same for any number: '
                              'subapf-bench, one process per core, uses 1)', '', 0, 64,
                              read_only=True)
    scan_beams: int = param(0, "Lidar beams per sweep over its field of view (0: the "
                            "lidar's own, the LDS-01's 360)", '', 0, 4096, read_only=True)
    range_min: float = param(0.0, "Lidar minimum range (0: the lidar's own)", 'm', 0.0, 1.0,
                             read_only=True)
    range_max: float = param(0.0, "Lidar maximum range (0: the lidar's own)", 'm', 0.0,
                             100.0, read_only=True)
    sensor: str = param('realistic', 'Lidar model: realistic (the datasheet errors of '
                        '`lidar`, each beam at its own instant of the sweep, latency and '
                        'lost scans: sim/sensor.py) or ideal (exact rays at one instant, '
                        'plus range_noise and beam_dropout)', choices=('ideal', 'realistic'),
                        read_only=True)
    lidar: str = param('', "The lidar simulated: its beams, field of view, rate and "
                       "datasheet errors (sim/sensor.py LIDARS; '': the robot's own, the "
                       "burger's LDS-01)", choices=('', *LIDARS), read_only=True)
    range_noise: float = param(0.0, 'Extra lidar range noise sigma on top of the sensor '
                               "model (the bench's faults)", 'm', 0.0, 1.0, read_only=True)
    beam_dropout: float = param(0.0, 'Extra fraction of beams dropped (reported +inf) on top '
                                'of the sensor model', '', 0.0, 1.0, read_only=True)
    odom_noise: float = param(0.0, 'Relative odometry drift per step', '', 0.0, 1.0,
                              read_only=True)
    odom_distance_scale: float = param(1.0, 'Odometry reports the distance driven times '
                                       'this: wheels whose radius is (scale - 1) larger in '
                                       'the driver than on the robot', '', 0.5, 1.5,
                                       read_only=True)
    odom_yaw_scale: float = param(1.0, 'Odometry reports the turn rate times this: '
                                  '(1 + e_r) / (1 + e_b) for a wheel radius error e_r and '
                                  'a wheel separation error e_b', '', 0.5, 1.5,
                                  read_only=True)
    max_linear_velocity: float = param(0.0, "Base speed limit (0: the robot's)", 'm/s',
                                       0.0, 5.0, read_only=True)
    max_angular_velocity: float = param(0.0, "Base turn-rate limit (0: the robot's)",
                                        'rad/s', 0.0, 20.0, read_only=True)
    wheel_torque: float = param(0.0, "Wheel motor torque limit (0: the robot's)", 'N m',
                                0.0, 100.0, read_only=True)
    cmd_timeout: float = param(0.5, 'Base watchdog: zero velocity after this without a '
                               'command', 's', 0.05, 10.0, read_only=True)
    seed: int = param(0, 'Random seed of all noise', '', 0, 2**31 - 1, read_only=True)

    def __post_init__(self) -> None:
        check_fields(self)
        low, high = self.ranges
        if low >= high:
            raise ConfigError(f'range_min: {low} must be below range_max {high}')

    @property
    def description(self) -> RobotDescription:
        """The robot simulated."""
        return ROBOTS[self.robot]

    @property
    def model(self) -> Lidar:
        """The lidar simulated: its beams, field of view, timing and errors."""
        return LIDARS[self.lidar or self.description.lidar]

    @property
    def beams(self) -> int:
        """Beams per sweep."""
        return self.scan_beams or self.model.beams

    @property
    def ranges(self) -> tuple[float, float]:
        """The lidar's (minimum, maximum) range [m]."""
        return (self.range_min or self.model.range_min, self.range_max or self.model.range_max)

    @property
    def limits(self) -> tuple[float, float]:
        """The base's (speed [m/s], turn rate [rad/s]) limits."""
        robot = self.description
        return (self.max_linear_velocity or robot.max_linear_velocity,
                self.max_angular_velocity or robot.max_angular_velocity)

    @property
    def torque(self) -> float:
        """The wheel motors' torque limit [N m]."""
        return self.wheel_torque or self.description.body.wheel_torque

    @property
    def realistic(self) -> bool:
        return self.sensor == 'realistic'


class RobotSim:
    """One world, one robot, fixed-step physics. Not thread-safe."""

    def __init__(self, world: World, config: SimConfig | None = None) -> None:
        self.world = world
        self.config = config or SimConfig()
        #: The robot simulated, and its lidar.
        self.robot = self.config.description
        self.lidar = self.config.model
        self._rng = np.random.default_rng(self.config.seed)
        with _quiet_stdout():
            self._client = BulletClient(connection_mode=pybullet.DIRECT)
        self._cid = self._client._client   # for the raw calls of every physics step
        self._build()
        self.time = 0.0
        self.collided = False
        #: At the first contact: whether the base was commanded to stand still.
        self.hit_while_stopped = False
        self._cmd = (0.0, 0.0)
        self._cmd_time = -math.inf
        self._wheels_sent: tuple[float, float] | None = None   # motor targets [rad/s]
        x, y, yaw = world.start
        #: The odometry pose; None: the true pose (perfect odometry once it moved).
        self._odom: np.ndarray | None = np.array([x, y, yaw])
        self._truth_prev = self.true_pose()
        n = self.config.beams
        self._angles = self.lidar.angles(n)
        #: The sweep being taken: its start [s], beams cast so far, their true ranges;
        #: and the sweeps completed since the last ``sweeps()``.
        self._sweep_t0 = 0.0
        self._sweep_cast = 0
        self._sweep_true = np.full(n, np.inf)
        self._swept: list[Scan] = []
        #: The time and true pose of the last physics step (beams are cast from the pose
        #: between it and the next one at their own instants).
        self._stepped_from = (self.time, self.true_pose())
        self._advance_sweep()

    def _build(self) -> None:
        c = self._client
        c.resetSimulation()
        c.setGravity(0, 0, -9.81)
        c.setTimeStep(self.config.physics_dt)
        c.setPhysicsEngineParameter(numSolverIterations=self.config.solver_iterations)
        plane = c.createCollisionShape(pybullet.GEOM_PLANE)
        self._plane = c.createMultiBody(0, plane)
        c.changeDynamics(self._plane, -1, lateralFriction=1.0)
        self._obstacles = [self._add_obstacle(o) for o in self.world.all_obstacles()]
        self._movers = [self._add_obstacle(o) for o in self.world.moving_at(0.0)]
        self._mover_orn = [c.getBasePositionAndOrientation(b)[1] for b in self._movers]
        x, y, yaw = self.world.start
        with urdf_file(self.robot) as urdf:
            self.body = c.loadURDF(str(urdf), [x, y, 0.001],
                                   c.getQuaternionFromEuler([0, 0, yaw]))
        c.changeDynamics(self.body, -1, lateralFriction=0.0, spinningFriction=0.0,
                         rollingFriction=0.0)
        names = {c.getJointInfo(self.body, j)[1].decode(): j
                 for j in range(c.getNumJoints(self.body))}
        self._wheels = (names['wheel_left_joint'], names['wheel_right_joint'])
        for j in self._wheels:
            c.changeDynamics(self.body, j, lateralFriction=1.0)

    def _add_obstacle(self, o: Circle | Box) -> int:
        c = self._client
        h = OBSTACLE_HEIGHT
        if isinstance(o, Circle):
            shape = c.createCollisionShape(pybullet.GEOM_CYLINDER, radius=o.radius, height=h)
            orn = [0, 0, 0, 1]
        else:
            shape = c.createCollisionShape(pybullet.GEOM_BOX,
                                           halfExtents=[o.size[0] / 2, o.size[1] / 2, h / 2])
            orn = c.getQuaternionFromEuler([0, 0, o.yaw])
        return c.createMultiBody(0, shape, basePosition=[o.center[0], o.center[1], h / 2],
                                 baseOrientation=orn)

    def close(self) -> None:
        """Release the physics server."""
        if self._client is not None:
            self._client.disconnect()
            self._client = None

    def __enter__(self) -> 'RobotSim':
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()

    # --- commands and stepping ----------------------------------------------------------
    def set_command(self, v: float, w: float) -> None:
        """Velocity command [m/s, rad/s], clamped to the base's limits; NaN -> 0."""
        v_max, w_max = self.config.limits
        v = 0.0 if not math.isfinite(v) else max(-v_max, min(v_max, v))
        w = 0.0 if not math.isfinite(w) else max(-w_max, min(w_max, w))
        self._cmd = (v, w)
        self._cmd_time = self.time

    def wheel_command(self) -> tuple[float, float]:
        """The (v, w) the base drives: the last command, or zero after cmd_timeout."""
        if self.time - self._cmd_time > self.config.cmd_timeout:
            return 0.0, 0.0
        return self._cmd

    def _apply_wheels(self) -> None:
        """The wheel motors' target velocities for the base's (v, w), sent when they
        change (PyBullet keeps a motor's target until it is set again)."""
        targets = wheel_speeds(self.robot, *self.wheel_command())
        if targets != self._wheels_sent:
            pybullet.setJointMotorControlArray(
                self.body, list(self._wheels), pybullet.VELOCITY_CONTROL,
                targetVelocities=list(targets), forces=[self.config.torque] * 2,
                physicsClientId=self._cid)
            self._wheels_sent = targets

    def step(self, duration: float) -> None:
        """Advance by ``duration`` seconds (rounded to whole physics steps).

        Every physics step: the wheel targets, the moving obstacles placed, the physics,
        the odometry increment (only when odometry has errors: perfect odometry is the
        true pose, read when asked), the contact check. The hot calls go to PyBullet
        directly (BulletClient's wrapper costs a few microseconds a call)."""
        dt = self.config.physics_dt
        times = []
        t = self.time
        for _ in range(max(1, int(round(duration / dt)))):
            t += dt   # (summed as self.time is, so the movers' times are the same floats)
            times.append(t)
        placed = self._mover_positions(np.asarray(times)) if self._movers else None
        cid, perfect = self._cid, self._perfect_odometry
        for i, t in enumerate(times):
            self._apply_wheels()
            if placed is not None:
                self._place_movers(placed[:, i])
            pybullet.stepSimulation(physicsClientId=cid)
            self.time = t
            self._advance_sweep()
            if not perfect:
                self._integrate_odom()
            if not self.collided and self._touching_obstacle():
                self.collided = True
                self.hit_while_stopped = self.wheel_command() == (0.0, 0.0)
        if perfect:
            self._odom = None   # the true pose, read when asked

    def _mover_positions(self, times: np.ndarray) -> np.ndarray:
        """Centres (movers, len(times), 2) of the moving obstacles at ``times`` [s]."""
        return np.stack([m.position(times) for m in self.world.moving])

    def _place_movers(self, centres: np.ndarray) -> None:
        """Put each moving obstacle at its centre (movers, 2) [m]."""
        reset, cid, z = pybullet.resetBasePositionAndOrientation, self._cid, OBSTACLE_HEIGHT / 2
        for body, orn, (x, y) in zip(self._movers, self._mover_orn, centres.tolist(),
                                     strict=True):
            reset(body, [x, y, z], orn, physicsClientId=cid)

    def _touching_obstacle(self) -> bool:
        plane = self._plane
        return any(cp[2] != plane
                   for cp in pybullet.getContactPoints(self.body, physicsClientId=self._cid))

    @property
    def _perfect_odometry(self) -> bool:
        cfg = self.config
        return cfg.odom_noise == 0.0 and cfg.odom_distance_scale == 1.0 \
            and cfg.odom_yaw_scale == 1.0

    # --- state --------------------------------------------------------------------------
    def true_pose(self) -> np.ndarray:
        """Ground-truth (x, y, yaw) of base_footprint in the world frame."""
        pos, orn = pybullet.getBasePositionAndOrientation(self.body, physicsClientId=self._cid)
        yaw = pybullet.getEulerFromQuaternion(orn)[2]
        return np.array([pos[0], pos[1], yaw])

    def true_velocity(self) -> tuple[float, float]:
        """Ground-truth forward speed [m/s] and yaw rate [rad/s] in the body frame."""
        lin, ang = pybullet.getBaseVelocity(self.body, physicsClientId=self._cid)
        yaw = self.true_pose()[2]
        return lin[0] * math.cos(yaw) + lin[1] * math.sin(yaw), ang[2]

    def _integrate_odom(self) -> None:
        """Odometry with errors from the base's motion over the last physics step: the
        body-frame increment (forward, lateral, yaw), scaled by odom_distance_scale
        (translation) and odom_yaw_scale (rotation), each with relative noise odom_noise,
        added to the odometry pose. The scales are the systematic error of wheel odometry: a driver
        that assumes wheels (1 + e_r) times their real radius and a separation (1 + e_b)
        times the real one reports (1 + e_r) times the distance and (1 + e_r) / (1 + e_b)
        times the turn (+2 % distance and +3 % turn: e_r = 0.02, e_b = -0.0097)."""
        truth = self.true_pose()
        cfg = self.config
        prev = self._truth_prev
        c, s = math.cos(prev[2]), math.sin(prev[2])
        dx, dy = truth[0] - prev[0], truth[1] - prev[1]
        fwd, lat = c * dx + s * dy, -s * dx + c * dy
        dyaw = math.remainder(truth[2] - prev[2], 2 * math.pi)
        scale = np.array([cfg.odom_distance_scale, cfg.odom_distance_scale,
                          cfg.odom_yaw_scale])
        if cfg.odom_noise > 0.0:
            scale = scale * (1.0 + cfg.odom_noise * self._rng.standard_normal(3))
        fwd, lat, dyaw = np.array([fwd, lat, dyaw]) * scale
        oc, os_ = math.cos(self._odom[2]), math.sin(self._odom[2])
        self._odom = self._odom + [oc * fwd - os_ * lat, os_ * fwd + oc * lat, dyaw]
        self._odom[2] = math.remainder(self._odom[2], 2 * math.pi)
        self._truth_prev = truth

    def odometry(self) -> tuple[np.ndarray, tuple[float, float]]:
        """Odometry pose (x, y, yaw) in odom and body twist (v, w)."""
        pose = self.true_pose() if self._odom is None else self._odom.copy()
        return pose, self.true_velocity()

    def _cast(self, beams: slice, poses: np.ndarray | None = None) -> np.ndarray:
        """True ranges [m] (+inf: no return) of ``beams`` of a sweep, cast from where the
        laser is now, or with base_footprint at ``poses`` (one (x, y, yaw) per beam)."""
        cfg = self.config
        a = self._angles[beams]
        n = a.size
        if poses is None:
            poses = np.tile(self.true_pose(), (n, 1))
        mx, my, myaw = self.robot.laser.planar
        c, s = np.cos(poses[:, 2]), np.sin(poses[:, 2])
        origin = np.column_stack((poses[:, 0] + c * mx - s * my, poses[:, 1] + s * mx + c * my,
                                  np.full(n, self.robot.laser.z)))
        a = a + poses[:, 2] + myaw
        reach = cfg.ranges[1]
        ends = origin + reach * np.column_stack((np.cos(a), np.sin(a), np.zeros(n)))
        hits = pybullet.rayTestBatch(origin.tolist(), ends.tolist(),
                                     numThreads=cfg.scan_threads, physicsClientId=self._cid)
        return np.array([h[2] if h[0] >= 0 else np.inf for h in hits]) * reach

    def _reported(self, true: np.ndarray) -> np.ndarray:
        """The ranges the lidar reports for the true ones: the sensor model's errors
        (realistic), the extra noise and dropout, +inf outside [range_min, range_max)."""
        cfg = self.config
        ranges = corrupt(true, self.lidar, self._rng) if cfg.realistic else true.copy()
        n = ranges.size
        if cfg.range_noise > 0.0:
            ranges = ranges + cfg.range_noise * self._rng.standard_normal(n)
        if cfg.beam_dropout > 0.0:
            ranges[self._rng.random(n) < cfg.beam_dropout] = np.inf
        low, high = cfg.ranges
        ranges[(ranges < low) | (ranges >= high)] = \
            self.lidar.no_return if cfg.realistic else np.inf
        return ranges

    def _advance_sweep(self) -> None:
        """Cast the beams of the sweep in progress whose instants have come (all at its
        start with the ideal sensor), and complete it when its last beam is cast."""
        cfg = self.config
        n, period = cfg.beams, self.lidar.scan_time
        inc = period / n if cfg.realistic else 0.0
        tau = self.time - self._sweep_t0
        if tau < -1e-9:
            return
        due = n if inc == 0.0 else min(n, int(math.floor(tau / inc + 1e-6)) + 1)
        t1, p1 = self.time, self.true_pose()
        if due > self._sweep_cast:
            # each beam from where the laser was at its instant, between the last physics
            # step and this one (a beam is due up to a step after its instant)
            t0, p0 = self._stepped_from
            instants = self._sweep_t0 + inc * np.arange(self._sweep_cast, due)
            f = np.clip((instants - t0) / (t1 - t0), 0.0, 1.0) if t1 > t0 \
                else np.ones(instants.size)
            turn = math.remainder(p1[2] - p0[2], 2.0 * math.pi)
            poses = np.column_stack((p0[0] + f * (p1[0] - p0[0]), p0[1] + f * (p1[1] - p0[1]),
                                     p0[2] + f * turn))
            self._sweep_true[self._sweep_cast:due] = self._cast(slice(self._sweep_cast, due),
                                                                poses)
            self._sweep_cast = due
        self._stepped_from = (t1, p1)
        if due < n:
            return
        self._swept.append(Scan(self._reported(self._sweep_true), *self._geometry(),
                                stamp=self._sweep_t0, time_increment=inc, scan_time=period))
        self._sweep_t0 += period
        self._sweep_cast = 0
        self._sweep_true = np.full(n, np.inf)

    def sweeps(self) -> list[Scan]:
        """The sweeps completed since the last call, oldest first: each stamped with its
        first beam's instant, beam i taken ``time_increment`` after the one before
        (``scan_time`` a sweep), as a lidar driver publishes them."""
        done, self._swept = self._swept, []
        return done

    @staticmethod
    def sweep_end(scan: Scan) -> float:
        """When a sweep's last beam was taken [s]."""
        return scan.stamp + scan.time_increment * (np.size(scan.ranges) - 1)

    def scan(self) -> Scan:
        """One sweep from base_scan cast now, at the current pose, with the sensor's
        range errors but no sweep timing (+inf: no return)."""
        return Scan(self._reported(self._cast(slice(0, self.config.beams))),
                    *self._geometry(), stamp=self.time)

    def _geometry(self) -> tuple[float, float, float, float]:
        """A scan's angle_min, angle_increment [rad], range_min, range_max [m]."""
        a = self._angles
        increment = float(a[1] - a[0]) if a.size > 1 else self.lidar.angle_increment
        return (float(a[0]), increment, *self.config.ranges)
