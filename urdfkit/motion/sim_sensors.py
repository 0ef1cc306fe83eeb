"""Sensors: measuring a robot, its feet, noise, delay and history.

:class:`Sensors` measures the world's robots when an observation is due and keeps what each
reports in its :class:`~urdfkit.motion.sim_robot.Readings`: the true observations (as many as
its ``delay`` and ``history`` need), and the reported one of the step (delay, then noise).
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from urdfkit.model.spec import quat_mul, quat_to_matrix, rotate_back, rpy_to_quat
from urdfkit.motion.scenario import OBSERVATION_FIELDS
from urdfkit.motion.sim_state import FootReading, Observation

if TYPE_CHECKING:
    from urdfkit.motion.sim_robot import SimRobot
    from urdfkit.motion.sim_world import World



class Sensors:
    """What the world's robots measure and report."""

    def __init__(self, world: World) -> None:
        self.world = world

    def start(self) -> None:
        """Every robot's first true observation (the state a delayed robot reports at first)."""
        for r in self.world.robots.values():
            r.readings.history.append(self.measure(r))

    def keep_velocities(self, r: SimRobot) -> None:
        """Remember the joint velocities now, for the next measurement's accelerations."""
        states = self.world.engine.joint_rows(r.body, r.frame[0])
        r.readings.previous_velocities = [st[1] for st in states]
        r.readings.previous_step = self.world.step_count

    def fresh(self, r: SimRobot) -> Observation:
        """The true observation at this step, measuring it now if it was not yet."""
        history = r.readings.history
        if history[-1].step != self.world.step_count:
            history.append(self.measure(r))
        return history[-1]

    def measure(self, r: SimRobot) -> Observation:
        """The true observation now, in the measured joint frame."""
        world = self.world
        engine, step = world.engine, world.step_count
        base = engine.base_state(r.body)
        pos, orn, lin, ang = base.position, base.orientation, base.linear, base.angular
        matrix = quat_to_matrix(orn)
        angles: dict[str, float] = {}
        velocities: dict[str, float] = {}
        accelerations: dict[str, float] = {}
        torques: dict[str, float] | None = None
        if r.active:
            indices, names, signs, offsets = r.frame
            states = engine.joint_rows(r.body, indices)
            if world.config.record.motor_torques:  # the joint's own frame, as applied
                torques = {n: r.torques.get(n, st[3])
                           for n, st in zip(names, states, strict=True)}
            qd = [st[1] for st in states]
            angles = {n: (st[0] - o) * s
                      for n, st, s, o in zip(names, states, signs, offsets, strict=True)}
            velocities = {n: v * s for n, v, s in zip(names, qd, signs, strict=True)}
            readings = r.readings
            # Over the time since the velocities were last taken (one step, when recording).
            span = (step - readings.previous_step) * world.time_step
            before = readings.previous_velocities
            if before is None or span <= 0:
                accelerations = dict.fromkeys(names, 0.0)
            else:
                accelerations = {n: (v - v0) * s / span for n, v, v0, s
                                 in zip(names, qd, before, signs, strict=True)}
            readings.previous_velocities = qd
            readings.previous_step = step
        # In this order (the engine's queries as they always were made).
        forces = self._forces(r) if r.force_joints else None
        contacts = self._contacts(r) if r.contact_links else None
        feet = self._feet(r) if r.feet else None
        poses = self._poses(r) if r.pose_links else None
        return Observation(
            t=step * world.time_step, step=step, robot=r.name, motor_angles=angles,
            motor_velocities=velocities, motor_accelerations=accelerations,
            base_position=list(pos), base_orientation=list(orn), base_lin_vel=list(lin),
            base_ang_vel=list(ang), base_lin_vel_body_frame=list(rotate_back(matrix, lin)),
            base_ang_vel_body_frame=list(rotate_back(matrix, ang)), contacts=contacts,
            joint_forces=forces, motor_torques=torques, link_poses=poses, feet=feet)

    def _forces(self, r: SimRobot) -> dict[str, list[float]]:
        rows = self.world.engine.joint_rows(r.body, list(r.force_joints.values()))
        return {name: [float(x) for x in row[2]]
                for name, row in zip(r.force_joints, rows, strict=True)}

    def _contacts(self, r: SimRobot) -> dict[str, dict[str, float]]:
        engine, ground = self.world.engine, self.world.ground
        contacts = {}
        for link, index in r.contact_links.items():
            points = engine.contacts(r.body, index, ground)
            contacts[link] = {"normal_force": float(sum(pt.normal_force for pt in points)),
                              "count": len(points)}
        return contacts

    def _poses(self, r: SimRobot) -> dict[str, dict[str, list[float]]]:
        poses = {}
        for link in r.pose_links:
            at, turn = r.link_pose(link)
            poses[link] = {"position": at, "orientation": turn}
        return poses

    def _feet(self, r: SimRobot) -> dict[str, FootReading]:
        """Each foot's contact forces from everything but its own robot (world and local)."""
        engine = self.world.engine
        out: dict[str, FootReading] = {}
        for label, index in r.feet.items():
            normal = [0.0, 0.0, 0.0]
            friction = [0.0, 0.0, 0.0]
            total = 0.0
            count = 0
            for pt in engine.contacts(r.body, index):
                if pt.body_b == r.body:
                    continue  # self-contact: not a ground reaction
                count += 1
                total += pt.normal_force
                # The normal points from B to A: the push on the foot (A). The lateral
                # friction directions are those of the force on B (measured: a box sliding
                # along +x reads +mu m g), so the foot feels their opposite.
                for k in range(3):
                    normal[k] += pt.normal_force * pt.normal[k]
                    friction[k] -= pt.friction1 * pt.direction1[k] + \
                        pt.friction2 * pt.direction2[k]
            if index == -1:  # the URDF frame, not the centre of mass
                orn = r.link_pose(next(k for k, v in r.links.items() if v == -1))[1]
            else:
                orn = list(engine.link_frame(r.body, index)[1])
            local = rotate_back(quat_to_matrix(orn), normal)
            out[label] = {"contact": int(count > 0), "normal": total, "world": normal,
                          "local": list(local), "friction_world": friction}
        return out

    # ---- what a robot reports

    def report(self, r: SimRobot) -> Observation:
        """What the robot reports now (delay, then noise); the same object all this step."""
        readings, step = r.readings, self.world.step_count
        if readings.reported is None or readings.reported[0] != step:
            self.fresh(r)
            delay = r.config.delay
            history = readings.history
            # history ends with the current observation; the delayed one is `delay` before.
            source = history[max(0, len(history) - 1 - delay)]
            if delay:  # angles and velocities are delayed; torques are not
                source = source._replace(motor_torques=history[-1].motor_torques)
            if delay or r.config.noise is not None:
                source = self._add_noise(r, source._replace(t=self.world.t, step=step))
            readings.reported = (step, source)
            if readings.reports is not None:
                readings.reports.append(source)
        return readings.reported[1]

    def observe(self, r: SimRobot, *, ideal: bool = False) -> Observation:
        """A copy of the observation now: as reported (delay, then noise) or ``ideal``."""
        self.fresh(r)
        if ideal:
            return r.readings.history[-1].copy()
        # A copy: a caller changing what it got must not change later observations.
        return self.report(r).copy()

    def history(self, r: SimRobot, *, ideal: bool = False) -> list[Observation]:
        """The robot's last ``history`` observations, oldest first (copies)."""
        readings = r.readings
        if ideal:
            self.fresh(r)
            return [o.copy() for o in list(readings.history)[-r.config.history:]]
        self.report(r)
        if readings.reports is None:
            return [readings.reported[1].copy()] if readings.reported is not None else []
        return [o.copy() for o in readings.reports]

    def _add_noise(self, r: SimRobot, obs: Observation) -> Observation:
        """Independent Gaussian samples on the reported fields (standard deviations).

        Joint fields take one value for every joint or one per joint; base vectors one for
        every axis or one per axis. ``base_orientation`` is turned by a random rotation
        (roll, pitch, yaw drawn with those deviations), so it stays a unit quaternion.
        """
        noise = r.config.noise
        if noise is None:
            return obs
        gauss = r.readings.rng.gauss
        changes: dict[str, object] = {}
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
