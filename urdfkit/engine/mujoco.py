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

from collections.abc import Sequence
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
from urdfkit.engine.mujoco_motors import Motor
from urdfkit.engine.mujoco_world import (
    World,
    add,
    bad_count,
    cross,
    rotate,
    unit_quat,
    vec3,
    wxyz,
    xyzw,
)

#: PyBullet's force cap when a motor is set without one (setJointMotorControl2's default).
MOTOR_FORCE = 100000.0


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


class MuJoCoEngine:
    """One MuJoCo world of robots, behind the seam's :class:`~urdfkit.engine.api.Simulator`.

    A facade over its :class:`~urdfkit.engine.mujoco_world.World` (the model, the data, what
    was set at run time), :mod:`~urdfkit.engine.mujoco_query` (contacts, mass matrix,
    inverse dynamics) and :mod:`~urdfkit.engine.mujoco_dynamics` (changeDynamics).

    Attributes:
        name: ``"mujoco"``.
        world: The world.
        notes: Per body, what its export dropped, approximated or defaulted, and what the
            engine left out (one line each).
    """

    name = "mujoco"

    def __init__(self, gui: bool = False) -> None:
        if gui:
            raise ParameterError("`gui`: the MuJoCo engine runs headless here (no viewer)",
                                 param="gui")
        self.world = World(import_mujoco())
        self.notes = self.world.notes

    def load(self, path: str, settings: LoadSettings, display: str | None = None) -> int:
        """Load a guarded URDF: its export attached to the world, compiled when next needed.

        Raises:
            InputError: What MuJoCo refuses (a massless moving link, an impossible inertia),
                naming the link and the ``urdfkit fix`` that repairs it.
            ParameterError: A load setting MuJoCo cannot honour.
        """
        from urdfkit.engine.mujoco_build import prepare

        self.world.open()
        return self.world.add(prepare(self.world.mj, path, settings, display), settings)

    def set_gravity(self, gravity: Vec3) -> None:
        """The world's gravity, m/s^2."""
        w = self.world
        w.open()
        w.gravity = (float(gravity[0]), float(gravity[1]), float(gravity[2]))
        if w.m is not None:
            w.m.opt.gravity[:] = w.gravity

    def set_time_step(self, time_step: float) -> None:
        """The physics step, s (the default motors' caps, one impulse per step, follow it)."""
        w = self.world
        w.open()
        if not 0 < time_step <= 1:
            raise ParameterError(f"`time_step` must be in (0, 1], got {time_step!r}",
                                 param="time_step")
        w.time_step = float(time_step)
        if w.m is not None:
            w.m.opt.timestep = w.time_step

    def set_physics(self, *, deterministic_pairs: bool | None = None,
                    solver_iterations: int | None = None,
                    cone_friction: bool | None = None) -> None:
        """The solver's settings, PyBullet's names; None leaves one as it is.

        ``deterministic_pairs`` is what MuJoCo always does (a run replays exactly);
        ``cone_friction`` False is MuJoCo's pyramid, True its elliptic cone (the default).

        Raises:
            ParameterError: ``solver_iterations``: MuJoCo solves each step to a tolerance by
                Newton's method, where PyBullet's iteration count has no meaning.
        """
        w = self.world
        w.open()
        if solver_iterations is not None:
            raise ParameterError(f"`solver_iterations` {solver_iterations!r}: MuJoCo solves "
                                 "each step's constraints to a tolerance (Newton's method); "
                                 "PyBullet's iteration count has no meaning there",
                                 param="solver_iterations")
        if cone_friction is not None:
            cones = w.mj.mjtCone
            w.spec.option.cone = cones.mjCONE_ELLIPTIC if cone_friction else \
                cones.mjCONE_PYRAMIDAL
            if w.m is not None:
                w.m.opt.cone = w.spec.option.cone

    def step(self) -> None:
        """One physics step.

        Raises:
            EngineError: The simulation diverged (MuJoCo found NaN or huge values).
        """
        from urdfkit.formats.mjwarn import mujoco_warnings

        w = self.world
        m, d = w.compiled()
        mj = w.mj
        bank = w.bank
        assert bank is not None
        h = w.time_step
        bank.bound(m, h)
        for dof, torque in w.torques.items():
            d.qfrc_applied[dof] = torque
        bad = bad_count(mj, d)
        with mujoco_warnings(mj) as said:
            mj.mj_step1(m, d)       # positions, velocities, the constraint rows
            bank.aim(m, d, h)       # each motor row asks for its velocity (mujoco_motors)
            mj.mj_step2(m, d)       # forces, the solver, the integration
        bank.record(m, d)
        for dof in w.torques:
            d.qfrc_applied[dof] = 0.0
        w.torques.clear()
        w.kinematics = False
        if bad_count(mj, d) != bad:
            raise EngineError("MuJoCo's simulation diverged" + (f": {said[0]}" if said else
                                                                "") + " (a smaller time step, "
                              "or smaller forces, may help)")

    def save(self) -> int:
        """Keep the state now: time, positions, velocities, the solver's warm start.

        The motors' targets are not kept (PyBullet's restoreState keeps the targets set since:
        measured).
        """
        import numpy as np

        w = self.world
        m, d = w.compiled()
        sig = w.state_sig()
        state = np.empty(w.mj.mj_stateSize(m, sig))
        w.mj.mj_getState(m, d, state, sig)
        w.saved.append((len(w.robots), state))
        return len(w.saved) - 1

    def restore(self, state: int) -> None:
        """Back to a saved state, exactly as it was: the next steps are the ones that followed.

        Raises:
            ParameterError: An id :meth:`save` did not give, or a state saved before a body
                was loaded.
        """
        w = self.world
        m, d = w.compiled()
        if not 0 <= state < len(w.saved):
            raise ParameterError(f"`state` {state} was not saved", param="state")
        bodies, saved = w.saved[state]
        if bodies != len(w.robots):
            raise ParameterError(f"`state` {state} was saved with {bodies} bodies; the world "
                                 f"has {len(w.robots)} now", param="state")
        w.mj.mj_setState(m, d, saved, w.state_sig())
        w.torques.clear()
        w.kinematics = False

    def close(self) -> None:
        """Release the world (safe to call twice)."""
        w = self.world
        w.closed = True
        w.m = w.d = w.scratch = None
        w.spec = None
        w.robots = []
        w.ids = []

    def joints(self, body: int) -> list[JointInfo]:
        """Every joint of ``body``, fixed ones included, in PyBullet's order."""
        return list(self.world.body(body)[1].joints)

    def link_names(self, body: int) -> list[str]:
        """Every link's name, the root first, then by index."""
        return [link.name for link in self.world.body(body)[0].links]

    def dynamics(self, body: int, link: int) -> LinkDynamics:
        """A link's mass properties and contact coefficients now (PyBullet's at load)."""
        return self.world.body(body)[0].link(link).dynamics

    def set_joint_positions(self, body: int, positions: Sequence[float],
                            velocities: Sequence[float] | None = None) -> None:
        """Put every movable joint (in :meth:`joints` order) at these values."""
        w = self.world
        m, d = w.compiled()
        moving = w.movable(body)
        if len(positions) != len(moving) or (velocities is not None
                                             and len(velocities) != len(moving)):
            raise ParameterError(f"`positions` needs {len(moving)} values, one per movable "
                                 f"joint of body {body}", param="positions")
        for k, j in enumerate(moving):
            d.qpos[j.q_index] = positions[k]
            d.qvel[j.v_index] = velocities[k] if velocities is not None else 0.0
        w.kinematics = False

    def link_frames(self, body: int) -> list[tuple[Vec3, Quat]]:
        """Every link frame's world pose now, the root first (position, quaternion x y z w)."""
        w = self.world
        w.fresh_kinematics()
        d = w.d
        _, ids = w.body(body)
        out = []
        for kind, i in ids.frames:
            if kind == "body":
                out.append((vec3(d.xpos[i]), xyzw(d.xquat[i])))
            else:
                out.append((vec3(d.site_xpos[i]), w.mat_quat(d.site_xmat[i])))
        return out

    def base_state(self, body: int) -> BaseState:
        """The root's inertial frame (PyBullet's base pose) and its velocity, world."""
        from urdfkit.model.spec import quat_mul

        w = self.world
        r, ids = w.body(body)
        p0, q0, rot = w.root_frame(ids)
        offset, turn = r.root_offset()
        p = add(p0, rotate(rot, offset))
        linear, angular = (0.0, 0.0, 0.0), (0.0, 0.0, 0.0)
        if ids.free >= 0:
            a = int(w.m.jnt_dofadr[w.m.body_jntadr[ids.root]])
            qvel = w.d.qvel
            spin = rotate(rot, (qvel[a + 3], qvel[a + 4], qvel[a + 5]))  # a free joint's: local
            arm = (p[0] - p0[0], p[1] - p0[1], p[2] - p0[2])
            linear = add((qvel[a], qvel[a + 1], qvel[a + 2]), cross(spin, arm))
            angular = spin
        return BaseState(p, quat_mul(q0, turn), linear, angular)

    def reset_base(self, body: int, position: Vec3, orientation: Quat) -> None:
        """Move the root's inertial frame there, at rest."""
        import numpy as np

        from urdfkit.model.spec import quat_mul, quat_to_matrix

        w = self.world
        m, d = w.compiled()
        r, ids = w.body(body)
        offset, turn = r.root_offset()
        inverse = (-turn[0], -turn[1], -turn[2], turn[3])
        q = quat_mul(unit_quat(orientation), inverse)
        p = np.array(position, dtype=float) - np.array(quat_to_matrix(q)) @ np.array(offset)
        if ids.free >= 0:
            a = ids.free
            d.qpos[a:a + 3] = p
            d.qpos[a + 3:a + 7] = wxyz(q)
            v = w.m.jnt_dofadr[w.m.body_jntadr[ids.root]]
            d.qvel[v:v + 6] = 0.0
        elif ids.root >= 0:
            w.root_poses[body] = (vec3(p), q)
            m.body_pos[ids.root] = p
            m.body_quat[ids.root] = wxyz(q)
        else:
            raise ParameterError(f"body {body}'s root is MuJoCo's world; it cannot move",
                                 param="body")
        w.kinematics = False

    def reset_base_velocity(self, body: int, linear: Vec3, angular: Vec3) -> None:
        """Set the root's velocity: its inertial frame's linear velocity, and the angular."""
        w = self.world
        m, d = w.compiled()
        r, ids = w.body(body)
        if ids.free < 0:
            return  # a fixed base does not move (PyBullet's does not either)
        _, _, rot = w.root_frame(ids)
        arm = rotate(rot, r.root_offset()[0])   # from the link frame to the inertial frame
        spin = (float(angular[0]), float(angular[1]), float(angular[2]))
        swing = cross(spin, arm)
        a = int(m.jnt_dofadr[m.body_jntadr[ids.root]])
        d.qvel[a:a + 3] = (linear[0] - swing[0], linear[1] - swing[1], linear[2] - swing[2])
        d.qvel[a + 3:a + 6] = rotate(rot.T, spin)

    def joint_states(self, body: int, joints: Sequence[int]) -> list[JointState]:
        """The state of these joints now; ``applied``: the motor's force in the last step.

        ``reaction`` is zeros: this engine measures no joint reactions.
        """
        w = self.world
        m, d = w.compiled()
        r, ids = w.body(body)
        out = []
        for j in joints:
            info = w.joint(r, ids, j)
            if info.kind == "fixed":
                out.append(JointState(0.0, 0.0, (0.0,) * 6, 0.0))
                continue
            if info.kind == "spherical":
                raise ParameterError(f"joint {info.name!r} is spherical: joint_states reads "
                                     "joints of one degree of freedom", param="joints")
            out.append(JointState(float(d.qpos[info.q_index]), float(d.qvel[info.v_index]),
                                  (0.0,) * 6, w.applied(info.v_index)))
        return out

    def reset_joint(self, body: int, joint: int, position: float, velocity: float = 0.0
                    ) -> None:
        """Put one joint at a position and velocity (a fixed joint: nothing to do)."""
        w = self.world
        m, d = w.compiled()
        r, ids = w.body(body)
        info = w.joint(r, ids, joint)
        if info.kind == "fixed":
            return
        if info.kind == "spherical":
            raise ParameterError(f"joint {info.name!r} is spherical: reset_joint sets joints "
                                 "of one degree of freedom", param="joint")
        d.qpos[info.q_index] = position
        d.qvel[info.v_index] = velocity
        w.kinematics = False

    def motors(self, body: int, joints: Sequence[int], mode: MotorMode,
               targets: Sequence[float], forces: Sequence[float] | None = None,
               velocities: Sequence[float] | None = None) -> None:
        """Drive joints (see the module).

        To a velocity or a position under a force cap (kept until changed; PyBullet's 100000
        where none is given), or by a torque for the next step only.
        """
        w = self.world
        w.compiled()
        r, ids = w.body(body)
        if len(targets) != len(joints) or (forces is not None and len(forces) != len(joints)) \
                or (velocities is not None and len(velocities) != len(joints)):
            raise ParameterError("`targets`, `forces` and `velocities` need one value per "
                                 "joint", param="targets")
        if mode not in ("velocity", "position", "torque"):
            raise ParameterError(f"`mode` must be velocity, position or torque, got {mode!r}",
                                 param="mode")
        for k, j in enumerate(joints):
            info = w.joint(r, ids, j)
            if j not in r.motors:
                raise ParameterError(f"joint {info.name!r} is {info.kind}: it has no motor",
                                     param="joints")
            if mode == "torque":
                w.torques[info.v_index] = float(targets[k])
                continue
            force = MOTOR_FORCE if forces is None else float(forces[k])
            if not force >= 0:
                raise ParameterError(f"`forces` must be >= 0, got {force!r}", param="forces")
            r.motors[j] = Motor(mode, float(targets[k]),
                                float(velocities[k]) if velocities is not None else 0.0, force)
            assert w.bank is not None
            w.bank.set(info.v_index, r.motors[j])

    def mass_matrix(self, body: int, positions: Sequence[float]) -> list[list[float]]:
        """The joint-space mass matrix at ``positions``: the movable joints' block."""
        from urdfkit.engine.mujoco_query import mass_matrix

        return mass_matrix(self.world, body, positions)

    def inverse_dynamics(self, body: int, positions: Sequence[float],
                         velocities: Sequence[float],
                         accelerations: Sequence[float]) -> list[float]:
        """The joint torques that give ``accelerations`` at this state, gravity included."""
        from urdfkit.engine.mujoco_query import inverse_dynamics

        return inverse_dynamics(self.world, body, positions, velocities, accelerations)

    def change_dynamics(self, body: int, link: int, **values: float | Sequence[float]
                        ) -> None:
        """Change a link's dynamics by PyBullet's ``changeDynamics`` names.

        Raises:
            ParameterError: A name MuJoCo cannot carry, or not one of PyBullet's, or a value
                that leaves a moving body without mass (:mod:`urdfkit.engine.mujoco_dynamics`).
        """
        from urdfkit.engine.mujoco_dynamics import change_dynamics

        change_dynamics(self.world, body, link, values)

    def contacts(self, body: int, link: int | None = None, other: int | None = None
                 ) -> list[ContactPoint]:
        """The contact points of the last step: ``body`` (one link, or all) with ``other``.

        A is ``body``; the normal points from B to A and the normal force pushes A off B.
        """
        from urdfkit.engine.mujoco_query import contacts

        return contacts(self.world, body, link, other)
