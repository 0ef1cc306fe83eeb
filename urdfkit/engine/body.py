"""A loaded body's links and the body as a whole: ``urdfkit links`` and ``urdfkit info``.

:func:`link_table` puts each link's ``p.getDynamicsInfo`` beside the file's ``<inertial>``:
without ``URDF_USE_INERTIA_FROM_FILE`` PyBullet discards ``<inertia>`` and recomputes it from
the collision shapes, and a link with no ``<inertial>`` gets 1 kg, so the two often differ.
:func:`summary` adds counts, degrees of freedom, mass and the bounding box.

Kept apart from :mod:`urdfkit.engine.joints` so that ``urdfkit joints``, which users run in loops,
does not pay for building these classes.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

from lxml import etree

from urdfkit.engine.joints import JointInfo, base_link_name, joint_table
from urdfkit.engine.session import Session
from urdfkit.model.spec import JOINT_DOF, attr_float, attr_vec
from urdfkit.model.xmlio import children

Vec3 = tuple[float, float, float]
Quat = tuple[float, float, float, float]

@dataclass
class FileInertial:
    """What a link's ``<inertial>`` says.

    Attributes:
        mass: ``<mass value>``.
        inertia: ixx, ixy, ixz, iyy, iyz, izz as written.
        principal: The principal moments (eigenvalues of the tensor), ascending. This is what
            PyBullet keeps, as ``localInertiaDiagonal``, when it uses the file's inertia.
        xyz: ``<origin xyz>`` of the inertial frame.
        rpy: ``<origin rpy>`` of the inertial frame.
    """

    mass: float
    inertia: tuple[float, float, float, float, float, float]
    principal: Vec3
    xyz: Vec3
    rpy: Vec3

    def to_dict(self) -> dict[str, Any]:
        """The JSON form."""
        names = ("ixx", "ixy", "ixz", "iyy", "iyz", "izz")
        return {"mass": self.mass, "inertia": dict(zip(names, self.inertia, strict=False)),
                "principal": list(self.principal), "xyz": list(self.xyz), "rpy": list(self.rpy)}


def file_inertial(link: etree._Element | None) -> FileInertial | None:
    """Read a ``<link>``'s ``<inertial>``; ``None`` if it has none."""
    if link is None:
        return None
    el = link.find("inertial")
    if el is None:
        return None
    from urdfkit.core.errors import ModelError
    from urdfkit.model.builder_elements import Inertia

    mass = attr_float(el.find("mass"), "value") or 0.0
    i = el.find("inertia")
    values = tuple(attr_float(i, k) or 0.0 for k in ("ixx", "ixy", "ixz", "iyy", "iyz", "izz"))
    try:
        principal = Inertia(*values).principal_moments
    except ModelError:  # nan/inf in the file: show the diagonal as written
        principal = (values[0], values[3], values[5])
    origin = el.find("origin")
    return FileInertial(mass, values, tuple(sorted(principal)),  # type: ignore[arg-type]
                        attr_vec(origin, "xyz", 3, (0, 0, 0)),  # type: ignore[arg-type]
                        attr_vec(origin, "rpy", 3, (0, 0, 0)))  # type: ignore[arg-type]


@dataclass
class LinkDynamics:
    """One link's ``p.getDynamicsInfo``, beside what the file says.

    Attributes:
        link_index: -1 for the base link, else the index of the joint whose child it is.
        local_inertia_diagonal: The engine's principal moments, in the inertial frame.
        local_inertial_pos: The inertial frame (centre of mass) in the link frame.
        local_inertial_orn: Its orientation (x, y, z, w): the principal axes.
        file: The file's ``<inertial>``, if the link has one.
    """

    link_index: int
    link_name: str
    mass: float
    lateral_friction: float
    local_inertia_diagonal: Vec3
    local_inertial_pos: Vec3
    local_inertial_orn: Quat
    restitution: float
    rolling_friction: float
    spinning_friction: float
    contact_damping: float
    contact_stiffness: float
    body_type: int
    collision_margin: float
    file: FileInertial | None = None

    @property
    def mass_differs(self) -> bool:
        """Whether PyBullet's mass is not the file's (a link without ``<inertial>`` gets 1 kg)."""
        file_mass = self.file.mass if self.file else None
        return file_mass is None or not math.isclose(self.mass, file_mass, rel_tol=1e-6,
                                                     abs_tol=1e-12)

    @property
    def inertia_differs(self) -> bool:
        """Whether the engine's principal moments are not the file's.

        Compared sorted, because PyBullet orders the diagonal along its own principal axes.
        """
        if self.file is None:
            return True
        engine = sorted(self.local_inertia_diagonal)
        return not all(math.isclose(a, b, rel_tol=1e-4, abs_tol=1e-12)
                       for a, b in zip(engine, self.file.principal, strict=False))

    def to_dict(self) -> dict[str, Any]:
        """The JSON form: getDynamicsInfo's fields in snake_case, and the file's values."""
        return {
            "linkIndex": self.link_index, "linkName": self.link_name, "mass": self.mass,
            "lateral_friction": self.lateral_friction,
            "local_inertia_diagonal": list(self.local_inertia_diagonal),
            "local_inertial_pos": list(self.local_inertial_pos),
            "local_inertial_orn": list(self.local_inertial_orn),
            "restitution": self.restitution, "rolling_friction": self.rolling_friction,
            "spinning_friction": self.spinning_friction,
            "contact_damping": self.contact_damping, "contact_stiffness": self.contact_stiffness,
            "body_type": self.body_type, "collision_margin": self.collision_margin,
            "file": self.file.to_dict() if self.file else None,
            "mass_differs": self.mass_differs, "inertia_differs": self.inertia_differs,
        }


def link_table(s: Session, body: int, root: etree._Element | None = None,
               joints: Sequence[JointInfo] | None = None) -> list[LinkDynamics]:
    """The base link and every child link, with engine dynamics and the file's inertial."""
    joints = joint_table(s, body, root) if joints is None else joints
    by_name = {}
    if root is not None:
        by_name = {el.get("name", ""): el for el in children(root, "link")}
    names = [base_link_name(s, body)] + [j.link_name for j in joints]
    out = []
    for index, name in zip(range(-1, len(joints)), names, strict=True):
        d = s.call("getDynamicsInfo", body, index)
        out.append(LinkDynamics(
            index, name, float(d[0]), float(d[1]), tuple(d[2]), tuple(d[3]), tuple(d[4]),
            float(d[5]), float(d[6]), float(d[7]), float(d[8]), float(d[9]), int(d[10]),
            float(d[11]), file_inertial(by_name.get(name))))
    return out


# --------------------------------------------------------------------------- summary


@dataclass
class Summary:
    """``urdfkit info``: the robot at a glance.

    Attributes:
        joint_types: Joint counts by URDF type (continuous counted apart from revolute).
        dof: Degrees of freedom of the joints (the floating base's 6 not included).
        total_mass: Sum of PyBullet's link masses, kg.
        file_mass: Sum of the file's ``<mass>`` values, kg.
        aabb_min: Lower corner of the body's bounding box in its loaded pose.
        aabb_max: Upper corner.
    """

    robot: str
    base_link: str
    links: int
    joints: int
    joint_types: dict[str, int]
    dof: int
    fixed_base: bool
    total_mass: float
    file_mass: float
    links_without_inertial: list[str]
    aabb_min: Vec3
    aabb_max: Vec3
    #: Why the base does not move, or None: loaded with useFixedBase, or a root PyBullet
    #: gives mass 0 (written so, or a ``world`` link without ``<inertial>``), which it makes
    #: static. ``fixed_base`` is True in every one of these cases.
    static_base: str | None = None

    @property
    def size(self) -> Vec3:
        """Extent of the bounding box along x, y, z."""
        return tuple(hi - lo for lo, hi in zip(self.aabb_min, self.aabb_max, strict=False))  # type: ignore[return-value]

    def to_dict(self) -> dict[str, Any]:
        """The JSON form."""
        return {
            "robot": self.robot, "base_link": self.base_link, "links": self.links,
            "joints": self.joints, "joint_types": self.joint_types, "dof": self.dof,
            "fixed_base": self.fixed_base, "static_base": self.static_base,
            "total_mass": self.total_mass,
            "file_mass": self.file_mass, "links_without_inertial": self.links_without_inertial,
            "aabb": {"min": list(self.aabb_min), "max": list(self.aabb_max),
                     "size": list(self.size)},
        }


def summary(s: Session, body: int, root: etree._Element, fixed_base: bool = False) -> Summary:
    """Counts, DOF, mass and bounding box of a loaded body."""
    joints = joint_table(s, body, root)
    links = link_table(s, body, root, joints)
    types: dict[str, int] = {}
    for j in joints:
        key = j.urdf_type or j.joint_type.lower()
        types[key] = types.get(key, 0) + 1
    lo = [math.inf] * 3
    hi = [-math.inf] * 3
    for index in range(-1, len(joints)):
        a, b = s.call("getAABB", body, index)
        lo = [min(x, y) for x, y in zip(lo, a, strict=False)]
        hi = [max(x, y) for x, y in zip(hi, b, strict=False)]
    base = links[0]
    # PyBullet makes a base of mass 0 static (measured): it stays where it is loaded.
    static = ("loaded with useFixedBase" if fixed_base else None if base.mass != 0 else
              f"the root link {base.link_name!r} has no <inertial>, and PyBullet gives a link "
              "named world mass 0" if base.file is None else
              f"the root link {base.link_name!r} has mass 0")
    return Summary(
        robot=root.get("name", ""), base_link=base_link_name(s, body), links=len(links),
        joints=len(joints), joint_types=dict(sorted(types.items())),
        dof=sum(JOINT_DOF.get(j.joint_type, 0) for j in joints),
        fixed_base=static is not None, static_base=static,
        total_mass=sum(link.mass for link in links),
        file_mass=sum(link.file.mass for link in links if link.file),
        links_without_inertial=[link.link_name for link in links if link.file is None],
        aabb_min=tuple(lo), aabb_max=tuple(hi),  # type: ignore[arg-type]
    )
