"""MuJoCo as an engine: the robot PyBullet simulates, built from urdfkit's own MJCF export.

:class:`MuJoCoEngine` implements :class:`urdfkit.engine.api.Simulator`. MuJoCo's own URDF
reader refuses COLLADA meshes and ``package://``, and reads inertia, joints and friction its
own way; the export (:mod:`urdfkit.formats.mjcf`, which ``urdfkit agree`` proves against
PyBullet) writes what PyBullet loads, so each robot is that export, built in memory with
PyBullet's own mass properties (:mod:`urdfkit.engine.mujoco_build`).

How the world is made. MuJoCo compiles one model for the whole world, so :meth:`load` parses a
robot's MJCF into an ``MjSpec`` and attaches it to the world's (``MjSpec.attach``, names
prefixed ``"<body id>/"``); the world is compiled at the first call that needs it, and
recompiled (``MjSpec.recompile``, which carries every joint's state over) when bodies were
added since. Ten loads cost one compile. What is set at run time (motors, friction, masses,
time step, gravity) is kept here and applied again after each compile.

Where it mirrors PyBullet, measured (docs/engines.md):

- **The integrator** is ``Euler``, MuJoCo's semi-implicit Euler, as PyBullet's (a free swing
  agrees with PyBullet's to 1e-16 rad over 2 s), with joint damping integrated implicitly.
  ``implicitfast`` would differ only for actuators, and the world has none: motors are
  constraint rows.
- **Motors** reach their velocity within a step under their force cap, as PyBullet's motor
  rows do, solved with the contacts (:mod:`urdfkit.engine.mujoco_motors`); a position motor
  is PyBullet's POSITION_CONTROL law. Every revolute and prismatic joint starts with
  PyBullet's default motor: velocity 0 under one N m s of impulse per step. A torque acts for
  the next step only (``qfrc_applied``).
- **Contacts** are explicit pairs with PyBullet's combined friction (the product of the two
  lateral coefficients; MuJoCo would take the larger), between every two bodies, and within a
  robot only with ``self_collision``, never a link with its parent; the friction cone is
  elliptic, as PyBullet's is a cone.
- **Indices** are PyBullet's: joints in its depth-first order, link ``i`` the child of joint
  ``i``, -1 the root; a fixed link fused into its parent's body keeps its index and frame.

What cannot be the same (the contact model, the friction cone, the solver, link damping) is
said in docs/engines.md with what it costs on the contract cases.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import replace
from typing import Any

from urdfkit.core.errors import EngineError, MissingDependencyError, ParameterError
from urdfkit.engine.api import (
    BaseState,
    ContactPoint,
    JointInfo,
    JointState,
    LinkDynamics,
    LoadSettings,
    MotorMode,
    Quat,
    Vec3,
)
from urdfkit.engine.mujoco_build import Loaded, Pair
from urdfkit.engine.mujoco_motors import Motor, MotorBank

#: PyBullet's force cap when a motor is set without one (setJointMotorControl2's default).
MOTOR_FORCE = 100000.0
#: PyBullet's default time step and gravity (none until set).
DEFAULT_TIME_STEP = 1.0 / 240.0

#: The changeDynamics names this engine carries, and those it cannot (each with why).
CARRIED = ("mass", "localInertiaDiagonal", "lateralFriction", "spinningFriction",
           "rollingFriction", "jointDamping", "jointLowerLimit", "jointUpperLimit",
           "linearDamping", "angularDamping", "restitution")
NOT_CARRIED = {
    "contactStiffness": "MuJoCo's contacts are soft by its own solref/solimp, not a spring",
    "contactDamping": "MuJoCo's contacts are soft by its own solref/solimp, not a spring",
    "maxJointVelocity": "MuJoCo has no joint velocity cap (PyBullet's is 100 rad/s)",
    "anisotropicFriction": "MuJoCo's friction is the same in every direction of a contact",
    "frictionAnchor": "MuJoCo's friction has no anchor",
    "ccdSweptSphereRadius": "MuJoCo has no continuous collision detection by swept spheres",
    "contactProcessingThreshold": "MuJoCo makes a contact at a geom's margin (0), no sooner",
    "activationState": "MuJoCo's bodies do not sleep",
    "jointLimitForce": "MuJoCo's joint limits are soft constraints without a force cap",
    "collisionMargin": "MuJoCo's geom margins are fixed when the world is compiled",
}
#: The state save() keeps: time, positions, velocities, and the solver's warm start, so that
#: a restored run steps as the first did.
_STATE = "mjSTATE_FULLPHYSICS", "mjSTATE_WARMSTART"


def import_mujoco() -> Any:
    """mujoco, or an error saying how to install it."""
    try:
        import mujoco
    except ImportError as e:
        raise MissingDependencyError("the MuJoCo engine needs MuJoCo: pip install "
                                     "'urdfkit[mujoco]'") from e
    return mujoco


def preload() -> None:
    """Import mujoco now (the registry's :func:`~urdfkit.engine.registry.preload`)."""
    import_mujoco()


class _Body:
    """A loaded robot's ids in the compiled world (remade at every compile)."""

    def __init__(self) -> None:
        self.joints: list[JointInfo] = []
        self.jnt: list[int] = []          # MuJoCo joint id per joint index, -1 fixed
        self.frames: list[tuple[str, int]] = []  # per link (root first): ("body"|"site", id)
        self.bodies: dict[str, int] = {}  # MuJoCo body id per body (by link name)
        self.root = -1                    # the root's MuJoCo body (-1: MuJoCo's world)
        self.free = -1                    # the root's free joint's qpos address (-1: none)


class MuJoCoEngine:
    """One MuJoCo world of robots, behind the seam's :class:`~urdfkit.engine.api.Simulator`.

    Attributes:
        name: ``"mujoco"``.
        notes: Per body, what its export dropped, approximated or defaulted, and what the
            engine left out (one line each).
    """

    name = "mujoco"

    def __init__(self, gui: bool = False) -> None:
        if gui:
            raise ParameterError("`gui`: the MuJoCo engine runs headless here (no viewer)",
                                 param="gui")
        mj = import_mujoco()
        self._mj = mj
        self.notes: dict[int, list[str]] = {}
        self._spec: Any = mj.MjSpec()
        self._spec.modelname = "urdfkit"
        self._spec.option.integrator = mj.mjtIntegrator.mjINT_EULER
        # PyBullet's friction is a cone by default (enableConeFriction); docs/engines.md
        # measures MuJoCo's two against it
        self._spec.option.cone = mj.mjtCone.mjCONE_ELLIPTIC
        # a diverging run shows its NaNs (and step() says so) instead of starting over
        self._spec.option.disableflags |= mj.mjtDisableBit.mjDSBL_AUTORESET
        self._assets: dict[str, bytes] = {}
        self._robots: list[Loaded] = []
        self._ids: list[_Body] = []
        self._pairs: list[Pair] = []
        self._pair_ids: list[int] = []
        self._geom_owner: dict[int, tuple[int, int]] = {}
        self._m: Any = None
        self._d: Any = None
        self._scratch: Any = None
        self._stale = False
        self._compiled_bodies = 0
        self._closed = False
        self._time_step = DEFAULT_TIME_STEP
        self._gravity: Vec3 = (0.0, 0.0, 0.0)
        self._saved: list[tuple[int, Any]] = []
        self._torques: dict[int, float] = {}
        self._bank: MotorBank | None = None
        self._kinematics = False
        self._changed: set[tuple[int, str]] = set()   # (robot, body) with new mass properties
        self._damping: dict[tuple[int, int], float] = {}
        self._limits: dict[tuple[int, int], tuple[float, float]] = {}
        self._root_poses: dict[int, tuple[Vec3, Quat]] = {}   # static roots moved by reset_base

    # ------------------------------------------------------------------ the world

    def load(self, path: str, settings: LoadSettings, display: str | None = None) -> int:
        """Load a guarded URDF: its export attached to the world, compiled when next needed.

        Raises:
            InputError: What MuJoCo refuses (a massless moving link, an impossible inertia),
                naming the link and the ``urdfkit fix`` that repairs it.
            ParameterError: A load setting MuJoCo cannot honour.
        """
        from urdfkit.engine.mujoco_build import pairs, prepare

        self._open()
        mj = self._mj
        r = prepare(mj, path, settings, display)
        index = len(self._robots)
        child = r.spec
        # the world's options are the world's: the same values, so attach has nothing to say
        child.option.integrator = self._spec.option.integrator
        child.option.cone = self._spec.option.cone
        child.option.disableflags = self._spec.option.disableflags
        frame = self._spec.worldbody.add_frame(pos=list(settings.position),
                                               quat=_wxyz(settings.orientation))
        self._spec.attach(child, prefix=f"{index}/", frame=frame)
        self._robots.append(r)
        for p in pairs(self._robots, index):
            friction, condim = self._pair_friction(p)
            self._spec.add_pair(name=f"pair{len(self._pairs)}",
                                geomname1=f"{p.robot_a}/{p.geom_a}",
                                geomname2=f"{p.robot_b}/{p.geom_b}", condim=condim,
                                friction=friction)
            self._pairs.append(p)
        self._assets.update(r.assets)
        self.notes[index] = r.notes
        self._stale = True
        return index

    def set_gravity(self, gravity: Vec3) -> None:
        """The world's gravity, m/s^2."""
        self._open()
        self._gravity = (float(gravity[0]), float(gravity[1]), float(gravity[2]))
        if self._m is not None:
            self._m.opt.gravity[:] = self._gravity

    def set_time_step(self, time_step: float) -> None:
        """The physics step, s (the default motors' caps, one impulse per step, follow it)."""
        self._open()
        if not 0 < time_step <= 1:
            raise ParameterError(f"`time_step` must be in (0, 1], got {time_step!r}",
                                 param="time_step")
        self._time_step = float(time_step)
        if self._m is not None:
            self._m.opt.timestep = self._time_step

    def step(self) -> None:
        """One physics step.

        Raises:
            EngineError: The simulation diverged (MuJoCo found NaN or huge values).
        """
        from urdfkit.formats.mjwarn import mujoco_warnings

        m, d = self._world()
        mj = self._mj
        bank = self._bank
        assert bank is not None
        h = self._time_step
        bank.bound(m, h)
        for dof, torque in self._torques.items():
            d.qfrc_applied[dof] = torque
        bad = _bad_count(mj, d)
        with mujoco_warnings(mj) as said:
            mj.mj_step1(m, d)       # positions, velocities, the constraint rows
            bank.aim(m, d, h)       # each motor row asks for its velocity (mujoco_motors)
            mj.mj_step2(m, d)       # forces, the solver, the integration
        bank.record(m, d)
        for dof in self._torques:
            d.qfrc_applied[dof] = 0.0
        self._torques.clear()
        self._kinematics = False
        if _bad_count(mj, d) != bad:
            raise EngineError("MuJoCo's simulation diverged" + (f": {said[0]}" if said else
                                                                "") + " (a smaller time step, "
                              "or smaller forces, may help)")

    def save(self) -> int:
        """Keep the state now: time, positions, velocities, the solver's warm start.

        The motors' targets are not kept (PyBullet's restoreState keeps the targets set since:
        measured).
        """
        import numpy as np

        m, d = self._world()
        sig = self._state_sig()
        state = np.empty(self._mj.mj_stateSize(m, sig))
        self._mj.mj_getState(m, d, state, sig)
        self._saved.append((len(self._robots), state))
        return len(self._saved) - 1

    def restore(self, state: int) -> None:
        """Back to a saved state, exactly as it was: the next steps are the ones that followed.

        Raises:
            ParameterError: An id :meth:`save` did not give, or a state saved before a body
                was loaded.
        """
        m, d = self._world()
        if not 0 <= state < len(self._saved):
            raise ParameterError(f"`state` {state} was not saved", param="state")
        bodies, saved = self._saved[state]
        if bodies != len(self._robots):
            raise ParameterError(f"`state` {state} was saved with {bodies} bodies; the world "
                                 f"has {len(self._robots)} now", param="state")
        self._mj.mj_setState(m, d, saved, self._state_sig())
        self._torques.clear()
        self._kinematics = False

    def close(self) -> None:
        """Release the world (safe to call twice)."""
        self._closed = True
        self._m = self._d = self._scratch = None
        self._spec = None
        self._robots = []
        self._ids = []

    # ------------------------------------------------------------------ the model

    def joints(self, body: int) -> list[JointInfo]:
        """Every joint of ``body``, fixed ones included, in PyBullet's order."""
        self._world()
        return list(self._body(body)[1].joints)

    def link_names(self, body: int) -> list[str]:
        """Every link's name, the root first, then by index."""
        return [link.name for link in self._body(body)[0].links]

    def dynamics(self, body: int, link: int) -> LinkDynamics:
        """A link's mass properties and contact coefficients now (PyBullet's at load)."""
        return self._body(body)[0].link(link).dynamics

    def set_joint_positions(self, body: int, positions: Sequence[float],
                            velocities: Sequence[float] | None = None) -> None:
        """Put every movable joint (in :meth:`joints` order) at these values."""
        m, d = self._world()
        moving = self._movable(body)
        if len(positions) != len(moving) or (velocities is not None
                                             and len(velocities) != len(moving)):
            raise ParameterError(f"`positions` needs {len(moving)} values, one per movable "
                                 f"joint of body {body}", param="positions")
        for k, j in enumerate(moving):
            d.qpos[j.q_index] = positions[k]
            d.qvel[j.v_index] = velocities[k] if velocities is not None else 0.0
        self._kinematics = False

    def link_frames(self, body: int) -> list[tuple[Vec3, Quat]]:
        """Every link frame's world pose now, the root first (position, quaternion x y z w)."""
        self._fresh_kinematics()
        d = self._d
        _, ids = self._body(body)
        out = []
        for kind, i in ids.frames:
            if kind == "body":
                out.append((_vec(d.xpos[i]), _xyzw(d.xquat[i])))
            else:
                out.append((_vec(d.site_xpos[i]), self._mat_quat(d.site_xmat[i])))
        return out

    def mass_matrix(self, body: int, positions: Sequence[float]) -> list[list[float]]:
        """The joint-space mass matrix at ``positions``: the movable joints' block.

        The rest of the world stays as it is; a floating base's own rows are left out (the
        block is the fixed-base mass matrix).
        """
        import numpy as np

        m, s = self._posed(body, positions, None)
        mj = self._mj
        mj.mj_kinematics(m, s)
        mj.mj_comPos(m, s)
        mj.mj_crb(m, s)
        full = np.zeros((m.nv, m.nv))
        if hasattr(s, "qM"):   # MuJoCo 3: mj_fullM(m, dst, qM)
            mj.mj_fullM(m, full, s.qM)
        else:                  # MuJoCo 4: mj_fullM(m, d, dst)
            mj.mj_fullM(m, s, full)
        dofs = [j.v_index for j in self._movable(body)]
        return full[np.ix_(dofs, dofs)].tolist()

    def inverse_dynamics(self, body: int, positions: Sequence[float],
                         velocities: Sequence[float],
                         accelerations: Sequence[float]) -> list[float]:
        """The joint torques that give ``accelerations`` at this state, gravity included.

        Rigid-body dynamics only, as PyBullet's calculateInverseDynamics: no contact, limit,
        joint damping or motor; a floating base held still.
        """
        m, s = self._posed(body, positions, velocities)
        mj = self._mj
        moving = self._movable(body)
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

    # ------------------------------------------------------------------ state

    def base_state(self, body: int) -> BaseState:
        """The root's inertial frame (PyBullet's base pose) and its velocity, world."""
        from urdfkit.model.spec import quat_mul

        r, ids = self._body(body)
        p0, q0, rot = self._root_frame(ids)
        offset, turn = r.root_offset()
        p = _add(p0, _rotate(rot, offset))
        linear, angular = (0.0, 0.0, 0.0), (0.0, 0.0, 0.0)
        if ids.free >= 0:
            a = int(self._m.jnt_dofadr[self._m.body_jntadr[ids.root]])
            qvel = self._d.qvel
            w = _rotate(rot, (qvel[a + 3], qvel[a + 4], qvel[a + 5]))  # a free joint's: local
            arm = (p[0] - p0[0], p[1] - p0[1], p[2] - p0[2])
            linear = _add((qvel[a], qvel[a + 1], qvel[a + 2]), _cross(w, arm))
            angular = w
        return BaseState(p, quat_mul(q0, turn), linear, angular)

    def _root_frame(self, ids: _Body) -> tuple[Vec3, Quat, Any]:
        """The root link frame now: position, quaternion (x y z w), rotation matrix (3x3)."""
        self._fresh_kinematics()
        d = self._d
        kind, i = ids.frames[0]
        if kind == "body":
            return _vec(d.xpos[i]), _xyzw(d.xquat[i]), d.xmat[i].reshape(3, 3)
        return _vec(d.site_xpos[i]), self._mat_quat(d.site_xmat[i]), d.site_xmat[i].reshape(3, 3)

    def reset_base(self, body: int, position: Vec3, orientation: Quat) -> None:
        """Move the root's inertial frame there, at rest."""
        import numpy as np

        from urdfkit.model.spec import quat_mul, quat_to_matrix

        m, d = self._world()
        r, ids = self._body(body)
        offset, turn = r.root_offset()
        inverse = (-turn[0], -turn[1], -turn[2], turn[3])
        q = quat_mul(_unit(orientation), inverse)
        p = np.array(position, dtype=float) - np.array(quat_to_matrix(q)) @ np.array(offset)
        if ids.free >= 0:
            a = ids.free
            d.qpos[a:a + 3] = p
            d.qpos[a + 3:a + 7] = _wxyz(q)
            v = self._m.jnt_dofadr[self._m.body_jntadr[ids.root]]
            d.qvel[v:v + 6] = 0.0
        elif ids.root >= 0:
            self._root_poses[body] = (_vec(p), q)
            m.body_pos[ids.root] = p
            m.body_quat[ids.root] = _wxyz(q)
        else:
            raise ParameterError(f"body {body}'s root is MuJoCo's world; it cannot move",
                                 param="body")
        self._kinematics = False

    def reset_base_velocity(self, body: int, linear: Vec3, angular: Vec3) -> None:
        """Set the root's velocity: its inertial frame's linear velocity, and the angular."""
        m, d = self._world()
        r, ids = self._body(body)
        if ids.free < 0:
            return  # a fixed base does not move (PyBullet's does not either)
        _, _, rot = self._root_frame(ids)
        arm = _rotate(rot, r.root_offset()[0])   # from the link frame to the inertial frame
        w = (float(angular[0]), float(angular[1]), float(angular[2]))
        cross = _cross(w, arm)
        a = int(m.jnt_dofadr[m.body_jntadr[ids.root]])
        d.qvel[a:a + 3] = (linear[0] - cross[0], linear[1] - cross[1], linear[2] - cross[2])
        d.qvel[a + 3:a + 6] = _rotate(rot.T, w)

    def joint_states(self, body: int, joints: Sequence[int]) -> list[JointState]:
        """The state of these joints now; ``applied``: the motor's force in the last step.

        ``reaction`` is zeros: this engine measures no joint reactions.
        """
        m, d = self._world()
        r, ids = self._body(body)
        out = []
        for j in joints:
            info = self._joint(r, ids, j)
            if info.kind == "fixed":
                out.append(JointState(0.0, 0.0, (0.0,) * 6, 0.0))
                continue
            if info.kind == "spherical":
                raise ParameterError(f"joint {info.name!r} is spherical: joint_states reads "
                                     "joints of one degree of freedom", param="joints")
            out.append(JointState(float(d.qpos[info.q_index]), float(d.qvel[info.v_index]),
                                  (0.0,) * 6, self._applied(info.v_index)))
        return out

    def reset_joint(self, body: int, joint: int, position: float, velocity: float = 0.0
                    ) -> None:
        """Put one joint at a position and velocity (a fixed joint: nothing to do)."""
        m, d = self._world()
        r, ids = self._body(body)
        info = self._joint(r, ids, joint)
        if info.kind == "fixed":
            return
        if info.kind == "spherical":
            raise ParameterError(f"joint {info.name!r} is spherical: reset_joint sets joints "
                                 "of one degree of freedom", param="joint")
        d.qpos[info.q_index] = position
        d.qvel[info.v_index] = velocity
        self._kinematics = False

    # ------------------------------------------------------------------ motors

    def motors(self, body: int, joints: Sequence[int], mode: MotorMode,
               targets: Sequence[float], forces: Sequence[float] | None = None,
               velocities: Sequence[float] | None = None) -> None:
        """Drive joints (see the module).

        To a velocity or a position under a force cap (kept until changed; PyBullet's 100000
        where none is given), or by a torque for the next step only.
        """
        self._world()
        r, ids = self._body(body)
        if len(targets) != len(joints) or (forces is not None and len(forces) != len(joints)) \
                or (velocities is not None and len(velocities) != len(joints)):
            raise ParameterError("`targets`, `forces` and `velocities` need one value per "
                                 "joint", param="targets")
        if mode not in ("velocity", "position", "torque"):
            raise ParameterError(f"`mode` must be velocity, position or torque, got {mode!r}",
                                 param="mode")
        for k, j in enumerate(joints):
            info = self._joint(r, ids, j)
            if j not in r.motors:
                raise ParameterError(f"joint {info.name!r} is {info.kind}: it has no motor",
                                     param="joints")
            if mode == "torque":
                self._torques[info.v_index] = float(targets[k])
                continue
            force = MOTOR_FORCE if forces is None else float(forces[k])
            if not force >= 0:
                raise ParameterError(f"`forces` must be >= 0, got {force!r}", param="forces")
            r.motors[j] = Motor(mode, float(targets[k]),
                                float(velocities[k]) if velocities is not None else 0.0, force)
            assert self._bank is not None
            self._bank.set(info.v_index, r.motors[j])

    def change_dynamics(self, body: int, link: int, **values: float | Sequence[float]
                        ) -> None:
        """Change a link's dynamics by PyBullet's ``changeDynamics`` names (see :data:`CARRIED`).

        Raises:
            ParameterError: A name MuJoCo cannot carry (:data:`NOT_CARRIED` says why), or not
                one of PyBullet's, or a value that leaves a moving body without mass.
        """
        self._world()
        r, ids = self._body(body)
        target = r.link(link)
        for key, value in values.items():
            self._check_dynamics(key, value)
            if key.startswith("joint") and link < 0:
                raise ParameterError(f"`{key}`: link -1 is the root, which has no joint",
                                     param=key)
        d = target.dynamics
        changes: dict[str, Any] = {}
        for key, value in values.items():
            if key == "mass":
                changes["mass"] = float(value)  # type: ignore[arg-type]
            elif key == "localInertiaDiagonal":
                v = list(value)  # type: ignore[arg-type]
                changes["inertia"] = (float(v[0]), float(v[1]), float(v[2]))
            elif key in ("lateralFriction", "spinningFriction", "rollingFriction"):
                field = {"lateralFriction": "lateral_friction",
                         "spinningFriction": "spinning_friction",
                         "rollingFriction": "rolling_friction"}[key]
                changes[field] = float(value)  # type: ignore[arg-type]
            elif key == "jointDamping":
                self._damping[(body, link)] = float(value)  # type: ignore[arg-type]
            elif key in ("jointLowerLimit", "jointUpperLimit"):
                lo, hi = self._limits.get((body, link), (ids.joints[link].lower,
                                                         ids.joints[link].upper))
                new = float(value)  # type: ignore[arg-type]
                self._limits[(body, link)] = (new, hi) if key == "jointLowerLimit" else (lo, new)
        old = d
        target.dynamics = replace(d, **changes)
        if "mass" in changes or "inertia" in changes:
            try:
                self._changed.add((body, target.body))
                self._apply_mass(body, target.body)
            except ParameterError:
                target.dynamics = old
                self._apply_mass(body, target.body)
                raise
        self._apply_joints()
        self._apply_pairs()

    # ------------------------------------------------------------------ contacts

    def contacts(self, body: int, link: int | None = None, other: int | None = None
                 ) -> list[ContactPoint]:
        """The contact points of the last step: ``body`` (one link, or all) with ``other``.

        A is ``body``; the normal points from B to A and the normal force pushes A off B.
        """
        import numpy as np

        m, d = self._world()
        self._body(body)
        mj = self._mj
        owner = self._geom_owner
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
                position_a=_vec(p2 if flip else p1), position_b=_vec(p1 if flip else p2),
                normal=_vec(sign * n), distance=float(c.dist), normal_force=float(f[0]),
                friction1=float(f[1]), direction1=_vec(-sign * frame[1]),
                friction2=float(f[2]), direction2=_vec(-sign * frame[2])))
        return out

    # ------------------------------------------------------------------ inside

    def _open(self) -> None:
        if self._closed:
            raise EngineError("the MuJoCo engine is closed")

    def _world(self) -> tuple[Any, Any]:
        """The compiled world, compiled or recompiled first if bodies were added."""
        self._open()
        if self._stale or self._m is None:
            self._compile()
        return self._m, self._d

    def _compile(self) -> None:
        import warnings

        from urdfkit.formats.mjwarn import mujoco_warnings

        mj = self._mj
        self._spec.assets = self._assets
        new = [r.display for r in self._robots[self._compiled_bodies:]]
        try:
            with warnings.catch_warnings(), mujoco_warnings(mj):
                warnings.simplefilter("ignore")
                if self._m is None:
                    self._m = self._spec.compile()
                    self._d = mj.MjData(self._m)
                else:
                    self._m, self._d = self._spec.recompile(self._m, self._d)
        except (ValueError, RuntimeError) as e:
            first = str(e).strip().splitlines()[0] if str(e).strip() else type(e).__name__
            raise EngineError(f"MuJoCo cannot compile the world with {', '.join(new)}: "
                              f"{first}") from None
        self._compiled_bodies = len(self._robots)
        self._stale = False
        self._scratch = mj.MjData(self._m)
        self._kinematics = False
        # the motors' forces in the last step, by joint: the ids are remade below
        applied = {(body, j): self._applied(info.v_index)
                   for body, ids in enumerate(self._ids) for j, info in enumerate(ids.joints)
                   if info.v_index >= 0}
        self._index()
        self._apply_all()
        assert self._bank is not None
        for (body, j), force in applied.items():
            self._bank.applied[self._ids[body].joints[j].v_index] = force

    def _index(self) -> None:
        """Every robot's ids in the compiled world, and each geom's robot and link."""
        m, mj = self._m, self._mj
        self._ids = []
        self._geom_owner = {}
        for index, r in enumerate(self._robots):
            ids = _Body()
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
                ids.joints.append(self._joint_info(r, i, jid, link_index))
            for g, owner in r.geom_links.items():
                self._geom_owner[m.geom(prefix + g).id] = (index, link_index[owner])
            self._ids.append(ids)
        self._pair_ids = [m.pair(f"pair{k}").id for k in range(len(self._pairs))]

    def _joint_info(self, r: Loaded, i: int, jid: int, link_index: dict[str, int]
                    ) -> JointInfo:
        from urdfkit.formats.fk import unit

        j = r.robot.joints[i]
        kind = {"continuous": "revolute", "revolute": "revolute", "prismatic": "prismatic",
                "spherical": "spherical"}.get(j.type, "fixed")
        m = self._m
        return JointInfo(
            index=i, name=j.name, kind=kind,  # type: ignore[arg-type]
            q_index=int(m.jnt_qposadr[jid]) if jid >= 0 else -1,
            v_index=int(m.jnt_dofadr[jid]) if jid >= 0 else -1,
            damping=j.damping, friction=j.friction, lower=j.lower, upper=j.upper,
            limited=j.limited, effort=j.effort, velocity=j.velocity, link=j.child,
            axis=unit(j.axis) if j.moves and j.type != "spherical" else (0.0, 0.0, 0.0),
            parent=link_index[j.parent])

    def _apply_all(self) -> None:
        """What is set at run time, again on a newly compiled world."""
        m = self._m
        m.opt.timestep = self._time_step
        m.opt.gravity[:] = self._gravity
        for body, (p, q) in self._root_poses.items():
            root = self._ids[body].root
            m.body_pos[root] = p
            m.body_quat[root] = _wxyz(q)
        for body, name in sorted(self._changed):
            self._apply_mass(body, name, set_const=False)
        if self._changed:
            self._set_const()
        self._apply_joints()
        self._apply_pairs()
        self._build_bank()

    def _build_bank(self) -> None:
        """Every motor as its joint's constraint row (see :mod:`urdfkit.engine.mujoco_motors`)."""
        import numpy as np

        bank = MotorBank(np, self._m.nv, int(self._mj.mjtConstraint.mjCNSTR_FRICTION_DOF))
        for r, ids in zip(self._robots, self._ids, strict=True):
            for j, motor in r.motors.items():
                info = ids.joints[j]
                bank.place(info.v_index, info.q_index, motor)
        self._bank = bank

    def _applied(self, dof: int) -> float:
        """The force a joint's motor applied in the last step."""
        return 0.0 if self._bank is None else float(self._bank.applied[dof])

    def _apply_joints(self) -> None:
        """Joint damping and limits changed at run time, in the model and in :meth:`joints`."""
        m = self._m
        for (body, j), value in self._damping.items():
            ids = self._ids[body]
            if ids.jnt[j] >= 0:
                m.dof_damping[ids.joints[j].v_index] = value
            ids.joints[j] = replace(ids.joints[j], damping=value)
        for (body, j), (lo, hi) in self._limits.items():
            ids = self._ids[body]
            if ids.jnt[j] >= 0:
                m.jnt_range[ids.jnt[j]] = (lo, hi)
                m.jnt_limited[ids.jnt[j]] = lo <= hi
            ids.joints[j] = replace(ids.joints[j], lower=lo, upper=hi, limited=lo <= hi)

    def _pair_friction(self, p: Pair) -> tuple[list[float], int]:
        from urdfkit.engine.mujoco_build import combined_friction

        def dyn(robot: int, link: str) -> LinkDynamics:
            return next(x.dynamics for x in self._robots[robot].links if x.name == link)

        return combined_friction(dyn(p.robot_a, p.link_a), dyn(p.robot_b, p.link_b))

    def _apply_pairs(self) -> None:
        m = self._m
        for p, pid in zip(self._pairs, self._pair_ids, strict=True):
            friction, condim = self._pair_friction(p)
            m.pair_friction[pid] = friction
            m.pair_dim[pid] = condim

    def _apply_mass(self, body: int, name: str, set_const: bool = True) -> None:
        """A MuJoCo body's mass properties again, from the links fused into it.

        Raises:
            ParameterError: The body moves and would be left without mass or inertia.
        """
        import numpy as np

        from urdfkit.engine.inertials import link_tensor
        from urdfkit.formats.mjcf import combine
        from urdfkit.formats.robot import Inertial

        r, ids = self._robots[body], self._ids[body]
        parts = [(Inertial(x.dynamics.mass, x.dynamics.inertial_position,
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
        m = self._m
        m.body_mass[b] = total.mass
        m.body_ipos[b] = total.com
        m.body_inertia[b] = moments
        quat = np.zeros(4)
        self._mj.mju_mat2Quat(quat, axes.flatten())
        m.body_iquat[b] = quat
        if set_const:
            self._set_const()

    def _set_const(self) -> None:
        """The model's derived constants (dof_M0, subtree masses) after a mass changed.

        On the scratch data: mj_setConst poses its data at qpos0.
        """
        self._mj.mj_setConst(self._m, self._scratch)

    def _check_dynamics(self, key: str, value: float | Sequence[float]) -> None:
        if key in NOT_CARRIED:
            raise ParameterError(f"`{key}`: {NOT_CARRIED[key]}", param=key)
        if key not in CARRIED:
            from urdfkit.core.suggest import hint

            raise ParameterError(f"`{key}` is not a changeDynamics name"
                                 f"{hint(key, (*CARRIED, *NOT_CARRIED))}", param=key)
        if key in ("linearDamping", "angularDamping") and value != 0:
            raise ParameterError(f"`{key}` {value!r}: MuJoCo has no per-body velocity damping "
                                 "(0 is what it does; PyBullet's default is 0.04)", param=key)
        if key == "restitution" and value != 0:
            raise ParameterError(f"`restitution` {value!r}: MuJoCo's contacts do not bounce by "
                                 "a coefficient (0 is what it does)", param=key)
        if key == "localInertiaDiagonal":
            if isinstance(value, (int, float)) or len(value) != 3:
                raise ParameterError("`localInertiaDiagonal` needs 3 values", param=key)
            if not all(math.isfinite(x) and x >= 0 for x in value):
                raise ParameterError(f"`localInertiaDiagonal` must be >= 0, got {value!r}",
                                     param=key)
        elif not isinstance(value, (int, float)) or not math.isfinite(value):
            raise ParameterError(f"`{key}` must be a number, got {value!r}", param=key)
        elif key in ("mass", "lateralFriction", "spinningFriction", "rollingFriction",
                     "jointDamping") and value < 0:
            raise ParameterError(f"`{key}` must be >= 0, got {value!r}", param=key)

    def _posed(self, body: int, positions: Sequence[float],
               velocities: Sequence[float] | None) -> tuple[Any, Any]:
        """The scratch data: the world as it is, this body's joints at ``positions``."""
        m, d = self._world()
        s = self._scratch
        moving = self._movable(body)
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

    def _movable(self, body: int) -> list[JointInfo]:
        """The joints of one degree of freedom, in order (spherical ones refused)."""
        self._world()
        joints = self._body(body)[1].joints
        ball = [j.name for j in joints if j.kind == "spherical"]
        if ball:
            raise ParameterError(f"body {body} has spherical joints ({', '.join(ball)}): this "
                                 "call takes joints of one degree of freedom", param="body")
        return [j for j in joints if j.kind != "fixed"]

    def _body(self, body: int) -> tuple[Loaded, _Body]:
        self._world()
        if not 0 <= body < len(self._robots):
            raise ParameterError(f"`body` {body} is not loaded (bodies 0 to "
                                 f"{len(self._robots) - 1})", param="body")
        return self._robots[body], self._ids[body]

    def _joint(self, r: Loaded, ids: _Body, joint: int) -> JointInfo:
        if not 0 <= joint < len(ids.joints):
            raise ParameterError(f"`joint` {joint} is not a joint of {r.display} (it has 0 to "
                                 f"{len(ids.joints) - 1})", param="joint")
        return ids.joints[joint]

    def _fresh_kinematics(self) -> None:
        m, d = self._world()
        if not self._kinematics:
            self._mj.mj_kinematics(m, d)
            self._kinematics = True

    def _mat_quat(self, mat: Any) -> Quat:
        import numpy as np

        q = np.zeros(4)
        self._mj.mju_mat2Quat(q, mat)
        return _xyzw(q)

    def _state_sig(self) -> int:
        flags = self._mj.mjtState
        return int(getattr(flags, _STATE[0])) | int(getattr(flags, _STATE[1]))


def _bad_count(mj: Any, d: Any) -> int:
    """How often MuJoCo has found NaN or huge values (positions, velocities, accelerations)."""
    w = mj.mjtWarning
    warning = d.warning
    return int(warning[int(w.mjWARN_BADQACC)].number + warning[int(w.mjWARN_BADQVEL)].number
               + warning[int(w.mjWARN_BADQPOS)].number)


def _rotate(rot: Any, v: Sequence[float]) -> Vec3:
    return (float(rot[0][0] * v[0] + rot[0][1] * v[1] + rot[0][2] * v[2]),
            float(rot[1][0] * v[0] + rot[1][1] * v[1] + rot[1][2] * v[2]),
            float(rot[2][0] * v[0] + rot[2][1] * v[1] + rot[2][2] * v[2]))


def _add(a: Sequence[float], b: Sequence[float]) -> Vec3:
    return (float(a[0] + b[0]), float(a[1] + b[1]), float(a[2] + b[2]))


def _cross(a: Sequence[float], b: Sequence[float]) -> Vec3:
    return (a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0])


def _vec(v: Any) -> Vec3:
    return (float(v[0]), float(v[1]), float(v[2]))


def _xyzw(q: Any) -> Quat:
    """MuJoCo's (w, x, y, z) as the seam's (x, y, z, w)."""
    return (float(q[1]), float(q[2]), float(q[3]), float(q[0]))


def _wxyz(q: Sequence[float]) -> list[float]:
    """The seam's (x, y, z, w) as MuJoCo's (w, x, y, z)."""
    return [float(q[3]), float(q[0]), float(q[1]), float(q[2])]


def _unit(q: Sequence[float]) -> Quat:
    n = math.sqrt(sum(x * x for x in q))
    if not n > 0 or not math.isfinite(n):
        raise ParameterError(f"`orientation` {tuple(q)!r} is not a rotation", param="orientation")
    return (q[0] / n, q[1] / n, q[2] / n, q[3] / n)
