"""PyBullet's user constraints on MuJoCo: a base held to the world, a joint geared to another.

Each is a MuJoCo equality added to the world's spec (the world is recompiled at the next call
that needs it, every joint's state carried over): :func:`hold_base` a weld of the root to the
world where it is now, PyBullet's ``JOINT_FIXED`` constraint; :func:`couple_joints` a joint
equality, ``follower = offset + multiplier * leader`` (its ``polycoef``), PyBullet's
``JOINT_GEAR``. Both are made as hard as MuJoCo allows, as the motors are
(:data:`~urdfkit.engine.mujoco_motors.HARD`, and the shortest time constant MuJoCo takes: two
steps): a base held while its arm swings moves 8.5e-8 m in 1 s; a follower lags by what
docs/engines.md measures.

What cannot be the same: a MuJoCo equality has no force bound, so ``couple_joints``'s
``max_force`` (PyBullet's cap on the gear's impulse) is not a cap here; the engine says so in
its notes for the body.
"""

from __future__ import annotations

import math

from urdfkit.core.errors import ParameterError
from urdfkit.engine.mujoco_motors import HARD
from urdfkit.engine.mujoco_world import World, wxyz

#: An equality's time constant (s): MuJoCo takes two steps instead of anything shorter (its
#: ``refsafe``), the stiffest it simulates stably, whatever the time step is set to later.
SHORTEST = 1e-6


def hold_base(w: World, body: int) -> int:
    """A weld of the root to the world where it is now; the constraint's id.

    A root that MuJoCo already welds to the world (a fixed base) gets an id and nothing more.
    """
    m, _ = w.compiled()
    _, ids = w.body(body)
    cid = w.new_constraint()
    if ids.free < 0:
        return cid
    p, q, _ = w.frame_of(ids, 0)
    eq = w.spec.add_equality(name=f"hold{cid}", type=w.mj.mjtEq.mjEQ_WELD,
                             objtype=w.mj.mjtObj.mjOBJ_BODY, name1="world",
                             name2=m.body(ids.root).name)
    data = [0.0] * 12
    data[3:6] = p                # the root link frame (body 2) in the world (body 1) ...
    data[6:10] = wxyz(q)
    data[10] = 1.0               # ... the anchor at its origin; torques as forces
    eq.data = data
    _harden(eq)
    w.stale = True
    return cid


def couple_joints(w: World, body: int, leader: int, follower: int, multiplier: float,
                  offset: float, max_force: float) -> int:
    """A joint equality holding ``follower`` at ``multiplier * leader + offset``; its id.

    Raises:
        ParameterError: A joint that is not revolute or prismatic, the same joint twice, or
            a multiplier that is not a finite number.
    """
    m, _ = w.compiled()
    r, ids = w.body(body)
    pair = [w.joint(r, ids, leader), w.joint(r, ids, follower)]
    for info in pair:
        if info.kind not in ("revolute", "prismatic"):
            raise ParameterError(f"joint {info.name!r} is {info.kind}: couple_joints couples "
                                 "revolute and prismatic joints", param="joint")
    if leader == follower:
        raise ParameterError(f"joint {pair[0].name!r} cannot follow itself", param="follower")
    if not (math.isfinite(multiplier) and math.isfinite(offset)):
        raise ParameterError(f"`multiplier` {multiplier!r} and `offset` {offset!r} must be "
                             "finite numbers", param="multiplier")
    cid = w.new_constraint()
    lead, follow = (m.joint(ids.jnt[j]) for j in (leader, follower))
    eq = w.spec.add_equality(name=f"couple{cid}", type=w.mj.mjtEq.mjEQ_JOINT,
                             name1=follow.name, name2=lead.name)
    # MuJoCo's polynomial is about the joints' reference positions (qpos0):
    # y - y0 = a0 + a1 (x - x0); for y = offset + multiplier x, a0 = offset - y0 + a1 x0.
    x0, y0 = float(m.qpos0[pair[0].q_index]), float(m.qpos0[pair[1].q_index])
    data = [0.0] * 12
    data[0] = offset - y0 + multiplier * x0
    data[1] = multiplier
    eq.data = data
    _harden(eq)
    w.stale = True
    w.notes.setdefault(body, []).append(
        f"joint {pair[1].name!r} follows {pair[0].name!r} by a MuJoCo joint equality, which "
        f"has no force bound: its max_force {max_force:g} is not a cap here")
    return cid


def _harden(eq: object) -> None:
    eq.solref = [SHORTEST, 1.0]   # type: ignore[attr-defined]
    eq.solimp = list(HARD)        # type: ignore[attr-defined]
