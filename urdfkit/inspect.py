"""Turn a loaded body into plain data: the joint table, and the report every command fills.

Everything here returns dataclasses; nothing prints. ``cli.py`` presents them as rich tables
or JSON. The link table and the summary live in :mod:`urdfkit.body`, the kinematic tree (no
PyBullet) in :mod:`urdfkit.tree`, so that ``urdfkit joints`` loads only what it shows.

The joint table carries all 17 fields of ``p.getJointInfo`` under the names the PyBullet
Quickstart Guide uses (``jointIndex`` ... ``parentIndex``); :meth:`JointInfo.to_dict` is the
JSON contract of ``urdfkit joints --json`` (see ``docs/inspect.md``). Three PyBullet facts
shape this module:

- Continuous joints come back as ``JOINT_REVOLUTE`` with lower=0, upper=-1 (PyBullet's "no
  limit" marker). Only the URDF says they were continuous, so each joint is matched to its
  ``<joint>`` element by name to report ``urdfType``.
- ``parentFramePos``/``parentFrameOrn`` are relative to the parent's *inertial* frame (its
  centre of mass), not to the parent link frame the URDF ``<origin>`` is written in.
- Joints are indexed depth-first from the root, each link's children in file order; a
  joint's parent link is the child link of joint ``parentIndex`` (-1: the base link).
"""

from __future__ import annotations

import math
import re
from collections.abc import Iterator, Sequence
from contextlib import contextmanager
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any

from lxml import etree

from .resolve import Resolved
from .session import LoadOptions, Session, quiet_stdout
from .xmlio import children

if TYPE_CHECKING:
    from .body import LinkDynamics, Summary

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
            tuple(info[13]), tuple(info[14]), tuple(info[15]), int(info[16]),
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
        urdf_types = {j.get("name", ""): j.get("type", "") for j in children(root, "joint")}
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
            if links or info:
                from .body import link_table, summary

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
