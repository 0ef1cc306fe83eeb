"""Episodes: reset in place and randomisation.

Methods of :class:`urdfkit.sim.Simulation`, split out of :mod:`urdfkit.sim`: each function
takes the simulation as ``self`` and is bound as a method of ``Simulation`` (a class
attribute), so a call costs what a method defined in the class costs.
"""

from __future__ import annotations

import functools
import math
import random
from collections.abc import Callable, Mapping
from typing import Any

from urdfkit.core.errors import ParameterError
from urdfkit.engine.session import restore_clean
from urdfkit.model.spec import UP_AXES, quat_mul, rpy_to_quat
from urdfkit.motion.sim_state import _Body


def _robot_seed(seed: int, i: int) -> int:
    return seed * 1_000_003 + i


def reset(self: Any, seed: int | None = None,  # noqa: D417 (self: the Simulation)
          overrides: Mapping[str, Mapping[str, Any]] | None = None) -> None:
    """Go back to the starting state in place, deterministically.

    Positions, velocities and contacts come back through PyBullet's saveState and
    restoreState; time, observation history, delays, commands and noise generators
    (reseeded with ``seed``, default the scenario's) start over, so the same seed and the
    same actions give the same observations. Changes made with the ``set_*`` methods
    stay: they change the robot, not its state.

    Args:
        seed: Reseeds the noise; default: the scenario's ``seed``.
        overrides: Per robot name, a different start for this episode, with the
            scenario's keys and meanings: ``initial_joints`` (joint -> position, or ->
            ``{"position", "velocity"}``; measured frame), ``position`` and
            ``orientation_rpy`` or ``orientation_quat`` (in the robot's ``pose_frame``),
            ``base_velocity`` and ``base_angular_velocity``. What is not given is the
            scenario's start.

    Raises:
        ParameterError: an unknown robot, key or joint, or a value of the wrong shape;
            nothing is reset then.
    """
    p, client = self.session.p, self.session.client
    plans = {self._body(robot).name: self._reset_plan(self._body(robot), changes)
             for robot, changes in (overrides or {}).items()}
    restore_clean(p, client, self._start_state, [b.body for b in self.bodies.values()])
    self.step_count = 0
    base_seed = self.config.seed if seed is None else seed
    for i, b in enumerate(self.bodies.values()):
        b.rng = random.Random(self._robot_seed(base_seed, i))
        b.history.clear()
        if b.reports is not None:
            b.reports.clear()
        b.previous_velocities = None
        b.previous_step = -1
        b.applied = b.override = None
        b.reported = None
        self._free(b)
        b.torques.clear()
        for call in plans.get(b.name, ()):
            call()
        b.history.append(self._measure(b))


def _reset_plan(self: Any, b: _Body, changes: Mapping[str, Any]) -> list[Callable[[], None]]:
    """The PyBullet calls that start ``b`` as ``changes`` says, checked before any runs."""
    p, client = self.session.p, self.session.client
    known = ("initial_joints", "position", "orientation_rpy", "orientation_quat",
             "base_velocity", "base_angular_velocity")
    for key in changes:
        if key not in known:
            raise ParameterError(f"`overrides`: unknown key {key!r} for {b.name}; known "
                                 f"keys: {', '.join(known)}", param="overrides")

    def vector(key: str, size: int) -> list[float] | None:
        value = changes.get(key)
        if value is None:
            return None
        try:
            out = [float(v) for v in value]
        except (TypeError, ValueError):
            out = []
        if len(out) != size or not all(math.isfinite(v) for v in out):
            raise ParameterError(f"`overrides`: {b.name}.{key} needs {size} finite "
                                 "numbers", param="overrides")
        return out

    calls: list[Callable[[], None]] = []
    for name, value in (changes.get("initial_joints") or {}).items():
        spec = next((j for j in b.active if j.name == name), None)
        if spec is None:
            raise ParameterError(f"`overrides`: {b.name} has no active joint named "
                                 f"{name!r}", param="overrides")
        position, velocity = (value.get("position", 0.0), value.get("velocity", 0.0)) \
            if isinstance(value, Mapping) else (value, 0.0)
        q = self._to_physical(b, name, float(position))
        qd = float(velocity) * b.directions.get(name, 1.0)
        calls.append(functools.partial(p.resetJointState, b.body, spec.index, q, qd,
                                       physicsClientId=client))
    position = vector("position", 3)
    rpy = vector("orientation_rpy", 3)
    quat = vector("orientation_quat", 4)
    if rpy is not None and quat is not None:
        raise ParameterError(f"`overrides`: give {b.name} orientation_rpy or "
                             "orientation_quat, not both", param="overrides")
    if position is not None or rpy is not None or quat is not None:
        cfg = b.config
        if quat is None:
            quat = list(rpy_to_quat(*rpy)) if rpy is not None else \
                list(cfg.orientation_quat) if cfg.orientation_quat is not None else \
                list(rpy_to_quat(*(cfg.orientation_rpy or (0.0, 0.0, 0.0))))
        norm = math.sqrt(math.fsum(v * v for v in quat))
        if norm < 1e-12:
            raise ParameterError(f"`overrides`: {b.name}.orientation_quat must not be all "
                                 "zeros", param="overrides")
        orn = quat_mul([v / norm for v in quat], UP_AXES[cfg.up])
        at = position if position is not None else list(cfg.position)
        if cfg.pose_frame == "link":
            # resetBasePositionAndOrientation places the centre of mass.
            dyn = p.getDynamicsInfo(b.body, -1, physicsClientId=client)
            at, orn = p.multiplyTransforms(at, orn, dyn[3], dyn[4])
        calls.append(lambda: p.resetBasePositionAndOrientation(
            b.body, at, orn, physicsClientId=client))
    lin = vector("base_velocity", 3)
    ang = vector("base_angular_velocity", 3)
    if lin is not None or ang is not None:
        velocity = (lin if lin is not None else list(b.config.base_velocity),
                    ang if ang is not None else list(b.config.base_angular_velocity))
        calls.append(lambda: p.resetBaseVelocity(b.body, *velocity,
                                                 physicsClientId=client))
    return calls
