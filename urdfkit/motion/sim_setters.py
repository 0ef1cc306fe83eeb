"""Setters: a robot's physical parameters.

Methods of :class:`urdfkit.sim.Simulation`, split out of :mod:`urdfkit.sim`: each function
takes the simulation as ``self`` and is bound as a method of ``Simulation`` (a class
attribute), so a call costs what a method defined in the class costs.
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from typing import Any

from urdfkit.core.errors import ParameterError
from urdfkit.motion.sim_state import JointSpec, _Body


def _link_index(self: Any, b: _Body, link: str) -> int:
    if link not in b.links:
        from urdfkit.core.suggest import hint

        raise ParameterError(f"`link`: {b.name} has no link named {link!r}"
                             f"{hint(link, b.links)}", param="link")
    return b.links[link]


def _change(self: Any, target: str, link: str | None, **values: Any) -> None:
    p, client = self.session.p, self.session.client
    if target == "ground":
        if self.ground is None:
            raise ParameterError("the scenario has no ground", param="robot")
        p.changeDynamics(self.ground, -1, physicsClientId=client, **values)
        return
    b = self._body(target)
    links = [self._link_index(b, link)] if link is not None else \
        [-1, *range(len(b.joints))]
    for index in links:
        p.changeDynamics(b.body, index, physicsClientId=client, **values)


def set_mass(self: Any, robot: str, link: str, mass: float) -> None:
    """A link's mass, kg; its inertia scales with it (the same body, heavier).

    PyBullet's changeDynamics(mass=...) alone throws the inertia away and recomputes it
    from the collision shapes (a link without any gets ~1e-6): not what "heavier" means.
    """
    b = self._body(robot)
    index = self._link_index(b, link)
    p, client = self.session.p, self.session.client
    info = p.getDynamicsInfo(b.body, index, physicsClientId=client)
    old, diagonal = info[0], info[2]
    scaled = [float(v) * float(mass) / old for v in diagonal] if old > 0 else None
    for values in ({"mass": float(mass)},
                   {"localInertiaDiagonal": scaled} if scaled is not None else {}):
        if values:
            p.changeDynamics(b.body, index, physicsClientId=client, **values)
            self._changed(b, index, values)


def set_inertia(self: Any, robot: str, link: str, diagonal: Sequence[float]) -> None:
    """A link's principal moments of inertia, kg m^2 (in its inertial frame)."""
    b = self._body(robot)
    index = self._link_index(b, link)
    values = {"localInertiaDiagonal": [float(v) for v in diagonal]}
    p, client = self.session.p, self.session.client
    p.changeDynamics(b.body, index, physicsClientId=client, **values)
    self._changed(b, index, values)


def set_friction(self: Any, robot: str, link: str | None, lateral: float) -> None:
    """Lateral friction of a link (every link when ``link`` is None).

    Robot ``"ground"`` is the floor.
    """
    self._change(robot, link, lateralFriction=float(lateral))


def set_restitution(self: Any, robot: str, link: str | None, restitution: float) -> None:
    """Restitution (bounciness) of a link, or of the floor with robot ``"ground"``."""
    self._change(robot, link, restitution=float(restitution))


def _joint_named(b: _Body, joint: str) -> JointSpec:
    try:
        return b.joint(joint)
    except KeyError:
        raise ParameterError(f"`joint`: {b.name} has no joint named {joint!r}",
                             param="joint") from None


def set_joint_damping(self: Any, robot: str, joint: str, damping: float) -> None:
    """PyBullet's joint damping of one joint (N m s/rad)."""
    b = self._body(robot)
    spec = self._joint_named(b, joint)
    p, client = self.session.p, self.session.client
    p.changeDynamics(b.body, spec.index, jointDamping=float(damping),
                     physicsClientId=client)


def set_joint_friction(self: Any, robot: str, joint: str, friction: float) -> None:
    """A joint's dry (Coulomb) friction, N m (N for a prismatic joint); 0 removes it.

    The joint holds against up to ``friction`` of torque and is slowed by that much when
    it moves (PyBullet's joint motor at velocity 0 with that force limit). While a
    PyBullet position or velocity command drives the joint (a ``joints`` segment without
    a ``motor`` table, or a car's wheels and hinges), that command owns the motor; the
    friction comes back when it ends. It stays across ``reset()``.
    """
    b = self._body(robot)
    spec = self._joint_named(b, joint)
    if spec not in b.active:
        raise ParameterError(f"`joint`: {joint} of {robot} is fixed", param="joint")
    if not (isinstance(friction, (int, float)) and math.isfinite(friction)
            and friction >= 0):
        raise ParameterError(f"`friction` must be a finite number >= 0, got {friction!r}",
                             param="friction")
    b.dry_friction[spec.index] = float(friction)
    if not self._motor_driven(b, spec):
        self._free(b, [spec.index])


def _motor_driven(self: Any, b: _Body, spec: JointSpec) -> bool:
    """Whether a PyBullet position or velocity command holds this joint's motor now."""
    cmd = b.applied
    if cmd is None or b.servo:
        return False
    if cmd.kind == "drive":
        return b.train is not None and spec.index in (*b.train.wheels, *b.train.hinges)
    return spec.name in cmd.targets and cmd.mode_of(spec.name) != "torque"


def set_link_damping(self: Any, robot: str, linear: float, angular: float) -> None:
    """Every link's linear and angular velocity damping (PyBullet's default is 0.04)."""
    self._change(robot, None, linearDamping=float(linear), angularDamping=float(angular))


def set_motor_gains(self: Any, robot: str, kp: float | Mapping[str, float] | None = None,
                    kd: float | Mapping[str, float] | None = None) -> None:
    """The servo's position and velocity gains: one for every joint, or per joint name.

    A gain not given keeps its value. Needs the robot's ``motor`` table (the servo).
    """
    b = self._body(robot)
    if not b.servo:
        raise ParameterError(f"`robot`: {robot} has no servo model; give it a 'motor' "
                             "table in the scenario", param="robot")
    names = {j.name for j in b.servo}
    for label, gain in (("kp", kp), ("kd", kd)):
        if gain is None:
            continue
        values = dict(gain) if isinstance(gain, Mapping) else {"": gain}
        for name, value in values.items():
            if name and name not in names:
                raise ParameterError(f"`{label}`: {robot}'s servo drives no joint named "
                                     f"{name!r}", param=label)
            if not (isinstance(value, (int, float)) and math.isfinite(value)
                    and value >= 0):
                raise ParameterError(f"`{label}` must be a finite number >= 0, got "
                                     f"{value!r}", param=label)
        setattr(b, label, {k: float(v) for k, v in values.items()}
                if isinstance(gain, Mapping) else float(gain))
