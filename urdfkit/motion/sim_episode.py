"""Episodes: the start of one robot for one episode (``Simulation.reset(overrides=...)``).

:func:`reset_plan` checks a robot's overrides and turns them into the engine calls that
start it there; ``Simulation.reset`` checks every robot's before it restores anything.
"""

from __future__ import annotations

import functools
import math
from collections.abc import Callable, Mapping
from typing import TYPE_CHECKING

from urdfkit.core.errors import ParameterError
from urdfkit.model.spec import UP_AXES, quat_mul, rpy_to_quat

if TYPE_CHECKING:
    from urdfkit.motion.sim_robot import SimRobot

#: The keys ``overrides`` takes per robot.
OVERRIDE_KEYS = ("initial_joints", "position", "orientation_rpy", "orientation_quat",
                 "base_velocity", "base_angular_velocity")


def _vector(r: SimRobot, changes: Mapping[str, object], key: str, size: int
            ) -> list[float] | None:
    value = changes.get(key)
    if value is None:
        return None
    try:
        out = [float(v) for v in value]  # type: ignore[attr-defined]
    except (TypeError, ValueError):
        out = []
    if len(out) != size or not all(math.isfinite(v) for v in out):
        raise ParameterError(f"`overrides`: {r.name}.{key} needs {size} finite "
                             "numbers", param="overrides")
    return out


def _number(r: SimRobot, joint: str, value: object) -> float:
    if not isinstance(value, (int, float, str)):
        raise ParameterError(f"`overrides`: {r.name}.initial_joints.{joint} needs a number",
                             param="overrides")
    return float(value)


def _joint_calls(r: SimRobot, joints: Mapping[str, object]) -> list[Callable[[], None]]:
    calls: list[Callable[[], None]] = []
    for name, value in joints.items():
        spec = next((j for j in r.active if j.name == name), None)
        if spec is None:
            raise ParameterError(f"`overrides`: {r.name} has no active joint named "
                                 f"{name!r}", param="overrides")
        position, velocity = (value.get("position", 0.0), value.get("velocity", 0.0)) \
            if isinstance(value, Mapping) else (value, 0.0)
        q = r.to_physical(name, _number(r, name, position))
        qd = _number(r, name, velocity) * r.directions.get(name, 1.0)
        calls.append(functools.partial(r.engine.reset_joint, r.body, spec.index, q, qd))
    return calls


def _pose_call(r: SimRobot, position: list[float] | None, rpy: list[float] | None,
               quat: list[float] | None) -> Callable[[], None]:
    engine, cfg = r.engine, r.config
    if quat is None:
        quat = list(rpy_to_quat(*rpy)) if rpy is not None else \
            list(cfg.orientation_quat) if cfg.orientation_quat is not None else \
            list(rpy_to_quat(*(cfg.orientation_rpy or (0.0, 0.0, 0.0))))
    norm = math.sqrt(math.fsum(v * v for v in quat))
    if norm < 1e-12:
        raise ParameterError(f"`overrides`: {r.name}.orientation_quat must not be all "
                             "zeros", param="overrides")
    orn = quat_mul([v / norm for v in quat], UP_AXES[cfg.up])
    given = position if position is not None else list(cfg.position)
    at = (given[0], given[1], given[2])
    if cfg.pose_frame == "link":  # a reset of the base places its centre of mass
        return functools.partial(engine.reset_base_frame, r.body, at, orn)
    return functools.partial(engine.reset_base, r.body, at, orn)


def reset_plan(r: SimRobot, changes: Mapping[str, object]) -> list[Callable[[], None]]:
    """The engine calls that start ``r`` as ``changes`` says, checked before any runs."""
    for key in changes:
        if key not in OVERRIDE_KEYS:
            raise ParameterError(f"`overrides`: unknown key {key!r} for {r.name}; known "
                                 f"keys: {', '.join(OVERRIDE_KEYS)}", param="overrides")
    joints = changes.get("initial_joints") or {}
    if not isinstance(joints, Mapping):
        raise ParameterError(f"`overrides`: {r.name}.initial_joints needs joint names to "
                             "positions", param="overrides")
    calls = _joint_calls(r, joints)
    position = _vector(r, changes, "position", 3)
    rpy = _vector(r, changes, "orientation_rpy", 3)
    quat = _vector(r, changes, "orientation_quat", 4)
    if rpy is not None and quat is not None:
        raise ParameterError(f"`overrides`: give {r.name} orientation_rpy or "
                             "orientation_quat, not both", param="overrides")
    if position is not None or rpy is not None or quat is not None:
        calls.append(_pose_call(r, position, rpy, quat))
    lin = _vector(r, changes, "base_velocity", 3)
    ang = _vector(r, changes, "base_angular_velocity", 3)
    if lin is not None or ang is not None:
        velocity = (lin if lin is not None else list(r.config.base_velocity),
                    ang if ang is not None else list(r.config.base_angular_velocity))
        lin, ang = velocity
        calls.append(functools.partial(r.engine.reset_base_velocity, r.body,
                                       (lin[0], lin[1], lin[2]), (ang[0], ang[1], ang[2])))
    return calls
