"""A free swing of an MJCF file in MuJoCo, set to integrate as PyBullet does.

``agree`` swings the robot on both engines side by side, step by step (docs/export.md). This
is MuJoCo's side: a copy of the file (the base welded unless the swing floats; each joint
PyBullet locks welded at its value, as PyBullet holds it), stepped with MuJoCo's
semi-implicit Euler and its implicit damping off (``eulerdamp``: PyBullet steps damping
explicitly), contacts, equalities and actuation off.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from typing import Any

from urdfkit.engine.mujoco_file import MjcfFile


class Swing:
    """The file, ready to swing from a start set by :meth:`start`.

    Args:
        file: The compiled file.
        floating: Keep the root body's free joint (``root``), else weld it at the origin.
        locked: Joints of the welded copy (by id) to weld at these values.
        time_step: The step, s.
        root: The root body (its free joint floats).
        joints: The welded copy's joints (by id, none locked) whose positions
            :meth:`positions` reads.

    Raises:
        ValueError, RuntimeError: MuJoCo cannot weld the locked joints (its compiler's error).
    """

    def __init__(self, file: MjcfFile, floating: bool, locked: Mapping[int, float],
                 time_step: float, root: int | None, joints: Sequence[int]) -> None:
        mj = file.mj
        self.mj = mj
        m = self.m = swing_model(file, floating, locked)
        m.opt.timestep = time_step
        m.opt.integrator = mj.mjtIntegrator.mjINT_EULER
        m.opt.disableflags |= (mj.mjtDisableBit.mjDSBL_CONTACT | mj.mjtDisableBit.mjDSBL_EULERDAMP
                               | mj.mjtDisableBit.mjDSBL_EQUALITY
                               | mj.mjtDisableBit.mjDSBL_ACTUATION)
        self.d = mj.MjData(m)
        # the swing model's joints are the base-welded copy's, in order, less the locked
        # ones (welded): matched by position, as unnamed joints have no name to look up
        kept = [k for k in range(file.fixed.njnt) if k not in locked]
        own = [k for k in range(m.njnt) if m.jnt_type[k] != mj.mjtJoint.mjJNT_FREE]
        self._to_swing = dict(zip(kept, own, strict=True))
        self._adr = [int(m.jnt_qposadr[self._to_swing[k]]) for k in joints]
        self.free: int | None = None
        if floating:
            self.free = next((i for i in range(m.njnt) if m.jnt_type[i] == mj.mjtJoint.mjJNT_FREE
                              and int(m.jnt_bodyid[i]) == root), None)

    def start(self, positions: Mapping[int, float], velocities: Mapping[int, float]) -> None:
        """The joints (welded copy's ids) at these positions and speeds.

        A floating swing's free root at the origin, unturned, at rest.
        """
        m, d = self.m, self.d
        for k, q in positions.items():
            d.qpos[m.jnt_qposadr[self._to_swing[k]]] = q
        for k, v in velocities.items():
            d.qvel[m.jnt_dofadr[self._to_swing[k]]] = v
        if self.free is not None:
            at = int(m.jnt_qposadr[self.free])
            d.qpos[at:at + 7] = [0, 0, 0, 1, 0, 0, 0]

    def gravity_off(self) -> None:
        """No gravity (it moves a free robot's every body alike)."""
        self.m.opt.gravity[:] = 0.0

    def step(self) -> None:
        """One ``mj_step``."""
        self.mj.mj_step(self.m, self.d)

    def positions(self) -> list[float]:
        """The positions of the joints given at construction, now."""
        q = self.d.qpos
        return [float(q[a]) for a in self._adr]

    def base_frame(self) -> Any:
        """The root link's frame (4 x 4, world), from its free joint's ``qpos``.

        (``xpos`` would lag a step: it is computed at the start of the next.)
        """
        import numpy as np

        assert self.free is not None  # a floating swing has its root's free joint
        at = int(self.m.jnt_qposadr[self.free])
        turn = np.zeros(9)
        self.mj.mju_quat2Mat(turn, self.d.qpos[at + 3:at + 7])
        t = np.eye(4)
        t[:3, :3] = turn.reshape(3, 3)
        t[:3, 3] = self.d.qpos[at:at + 3]
        return t

    def spin(self) -> float:
        """The root's squared angular speed now, (rad/s)^2."""
        assert self.free is not None
        w = int(self.m.jnt_dofadr[self.free]) + 3
        v = self.d.qvel[w:w + 3]
        return float(v @ v)


def swing_model(file: MjcfFile, floating: bool, locked: Mapping[int, float]) -> Any:
    """The MJCF for a swing: base welded unless ``floating``, ``locked`` joints welded.

    A locked joint (by its id in the welded copy) is welded at its value, as PyBullet holds it
    (measured: to 5.6e-16 rad of the same joint written fixed): its body turned or moved by
    it, the joint and its equalities and actuators removed.
    """
    if not locked:
        return file.model if floating else file.fixed
    import warnings

    import numpy as np

    from urdfkit.model.spec import axis_angle_matrix

    mj, m, written = file.mj, file.fixed, file.model
    spec = mj.MjSpec.from_file(file.path)
    # the spec's joints in the written model's order (checked by type below): a locked
    # joint by its position, as an unnamed joint has no name to find it by
    kept = [i for i in range(written.njnt) if written.jnt_type[i] != mj.mjtJoint.mjJNT_FREE]
    weld_at = {kept[k]: (k, q) for k, q in locked.items()}
    joints = list(spec.joints)
    if [int(j.type) for j in joints] != [int(t) for t in written.jnt_type]:
        raise ValueError("the MJCF's joints are not in the order MuJoCo compiles them")
    for i, j in enumerate(joints):
        if j.type == mj.mjtJoint.mjJNT_FREE and not floating:
            j.parent.pos, j.parent.quat = [0.0, 0.0, 0.0], [1.0, 0.0, 0.0, 0.0]
            spec.delete(j)
        elif i in weld_at:
            k, q = weld_at[i]
            body, b = j.parent, int(m.jnt_bodyid[k])
            axis, at = np.array(m.jnt_axis[k]), np.array(m.jnt_pos[k])
            turn = np.array(axis_angle_matrix(tuple(axis), q)) if int(m.jnt_type[k]) == int(
                mj.mjtJoint.mjJNT_HINGE) else np.eye(3)
            shift = at - turn @ at if int(m.jnt_type[k]) == int(
                mj.mjtJoint.mjJNT_HINGE) else axis * q
            rb = np.zeros(9)
            mj.mju_quat2Mat(rb, np.array(m.body_quat[b]))
            quat = np.zeros(4)
            mj.mju_mat2Quat(quat, (rb.reshape(3, 3) @ turn).flatten())
            body.alt.type = mj.mjtOrientation.mjORIENTATION_QUAT
            body.pos = list(np.array(m.body_pos[b]) + rb.reshape(3, 3) @ shift)
            body.quat = list(quat)
            for e in list(spec.equalities) if j.name else ():
                if j.name in (e.name1, e.name2):
                    spec.delete(e)
            for a in list(spec.actuators) if j.name else ():
                if a.target == j.name:
                    spec.delete(a)
            spec.delete(j)
    for key in list(spec.keys):
        spec.delete(key)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return spec.compile()
