"""Does an MJCF agree with the URDF PyBullet loads? Both engines loaded and compared.

The URDF goes into PyBullet (the flags ``export`` mirrors), the MJCF into MuJoCo; links are
matched to bodies or sites and joints to joints by name, and each comparison is one
:class:`Row` with its worst figure and its tolerance beside it:

- structure: joint names, order, kinds, limits, damping (1e-12); total and per-body mass
  (1e-12 relative) and inertia about the centre of mass (1e-9 relative), bodies welded
  together (fixed links fused; MuJoCo's own welded bodies) compared as one;
- kinematics: every matched link frame at seeded poses, against PyBullet's ``getLinkState``
  (float32 inside: 1e-6) and against :mod:`urdfkit.formats.fk` (1e-12);
- dynamics: the joint-space mass matrix and inverse-dynamics torques at those poses (1e-9
  relative), base fixed on both sides (the joint block of the floating model);
- a free swing under gravity, MuJoCo set to PyBullet's integration (Euler, implicit damping
  off, contacts off) and PyBullet's motors and link damping off, base fixed (a free-falling
  floating robot does not swing), compared until a joint comes within 0.01 rad of a limit:
  the engines' limit models differ (PyBullet's a hard constraint, MuJoCo's a soft one);
- self-contacts at the poses: none unless self-collision was asked for.

The MJCF need not be ours: anything matched by name is compared, and what cannot be matched
is listed.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, Any

from urdfkit.core.errors import EngineError, InputError, MissingDependencyError
from urdfkit.exchange.agree_tree import match_models, tree_errors
from urdfkit.formats.fk import fused, link_frames
from urdfkit.formats.mjcf import combine
from urdfkit.formats.robot import LoadedInertial, LoadedRobot

if TYPE_CHECKING:
    from urdfkit.engine.session import Session

#: Tolerances (docs/export.md explains each).
TOL_EXACT = 1e-12          # joint limits, damping (absolute); masses (relative)
TOL_COM = 1e-12            # centres of mass, m
TOL_INERTIA = 1e-9         # inertia tensors, relative to the largest moment
TOL_PYBULLET_FRAME = 1e-6  # getLinkState: float32 inside
TOL_FK = 1e-12             # against double-precision forward kinematics
TOL_DYNAMICS = 1e-9        # mass matrix, inverse dynamics, relative
TOL_SWING = 1e-9           # rad over the free swing
TOL_FLOATING_BASE = 1e-9   # m, and in the rotation matrix, over the floating swing
LIMIT_MARGIN = 0.01        # rad: the swing is compared until a joint comes this close
_ZERO3 = ((0.0, 0.0, 0.0), (0.0, 0.0, 0.0), (0.0, 0.0, 0.0))
#: What MuJoCo warned while loading the last model (see :func:`load_mjcf`).
LOAD_WARNINGS: list[str] = []


@dataclass
class Row:
    """One comparison: its worst figure, the tolerance, and what the figure is about."""

    group: str
    what: str
    value: float | None
    tolerance: float | None
    unit: str
    status: str          # pass, fail, info, known
    detail: str = ""

    @property
    def ok(self) -> bool:
        """Whether the row holds (info and known differences do not fail)."""
        return self.status != "fail"



@dataclass
class AgreeOptions:
    """How to compare.

    Attributes:
        fixed_base: The export welded the base (``useFixedBase``).
        inertia_from_file: PyBullet loads with URDF_USE_INERTIA_FROM_FILE (export's default).
        self_collision: Self-collision was asked for (contacts at the poses are allowed).
        poses: How many seeded poses.
        seed: The poses' seed.
        seconds: The free swing's length.
        time_step: Its step.
        name_map: URDF link or joint name -> MJCF body, site or joint name, for pairs whose
            names differ (``--map``); the rest match by name, then by the tree's shape.
    """

    fixed_base: bool = False
    inertia_from_file: bool = True
    self_collision: bool = False
    poses: int = 100
    seed: int = 0
    seconds: float = 1.0
    time_step: float = 1e-3
    name_map: dict[str, str] = field(default_factory=dict)


@dataclass
class Agreement:
    """Every row, and what could not be matched."""

    file: str
    model: str
    rows: list[Row] = field(default_factory=list)
    unmatched_links: list[str] = field(default_factory=list)
    unmatched_joints: list[str] = field(default_factory=list)
    extra_joints: list[str] = field(default_factory=list)
    #: pairs not matched by name: {"urdf", "mjcf", "how": "map" | "structure"}
    matched_by: list[dict[str, str]] = field(default_factory=list)
    load_flags: list[str] = field(default_factory=list)
    #: What MuJoCo said while loading the model (its decoders' warnings).
    warnings: list[str] = field(default_factory=list)

    @property
    def ok(self) -> bool:
        """Whether every row holds."""
        return all(r.ok for r in self.rows)

    def add(self, group: str, what: str, value: float | None, tolerance: float | None,
            unit: str, detail: str = "", status: str | None = None) -> None:
        """A row; its status from the figure and the tolerance unless given."""
        if status is None:  # (a NaN figure fails: NaN <= tolerance is False)
            status = "pass" if value is not None and tolerance is not None and \
                value <= tolerance else "fail"
        self.rows.append(Row(group, what, value, tolerance, unit, status, detail))


def import_mujoco() -> Any:
    """mujoco, or an error saying how to install it."""
    try:
        import mujoco
    except ImportError as e:
        raise MissingDependencyError("agree needs MuJoCo: pip install 'urdfkit[mujoco]'") from e
    return mujoco


def load_mjcf(path: str | Path) -> tuple[Any, Any]:
    """The model as written, and the same model with its free joints removed (base fixed)."""
    mujoco = import_mujoco()
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
                mujoco_warnings(mujoco) as said_in_c:  # its C parser's too ("a 'NaN'")
            warnings.simplefilter("always")
            spec = mujoco.MjSpec.from_file(str(p))
            model = spec.compile()
        LOAD_WARNINGS[:] = sorted({str(w.message) for w in said} | set(said_in_c))
        fixed_spec = mujoco.MjSpec.from_file(str(p))
        for key in list(fixed_spec.keys):
            fixed_spec.delete(key)  # a keyframe's qpos holds the free joints removed below
        for j in list(fixed_spec.joints):
            if j.type == mujoco.mjtJoint.mjJNT_FREE:
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
    return model, fixed


def _worst(items: list[tuple[float, str]]) -> tuple[float, str]:
    """The largest figure, a NaN above all (a NaN in the MJCF must not pass as 0)."""
    return max(items, key=lambda x: math.inf if x[0] != x[0] else x[0]) if items else (0.0, "")


def _name(m: Any, kind: Any, i: int) -> str:
    import mujoco

    return mujoco.mj_id2name(m, kind, i) or ""


class _Pybullet:
    """The URDF in PyBullet: a floating load for masses, a fixed one for the rest."""

    def __init__(self, session: Session, path: str, display: str, options: AgreeOptions
                 ) -> None:
        from urdfkit.engine.session import LoadOptions

        load = LoadOptions(fixed_base=True, inertia_from_file=options.inertia_from_file,
                           self_collision=options.self_collision)
        self.flags = load.flag_names()
        self.b = session.bullet
        self.gravity = (0.0, 0.0, -9.81)
        self.reload = (session, path, display, LoadOptions(
            inertia_from_file=options.inertia_from_file, self_collision=options.self_collision))
        self.free = session.load_urdf(path, self.reload[3], display)
        self.body = session.load_urdf(path, load, display)
        b = self.b
        n = b.getNumJoints(self.body)
        self.info = [b.getJointInfo(self.body, i) for i in range(n)]
        self.base = b.getBodyInfo(self.body)[0].decode("utf-8", "replace")
        self.link_index = {self.base: -1}
        for i, info in enumerate(self.info):
            self.link_index[info[12].decode("utf-8", "replace")] = i
        # revolute, prismatic and spherical joints (planar ones export refuses)
        self.movable = [i for i, info in enumerate(self.info) if info[2] in (0, 1, 2)]
        self.names = [self.info[i][1].decode("utf-8", "replace") for i in self.movable]
        #: the 1-dof joints, which the poses and the swing move (spherical ones stay at rest)
        self.one = [i for i in self.movable if self.info[i][2] in (0, 1)]
        self.one_names = [self.info[i][1].decode("utf-8", "replace") for i in self.one]
        self.spherical = [n for i, n in zip(self.movable, self.names, strict=True)
                          if self.info[i][2] == 2]
        # the floating copy's mass properties, read now: it must not fall onto the other
        self.inertials = {n: self._inertial(i) for n, i in self.link_index.items()}
        b.removeBody(self.free)

    def swinger(self, floating: bool, q0: dict[str, float], v0: dict[str, float],
                time_step: float) -> int:
        """The body to swing, set at ``q0`` (speeds ``v0``).

        The fixed load, or a floating one at rest at the origin; motors, link damping and
        contacts off, as MuJoCo is set.
        """
        b = self.b
        body = self.body
        if floating:
            session, path, display, load = self.reload
            body = session.load_urdf(path, load, display)
        b.setTimeStep(time_step)
        for i, n in zip(self.one, self.one_names, strict=True):
            b.resetJointState(body, i, q0.get(n, 0.0), v0.get(n, 0.0))
        b.setJointMotorControlArray(body, self.movable, b.VELOCITY_CONTROL,
                                    forces=[0.0] * len(self.movable))
        for i in range(-1, len(self.info)):
            b.changeDynamics(body, i, linearDamping=0.0, angularDamping=0.0)
            # contacts off on this side too (URDF_USE_SELF_COLLISION would collide links)
            b.setCollisionFilterGroupMask(body, i, 0, 0)
        return int(body)

    def base_frame(self, body: int) -> Any:
        """The root link's frame (4x4, world): PyBullet reports the base's inertial frame."""
        import numpy as np

        from urdfkit.model.spec import quat_to_matrix

        def frame(pos: Any, orn: Any) -> Any:
            t = np.eye(4)
            norm = math.sqrt(sum(c * c for c in orn))
            t[:3, :3] = quat_to_matrix([c / norm for c in orn])
            t[:3, 3] = pos
            return t

        d = self.b.getDynamicsInfo(body, -1)
        # in double precision: PyBullet's invertTransform and multiplyTransforms round to
        # float32 (bicycle's turned inertial frame: 1.9e-7 in the matrix)
        return frame(*self.b.getBasePositionAndOrientation(body)) @ np.linalg.inv(
            frame(d[3], d[4]))

    def inertial(self, link: str) -> LoadedInertial:
        """A link's mass properties as PyBullet loaded them (floating load), link frame."""
        return self.inertials[link]

    def _inertial(self, index: int) -> LoadedInertial:
        import numpy as np

        from urdfkit.model.spec import quat_to_matrix

        d = self.b.getDynamicsInfo(self.free, index)
        r = np.array(quat_to_matrix(d[4]))
        tensor = r @ np.diag(d[2]) @ r.T
        return LoadedInertial(float(d[0]), tuple(d[3]),
                              tuple(map(tuple, tensor)))  # type: ignore[arg-type]

    def pose(self, q: dict[str, float]) -> None:
        for i, name in zip(self.one, self.one_names, strict=True):
            self.b.resetJointState(self.body, i, q.get(name, 0.0), 0.0)

    def frames(self, links: list[str]) -> dict[str, Any]:
        import numpy as np

        from urdfkit.exchange.bullet_state import unreadable_state
        from urdfkit.model.spec import quat_to_matrix

        out: dict[str, Any] = {}
        if unreadable_state(self.info):
            return out  # past PyBullet's state queries: none to compare (the row says why)
        idx = [self.link_index[n] for n in links if self.link_index[n] >= 0]
        states = self.b.getLinkStates(self.body, idx, computeForwardKinematics=1) if idx else []
        by_index = dict(zip(idx, states or [], strict=True))
        for n in links:
            i = self.link_index[n]
            t = np.eye(4)
            if i < 0:
                pos, orn = self.b.getBasePositionAndOrientation(self.body)
                d = self.b.getDynamicsInfo(self.body, -1)
                inv_p, inv_o = self.b.invertTransform(d[3], d[4])
                pos, orn = self.b.multiplyTransforms(pos, orn, inv_p, inv_o)
            else:
                pos, orn = by_index[i][4], by_index[i][5]
            # PyBullet's quaternions are float32 products, up to ~4e-7 off unit length where
            # a link's inertial frame is turned (youBot's casters): the unit formula would add
            # 2x that to the matrix; normalised, as PyBullet's getMatrixFromQuaternion does
            norm = math.sqrt(sum(c * c for c in orn))
            t[:3, :3] = quat_to_matrix([c / norm for c in orn])
            t[:3, 3] = pos
            out[n] = t
        return out


def pybullet_frame_tolerances(robot: LoadedRobot) -> dict[str, float]:
    """Each link frame's tolerance against PyBullet's ``getLinkState``: float32 inside.

    A float32 rounding is 2^-24 relative; each transform on the way from the root rounds a
    few times (4 roundings a step, 2^-22), and a joint angle q is itself held to |q| 2^-24,
    which its sine and cosine carry. So a frame's error is bounded by
    2^-22 x sum over its chain of (1 + the joint's largest |q|), never below the issue's 1e-6
    (go2's FL_calf, whose joints reach 1.05, 3.49 and 2.72 rad, measured 1.0e-6, gets
    2.5e-6; kuka_iiwa's frames, measured 7.6e-7 at worst, mostly 1e-6).
    """
    acc = {robot.root: 0.0}
    for j in robot.joints:
        reach = 0.0
        if j.moves:
            reach = max(map(abs, sample_range(j))) if j.limited else \
                (1.0 if j.type == "prismatic" else math.pi)
        acc[j.child] = acc[j.parent] + 1.0 + reach
    return {n: max(TOL_PYBULLET_FRAME, 2.0 ** -22 * a) for n, a in acc.items()}


#: How far from the point of its range nearest zero a limited joint is sampled: a turn each
#: way (a revolute pose repeats past it), a metre along a prismatic one. Real ranges fit
#: whole (UR's +-2 pi); +-1e308 overflowed the sampler (exit 3), and poses that far out
#: would make every figure meaningless (float32 PyBullet, sines of 1e300).
SAMPLE_REACH = {"revolute": 2 * math.pi, "prismatic": 1.0}


def sample_range(j: Any) -> tuple[float, float]:
    """The part of a limited joint's range poses and the swing start are drawn from."""
    reach = SAMPLE_REACH["prismatic" if j.type == "prismatic" else "revolute"]
    near = min(max(0.0, j.lower), j.upper)
    return max(j.lower, near - reach), min(j.upper, near + reach)


def _sample(robot: LoadedRobot, names: list[str], rng: Any) -> dict[str, float]:
    q = {}
    joints = {j.name: j for j in robot.joints}
    for n in names:
        j = joints[n]
        if j.limited:
            q[n] = float(rng.uniform(*sample_range(j)))
        elif j.type == "prismatic":
            q[n] = float(rng.uniform(-1.0, 1.0))
        else:
            q[n] = float(rng.uniform(-math.pi, math.pi))
    return q


def _full_mass_matrix(mj: Any, m: Any, d: Any, out: Any) -> None:
    """``mj_fullM``: (m, d, dst) since MuJoCo 3.3's sparse M; (m, dst, qM) before."""
    try:
        mj.mj_fullM(m, d, out)
    except TypeError:
        mj.mj_fullM(m, out, d.qM)


def _joint_mass_matrix(mj: Any, m: Any, d: Any, dof: list[int]) -> Any:
    """MuJoCo's joint-space mass matrix at ``d``'s pose, over the degrees of freedom ``dof``."""
    import numpy as np

    mj.mj_kinematics(m, d)
    mj.mj_comPos(m, d)
    mj.mj_crb(m, d)
    full = np.zeros((m.nv, m.nv))
    _full_mass_matrix(mj, m, d, full)
    return full[np.ix_(dof, dof)]


def _frame_error(a: Any, b: Any) -> tuple[float, float]:
    import numpy as np

    return float(np.abs(a[:3, 3] - b[:3, 3]).max()), float(np.abs(a[:3, :3] - b[:3, :3]).max())


class _Compare:
    def __init__(self, robot: LoadedRobot, model_path: str, session: Any,
                 load_path: str, options: AgreeOptions) -> None:
        import mujoco

        self.mj = mujoco
        self.robot = robot
        self.o = options
        self.path = model_path
        self.model, self.fixed = load_mjcf(model_path)
        self.pb = _Pybullet(session, load_path, robot.file, options)
        self.result = Agreement(robot.file, model_path, load_flags=self.pb.flags,
                                warnings=list(LOAD_WARNINGS))
        m = self.fixed
        #: URDF names -> MuJoCo ids: by name, by ``--map``, then by the tree's shape
        self.match = match_models(mujoco, m, robot, self.pb.names, options.name_map)
        self.jnt = self.match.joints
        self.body = self.match.bodies
        self.site = self.match.sites
        self.result.matched_by = [{"urdf": a, "mjcf": b, "how": how}
                                  for a, b, how in self.match.pairs]
        self.matched = [n for n in self.pb.names if n in self.jnt]
        #: links PyBullet zeroes whose body the MJCF gives another inertia (see masses)
        self.repaired: list[str] = []
        # PyBullet's world has no gravity until set: MuJoCo's, for inverse dynamics and swing
        self.pb.b.setGravity(*map(float, self.fixed.opt.gravity))

    # ------------------------------------------------------------------ structure

    def structure(self) -> None:
        mj, m, res = self.mj, self.fixed, self.result
        moving_root = not self.o.fixed_base and self.robot.links[self.robot.root].inertial.mass \
            != 0 and self.robot.root != "world"
        want = "free joint" if moving_root else "welded"
        # the root's own free joint: another free body (a loose box) is no robot base
        got = "free joint" if self._root_free(self.model) is not None else "welded"
        res.add("structure", "base", None, None, "", f"PyBullet: {want}; MJCF: {got}",
                "pass" if want == got else "fail")
        self.joint_rows()
        mimic = [f"{j.name} = {j.mimic[1]:g} x {j.mimic[0]} + {j.mimic[2]:g}"
                 for j in self.robot.movable() if j.mimic is not None and j.name in self.jnt]
        if mimic:
            res.add("structure", "mimic joints", float(len(mimic)), None, "known",
                    "PyBullet ignores <mimic>; an MJCF equality means it: " + "; ".join(mimic),
                    status="known")
        self.masses()
        errors, groups = tree_errors(mj, self.model, m, self.robot, self.match)
        if groups:
            res.add("structure", "body tree", float(len(errors)), 0.0, "differ",
                    "; ".join(errors[:3]) + (" ..." if len(errors) > 3 else "")
                    or f"{groups} bodies, each under its PyBullet parent")
        else:
            res.add("structure", "body tree", None, None, "", "not compared: no link has a "
                    "body or site in the MJCF")
        self.forces_of_mujoco_alone()

    def forces_of_mujoco_alone(self) -> None:
        """What MuJoCo would push the robot with that PyBullet has no counterpart of.

        Joint springs (``stiffness``), gravity compensation (``gravcomp``), the medium's
        forces (``density``, ``viscosity``, ``wind``), and a gravity other than the
        0 0 -9.81 urdfkit's PyBullet commands set. Each would move MuJoCo's robot otherwise
        while the rows at poses (kinematics, mass matrix) still agreed.
        """
        import numpy as np

        mj, m, res = self.mj, self.model, self.result
        said = []
        for k in range(m.njnt):
            if float(m.jnt_stiffness[k]):
                said.append(f"joint {_name(m, mj.mjtObj.mjOBJ_JOINT, k) or k} stiffness "
                            f"{float(m.jnt_stiffness[k]):g}")
        for b in range(1, m.nbody):
            if float(m.body_gravcomp[b]):
                said.append(f"body {_name(m, mj.mjtObj.mjOBJ_BODY, b) or b} gravcomp "
                            f"{float(m.body_gravcomp[b]):g}")
        if not np.allclose(m.opt.gravity, (0.0, 0.0, -9.81), rtol=0.0, atol=1e-12):
            said.append(f"gravity {' '.join(f'{g:g}' for g in m.opt.gravity)} (PyBullet's "
                        "commands: 0 0 -9.81)")
        for what in ("density", "viscosity"):
            if float(getattr(m.opt, what)):
                said.append(f"{what} {float(getattr(m.opt, what)):g}")
        if np.any(m.opt.wind):
            said.append(f"wind {' '.join(f'{w:g}' for w in m.opt.wind)}")
        said += self._equalities_of_mujoco_alone()
        res.add("structure", "forces MuJoCo alone applies", float(len(said)), 0.0, "found",
                "; ".join(said[:3]) + (" ..." if len(said) > 3 else "")
                or "no joint springs, gravity compensation or medium; gravity 0 0 -9.81")

    def _equalities_of_mujoco_alone(self) -> list[str]:
        """Active MJCF equalities that are not the export's.

        The export's are a URDF ``<mimic>`` and a joint PyBullet locks (lower == upper). The
        swing turns equalities off, so a weld or a held joint the URDF has not would
        otherwise pass unseen.
        """
        mj, m = self.mj, self.model
        mimic = {j.name: j.mimic[0] for j in self.robot.movable() if j.mimic is not None}
        locked = {j.name for j in self.robot.movable() if j.limited and j.lower == j.upper}
        out = []
        for e in range(m.neq):
            if not m.eq_active0[e]:
                continue
            kind = int(m.eq_type[e])
            if kind == int(mj.mjtEq.mjEQ_JOINT):
                a = _name(m, mj.mjtObj.mjOBJ_JOINT, int(m.eq_obj1id[e]))
                b = _name(m, mj.mjtObj.mjOBJ_JOINT, int(m.eq_obj2id[e])) \
                    if int(m.eq_obj2id[e]) >= 0 else ""
                urdf = next((n for n, k in self.jnt.items()
                             if _name(self.fixed, mj.mjtObj.mjOBJ_JOINT, k) == a), a)
                lead = next((n for n, k in self.jnt.items()
                             if _name(self.fixed, mj.mjtObj.mjOBJ_JOINT, k) == b), b)
                if (b and mimic.get(urdf) == lead) or (not b and urdf in locked):
                    continue
                out.append(f"equality on joint {a or e}" + (f" and {b}" if b else ""))
            else:
                kinds = {int(mj.mjtEq.mjEQ_WELD): "weld", int(mj.mjtEq.mjEQ_CONNECT): "connect"}
                out.append(f"{kinds.get(kind, 'equality')} "
                           f"{_name(m, mj.mjtObj.mjOBJ_EQUALITY, e) or e}")
        return out

    def joint_rows(self) -> None:
        """Names, order, kinds, limits, damping, armature and friction of the matched joints."""
        mj, m, pb, res = self.mj, self.fixed, self.pb, self.result
        mine = {k: n for n, k in self.jnt.items()}
        names = [_name(m, mj.mjtObj.mjOBJ_JOINT, k) for k in range(m.njnt)]
        res.unmatched_joints = [n for n in pb.names if n not in self.jnt]
        res.extra_joints = [names[k] or f"joint {k}" for k in range(m.njnt) if k not in mine]
        missing = res.unmatched_joints + [f"+{n}" for n in res.extra_joints]
        res.add("structure", "joint names", float(len(missing)), 0.0, "unmatched",
                ", ".join(missing[:6]) + (" ..." if len(missing) > 6 else ""))
        if not self.matched:
            for what in ("joint order", "joint kinds", "joint limits", "joint damping"):
                res.add("structure", what, None, None, "",
                        "no movable joints" if not pb.names and not res.extra_joints else
                        "not compared: no joint matched", status="info"
                        if not pb.names and not res.extra_joints else None)
            return
        order = [mine[k] for k in range(m.njnt) if k in mine]
        bad = next((a for a, b in zip(order, self.matched, strict=True) if a != b), "")
        res.add("structure", "joint order", 0.0 if not bad else 1.0, 0.0, "moved",
                f"first out of place: {bad}" if bad else f"{len(order)} joints")
        joints = {j.name: j for j in self.robot.joints}
        kinds = {0: mj.mjtJoint.mjJNT_HINGE, 1: mj.mjtJoint.mjJNT_SLIDE,
                 2: mj.mjtJoint.mjJNT_BALL}
        wrong, limits, damping, armature, friction = [], [], [], [], []
        known_friction = []
        for i, n in zip(pb.movable, pb.names, strict=True):
            if n not in self.jnt:
                continue
            info, k = pb.info[i], self.jnt[n]
            dof = int(m.jnt_dofadr[k])
            if int(kinds[info[2]]) != int(m.jnt_type[k]):
                wrong.append(n)
            armature.append((abs(float(m.dof_armature[dof])), n))
            loss = float(m.dof_frictionloss[dof])
            if loss and loss == joints[n].friction:
                known_friction.append(f"{n} {loss:g}")
            else:
                friction.append((abs(loss), n))  # PyBullet 3.2.7 simulates none
            if info[2] == 2:  # PyBullet's spherical joint has no limit
                limits.append((math.inf if m.jnt_limited[k] else 0.0, n))
                continue
            limits.append((self._limit_error(joints[n], info, k), n))
            if int(kinds[info[2]]) == int(m.jnt_type[k]):
                damping.append((abs(info[6] - m.dof_damping[dof]), n))
        res.add("structure", "joint kinds", float(len(wrong)), 0.0, "differ", ", ".join(wrong))
        for what, items, unit in (("joint limits", limits, "rad|m"),
                                  ("joint damping", damping, "N m s/rad")):
            v, d = _worst(items)
            res.add("structure", what, v, TOL_EXACT, unit, d if items else
                    "not compared: only ball joints matched", status=None if items else "info")
        v, d = _worst(armature)
        res.add("structure", "joint armature", v, TOL_EXACT, "kg m^2",
                f"{d}: MuJoCo adds rotor inertia PyBullet does not have" if v > TOL_EXACT
                else d)
        v, d = _worst(friction)
        res.add("structure", "joint frictionloss", v, TOL_EXACT, "N m",
                f"{d}: MuJoCo simulates a dry friction PyBullet 3.2.7 does not" if v > TOL_EXACT
                else d)
        if known_friction:
            res.add("structure", "joint friction of the URDF", float(len(known_friction)), None,
                    "known", "PyBullet 3.2.7 does not simulate <dynamics friction>; the MJCF's "
                    "frictionloss does: " + "; ".join(known_friction[:4]), status="known")

    def _limit_error(self, joint: Any, info: Any, k: int) -> float:
        """How far MuJoCo's range is from the limits PyBullet loaded (inf: one side only)."""
        m = self.fixed
        # PyBullet limits a revolute or prismatic joint with lower <= upper, never a
        # continuous one (getJointInfo shows a continuous joint's <limit> all the same)
        if joint.limited and joint.lower == joint.upper and not m.jnt_limited[k]:
            return 0.0  # locked: MuJoCo has no empty range (export holds it with an equality)
        if joint.limited != bool(m.jnt_limited[k]):
            return math.inf
        if not joint.limited:
            return 0.0
        return float(max(abs(info[8] - m.jnt_range[k][0]), abs(info[9] - m.jnt_range[k][1])))

    def masses(self) -> None:
        """Mass, centre of mass and inertia, welded groups compared at the zero pose."""
        import numpy as np

        mj, m, res = self.mj, self.fixed, self.result
        robot = self.robot
        where = fused(robot)
        zero = link_frames(robot, {})
        # PyBullet: each body group (fixed links fused), in the world at the zero pose
        groups: dict[str, list[tuple[LoadedInertial, Any]]] = {}
        for link, (body, _) in where.items():
            if link in self.pb.link_index:
                groups.setdefault(body, []).append((self.pb.inertial(link), zero[link]))
        # MuJoCo: bodies grouped by the body they are welded to, at qpos0 = 0
        d = mj.MjData(m)
        d.qpos[:] = 0
        mj.mj_kinematics(m, d)
        mj.mj_comPos(m, d)
        weld, snapped = self._mujoco_weld_groups(d)
        image = self._weld_image(where, self.model)
        total_pb = sum(i.mass for parts in groups.values() for i, _ in parts)
        total_mj = float(m.body_mass[1:].sum())
        res.add("structure", "total mass", abs(total_pb - total_mj) / max(total_pb, 1e-300),
                TOL_EXACT, "relative", f"PyBullet {total_pb!r} kg, MuJoCo {total_mj!r} kg"
                + self._defaults_said(list(robot.links), abs(total_pb - total_mj)))
        mass: list[tuple[float, str]] = []
        com: list[tuple[float, str]] = []
        inertia: list[tuple[float, str]] = []
        missing: list[str] = []
        zeroed = self.zeroed_inertia()
        self.repaired = []
        for body, parts in groups.items():
            if body not in image:
                if not (body == robot.root == "world" and combine(parts).mass == 0):
                    missing.append(body)  # (a massless `world` is MuJoCo's world body)
                continue
            ours, theirs = combine(parts), combine(
                weld.get(image[body], []) or [(LoadedInertial(0.0, (0, 0, 0), _ZERO3), np.eye(4))])
            mass.append((abs(ours.mass - theirs.mass) / max(ours.mass, theirs.mass, 1e-300),
                         body))
            if ours.mass <= 0:
                continue
            com.append((float(np.abs(ours.com - theirs.com).max()), body))
            scale = max(float(np.abs(ours.tensor).max()), 1e-300)
            off = float(np.abs(ours.tensor - theirs.tensor).max()) / scale
            mine = [z for z in zeroed if where[z][0] == body]
            if mine and off > TOL_INERTIA:
                # PyBullet zeroed a link's tensor here and the MJCF holds another (export
                # writes the one `fix` would: MuJoCo refuses a moving body without one)
                self.repaired += mine
                continue
            inertia.append((off, body))
        taken = set(image.values())
        missing += [f"+{_name(self.model, mj.mjtObj.mjOBJ_BODY, w) or f'body {w}'}"
                    for w, parts in weld.items() if w and w not in taken
                    and sum(i.mass for i, _ in parts) > 0]
        if missing:
            res.add("structure", "bodies", float(len(missing)), 0.0, "unmatched",
                    ", ".join(missing[:6]) + (" ..." if len(missing) > 6 else ""))
        if not mass:
            res.add("structure", "body masses", None, None, "", "not compared: no link has a "
                    "body or site in the MJCF")
        else:
            v, dd = _worst(mass)
            members = [n for n, (g, _) in where.items() if g == dd]
            res.add("structure", "body masses", v, TOL_EXACT, "relative",
                    dd + (self._defaults_said(members, v) if v > TOL_EXACT else ""))
        for what, items, tol in (("centres of mass", com, TOL_COM),
                                 ("inertia tensors", inertia, TOL_INERTIA)):
            if items:
                v, dd = _worst(items)
                res.add("structure", what, v, tol, "m" if what[0] == "c" else "relative", dd)
        v, dd = _worst(snapped)
        if v > 0:
            res.add("structure", "inertial frames MuJoCo puts on their body", v, None,
                    "relative", f"{dd}: MuJoCo's compiler takes an inertial frame this close "
                    "to its body's as the body's (body_sameframe) and simulates the tensor "
                    "so turned; the inertia row compares the MJCF's own", status="known")
        if self.repaired:
            res.add("structure", "inertia MuJoCo cannot take", float(len(self.repaired)), None,
                    "known", f"{', '.join(self.repaired[:4])}: PyBullet simulates a singular "
                    "tensor here (zero where the file's breaks the triangle inequality) and "
                    "MuJoCo refuses a moving body without one; "
                    "their bodies' inertia tensors (not their masses or centres of mass), "
                    "the dynamics and the swing are not compared",
                    status="known")

    def _mujoco_weld_groups(self, d: Any) -> tuple[dict[int, list[tuple[LoadedInertial, Any]]],
                                                    list[tuple[float, str]]]:
        """MuJoCo's bodies' mass properties by weld group (as written), placed by ``d``.

        And the bodies whose inertial frame MuJoCo's compiler snapped onto the body's, with the
        relative change of their tensor.
        """
        import numpy as np

        mj, m = self.mj, self.fixed
        weld: dict[int, list[tuple[LoadedInertial, Any]]] = {}
        snapped: list[tuple[float, str]] = []
        for b in range(1, m.nbody):
            # the inertial frame as the MJCF gives it (body_ipos, body_iquat): MuJoCo's
            # compiler puts one within ~1e-6 of the body's frame at that frame
            # (body_sameframe), which ximat then shows; said in a known row below
            turn = np.zeros(9)
            mj.mju_quat2Mat(turn, m.body_iquat[b])
            t = np.eye(4)
            t[:3, :3] = d.xmat[b].reshape(3, 3) @ turn.reshape(3, 3)
            t[:3, 3] = d.xpos[b] + d.xmat[b].reshape(3, 3) @ m.body_ipos[b]
            own = LoadedInertial(float(m.body_mass[b]), (0.0, 0.0, 0.0),
                                 tuple(map(tuple, np.diag(m.body_inertia[b]))))  # type: ignore[arg-type]
            if int(m.body_sameframe[b]):
                sim = d.ximat[b].reshape(3, 3)
                full = t[:3, :3] @ np.diag(m.body_inertia[b]) @ t[:3, :3].T
                off = sim @ np.diag(m.body_inertia[b]) @ sim.T - full
                snapped.append((float(np.abs(off).max()) / max(float(np.abs(full).max()),
                                                                1e-300),
                                _name(m, mj.mjtObj.mjOBJ_BODY, b)))
            # grouped as written: a body with a free joint of its own that no link matches
            # (a second robot, a loose box) is a group of its own, said as extra
            weld.setdefault(int(self.model.body_weldid[b]), []).append((own, t))
        return weld, snapped

    def _weld_image(self, where: dict[str, tuple[str, Any]], m: Any = None) -> dict[str, int]:
        """Each PyBullet body group -> the MuJoCo weld group its matched links are in.

        In ``m``'s weld groups: the base-welded copy's by default (body ids are the same).
        """
        m = self.fixed if m is None else m
        image: dict[str, int] = {}
        for link, (group, _) in where.items():
            if group in image:
                continue
            if link in self.body:
                image[group] = int(m.body_weldid[self.body[link]])
            elif link in self.site:
                image[group] = int(m.body_weldid[int(m.site_bodyid[self.site[link]])])
        return image

    def _defaults_said(self, links: list[str], off: float) -> str:
        """A mass difference's likely cause: links PyBullet gives its default 1 kg."""
        if off <= 0:
            return ""
        made = [n for n in links if not self.robot.links[n].inertial.given]
        if not made:
            return ""
        return (f"; {len(made)} link(s) without <inertial> ({', '.join(made[:3])}"
                f"{' ...' if len(made) > 3 else ''}) weigh PyBullet's default 1 kg each")

    def zeroed_inertia(self) -> list[str]:
        """Moving links PyBullet simulates with a singular tensor.

        A principal moment under MuJoCo's 1e-15: zeroed where the file's breaks the triangle
        inequality, or so in the file (laikago's chassis). MuJoCo refuses a moving body
        without inertia.
        """
        import numpy as np

        if not self.o.inertia_from_file:
            return []
        out = []
        where = fused(self.robot)
        for n, link in self.robot.links.items():
            if not link.inertial.given or link.inertial.mass <= 0 or n not in self.pb.link_index:
                continue
            loaded = np.array(self.pb.inertial(n).tensor)
            if not np.isfinite(loaded).all() or np.linalg.eigvalsh(loaded)[0] > 1e-15:
                continue
            group = where[n][0]
            if group != self.robot.root or (not self.o.fixed_base
                                             and self.robot.links[group].inertial.mass != 0):
                out.append(n)
        return out

    # ------------------------------------------------------------------ contacts

    def collisions(self) -> None:
        """Collision geometry and contact parameters (:mod:`urdfkit.exchange.agree_contact`)."""
        from urdfkit.exchange.agree_contact import (
            TOL_BULLET_HULL,
            TOL_MESH,
            TOL_SHAPE,
            collision_verdict,
        )

        robot, res = self.robot, self.result
        where = fused(robot)
        group = {n: g for n, (g, _) in where.items()}
        static = {robot.root} if (self.o.fixed_base or robot.root == "world"
                                  or robot.links[robot.root].inertial.mass == 0) else set()
        v = collision_verdict(self.mj, self.fixed, self.pb.b, self.pb.body, self.pb.link_index,
                              link_frames(robot, {}), group, self._weld_image(where), static,
                              keep_world=robot.root == "world")
        lost = ([f"missing in the MJCF: {', '.join(v.missing[:3])}"
                 f"{' ...' if len(v.missing) > 3 else ''}"] if v.missing else []) + \
            ([f"extra in the MJCF: {', '.join(v.extra[:3])}{' ...' if len(v.extra) > 3 else ''}"]
             if v.extra else [])
        if not v.pairs and not lost:
            res.add("contacts", "collision shapes", None, None, "",
                    "no collision shapes on either side", status="info")
            return self._said_skipped(v.skipped)
        if lost or v.shape_error is not None:
            worst, at = v.shape_error or (0.0, "")
            res.add("contacts", "collision shapes", math.inf if lost else worst, TOL_SHAPE, "m",
                    "; ".join(x for x in [*lost, at] if x))
        if v.mesh_error is not None:
            res.add("contacts", "collision meshes", v.mesh_error[0], TOL_MESH, "relative",
                    v.mesh_error[1])
        if v.hull_error is not None:
            res.add("contacts", "collision meshes vs PyBullet's own vertices",
                    v.hull_error[0], TOL_BULLET_HULL, "relative", f"{v.hull_error[1]} "
                    "(getMeshData: Bullet's hull points lie up to ~2e-4 off the file's, measured)")
        res.add("contacts", "contact parameters", float(len(v.contact)), 0.0, "links",
                "; ".join(v.contact[:2]) + (" ..." if len(v.contact) > 2 else "")
                or f"friction, condim, priority of {v.pairs} geoms")
        self._said_skipped(v.skipped)

    def _said_skipped(self, skipped: list[str]) -> None:
        if skipped:
            self.result.add(
                "contacts", "shapes MuJoCo cannot hold", float(len(skipped)), None, "known",
                "; ".join(skipped[:3]) + (" ..." if len(skipped) > 3 else "")
                + " (left out by export)", status="known")

    # ------------------------------------------------------------------ poses

    def mj_frame(self, d: Any, name: str) -> Any:
        import numpy as np

        t = np.eye(4)
        if name in self.body:
            i = self.body[name]
            t[:3, :3] = d.xmat[i].reshape(3, 3)
            t[:3, 3] = d.xpos[i]
        else:
            i = self.site[name]
            t[:3, :3] = d.site_xmat[i].reshape(3, 3)
            t[:3, 3] = d.site_xpos[i]
        return t

    def _say_unreadable(self, links: list[str]) -> None:
        """Known rows saying why the frames are not compared with PyBullet's, if they are not."""
        from urdfkit.exchange.bullet_state import unreadable_state

        why = unreadable_state(self.pb.info)
        if not links or not why:
            return
        for what in ("frames vs PyBullet: position", "frames vs PyBullet: rotation"):
            self.result.add("kinematics", what, None, None, "", f"not compared: {why}; the "
                            "exact-FK rows cover every frame", status="known")

    def _say_snapped(self, snapped: dict[str, tuple[str, Any, float]]) -> None:
        """A known row naming the sites MuJoCo computes at their body's frame, if any."""
        if not snapped:
            return
        worst = max(snapped, key=lambda n: snapped[n][2])
        more = f" and {len(snapped) - 1} more" if len(snapped) > 1 else ""
        self.result.add("kinematics", "sites MuJoCo puts on their body", snapped[worst][2], None,
                        "m|rad", f"{worst}{more}; MuJoCo's compiler places a site this close "
                        "to its body's frame at that frame (site_sameframe), so its frame is "
                        "compared there; the MJCF writes it where the file does", status="known")

    def _snapped_sites(self, links: list[str]) -> dict[str, tuple[str, Any, float]]:
        """Sites MuJoCo's compiler moved onto their body's frame: name -> (body, where, by).

        MuJoCo 4.0 marks a site within about 1e-6 (position, quaternion) of its body's frame
        as the same frame and computes it there (``site_sameframe`` 1, or 3 for the rotation
        alone), dropping the offset: HSR's ``head_l_stereo_camera_gazebo_frame`` (rpy
        1.5707963268 -1.5707963268 0 after -1.5707963268 0 -1.5707963268) sits 5.1e-12 rad
        from its body, which MuJoCo's site_xmat leaves out. ``where`` is the frame MuJoCo
        uses in the body; ``by`` the larger of the offset's length and rotation angle.
        """
        import numpy as np

        m = self.fixed
        frames = {j.child for j in self.robot.joints} | {self.robot.root}
        out: dict[str, tuple[str, Any, float]] = {}
        for n in links:
            if n in self.body or n not in self.site:
                continue
            i = self.site[n]
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
            if by == 0.0:
                continue
            # the URDF link of the site's body (matched by name or by the tree's shape)
            body = next((link for link, b in self.body.items()
                         if b == int(m.site_bodyid[i])), "")
            if body in frames:
                out[n] = (body, where, by)
        return out

    def set_q(self, d: Any, q: dict[str, float], qd: dict[str, float] | None = None) -> None:
        m = self.fixed
        for n, v in q.items():
            k = self.jnt[n]
            d.qpos[m.jnt_qposadr[k]] = v
            if qd is not None:
                d.qvel[m.jnt_dofadr[k]] = qd[n]

    def _dynamics_errors(self, d: Any, q: dict[str, float], qd: dict[str, float],
                         qdd: dict[str, float], dof: list[int],
                         turned_back: Any) -> tuple[tuple[float, str], tuple[float, str]] | str:
        """The worst relative mass-matrix and inverse-dynamics errors at one pose.

        Each with its joint; or, when PyBullet cannot build its inverse-dynamics model of this
        robot (:func:`urdfkit.engine.session.dynamics_call`), the call that failed and why.
        """
        import numpy as np

        from urdfkit.engine.session import dynamics_call

        mj, m, pb = self.mj, self.fixed, self.pb
        from urdfkit.exchange.bullet_state import unreliable_dynamics

        if unreliable_dynamics(len(pb.names)):
            return unreliable_dynamics(len(pb.names))
        qs = [q[n] for n in pb.names]
        try:
            pm = np.array(dynamics_call(pb.b, "calculateMassMatrix", pb.body, qs))
        except EngineError as refusal:
            return f"calculateMassMatrix fails on this model ({refusal.message})"
        # PyBullet's calculateInverseDynamics turns gravity by the base's inertial
        # orientation (measured: bicycle/bike.urdf, base inertial rpy 1.57 0 0,
        # 0.656 N m where MuJoCo and the swing say 0.0525): handed gravity turned
        # back, it answers for the world's
        pb.b.setGravity(*map(float, turned_back))
        try:
            tau_pb = np.array(dynamics_call(
                pb.b, "calculateInverseDynamics", pb.body, qs, [qd[n] for n in pb.names],
                [qdd[n] for n in pb.names]))
        except EngineError as refusal:
            return f"calculateInverseDynamics fails on this model ({refusal.message})"
        finally:
            pb.b.setGravity(*map(float, m.opt.gravity))
        self.set_q(d, {n: q[n] for n in self.matched}, qd)
        mm = _joint_mass_matrix(mj, m, d, dof)
        scale = max(float(np.abs(pm).max()), 1e-300)
        e = np.abs(pm - mm) / scale
        mass = (float(e.max()), pb.names[int(np.unravel_index(e.argmax(), e.shape)[0])])
        d.qacc[:] = 0
        for n, i in zip(self.matched, dof, strict=True):
            d.qacc[i] = qdd[n]
        mj.mj_comVel(m, d)
        out = np.zeros(m.nv)
        mj.mj_rne(m, d, 1, out)
        tau_mj = out[dof]
        scale = max(float(np.abs(tau_pb).max()), 1e-300)
        e = np.abs(tau_pb - tau_mj) / scale
        return mass, (float(e.max()), pb.names[int(e.argmax())])

    def poses(self) -> None:
        import numpy as np

        mj, m, pb, res, robot = self.mj, self.fixed, self.pb, self.result, self.robot
        links = [n for n in pb.link_index if n in self.body or n in self.site]
        res.unmatched_links = [n for n in pb.link_index if n not in links and n != "world"]
        rng = np.random.default_rng(self.o.seed)
        d = mj.MjData(m)
        pb_pos: list[tuple[float, str]] = []
        pb_rot: list[tuple[float, str]] = []
        fk_pos: list[tuple[float, str]] = []
        fk_rot: list[tuple[float, str]] = []
        mass_err: list[tuple[float, str]] = []
        id_err: list[tuple[float, str]] = []
        contacts: list[str] = []
        dyn = not res.unmatched_joints and not res.extra_joints and self.matched \
            and not pb.spherical
        dof = [int(m.jnt_dofadr[self.jnt[n]]) for n in self.matched]
        refused: str | None = None  # the PyBullet call that failed on this model
        zeroed = self.repaired
        if dyn and zeroed:
            refused = f"model has a singular inertia on {', '.join(zeroed[:3])} (see the " \
                "structure rows)"
        d_contact = mj.MjData(m)
        tol = pybullet_frame_tolerances(robot)
        from urdfkit.model.spec import quat_to_matrix

        base_inertial = np.array(quat_to_matrix(pb.b.getDynamicsInfo(pb.body, -1)[4]))
        turned_back = base_inertial.T @ np.array(m.opt.gravity)
        snapped = self._snapped_sites(links)
        for _ in range(self.o.poses):
            q = _sample(robot, pb.one_names, rng)
            qd = _sample(robot, pb.one_names, rng)
            qdd = _sample(robot, pb.one_names, rng)
            d.qpos[:] = m.qpos0
            d.qvel[:] = 0
            self.set_q(d, {n: q[n] for n in self.matched if n in q})
            mj.mj_kinematics(m, d)
            pb.pose(q)
            # none where PyBullet cannot report the body's state (_say_unreadable)
            pb_err = {n: _frame_error(self.mj_frame(d, n), t) for n, t in pb.frames(links).items()}
            pb_pos += [(a / tol[n], n) for n, (a, _) in pb_err.items()]
            pb_rot += [(b / tol[n], n) for n, (_, b) in pb_err.items()]
            exact = link_frames(robot, q)
            for n in links:
                f = self.mj_frame(d, n)
                ref = exact[n] if n not in snapped else exact[snapped[n][0]] @ snapped[n][1]
                a, b = _frame_error(f, ref)
                fk_pos.append((a, n))
                fk_rot.append((b, n))
            if dyn and refused is None:
                got = self._dynamics_errors(d, q, qd, qdd, dof, turned_back)
                if isinstance(got, str):
                    refused = got  # PyBullet cannot answer for this model: not compared
                else:
                    mass_err.append(got[0])
                    id_err.append(got[1])
            d_contact.qpos[:] = d.qpos
            mj.mj_forward(m, d_contact)
            for c in d_contact.contact[:d_contact.ncon]:
                b1, b2 = int(m.geom_bodyid[c.geom1]), int(m.geom_bodyid[c.geom2])
                if b1 and b2:
                    contacts.append(f"{_name(m, mj.mjtObj.mjOBJ_BODY, b1) or f'body {b1}'}/"
                                    f"{_name(m, mj.mjtObj.mjOBJ_BODY, b2) or f'body {b2}'}")
        if not links:
            res.add("kinematics", "link frames", None, None, "", "not compared: no link has "
                    "a body or site of its name")
        self._say_unreadable(links)
        for what, items, fixed in (("frames vs PyBullet: position", pb_pos, None),
                                   ("frames vs PyBullet: rotation", pb_rot, None),
                                   ("frames vs exact FK: position", fk_pos, TOL_FK),
                                   ("frames vs exact FK: rotation", fk_rot, TOL_FK)):
            if not items:  # no link matched, or PyBullet cannot report the frames (said above)
                continue
            v, n = _worst(items)
            limit = fixed if fixed is not None else tol[n]
            if fixed is None:
                v *= limit  # the worst error relative to its own frame's tolerance
            res.add("kinematics", what, v, limit, "m" if "position" in what else "matrix",
                    f"{n} ({len(links)} frames x {self.o.poses} poses)")
        self._say_snapped(snapped)
        self._dynamics_rows(bool(dyn), refused, mass_err, id_err)
        pairs = sorted(set(contacts))
        res.add("contacts", "self-contacts at the poses", float(len(contacts)), 0.0, "contacts",
                ", ".join(pairs[:4]) + (" ..." if len(pairs) > 4 else ""),
                status="info" if self.o.self_collision else None)

    def _dynamics_rows(self, dyn: bool, refused: str | None,
                       mass_err: list[tuple[float, str]], id_err: list[tuple[float, str]]
                       ) -> None:
        res, pb = self.result, self.pb
        if dyn and refused is not None:
            res.add("dynamics", "mass matrix, inverse dynamics", None, None, "",
                    f"not compared: raw PyBullet's {refused}", status="known")
        elif dyn:
            v, n = _worst(mass_err)
            res.add("dynamics", "mass matrix", v, TOL_DYNAMICS, "relative", n)
            v, n = _worst(id_err)
            res.add("dynamics", "inverse dynamics", v, TOL_DYNAMICS, "relative", n)
        elif not pb.names and not res.extra_joints:
            res.add("dynamics", "mass matrix, inverse dynamics", None, None, "",
                    "no movable joints", status="info")
        elif pb.spherical and not res.unmatched_joints and not res.extra_joints:
            res.add("dynamics", "mass matrix, inverse dynamics", None, None, "",
                    f"not compared: spherical joints ({', '.join(pb.spherical[:3])}); their "
                    "frames are compared at rest", status="info")
        else:
            res.add("dynamics", "mass matrix, inverse dynamics", None, None, "",
                    "not compared: the joints differ")

    # ------------------------------------------------------------------ swing

    def swing(self) -> None:
        """The free swing with the base fixed; where the base is free, floating too."""
        res = self.result
        blocked = self._swing_blocked()
        if blocked is not None:
            res.add("swing", "free swing", None, None, "", blocked[0], status=blocked[1])
            return
        self._swing(floating=False)
        if self._root_free(self.model) is not None and not self._pybullet_static():
            self._swing(floating=True)

    def _root_free(self, m: Any) -> int | None:
        """The free joint of the robot's root body in ``m`` (not another free body's)."""
        root = self.body.get(self.robot.root)
        return next((i for i in range(m.njnt) if m.jnt_type[i] == self.mj.mjtJoint.mjJNT_FREE
                     and int(m.jnt_bodyid[i]) == root), None) if root is not None else None

    def _pybullet_static(self) -> bool:
        root = self.robot.links[self.robot.root]
        return self.o.fixed_base or self.robot.root == "world" or root.inertial.mass == 0

    def _swing_blocked(self) -> tuple[str, str | None] | None:
        """Why no swing can be compared (the row's detail and status), or None."""
        res = self.result
        if not self.pb.names and not res.extra_joints:
            return "no movable joints", "info"
        if not self.matched or res.unmatched_joints or res.extra_joints:
            return "not compared: the joints differ", None
        if self.pb.spherical:
            return "not compared: spherical joints", "info"
        from urdfkit.exchange.bullet_state import unreadable_state

        if unreadable_state(self.pb.info):  # getJointStates would raise or misread
            return "not compared: " + unreadable_state(self.pb.info), "known"
        zeroed = self.repaired
        if zeroed:
            return (f"not compared: PyBullet simulates a singular inertia on "
                    f"{', '.join(zeroed[:3])} "
                    "(see the structure rows)", "known")
        return None

    def _locked(self) -> dict[str, float]:
        """Joints PyBullet locks (lower == upper) that the MJCF leaves unlimited: name -> q."""
        m, out = self.fixed, {}
        for j in self.robot.movable():
            if j.limited and j.lower == j.upper and j.name in self.jnt \
                    and not m.jnt_limited[self.jnt[j.name]]:
                out[j.name] = j.lower
        return out

    def _swing_model(self, floating: bool, locked: dict[str, float]) -> Any:
        """The MJCF for a swing: base welded unless ``floating``.

        Locked joints are welded at their value, as PyBullet holds them (measured: to
        5.6e-16 rad of the same joint written fixed).
        """
        if not locked:
            return self.model if floating else self.fixed
        import warnings

        import numpy as np

        from urdfkit.model.spec import axis_angle_matrix

        mj, m = self.mj, self.fixed
        spec = mj.MjSpec.from_file(self.path)
        # the spec's joints in the written model's order (checked by type below): a locked
        # joint by its position, as an unnamed joint has no name to find it by
        kept = [i for i in range(self.model.njnt)
                if self.model.jnt_type[i] != mj.mjtJoint.mjJNT_FREE]
        weld_at = {kept[self.jnt[n]]: (self.jnt[n], q) for n, q in locked.items()}
        joints = list(spec.joints)
        if [int(j.type) for j in joints] != [int(t) for t in self.model.jnt_type]:
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

    def _swing_start(self) -> tuple[dict[str, float], dict[str, float]]:
        """The seeded start: each limited joint in the middle half of its range.

        And joint speeds for the floating swing: a free robot falling from rest does not swing.
        """
        import numpy as np

        rng = np.random.default_rng(self.o.seed + 1)
        joints = {j.name: j for j in self.robot.joints}
        q0, v0 = {}, {}
        for n in self.pb.names:
            j = joints[n]
            lo, hi = sample_range(j) if j.limited else (-2.0, 2.0)
            mid = (lo + hi) / 2 if math.isfinite(lo + hi) else lo / 2 + hi / 2  # 1e308 and up
            half = (hi - lo) / 4
            q0[n] = float(rng.uniform(mid - half, mid + half))
        for n in self.pb.names:
            v0[n] = float(rng.uniform(-1.0, 1.0))
        return q0, v0

    def _swing(self, floating: bool) -> None:
        mj, pb, res = self.mj, self.pb, self.result
        locked = self._locked()
        try:
            m = self._swing_model(floating, locked)
        except (ValueError, RuntimeError) as e:
            res.add("swing", "free swing", None, None, "", "not compared: MuJoCo cannot weld "
                    f"the locked joints ({str(e).strip().splitlines()[0][:120]})")
            return
        m.opt.timestep = self.o.time_step
        m.opt.integrator = mj.mjtIntegrator.mjINT_EULER
        m.opt.disableflags |= (mj.mjtDisableBit.mjDSBL_CONTACT | mj.mjtDisableBit.mjDSBL_EULERDAMP
                               | mj.mjtDisableBit.mjDSBL_EQUALITY
                               | mj.mjtDisableBit.mjDSBL_ACTUATION)
        d = mj.MjData(m)
        q0, v0 = self._swing_start()
        names = [n for n in pb.names if n not in locked]
        # the swing model's joints are the base-welded copy's, in order, less the locked
        # ones (welded): matched by position, as unnamed joints have no name to look up
        gone = {self.jnt[n] for n in locked}
        kept = [k for k in range(self.fixed.njnt) if k not in gone]
        own = [k for k in range(m.njnt) if m.jnt_type[k] != mj.mjtJoint.mjJNT_FREE]
        to_swing = dict(zip(kept, own, strict=True))
        ids = {n: to_swing[self.jnt[n]] for n in names}
        for n in names:
            d.qpos[m.jnt_qposadr[ids[n]]] = q0[n]
            if floating:
                d.qvel[m.jnt_dofadr[ids[n]]] = v0[n]
        if floating:
            free = self._root_free(m)
            assert free is not None  # swing() runs the floating swing only then
            d.qpos[m.jnt_qposadr[free]:m.jnt_qposadr[free] + 7] = [0, 0, 0, 1, 0, 0, 0]
        at_start = mj.MjData(self.fixed)
        self.set_q(at_start, {n: q0[n] for n in self.matched})
        unstable = self._explicit_damping_unstable(at_start)
        if unstable:
            kind = "floating swing" if floating else "free swing"
            res.add("swing", f"{kind}, dt {self.o.time_step:g}", None, None, "", unstable,
                    status="known")
            return
        body = pb.swinger(floating, {n: q0.get(n, 0.0) for n in pb.names},
                          {n: v0[n] for n in names} if floating else {}, self.o.time_step)
        if floating:
            # uniform gravity moves a free robot's every body alike: off, the base's motion
            # is the joints' reaction alone, a few cm, where PyBullet's float32 base frame is
            # good to ~1e-9 m (with gravity, 4.9 m of fall leave 2.4e-7 of float32 rounding)
            m.opt.gravity[:] = 0.0
            pb.b.setGravity(0.0, 0.0, 0.0)
        try:
            self._swing_compare(m, d, body, names, [int(m.jnt_qposadr[ids[n]]) for n in names],
                                floating, locked)
        finally:
            if body != pb.body:
                pb.b.removeBody(body)
            pb.b.setGravity(*map(float, self.fixed.opt.gravity))

    def _swing_compare(self, m: Any, d: Any, body: int, names: list[str], adr: list[int],
                       floating: bool, locked: dict[str, float]) -> None:
        import numpy as np

        mj, pb = self.mj, self.pb
        b = pb.b
        joints = {j.name: j for j in self.robot.joints}
        index = [pb.movable[pb.names.index(n)] for n in names]
        # how near a limit the swing may come: LIMIT_MARGIN, or an eighth of a short range
        # (the start is a quarter of the range in from each limit), so that a gripper finger
        # of 11.5 mm (youBot's) does not stop the whole swing at its first step
        margin = {n: min(LIMIT_MARGIN, (joints[n].upper - joints[n].lower) / 8)
                  for n in names if joints[n].limited}
        free_joint = self._root_free(m) if floating else None
        free = int(m.jnt_qposadr[free_joint]) if free_joint is not None else 0
        spin = int(m.jnt_dofadr[free_joint]) + 3 if free_joint is not None else 0
        turn = np.zeros(9)
        spun = 0.0  # the integral of the base's squared angular speed (rad^2/s)
        steps = round(self.o.seconds / self.o.time_step)
        worst, at, stop, why, base = 0.0, "", steps, "", 0.0
        for step in range(steps):
            mj.mj_step(m, d)
            b.stepSimulation()
            qp = [s[0] for s in b.getJointStates(body, index)] if index else []
            near = ""
            for n, a, v in zip(names, adr, qp, strict=True):
                j = joints[n]
                e = abs(d.qpos[a] - v)
                if e > worst or e != e:
                    worst, at = (e if e == e else math.inf), n
                if j.limited and min(v - j.lower, j.upper - v, d.qpos[a] - j.lower,
                                     j.upper - d.qpos[a]) < margin[n]:
                    near = n
            if floating:  # the root's frame is its free joint's qpos (xpos lags a step)
                t = pb.base_frame(body)
                mj.mju_quat2Mat(turn, d.qpos[free + 3:free + 7])
                off = max(float(np.abs(t[:3, 3] - d.qpos[free:free + 3]).max()),
                          float(np.abs(t[:3, :3] - turn.reshape(3, 3)).max()))
                base = max(base, off if off == off else math.inf)
                spun += float(d.qvel[spin:spin + 3] @ d.qvel[spin:spin + 3]) * self.o.time_step
            if near:
                unit = "m" if joints[near].type == "prismatic" else "rad"
                stop, why = step + 1, f"; stopped at {(step + 1) * self.o.time_step:g} s: " \
                    f"{near} within {margin[near]:g} {unit} of a limit"
                break
        self._swing_rows(floating, stop, worst, at, why, (base, spun), locked)

    def _swing_rows(self, floating: bool, stop: int, worst: float, at: str, why: str,
                    base: tuple[float, float], locked: dict[str, float]) -> None:
        res, dt = self.result, self.o.time_step
        mimic = [j.name for j in self.robot.movable() if j.mimic is not None]
        known = f"; mimic joints free on both sides ({', '.join(mimic)}): PyBullet ignores " \
            "<mimic>" if mimic else ""
        if locked:
            known += f"; locked joints welded at their value on both sides ({', '.join(locked)})"
        kind = "floating swing" if floating else "free swing"
        what = f"{kind} {stop * dt:g} s, dt {dt:g}"
        skew = self._skewed_axes()
        status = None
        if skew and worst > TOL_SWING:
            status = "known"
            known += (f"; the axis of {skew[0][1]} is {skew[0][0]:.2g} off unit length in the "
                      "file: PyBullet's step uses it so (its own mass matrix normalises it), "
                      "MuJoCo normalises it, so the two step slightly different robots")
        res.add("swing", what, worst, TOL_SWING, "rad", f"{at}{why}{known}", status=status)
        if floating:
            # the engines turn a spinning base by different first-order steps (measured on
            # a1: 1.5e-10, 7.7e-11, 3.8e-11 at dt 1, 0.5, 0.25 ms while its joints agree to
            # 1e-16): they part by up to dt x the integral of the squared spin rate
            tol = TOL_FLOATING_BASE + dt * base[1]
            res.add("swing", f"{kind}: base frame", base[0], tol, "m|matrix",
                    f"{self.robot.root} (free on both sides, from rest, joints set moving; "
                    f"tolerance 1e-9 + dt x {base[1]:.3g} rad^2/s of spin)"
                    + (f"; {known.lstrip('; ')}" if status else ""), status=status)

    def _skewed_axes(self) -> list[tuple[float, str]]:
        """Joints whose axis PyBullet loaded off unit length (worst first)."""
        out = []
        for i, n in zip(self.pb.movable, self.pb.names, strict=True):
            off = abs(math.sqrt(sum(a * a for a in self.pb.info[i][13])) - 1.0)
            if off > 1e-12:
                out.append((off, n))
        return sorted(out, reverse=True)

    def _explicit_damping_unstable(self, d: Any) -> str:
        """Why the swing cannot be compared when joint damping makes it unstable, else "".

        Both sides step joint damping explicitly (PyBullet does; MuJoCo is set so, its
        implicit ``eulerdamp`` off), so a joint's speed is multiplied by about
        ``1 - dt * damping / inertia`` each step: past 2 it flips sign and grows. PyBullet
        caps it at its 100 rad/s joint-speed limit, MuJoCo does not, so the two part by
        radians in a few steps (a Shadow hand's 0.1 N m s/rad on fingertips of ~1e-6 kg m^2
        at 1 ms: 100). The bound is the largest eigenvalue of ``dt M^-1 B`` at the start pose.
        """
        import numpy as np

        mj, m = self.mj, self.fixed
        dof = [int(m.jnt_dofadr[self.jnt[n]]) for n in self.pb.names]
        damping = np.array([float(m.dof_damping[i]) for i in dof])
        if not damping.any():
            return ""
        mass = _joint_mass_matrix(mj, m, d, dof)
        dt = self.o.time_step
        try:
            rate = float(np.linalg.eigvals(np.linalg.solve(mass, np.diag(damping))).real.max())
        except np.linalg.LinAlgError:  # a singular mass matrix: the dynamics rows say so
            return ""
        if rate * dt <= 2.0:
            return ""
        own = damping * dt / np.maximum(np.diag(mass), 1e-300)
        k = int(own.argmax())
        return (f"not compared: joint damping makes the swing unstable at this step: both "
                f"engines step it explicitly, and dt x damping / inertia reaches "
                f"{rate * dt:.3g} (stable under 2; {self.pb.names[k]}: damping "
                f"{damping[k]:.3g} N m s/rad on "
                f"{mass[k, k]:.3g} kg m^2), so joint speeds flip sign each "
                f"step and grow, PyBullet's to its 100 rad/s cap; PyBullet's own simulation "
                f"of this file is unstable at any step over {2.0 / rate:.3g} s")


def agree(resolved: Any, model_path: str | Path, options: AgreeOptions | None = None
          ) -> Agreement:
    """Compare ``model_path`` (MJCF) with the resolved URDF as PyBullet loads it.

    Raises:
        InputError: MuJoCo cannot load the MJCF.
        MissingDependencyError: MuJoCo is not installed.
    """
    import numpy as np

    from urdfkit.engine.session import Session
    from urdfkit.formats.mjwarn import mujoco_warnings
    from urdfkit.formats.robot import read_robot

    o = options or AgreeOptions()
    robot = read_robot(resolved.root, resolved.name)
    mujoco = import_mujoco()
    # a model that diverges says so in its rows (inf, NaN: null in JSON) and in MuJoCo's
    # warnings, not in numpy's or MuJoCo's lines on stderr
    with Session() as session, mujoco_warnings(mujoco) as said, np.errstate(all="ignore"):
        c = _Compare(robot, str(model_path), session, str(resolved.load_path), o)
        c.structure()
        c.poses()
        c.collisions()
        c.swing()
        c.result.warnings += [w for w in dict.fromkeys(said) if w not in c.result.warnings]
        return c.result


