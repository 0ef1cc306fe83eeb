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

- **The rest of the seam** is each in a part: frames, resets and joint states
  (:mod:`~urdfkit.engine.mujoco_bodies`), closest points, Jacobians and mass matrices in
  PyBullet's coordinates (:mod:`~urdfkit.engine.mujoco_query`), collision shapes and boxes
  (:mod:`~urdfkit.engine.mujoco_shapes`), a held base and geared joints as equalities
  (:mod:`~urdfkit.engine.mujoco_constraints`), PyBullet's joint force/torque sensor
  (:mod:`~urdfkit.engine.mujoco_reactions`).

What cannot be the same (the contact model, the friction cone, the solver, link damping, an
uncapped coupling) is said in docs/engines.md with what it costs on the contract cases.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import TYPE_CHECKING, Any

from urdfkit.core.errors import EngineError, MissingDependencyError, ParameterError
from urdfkit.engine import mujoco_bodies as bodies
from urdfkit.engine.api import (
    BaseState,
    Camera,
    CollisionShape,
    ContactPoint,
    JointInfo,
    JointRow,
    JointState,
    Light,
    LinkDynamics,
    LinkPose,
    LoadSettings,
    MotorMode,
    Picture,
    Quat,
    Vec3,
    VisualShape,
)
from urdfkit.engine.mujoco_motors import Motor
from urdfkit.engine.mujoco_world import World, bad_count
from urdfkit.formats.mjwarn import listen, stop_listening

#: PyBullet's force cap when a motor is set without one (setJointMotorControl2's default).
MOTOR_FORCE = 100000.0


def import_mujoco() -> Any:
    """mujoco, or an error saying how to install it."""
    import os
    import sys

    if sys.platform.startswith("linux") and "MUJOCO_GL" not in os.environ \
            and not os.environ.get("DISPLAY"):
        os.environ["MUJOCO_GL"] = "egl"  # headless: pictures through EGL (mujoco_render)
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
    label = "MuJoCo"
    #: No window of its own: the engine runs headless.
    gui = False
    #: What its calls raise when it fails (a closed world, a diverged run).
    error: type[Exception] = EngineError

    def __init__(self, gui: bool = False) -> None:
        if gui:
            raise ParameterError("`gui`: the MuJoCo engine runs headless here (no viewer)",
                                 param="gui")
        self.world = World(import_mujoco())
        self.notes = self.world.notes
        self._renderers: dict[tuple[int, int, int], Any] = {}
        #: What MuJoCo warns while this engine is open, one line each (cleared every step).
        self._said = listen(self.world.mj)

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

    def require_state_queries(self, body: int, display: str) -> None:
        """Nothing to refuse: MuJoCo reports the state of a body of any size.

        (PyBullet cannot past 127 links.) An unknown body is a ParameterError.
        """
        self.world.body(body)

    def connected(self) -> bool:
        """Whether the world is still open (it has no window to be closed)."""
        return not self.world.closed

    def step(self) -> None:
        """One physics step.

        Raises:
            EngineError: The simulation diverged (MuJoCo found NaN or huge values).
        """
        w = self.world
        m, d = w.compiled()
        mj = w.mj
        bank = w.bank
        assert bank is not None
        h = w.time_step
        bank.bound(m, h)
        if w.torques:
            for dof, torque in w.torques.items():
                d.qfrc_applied[dof] = torque
        said = self._said
        said.clear()
        mj.mj_step1(m, d)       # positions, velocities, the constraint rows
        bank.aim(m, d, h)       # each motor row asks for its velocity (mujoco_motors)
        if w.sensors:           # joint force/torque sensors: at the step's start state
            from urdfkit.engine.mujoco_reactions import measure

            before = d.qvel.copy()
            mj.mj_step2(m, d)
            measure(w, m, d, before)
        else:
            mj.mj_step2(m, d)   # forces, the solver, the integration
        bank.record(m, d)
        if w.torques:
            for dof in w.torques:
                d.qfrc_applied[dof] = 0.0
            w.torques.clear()
        w.kinematics = False
        bad = bad_count(mj, d)
        if bad != w.bad:
            w.bad = bad
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
        if not w.closed:
            stop_listening(w.mj)
        w.closed = True
        for renderer in self._renderers.values():
            renderer.close()
        self._renderers.clear()
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
        bodies.set_joint_positions(self.world, body, positions, velocities)

    def link_frames(self, body: int) -> list[tuple[Vec3, Quat]]:
        """Every link frame's world pose now, the root first (position, quaternion x y z w)."""
        return bodies.link_frames(self.world, body)

    def link_frame(self, body: int, link: int) -> tuple[Vec3, Quat]:
        """One link's URDF frame now, world (link -1: the root)."""
        return bodies.link_frame(self.world, body, link)

    def link_pose(self, body: int, link: int) -> LinkPose:
        """One link's inertial and URDF frames now, world (link -1: the root)."""
        return bodies.link_pose(self.world, body, link)

    def base_state(self, body: int) -> BaseState:
        """The root's inertial frame (PyBullet's base pose) and its velocity, world."""
        return bodies.base_state(self.world, body)

    def base_pose(self, body: int) -> tuple[Vec3, Quat]:
        """The root's inertial frame (PyBullet's base pose), world."""
        return bodies.base_pose(self.world, body)

    def reset_base(self, body: int, position: Vec3, orientation: Quat) -> None:
        """Move the root's inertial frame there, at rest."""
        bodies.reset_base(self.world, body, position, orientation)

    def reset_base_frame(self, body: int, position: Vec3, orientation: Quat) -> None:
        """Move the root's URDF link frame there, at rest."""
        bodies.reset_base_frame(self.world, body, position, orientation)

    def reset_base_velocity(self, body: int, linear: Vec3, angular: Vec3) -> None:
        """Set the root's velocity: its inertial frame's linear velocity, and the angular."""
        bodies.reset_base_velocity(self.world, body, linear, angular)

    def joint_states(self, body: int, joints: Sequence[int]) -> list[JointState]:
        """The state of these joints now; ``applied``: the motor's force in the last step."""
        return bodies.joint_states(self.world, body, joints)

    def joint_rows(self, body: int, joints: Sequence[int]) -> Sequence[JointRow]:
        """:meth:`joint_states` as plain tuples (``reaction``: see the sensor below)."""
        return bodies.joint_rows(self.world, body, joints)

    def reset_joint(self, body: int, joint: int, position: float, velocity: float = 0.0
                    ) -> None:
        """Put one joint at a position and velocity (a fixed joint: nothing to do)."""
        bodies.reset_joint(self.world, body, joint, position, velocity)

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
        """The joint-space mass matrix at ``positions`` (a floating base's 6 first)."""
        from urdfkit.engine.mujoco_query import mass_matrix

        return mass_matrix(self.world, body, positions)

    def floating_mass_matrix(self, body: int, position: Vec3, orientation: Quat,
                             positions: Sequence[float]) -> list[list[float]]:
        """The mass matrix with the root's inertial frame at this pose (linear first)."""
        from urdfkit.engine.mujoco_query import floating_mass_matrix

        return floating_mass_matrix(self.world, body, position, orientation, positions)

    def jacobian(self, body: int, link: int, point: Vec3, positions: Sequence[float]
                 ) -> tuple[list[list[float]], list[list[float]]]:
        """The linear and angular Jacobians of a point of a link (the URDF frame's)."""
        from urdfkit.engine.mujoco_query import jacobian

        return jacobian(self.world, body, link, point, positions)

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

    def closest_points(self, body: int, other: int, distance: float, link: int | None = None,
                       other_link: int | None = None) -> list[ContactPoint]:
        """Points of ``body`` and ``other`` nearer than ``distance`` (negative: sunk in)."""
        from urdfkit.engine.mujoco_query import closest_points

        return closest_points(self.world, body, other, distance, link, other_link)

    def enable_joint_force_sensor(self, body: int, joint: int) -> None:
        """Measure the wrench on a joint from the next step on (mujoco_reactions)."""
        r, ids = self.world.body(body)
        self.world.joint(r, ids, joint)
        self.world.sensors.add((body, joint))

    def hold_base(self, body: int) -> int:
        """A weld of the root to the world where it is now; its id (mujoco_constraints)."""
        from urdfkit.engine.mujoco_constraints import hold_base

        return hold_base(self.world, body)

    def couple_joints(self, body: int, leader: int, follower: int, multiplier: float,
                      offset: float, max_force: float) -> int:
        """A joint equality, follower = multiplier * leader + offset; its id."""
        from urdfkit.engine.mujoco_constraints import couple_joints

        return couple_joints(self.world, body, leader, follower, multiplier, offset, max_force)

    def collision_shapes(self, body: int, link: int) -> list[CollisionShape]:
        """A link's collision shapes, PyBullet's getCollisionShapeData (mujoco_shapes)."""
        from urdfkit.engine.mujoco_shapes import collision_shapes

        return collision_shapes(self.world, body, link)

    def aabb(self, body: int, link: int) -> tuple[Vec3, Vec3]:
        """A link's axis-aligned bounding box now, world (mujoco_shapes)."""
        from urdfkit.engine.mujoco_shapes import aabb

        return aabb(self.world, body, link)

    def camera_image(self, camera: Camera, width: int, height: int) -> bytes:
        """What ``camera`` sees now, RGB rows top first (mujoco_render; +Z up)."""
        from urdfkit.engine.mujoco_render import camera_image

        return camera_image(self.world, self._renderers, camera, width, height)

    def picture(self, camera: Camera, width: int, height: int, light: Light | None = None
                ) -> Picture:
        """What ``camera`` sees now, each pixel's body, the matrices (mujoco_render)."""
        from urdfkit.engine.mujoco_render import picture

        return picture(self.world, self._renderers, camera, width, height, light)

    def visual_shapes(self, body: int) -> list[VisualShape]:
        """The visual geoms of ``body`` as PyBullet's visual shapes (mujoco_shapes)."""
        from urdfkit.engine.mujoco_shapes import visual_shapes

        return visual_shapes(self.world, body)

    def reset_spherical_joint(self, body: int, joint: int, orientation: Quat) -> None:
        """Put a ball joint at an orientation, at rest."""
        bodies.reset_spherical_joint(self.world, body, joint, orientation)


if TYPE_CHECKING:
    from urdfkit.engine.api import Simulator

    def _is_a_simulator(engine: MuJoCoEngine) -> Simulator:
        """Never called: mypy checks here that the class keeps the whole protocol."""
        return engine
