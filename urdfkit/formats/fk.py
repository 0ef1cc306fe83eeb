"""Forward kinematics in double precision, from the URDF itself (no engine).

``agree`` holds MuJoCo's frames to these at 1e-12 m: PyBullet's ``getLinkState`` is float32
inside (its frames are good to ~1e-7 m), so it cannot tell a file written with 6 significant
digits from one written in full; this can.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from typing import Any

from urdfkit.formats.robot import Joint, Robot
from urdfkit.model.spec import axis_angle_matrix, rpy_to_matrix


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


def motion(joint: Joint, q: float) -> Any:
    """The transform a 1-dof joint adds at position ``q`` (rad or m)."""
    import numpy as np

    t = np.eye(4)
    if joint.type in ("revolute", "continuous"):
        t[:3, :3] = axis_angle_matrix(unit(joint.axis), q)
    elif joint.type == "prismatic":
        t[:3, 3] = np.array(unit(joint.axis)) * q
    return t


def link_frames(robot: Robot, q: Mapping[str, float], base: Any = None) -> dict[str, Any]:
    """Every link's frame (4x4, world) at joint positions ``q`` (missing joints at 0).

    ``base`` is the root link's frame (identity by default). Spherical joints count as fixed
    here (``agree`` poses 1-dof joints only).
    """
    import numpy as np

    frames = {robot.root: np.eye(4) if base is None else base}
    for j in robot.joints:
        t = frames[j.parent] @ origin_matrix(j.xyz, j.rpy)
        if j.type in ("revolute", "continuous", "prismatic"):
            t = t @ motion(j, q.get(j.name, 0.0))
        frames[j.child] = t
    return frames


def fused(robot: Robot, split_world: bool = False) -> dict[str, tuple[str, Any]]:
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
