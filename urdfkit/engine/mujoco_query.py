"""What the MuJoCo engine computes from its world: contacts, the mass matrix, inverse dynamics.

Each takes the :class:`~urdfkit.engine.mujoco_world.World` and answers in the seam's terms
(:mod:`urdfkit.engine.api`): PyBullet's bodies, links and sign conventions.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

from urdfkit.core.errors import ParameterError
from urdfkit.engine.api import ContactPoint, Quat, Vec3
from urdfkit.engine.mujoco_build import Loaded
from urdfkit.engine.mujoco_world import Ids, World, unit_quat, vec3, wxyz


def contacts(w: World, body: int, link: int | None = None, other: int | None = None
             ) -> list[ContactPoint]:
    """The contact points of the last step: ``body`` (one link, or all) with ``other``.

    A is ``body``; the normal points from B to A and the normal force pushes A off B.
    """
    import numpy as np

    m, d = w.compiled()
    w.body(body)
    mj = w.mj
    owner = w.geom_owner
    out = []
    f = np.zeros(6)
    for i in range(d.ncon):
        c = d.contact[i]
        a, b = owner.get(int(c.geom[0])), owner.get(int(c.geom[1]))
        if a is None or b is None:
            continue
        if a[0] == body and (link is None or a[1] == link):
            flip = False
        elif b[0] == body and (link is None or b[1] == link):
            flip, a, b = True, b, a
        else:
            continue
        if other is not None and b[0] != other:
            continue
        mj.mj_contactForce(m, d, i, f)
        frame = np.array(c.frame).reshape(3, 3)
        n = frame[0]  # from geom 1 to geom 2
        pos = np.array(c.pos)
        p1, p2 = pos - n * c.dist / 2, pos + n * c.dist / 2
        # MuJoCo's force is geom 1's on geom 2; PyBullet's normal points from B to A
        sign = -1.0 if not flip else 1.0   # A is geom 1 unless flipped
        out.append(ContactPoint(
            body_a=a[0], body_b=b[0], link_a=a[1], link_b=b[1],
            position_a=vec3(p2 if flip else p1), position_b=vec3(p1 if flip else p2),
            normal=vec3(sign * n), distance=float(c.dist), normal_force=float(f[0]),
            friction1=float(f[1]), direction1=vec3(-sign * frame[1]),
            friction2=float(f[2]), direction2=vec3(-sign * frame[2])))
    return out


def closest_points(w: World, body: int, other: int, distance: float, link: int | None = None,
                   other_link: int | None = None) -> list[ContactPoint]:
    """The closest points of ``body`` (one link, or all) and ``other`` within ``distance``.

    PyBullet's getClosestPoints by MuJoCo's ``mj_geomDistance``: one point per pair of
    collision shapes nearer than ``distance`` (PyBullet gives up to four of a contact
    manifold: two boxes sunk into each other), at the positions now. A is ``body``; the
    normal points from B to A; a negative distance is a penetration; no forces. A body with
    itself: every pair of its shapes, a shape never with itself.
    """
    import math

    import numpy as np

    m, d = w.compiled()
    w.body(body)
    w.body(other)
    w.fresh_kinematics()
    mine = [(g, o[1]) for g, o in w.colliders.items()
            if o[0] == body and (link is None or o[1] == link)]
    theirs = [(g, o[1]) for g, o in w.colliders.items()
              if o[0] == other and (other_link is None or o[1] == other_link)]
    reach = math.nextafter(float(distance), math.inf)  # MuJoCo returns this when farther
    fromto = np.zeros(6)
    out = []
    for ga, la in mine:
        for gb, lb in theirs:
            if ga == gb:
                continue
            dist = float(w.mj.mj_geomDistance(m, d, ga, gb, reach, fromto))
            if not dist <= distance:
                continue
            pa, pb = fromto[:3].copy(), fromto[3:].copy()
            gap = pa - pb
            size = float(np.linalg.norm(gap))
            # from B to A: A's point lies beyond B's when apart, inside it when sunk in
            normal = gap / size * (1.0 if dist >= 0 else -1.0) if size > 0 else np.zeros(3)
            out.append(ContactPoint(
                body_a=body, body_b=other, link_a=la, link_b=lb, position_a=vec3(pa),
                position_b=vec3(pb), normal=vec3(normal), distance=dist, normal_force=0.0,
                friction1=0.0, direction1=(0.0, 0.0, 0.0), friction2=0.0,
                direction2=(0.0, 0.0, 0.0)))
    return out


def mass_matrix(w: World, body: int, positions: Sequence[float]) -> list[list[float]]:
    """The joint-space mass matrix at ``positions``, PyBullet's calculateMassMatrix.

    A floating base's 6 coordinates first: its angular, then its linear velocity, in the
    root's inertial frame (PyBullet computes with the base at the origin, unturned); then the
    movable joints. The rest of the world stays as it is.
    """
    import numpy as np

    m, s = w.posed(body, positions, None)
    full = _full_mass(w, m, s, np)
    base = _coordinates(w, body, s, np, world=False)
    return (base.T @ full @ base).tolist()


def floating_mass_matrix(w: World, body: int, position: Vec3, orientation: Quat,
                         positions: Sequence[float]) -> list[list[float]]:
    """The mass matrix with the root's inertial frame at this pose, PyBullet's ``flags=1``.

    Its 6 base coordinates first: the linear velocity of the root's centre of mass, then the
    angular velocity, both in world axes; then the movable joints.

    Raises:
        ParameterError: The body's root does not float.
    """
    import numpy as np

    from urdfkit.engine.mujoco_bodies import inertial_to_link

    m, s = w.posed(body, positions, None)
    r, ids = w.body(body)
    if ids.free < 0:
        raise ParameterError(f"body {body}'s root is fixed: floating_mass_matrix is the mass "
                             "matrix of a floating base", param="body")
    p, q = inertial_to_link(r, position, unit_quat(orientation))
    s.qpos[ids.free:ids.free + 3] = p
    s.qpos[ids.free + 3:ids.free + 7] = wxyz(q)
    full = _full_mass(w, m, s, np)
    base = _coordinates(w, body, s, np, world=True)
    return (base.T @ full @ base).tolist()


def jacobian(w: World, body: int, link: int, point: Vec3, positions: Sequence[float]
             ) -> tuple[list[list[float]], list[list[float]]]:
    """The linear and angular Jacobians of a point of a link, PyBullet's calculateJacobian.

    ``point`` is from the link's URDF frame's origin along its inertial frame's axes, as
    PyBullet takes it (measured on 3.2.7: a link whose ``<inertial>`` is turned; the URDF
    frame's axes otherwise). Columns as :func:`mass_matrix`'s coordinates (a
    floating base's angular and linear velocity first); rows in the root's inertial frame,
    PyBullet's world when it computes (the base at the origin, unturned).
    """
    import numpy as np

    from urdfkit.model.spec import quat_to_matrix

    m, s = w.posed(body, positions, None)
    r, ids = w.body(body)
    mj = w.mj
    mj.mj_kinematics(m, s)
    mj.mj_comPos(m, s)
    at, _, rot = _frame(s, ids, link + 1)
    # PyBullet's point: from the link frame's origin along its inertial frame's axes
    axes = rot @ np.array(quat_to_matrix(r.link(link).dynamics.inertial_orientation))
    where = np.array(at) + axes @ np.array(point, dtype=float)
    kind, i = ids.frames[link + 1]
    b = i if kind == "body" else int(m.site_bodyid[i])
    lin, ang = np.zeros((3, m.nv)), np.zeros((3, m.nv))
    mj.mj_jac(m, s, lin, ang, where, b)
    base = _coordinates(w, body, s, np, world=False)
    turn = _root_inertial(r, ids, s, np).T
    return (turn @ lin @ base).tolist(), (turn @ ang @ base).tolist()


def _full_mass(w: World, m: Any, s: Any, np: Any) -> Any:
    """The world's whole mass matrix at the scratch data's positions."""
    mj = w.mj
    mj.mj_kinematics(m, s)
    mj.mj_comPos(m, s)
    mj.mj_crb(m, s)
    full = np.zeros((m.nv, m.nv))
    if hasattr(s, "qM"):   # MuJoCo 3: mj_fullM(m, dst, qM)
        mj.mj_fullM(m, full, s.qM)
    else:                  # MuJoCo 4: mj_fullM(m, d, dst)
        mj.mj_fullM(m, s, full)
    return full


def _coordinates(w: World, body: int, s: Any, np: Any, world: bool) -> Any:
    """MuJoCo's velocities (nv) from PyBullet's coordinates of ``body`` (a matrix).

    PyBullet's: a floating base's 6 (angular then linear in the root's inertial frame; with
    ``world``, linear then angular in world axes), then the movable joints. MuJoCo's free
    joint moves the root link frame's origin (world axes) and turns about it (local axes).
    """
    r, ids = w.body(body)
    moving = w.movable(body)
    n = 6 if ids.free >= 0 else 0
    out = np.zeros((w.m.nv, n + len(moving)))
    for k, j in enumerate(moving):
        out[j.v_index, n + k] = 1.0
    if n:
        m = w.m
        a = int(m.jnt_dofadr[m.body_jntadr[ids.root]])
        link_rot = s.xmat[ids.root].reshape(3, 3)
        arm = link_rot @ np.array(r.root_offset()[0])       # link origin to centre of mass
        axes = np.eye(3) if world else _root_inertial(r, ids, s, np)
        spin, move = (slice(3, 6), slice(0, 3)) if world else (slice(0, 3), slice(3, 6))
        cross = np.array([[0.0, -arm[2], arm[1]], [arm[2], 0.0, -arm[0]],
                          [-arm[1], arm[0], 0.0]])
        out[a:a + 3, move] = axes                  # the centre of mass's velocity ...
        out[a:a + 3, spin] = cross @ axes          # ... is the origin's plus w x arm
        out[a + 3:a + 6, spin] = link_rot.T @ axes
    return out


def _root_inertial(r: Loaded, ids: Ids, s: Any, np: Any) -> Any:
    """The root's inertial frame's rotation (3x3, world) in the scratch data."""
    from urdfkit.model.spec import quat_to_matrix

    rot = _frame(s, ids, 0)[2]
    return rot @ np.array(quat_to_matrix(r.root_offset()[1]))


def _frame(s: Any, ids: Ids, k: int) -> tuple[Any, Any, Any]:
    """Link frame ``k`` (0: the root) in data ``s``: position, None, rotation (3x3)."""
    kind, i = ids.frames[k]
    if kind == "body":
        return s.xpos[i], None, s.xmat[i].reshape(3, 3)
    return s.site_xpos[i], None, s.site_xmat[i].reshape(3, 3)


def inverse_dynamics(w: World, body: int, positions: Sequence[float],
                     velocities: Sequence[float], accelerations: Sequence[float]
                     ) -> list[float]:
    """The joint torques that give ``accelerations`` at this state, gravity included.

    Rigid-body dynamics only, as PyBullet's calculateInverseDynamics: no contact, limit,
    joint damping or motor; a floating base held still.
    """
    m, s = w.posed(body, positions, velocities)
    mj = w.mj
    moving = w.movable(body)
    if len(accelerations) != len(moving):
        raise ParameterError(f"`accelerations` needs {len(moving)} values",
                             param="accelerations")
    s.qacc[:] = 0.0
    for k, j in enumerate(moving):
        s.qacc[j.v_index] = accelerations[k]
    off = (mj.mjtDisableBit.mjDSBL_CONSTRAINT | mj.mjtDisableBit.mjDSBL_SPRING
           | mj.mjtDisableBit.mjDSBL_DAMPER)
    flags = m.opt.disableflags
    m.opt.disableflags = flags | off
    try:
        mj.mj_inverse(m, s)
    finally:
        m.opt.disableflags = flags
    return [float(s.qfrc_inverse[j.v_index]) for j in moving]
