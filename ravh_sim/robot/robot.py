"""The virtual robot: a Giraff-like body in the World's pybullet client, driven by (v, w) commands.

Why a planar multibody: the body hangs from a fixed base by three joints (slide x, slide y, turn
about z), so roll, pitch and height are locked by construction and no floor contact is needed.
Velocity motors with a force limit (mass times the acceleration limit, with a margin) drive the
joints every physics step, and pybullet's contact solver stops the body at walls, furniture,
closed doors and other robots: it never passes through them, and at 0.25 m/s it moves about a
millimetre per step at 240 Hz, far less than any wall's thickness, so it cannot tunnel either.
The x/y motors also hold the body against sliding sideways, as a differential drive's wheels do.

The collision shape is one cylinder of the profile's radius from 2 cm above the floor up to the
profile's height: the disc the free-space map inflates by, and the same 2 cm below which objects
(rugs) do not block in :mod:`ravh_sim.nav.freespace`. The look (a base, a thin pole and a head
screen under the camera) is visual only, on links of its own so that each part has its colour.
"""
from __future__ import annotations

import math
import random

import pybullet as pb

from ravh_msgs_py.names import DEFAULT_AGENT
from ravh_sim.poses import Pose2D, compose, relative, wrap_angle
from ravh_sim.robot.profile import RobotProfile
from ravh_sim.world.scene import World

GROUND_CLEARANCE = 0.02          # m between the floor and the collision cylinder
MOTOR_FORCE_MARGIN = 2.0         # motor force/torque limit over what the acceleration limit needs
BRAKE_RATIO = 3.0                # force slowing down or holding still over force speeding up: a
                                 # robot at rest is not pushed along by another of its weight
BODY_FRICTION = 0.2              # smooth plastic shell: slides along walls instead of sticking
SLIDER_MASS = 0.01               # kg, each of the x and y slide links (joints, not real parts)
PART_MASS = 0.05                 # kg, the pole and the head (all real mass is in the base)
BASE_LOOK_HEIGHT = 0.45          # m, the white drum the Giraff stands on
POLE_RADIUS = 0.02               # m
HEAD_SIZE = (0.04, 0.34, 0.24)   # m: depth, width, height of the screen
HEAD_TOP_GAP = 0.01              # m between the head's top and the profile's height
HEAD_BACK = 0.02                 # m the head sits behind the base centre (keeps it off the camera)
BASE_RGBA = (0.92, 0.92, 0.9, 1.0)
POLE_RGBA = (0.6, 0.6, 0.62, 1.0)
HEAD_RGBA = (0.08, 0.08, 0.1, 1.0)
PLACE_ITERATIONS = 8             # rounds of pushing a new pose out of overlaps
PLACE_TOLERANCE = 0.001          # m of overlap accepted at a new pose
SLIDE_X, SLIDE_Y, TURN, POLE, HEAD = range(5)        # link (and joint) indices
DRIVE_JOINTS = [SLIDE_X, SLIDE_Y, TURN]


class Odometry:
    """Dead reckoning: the robot's measured motion, integrated with zero-mean Gaussian noise.

    The odom frame is the pose where odometry started (identity there). Each increment of true
    motion, taken in the robot frame, has its length and its turn perturbed with variances
    proportional to the distance and angle it covers: after driving L metres the position error
    along the way has std ``linear_sigma * sqrt(L)`` and after turning A radians the heading error
    has std ``angular_sigma * sqrt(A)`` -- the profile's sigmas are the spread after one metre and
    one radian, whatever the physics rate (noise proportional to each step's length would vanish
    as steps get shorter).
    """

    def __init__(self, start: Pose2D, linear_sigma: float, angular_sigma: float,
                 rng: random.Random) -> None:
        self.linear_sigma, self.angular_sigma, self._rng = linear_sigma, angular_sigma, rng
        self._last_true = start
        self.pose: Pose2D = (0.0, 0.0, 0.0)

    def update(self, true_pose: Pose2D) -> None:
        """Integrate the motion from the last true pose to ``true_pose``."""
        dx, dy, dyaw = relative(self._last_true, true_pose)
        self._last_true = true_pose
        dist, turn = math.hypot(dx, dy), abs(dyaw)
        if dist > 0.0 and self.linear_sigma > 0.0:
            scale = 1.0 + self._rng.gauss(0.0, self.linear_sigma * math.sqrt(dist)) / dist
            dx, dy = dx * scale, dy * scale
        if turn > 0.0 and self.angular_sigma > 0.0:
            dyaw += self._rng.gauss(0.0, self.angular_sigma * math.sqrt(turn))
        self.pose = compose(self.pose, (dx, dy, dyaw))

    def jump(self, true_pose: Pose2D) -> None:
        """The robot was moved without driving (teleported): the wheels saw nothing."""
        self._last_true = true_pose


class Robot:
    """One agent's body: commands in, ground-truth pose, velocity and odometry out.

    A :class:`~ravh_sim.robot.simulation.Simulation` calls :meth:`step` before each physics step
    (apply the command within the limits) and :meth:`sync` after it (read the result).
    ``seed`` drives the odometry noise; by default it comes from the world's seed and the name.
    """

    def __init__(self, world: World, profile: RobotProfile, name: str = DEFAULT_AGENT,
                 pose: Pose2D = (0.0, 0.0, 0.0), seed: int | None = None) -> None:
        self.world, self.profile, self.name = world, profile, name
        self._client = world.client
        self._dt = 1.0 / world.physics_hz
        self.body = self._create_body()
        inertia = sum(pb.getDynamicsInfo(self.body, link, physicsClientId=self._client)[2][2]
                      for link in (TURN, POLE, HEAD))
        mass = profile.mass + 2 * SLIDER_MASS + 2 * PART_MASS
        self._limits = (MOTOR_FORCE_MARGIN * mass * profile.max_linear_acceleration,
                        MOTOR_FORCE_MARGIN * inertia * profile.max_angular_acceleration)
        self._place(*pose)
        rng = random.Random(f"{world.state.seed if seed is None else seed}/odometry/{name}")
        self._odometry = Odometry(self._pose, profile.odom_linear_sigma, profile.odom_angular_sigma, rng)

    # ------------------------------------------------------------------ body
    def _create_body(self) -> int:
        p, c = self.profile, self._client
        length = p.height - GROUND_CLEARANCE
        collision = pb.createCollisionShape(pb.GEOM_CYLINDER, radius=p.radius, height=length,
                                            collisionFramePosition=[0, 0, GROUND_CLEARANCE + length / 2],
                                            physicsClientId=c)
        base = pb.createVisualShape(pb.GEOM_CYLINDER, radius=p.radius,
                                    length=BASE_LOOK_HEIGHT - GROUND_CLEARANCE,
                                    visualFramePosition=[0, 0, (GROUND_CLEARANCE + BASE_LOOK_HEIGHT) / 2],
                                    rgbaColor=BASE_RGBA, physicsClientId=c)
        head_z = p.height - HEAD_TOP_GAP - HEAD_SIZE[2] / 2
        pole_length = head_z - BASE_LOOK_HEIGHT
        pole = pb.createVisualShape(pb.GEOM_CYLINDER, radius=POLE_RADIUS, length=pole_length,
                                    visualFramePosition=[-HEAD_BACK, 0, BASE_LOOK_HEIGHT + pole_length / 2],
                                    rgbaColor=POLE_RGBA, physicsClientId=c)
        head = pb.createVisualShape(pb.GEOM_BOX, halfExtents=[s / 2 for s in HEAD_SIZE],
                                    visualFramePosition=[-HEAD_BACK, 0, head_z],
                                    rgbaColor=HEAD_RGBA, physicsClientId=c)
        body = pb.createMultiBody(
            0, -1, -1, basePosition=[0, 0, self.world.floor_z],
            linkMasses=[SLIDER_MASS, SLIDER_MASS, p.mass, PART_MASS, PART_MASS],
            linkCollisionShapeIndices=[-1, -1, collision, -1, -1],
            linkVisualShapeIndices=[-1, -1, base, pole, head],
            linkPositions=[[0, 0, 0]] * 5, linkOrientations=[[0, 0, 0, 1]] * 5,
            linkInertialFramePositions=[[0, 0, 0]] * 5, linkInertialFrameOrientations=[[0, 0, 0, 1]] * 5,
            linkParentIndices=[0, SLIDE_X + 1, SLIDE_Y + 1, TURN + 1, TURN + 1],
            linkJointTypes=[pb.JOINT_PRISMATIC, pb.JOINT_PRISMATIC, pb.JOINT_REVOLUTE,
                            pb.JOINT_FIXED, pb.JOINT_FIXED],
            linkJointAxis=[[1, 0, 0], [0, 1, 0], [0, 0, 1], [0, 0, 1], [0, 0, 1]], physicsClientId=c)
        for link in range(5):
            pb.changeDynamics(body, link, linearDamping=0.0, angularDamping=0.0, jointDamping=0.0,
                              physicsClientId=c)
        pb.changeDynamics(body, TURN, lateralFriction=BODY_FRICTION, physicsClientId=c)
        return body

    # ------------------------------------------------------------------ commands
    def set_command(self, v: float, w: float) -> None:
        """Target forward speed (m/s) and turn rate (rad/s), clamped to the profile's maxima.

        Raises ValueError for NaN or infinite values (the robot keeps its previous command)."""
        if not (math.isfinite(v) and math.isfinite(w)):
            raise ValueError(f"velocity command must be finite, got v={v}, w={w}")
        vmax, wmax = self.profile.max_linear_speed, self.profile.max_angular_speed
        self._command = (min(max(float(v), -vmax), vmax), min(max(float(w), -wmax), wmax))

    @property
    def command(self) -> tuple[float, float]:
        """The clamped target (v, w) the robot accelerates towards."""
        return self._command

    def step(self) -> None:
        """Before a physics step: move the actual velocity towards the command within the
        acceleration limits and drive the motors at it for this step (harder when slowing down
        or holding still than when speeding up)."""
        v0, w0 = self._velocity
        dv = self.profile.max_linear_acceleration * self._dt
        dw = self.profile.max_angular_acceleration * self._dt
        v = v0 + min(max(self._command[0] - v0, -dv), dv)
        w = w0 + min(max(self._command[1] - w0, -dw), dw)
        brake_v = BRAKE_RATIO if v == 0.0 or abs(v) < abs(v0) else 1.0
        brake_w = BRAKE_RATIO if w == 0.0 or abs(w) < abs(w0) else 1.0
        yaw = self._pose[2]
        force, torque = self._limits
        pb.setJointMotorControlArray(self.body, DRIVE_JOINTS, pb.VELOCITY_CONTROL,
                                     targetVelocities=[v * math.cos(yaw), v * math.sin(yaw), w],
                                     forces=[force * brake_v, force * brake_v, torque * brake_w],
                                     physicsClientId=self._client)

    def sync(self) -> None:
        """After a physics step: read the pose and velocity and update the odometry."""
        self._read_state()
        self._odometry.update(self._pose)

    def _read_state(self) -> None:
        (x, vx, *_), (y, vy, *_), (yaw, w, *_) = pb.getJointStates(self.body, DRIVE_JOINTS,
                                                                 physicsClientId=self._client)
        yaw = wrap_angle(yaw)
        self._pose: Pose2D = (x, y, yaw)
        self._velocity: tuple[float, float] = (vx * math.cos(yaw) + vy * math.sin(yaw), w)

    # ------------------------------------------------------------------ state
    @property
    def pose(self) -> Pose2D:
        """Ground truth (x, y, yaw) in the house frame."""
        return self._pose

    @property
    def velocity(self) -> tuple[float, float]:
        """Actual forward speed (m/s, along the heading) and turn rate (rad/s)."""
        return self._velocity

    @property
    def odometry(self) -> Pose2D:
        """Dead-reckoned (x, y, yaw) in the odom frame (the spawn pose is the origin)."""
        return self._odometry.pose

    def teleport(self, x: float, y: float, yaw: float) -> None:
        """Put the robot at a pose, at rest. Odometry does not see the jump (a kidnapped robot)."""
        self._place(x, y, yaw)
        self._odometry.jump(self._pose)

    def _place(self, x: float, y: float, yaw: float) -> None:
        """Put the body at (x, y, yaw), moved out of anything it would overlap there.

        A start pose may overlap a wall (house stations sit close to walls); left to the contact
        solver, the overlap would fling the robot out at metres per second."""
        for _ in range(PLACE_ITERATIONS):
            for joint, value in zip(DRIVE_JOINTS, (x, y, yaw)):
                pb.resetJointState(self.body, joint, value, 0.0, physicsClientId=self._client)
            push = self._deepest_overlap()
            if push is None:
                break
            x, y = x + push[0], y + push[1]
        self._command = (0.0, 0.0)
        self._read_state()

    def is_clear(self) -> bool:
        """Whether the body overlaps nothing (beyond PLACE_TOLERANCE) where it stands."""
        return self._deepest_overlap() is None

    def _deepest_overlap(self) -> tuple[float, float] | None:
        """The horizontal move that clears the deepest overlap of the body, or None if it is
        clear of everything (within PLACE_TOLERANCE)."""
        c = self._client
        lo, hi = pb.getAABB(self.body, TURN, physicsClientId=c)
        best = None
        for other, _ in pb.getOverlappingObjects(lo, hi, physicsClientId=c) or ():
            if other == self.body:
                continue
            for point in pb.getClosestPoints(self.body, other, 0.0, linkIndexA=TURN, physicsClientId=c):
                depth, normal = -point[8], point[7]           # normal on B points from B to A
                if depth > PLACE_TOLERANCE and (best is None or depth > best[0]):
                    best = (depth, normal)
        if best is None:
            return None
        depth, (nx, ny, _) = best
        norm = math.hypot(nx, ny) or 1.0
        return (nx / norm * (depth + PLACE_TOLERANCE), ny / norm * (depth + PLACE_TOLERANCE))
