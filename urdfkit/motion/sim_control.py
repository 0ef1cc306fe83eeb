"""Controllers: what turns a robot's command into motor settings, every physics step.

A robot's command at time t is its override (``Simulation.set_drive``,
``set_joint_targets``), else its scenario segment (:meth:`SimRobot.command`). Two controllers
apply it, both behind :class:`Controller`:

- :class:`MotorControl`: the engine's own motors, set when the command changes (they
  persist), torques every step (they last one);
- :class:`ServoControl`: the servo model, a torque law every step.
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING, Protocol

from urdfkit.motion.sim_robot import SimRobot
from urdfkit.motion.sim_state import Command

if TYPE_CHECKING:
    from urdfkit.engine.api import Simulator
    from urdfkit.motion.scenario_models import Motor
    from urdfkit.motion.sim_dynamics import Dynamics
    from urdfkit.motion.sim_sensors import Sensors


class Controller(Protocol):
    """Applies a robot's command before a physics step."""

    def control(self, robot: SimRobot, t: float) -> None:
        """Set ``robot``'s motors for the step starting at time ``t``."""


class MotorControl:
    """The engine's motors: a drive train's wheels and hinges, or joint targets."""

    def __init__(self, engine: Simulator) -> None:
        self.engine = engine

    def control(self, robot: SimRobot, t: float) -> None:
        """Set the motors when the command changes; re-apply torques every step."""
        cmd = robot.command(t)
        if cmd != robot.applied:
            robot.release()
            if cmd is not None and cmd.kind == "drive":
                self._drive(robot, cmd)
            elif cmd is not None:
                self._motors(robot, cmd, torque=False)  # motors persist: set on change
            robot.applied = cmd
        if cmd is not None and cmd.any_torque:
            self._motors(robot, cmd, torque=True)  # torques last one step only

    def _drive(self, robot: SimRobot, cmd: Command) -> None:
        from urdfkit.motion.vehicle import apply_drive, clamp_steer

        train = robot.train
        assert train is not None
        vehicle = robot.config.vehicle
        max_force = vehicle.max_force if vehicle else 10.0
        # Motors persist: set once per change of command.
        apply_drive(self.engine, robot.body, train, cmd.throttle,
                    clamp_steer(train, cmd.steer)[0], max_force)
        if robot.dry_friction:  # apply_drive frees the undriven wheels
            robot.free([i for i in train.free if i in robot.dry_friction])

    def _motors(self, robot: SimRobot, cmd: Command, *, torque: bool) -> None:
        """The engine's own motors for a ``joints`` command (no servo model), joint by joint.

        ``torque``: the torque targets (every step), else the position and velocity ones.
        """
        motors = self.engine.motors
        for name, target in cmd.targets.items():
            mode = cmd.mode_of(name)
            if (mode == "torque") != torque:
                continue
            spec = robot.joint(name)
            sign = robot.directions.get(name, 1.0)
            if mode == "torque":
                motors(robot.body, [spec.index], "torque", [target * sign])
                robot.torques[name] = target * sign
                continue
            force = cmd.max_force or (spec.effort if spec.effort > 0 else None)
            limit = None if force is None else [force]  # None: the engine's default cap
            if mode == "position":
                motors(robot.body, [spec.index], "position",
                       [robot.to_physical(name, target)], forces=limit,
                       velocities=[cmd.velocities.get(name, 0.0) * sign])
            else:
                motors(robot.body, [spec.index], "velocity", [target * sign], forces=limit)


def _per_joint(value: float | dict[str, float], name: str) -> float:
    return value.get(name, 0.0) if isinstance(value, dict) else value


class ServoControl:
    """The servo model: a PD law plus viscous friction, a spring and rotor inertia.

    In the measured frame (offsets and directions applied), per joint::

        tau = -kp (q - q_des) - kd (qd - qd_des) + e - J qdd,   e = -b qd - k q

    clipped to the effort limit (or ``max_torque``; not at all when "unlimited"). With
    ``scale_by_mass_matrix`` the friction and spring terms are ``M(q) e`` instead of
    ``e`` (simulation_and_control's servo; M over the servo joints, at the true state).
    A position target sets q_des and qd_des (the segment's ``velocities``, default 0); a
    velocity target sets qd_des and drops the kp term; a torque target is added as is.
    Joints without a target feel only friction, the spring and the inertia. With
    ``measured_state`` the law reads the reported state (delayed, noisy) instead of the
    true one, as a real robot's servo does; ``qdd`` is the last measured acceleration.
    """

    def __init__(self, engine: Simulator, sensors: Sensors, dynamics: Dynamics) -> None:
        self.engine = engine
        self.sensors = sensors
        self.dynamics = dynamics

    @staticmethod
    def needs_mass_matrix(robot: SimRobot) -> bool:
        """Whether the law takes the mass matrix: scaled friction or a scaled spring."""
        m = robot.config.motor
        return m is not None and m.scale_by_mass_matrix and any(
            _per_joint(m.viscous_friction, spec.name) or _per_joint(m.stiffness, spec.name)
            for spec in robot.servo)

    def control(self, robot: SimRobot, t: float) -> None:
        """The servo's torques for this step, under the command in force."""
        cmd = robot.command(t)
        if cmd != robot.applied:
            robot.release()
            robot.applied = cmd
        self._apply(robot, cmd)

    def _state(self, robot: SimRobot, m: Motor
               ) -> tuple[dict[str, tuple[float, float]], dict[str, float]]:
        """Each servo joint's (q, qd) and the accelerations the law reads, measured frame."""
        if m.measured_state:
            seen = self.sensors.observe(robot)
            return ({spec.name: (seen.motor_angles[spec.name], seen.motor_velocities[spec.name])
                     for spec in robot.servo}, seen.motor_accelerations)
        states = self.engine.joint_rows(robot.body, [j.index for j in robot.servo])
        state_of = {}
        for spec, st in zip(robot.servo, states, strict=True):
            sign = robot.directions.get(spec.name, 1.0)
            state_of[spec.name] = ((st[0] - robot.offsets.get(spec.name, 0.0)) * sign,
                                   st[1] * sign)
        qdds = self.sensors.fresh(robot).motor_accelerations if m.inertia else {}
        return state_of, qdds

    def _apply(self, robot: SimRobot, cmd: Command | None) -> None:
        m = robot.config.motor
        assert m is not None
        state_of, qdds = self._state(robot, m)
        extra = [-_per_joint(m.viscous_friction, spec.name) * state_of[spec.name][1]
                 - _per_joint(m.stiffness, spec.name) * state_of[spec.name][0]
                 for spec in robot.servo]
        if m.scale_by_mass_matrix and any(extra):
            extra = self.dynamics.times_mass_matrix(robot, extra)
        joints = cmd is not None and cmd.kind == "joints"
        targets = cmd.targets if cmd is not None and joints else {}
        velocities = cmd.velocities if cmd is not None and joints else {}
        torques = []
        for spec, tau in zip(robot.servo, extra, strict=True):
            q, qd = state_of[spec.name]
            if m.inertia:
                tau -= m.inertia * qdds.get(spec.name, 0.0)
            if spec.name in targets:
                target = targets[spec.name]
                mode = cmd.mode_of(spec.name) if cmd is not None else "position"
                kd = _per_joint(robot.kd, spec.name)
                if mode == "position":
                    tau += -_per_joint(robot.kp, spec.name) * (q - target) \
                        - kd * (qd - velocities.get(spec.name, 0.0))
                elif mode == "velocity":
                    tau += -kd * (qd - target)
                else:
                    tau += target
            limit = math.inf if m.max_torque == "unlimited" else \
                m.max_torque or (spec.effort if spec.effort > 0 else math.inf)
            tau = min(max(tau, -limit), limit)
            torques.append(tau * robot.directions.get(spec.name, 1.0))
        self.engine.motors(robot.body, [j.index for j in robot.servo], "torque", torques)
        robot.torques.update(zip((spec.name for spec in robot.servo), torques, strict=True))
