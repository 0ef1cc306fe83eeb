"""What the MuJoCo engine computes from its world: contacts, the mass matrix, inverse dynamics.

Each takes the :class:`~urdfkit.engine.mujoco_world.World` and answers in the seam's terms
(:mod:`urdfkit.engine.api`): PyBullet's bodies, links and sign conventions.
"""

from __future__ import annotations

from collections.abc import Sequence

from urdfkit.core.errors import ParameterError
from urdfkit.engine.api import ContactPoint
from urdfkit.engine.mujoco_world import World, vec3


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


def mass_matrix(w: World, body: int, positions: Sequence[float]) -> list[list[float]]:
    """The joint-space mass matrix at ``positions``: the movable joints' block.

    The rest of the world stays as it is; a floating base's own rows are left out (the
    block is the fixed-base mass matrix).
    """
    import numpy as np

    m, s = w.posed(body, positions, None)
    mj = w.mj
    mj.mj_kinematics(m, s)
    mj.mj_comPos(m, s)
    mj.mj_crb(m, s)
    full = np.zeros((m.nv, m.nv))
    if hasattr(s, "qM"):   # MuJoCo 3: mj_fullM(m, dst, qM)
        mj.mj_fullM(m, full, s.qM)
    else:                  # MuJoCo 4: mj_fullM(m, d, dst)
        mj.mj_fullM(m, s, full)
    dofs = [j.v_index for j in w.movable(body)]
    return full[np.ix_(dofs, dofs)].tolist()


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
