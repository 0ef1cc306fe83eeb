"""Where the MuJoCo engine's bodies are: base and link frames, resets, joint states.

Each takes the :class:`~urdfkit.engine.mujoco_world.World` and answers in the seam's terms
(:mod:`urdfkit.engine.api`): a body's "base" is its root link's inertial frame, as PyBullet's
``getBasePositionAndOrientation`` gives it, while MuJoCo's free joint moves the root link
frame; a link fused into its parent's MuJoCo body (a fixed joint) keeps its own frame, a site.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

from urdfkit.core.errors import ParameterError
from urdfkit.engine.api import BaseState, JointRow, JointState, LinkPose, Quat, Vec3
from urdfkit.engine.mujoco_build import Loaded
from urdfkit.engine.mujoco_reactions import reaction
from urdfkit.engine.mujoco_world import World, add, cross, rotate, unit_quat, vec3, wxyz

_ZERO6 = (0.0, 0.0, 0.0, 0.0, 0.0, 0.0)


def link_frames(w: World, body: int) -> list[tuple[Vec3, Quat]]:
    """Every link frame's world pose now, the root first (position, quaternion x y z w)."""
    _, ids = w.body(body)
    return [w.frame_of(ids, k)[:2] for k in range(len(ids.frames))]


def link_frame(w: World, body: int, link: int) -> tuple[Vec3, Quat]:
    """One link's URDF frame now, world (link -1: the root)."""
    r, ids = w.body(body)
    r.link(link)   # the range, named
    p, q, _ = w.frame_of(ids, link + 1)
    return p, q


def link_pose(w: World, body: int, link: int) -> LinkPose:
    """One link's inertial and URDF frames now, world (link -1: the root)."""
    from urdfkit.model.spec import quat_mul

    r, ids = w.body(body)
    d = r.link(link).dynamics
    p, q, rot = w.frame_of(ids, link + 1)
    return LinkPose(add(p, rotate(rot, d.inertial_position)),
                    quat_mul(q, d.inertial_orientation), p, q)


def base_pose(w: World, body: int) -> tuple[Vec3, Quat]:
    """The root's inertial frame (PyBullet's base pose), world."""
    from urdfkit.model.spec import quat_mul

    r, ids = w.body(body)
    p0, q0, rot = w.frame_of(ids, 0)
    offset, turn = r.root_offset()
    return add(p0, rotate(rot, offset)), quat_mul(q0, turn)


def base_state(w: World, body: int) -> BaseState:
    """The root's inertial frame (PyBullet's base pose) and its velocity, world."""
    from urdfkit.model.spec import quat_mul

    r, ids = w.body(body)
    p0, q0, rot = w.frame_of(ids, 0)
    offset, turn = r.root_offset()
    p = add(p0, rotate(rot, offset))
    linear, angular = (0.0, 0.0, 0.0), (0.0, 0.0, 0.0)
    if ids.free >= 0:
        a = int(w.m.jnt_dofadr[w.m.body_jntadr[ids.root]])
        qvel = w.d.qvel
        spin = rotate(rot, (qvel[a + 3], qvel[a + 4], qvel[a + 5]))  # a free joint's: local
        arm = (p[0] - p0[0], p[1] - p0[1], p[2] - p0[2])
        linear = add((qvel[a], qvel[a + 1], qvel[a + 2]), cross(spin, arm))
        angular = spin
    return BaseState(p, quat_mul(q0, turn), linear, angular)


def reset_base(w: World, body: int, position: Vec3, orientation: Quat) -> None:
    """Move the root's inertial frame there, at rest."""
    r, _ = w.body(body)
    p, q = inertial_to_link(r, position, unit_quat(orientation))
    place_root(w, body, p, q)


def inertial_to_link(r: Loaded, position: Vec3, orientation: Quat) -> tuple[Vec3, Quat]:
    """The root link frame whose inertial frame is at ``position``, ``orientation`` (unit)."""
    from urdfkit.model.spec import quat_mul, quat_to_matrix

    offset, turn = r.root_offset()
    q = quat_mul(orientation, (-turn[0], -turn[1], -turn[2], turn[3]))
    return add(position, rotate(quat_to_matrix(q), (-offset[0], -offset[1], -offset[2]))), q


def reset_base_frame(w: World, body: int, position: Vec3, orientation: Quat) -> None:
    """Move the root's URDF link frame there, at rest."""
    w.body(body)
    place_root(w, body, vec3(position), unit_quat(orientation))


def place_root(w: World, body: int, p: Vec3, q: Quat) -> None:
    """The root link frame at ``p``, ``q`` (a unit quaternion), at rest."""
    m, d = w.compiled()
    _, ids = w.body(body)
    if ids.free >= 0:
        a = ids.free
        d.qpos[a:a + 3] = p
        d.qpos[a + 3:a + 7] = wxyz(q)
        v = m.jnt_dofadr[m.body_jntadr[ids.root]]
        d.qvel[v:v + 6] = 0.0
    elif ids.root >= 0:
        w.root_poses[body] = (p, q)
        m.body_pos[ids.root] = p
        m.body_quat[ids.root] = wxyz(q)
    else:
        raise ParameterError(f"body {body}'s root is MuJoCo's world; it cannot move",
                             param="body")
    w.kinematics = False


def reset_base_velocity(w: World, body: int, linear: Vec3, angular: Vec3) -> None:
    """Set the root's velocity: its inertial frame's linear velocity, and the angular."""
    m, d = w.compiled()
    r, ids = w.body(body)
    if ids.free < 0:
        return  # a fixed base does not move (PyBullet's does not either)
    _, _, rot = w.frame_of(ids, 0)
    arm = rotate(rot, r.root_offset()[0])   # from the link frame to the inertial frame
    spin = (float(angular[0]), float(angular[1]), float(angular[2]))
    swing = cross(spin, arm)
    a = int(m.jnt_dofadr[m.body_jntadr[ids.root]])
    d.qvel[a:a + 3] = (linear[0] - swing[0], linear[1] - swing[1], linear[2] - swing[2])
    d.qvel[a + 3:a + 6] = rotate(rot.T, spin)


def joint_rows(w: World, body: int, joints: Sequence[int]) -> list[JointRow]:
    """The state of these joints now, as plain tuples (position, velocity, reaction, applied).

    ``applied`` is the motor's force in the last step; ``reaction`` the wrench measured in the
    last step where :meth:`~urdfkit.engine.mujoco.MuJoCoEngine.enable_joint_force_sensor`
    asked for it (:mod:`urdfkit.engine.mujoco_reactions`), zeros elsewhere.
    """
    d = w.compiled()[1]
    r, ids = w.body(body)
    qpos, qvel, sensors = d.qpos, d.qvel, w.sensors
    out: list[JointRow] = []
    for j in joints:
        info = w.joint(r, ids, j)
        measured: Any = reaction(w, body, j) if sensors and (body, j) in sensors else _ZERO6
        if info.kind == "fixed":
            out.append((0.0, 0.0, measured, 0.0))
            continue
        if info.kind == "spherical":
            raise ParameterError(f"joint {info.name!r} is spherical: joint states are read "
                                 "for joints of one degree of freedom", param="joints")
        out.append((float(qpos[info.q_index]), float(qvel[info.v_index]), measured,
                    w.applied(info.v_index)))
    return out


def joint_states(w: World, body: int, joints: Sequence[int]) -> list[JointState]:
    """:func:`joint_rows` as records."""
    return [JointState(q, v, tuple(f), a)   # type: ignore[arg-type]
            for q, v, f, a in joint_rows(w, body, joints)]


def reset_joint(w: World, body: int, joint: int, position: float, velocity: float) -> None:
    """Put one joint at a position and velocity (a fixed joint: nothing to do)."""
    d = w.compiled()[1]
    r, ids = w.body(body)
    info = w.joint(r, ids, joint)
    if info.kind == "fixed":
        return
    if info.kind == "spherical":
        raise ParameterError(f"joint {info.name!r} is spherical: reset_joint sets joints "
                             "of one degree of freedom", param="joint")
    d.qpos[info.q_index] = position
    d.qvel[info.v_index] = velocity
    w.kinematics = False


def reset_spherical_joint(w: World, body: int, joint: int, orientation: Quat) -> None:
    """Put a ball joint at an orientation (x, y, z, w), at rest."""
    d = w.compiled()[1]
    r, ids = w.body(body)
    info = w.joint(r, ids, joint)
    if info.kind != "spherical":
        raise ParameterError(f"joint {info.name!r} is {info.kind}, not spherical",
                             param="joint")
    x, y, z, s = orientation
    d.qpos[info.q_index:info.q_index + 4] = (s, x, y, z)
    d.qvel[info.v_index:info.v_index + 3] = 0.0
    w.kinematics = False


def set_joint_positions(w: World, body: int, positions: Sequence[float],
                        velocities: Sequence[float] | None) -> None:
    """Put every movable joint (in joint order) at these values."""
    d = w.compiled()[1]
    moving = w.movable(body)
    if len(positions) != len(moving) or (velocities is not None
                                         and len(velocities) != len(moving)):
        raise ParameterError(f"`positions` needs {len(moving)} values, one per movable "
                             f"joint of body {body}", param="positions")
    for k, j in enumerate(moving):
        d.qpos[j.q_index] = positions[k]
        d.qvel[j.v_index] = velocities[k] if velocities is not None else 0.0
    w.kinematics = False
