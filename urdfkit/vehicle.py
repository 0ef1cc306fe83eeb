"""Which joints of a loaded body are wheels and steering hinges, and driving them.

Detection works on the body PyBullet loaded, not on the XML, so it sees exactly the joint
indices the motors are addressed by:

- a **wheel** is a continuous joint (PyBullet reports those as ``JOINT_REVOLUTE`` with
  ``lower=0, upper=-1``; a revolute joint whose range covers a full turn counts too) whose
  axis is horizontal in the world at load time;
- a **steering hinge** is a revolute joint about a vertical axis with at least one wheel
  somewhere below it in the tree;
- every other movable joint is **passive**: its default velocity motor is switched off, or
  PyBullet would hold it still like a brake.

PyBullet gives a joint's axis in the child link's frame. To know whether it is horizontal we
need that frame's world orientation at load time: ``getLinkState``'s ``worldLinkFrameOrientation``,
or, composed from ``getJointInfo``'s ``parentFrameOrn`` and ``getDynamicsInfo``'s
local inertial frame only when ``getLinkState`` fails (bodies with 128 links or more).

Signs are part of detection. Positive throttle means "forward along the base's x axis" and
positive steer means "left, counter-clockwise seen from above", whatever way each joint's axis
points in the file: racecar.urdf's wheel axes point along -y, simplecar's along +y.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import Any

from .errors import ParameterError
from .spec import quat_to_matrix, rotate

#: |axis . z| below this is "horizontal" (about 11 degrees of tilt allowed).
HORIZONTAL_TOLERANCE = 0.2
#: |axis . z| above this is "vertical".
VERTICAL_TOLERANCE = 0.98

#: Hinge motor force (N m): PyBullet's own default for POSITION_CONTROL, which the tutorial
#: relies on. With the wheel force (10) instead, one hinge of simplecar stalls at 0.02 rad of
#: a 0.2 rad target while the tyres scrub: steering would silently not happen.
STEER_FORCE = 100000.0

_REVOLUTE = 0  # p.JOINT_REVOLUTE
_PRISMATIC = 1  # p.JOINT_PRISMATIC


class DrivetrainError(ParameterError):
    """The model has no wheels, or ``wheels``/``hinges`` name joints it does not have."""


@dataclass
class Drivetrain:
    """The driven joints of a body.

    Attributes:
        wheels: Joints driven with VELOCITY_CONTROL (continuous joints about a horizontal axis).
        hinges: Steering joints (revolute about a vertical axis, carrying wheels), driven with
            POSITION_CONTROL.
        passive: Other movable joints; their default motors are switched off.
        joint_names: Name of every joint index above.
        hinge_limits: ``(lower, upper)`` of each hinge, in the steer convention (positive =
            left); ``(-inf, inf)`` when the joint has no limits.
        wheel_signs: ``+1`` or ``-1`` per wheel: the factor that turns "forward" throttle into
            that joint's target velocity.
        hinge_signs: ``+1`` or ``-1`` per hinge: the factor that turns "left" steer into that
            joint's target position.
    """

    wheels: list[int]
    hinges: list[int]
    passive: list[int]
    joint_names: dict[int, str]
    hinge_limits: dict[int, tuple[float, float]]
    wheel_signs: dict[int, float] = field(default_factory=dict)
    hinge_signs: dict[int, float] = field(default_factory=dict)

    def steer_range(self) -> tuple[float, float]:
        """The steer angles every hinge can reach (the intersection of their limits)."""
        lo, hi = -math.inf, math.inf
        for lower, upper in self.hinge_limits.values():
            lo, hi = max(lo, lower), min(hi, upper)
        return lo, hi

    def to_dict(self) -> dict[str, Any]:
        """The JSON form: names keyed by joint index."""
        def named(joints: list[int]) -> list[dict[str, Any]]:
            return [{"index": j, "name": self.joint_names[j]} for j in joints]

        return {"wheels": named(self.wheels), "hinges": named(self.hinges),
                "passive": named(self.passive)}


def _rotate(orn: Sequence[float], v: Sequence[float]) -> tuple[float, float, float]:
    return rotate(quat_to_matrix(orn), v)


def _link_orientations(p: Any, body: int, client: int, infos: list[tuple[Any, ...]]
                       ) -> list[tuple[float, ...]]:
    """World orientation of each link's URDF frame (= its joint frame) at load time."""
    try:
        return [tuple(p.getLinkState(body, j, computeForwardKinematics=True,
                                     physicsClientId=client)[5]) for j in range(len(infos))]
    except p.error:
        pass
    # getLinkState fails on bodies with 128 links or more: compose the frames ourselves.
    # Measured on PyBullet 3.2.7: getJointInfo's parentFrameOrn is the *inverse* of the URDF
    # <origin rpy> (racecar.urdf's rpy="1.5708 0 0" comes back as -90 degrees about x), while
    # getLinkState agrees with the file; hence the invertTransform.
    _, base_com_orn = p.getBasePositionAndOrientation(body, physicsClientId=client)
    com: dict[int, tuple[float, ...]] = {-1: tuple(base_com_orn)}
    frames: list[tuple[float, ...]] = []
    for j, info in enumerate(infos):
        _, joint_orn = p.invertTransform((0, 0, 0), info[15])
        _, link_orn = p.multiplyTransforms((0, 0, 0), com[info[16]], (0, 0, 0), joint_orn)
        frames.append(tuple(link_orn))
        dyn = p.getDynamicsInfo(body, j, physicsClientId=client)
        _, com_orn = p.multiplyTransforms((0, 0, 0), link_orn, (0, 0, 0), dyn[4])
        com[j] = tuple(com_orn)
    return frames


def _is_continuous(info: tuple[Any, ...]) -> bool:
    lower, upper = info[8], info[9]
    return info[2] == _REVOLUTE and (lower > upper or upper - lower >= 2 * math.pi - 1e-6)


def _pick(spec: Sequence[str | int], names: dict[int, str], movable: list[int],
          what: str) -> list[int]:
    by_name = {n: j for j, n in names.items()}
    out: list[int] = []
    for item in spec:
        key = item.strip() if isinstance(item, str) else item
        if isinstance(key, str) and key.lstrip("-").isdigit():
            key = int(key)
        if isinstance(key, int):
            if key not in names:
                raise DrivetrainError(f"`{what}`: no joint with index {key} (the model has "
                                      f"joints 0..{len(names) - 1})", param=what)
            out.append(key)
        elif key in by_name:
            out.append(by_name[key])
        else:
            from .suggest import hint

            known = ", ".join(names.values()) or "none"
            raise DrivetrainError(f"`{what}`: no joint named {key!r}"
                                  f"{hint(str(key), names.values())} (joints: {known})",
                                  param=what)
        if out[-1] not in movable:
            raise DrivetrainError(f"`{what}`: joint {names[out[-1]]!r} is fixed and cannot "
                                  "be driven", param=what)
    return out


def detect_drivetrain(p: Any, body: int, client: int,
                      wheels: Sequence[str | int] | None = None,
                      hinges: Sequence[str | int] | None = None) -> Drivetrain:
    """Find the wheels, steering hinges and passive joints of a freshly loaded body.

    Call it before the first ``stepSimulation``: "horizontal" and "vertical" are judged from
    the pose at load time, with every joint at zero.

    Args:
        p: The pybullet module.
        body: The body id.
        client: The physics client id.
        wheels: Joint names or indices to drive instead of the detected wheels.
        hinges: Joint names or indices to steer instead of the detected hinges.

    Raises:
        DrivetrainError: no wheels were found (or given), or a name/index is unknown.
    """
    n = p.getNumJoints(body, physicsClientId=client)
    infos = [p.getJointInfo(body, j, physicsClientId=client) for j in range(n)]
    names = {j: info[1].decode("utf-8", "replace") for j, info in enumerate(infos)}
    movable = [j for j, info in enumerate(infos) if info[2] in (_REVOLUTE, _PRISMATIC)]
    frames = _link_orientations(p, body, client, infos)
    axes = {j: _rotate(frames[j], infos[j][13]) for j in movable}
    _, base_orn = p.getBasePositionAndOrientation(body, physicsClientId=client)
    forward = _rotate(base_orn, (1.0, 0.0, 0.0))

    if wheels is not None:
        wheel_list = _pick(wheels, names, movable, "wheels")
    else:
        wheel_list = [j for j in movable if _is_continuous(infos[j])
                      and abs(axes[j][2]) < HORIZONTAL_TOLERANCE]
    if not wheel_list:
        raise DrivetrainError("no wheels found: a wheel is a continuous joint about a "
                              "horizontal axis; name them with `wheels`")
    if hinges is not None:
        hinge_list = _pick(hinges, names, movable, "hinges")
    else:
        wheel_set = set(wheel_list)

        def carries_wheel(j: int) -> bool:
            for w in wheel_set:
                k = infos[w][16]
                while k >= 0:
                    if k == j:
                        return True
                    k = infos[k][16]
            return False

        hinge_list = [j for j in movable if j not in wheel_set and infos[j][2] == _REVOLUTE
                      and abs(axes[j][2]) > VERTICAL_TOLERANCE and carries_wheel(j)]
    overlap = set(wheel_list) & set(hinge_list)
    if overlap:
        raise DrivetrainError(f"joint {names[min(overlap)]!r} cannot be both a wheel and a hinge")

    wheel_signs: dict[int, float] = {}
    for j in wheel_list:
        a = axes.get(j, (0.0, 1.0, 0.0))
        # A wheel spinning positively about axis a moves the car along a x z.
        along = a[1] * forward[0] - a[0] * forward[1]
        wheel_signs[j] = -1.0 if along < 0 else 1.0
    hinge_signs: dict[int, float] = {}
    hinge_limits: dict[int, tuple[float, float]] = {}
    for j in hinge_list:
        sign = -1.0 if axes.get(j, (0.0, 0.0, 1.0))[2] < 0 else 1.0
        hinge_signs[j] = sign
        lower, upper = infos[j][8], infos[j][9]
        if lower > upper:
            hinge_limits[j] = (-math.inf, math.inf)
        else:
            ends = sorted((lower * sign, upper * sign))
            hinge_limits[j] = (ends[0], ends[1])
    driven = set(wheel_list) | set(hinge_list)
    passive = [j for j in movable if j not in driven]
    return Drivetrain(wheel_list, hinge_list, passive, names, hinge_limits,
                      wheel_signs, hinge_signs)


def disable_default_motors(p: Any, body: int, client: int, joints: Sequence[int]) -> None:
    """Switch off PyBullet's default velocity motors on ``joints``.

    PyBullet gives every revolute and prismatic joint a velocity motor with target 0 at load
    time; left on, it brakes the joint. Force 0 frees it (and makes the first step of large
    bodies fast).
    """
    if not joints:
        return
    p.setJointMotorControlArray(body, list(joints), p.VELOCITY_CONTROL,
                                targetVelocities=[0.0] * len(joints),
                                forces=[0.0] * len(joints), physicsClientId=client)


def apply_drive(p: Any, body: int, client: int, train: Drivetrain, throttle: float,
                steer: float, max_force: float, steer_force: float = STEER_FORCE) -> None:
    """Set the wheel and hinge motors once; PyBullet keeps them until they are changed.

    Args:
        p: The pybullet module.
        body: The body id.
        client: The physics client id.
        train: What :func:`detect_drivetrain` found.
        throttle: Target wheel angular velocity, rad/s (positive = forward).
        steer: Target hinge angle, rad (positive = left). Callers clamp it to
            :meth:`Drivetrain.steer_range` first.
        max_force: Maximum torque (N m) of every wheel motor.
        steer_force: Maximum torque (N m) of every hinge motor.
    """
    if train.wheels:
        p.setJointMotorControlArray(
            body, train.wheels, p.VELOCITY_CONTROL,
            targetVelocities=[throttle * train.wheel_signs.get(j, 1.0) for j in train.wheels],
            forces=[max_force] * len(train.wheels), physicsClientId=client)
    if train.hinges:
        p.setJointMotorControlArray(
            body, train.hinges, p.POSITION_CONTROL,
            targetPositions=[steer * train.hinge_signs.get(j, 1.0) for j in train.hinges],
            forces=[steer_force] * len(train.hinges), physicsClientId=client)
