"""Sensors: measuring, feet, noise, delay and history.

Methods of :class:`urdfkit.sim.Simulation`, split out of :mod:`urdfkit.sim`: each function
takes the simulation as ``self`` and is bound as a method of ``Simulation`` (a class
attribute), so a call costs what a method defined in the class costs.
"""

from __future__ import annotations

from typing import Any

from urdfkit.model.spec import quat_mul, quat_to_matrix, rotate_back, rpy_to_quat
from urdfkit.motion.scenario import OBSERVATION_FIELDS
from urdfkit.motion.sim_state import Observation, _Body


def _keep_velocities(self: Any, b: _Body) -> None:
    """Remember the joint velocities now, for the next measurement's accelerations."""
    p, client = self.session.p, self.session.client
    states = p.getJointStates(b.body, b.frame[0], physicsClientId=client)
    b.previous_velocities = [st[1] for st in states]
    b.previous_step = self.step_count


def _fresh(self: Any, b: _Body) -> Observation:
    """The true observation at this step, measuring it now if it was not yet."""
    if b.history[-1].step != self.step_count:
        b.history.append(self._measure(b))
    return b.history[-1]


def _measure(self: Any, b: _Body) -> Observation:
    """The true observation now, in the measured joint frame."""
    p, client = self.session.p, self.session.client
    pos, orn = p.getBasePositionAndOrientation(b.body, physicsClientId=client)
    lin, ang = p.getBaseVelocity(b.body, physicsClientId=client)
    matrix = quat_to_matrix(orn)
    angles: dict[str, float] = {}
    velocities: dict[str, float] = {}
    accelerations: dict[str, float] = {}
    forces: dict[str, list[float]] | None = None
    torques: dict[str, float] | None = None
    if b.active:
        indices, names, signs, offsets = b.frame
        states = p.getJointStates(b.body, indices, physicsClientId=client)
        if self.config.record.motor_torques:  # the joint's own frame, as applied
            torques = {n: b.torques.get(n, st[3]) for n, st in zip(names, states, strict=True)}
        qd = [st[1] for st in states]
        angles = {n: (st[0] - o) * s
                  for n, st, s, o in zip(names, states, signs, offsets, strict=True)}
        velocities = {n: v * s for n, v, s in zip(names, qd, signs, strict=True)}
        # Over the time since the velocities were last taken (one step, when recording).
        span = (self.step_count - b.previous_step) * self.time_step
        before = b.previous_velocities
        if before is None or span <= 0:
            accelerations = dict.fromkeys(names, 0.0)
        else:
            accelerations = {n: (v - v0) * s / span for n, v, v0, s
                             in zip(names, qd, before, signs, strict=True)}
        b.previous_velocities = qd
        b.previous_step = self.step_count
    if b.force_joints:
        forces = {}
        for name, index in b.force_joints.items():
            state = p.getJointState(b.body, index, physicsClientId=client)
            forces[name] = [float(x) for x in state[2]]
    contacts = None
    if b.contact_links:
        contacts = {}
        for link, index in b.contact_links.items():
            kwargs: dict[str, Any] = {"bodyA": b.body, "linkIndexA": index}
            if self.ground is not None:
                kwargs["bodyB"] = self.ground
            points = p.getContactPoints(physicsClientId=client, **kwargs)
            contacts[link] = {"normal_force": float(sum(pt[9] for pt in points)),
                              "count": len(points)}
    feet = self._feet(b) if b.feet else None
    poses = None
    if b.pose_links:
        poses = {}
        for link in b.pose_links:
            at, turn = self.link_pose(b.name, link)
            poses[link] = {"position": at, "orientation": turn}
    return Observation(
        t=self.t, step=self.step_count, robot=b.name, motor_angles=angles,
        motor_velocities=velocities, motor_accelerations=accelerations,
        base_position=list(pos), base_orientation=list(orn), base_lin_vel=list(lin),
        base_ang_vel=list(ang), base_lin_vel_body_frame=list(rotate_back(matrix, lin)),
        base_ang_vel_body_frame=list(rotate_back(matrix, ang)), contacts=contacts,
        joint_forces=forces, motor_torques=torques, link_poses=poses, feet=feet)


def _feet(self: Any, b: _Body) -> dict[str, dict[str, Any]]:
    """Each foot's contact forces from everything but its own robot (world and local)."""
    p, client = self.session.p, self.session.client
    out: dict[str, dict[str, Any]] = {}
    for label, index in b.feet.items():
        normal = [0.0, 0.0, 0.0]
        friction = [0.0, 0.0, 0.0]
        total = 0.0
        count = 0
        for pt in p.getContactPoints(bodyA=b.body, linkIndexA=index,
                                     physicsClientId=client):
            if pt[2] == b.body:
                continue  # self-contact: not a ground reaction
            count += 1
            total += pt[9]
            # contactNormalOnB points from B to A: the push on the foot (A). The lateral
            # friction directions are those of the force on B (measured: a box sliding
            # along +x reads +mu m g), so the foot feels their opposite.
            for k in range(3):
                normal[k] += pt[9] * pt[7][k]
                friction[k] -= pt[10] * pt[11][k] + pt[12] * pt[13][k]
        if index == -1:  # the URDF frame, not the centre of mass
            orn = self.link_pose(b.name, next(k for k, v in b.links.items() if v == -1))[1]
        else:
            orn = p.getLinkState(b.body, index, computeForwardKinematics=True,
                                 physicsClientId=client)[5]
        local = rotate_back(quat_to_matrix(orn), normal)
        out[label] = {"contact": int(count > 0), "normal": total, "world": normal,
                      "local": list(local), "friction_world": friction}
    return out


def _report(self: Any, b: _Body) -> Observation:
    """What the robot reports now (delay, then noise); the same object all this step."""
    if b.reported is None or b.reported[0] != self.step_count:
        self._fresh(b)
        # history ends with the current observation; the delayed one is `delay` before.
        source = b.history[max(0, len(b.history) - 1 - b.config.delay)]
        if b.config.delay:  # angles and velocities are delayed; torques are not
            source = source._replace(motor_torques=b.history[-1].motor_torques)
        if b.config.delay or b.config.noise is not None:
            source = self._add_noise(b, source._replace(t=self.t, step=self.step_count))
        b.reported = (self.step_count, source)
        if b.reports is not None:
            b.reports.append(b.reported[1])
    return b.reported[1]


def _add_noise(self: Any, b: _Body, obs: Observation) -> Observation:
    """Independent Gaussian samples on the reported fields (standard deviations).

    Joint fields take one value for every joint or one per joint; base vectors one for
    every axis or one per axis. ``base_orientation`` is turned by a random rotation
    (roll, pitch, yaw drawn with those deviations), so it stays a unit quaternion.
    """
    noise = b.config.noise
    if noise is None:
        return obs
    gauss = b.rng.gauss
    changes: dict[str, Any] = {}
    for name in (*OBSERVATION_FIELDS, "motor_torques"):
        std = getattr(noise, name)
        value = getattr(obs, name)
        if value is None or not std:
            continue
        if isinstance(value, dict):
            changes[name] = {k: v + gauss(0.0, std.get(k, 0.0) if isinstance(std, dict)
                                          else std) for k, v in value.items()}
            continue
        axes = std if isinstance(std, list) else [std] * 3
        if name == "base_orientation":
            turn = rpy_to_quat(*(gauss(0.0, a) if a > 0 else 0.0 for a in axes))
            changes[name] = list(quat_mul(turn, value))
        else:
            changes[name] = [v + (gauss(0.0, a) if a > 0 else 0.0)
                             for v, a in zip(value, axes, strict=True)]
    return obs._replace(**changes)
