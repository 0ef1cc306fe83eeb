"""An MJCF file's base-welded copy as a :class:`~urdfkit.engine.api.Model`, in PyBullet's indices.

``agree`` loads the URDF in PyBullet (:class:`~urdfkit.engine.pybullet.PyBulletEngine`) and the
MJCF file in MuJoCo (:class:`~urdfkit.engine.mujoco_file.MjcfFile`), matches each link to a
body or site and each joint to a joint, and then asks both the same questions through the same
interface. :class:`MjcfModel` is the file's side: its link ``i`` is the body or site matched to
PyBullet's link ``i`` (-1 the root), its joint ``i`` the MuJoCo joint matched to PyBullet's
joint ``i``, and a PyBullet joint nothing in the file moves is a fixed one here. It is the
welded copy (free joints removed, the root at the origin), as PyBullet's fixed load, so the
mass matrix and inverse dynamics are over the joints alone.

Where the file cannot say what PyBullet's conventions ask for, this says what it gives instead:
the file keeps no URDF ``<inertial>`` frame (a body's inertia is its fused links' sum, on
MuJoCo's principal axes), so :meth:`MjcfModel.jacobian` takes its point along the link frame's
axes and gives its rows in the world (the root link's frame, welded at the origin): PyBullet's
own where the ``<inertial>`` frames are not turned. A link the file fuses into its body (a
site) carries no mass of its own.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from typing import TYPE_CHECKING, Any

from urdfkit.core.errors import EngineError, ParameterError
from urdfkit.engine.api import JointInfo, JointKind, LinkDynamics, Quat, Vec3
from urdfkit.engine.mujoco_file import Geom, MjcfFile

#: MuJoCo's joint kinds (:attr:`~urdfkit.engine.mujoco_file.Tree.joint_kind`) as the seam's.
KINDS: dict[str, JointKind] = {"hinge": "revolute", "slide": "prismatic", "ball": "spherical"}


class MjcfModel:
    """The welded copy of an MJCF file in PyBullet's indices (a :class:`Model` of one body, 0).

    Args:
        file: The compiled file.
        root: The name of PyBullet's root link (link -1).
        layout: PyBullet's joints (its :meth:`~urdfkit.engine.api.Model.joints`): the indices,
            names, child links and parents this model keeps.
        frames: Each matched link's ``("body", id)`` or ``("site", id)`` in the file.
        joints: Each matched joint's id in the welded copy, by PyBullet's joint name.
    """

    name = "mujoco"
    label = "MuJoCo"

    def __init__(self, file: MjcfFile, root: str, layout: Sequence[JointInfo],
                 frames: Mapping[str, tuple[str, int]], joints: Mapping[str, int]) -> None:
        mj, m = file.mj, file.fixed
        self.file = file
        self._layout = list(layout)
        self._links = [root] + [j.link for j in layout]
        self._frames = [frames.get(n) for n in self._links]
        self._ids = [joints.get(j.name) if j.kind != "fixed" else None for j in layout]
        #: the matched joints, in PyBullet's order: what positions and matrices are over
        self._movable = [k for k in self._ids if k is not None]
        #: their degrees of freedom, one each (a ball joint's first: see set_joint_positions)
        self._dofs = [int(m.jnt_dofadr[k]) for k in self._movable]
        self._data: Any = mj.MjData(m)
        self._contact: Any = None
        self._geoms: list[Geom] | None = None

    def _check(self, body: int) -> None:
        if body != 0:
            raise ParameterError(f"the MJCF file is body 0, not {body}", param="body")

    def _frame(self, link: int) -> tuple[str, int]:
        at = self._frames[link + 1]
        if at is None:
            raise EngineError(f"link {self._links[link + 1]!r} has no body or site in the MJCF")
        return at

    # ---- the tables

    def joints(self, body: int) -> list[JointInfo]:
        """PyBullet's joints as the file has them; one the file does not move is fixed."""
        self._check(body)
        return [self._joint(j, k) for j, k in zip(self._layout, self._ids, strict=True)]

    def _joint(self, j: JointInfo, k: int | None) -> JointInfo:
        """Joint ``j``'s index, URDF name, link and parent, the rest from the file's joint ``k``.

        The axis is turned into its body's inertial frame (MuJoCo's principal axes); the effort
        is the joint's actuator force limit (0: none), the velocity 0 (MuJoCo has no limit).
        """
        if k is None:
            return JointInfo(j.index, j.name, "fixed", -1, -1, 0.0, 0.0, 0.0, -1.0, False, 0.0,
                             0.0, j.link, (0.0, 0.0, 0.0), j.parent)
        import numpy as np

        mj, m = self.file.mj, self.file.fixed
        dof, b = int(m.jnt_dofadr[k]), int(m.jnt_bodyid[k])
        turn = np.zeros(9)
        mj.mju_quat2Mat(turn, m.body_iquat[b])
        axis = turn.reshape(3, 3).T @ np.array(m.jnt_axis[k], dtype=float)
        lower, upper = (float(x) for x in m.jnt_range[k])
        effort = float(m.jnt_actfrcrange[k][1]) if int(m.jnt_actfrclimited[k]) else 0.0
        return JointInfo(
            j.index, j.name, KINDS.get(self.file.tree.joint_kind[k], "fixed"),
            int(m.jnt_qposadr[k]), dof, float(m.dof_damping[dof]),
            float(m.dof_frictionloss[dof]), lower, upper, bool(m.jnt_limited[k]), effort, 0.0,
            j.link, (float(axis[0]), float(axis[1]), float(axis[2])), j.parent)

    def link_names(self, body: int) -> list[str]:
        """PyBullet's link names, the root first."""
        self._check(body)
        return list(self._links)

    def dynamics(self, body: int, link: int) -> LinkDynamics:
        """A link's body's mass properties (its body frame) and first collision geom's friction.

        A link the file fuses into its body (a site) has no mass of its own there: 0 kg at its
        frame, and its body's friction. Torsional and rolling friction count where the geom's
        ``condim`` makes MuJoCo use them (4, 6), as PyBullet's spinning and rolling friction.
        """
        self._check(body)
        kind, i = self._frame(link)
        m = self.file.fixed
        b = i if kind == "body" else int(m.site_bodyid[i])
        if self._geoms is None:
            self._geoms = self.file.geoms()
        geom = next((g for g in self._geoms if g.body == b), None)
        slide, torsion, roll = geom.friction if geom is not None else (0.0, 0.0, 0.0)
        condim = geom.condim if geom is not None else 1
        spin, rolling = (torsion if condim >= 4 else 0.0), (roll if condim >= 6 else 0.0)
        if kind == "site":
            return LinkDynamics(0.0, (0.0, 0.0, 0.0), (0.0, 0.0, 0.0), (0.0, 0.0, 0.0, 1.0),
                                slide, rolling, spin, 0.0, -1.0, -1.0)
        w, x, y, z = (float(v) for v in m.body_iquat[b])
        return LinkDynamics(float(m.body_mass[b]), _vec3(m.body_inertia[b]),
                            _vec3(m.body_ipos[b]), (x, y, z, w), slide, rolling, spin, 0.0,
                            -1.0, -1.0)

    # ---- a pose

    def set_joint_positions(self, body: int, positions: Sequence[float],
                            velocities: Sequence[float] | None = None) -> None:
        """The matched joints at these values (PyBullet's order), the rest at ``qpos0``.

        A joint given NaN stays at its reference (``qpos0``): ``agree`` poses only the joints
        PyBullet moves with one coordinate. The seam gives each joint one value: a ball
        joint's position is not read (it stays at rest), its velocity is about its first
        axis, and the mass matrix, inverse dynamics and Jacobians count its first degree of
        freedom alone (``agree`` compares a ball joint at rest, and only its frames).
        """
        self._check(body)
        m, d = self.file.fixed, self._data
        d.qpos[:] = m.qpos0
        d.qvel[:] = 0
        ball = self.file.tree.joint_kind
        speeds = velocities if velocities is not None else [None] * len(self._movable)
        for k, q, v in zip(self._movable, positions, speeds, strict=True):
            if ball[k] != "ball" and q == q:
                d.qpos[m.jnt_qposadr[k]] = q
            if v is not None:
                d.qvel[m.jnt_dofadr[k]] = v

    def link_matrices(self, body: int, links: Sequence[int]) -> list[Any]:
        """These links' frames at the pose set, world, as MuJoCo computes them (4 x 4 each).

        MuJoCo's rotation matrices themselves: a quaternion (:meth:`link_frames`) would round
        them, and ``agree`` compares frames to 1e-12.
        """
        import numpy as np

        self._check(body)
        mj, m, d = self.file.mj, self.file.fixed, self._data
        mj.mj_kinematics(m, d)
        out = []
        for link in links:
            kind, i = self._frame(link)
            t = np.eye(4)
            if kind == "body":
                t[:3, :3] = d.xmat[i].reshape(3, 3)
                t[:3, 3] = d.xpos[i]
            else:
                t[:3, :3] = d.site_xmat[i].reshape(3, 3)
                t[:3, 3] = d.site_xpos[i]
            out.append(t)
        return out

    def link_frames(self, body: int) -> list[tuple[Vec3, Quat]]:
        """Every link frame at the pose set, world, the root first.

        Raises:
            EngineError: A link has no body or site in the file.
        """
        import numpy as np

        mj = self.file.mj
        out: list[tuple[Vec3, Quat]] = []
        for t in self.link_matrices(body, range(-1, len(self._layout))):
            q = np.zeros(4)
            mj.mju_mat2Quat(q, t[:3, :3].flatten())
            out.append((_vec3(t[:3, 3]), (float(q[1]), float(q[2]), float(q[3]), float(q[0]))))
        return out

    def self_contacts(self, body: int) -> list[tuple[str, str]]:
        """The pairs of bodies (not the world) whose geoms touch at the pose set, by name."""
        self._check(body)
        mj, m = self.file.mj, self.file.fixed
        if self._contact is None:
            self._contact = mj.MjData(m)
        c = self._contact
        c.qpos[:] = self._data.qpos
        mj.mj_forward(m, c)
        names = self.file.tree.body_names
        out = []
        for contact in c.contact[:c.ncon]:
            b1, b2 = int(m.geom_bodyid[contact.geom1]), int(m.geom_bodyid[contact.geom2])
            if b1 and b2:
                out.append((names[b1] or f"body {b1}", names[b2] or f"body {b2}"))
        return out

    # ---- dynamics

    def mass_matrix(self, body: int, positions: Sequence[float]) -> list[list[float]]:
        """``mj_fullM`` at ``positions`` over the matched joints, in PyBullet's order."""
        self.set_joint_positions(body, positions)
        return joint_mass_matrix(self.file.mj, self.file.fixed, self._data,
                                 self._dofs).tolist()

    def inverse_dynamics(self, body: int, positions: Sequence[float],
                         velocities: Sequence[float],
                         accelerations: Sequence[float]) -> list[float]:
        """``mj_rne`` with accelerations: rigid-body torques, gravity included."""
        import numpy as np

        self.set_joint_positions(body, positions, velocities)
        mj, m, d = self.file.mj, self.file.fixed, self._data
        d.qacc[:] = 0
        for i, a in zip(self._dofs, accelerations, strict=True):
            d.qacc[i] = a
        mj.mj_kinematics(m, d)
        mj.mj_comPos(m, d)
        mj.mj_comVel(m, d)
        out = np.zeros(m.nv)
        mj.mj_rne(m, d, 1, out)
        return [float(x) for x in out[self._dofs]]

    def floating_mass_matrix(self, body: int, position: Vec3, orientation: Quat,
                             positions: Sequence[float]) -> list[list[float]]:
        """None here: the welded copy has no floating base.

        Raises:
            ParameterError: always.
        """
        self._check(body)
        raise ParameterError("the MJCF's base-welded copy has no floating base: "
                             "floating_mass_matrix is the mass matrix of a floating base",
                             param="body")

    def jacobian(self, body: int, link: int, point: Vec3, positions: Sequence[float]
                 ) -> tuple[list[list[float]], list[list[float]]]:
        """``mj_jac`` of a point of a link, columns the matched joints in PyBullet's order.

        ``point`` is from the link frame's origin along the link frame's axes, and the rows
        are in the world (the welded root's link frame): see the module's docstring.
        """
        import numpy as np

        self.set_joint_positions(body, positions)
        mj, m, d = self.file.mj, self.file.fixed, self._data
        t = self.link_matrices(body, [link])[0]
        kind, i = self._frame(link)
        b = i if kind == "body" else int(m.site_bodyid[i])
        mj.mj_comPos(m, d)
        lin, ang = np.zeros((3, m.nv)), np.zeros((3, m.nv))
        mj.mj_jac(m, d, lin, ang, t[:3, 3] + t[:3, :3] @ np.array(point, dtype=float), b)
        return lin[:, self._dofs].tolist(), ang[:, self._dofs].tolist()

    def close(self) -> None:
        """Nothing to release (the file's models are Python objects)."""
        self._contact = None


def joint_mass_matrix(mj: Any, m: Any, d: Any, dofs: Sequence[int]) -> Any:
    """MuJoCo's joint-space mass matrix at ``d``'s positions, over the degrees of freedom given."""
    import numpy as np

    mj.mj_kinematics(m, d)
    mj.mj_comPos(m, d)
    mj.mj_crb(m, d)
    full = np.zeros((m.nv, m.nv))
    try:  # (m, d, dst) since MuJoCo 3.3's sparse M; (m, dst, qM) before
        mj.mj_fullM(m, d, full)
    except TypeError:
        mj.mj_fullM(m, full, d.qM)
    return full[np.ix_(dofs, dofs)]


def _vec3(v: Any) -> Vec3:
    return float(v[0]), float(v[1]), float(v[2])


if TYPE_CHECKING:
    from urdfkit.engine.api import Model

    def _is_a_model(model: MjcfModel) -> Model:
        """Never called: mypy checks here that the class keeps the whole protocol."""
        return model
