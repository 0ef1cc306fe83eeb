"""A URDF's Gazebo contact parameters applied to a loaded body (drive, sim).

PyBullet ignores ``<gazebo reference>``; :mod:`urdfkit.model.gazebo` reads each link's
mu1/mu2/kp/kd, and this applies them as the engine's dynamics changes: lateral friction from
the smaller of mu1 and mu2, contact stiffness and damping from kp and kd when both are given.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from urdfkit.model.gazebo import GazeboContact, gazebo_contacts

if TYPE_CHECKING:
    from lxml import etree

    from urdfkit.engine.api import Simulator


def link_indices(engine: Simulator, body: int) -> dict[str, int]:
    """Every link's index by name (the root -1)."""
    return {name: k - 1 for k, name in enumerate(engine.link_names(body))}


def contacts_to_apply(root: etree._Element) -> dict[str, GazeboContact]:
    """The links whose <gazebo> gives something PyBullet can take."""
    return {k: g for k, g in gazebo_contacts(root).items() if g.pybullet()}


def apply_gazebo_contacts(engine: Simulator, body: int,
                          contacts: dict[str, GazeboContact]) -> dict[str, dict[str, float]]:
    """Set each link's dynamics as its Gazebo block says; {link: the values set}."""
    index, applied = link_indices(engine, body), {}
    for name, g in contacts.items():
        if name not in index:
            continue
        values: dict[str, float] = {}
        if g.lateral_friction is not None:
            values["lateralFriction"] = g.lateral_friction
        if g.kp is not None and g.kd is not None:
            values.update(contactStiffness=g.kp, contactDamping=g.kd)
        if values:
            engine.change_dynamics(body, index[name], **values)
            applied[name] = values
    return applied
