"""A URDF's Gazebo contact parameters applied to a loaded body (drive, sim).

PyBullet ignores ``<gazebo reference>``; :mod:`urdfkit.model.gazebo` reads each link's
mu1/mu2/kp/kd, and this applies them with changeDynamics: lateral friction from the smaller
of mu1 and mu2, contact stiffness and damping from kp and kd when both are given.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from urdfkit.model.gazebo import GazeboContact, gazebo_contacts

if TYPE_CHECKING:
    from lxml import etree

    from urdfkit.engine.session import Bullet


def link_indices(p: Bullet, body: int) -> dict[str, int]:
    """Every link's PyBullet index by name (the root -1)."""
    out = {p.getBodyInfo(body)[0].decode("utf-8", "replace"): -1}
    for j in range(p.getNumJoints(body)):
        out[p.getJointInfo(body, j)[12].decode("utf-8", "replace")] = j
    return out


def contacts_to_apply(root: etree._Element) -> dict[str, GazeboContact]:
    """The links whose <gazebo> gives something PyBullet can take."""
    return {k: g for k, g in gazebo_contacts(root).items() if g.pybullet()}


def apply_gazebo_contacts(p: Bullet, body: int,
                          contacts: dict[str, GazeboContact]) -> dict[str, dict[str, float]]:
    """Set each link's dynamics as its Gazebo block says; {link: the values set}."""
    index, applied = link_indices(p, body), {}
    for name, g in contacts.items():
        if name not in index:
            continue
        values: dict[str, float] = {}
        if g.lateral_friction is not None:
            values["lateralFriction"] = g.lateral_friction
        if g.kp is not None and g.kd is not None:
            values.update(contactStiffness=g.kp, contactDamping=g.kd)
        if values:
            p.changeDynamics(body, index[name], **values)
            applied[name] = values
    return applied
