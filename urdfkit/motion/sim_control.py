"""Control: the schedule, the motors, the servo model.

Methods of :class:`urdfkit.sim.Simulation`, split out of :mod:`urdfkit.sim`: each function
takes the simulation as ``self`` and is bound as a method of ``Simulation`` (a class
attribute), so a call costs what a method defined in the class costs.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from typing import Any

from urdfkit.motion.sim_state import _Body, _Command


def _scheduled(self: Any, b: _Body) -> _Command | None:
    """The segment in force at the current time; the last one holds after it ends."""
    t = self.t
    if b.config.drive is not None:
        segs = b.config.drive
        seg = next((s for s in segs if t < s.until - 1e-9), segs[-1])
        return _Command("drive", throttle=seg.throttle, steer=seg.steer)
    if b.config.joints is not None:
        segs = b.config.joints
        seg = next((s for s in segs if t < s.until - 1e-9), segs[-1])
        mode = dict(seg.mode) if isinstance(seg.mode, dict) else seg.mode
        return _Command("joints", mode=mode, targets=dict(seg.targets),
                        max_force=seg.max_force, velocities=dict(seg.velocities))
    return None


def _control(self: Any, b: _Body) -> None:
    cmd = b.override or self._scheduled(b)
    if cmd != b.applied:
        if b.applied is not None:
            # Free every joint before the new command: a position motor set by the last
            # segment would otherwise keep fighting a torque command.
            self._free(b)
            b.torques.clear()
        if cmd is not None and cmd.kind == "drive":
            from urdfkit.motion.vehicle import apply_drive, clamp_steer

            max_force = b.config.vehicle.max_force if b.config.vehicle else 10.0
            # Motors persist in PyBullet: set once per change of command.
            apply_drive(self.session.bullet, b.body, b.train, cmd.throttle,
                        clamp_steer(b.train, cmd.steer)[0], max_force)
            if b.dry_friction:  # apply_drive frees the undriven wheels
                self._free(b, [i for i in b.train.free if i in b.dry_friction])
        elif cmd is not None and not b.servo:
            self._apply_motors(b, cmd, torque=False)  # motors persist: set on change
        b.applied = cmd
    if cmd is not None and cmd.any_torque and not b.servo:
        self._apply_motors(b, cmd, torque=True)  # torques last one step only
    if b.servo:
        self._apply_servo(b, cmd)


def _free(self: Any, b: _Body, indices: Sequence[int] | None = None) -> None:
    """Switch PyBullet's velocity motors to their joints' dry friction (0: free).

    A velocity motor with target 0 and a force limit is Coulomb friction: it holds the
    joint against up to that much torque and slows it by that much when it moves. It
    works alongside TORQUE_CONTROL (the servo); PyBullet's position and velocity
    commands use the same motor and replace it while they drive the joint.
    """
    p, client = self.session.p, self.session.client
    joints = [j.index for j in b.active] if indices is None else list(indices)
    if joints:
        p.setJointMotorControlArray(
            b.body, joints, p.VELOCITY_CONTROL, targetVelocities=[0.0] * len(joints),
            forces=[b.dry_friction.get(j, 0.0) for j in joints], physicsClientId=client)


def _apply_motors(self: Any, b: _Body, cmd: _Command, *, torque: bool) -> None:
    """PyBullet's own motors for a ``joints`` command (no servo model).

    ``torque``: the torque targets (every step), else the position and velocity ones.
    """
    p, client = self.session.p, self.session.client
    for name, target in cmd.targets.items():
        mode = cmd.mode_of(name)
        if (mode == "torque") != torque:
            continue
        spec = b.joint(name)
        sign = b.directions.get(name, 1.0)
        if mode == "torque":
            p.setJointMotorControl2(b.body, spec.index, p.TORQUE_CONTROL,
                                    force=target * sign, physicsClientId=client)
            b.torques[name] = target * sign
            continue
        force = cmd.max_force or (spec.effort if spec.effort > 0 else None)
        kwargs: dict[str, Any] = {} if force is None else {"force": force}
        if mode == "position":
            p.setJointMotorControl2(b.body, spec.index, p.POSITION_CONTROL,
                                    targetPosition=self._to_physical(b, name, target),
                                    targetVelocity=cmd.velocities.get(name, 0.0) * sign,
                                    physicsClientId=client, **kwargs)
        else:
            p.setJointMotorControl2(b.body, spec.index, p.VELOCITY_CONTROL,
                                    targetVelocity=target * sign,
                                    physicsClientId=client, **kwargs)


def _apply_servo(self: Any, b: _Body, cmd: _Command | None) -> None:
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
    p, client = self.session.p, self.session.client
    m = b.config.motor
    indices = [j.index for j in b.servo]
    if m.measured_state:
        seen = self._observe_one(b.name)
        state_of = {spec.name: (seen.motor_angles[spec.name],
                                seen.motor_velocities[spec.name]) for spec in b.servo}
        qdds = seen.motor_accelerations
    else:
        states = p.getJointStates(b.body, indices, physicsClientId=client)
        state_of = {}
        for spec, st in zip(b.servo, states, strict=True):
            sign = b.directions.get(spec.name, 1.0)
            state_of[spec.name] = ((st[0] - b.offsets.get(spec.name, 0.0)) * sign,
                                   st[1] * sign)
        qdds = self._fresh(b).motor_accelerations if m.inertia else {}

    def per_joint(value: float | dict[str, float], name: str) -> float:
        return value.get(name, 0.0) if isinstance(value, dict) else value

    extra = [-per_joint(m.viscous_friction, spec.name) * state_of[spec.name][1]
             - per_joint(m.stiffness, spec.name) * state_of[spec.name][0]
             for spec in b.servo]
    if m.scale_by_mass_matrix and any(extra):
        extra = self._times_mass_matrix(b, extra)
    torques = []
    targets = cmd.targets if cmd is not None and cmd.kind == "joints" else {}
    velocities = cmd.velocities if cmd is not None and cmd.kind == "joints" else {}
    for spec, tau in zip(b.servo, extra, strict=True):
        q, qd = state_of[spec.name]
        if m.inertia:
            tau -= m.inertia * qdds.get(spec.name, 0.0)
        if spec.name in targets:
            target = targets[spec.name]
            mode = cmd.mode_of(spec.name) if cmd is not None else "position"
            kd = per_joint(b.kd, spec.name)
            if mode == "position":
                tau += -per_joint(b.kp, spec.name) * (q - target) \
                    - kd * (qd - velocities.get(spec.name, 0.0))
            elif mode == "velocity":
                tau += -kd * (qd - target)
            else:
                tau += target
        limit = math.inf if m.max_torque == "unlimited" else \
            m.max_torque or (spec.effort if spec.effort > 0 else math.inf)
        tau = min(max(tau, -limit), limit)
        torques.append(tau * b.directions.get(spec.name, 1.0))
    p.setJointMotorControlArray(b.body, indices, p.TORQUE_CONTROL, forces=torques,
                                physicsClientId=client)
    b.torques.update(zip((spec.name for spec in b.servo), torques, strict=True))


def _times_mass_matrix(self: Any, b: _Body, vector: list[float]) -> list[float]:
    """``D M D v`` for the servo joints: M(q) at the true state, in the measured frame.

    With ``mass_matrix_angles = "measured"`` (simulation_and_control's servo): ``M v``
    with M from calculateMassMatrix given the measured angles ``(q - offset) * direction``
    as if they were joint angles, and no ``D``; the same as ``D M D v`` when every offset
    is 0 and every direction 1.
    """
    dyn = self._dynamics_joints(b)
    q, _ = self._physical_state(b)
    measured = b.config.motor is not None and \
        b.config.motor.mass_matrix_angles == "measured"
    if measured:
        q = [(x - b.offsets.get(j.name, 0.0)) * b.directions.get(j.name, 1.0)
             for x, j in zip(q, dyn, strict=True)]
    p, client, body = self._model(b)
    matrix = p.calculateMassMatrix(body, q, physicsClientId=client)
    skip = len(matrix) - len(dyn)  # a floating base's 6 coordinates come first
    where = {j.name: skip + k for k, j in enumerate(dyn)}
    rows = [where[spec.name] for spec in b.servo]
    if measured and rows == list(range(skip, skip + len(rows))):
        # As simulation_and_control computes it, to the last bit: a floating base's
        # matrix at the base's true pose (flags=1 takes position and quaternion first;
        # the quaternion's 4th row and column are zero and dropped), and numpy's matrix
        # product (whose rounding differs from an exact sum by an ulp or two).
        import numpy as np

        if skip:
            pos, orn = self.session.p.getBasePositionAndOrientation(
                b.body, physicsClientId=self.session.client)
            full = np.asarray(p.calculateMassMatrix(body, [*pos, *orn, *q], flags=1,
                                                    physicsClientId=client))
            full = np.delete(np.delete(full, 6, 0), 6, 1)
        else:
            full = np.asarray(matrix)
        block = full[skip:, skip:][:len(rows), :len(rows)]
        return [float(x) for x in block @ np.asarray(vector, dtype=float)]
    signs = [1.0 if measured else b.directions.get(spec.name, 1.0) for spec in b.servo]
    return [signs[i] * math.fsum(matrix[r][c] * signs[k] * vector[k]
                                 for k, c in enumerate(rows))
            for i, r in enumerate(rows)]
