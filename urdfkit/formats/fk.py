"""Forward kinematics in double precision, from the URDF itself (no engine).

``agree`` holds MuJoCo's frames to these at 1e-12 m: PyBullet's ``getLinkState`` is float32
inside (its frames are good to ~1e-7 m), so it cannot tell a file written with 6 significant
digits from one written in full; this can. :func:`child_frame` and :func:`moved` are the one
composition of a link's frame: :func:`link_frames` walks the robot with them, and ``check``'s
U311 (``checks/rules_joints``) places the links of its zero-pose mass matrix with them. Plain
Python, so that ``check`` stays without numpy.
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from typing import TYPE_CHECKING, Any

from urdfkit.model.spec import Matrix3, Vec3, axis_angle_matrix, matmul, rotate, rpy_to_matrix

if TYPE_CHECKING:
    from urdfkit.formats.robot import LoadedJoint, LoadedRobot

#: A link's frame: its rotation (the link's axes in the world's) and its origin.
Frame = tuple[Matrix3, Vec3]
#: The world's own frame.
WORLD: Frame = (((1.0, 0.0, 0.0), (0.0, 1.0, 0.0), (0.0, 0.0, 1.0)), (0.0, 0.0, 0.0))


def origin_matrix(xyz: Any, rpy: Any) -> Any:
    """The 4x4 transform of a URDF ``<origin>``."""
    import numpy as np

    t = np.eye(4)
    t[:3, :3] = rpy_to_matrix(rpy)
    t[:3, 3] = xyz
    return t


def unit(axis: Any) -> tuple[float, float, float]:
    """``axis`` normalised, as both engines do."""
    n = math.sqrt(sum(a * a for a in axis))
    return (axis[0] / n, axis[1] / n, axis[2] / n)


def child_frame(parent: Frame, xyz: Sequence[float], rpy: Sequence[float]) -> Frame:
    """A joint's child link frame at q = 0: its parent's, moved by the joint's ``<origin>``."""
    rot, pos = parent
    o = rotate(rot, xyz)
    return matmul(rot, rpy_to_matrix(rpy)), (pos[0] + o[0], pos[1] + o[1], pos[2] + o[2])


def moved(frame: Frame, joint: LoadedJoint, q: float) -> Frame:
    """A 1-dof joint's child frame (at q = 0: ``frame``) at position ``q`` (rad or m)."""
    if q == 0:
        return frame
    rot, pos = frame
    if joint.type in ("revolute", "continuous"):
        return matmul(rot, axis_angle_matrix(unit(joint.axis), q)), pos
    if joint.type == "prismatic":
        a = unit(joint.axis)
        o = rotate(rot, (a[0] * q, a[1] * q, a[2] * q))
        return rot, (pos[0] + o[0], pos[1] + o[1], pos[2] + o[2])
    return frame


def frames(robot: LoadedRobot, q: Mapping[str, float], base: Frame = WORLD) -> dict[str, Frame]:
    """Every link's frame at joint positions ``q`` (missing joints at 0), the root's ``base``.

    Spherical joints count as fixed here (``agree`` poses 1-dof joints only).
    """
    out = {robot.root: base}
    for j in robot.joints:  # PyBullet's depth-first order: a parent before its children
        f = child_frame(out[j.parent], j.xyz, j.rpy)
        if j.type in ("revolute", "continuous", "prismatic"):
            f = moved(f, j, q.get(j.name, 0.0))
        out[j.child] = f
    return out


def link_frames(robot: LoadedRobot, q: Mapping[str, float], base: Any = None) -> dict[str, Any]:
    """:func:`frames` as 4x4 transforms (numpy); ``base`` the root's (identity by default)."""
    import numpy as np

    start = WORLD
    if base is not None:
        (r0, r1, r2), p = base[:3, :3].tolist(), base[:3, 3].tolist()
        start = ((r0[0], r0[1], r0[2]), (r1[0], r1[1], r1[2]), (r2[0], r2[1], r2[2])), \
            (p[0], p[1], p[2])
    out = {}
    for name, (rot, pos) in frames(robot, q, start).items():
        t = np.eye(4)
        t[:3, :3] = rot
        t[:3, 3] = pos
        out[name] = t
    return out


def fused(robot: LoadedRobot, split_world: bool = False) -> dict[str, tuple[str, Any]]:
    """Each link's body after fixed links are fused: (body link, the link's frame in it).

    A body is the root link or the child of a joint that moves; a link under a fixed joint
    belongs to its parent's body, at the fixed joints' composed origins. With
    ``split_world``, a root link named ``world`` (MuJoCo's own world body, which takes no
    mass) keeps each fixed child as a body of its own, welded to it.
    """
    import numpy as np

    out: dict[str, tuple[str, Any]] = {robot.root: (robot.root, np.eye(4))}
    split = split_world and robot.root == "world"
    for j in robot.joints:
        if j.moves or (split and j.parent == robot.root):
            out[j.child] = (j.child, np.eye(4))
        else:
            body, at = out[j.parent]
            out[j.child] = (body, at @ origin_matrix(j.xyz, j.rpy))
    return out
