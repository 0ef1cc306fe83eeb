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


def apply_gazebo_contacts(engine: Simulator, body: int, contacts: dict[str, GazeboContact],
                          notes: list[str] | None = None) -> dict[str, dict[str, float]]:
    """Set each link's dynamics as its Gazebo block says; {link: the values set}.

    What the engine cannot carry (MuJoCo has no contact spring for kp/kd) is left out, the
    rest applied, and one line each goes to ``notes``.
    """
    from urdfkit.core.errors import ParameterError

    index, applied = link_indices(engine, body), {}
    refused: list[str] = []
    why = ""
    for name, g in contacts.items():
        if name not in index:
            continue
        values: dict[str, float] = {}
        if g.lateral_friction is not None:
            values["lateralFriction"] = g.lateral_friction
        if g.kp is not None and g.kd is not None:
            spring = {"contactStiffness": g.kp, "contactDamping": g.kd}
            try:
                engine.change_dynamics(body, index[name], **spring)
                values.update(spring)
            except ParameterError as e:
                refused.append(f"{name} kp {g.kp:g} kd {g.kd:g}")
                why = e.message.partition(": ")[2]
        if "lateralFriction" in values:
            engine.change_dynamics(body, index[name], lateralFriction=values["lateralFriction"])
        if values:
            applied[name] = values
    if refused and notes is not None:
        shown = "; ".join(refused[:4]) + ("; ..." if len(refused) > 4 else "")
        notes.append(f"<gazebo> contact stiffness not applied on {engine.label} ({shown}): "
                     f"{why}")
    return applied
