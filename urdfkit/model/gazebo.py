"""Gazebo's contact parameters in a URDF, read once for check, fix and (later) drive and sim.

ROS descriptions give each link's contact with the ground in ``<gazebo reference="link">``
blocks, which PyBullet 3.2.7 ignores whole: a wheel Gazebo drives on ``mu1 = mu2 = 200``
gets PyBullet's lateral friction 0.5. Three forms are in use, and all are read:

- ROS 1 attributes: ``<mu1 value="0.8"/>``, ``<kp value="1e6"/>``;
- ROS 2 (and most ROS 1) element text: ``<mu1>0.8</mu1>``;
- SDF inside the block: ``<collision><surface><friction><ode><mu>0.8</mu><mu2>...``, with
  ``<surface><contact><ode><kp>/<kd>``.

A ``<gazebo>`` without ``reference`` inside a ``<link>`` is taken as that link's. Several
blocks for one link merge, the later value winning, as Gazebo merges them.

What carries over to PyBullet's ``<contact>`` (:meth:`GazeboContact.pybullet`):

- **Friction.** PyBullet has one lateral coefficient in every direction; Gazebo's ODE has
  ``mu1`` along ``fdir1`` and ``mu2`` across it. Equal, that one number; different, the
  smaller, so the link never grips harder than Gazebo lets it in any direction; but never a
  smaller 0 beside a larger one (ROSbot 2R's wheels: ``mu 1`` along a 45 degree ``fdir1``,
  ``mu2 0`` across it): PyBullet's one coefficient at 0 takes away the grip Gazebo gives in
  ``fdir1`` too, and the robot cannot move (measured: 0.844 m in 4 s as built, 0 m with 0
  written), so the larger is written, and check and fix say so. PyBullet
  multiplies the two bodies' coefficients of a contact (Gazebo takes the smaller of the two):
  on a ground of lateral friction 1 (pybullet_data's plane.urdf) the link's own coefficient
  is the contact's, as on Gazebo's ground of mu 100.
- **Stiffness and damping** from ``kp`` (N/m) and ``kd`` (N s/m): the same spring-damper in
  both engines (ERP = h kp / (h kp + kd), CFM = 1 / (h kp + kd) at time step h), so the
  mapping is one to one; written only when both are given (PyBullet's contact spring takes
  the pair).
- **Refused** (:func:`unusable`): values that are no contact at all, as a fuzzed or mistyped
  block gives them: a stiffness of 0, negative or subnormal (PyBullet loads it as 2.2e-16 N/m
  and the link sinks through the ground), a negative damping or friction. Check and fix name
  them; fix writes the rest.
- **Not carried** (:data:`NOT_CARRIED`): ``fdir1`` (PyBullet's anisotropic friction is set
  at run time, not in a URDF), ``slip1``/``slip2`` (force-dependent slip; PyBullet has none),
  ``minDepth`` and ``maxVel`` (per-link penetration and correction speed; PyBullet's are
  global), torsional friction and bounce (other meanings in PyBullet).

Nothing here imports lxml: elements are read through ``get``, ``tag``, ``text``, iteration.
"""

from __future__ import annotations

import math
import sys
from dataclasses import dataclass, field
from typing import Any

El = Any  # an lxml element

#: PyBullet's lateral friction for a link without ``<contact><lateral_friction>``.
PYBULLET_LATERAL_FRICTION = 0.5
#: Gazebo contact parameters PyBullet has no URDF equivalent for, with why.
NOT_CARRIED = {
    "fdir1": "friction direction: PyBullet's anisotropic friction is set at run time "
             "(changeDynamics anisotropicFriction), not in a URDF",
    "slip1": "force-dependent slip: PyBullet has none",
    "slip2": "force-dependent slip: PyBullet has none",
    "minDepth": "allowed penetration: PyBullet's is global, not per link",
    "maxVel": "contact correction speed: PyBullet's is global, not per link",
    "min_depth": "allowed penetration: PyBullet's is global, not per link",
    "max_vel": "contact correction speed: PyBullet's is global, not per link",
    "torsional": "torsional friction: PyBullet's spinning friction means another thing",
    "bounce": "restitution with a velocity threshold: not mapped",
}
#: The smallest contact stiffness PyBullet keeps (N/m): a stiffness of 0, negative or subnormal
#: loads as 2.2e-16 (DBL_EPSILON), a contact that holds nothing up (measured on 3.2.7: a 1 kg
#: box written so falls 3.9 m through plane.urdf in 2 s).
MIN_STIFFNESS = sys.float_info.min


def unusable(name: str, value: float) -> str | None:
    """Why a contact parameter cannot be carried to PyBullet, or None if it can.

    ``name`` is a Gazebo name (mu1, mu2, kp, kd) or a ``<contact>`` child's tag.
    """
    if name in ("mu1", "mu2", "lateral_friction", "rolling_friction", "spinning_friction"):
        if value < 0:
            return "a negative friction coefficient, which means nothing (PyBullet uses its size)"
    elif name in ("kp", "stiffness"):
        if not value >= MIN_STIFFNESS:
            return ("not a positive stiffness: PyBullet loads it as 2.2e-16 N/m, a contact that "
                    "holds nothing up, and the link sinks through the ground")
    elif name in ("kd", "damping") and value < 0:
        return "a negative contact damping, which adds energy at every contact"
    return None


#: The SDF names of the parameters read (``mu`` under ``<friction><ode>`` is mu1).
_SDF_NAMES = {"mu": "mu1", "mu2": "mu2", "kp": "kp", "kd": "kd"}


@dataclass
class GazeboContact:
    """One link's Gazebo contact parameters, as the file gives them.

    Attributes:
        link: The link's name.
        element: The first ``<gazebo>`` element that set one (for its line).
        mu1, mu2: Friction coefficients (None when not given).
        kp, kd: Contact stiffness (N/m) and damping (N s/m).
        not_carried: Names of other contact parameters given, which PyBullet cannot take.

    A value :func:`unusable` refuses is not carried (:attr:`refused` says why).
    """

    link: str
    element: El
    mu1: float | None = None
    mu2: float | None = None
    kp: float | None = None
    kd: float | None = None
    not_carried: list[str] = field(default_factory=list)

    @property
    def refused(self) -> dict[str, str]:
        """The given values that cannot be carried, {name: why} (:func:`unusable`)."""
        return {k: why for k, v in self.given().items() if (why := unusable(k, v)) is not None}

    def _usable(self, name: str) -> float | None:
        value = getattr(self, name)
        return None if value is None or unusable(name, value) is not None else value

    @property
    def lateral_friction(self) -> float | None:
        """PyBullet's one coefficient for mu1 and mu2: the smaller when they differ.

        The larger when the smaller is 0: a coefficient of 0 in every direction is no grip
        where Gazebo grips (:attr:`grip_only_one_way`).
        """
        given = [m for m in (self._usable("mu1"), self._usable("mu2")) if m is not None]
        if not given:
            return None
        return max(given) if self.grip_only_one_way else min(given)

    @property
    def grip_only_one_way(self) -> bool:
        """mu1 and mu2 are both given, one 0 and the other not (a wheel that only rolls)."""
        mu1, mu2 = self._usable("mu1"), self._usable("mu2")
        return mu1 is not None and mu2 is not None and min(mu1, mu2) == 0 < max(mu1, mu2)

    def pybullet(self) -> dict[str, float]:
        """The ``<contact>`` children that carry these over: {tag: value}."""
        out: dict[str, float] = {}
        if self.lateral_friction is not None:
            out["lateral_friction"] = self.lateral_friction
        kp, kd = self._usable("kp"), self._usable("kd")
        if kp is not None and kd is not None:
            out["stiffness"] = kp
            out["damping"] = kd
        return out

    def given(self) -> dict[str, float]:
        """The parameters read: {mu1, mu2, kp, kd} that the file sets."""
        return {k: v for k, v in (("mu1", self.mu1), ("mu2", self.mu2), ("kp", self.kp),
                                  ("kd", self.kd)) if v is not None}


def _local(tag: Any) -> str:
    return tag.rpartition("}")[2] if isinstance(tag, str) else ""


def _value(el: El) -> float | None:
    """``value="x"`` or the element's text, as a finite number (None if neither parses)."""
    text = el.get("value")
    if text is None:
        text = el.text
    try:
        x = float((text or "").strip())
    except ValueError:
        return None
    return x if math.isfinite(x) else None


def _blocks(root: El) -> list[tuple[str, El]]:
    """Each ``<gazebo>`` block with the link it is about: ``reference=``, or the enclosing link."""
    blocks: list[tuple[str, El]] = []
    if next(root.iter("{*}gazebo"), None) is None:  # in C; most files have none
        return blocks
    for child in root:
        tag = _local(child.tag)
        if tag == "gazebo" and child.get("reference"):
            blocks.append((child.get("reference", ""), child))
        elif tag == "link" and child.get("name"):
            blocks.extend((child.get("name", ""), g) for g in child
                          if _local(g.tag) == "gazebo" and not g.get("reference"))
    return blocks


def _read_block(block: El) -> tuple[dict[str, float], list[str]]:
    """A block's contact parameters ({mu1, mu2, kp, kd} it sets) and the ones none can carry."""
    found: dict[str, float] = {}
    others: list[str] = []
    for el in block.iter():
        tag = _local(el.tag)
        if el is block or not tag:
            continue
        parent = el.getparent()
        if parent is block and tag in ("mu1", "mu2", "kp", "kd"):
            name: str | None = tag
        elif parent is not None and _local(parent.tag) == "ode" and tag in _SDF_NAMES:
            name = _SDF_NAMES[tag]
        else:
            name = None
            if tag in NOT_CARRIED and tag not in others:
                others.append(tag)
        if name is not None:
            value = _value(el)
            if value is not None:
                found[name] = value
    return found, others


def gazebo_contacts(root: El) -> dict[str, GazeboContact]:
    """Every link's Gazebo contact parameters, by link name (links with none left out).

    Args:
        root: The ``<robot>`` element.
    """
    out: dict[str, GazeboContact] = {}
    for link, block in _blocks(root):
        found, others = _read_block(block)
        contact = out.get(link)
        if contact is None:
            if not found:
                continue  # only parameters PyBullet cannot take, and nothing else: no contact
            contact = out[link] = GazeboContact(link, block)
        for name, value in found.items():
            setattr(contact, name, value)
        contact.not_carried.extend(o for o in others if o not in contact.not_carried)
    return out
