"""PyBullet's joint force/torque sensor on MuJoCo: the wrench a joint carries, as PyBullet says it.

PyBullet's ``enableJointForceTorqueSensor`` reports, for a joint, the force and torque its
parent link exerts on the child's subtree through it, in the child link's inertial frame and
about its centre of mass: ``[fx, fy, fz, mx, my, mz]``. Measured on PyBullet 3.2.7 (a 1 kg
pendulum, tests/test_engine_contract.py): a torque set by ``TORQUE_CONTROL`` and the joint's
damping are in it, the joint's own motor and limit are not (a pendulum held at 0.5 rad by a
velocity motor reads the hinge's moment alone, -2.35 N m about y; held by the same torque set
as a torque, 0).

MuJoCo computes the same wrench for a body's subtree (``cfrc_int``, by
``mj_rnePostConstraint``, contacts included). :func:`measure`, which
:meth:`~urdfkit.engine.mujoco.MuJoCoEngine.step` calls after each step only while a sensor is
on, has MuJoCo compute it at the state the step started from (as PyBullet's is, during its
step): the velocities are put back for the call, the positions' kinematics are still the
step's. A reading (:func:`reaction`) then does what PyBullet does: the joint's own constraint
rows are taken out (its motor, its limit, a coupling), and the wrench is moved to the child
link's centre of mass and turned into its inertial frame. The step pays only MuJoCo's call and
three copies (5 us on simplecar); the reading pays the rest, once per step and joint.

A fixed joint's child, fused into its parent's MuJoCo body, has no ``cfrc_int`` of its own:
its wrench is summed from what MuJoCo gives the bodies (each fused link's inertia times the
body's acceleration, the contacts on its geoms, the bodies hanging from it).
"""

from __future__ import annotations

from typing import Any

from urdfkit.engine.mujoco_build import Loaded, WorldLink
from urdfkit.engine.mujoco_world import Ids, World


def measure(w: World, m: Any, d: Any, before: Any) -> None:
    """MuJoCo's subtree wrenches of the step just taken; ``before``: its starting velocities.

    What a reading needs and a later call could overwrite (the frames, which the next query
    of a frame recomputes at the new positions) is kept; the rest stays in ``d`` until the
    next step. The wrenches are turned into PyBullet's terms when read (:func:`reaction`).
    """
    after = d.qvel.copy()
    d.qvel[:] = before
    w.mj.mj_rnePostConstraint(m, d)
    d.qvel[:] = after
    w.sensed = (d.xpos.copy(), d.xmat.copy(), d.xaxis.copy())
    w.held = None
    w.reactions.clear()


def reaction(w: World, body: int, j: int) -> tuple[float, ...]:
    """Joint ``j``'s wrench in the last step, PyBullet's ``[fx, fy, fz, mx, my, mz]``.

    Zeros before the first step with the sensor on, and after the world was recompiled.
    """
    import numpy as np

    found = w.reactions.get((body, j))
    if found is not None:
        return found
    if w.sensed is None:
        return (0.0,) * 6
    m, d = w.m, w.d
    if w.held is None:
        w.held = _joint_rows_force(w, m, d, np)
    found = w.reactions[(body, j)] = _wrench(w, m, d, np, body, j, w.held)
    return found


def _joint_rows_force(w: World, m: Any, d: Any, np: Any) -> Any:
    """The generalized force of the joints' own constraint rows: motors, limits, couplings."""
    mj = w.mj
    kinds = mj.mjtConstraint
    n = d.nefc
    types = d.efc_type[:n]
    mine = (types == int(kinds.mjCNSTR_FRICTION_DOF)) | \
        (types == int(kinds.mjCNSTR_LIMIT_JOINT))
    equality = np.flatnonzero(types == int(kinds.mjCNSTR_EQUALITY))
    if len(equality):
        joint = m.eq_type[d.efc_id[equality]] == int(mj.mjtEq.mjEQ_JOINT)
        mine[equality[joint]] = True
    force = np.where(mine, d.efc_force[:n], 0.0)
    out = np.zeros(m.nv)
    if n:
        mj.mj_mulJacTVec(m, d, out, force)
    return out


def _wrench(w: World, m: Any, d: Any, np: Any, body: int, j: int, held: Any
            ) -> tuple[float, ...]:
    """Joint ``j``'s wrench as PyBullet reports it (see the module)."""
    r, ids = w.robots[body], w.ids[body]
    child = r.links[j + 1]
    b = ids.bodies[child.body]
    point = d.subtree_com[m.body_rootid[b]]
    if child.body == child.name:
        spatial = np.array(d.cfrc_int[b])     # torque about `point`, then force; world axes
        jid = ids.jnt[j]
        if jid >= 0 and w.sensed is not None:   # the joint's own rows: not in PyBullet's
            along = w.sensed[2][jid] * held[m.jnt_dofadr[jid]]
            if m.jnt_type[jid] == w.mj.mjtJoint.mjJNT_HINGE:
                spatial[:3] -= along
            else:
                spatial[3:] -= along
    else:
        spatial = _fused(w, m, d, np, body, child, point)
    com, rot = _inertial(w, np, ids, child)
    force = spatial[3:]
    torque = spatial[:3] + np.cross(point - com, force)
    return (*(rot.T @ force).tolist(), *(rot.T @ torque).tolist())


def _inertial(w: World, np: Any, ids: Ids, link: WorldLink) -> tuple[Any, Any]:
    """A link's inertial frame in the world at the step: its origin and rotation."""
    from urdfkit.model.spec import quat_to_matrix

    assert w.sensed is not None
    xpos, xmat, _ = w.sensed
    b = ids.bodies[link.body]
    body_rot = xmat[b].reshape(3, 3)
    frame = np.asarray(link.frame, dtype=float)
    dyn = link.dynamics
    rot = body_rot @ frame[:3, :3] @ np.array(quat_to_matrix(dyn.inertial_orientation))
    origin = xpos[b] + body_rot @ (frame[:3, 3] + frame[:3, :3] @ dyn.inertial_position)
    return origin, rot


def _fused(w: World, m: Any, d: Any, np: Any, body: int, child: WorldLink, point: Any) -> Any:
    """The wrench on a fused link's subtree, about ``point`` in world axes.

    Its links' motion, less the contacts on their geoms, plus the bodies that hang from them.
    """
    r, ids = w.robots[body], w.ids[body]
    below = _subtree(r, child.name)
    b = ids.bodies[child.body]
    omega, v = d.cvel[b][:3], d.cvel[b][3:]
    alpha, a = d.cacc[b][:3], d.cacc[b][3:]
    total = np.zeros(6)
    for link in r.links:
        if link.name not in below:
            continue
        if link.body != child.body:
            if link.body == link.name and r.parents.get(link.name) == child.body:
                total += d.cfrc_int[ids.bodies[link.name]]   # a body hanging from them
            continue
        dyn = link.dynamics
        if dyn.mass <= 0:
            continue
        com, rot = _inertial(w, np, ids, link)
        c = com - point
        inertia = rot @ np.diag(dyn.inertia) @ rot.T
        about = inertia + dyn.mass * (c @ c * np.eye(3) - np.outer(c, c))

        def times(wv: Any, lv: Any, _i: Any = about, _c: Any = c, _m: float = dyn.mass
                  ) -> tuple[Any, Any]:
            """The link's spatial inertia times a motion (MuJoCo's mju_mulInertVec)."""
            return _i @ wv + _m * np.cross(_c, lv), _m * (lv + np.cross(wv, _c))

        ta, fa = times(alpha, a)
        tv, fv = times(omega, v)
        total[:3] += ta + np.cross(omega, tv) + np.cross(v, fv)
        total[3:] += fa + np.cross(omega, fv)
    mine = {m.geom(f"{body}/{g}").id for g, owner in r.geom_links.items()
            if owner in below}
    f6 = np.zeros(6)
    for i in range(d.ncon):
        con = d.contact[i]
        sign = 1.0 if con.geom[1] in mine else -1.0 if con.geom[0] in mine else 0.0
        if not sign or (con.geom[0] in mine and con.geom[1] in mine):
            continue
        w.mj.mj_contactForce(m, d, i, f6)
        frame = np.array(con.frame).reshape(3, 3)
        force, torque = sign * frame.T @ f6[:3], sign * frame.T @ f6[3:]
        total[:3] -= torque + np.cross(np.array(con.pos) - point, force)
        total[3:] -= force
    return total


def _subtree(r: Loaded, link: str) -> set[str]:
    """A link and every link below it."""
    out, todo = {link}, [link]
    while todo:
        name = todo.pop()
        for j in r.robot.joints:
            if j.parent == name and j.child not in out:
                out.add(j.child)
                todo.append(j.child)
    return out

