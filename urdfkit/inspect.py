"""Turn a loaded body into plain data: joint table, link dynamics, summary, kinematic tree.

Everything here returns dataclasses; nothing prints. ``cli.py`` presents them as rich tables
or JSON.

The joint table carries all 17 fields of ``p.getJointInfo`` under the names the PyBullet
Quickstart Guide uses (``jointIndex`` ... ``parentIndex``); :meth:`JointInfo.to_dict` is the
JSON contract of ``urdfkit joints --json`` (see ``docs/inspect.md``). Three PyBullet facts
shape this module:

- Continuous joints come back as ``JOINT_REVOLUTE`` with lower=0, upper=-1 (PyBullet's "no
  limit" marker). Only the URDF says they were continuous, so each joint is matched to its
  ``<joint>`` element by name to report ``urdfType``.
- ``parentFramePos``/``parentFrameOrn`` are relative to the parent's *inertial* frame (its
  centre of mass), not to the parent link frame the URDF ``<origin>`` is written in.
- Without ``URDF_USE_INERTIA_FROM_FILE`` PyBullet discards ``<inertia>`` and recomputes it from
  the collision shapes, so the link table shows the file's values beside the engine's.

:func:`kinematic_tree` needs no PyBullet at all: it reads the lxml document, and numbers the
joints the way PyBullet will (depth-first from the root, children in file order).
"""

from __future__ import annotations

import math
import re
from collections.abc import Iterator, Sequence
from contextlib import contextmanager
from dataclasses import dataclass, field
from typing import Any

from lxml import etree

from .resolve import Resolved
from .session import LoadOptions, Session, quiet_stdout

#: ``getJointInfo``'s jointType codes (p.JOINT_REVOLUTE == 0, ...), as names.
JOINT_TYPE_NAMES = {0: "REVOLUTE", 1: "PRISMATIC", 2: "SPHERICAL", 3: "PLANAR", 4: "FIXED",
                    5: "POINT2POINT", 6: "GEAR"}
#: Velocity degrees of freedom of each PyBullet joint type (a planar joint is x, y and yaw).
JOINT_DOF = {"REVOLUTE": 1, "PRISMATIC": 1, "SPHERICAL": 3, "PLANAR": 3, "FIXED": 0}

#: What ``--type`` accepts: PyBullet's type names and the URDF's, lower case.
FILTER_TYPES = ("revolute", "continuous", "prismatic", "fixed", "spherical", "planar",
                "floating")

#: The 17 ``getJointInfo`` fields, in tuple order, as the Quickstart Guide names them.
JOINT_INFO_FIELDS = (
    "jointIndex", "jointName", "jointType", "qIndex", "uIndex", "flags", "jointDamping",
    "jointFriction", "jointLowerLimit", "jointUpperLimit", "jointMaxForce", "jointMaxVelocity",
    "linkName", "jointAxis", "parentFramePos", "parentFrameOrn", "parentIndex",
)

Vec3 = tuple[float, float, float]
Quat = tuple[float, float, float, float]


def _text(value: Any) -> str:
    return value.decode("utf-8", "replace") if isinstance(value, bytes) else str(value)


def quat_to_rpy(q: Sequence[float]) -> Vec3:
    """Roll, pitch, yaw (URDF's fixed-axis X-Y-Z convention) of a quaternion (x, y, z, w).

    The same result as ``p.getEulerFromQuaternion``, without needing a PyBullet client.
    """
    x, y, z, w = q
    roll = math.atan2(2 * (w * x + y * z), 1 - 2 * (x * x + y * y))
    s = max(-1.0, min(1.0, 2 * (w * y - z * x)))
    pitch = math.asin(s)
    yaw = math.atan2(2 * (w * z + x * y), 1 - 2 * (y * y + z * z))
    return (_clean(roll), _clean(pitch), _clean(yaw))


def _clean(x: float) -> float:
    # -0.0 and 1e-17 noise make tables and golden files churn.
    return 0.0 if abs(x) < 1e-12 else x


def _vec(el: etree._Element | None, attr: str, default: Sequence[float]) -> tuple[float, ...]:
    if el is None or el.get(attr) is None:
        return tuple(float(v) for v in default)
    try:
        return tuple(float(v) for v in (el.get(attr) or "").split())
    except ValueError:
        return tuple(float(v) for v in default)


def _float(el: etree._Element | None, attr: str) -> float | None:
    if el is None or el.get(attr) is None:
        return None
    try:
        return float(el.get(attr) or "")
    except ValueError:
        return None


def _children(root: etree._Element, tag: str) -> Iterator[etree._Element]:
    return (c for c in root if isinstance(c.tag, str) and c.tag == tag)


# --------------------------------------------------------------------------- joints


@dataclass
class JointInfo:
    """One row of ``p.getJointInfo``, decoded, plus what the URDF adds.

    Attribute names are snake_case; :meth:`to_dict` gives the Quickstart Guide names.

    Attributes:
        urdf_type: The ``type`` attribute in the file (``continuous`` where PyBullet says
            REVOLUTE), or ``None`` if no ``<joint>`` of that name exists (PyBullet invents
            none, but a merged body could).
        parent_link_name: The parent link's name (the base link for parent_index -1).
        parent_frame_rpy: ``parent_frame_orn`` as roll, pitch, yaw, for humans.
    """

    joint_index: int
    joint_name: str
    joint_type: str
    q_index: int
    u_index: int
    flags: int
    joint_damping: float
    joint_friction: float
    joint_lower_limit: float
    joint_upper_limit: float
    joint_max_force: float
    joint_max_velocity: float
    link_name: str
    joint_axis: Vec3
    parent_frame_pos: Vec3
    parent_frame_orn: Quat
    parent_index: int
    urdf_type: str | None = None
    parent_link_name: str = ""
    parent_frame_rpy: Vec3 = (0.0, 0.0, 0.0)

    @classmethod
    def from_pybullet(cls, info: Sequence[Any]) -> JointInfo:
        """Decode the raw 17-tuple: bytes to text, type code to name, tuples kept as tuples."""
        return cls(
            int(info[0]), _text(info[1]), JOINT_TYPE_NAMES.get(int(info[2]), str(info[2])),
            int(info[3]), int(info[4]), int(info[5]), float(info[6]), float(info[7]),
            float(info[8]), float(info[9]), float(info[10]), float(info[11]), _text(info[12]),
            tuple(info[13]), tuple(info[14]), tuple(info[15]), int(info[16]),  # type: ignore[arg-type]
            parent_frame_rpy=quat_to_rpy(info[15]),
        )

    @property
    def movable(self) -> bool:
        """Whether the joint has a degree of freedom (anything but FIXED)."""
        return self.joint_type != "FIXED"

    @property
    def limited(self) -> bool:
        """Whether PyBullet enforces position limits: it uses lower > upper to mean none."""
        return self.joint_type in ("REVOLUTE", "PRISMATIC") and \
            self.joint_lower_limit <= self.joint_upper_limit and self.urdf_type != "continuous"

    @property
    def type_label(self) -> str:
        """The PyBullet type, with the URDF type where that says more (continuous)."""
        if self.urdf_type == "continuous":
            return "REVOLUTE (continuous)"
        return self.joint_type

    def to_dict(self) -> dict[str, Any]:
        """The JSON contract: the 17 Quickstart Guide keys, then urdfkit's extras."""
        values = (
            self.joint_index, self.joint_name, self.joint_type, self.q_index, self.u_index,
            self.flags, self.joint_damping, self.joint_friction, self.joint_lower_limit,
            self.joint_upper_limit, self.joint_max_force, self.joint_max_velocity,
            self.link_name, list(self.joint_axis), list(self.parent_frame_pos),
            list(self.parent_frame_orn), self.parent_index,
        )
        out = dict(zip(JOINT_INFO_FIELDS, values, strict=False))
        out.update(urdfType=self.urdf_type, parentLinkName=self.parent_link_name,
                   parentFrameRpy=list(self.parent_frame_rpy), movable=self.movable,
                   limited=self.limited)
        return out


def base_link_name(s: Session, body: int) -> str:
    """The name of the body's root link, as PyBullet reports it."""
    return _text(s.call("getBodyInfo", body)[0])


def joint_table(s: Session, body: int, root: etree._Element | None = None) -> list[JointInfo]:
    """Every joint of ``body``, decoded, in PyBullet's index order.

    Args:
        s: The session the body lives in.
        body: The body id from :meth:`Session.load_urdf`.
        root: The ``<robot>`` element the body was loaded from; gives ``urdfType``.
    """
    urdf_types: dict[str, str] = {}
    if root is not None:
        urdf_types = {j.get("name", ""): j.get("type", "") for j in _children(root, "joint")}
    joints = [JointInfo.from_pybullet(s.call("getJointInfo", body, i))
              for i in range(s.call("getNumJoints", body))]
    base = base_link_name(s, body)
    for j in joints:
        j.urdf_type = urdf_types.get(j.joint_name)
        j.parent_link_name = base if j.parent_index < 0 else joints[j.parent_index].link_name
    return joints


def filter_joints(joints: Sequence[JointInfo], *, movable: bool = False,
                  types: Sequence[str] = ()) -> list[JointInfo]:
    """Keep movable joints and/or the given types.

    A type matches the PyBullet name or the URDF type, case-insensitively, so ``--type
    continuous`` and ``--type revolute`` both work.
    """
    wanted = {t.lower() for t in types}
    unknown = sorted(wanted - set(FILTER_TYPES))
    if unknown:
        from .errors import ParameterError

        raise ParameterError(f"--type {unknown[0]!r} is not a joint type; use one of "
                             f"{', '.join(FILTER_TYPES)}")
    out = []
    for j in joints:
        if movable and not j.movable:
            continue
        if wanted and j.joint_type.lower() not in wanted and (j.urdf_type or "") not in wanted:
            continue
        out.append(j)
    return out


# --------------------------------------------------------------------------- links


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
    from .builder import Inertia
    from .errors import ModelError

    mass = _float(el.find("mass"), "value") or 0.0
    i = el.find("inertia")
    values = tuple(_float(i, k) or 0.0 for k in ("ixx", "ixy", "ixz", "iyy", "iyz", "izz"))
    try:
        principal = Inertia(*values).principal_moments
    except ModelError:  # nan/inf in the file: show the diagonal as written
        principal = (values[0], values[3], values[5])
    origin = el.find("origin")
    return FileInertial(mass, values, tuple(sorted(principal)),  # type: ignore[arg-type]
                        _vec(origin, "xyz", (0, 0, 0)), _vec(origin, "rpy", (0, 0, 0)))  # type: ignore[arg-type]


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
        by_name = {el.get("name", ""): el for el in _children(root, "link")}
    names = [base_link_name(s, body)] + [j.link_name for j in joints]
    out = []
    for index, name in zip(range(-1, len(joints)), names, strict=True):
        d = s.call("getDynamicsInfo", body, index)
        out.append(LinkDynamics(
            index, name, float(d[0]), float(d[1]), tuple(d[2]), tuple(d[3]), tuple(d[4]),  # type: ignore[arg-type]
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

    @property
    def size(self) -> Vec3:
        """Extent of the bounding box along x, y, z."""
        return tuple(hi - lo for lo, hi in zip(self.aabb_min, self.aabb_max, strict=False))  # type: ignore[return-value]

    def to_dict(self) -> dict[str, Any]:
        """The JSON form."""
        return {
            "robot": self.robot, "base_link": self.base_link, "links": self.links,
            "joints": self.joints, "joint_types": self.joint_types, "dof": self.dof,
            "fixed_base": self.fixed_base, "total_mass": self.total_mass,
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
    return Summary(
        robot=root.get("name", ""), base_link=base_link_name(s, body), links=len(links),
        joints=len(joints), joint_types=dict(sorted(types.items())),
        dof=sum(JOINT_DOF.get(j.joint_type, 0) for j in joints), fixed_base=fixed_base,
        total_mass=sum(link.mass for link in links),
        file_mass=sum(link.file.mass for link in links if link.file),
        links_without_inertial=[link.link_name for link in links if link.file is None],
        aabb_min=tuple(lo), aabb_max=tuple(hi),  # type: ignore[arg-type]
    )


# --------------------------------------------------------------------------- reports


@dataclass
class Report:
    """What a command shows about one file: its data plus what PyBullet said on the way.

    Attributes:
        file: The file as the user named it.
        path: The file found on disk (for example inside pybullet_data).
        robot: The ``<robot name>``.
        base_link: PyBullet's root link.
        joints: The joint table.
        links: The link table (``urdfkit links`` only).
        summary: The summary (``urdfkit info`` only).
        diagnostics: PyBullet's own output (warnings), captured off stdout.
    """

    file: str
    path: str
    robot: str
    base_link: str
    joints: list[JointInfo] = field(default_factory=list)
    links: list[LinkDynamics] = field(default_factory=list)
    summary: Summary | None = None
    diagnostics: list[str] = field(default_factory=list)

    def header(self) -> dict[str, Any]:
        """The keys every ``--json`` output starts with."""
        return {"file": self.file, "path": self.path, "robot": self.robot,
                "base_link": self.base_link}


@contextmanager
def loaded(resolved: Resolved, options: LoadOptions | None = None) -> Iterator[tuple[Session, int]]:
    """A fresh DIRECT session with the resolved file loaded; disconnected on exit."""
    with Session() as s:
        body = s.load_urdf(resolved.load_path, options, display=resolved.name)
        yield s, body


def inspect_file(resolved: Resolved, options: LoadOptions | None = None, *,
                 links: bool = False, info: bool = False) -> Report:
    """Load a resolved file and read its joint table, and optionally links and summary."""
    options = options or LoadOptions()
    with loaded(resolved, options) as (s, body):
        # One capture around all the queries instead of a temp file per PyBullet call (the
        # inner quiet_stdout blocks are re-entrant no-ops). Loading stays outside it, so a
        # refused file's error message can quote what PyBullet said.
        with quiet_stdout() as out:
            joints = joint_table(s, body, resolved.root)
            report = Report(resolved.name, str(resolved.source), resolved.robot_name,
                            base_link_name(s, body), joints)
            if links:
                report.links = link_table(s, body, resolved.root, joints)
            if info:
                report.summary = summary(s, body, resolved.root, options.fixed_base)
    # After close(), so disconnect's own chatter is included too.
    report.diagnostics = tidy_diagnostics([*s.diagnostics, *out.lines])
    return report


#: The location prefix of PyBullet's b3Warning/b3Error/b3Printf output: source file and line.
_B3_PREFIX = re.compile(r"b3(?:Warning|Error)\[[^\]]*\]:\s*|b3Printf:\s*")


def tidy_diagnostics(lines: Sequence[str]) -> list[str]:
    """PyBullet's captured output as readable, de-duplicated messages.

    PyBullet writes each warning as ``b3Warning[file.cpp,126]:``, a newline, then text with no
    newline after it, so messages run into the next prefix; and it reports the link a warning
    is about as a separate warning of its own. Drop the prefixes, and fold the link name back into
    the "No inertial data for link" message it belongs to.
    """
    parts = [p.strip() for p in _B3_PREFIX.split("\n".join(lines))]
    parts = [p for chunk in parts for p in chunk.splitlines() if p.strip()]
    out: list[str] = []
    i = 0
    while i < len(parts):
        msg = parts[i]
        if msg.startswith("No inertial data for link") and i + 1 < len(parts) and \
                " " not in parts[i + 1]:
            msg = msg.replace("for link,", f"for link {parts[i + 1]!r},", 1)
            i += 1
        out.append(msg)
        i += 1
    return list(dict.fromkeys(out))


# --------------------------------------------------------------------------- kinematic tree


@dataclass
class TreeJoint:
    """A ``<joint>`` as the tree shows it.

    Attributes:
        index: The index PyBullet will give this joint (depth-first, file order).
        axis: ``<axis xyz>``, ``None`` for joint types that have no axis.
        limit: (lower, upper) from ``<limit>``, ``None`` when absent or continuous.
    """

    name: str
    type: str
    index: int
    xyz: Vec3
    rpy: Vec3
    axis: Vec3 | None
    limit: tuple[float, float] | None
    line: int | None = None

    def to_dict(self) -> dict[str, Any]:
        """The JSON form."""
        return {"name": self.name, "type": self.type, "index": self.index,
                "xyz": list(self.xyz), "rpy": list(self.rpy),
                "axis": list(self.axis) if self.axis is not None else None,
                "limit": list(self.limit) if self.limit is not None else None}


@dataclass
class TreeNode:
    """A link and the joints hanging below it.

    Attributes:
        link: The link's name.
        joint: The joint that attaches this link to its parent; ``None`` at the root.
        children: Child nodes in file order, which is PyBullet's index order.
    """

    link: str
    joint: TreeJoint | None = None
    children: list[TreeNode] = field(default_factory=list)

    # Iterative, not recursive: the guard admits chains of up to 1000 links, deeper than
    # Python's recursion limit.
    def walk(self) -> Iterator[TreeNode]:
        """Every node, depth-first (PyBullet's joint order after the root)."""
        stack = [self]
        while stack:
            node = stack.pop()
            yield node
            stack.extend(reversed(node.children))

    def to_dict(self) -> dict[str, Any]:
        """The JSON form, nested."""
        out: dict[str, Any] = {}
        stack: list[tuple[TreeNode, dict[str, Any]]] = [(self, out)]
        while stack:
            node, d = stack.pop()
            d["link"] = node.link
            d["joint"] = node.joint.to_dict() if node.joint is not None else None
            d["children"] = [{} for _ in node.children]
            stack.extend(zip(node.children, d["children"], strict=True))
        return out


#: Joint types whose ``<axis>`` means something (URDF default (1, 0, 0) when absent).
_AXIS_TYPES = ("revolute", "continuous", "prismatic", "planar")


def kinematic_tree(root: etree._Element) -> TreeNode:
    """The link tree of a guarded ``<robot>`` document, with PyBullet's joint indices.

    Needs no PyBullet. The document must have passed :func:`urdfkit.validate.guard` (one
    root, single parents, no cycle); :func:`urdfkit.resolve.resolve` ensures that.
    """
    links = [el.get("name", "") for el in _children(root, "link")]
    below: dict[str, list[etree._Element]] = {}
    has_parent: set[str] = set()
    for j in _children(root, "joint"):
        parent = j.find("parent")
        child = j.find("child")
        if parent is None or child is None:
            continue
        below.setdefault(parent.get("link", ""), []).append(j)
        has_parent.add(child.get("link", ""))
    root_link = next((n for n in links if n not in has_parent), links[0] if links else "")
    top = TreeNode(root_link)
    # Pre-order walk with an explicit stack (see TreeNode.walk); the visit order is
    # PyBullet's joint index order.
    stack = [top]
    index = 0
    while stack:
        node = stack.pop()
        for j in below.get(node.link, []):
            child = TreeNode(j.find("child").get("link", ""))  # type: ignore[union-attr]
            node.children.append(child)
        stack.extend(reversed(node.children))
    # Number the joints in pre-order, now that the tree exists.
    by_child = {j.find("child").get("link", ""): j  # type: ignore[union-attr]
                for js in below.values() for j in js}
    for node in top.walk():
        if node is not top:
            node.joint = _tree_joint(by_child[node.link], index)
            index += 1
    return top


def _tree_joint(j: etree._Element, index: int) -> TreeJoint:
    jtype = j.get("type", "")
    origin = j.find("origin")
    axis = _vec(j.find("axis"), "xyz", (1, 0, 0)) if jtype in _AXIS_TYPES else None
    limit_el = j.find("limit")
    limit = None
    if jtype in ("revolute", "prismatic") and limit_el is not None:
        limit = (_float(limit_el, "lower") or 0.0, _float(limit_el, "upper") or 0.0)
    return TreeJoint(j.get("name", ""), jtype, index, _vec(origin, "xyz", (0, 0, 0)),  # type: ignore[arg-type]
                     _vec(origin, "rpy", (0, 0, 0)), axis, limit, j.sourceline)  # type: ignore[arg-type]
