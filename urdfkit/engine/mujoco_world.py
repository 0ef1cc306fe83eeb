"""The MuJoCo engine's world: every robot in one model, compiled when needed.

MuJoCo compiles one model for the whole world. :meth:`World.add` attaches a robot's parsed
export to the world's ``MjSpec`` (``MjSpec.attach``, names prefixed ``"<body>/"``), with the
contact pairs and motors it brings; the world is compiled at the first call that needs it, and
recompiled with ``MjSpec.recompile``, which carries every joint's state over, when bodies were
added since. What is set at run time (motors, friction, masses, limits, time step, gravity) is
kept here and applied again after each compile. :mod:`urdfkit.engine.mujoco` is the engine
built on it.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import replace
from typing import Any

from urdfkit.core.errors import EngineError, ParameterError
from urdfkit.engine.api import JointInfo, LinkDynamics, LoadSettings, Quat, Vec3
from urdfkit.engine.mujoco_build import Loaded, Pair
from urdfkit.engine.mujoco_motors import MotorBank

#: PyBullet's default time step (its gravity is none until set).
DEFAULT_TIME_STEP = 1.0 / 240.0
#: The state save() keeps: time, positions, velocities, and the solver's warm start, so that
#: a restored run steps as the first did.
_STATE = "mjSTATE_FULLPHYSICS", "mjSTATE_WARMSTART"


class Ids:
    """A loaded robot's ids in the compiled world (remade at every compile)."""

    def __init__(self) -> None:
        self.joints: list[JointInfo] = []
        self.jnt: list[int] = []          # MuJoCo joint id per joint index, -1 fixed
        self.frames: list[tuple[str, int]] = []  # per link (root first): ("body"|"site", id)
        self.bodies: dict[str, int] = {}  # MuJoCo body id per body (by link name)
        self.root = -1                    # the root's MuJoCo body (-1: MuJoCo's world)
        self.free = -1                    # the root's free joint's qpos address (-1: none)


class World:
    """The spec, the compiled model and data, the robots, and what was set at run time.

    Attributes:
        notes: Per body, what its export dropped, approximated or defaulted, and what the
            engine left out (one line each).
    """

    def __init__(self, mj: Any) -> None:
        self.mj = mj
        self.notes: dict[int, list[str]] = {}
        self.spec: Any = mj.MjSpec()
        self.spec.modelname = "urdfkit"
        # PyBullet's integrator; implicitfast would differ only for actuators, and motors are
        # constraint rows here (urdfkit/engine/mujoco_motors.py)
        self.spec.option.integrator = mj.mjtIntegrator.mjINT_EULER
        # PyBullet's friction is a cone by default (enableConeFriction); docs/engines.md
        # measures MuJoCo's two against it
        self.spec.option.cone = mj.mjtCone.mjCONE_ELLIPTIC
        # a diverging run shows its NaNs (and step() says so) instead of starting over
        self.spec.option.disableflags |= mj.mjtDisableBit.mjDSBL_AUTORESET
        self.assets: dict[str, bytes] = {}
        self.robots: list[Loaded] = []
        self.ids: list[Ids] = []
        self.pairs: list[Pair] = []
        self.pair_ids: list[int] = []
        self.geom_owner: dict[int, tuple[int, int]] = {}   # every geom's robot and link
        self.colliders: dict[int, tuple[int, int]] = {}    # the collision geoms' alone
        self.m: Any = None
        self.d: Any = None
        self.scratch: Any = None
        self.stale = False
        self.compiled_bodies = 0
        self.closed = False
        self.time_step = DEFAULT_TIME_STEP
        self.gravity: Vec3 = (0.0, 0.0, 0.0)
        self.saved: list[tuple[int, Any]] = []
        self.torques: dict[int, float] = {}
        self.bank: MotorBank | None = None
        self.kinematics = False
        self.changed: set[tuple[int, str]] = set()   # (robot, body) with new mass properties
        self.damping: dict[tuple[int, int], float] = {}
        self.limits: dict[tuple[int, int], tuple[float, float]] = {}
        self.root_poses: dict[int, tuple[Vec3, Quat]] = {}   # static roots moved by reset_base
        #: The joints with a force/torque sensor (body, joint), and what each measured in the
        #: last step (urdfkit/engine/mujoco_reactions.py).
        self.sensors: set[tuple[int, int]] = set()
        self.reactions: dict[tuple[int, int], tuple[float, ...]] = {}
        self.sensed: tuple[Any, Any, Any] | None = None   # frames at the last measured step
        self.held: Any = None   # the joints' own constraint forces in it, once read
        self.constraints = 0   # how many user constraints (holds, couplings) were made
        #: MuJoCo's count of NaN or huge values found, after the last step (bad_count).
        self.bad = 0

    def add(self, r: Loaded, settings: LoadSettings) -> int:
        """Attach a prepared robot where ``settings`` puts it, with its contact pairs."""
        from urdfkit.engine.mujoco_build import pairs

        self.open()
        index = len(self.robots)
        child = r.spec
        # the world's options are the world's: the same values, so attach has nothing to say
        child.option.integrator = self.spec.option.integrator
        child.option.cone = self.spec.option.cone
        child.option.disableflags = self.spec.option.disableflags
        frame = self.spec.worldbody.add_frame(pos=list(settings.position),
                                              quat=wxyz(settings.orientation))
        self.spec.attach(child, prefix=f"{index}/", frame=frame)
        self.robots.append(r)
        for p in pairs(self.robots, index):
            friction, condim = self.pair_friction(p)
            self.spec.add_pair(name=f"pair{len(self.pairs)}",
                               geomname1=f"{p.robot_a}/{p.geom_a}",
                               geomname2=f"{p.robot_b}/{p.geom_b}", condim=condim,
                               friction=friction)
            self.pairs.append(p)
        self.assets.update(r.assets)
        self.notes[index] = r.notes
        self.stale = True
        return index

    def new_constraint(self) -> int:
        """The next user constraint's id (PyBullet's ids: one count for every kind)."""
        self.constraints += 1
        return self.constraints - 1

    def open(self) -> None:
        """Refuse a closed world."""
        if self.closed:
            raise EngineError("the MuJoCo engine is closed")

    def compiled(self) -> tuple[Any, Any]:
        """The compiled world, compiled or recompiled first if bodies were added."""
        self.open()
        if self.stale or self.m is None:
            self.compile()
        return self.m, self.d

    def compile(self) -> None:
        """Compile the world, or recompile it with the bodies added since (state carried)."""
        import warnings

        from urdfkit.formats.mjwarn import mujoco_warnings

        mj = self.mj
        self.spec.assets = self.assets
        new = [r.display for r in self.robots[self.compiled_bodies:]]
        try:
            with warnings.catch_warnings(), mujoco_warnings(mj):
                warnings.simplefilter("ignore")
                if self.m is None:
                    self.m = self.spec.compile()
                    self.d = mj.MjData(self.m)
                else:
                    self.m, self.d = self.spec.recompile(self.m, self.d)
        except (ValueError, RuntimeError) as e:
            first = str(e).strip().splitlines()[0] if str(e).strip() else type(e).__name__
            raise EngineError(f"MuJoCo cannot compile the world with {', '.join(new)}: "
                              f"{first}") from None
        self.compiled_bodies = len(self.robots)
        self.stale = False
        self.bad = bad_count(mj, self.d)   # a recompile carries the data's warnings over
        self.scratch = mj.MjData(self.m)
        self.kinematics = False
        self.sensed = None          # the data is new: no step measured in it
        self.reactions.clear()
        # the motors' forces in the last step, by joint: the ids are remade below
        applied = {(body, j): self.applied(info.v_index)
                   for body, ids in enumerate(self.ids) for j, info in enumerate(ids.joints)
                   if info.v_index >= 0}
        self.index()
        self.apply_all()
        assert self.bank is not None
        for (body, j), force in applied.items():
            self.bank.applied[self.ids[body].joints[j].v_index] = force

    def index(self) -> None:
        """Every robot's ids in the compiled world, and each geom's robot and link."""
        m, mj = self.m, self.mj
        self.ids = []
        self.geom_owner = {}
        self.colliders = {}
        for index, r in enumerate(self.robots):
            ids = Ids()
            prefix = f"{index}/"
            link_index = {r.robot.root: -1} | {j.child: i for i, j in enumerate(r.robot.joints)}
            for link in r.links:
                if link.body == link.name and link.name != "world":
                    b = m.body(prefix + link.name).id
                    ids.bodies[link.name] = b
                    ids.frames.append(("body", b))
                else:
                    ids.frames.append(("site", m.site(prefix + link.name).id))
            ids.root = ids.bodies.get(r.robot.root, -1)
            if ids.root >= 0 and m.body_jntnum[ids.root] and \
                    m.jnt_type[m.body_jntadr[ids.root]] == mj.mjtJoint.mjJNT_FREE:
                ids.free = int(m.jnt_qposadr[m.body_jntadr[ids.root]])
            for i, j in enumerate(r.robot.joints):
                jid = m.joint(prefix + j.name).id if j.moves else -1
                ids.jnt.append(jid)
                ids.joints.append(self.joint_info(r, i, jid, link_index))
            for g, owner in r.geom_links.items():
                self.geom_owner[m.geom(prefix + g).id] = (index, link_index[owner])
            for g, owner, _ in r.collisions:
                self.colliders[m.geom(prefix + g).id] = (index, link_index[owner])
            self.ids.append(ids)
        self.pair_ids = [m.pair(f"pair{k}").id for k in range(len(self.pairs))]

    def joint_info(self, r: Loaded, i: int, jid: int, link_index: dict[str, int]
                   ) -> JointInfo:
        """Joint ``i`` of a robot as the seam records it, MuJoCo's state indices in."""
        from urdfkit.formats.fk import unit
        from urdfkit.model.spec import quat_to_matrix, rotate_back

        j = r.robot.joints[i]
        # PyBullet's axis is in the child's inertial frame (its link frame in Bullet)
        turn = quat_to_matrix(r.links[i + 1].dynamics.inertial_orientation)
        kind = {"continuous": "revolute", "revolute": "revolute", "prismatic": "prismatic",
                "spherical": "spherical"}.get(j.type, "fixed")
        m = self.m
        return JointInfo(
            index=i, name=j.name, kind=kind,  # type: ignore[arg-type]
            q_index=int(m.jnt_qposadr[jid]) if jid >= 0 else -1,
            v_index=int(m.jnt_dofadr[jid]) if jid >= 0 else -1,
            damping=j.damping, friction=j.friction, lower=j.lower, upper=j.upper,
            # as PyBullet reports it: a continuous joint's <limit> too, though not enforced
            limited=kind in ("revolute", "prismatic") and j.lower <= j.upper,
            effort=j.effort, velocity=j.velocity, link=j.child,
            axis=rotate_back(turn, unit(j.axis)) if j.moves and j.type != "spherical"
            else (0.0, 0.0, 0.0),
            parent=link_index[j.parent])

    def apply_all(self) -> None:
        """What is set at run time, again on a newly compiled world."""
        m = self.m
        m.opt.timestep = self.time_step
        m.opt.gravity[:] = self.gravity
        for body, (p, q) in self.root_poses.items():
            root = self.ids[body].root
            m.body_pos[root] = p
            m.body_quat[root] = wxyz(q)
        for body, name in sorted(self.changed):
            self.apply_mass(body, name, set_const=False)
        if self.changed:
            self.set_const()
        self.apply_joints()
        self.apply_pairs()
        self.build_bank()

    def build_bank(self) -> None:
        """Every motor as its joint's constraint row (see :mod:`urdfkit.engine.mujoco_motors`)."""
        import numpy as np

        bank = MotorBank(np, self.m.nv, int(self.mj.mjtConstraint.mjCNSTR_FRICTION_DOF))
        for r, ids in zip(self.robots, self.ids, strict=True):
            for j, motor in r.motors.items():
                info = ids.joints[j]
                bank.place(info.v_index, info.q_index, motor)
        self.bank = bank

    def applied(self, dof: int) -> float:
        """The force a joint's motor applied in the last step."""
        return 0.0 if self.bank is None else float(self.bank.applied[dof])

    def apply_joints(self) -> None:
        """Joint damping and limits changed at run time, in the model and in :meth:`joints`."""
        m = self.m
        for (body, j), value in self.damping.items():
            ids = self.ids[body]
            if ids.jnt[j] >= 0:
                m.dof_damping[ids.joints[j].v_index] = value
            ids.joints[j] = replace(ids.joints[j], damping=value)
        for (body, j), (lo, hi) in self.limits.items():
            ids = self.ids[body]
            if ids.jnt[j] >= 0:
                m.jnt_range[ids.jnt[j]] = (lo, hi)
                m.jnt_limited[ids.jnt[j]] = lo <= hi
            ids.joints[j] = replace(ids.joints[j], lower=lo, upper=hi, limited=lo <= hi)

    def pair_friction(self, p: Pair) -> tuple[list[float], int]:
        """A pair's combined friction and condim, from its two links' coefficients now."""
        from urdfkit.engine.mujoco_build import combined_friction

        def dyn(robot: int, link: str) -> LinkDynamics:
            return next(x.dynamics for x in self.robots[robot].links if x.name == link)

        return combined_friction(dyn(p.robot_a, p.link_a), dyn(p.robot_b, p.link_b))

    def apply_pairs(self) -> None:
        """Every pair's friction again, from the links' coefficients now."""
        m = self.m
        for p, pid in zip(self.pairs, self.pair_ids, strict=True):
            friction, condim = self.pair_friction(p)
            m.pair_friction[pid] = friction
            m.pair_dim[pid] = condim

    def apply_mass(self, body: int, name: str, set_const: bool = True) -> None:
        """A MuJoCo body's mass properties again, from the links fused into it.

        Raises:
            ParameterError: The body moves and would be left without mass or inertia.
        """
        import numpy as np

        from urdfkit.engine.inertials import link_tensor
        from urdfkit.formats.mjcf import combine
        from urdfkit.formats.robot import LoadedInertial

        r, ids = self.robots[body], self.ids[body]
        parts = [(LoadedInertial(x.dynamics.mass, x.dynamics.inertial_position,
                                 link_tensor(x.dynamics)), x.frame)
                 for x in r.links if x.body == name]
        total = combine(parts)
        moments, axes = np.linalg.eigh(total.tensor)
        if name not in r.static and not (total.mass > 0 and moments[0] > 0):
            raise ParameterError(f"the MuJoCo body of link {name!r} moves, and would have "
                                 f"mass {total.mass:.6g} and principal moments "
                                 f"{', '.join(f'{x:.3g}' for x in moments)}: MuJoCo needs "
                                 "both positive", param="mass")
        if name in r.static or name not in ids.bodies:
            return  # welded to the world: its mass moves nothing
        if np.linalg.det(axes) < 0:
            axes[:, 0] = -axes[:, 0]
        b = ids.bodies[name]
        m = self.m
        m.body_mass[b] = total.mass
        m.body_ipos[b] = total.com
        m.body_inertia[b] = moments
        quat = np.zeros(4)
        self.mj.mju_mat2Quat(quat, axes.flatten())
        m.body_iquat[b] = quat
        if set_const:
            self.set_const()

    def set_const(self) -> None:
        """The model's derived constants (dof_M0, subtree masses) after a mass changed.

        On the scratch data: mj_setConst poses its data at qpos0.
        """
        self.mj.mj_setConst(self.m, self.scratch)

    def posed(self, body: int, positions: Sequence[float],
              velocities: Sequence[float] | None) -> tuple[Any, Any]:
        """The scratch data: the world as it is, this body's joints at ``positions``."""
        m, d = self.compiled()
        s = self.scratch
        moving = self.movable(body)
        if len(positions) != len(moving) or (velocities is not None
                                             and len(velocities) != len(moving)):
            raise ParameterError(f"`positions` and `velocities` need {len(moving)} values, "
                                 f"one per movable joint of body {body}", param="positions")
        s.qpos[:] = d.qpos
        s.qvel[:] = 0.0
        for k, j in enumerate(moving):
            s.qpos[j.q_index] = positions[k]
            if velocities is not None:
                s.qvel[j.v_index] = velocities[k]
        return m, s

    def movable(self, body: int) -> list[JointInfo]:
        """The joints of one degree of freedom, in order (spherical ones refused)."""
        self.compiled()
        joints = self.body(body)[1].joints
        ball = [j.name for j in joints if j.kind == "spherical"]
        if ball:
            raise ParameterError(f"body {body} has spherical joints ({', '.join(ball)}): this "
                                 "call takes joints of one degree of freedom", param="body")
        return [j for j in joints if j.kind != "fixed"]

    def body(self, body: int) -> tuple[Loaded, Ids]:
        """A loaded robot and its ids (the world compiled first)."""
        self.compiled()
        if not 0 <= body < len(self.robots):
            raise ParameterError(f"`body` {body} is not loaded (bodies 0 to "
                                 f"{len(self.robots) - 1})", param="body")
        return self.robots[body], self.ids[body]

    def joint(self, r: Loaded, ids: Ids, joint: int) -> JointInfo:
        """Joint ``joint`` of a robot, or a ParameterError naming the range."""
        if not 0 <= joint < len(ids.joints):
            raise ParameterError(f"`joint` {joint} is not a joint of {r.display} (it has 0 to "
                                 f"{len(ids.joints) - 1})", param="joint")
        return ids.joints[joint]

    def fresh_kinematics(self) -> None:
        """Frames for the positions now (a step leaves them at the positions before it)."""
        m, d = self.compiled()
        if not self.kinematics:
            self.mj.mj_kinematics(m, d)
            self.kinematics = True

    def mat_quat(self, mat: Any) -> Quat:
        """A rotation matrix (9) as a quaternion (x y z w)."""
        import numpy as np

        q = np.zeros(4)
        self.mj.mju_mat2Quat(q, mat)
        return xyzw(q)

    def state_sig(self) -> int:
        """What :meth:`MuJoCoEngine.save` keeps, as MuJoCo's state signature."""
        flags = self.mj.mjtState
        return int(getattr(flags, _STATE[0])) | int(getattr(flags, _STATE[1]))

    def frame_of(self, ids: Ids, k: int) -> tuple[Vec3, Quat, Any]:
        """Link frame ``k`` (0: the root) now: position, quaternion (x y z w), matrix (3x3)."""
        self.fresh_kinematics()
        d = self.d
        kind, i = ids.frames[k]
        if kind == "body":
            return vec3(d.xpos[i]), xyzw(d.xquat[i]), d.xmat[i].reshape(3, 3)
        return vec3(d.site_xpos[i]), self.mat_quat(d.site_xmat[i]), d.site_xmat[i].reshape(3, 3)

_BAD: list[int] = []


def bad_count(mj: Any, d: Any) -> int:
    """How often MuJoCo has found NaN or huge values (positions, velocities, accelerations)."""
    if not _BAD:  # the warnings' indices, looked up once
        w = mj.mjtWarning
        _BAD.extend(int(k) for k in (w.mjWARN_BADQACC, w.mjWARN_BADQVEL, w.mjWARN_BADQPOS))
    warning = d.warning
    return int(warning[_BAD[0]].number + warning[_BAD[1]].number + warning[_BAD[2]].number)


def rotate(rot: Any, v: Sequence[float]) -> Vec3:
    """``rot`` (3x3) times ``v``."""
    return (float(rot[0][0] * v[0] + rot[0][1] * v[1] + rot[0][2] * v[2]),
            float(rot[1][0] * v[0] + rot[1][1] * v[1] + rot[1][2] * v[2]),
            float(rot[2][0] * v[0] + rot[2][1] * v[1] + rot[2][2] * v[2]))


def add(a: Sequence[float], b: Sequence[float]) -> Vec3:
    """``a + b``."""
    return (float(a[0] + b[0]), float(a[1] + b[1]), float(a[2] + b[2]))


def cross(a: Sequence[float], b: Sequence[float]) -> Vec3:
    """``a x b``."""
    return (a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0])


def vec3(v: Any) -> Vec3:
    """Three floats."""
    return (float(v[0]), float(v[1]), float(v[2]))


def xyzw(q: Any) -> Quat:
    """MuJoCo's (w, x, y, z) as the seam's (x, y, z, w)."""
    return (float(q[1]), float(q[2]), float(q[3]), float(q[0]))


def wxyz(q: Sequence[float]) -> list[float]:
    """The seam's (x, y, z, w) as MuJoCo's (w, x, y, z)."""
    return [float(q[3]), float(q[0]), float(q[1]), float(q[2])]


def unit_quat(q: Sequence[float]) -> Quat:
    """``q`` normalised, or a ParameterError when it is no rotation."""
    n = math.sqrt(sum(x * x for x in q))
    if not n > 0 or not math.isfinite(n):
        raise ParameterError(f"`orientation` {tuple(q)!r} is not a rotation", param="orientation")
    return (q[0] / n, q[1] / n, q[2] / n, q[3] / n)
