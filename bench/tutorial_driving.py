"""The tutorial's SimpleDriving-v0 as its part 2 writes it, for comparison (bench and tests).

A port to Gymnasium 1.x that keeps what costs time: ``reset`` calls ``resetSimulation`` and
loads the plane, the car and the goal again; ``step`` sets the steering and the wheel motors
every step, steps, and reads the pose, the Euler angles and the velocity. The files are
urdfkit's simplecar and simpleplane templates and a goal post like the tutorial's; loading
flags default to the tutorial's (none).
"""

from __future__ import annotations

import math
import tempfile
from pathlib import Path
from typing import Any

import gymnasium as gym
import numpy as np

GOAL_URDF = """<?xml version="1.0"?>
<robot name="goal">
  <link name="base_link">
    <visual><geometry><cylinder radius="0.5" length="1"/></geometry></visual>
    <collision><geometry><cylinder radius="0.25" length="0.5"/></geometry></collision>
    <inertial><mass value="0"/><inertia ixx="0" ixy="0" ixz="0" iyy="0" iyz="0" izz="0"/></inertial>
  </link>
</robot>
"""


class TutorialDrivingEnv(gym.Env):
    """The part-2 environment, reloading everything on reset."""

    metadata = {"render_modes": []}

    def __init__(self, flags: int = 0, deterministic: bool = False):
        import pybullet as p

        from urdfkit.engine.session import quiet_stdout
        from urdfkit.model.catalog import build_template

        self.p = p
        self.flags = flags
        self.deterministic = deterministic  # tests: the same pair order as urdfkit's env
        self._tmp = tempfile.TemporaryDirectory(prefix="tutorial-driving-")
        folder = Path(self._tmp.name)
        self.car_file = str(build_template("simplecar").write(folder / "simplecar.urdf"))
        self.plane_file = str(build_template("simpleplane", {"shape": "box"}).write(  # the box
            folder / "simpleplane.urdf"))
        self.goal_file = str(folder / "simplegoal.urdf")
        Path(self.goal_file).write_text(GOAL_URDF)
        self.action_space = gym.spaces.Box(np.array([0, -0.6], dtype=np.float32),
                                           np.array([1, 0.6], dtype=np.float32))
        self.observation_space = gym.spaces.Box(
            np.array([-10, -10, -1, -1, -5, -5, -10, -10], dtype=np.float32),
            np.array([10, 10, 1, 1, 5, 5, 10, 10], dtype=np.float32))
        with quiet_stdout():
            self.client = p.connect(p.DIRECT)
        p.setTimeStep(1 / 30, physicsClientId=self.client)
        self.goal = (0.0, 0.0)
        self.prev_dist_to_goal = 0.0
        self.joint_speed = 0.0

    def reset(self, *, seed: int | None = None, options: dict[str, Any] | None = None
              ) -> tuple[np.ndarray, dict[str, Any]]:
        super().reset(seed=seed)
        p, c = self.p, self.client
        p.resetSimulation(physicsClientId=c)
        p.setGravity(0, 0, -10, physicsClientId=c)
        if self.deterministic:
            p.setPhysicsEngineParameter(deterministicOverlappingPairs=1, physicsClientId=c)
        p.loadURDF(self.plane_file, basePosition=[0, 0, 0], physicsClientId=c)
        self.car = p.loadURDF(self.car_file, basePosition=[0, 0, 0.1], flags=self.flags,
                              physicsClientId=c)
        self.joint_speed = 0.0
        rng = self.np_random
        x = rng.uniform(5, 9) if rng.integers(2) else -rng.uniform(5, 9)
        y = rng.uniform(5, 9) if rng.integers(2) else -rng.uniform(5, 9)
        if options and "goal" in options:
            x, y = options["goal"]
        self.goal = (x, y)
        p.loadURDF(self.goal_file, basePosition=[x, y, 0], physicsClientId=c)
        car_ob = self._car_observation()
        self.prev_dist_to_goal = math.sqrt((car_ob[0] - x) ** 2 + (car_ob[1] - y) ** 2)
        return np.array(car_ob + self.goal, dtype=np.float32), {}

    def _car_observation(self) -> tuple[float, ...]:
        p, c = self.p, self.client
        pos, ang = p.getBasePositionAndOrientation(self.car, physicsClientId=c)
        ang = p.getEulerFromQuaternion(ang, physicsClientId=c)
        ori = (math.cos(ang[2]), math.sin(ang[2]))
        vel = p.getBaseVelocity(self.car, physicsClientId=c)[0][0:2]
        return tuple(pos[:2]) + ori + tuple(vel)

    def step(self, action: Any) -> tuple[np.ndarray, float, bool, bool, dict[str, Any]]:
        p, c = self.p, self.client
        throttle, steering_angle = action
        throttle = min(max(throttle, 0), 1)
        steering_angle = max(min(steering_angle, 0.6), -0.6)
        p.setJointMotorControlArray(self.car, [0, 2], controlMode=p.POSITION_CONTROL,
                                    targetPositions=[steering_angle] * 2, physicsClientId=c)
        friction = -self.joint_speed * (self.joint_speed * 0.01 + 0.2)
        acceleration = 20 * throttle + friction
        self.joint_speed = self.joint_speed + 1 / 30 * acceleration
        if self.joint_speed < 0:
            self.joint_speed = 0
        p.setJointMotorControlArray(self.car, [1, 3, 4, 5], controlMode=p.VELOCITY_CONTROL,
                                    targetVelocities=[self.joint_speed] * 4, forces=[1.2] * 4,
                                    physicsClientId=c)
        p.stepSimulation(physicsClientId=c)
        car_ob = self._car_observation()
        dist_to_goal = math.sqrt((car_ob[0] - self.goal[0]) ** 2
                                 + (car_ob[1] - self.goal[1]) ** 2)
        reward = max(self.prev_dist_to_goal - dist_to_goal, 0)
        self.prev_dist_to_goal = dist_to_goal
        done = False
        if car_ob[0] >= 10 or car_ob[0] <= -10 or car_ob[1] >= 10 or car_ob[1] <= -10:
            done = True
        elif dist_to_goal < 1:
            done = True
            reward = 50
        return np.array(car_ob + self.goal, dtype=np.float32), reward, done, False, {}

    def close(self) -> None:
        if self.client >= 0:
            self.p.disconnect(physicsClientId=self.client)
            self.client = -1
        self._tmp.cleanup()
