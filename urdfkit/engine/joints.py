"""The joint table: every joint of a loaded body, decoded, with what its URDF adds.

:mod:`urdfkit.inspect` is the public face and re-exports every name here. The table lives on
the engine's floor, beside the link table and summary (:mod:`urdfkit.engine.body`) and loading
a file into a report (:mod:`urdfkit.engine.report`), so that the rooms that check and draw a
body (collisions, render, the viewer) read it without importing a top-level module, and
``urdfkit joints`` loads only what it shows. Everything here returns dataclasses; nothing prints.

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

from collections.abc import Callable, Collection, Mapping, Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

from lxml import etree

from urdfkit.engine.session import Bullet, Session
from urdfkit.model.spec import (
    JOINT_TYPE_FILTERS,
    attr_float,
    attr_vec,
    pybullet_joint_type,
    quat_to_rpy,
)
from urdfkit.model.xmlio import children

if TYPE_CHECKING:
    from urdfkit.engine import api
    from urdfkit.engine.api import Simulator

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
        origin_xyz, origin_rpy: The joint's ``<origin>`` as the file writes it (in the parent
            link's frame). PyBullet's ``parent_frame_pos``/``orn`` differ: they are relative to
            the parent's centre of mass (its inertial frame), not its link frame. None if no
            ``<joint>`` of that name is in the file.
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
    origin_xyz: Vec3 | None = None
    origin_rpy: Vec3 | None = None
    axis_xyz: Vec3 | None = None
    #: The file's ``<mimic>`` (leader ``joint``, ``multiplier``, ``offset``; URDF's defaults 1
    #: and 0), which PyBullet ignores; None without one.
    mimic: dict[str, Any] | None = None

    @classmethod
    def from_pybullet(cls, info: Sequence[Any]) -> JointInfo:
        """Decode the raw 17-tuple: bytes to text, type code to name, tuples kept as tuples."""
        return cls(
            int(info[0]), _text(info[1]), pybullet_joint_type(info[2]),
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
                   limited=self.limited,
                   originXyz=None if self.origin_xyz is None else list(self.origin_xyz),
                   originRpy=None if self.origin_rpy is None else list(self.origin_rpy),
                   axisXyz=None if self.axis_xyz is None else list(self.axis_xyz),
                   mimic=self.mimic)
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
    origins: dict[str, tuple[Vec3, Vec3]] = {}
    axes: dict[str, Vec3] = {}
    mimics: dict[str, dict[str, Any]] = {}
    if root is not None:
        for el in children(root, "joint"):
            urdf_types[el.get("name", "")] = el.get("type", "")
            origin = el.find("origin")
            xyz = attr_vec(origin, "xyz", 3, (0.0, 0.0, 0.0)) or (0.0, 0.0, 0.0)
            rpy = attr_vec(origin, "rpy", 3, (0.0, 0.0, 0.0)) or (0.0, 0.0, 0.0)
            origins[el.get("name", "")] = (tuple(xyz), tuple(rpy))  # type: ignore[assignment]
            # The file's axis, in the joint (child link) frame; URDF's default is x.
            axis = attr_vec(el.find("axis"), "xyz", 3, (1.0, 0.0, 0.0)) or (1.0, 0.0, 0.0)
            axes[el.get("name", "")] = tuple(axis)  # type: ignore[assignment]
            mimic = el.find("mimic")
            if mimic is not None:
                mimics[el.get("name", "")] = {
                    "joint": mimic.get("joint"),
                    "multiplier": attr_float(mimic, "multiplier", 1.0),
                    "offset": attr_float(mimic, "offset", 0.0)}
    joints = [JointInfo.from_pybullet(s.call("getJointInfo", body, i))
              for i in range(s.call("getNumJoints", body))]
    base = base_link_name(s, body)
    for j in joints:
        j.urdf_type = urdf_types.get(j.joint_name)
        if j.joint_name in origins:
            j.origin_xyz, j.origin_rpy = origins[j.joint_name]
            j.axis_xyz = axes[j.joint_name]
            j.mimic = mimics.get(j.joint_name)
        j.parent_link_name = base if j.parent_index < 0 else joints[j.parent_index].link_name
    return joints


def filter_joints(joints: Sequence[JointInfo], *, movable: bool = False,
                  types: Sequence[str] = ()) -> list[JointInfo]:
    """Keep movable joints and/or the given types.

    A type matches the PyBullet name or the URDF type, case-insensitively, so ``--type
    continuous`` and ``--type revolute`` both work.
    """
    wanted = {t.lower() for t in types}
    unknown = sorted(wanted - set(JOINT_TYPE_FILTERS))
    if unknown:
        from urdfkit.core.errors import ParameterError
        from urdfkit.core.suggest import hint

        raise ParameterError(f"`types` {unknown[0]!r} is not a joint type"
                             f"{hint(unknown[0], JOINT_TYPE_FILTERS)} (use one of "
                             f"{', '.join(JOINT_TYPE_FILTERS)})", param="types")
    out = []
    for j in joints:
        if movable and not j.movable:
            continue
        if wanted and j.joint_type.lower() not in wanted and (j.urdf_type or "") not in wanted:
            continue
        out.append(j)
    return out


def pose_joints(bullet: Bullet, body: int, joints: Sequence[JointInfo],
                values: Mapping[str, float], warnings: list[str], file: str
                ) -> dict[str, float]:
    """Set joint positions by name with ``resetJointState``; return them by joint name.

    Only one-degree-of-freedom joints can be posed this way. A value beyond the joint's limits
    is set anyway (the user asked for it) and noted in ``warnings``.

    Raises:
        ParameterError: an unknown name, a fixed joint, or a multi-DOF joint.
    """
    rows = {j.joint_name: (j.joint_index, j.joint_type, j.limited, j.joint_lower_limit,
                           j.joint_upper_limit) for j in joints}
    return _pose(rows, values, lambda i, v: bullet.resetJointState(body, i, v), warnings, file)


def pose_by_name(engine: Simulator, body: int, joints: Sequence[api.JointInfo],
                 values: Mapping[str, float], warnings: list[str], file: str, *,
                 unlimited: Collection[str] = ()) -> dict[str, float]:
    """:func:`pose_joints` on any engine: the seam's joint records, ``reset_joint``.

    A joint named in ``unlimited`` has no limits to warn of: a URDF ``continuous`` joint,
    whose ``<limit>`` PyBullet reports (:attr:`api.JointInfo.limited` is True for it).
    """
    rows = {j.name: (j.index, j.kind.upper(), j.limited and j.name not in unlimited, j.lower,
                     j.upper) for j in joints}
    return _pose(rows, values, lambda i, v: engine.reset_joint(body, i, v), warnings, file)


def _pose(joints: Mapping[str, tuple[int, str, bool, float, float]],
          values: Mapping[str, float], reset: Callable[[int, float], None],
          warnings: list[str], file: str) -> dict[str, float]:
    """Check each name and value, then ``reset`` it.

    ``joints`` maps each name to (index, PyBullet's type name, limited, lower, upper).
    """
    import math

    from urdfkit.core.errors import ParameterError

    movable = [name for name, j in joints.items() if j[1] != "FIXED"]
    positions: dict[str, float] = {}
    for name, value in values.items():
        if not math.isfinite(value):
            raise ParameterError(f"`joints` {name}: {value!r} is not a finite number",
                                 file=file, param="joints")
        info = joints.get(name)
        if info is None:
            from urdfkit.core.suggest import hint

            known = ", ".join(movable) or "none"
            raise ParameterError(f"`joints`: no joint named {name!r}{hint(name, movable)} "
                                 f"(movable joints: {known})", file=file, param="joints")
        index, kind, limited, lower, upper = info
        if kind == "FIXED":
            raise ParameterError(f"`joints` {name}: a fixed joint cannot move", file=file,
                                 param="joints")
        if kind not in ("REVOLUTE", "PRISMATIC"):
            raise ParameterError(f"`joints` {name}: {kind.lower()} joints take more "
                                 "than one position; only revolute, continuous and prismatic "
                                 "joints can be posed", file=file, param="joints")
        if limited and not lower <= value <= upper:
            warnings.append(f"joint {name}: {value:g} is beyond its limits "
                            f"[{lower:g}, {upper:g}]")
        reset(index, value)
        positions[name] = value
    return positions
