"""An MJCF file as MuJoCo's own loader compiles it: the side ``agree`` proves against PyBullet.

``urdfkit agree`` proves the file ``export mjcf`` wrote (or any MJCF), so the file is loaded by
MuJoCo's loader as it is on disk (``MjSpec.from_file``), never rebuilt: the MuJoCo engine
(:mod:`urdfkit.engine.mujoco`) builds the export in memory instead. :class:`MjcfFile` holds the
model as written and a copy with its free joints removed (the base welded at the origin, as
PyBullet's fixed load puts it), and answers in plain records: the tree by id (:class:`Tree`),
each body's mass properties (:class:`BodyMass`), the collision geoms and their contact
parameters (:class:`Geom`), the active equalities (:class:`Equality`), the forces MuJoCo
alone applies (:class:`Forces`), the sites its compiler moves onto their body. The
:class:`~urdfkit.engine.api.Model` over the welded copy, in PyBullet's indices, is
:class:`urdfkit.engine.mujoco_file_model.MjcfModel`; a free swing of the file is
:class:`urdfkit.engine.mujoco_file_swing.Swing`.
"""

from __future__ import annotations

import math
from collections.abc import Iterator
from contextlib import contextmanager
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from urdfkit.core.errors import InputError, MissingDependencyError

#: MuJoCo's geom types (``mjtGeom``) by the names agree compares them under.
GEOM_KINDS = {0: "plane", 2: "sphere", 3: "capsule", 5: "cylinder", 6: "box", 7: "mesh"}


def import_mujoco() -> Any:
    """mujoco, or an error saying how to install it."""
    try:
        import mujoco
    except ImportError as e:
        raise MissingDependencyError("agree needs MuJoCo: pip install 'urdfkit[mujoco]'") from e
    return mujoco


@dataclass(frozen=True)
class Tree:
    """A compiled model's bodies, joints and sites by id: names, the tree, zero-pose frames.

    Attributes:
        joints, bodies, sites: Each named one's id (the world body and unnamed ones left out).
        body_names, joint_names: Each id's name ("" unnamed).
        parent: Each body's parent body (the world's own: 0).
        weld: Each body's weld group, MuJoCo's ``body_weldid`` (the body it moves with; 0 the
            world).
        body_joints: Each body's joints.
        joint_body: Each joint's body.
        joint_kind: Each joint's kind: ``hinge``, ``slide``, ``ball`` or ``free``.
        site_body: Each site's body.
        xpos, xmat: Each body's frame at the model's zero pose (``qpos0``), world (n x 3 and
            n x 3 x 3).
        xaxis: Each joint's axis there, world (n x 3).
    """

    joints: dict[str, int]
    bodies: dict[str, int]
    sites: dict[str, int]
    body_names: list[str]
    joint_names: list[str]
    parent: list[int]
    weld: list[int]
    body_joints: list[list[int]]
    joint_body: list[int]
    joint_kind: list[str]
    site_body: list[int]
    xpos: Any
    xmat: Any
    xaxis: Any


@dataclass(frozen=True)
class BodyMass:
    """One body's mass properties as the MJCF gives them, the model at qpos 0.

    Attributes:
        body, name: Its id and name ("" unnamed).
        mass: kg.
        inertia: Its principal moments (3), kg m^2.
        frame: Its inertial frame as the MJCF writes it (``body_ipos``, ``body_iquat``), world
            (4 x 4): MuJoCo's compiler may simulate another (``snapped``).
        weld: Its weld group in the model as written (a body with a free joint of its own is
            a group of its own there).
        snapped: Where MuJoCo's compiler took an inertial frame within ~1e-6 of the body's as
            the body's (``body_sameframe``), how much that turned the tensor it simulates,
            relative to its largest entry; None elsewhere.
    """

    body: int
    name: str
    mass: float
    inertia: Any
    frame: Any
    weld: int
    snapped: float | None


@dataclass(frozen=True)
class Geom:
    """One collision geom (``contype`` or ``conaffinity`` set) at the zero pose (``qpos0``).

    Attributes:
        index: Its id.
        name: Its name, or ``geom N of BODY``.
        body: The body it is on (0: the world).
        weld: That body's weld group in the base-welded copy.
        kind: ``plane``, ``sphere``, ``capsule``, ``cylinder``, ``box``, ``mesh`` or
            ``type N``.
        size: MuJoCo's sizes: a sphere's radius, a box's half sizes, a cylinder's or capsule's
            radius and half length; () for the others.
        frame: Its frame, world (4 x 4).
        box: A mesh's vertices' box in the world, (lower, upper); None for the others.
        friction: Sliding, torsional and rolling friction.
        condim, contype, conaffinity, priority: MuJoCo's contact settings.
    """

    index: int
    name: str
    body: int
    weld: int
    kind: str
    size: tuple[float, ...]
    frame: Any
    box: Any
    friction: tuple[float, float, float]
    condim: int
    contype: int
    conaffinity: int
    priority: int


@dataclass(frozen=True)
class Equality:
    """One active equality of the model as written.

    Attributes:
        index: Its id.
        kind: ``joint``, ``weld``, ``connect`` or ``equality`` (another kind).
        name: Its name ("" unnamed).
        joint1, joint2: A joint equality's joints' names ("" unnamed; ``joint2`` also "" when
            it holds one joint alone).
    """

    index: int
    kind: str
    name: str
    joint1: str
    joint2: str


@dataclass(frozen=True)
class Forces:
    """What MuJoCo would push a robot with beyond rigid-body physics, as the file sets it.

    Attributes:
        stiffness: (joint id, name, N m/rad) of each joint with a spring.
        gravcomp: (body id, name, fraction) of each body with gravity compensation.
        gravity: The model's gravity, m/s^2.
        density, viscosity: The medium's.
        wind: The medium's velocity, m/s.
    """

    stiffness: list[tuple[int, str, float]]
    gravcomp: list[tuple[int, str, float]]
    gravity: tuple[float, float, float]
    density: float
    viscosity: float
    wind: tuple[float, float, float]


class MjcfFile:
    """An MJCF file compiled by MuJoCo's own loader, as written and with its base welded.

    Open it with :func:`open_mjcf`, which also keeps what MuJoCo warns while it is used.

    Attributes:
        path: The file.
        model: The model as written (``MjModel``).
        fixed: The same with every free joint removed, its body at the origin, unturned, and
            no keyframe (their ``qpos`` held the free joints): the base welded where
            PyBullet's fixed load puts the root. Body and site ids are the model's; joint ids
            are the model's less the free joints.
        warnings: What MuJoCo said while compiling the file (its decoders', its parser's).
        run_warnings: What it has said since (a diverging swing), each once in order.
        tree, written: The welded copy's :class:`Tree`, and the model's as written.
    """

    def __init__(self, mj: Any, path: str | Path) -> None:
        self.mj = mj
        self.path = str(path)
        self.model, self.fixed, self.warnings = _load(mj, path)
        self.run_warnings: list[str] = []
        self.tree = _tree(mj, self.fixed)
        self.written = _tree(mj, self.model)

    @property
    def gravity(self) -> tuple[float, float, float]:
        """The model's gravity, m/s^2."""
        g = self.fixed.opt.gravity
        return float(g[0]), float(g[1]), float(g[2])

    def root_free(self, root: int | None) -> int | None:
        """The free joint of body ``root`` in the model as written (another free body's not)."""
        w = self.written
        return next((i for i, kind in enumerate(w.joint_kind) if kind == "free"
                     and w.joint_body[i] == root), None) if root is not None else None

    def armature(self, joint: int) -> float:
        """A joint's rotor inertia (``dof_armature``; PyBullet has none), kg m^2."""
        return float(self.fixed.dof_armature[int(self.fixed.jnt_dofadr[joint])])

    def total_mass(self) -> float:
        """Every body's mass, summed."""
        return float(self.fixed.body_mass[1:].sum())

    def bodies(self) -> list[BodyMass]:
        """Each body's mass properties with the welded copy at qpos 0 (world body left out)."""
        import numpy as np

        mj, m = self.mj, self.fixed
        d = mj.MjData(m)
        d.qpos[:] = 0
        mj.mj_kinematics(m, d)
        mj.mj_comPos(m, d)
        out = []
        for b in range(1, m.nbody):
            # the inertial frame as the MJCF gives it (body_ipos, body_iquat): MuJoCo's
            # compiler puts one within ~1e-6 of the body's frame at that frame
            # (body_sameframe), which ximat then shows
            turn = np.zeros(9)
            mj.mju_quat2Mat(turn, m.body_iquat[b])
            t = np.eye(4)
            t[:3, :3] = d.xmat[b].reshape(3, 3) @ turn.reshape(3, 3)
            t[:3, 3] = d.xpos[b] + d.xmat[b].reshape(3, 3) @ m.body_ipos[b]
            snapped = None
            if int(m.body_sameframe[b]):
                sim = d.ximat[b].reshape(3, 3)
                full = t[:3, :3] @ np.diag(m.body_inertia[b]) @ t[:3, :3].T
                off = sim @ np.diag(m.body_inertia[b]) @ sim.T - full
                snapped = float(np.abs(off).max()) / max(float(np.abs(full).max()), 1e-300)
            out.append(BodyMass(b, self.tree.body_names[b], float(m.body_mass[b]),
                                np.array(m.body_inertia[b]), t, int(self.model.body_weldid[b]),
                                snapped))
        return out

    def geoms(self) -> list[Geom]:
        """Every collision geom of the welded copy at its zero pose, the world's included."""
        import numpy as np

        mj, m = self.mj, self.fixed
        d = mj.MjData(m)
        d.qpos[:] = m.qpos0
        mj.mj_kinematics(m, d)
        names = self.tree.body_names
        out = []
        for g in range(m.ngeom):
            if not (int(m.geom_contype[g]) or int(m.geom_conaffinity[g])):
                continue  # a visual
            kind = GEOM_KINDS.get(int(m.geom_type[g]), f"type {int(m.geom_type[g])}")
            b = int(m.geom_bodyid[g])
            frame = np.eye(4)
            frame[:3, :3] = d.geom_xmat[g].reshape(3, 3)
            frame[:3, 3] = d.geom_xpos[g]
            size = tuple(float(x) for x in m.geom_size[g])
            box = None
            if kind == "mesh":
                k = int(m.geom_dataid[g])
                start, n = int(m.mesh_vertadr[k]), int(m.mesh_vertnum[k])
                pts = np.asarray(m.mesh_vert[start:start + n], dtype=float)
                world = pts @ frame[:3, :3].T + frame[:3, 3]
                box = (world.min(axis=0), world.max(axis=0))
            size = {"sphere": size[:1], "box": size, "cylinder": size[:2],
                    "capsule": size[:2]}.get(kind, ())
            slide, torsion, roll = (float(x) for x in m.geom_friction[g])
            out.append(Geom(
                g, mj.mj_id2name(m, mj.mjtObj.mjOBJ_GEOM, g)
                or f"geom {g} of {names[b] or f'body {b}'}", b, int(m.body_weldid[b]), kind,
                size, frame, box, (slide, torsion, roll), int(m.geom_condim[g]),
                int(m.geom_contype[g]), int(m.geom_conaffinity[g]), int(m.geom_priority[g])))
        return out

    def equalities(self) -> list[Equality]:
        """The model's active equalities (as written)."""
        mj, m = self.mj, self.model
        kinds = {int(mj.mjtEq.mjEQ_JOINT): "joint", int(mj.mjtEq.mjEQ_WELD): "weld",
                 int(mj.mjtEq.mjEQ_CONNECT): "connect"}
        out = []
        for e in range(m.neq):
            if not m.eq_active0[e]:
                continue
            kind = kinds.get(int(m.eq_type[e]), "equality")
            a = b = ""
            if kind == "joint":
                a = _name(mj, m, mj.mjtObj.mjOBJ_JOINT, int(m.eq_obj1id[e]))
                b = _name(mj, m, mj.mjtObj.mjOBJ_JOINT, int(m.eq_obj2id[e])) \
                    if int(m.eq_obj2id[e]) >= 0 else ""
            out.append(Equality(e, kind, _name(mj, m, mj.mjtObj.mjOBJ_EQUALITY, e), a, b))
        return out

    def forces(self) -> Forces:
        """Joint springs, gravity compensation, gravity and the medium, as written."""
        mj, m = self.mj, self.model
        stiff = [(k, _name(mj, m, mj.mjtObj.mjOBJ_JOINT, k), float(m.jnt_stiffness[k]))
                 for k in range(m.njnt) if float(m.jnt_stiffness[k])]
        comp = [(b, _name(mj, m, mj.mjtObj.mjOBJ_BODY, b), float(m.body_gravcomp[b]))
                for b in range(1, m.nbody) if float(m.body_gravcomp[b])]
        o = m.opt
        return Forces(stiff, comp, (float(o.gravity[0]), float(o.gravity[1]),
                                    float(o.gravity[2])), float(o.density), float(o.viscosity),
                      (float(o.wind[0]), float(o.wind[1]), float(o.wind[2])))

    def snapped_sites(self) -> dict[int, tuple[Any, float]]:
        """Sites MuJoCo's compiler moved onto their body's frame: id -> (where, by).

        MuJoCo 4.0 marks a site within about 1e-6 (position, quaternion) of its body's frame
        as the same frame and computes it there (``site_sameframe`` 1, or 3 for the rotation
        alone), dropping the offset: HSR's ``head_l_stereo_camera_gazebo_frame`` (rpy
        1.5707963268 -1.5707963268 0 after -1.5707963268 0 -1.5707963268) sits 5.1e-12 rad
        from its body, which MuJoCo's site_xmat leaves out. ``where`` is the frame MuJoCo
        uses in the body (4 x 4); ``by`` the larger of the offset's length and rotation angle.
        """
        import numpy as np

        m = self.fixed
        out: dict[int, tuple[Any, float]] = {}
        for i in range(m.nsite):
            same = int(m.site_sameframe[i])
            pos = np.array(m.site_pos[i], dtype=float)
            w, x, y, z = (float(v) for v in m.site_quat[i])
            angle = 2.0 * math.atan2(math.sqrt(x * x + y * y + z * z), abs(w))
            where = np.eye(4)
            if same == 1:  # mjSAMEFRAME_BODY: the body's frame
                by = max(float(np.linalg.norm(pos)), angle)
            elif same == 3:  # mjSAMEFRAME_BODYROT: the body's rotation, the site's position
                where[:3, 3] = pos
                by = angle
            else:
                continue
            if by != 0.0:
                out[i] = (where, by)
        return out


@contextmanager
def open_mjcf(path: str | Path) -> Iterator[MjcfFile]:
    """The file compiled (:class:`MjcfFile`), MuJoCo's warnings kept while it is open.

    Raises:
        InputError: MuJoCo cannot load it (one line naming the file), or it is no file.
        MissingDependencyError: MuJoCo is not installed.
    """
    from urdfkit.formats.mjwarn import mujoco_warnings

    mj = import_mujoco()
    # what MuJoCo's C code warns from here on (a diverging swing) is kept for the report,
    # not printed on stderr
    with mujoco_warnings(mj) as said:
        f = MjcfFile(mj, path)
        f.run_warnings = said
        yield f


def _name(mj: Any, m: Any, kind: Any, i: int) -> str:
    return mj.mj_id2name(m, kind, i) or ""


def _load(mj: Any, path: str | Path) -> tuple[Any, Any, list[str]]:
    """The model as written, the same with its free joints removed, and MuJoCo's warnings."""
    from urdfkit.sources.uris import not_a_file

    p = Path(path)
    why = not_a_file(p)  # a stat only: MuJoCo would block on a FIFO
    if why is not None:
        raise InputError("no such file" if why == "missing" else f"is {why}, not an MJCF "
                         "file", file=str(path))
    from urdfkit.formats.mjcf_files import check_mjcf_files

    check_mjcf_files(p)  # its includes, meshes, textures...: MuJoCo would block on a FIFO too
    import warnings

    from urdfkit.formats.mjwarn import mujoco_warnings

    try:
        # MuJoCo's decoders warn through Python (an OBJ's texture coordinates dropped): kept
        # for the report, not printed
        with warnings.catch_warnings(record=True) as said, \
                mujoco_warnings(mj) as said_in_c:  # its C parser's too ("a 'NaN'")
            warnings.simplefilter("always")
            spec = mj.MjSpec.from_file(str(p))
            model = spec.compile()
        said_loading = sorted({str(w.message) for w in said} | set(said_in_c))
        fixed_spec = mj.MjSpec.from_file(str(p))
        for key in list(fixed_spec.keys):
            fixed_spec.delete(key)  # a keyframe's qpos holds the free joints removed below
        for j in list(fixed_spec.joints):
            if j.type == mj.mjtJoint.mjJNT_FREE:
                # welded where PyBullet's fixed load puts the root: at the origin (a model
                # may spawn its root higher, as Menagerie's go2 at 0.445 m)
                body = j.parent
                body.pos = [0.0, 0.0, 0.0]
                body.quat = [1.0, 0.0, 0.0, 0.0]
                fixed_spec.delete(j)
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")  # the same warnings again
            fixed = fixed_spec.compile()
    except (ValueError, RuntimeError) as e:
        first = str(e).strip().splitlines()[0] if str(e).strip() else type(e).__name__
        raise InputError(f"MuJoCo cannot load it: {first}", file=str(path)) from None
    return model, fixed, said_loading


def _tree(mj: Any, m: Any) -> Tree:
    import numpy as np

    obj = mj.mjtObj
    joints = [_name(mj, m, obj.mjOBJ_JOINT, i) for i in range(m.njnt)]
    bodies = [_name(mj, m, obj.mjOBJ_BODY, i) for i in range(m.nbody)]
    sites = [_name(mj, m, obj.mjOBJ_SITE, i) for i in range(m.nsite)]
    d = mj.MjData(m)
    mj.mj_kinematics(m, d)
    kind = {int(mj.mjtJoint.mjJNT_HINGE): "hinge", int(mj.mjtJoint.mjJNT_SLIDE): "slide",
            int(mj.mjtJoint.mjJNT_BALL): "ball", int(mj.mjtJoint.mjJNT_FREE): "free"}

    def named(names: list[str], start: int = 0) -> dict[str, int]:
        out = {n: i for i, n in enumerate(names) if i >= start}
        out.pop("", None)
        return out

    return Tree(
        joints=named(joints), bodies=named(bodies, 1), sites=named(sites),
        body_names=bodies, joint_names=joints,
        parent=[int(b) for b in m.body_parentid], weld=[int(b) for b in m.body_weldid],
        body_joints=[list(range(int(m.body_jntadr[b]), int(m.body_jntadr[b])
                                + int(m.body_jntnum[b]))) if int(m.body_jntnum[b]) > 0 else []
                     for b in range(m.nbody)],
        joint_body=[int(b) for b in m.jnt_bodyid],
        joint_kind=[kind.get(int(t), "") for t in m.jnt_type],
        site_body=[int(b) for b in m.site_bodyid],
        xpos=np.array(d.xpos), xmat=np.array(d.xmat).reshape(-1, 3, 3),
        xaxis=np.array(d.xaxis))
