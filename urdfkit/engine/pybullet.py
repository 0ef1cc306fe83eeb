"""PyBullet behind the seam: :class:`PyBulletEngine`, a :class:`~urdfkit.engine.api.Simulator`.

It runs on a :class:`~urdfkit.engine.session.Session` of its own (DIRECT, or the GUI), so the
quiet-stdout machinery, the load flags and the file-cache rule stay in ``session.py``. Each
method makes the PyBullet calls the simulation made before the seam, with the same arguments
and in the same order, so every output on PyBullet is byte-identical to what it was: link
frames through PyBullet's own ``invertTransform`` and ``multiplyTransforms`` (which round to
float32), restores through :func:`~urdfkit.engine.session.restore_clean`, the first dynamics
call on a body quiet (:func:`~urdfkit.engine.session.dynamics_call`).

Three calls differ in form, not in effect (the call log of every scenario in the seam's
comparison, before and after): a single joint's motor goes through ``setJointMotorControlArray``
(``setJointMotorControl2`` and it set the same motor fields, with the same defaults, in
PyBullet's pybullet.c); ``resetJointState`` always gets its velocity (0 by default, as
PyBullet's own); ``calculateJacobian`` gets zero velocities (bit for bit the same Jacobian).

Costs: a method is one Python call over the bound PyBullet function(s) it wraps, and
:attr:`PyBulletEngine.step` is ``stepSimulation`` itself. The loops that run every step bind
what they call to a local name first (:class:`~urdfkit.engine.session.Bullet` says what each
costs); :meth:`PyBulletEngine.joint_rows` hands PyBullet's own state tuples through, and the
records are filled in C (:func:`_maker`).
"""

from __future__ import annotations

import dataclasses
from collections.abc import Callable, Iterable, Sequence
from typing import TYPE_CHECKING, Any, TypeVar

from urdfkit.engine.api import (
    BaseState,
    ContactPoint,
    JointInfo,
    JointKind,
    JointRow,
    JointState,
    LinkDynamics,
    LinkPose,
    LoadSettings,
    MotorMode,
    Quat,
    Vec3,
)
from urdfkit.engine.pybullet_dynamics import STALE_MODELS, Dynamics
from urdfkit.engine.pybullet_shapes import Shapes, text

if TYPE_CHECKING:
    from _typeshed import DataclassInstance

    from urdfkit.engine.session import Bullet, Session

#: ``getJointInfo``'s jointType codes as the seam's joint kinds (a continuous joint is a
#: revolute one without limits).
JOINT_KINDS: dict[int, JointKind] = {0: "revolute", 1: "prismatic", 2: "spherical",
                                     3: "planar", 4: "fixed"}
#: A mimic gear's error reduction per step (PyBullet's default, 0.2, leaves a sag under load:
#: a 0.5 kg mast following at x 2 against gravity sat 0.37 mm off; at 0.8, 0.010 mm;
#: urdfkit/motion/mimic.py has the measurements).
GEAR_ERP = 0.8

R = TypeVar("R", bound="DataclassInstance")


def _maker(cls: type[R]) -> Callable[[Iterable[Any]], R]:
    """A maker of ``cls`` (a frozen record of engine/api.py) from its field values, in order.

    A frozen dataclass's ``__init__`` sets each field through ``object.__setattr__``: ~1,000
    instructions a field, ~105k of each row a simulation_and_control quadruped records (its
    feet's contact points, link poses and joint forces; callgrind). Filling the new record's
    ``__dict__`` in C gives the same record (equal, hashable, frozen) for a tenth of it.
    """
    names = tuple(f.name for f in dataclasses.fields(cls))
    new = object.__new__

    def make(values: Iterable[Any]) -> R:
        record = new(cls)
        record.__dict__.update(zip(names, values, strict=True))
        return record

    return make


_base_state = _maker(BaseState)
_link_pose = _maker(LinkPose)
_joint_state = _maker(JointState)
_contact_point = _maker(ContactPoint)


def preload() -> None:
    """Import pybullet now, quietly (:func:`~urdfkit.engine.session.import_pybullet`)."""
    from urdfkit.engine.session import import_pybullet

    import_pybullet()


class PyBulletEngine(Shapes, Dynamics):
    """A PyBullet physics client behind the seam (DIRECT, or its GUI window).

    Args:
        gui: Open PyBullet's GUI window (needs a display).
        session: Run on this open session instead of a new one (it is closed with the
            engine): for code that still calls PyBullet itself beside the engine.

    Attributes:
        session: The PyBullet session (PyBullet only: the escape hatch's).
        gui: Whether it is the GUI window.
        error: ``pybullet.error``.
    """

    name = "pybullet"
    label = "PyBullet"
    #: One physics step: ``stepSimulation`` bound to the client itself, so a loop that binds
    #: ``step = engine.step`` pays what ``p.stepSimulation()`` does (a method here would add
    #: a Python call to every step). Rebound to the closed client by :meth:`close`.
    step: Callable[[], None]

    def __init__(self, gui: bool = False, *, session: Session | None = None) -> None:
        from urdfkit.engine.session import Session

        self.session = session if session is not None else Session(gui=gui)
        p = self.session.p
        self.gui = self.session.gui
        self.error: type[Exception] = p.error
        self._velocity, self._position = p.VELOCITY_CONTROL, p.POSITION_CONTROL
        self._torque = p.TORQUE_CONTROL
        self._gear, self._fixed = p.JOINT_GEAR, p.JOINT_FIXED
        #: Bodies :meth:`restore` moves apart (all but scenery), in load order.
        self._lifted: list[int] = []
        #: Per body, PyBullet's inverse-dynamics model: _UNTRIED, None (built: calls are
        #: bare) or why PyBullet refused to build it.
        self._models: dict[int, str | None] = {}
        #: A body was removed: PyBullet's inverse-dynamics models of later ones are not safe.
        self._removed = False
        self._bind()

    def _bind(self) -> None:
        """The calls a loop makes every step, bound to the client once (as :attr:`step`)."""
        b = self.session.bullet
        self.step = b.stepSimulation
        self._motor_array = b.setJointMotorControlArray
        self._base_pose = b.getBasePositionAndOrientation
        self._base_velocity = b.getBaseVelocity
        self._closest = b.getClosestPoints

    @property
    def bullet(self) -> Bullet:
        """PyBullet with this engine's client bound to every call (PyBullet only).

        The escape hatch ``Simulation.bullet`` hands out; after :meth:`close` every call
        through it fails.
        """
        return self.session.bullet

    def close(self) -> None:
        """Disconnect (safe to call twice)."""
        self.session.close()
        self._bind()  # to the closed client: every call fails now

    # ---- the world

    def load(self, path: str, settings: LoadSettings, display: str | None = None, *,
             flags: int = 0) -> int:
        """Load a guarded URDF (:meth:`Session.load_urdf`, its flags from ``settings``).

        ``flags``: further ``p.URDF_*`` flags, PyBullet's own (render's
        ``URDF_IGNORE_VISUAL_SHAPES``: :mod:`urdfkit.engine.pybullet_render`).
        """
        from urdfkit.engine.session import LoadOptions

        body = self.session.load_urdf(path, LoadOptions(
            fixed_base=settings.fixed_base, inertia_from_file=settings.inertia_from_file,
            implicit_cylinder=settings.implicit_cylinder,
            self_collision=settings.self_collision, base_position=settings.position,
            base_orientation=settings.orientation, extra_flags=flags), display=display)
        if not settings.scenery:
            self._lifted.append(body)
        if self._removed:
            self._models[body] = STALE_MODELS
        return body

    def set_gravity(self, gravity: Vec3) -> None:
        """``setGravity``."""
        self.session.bullet.setGravity(*gravity)

    def set_time_step(self, time_step: float) -> None:
        """``setTimeStep``."""
        self.session.bullet.setTimeStep(time_step)

    def set_physics(self, *, deterministic_pairs: bool | None = None,
                    solver_iterations: int | None = None,
                    cone_friction: bool | None = None) -> None:
        """``setPhysicsEngineParameter``: the sorted pairs first, then the solver's settings."""
        b = self.session.bullet
        if deterministic_pairs is not None:
            b.setPhysicsEngineParameter(deterministicOverlappingPairs=int(deterministic_pairs))
        values: dict[str, int] = {}
        if solver_iterations is not None:
            values["numSolverIterations"] = solver_iterations
        if cone_friction is not None:
            values["enableConeFriction"] = int(cone_friction)
        if values:
            b.setPhysicsEngineParameter(**values)

    def require_state_queries(self, body: int, display: str) -> None:
        """:meth:`Session.require_state_queries`: 128 links or more are refused."""
        self.session.require_state_queries(body, display)

    def connected(self) -> bool:
        """``isConnected``: False once the GUI window is closed."""
        return bool(self.session.bullet.isConnected())

    def save(self) -> int:
        """``saveState``, then :func:`prime_resets` over every body but scenery."""
        from urdfkit.engine.session import prime_resets

        b = self.session.bullet
        state = int(b.saveState())
        prime_resets(b, state, self._lifted)
        return state

    def restore(self, state: int) -> None:
        """:func:`restore_clean` over every body but scenery."""
        from urdfkit.engine.session import restore_clean

        restore_clean(self.session.bullet, state, self._lifted)

    # ---- bodies

    def joints(self, body: int) -> list[JointInfo]:
        """``getJointInfo`` of every joint, as records (limits as PyBullet reports them)."""
        b = self.session.bullet
        return [self._joint(b.getJointInfo(body, j)) for j in range(b.getNumJoints(body))]

    @staticmethod
    def _joint(info: Sequence[Any]) -> JointInfo:
        kind = JOINT_KINDS.get(info[2], "fixed")
        lower, upper = float(info[8]), float(info[9])
        return JointInfo(
            index=int(info[0]), name=text(info[1]), kind=kind, q_index=int(info[3]),
            v_index=int(info[4]), damping=float(info[6]), friction=float(info[7]),
            lower=lower, upper=upper,
            # PyBullet's continuous joints read lower 0, upper -1: no limits.
            limited=kind in ("revolute", "prismatic") and lower <= upper,
            effort=float(info[10]), velocity=float(info[11]), link=text(info[12]),
            axis=(info[13][0], info[13][1], info[13][2]), parent=int(info[16]))

    def link_names(self, body: int) -> list[str]:
        """``getBodyInfo``'s root name, then each joint's child link."""
        b = self.session.bullet
        return [text(b.getBodyInfo(body)[0])] + [
            text(b.getJointInfo(body, j)[12]) for j in range(b.getNumJoints(body))]

    def dynamics(self, body: int, link: int) -> LinkDynamics:
        """``getDynamicsInfo``."""
        d = self.session.bullet.getDynamicsInfo(body, link)
        return LinkDynamics(mass=d[0], inertia=d[2], inertial_position=d[3],
                            inertial_orientation=d[4], lateral_friction=d[1],
                            rolling_friction=d[6], spinning_friction=d[7], restitution=d[5],
                            contact_stiffness=d[9], contact_damping=d[8])

    def change_dynamics(self, body: int, link: int, **values: float | Sequence[float]) -> None:
        """``changeDynamics``, PyBullet's names as they are."""
        self.session.bullet.changeDynamics(body, link, **values)

    def base_state(self, body: int) -> BaseState:
        """``getBasePositionAndOrientation`` and ``getBaseVelocity``."""
        pos, orn = self._base_pose(body)
        lin, ang = self._base_velocity(body)
        return _base_state((pos, orn, lin, ang))

    def base_pose(self, body: int) -> tuple[Vec3, Quat]:
        """``getBasePositionAndOrientation``: the root's inertial frame."""
        pos, orn = self.session.bullet.getBasePositionAndOrientation(body)
        return pos, orn

    def link_pose(self, body: int, link: int) -> LinkPose:
        """``getLinkState`` with forward kinematics; for the root, its link frame computed.

        The root's link frame is the inertial frame times the inverse of the local inertial
        pose, through PyBullet's own transforms (float32, as every frame it reports).
        """
        b = self.session.bullet
        if link >= 0:
            st = b.getLinkState(body, link, computeForwardKinematics=True)
            return _link_pose((st[0], st[1], st[4], st[5]))
        pos, orn = b.getBasePositionAndOrientation(body)
        local = b.getDynamicsInfo(body, -1)
        inv = b.invertTransform(local[3], local[4])
        at, turn = b.multiplyTransforms(pos, orn, inv[0], inv[1])
        return _link_pose((pos, orn, at, turn))

    def link_frame(self, body: int, link: int) -> tuple[Vec3, Quat]:
        """:meth:`link_pose`'s URDF frame: the same calls, no record."""
        b = self.session.bullet
        if link >= 0:
            st = b.getLinkState(body, link, computeForwardKinematics=True)
            return st[4], st[5]
        pos, orn = b.getBasePositionAndOrientation(body)
        local = b.getDynamicsInfo(body, -1)
        inv = b.invertTransform(local[3], local[4])
        at, turn = b.multiplyTransforms(pos, orn, inv[0], inv[1])
        return at, turn

    def link_frames(self, body: int) -> list[tuple[Vec3, Quat]]:
        """Every URDF link frame's world pose now, the root first."""
        b = self.session.bullet
        pos, orn = b.getBasePositionAndOrientation(body)
        local = b.getDynamicsInfo(body, -1)
        inv = b.invertTransform(local[3], local[4])
        poses = [b.multiplyTransforms(pos, orn, inv[0], inv[1])]
        for j in range(b.getNumJoints(body)):
            st = b.getLinkState(body, j, computeForwardKinematics=True)
            poses.append((st[4], st[5]))
        return poses

    def reset_base(self, body: int, position: Vec3, orientation: Quat) -> None:
        """``resetBasePositionAndOrientation`` (the inertial frame; the base at rest)."""
        self.session.bullet.resetBasePositionAndOrientation(body, position, orientation)

    def reset_base_frame(self, body: int, position: Vec3, orientation: Quat) -> None:
        """The link frame there: times the local inertial pose, then the inertial frame."""
        b = self.session.bullet
        local = b.getDynamicsInfo(body, -1)
        com_pos, com_orn = b.multiplyTransforms(position, orientation, local[3], local[4])
        b.resetBasePositionAndOrientation(body, com_pos, com_orn)

    def reset_base_velocity(self, body: int, linear: Vec3, angular: Vec3) -> None:
        """``resetBaseVelocity``."""
        self.session.bullet.resetBaseVelocity(body, linear, angular)

    def joint_states(self, body: int, joints: Sequence[int]) -> list[JointState]:
        """``getJointStates``, as records."""
        return [_joint_state(st) for st in self.session.bullet.getJointStates(body, joints) or ()]

    def joint_rows(self, body: int, joints: Sequence[int]) -> Sequence[JointRow]:
        """``getJointStates`` as PyBullet gives it (its tuples are the seam's rows).

        Nothing is copied: three comprehensions over the states cost the servo loop ~5k
        instructions a step, a ``zip`` transposing them ~4k (callgrind).
        """
        rows: Sequence[JointRow] = self.session.bullet.getJointStates(body, joints) or ()
        return rows

    def reset_joint(self, body: int, joint: int, position: float, velocity: float = 0.0
                    ) -> None:
        """``resetJointState``."""
        self.session.bullet.resetJointState(body, joint, position, velocity)

    def reset_spherical_joint(self, body: int, joint: int, orientation: Quat) -> None:
        """``resetJointStateMultiDof`` (which zeroes the joint's velocity: measured)."""
        self.session.bullet.resetJointStateMultiDof(body, joint, list(orientation))

    def set_joint_positions(self, body: int, positions: Sequence[float],
                            velocities: Sequence[float] | None = None) -> None:
        """``resetJointState`` of every movable joint, in :meth:`joints` order."""
        movable = [j.index for j in self.joints(body) if j.kind != "fixed"]
        speeds = [0.0] * len(movable) if velocities is None else velocities
        for j, q, qd in zip(movable, positions, speeds, strict=True):
            self.reset_joint(body, j, q, qd)

    def motors(self, body: int, joints: Sequence[int], mode: MotorMode,
               targets: Sequence[float], forces: Sequence[float] | None = None,
               velocities: Sequence[float] | None = None) -> None:
        """``setJointMotorControlArray``; what is not given is PyBullet's default.

        A force cap not given is PyBullet's 100,000; a position target's velocity, 0.
        """
        # Each form spelt out, as in contacts(): a loop that sets motors every step (the
        # Gymnasium car's) pays no dict of keywords.
        motors = self._motor_array
        if mode == "torque":  # the servo's, every step
            motors(body, joints, self._torque, forces=targets)
        elif mode == "velocity":
            if forces is None:
                motors(body, joints, self._velocity, targetVelocities=targets)
            else:
                motors(body, joints, self._velocity, targetVelocities=targets, forces=forces)
        elif velocities is None:
            if forces is None:
                motors(body, joints, self._position, targetPositions=targets)
            else:
                motors(body, joints, self._position, targetPositions=targets, forces=forces)
        elif forces is None:
            motors(body, joints, self._position, targetPositions=targets,
                   targetVelocities=velocities)
        else:
            motors(body, joints, self._position, targetPositions=targets,
                   targetVelocities=velocities, forces=forces)

    def contacts(self, body: int, link: int | None = None, other: int | None = None
                 ) -> list[ContactPoint]:
        """``getContactPoints`` of ``body`` (``linkIndexA``) with ``other`` (``bodyB``).

        Each form spelt out: a dict of keywords spread into the call cost a recorded foot
        ~0.7 us more (measured).
        """
        points = self.session.bullet.getContactPoints
        if link is None:
            found = points(bodyA=body) if other is None else points(bodyA=body, bodyB=other)
        elif other is None:
            found = points(bodyA=body, linkIndexA=link)
        else:
            found = points(bodyA=body, linkIndexA=link, bodyB=other)
        if not found:
            return []
        return [_contact_point(pt[1:14]) for pt in found]

    def closest_points(self, body: int, other: int, distance: float, link: int | None = None,
                       other_link: int | None = None) -> list[ContactPoint]:
        """``getClosestPoints`` of ``body`` (``linkIndexA``) and ``other`` (``linkIndexB``).

        Bound once, each form spelt out, two links by position: collisions asks for every
        link pair in every pose (r2d2's 91 pairs: 2.5 us a pair here, 2.3 us the bare call;
        a dict of keywords cost 0.55 us more).
        """
        closest = self._closest
        if link is None:
            found = closest(body, other, distance) if other_link is None else \
                closest(body, other, distance, linkIndexB=other_link)
        elif other_link is None:
            found = closest(body, other, distance, linkIndexA=link)
        else:
            found = closest(body, other, distance, link, other_link)
        if not found:
            return []
        return [_contact_point(pt[1:14]) for pt in found]

    def enable_joint_force_sensor(self, body: int, joint: int) -> None:
        """``enableJointForceTorqueSensor``."""
        self.session.bullet.enableJointForceTorqueSensor(body, joint, True)

    def hold_base(self, body: int) -> int:
        """A ``JOINT_FIXED`` constraint between the base and the world, where it is."""
        b = self.session.bullet
        pos, orn = b.getBasePositionAndOrientation(body)
        return int(b.createConstraint(body, -1, -1, -1, self._fixed, [0, 0, 0], [0, 0, 0],
                                      pos, childFrameOrientation=orn))

    def couple_joints(self, body: int, leader: int, follower: int, multiplier: float,
                      offset: float, max_force: float) -> int:
        """A ``JOINT_GEAR`` constraint between the two joints' links.

        The gear holds ``q_leader + gearRatio * q_follower = relativePositionTarget``; with
        ``gearRatio = -1 / multiplier`` and ``relativePositionTarget = -offset / multiplier``
        that is the mimic relation, offset included, at :data:`GEAR_ERP`.
        """
        b = self.session.bullet
        c = b.createConstraint(body, leader, body, follower, self._gear, [1, 0, 0], [0, 0, 0],
                               [0, 0, 0])
        b.changeConstraint(c, gearRatio=-1.0 / multiplier, maxForce=max_force,
                           relativePositionTarget=-offset / multiplier, erp=GEAR_ERP)
        return int(c)

    def set_collision_filter(self, body: int, link: int, group: int, mask: int) -> None:
        """``setCollisionFilterGroupMask``: group and mask 0 take the link out of every contact.

        PyBullet only (not in the seam's protocol): ``agree`` swings a robot with contacts off.
        """
        self.session.bullet.setCollisionFilterGroupMask(body, link, group, mask)

    def remove_body(self, body: int) -> None:
        """``removeBody`` (PyBullet only, not in the seam's protocol).

        What the engine kept of the body goes with it: PyBullet gives its id to the next. So
        may its inverse-dynamics model (:data:`STALE_MODELS`): no body loaded after a removal
        is asked for its mass matrix, inverse dynamics or Jacobian.
        """
        self.session.bullet.removeBody(body)
        self._models.pop(body, None)
        self._removed = True
        if body in self._lifted:
            self._lifted.remove(body)

    @staticmethod
    def load_flags(settings: LoadSettings) -> list[str]:
        """The ``loadURDF`` flags :meth:`load` sets for ``settings``, by name (``URDF_*``)."""
        from urdfkit.engine.session import LoadOptions

        return LoadOptions(fixed_base=settings.fixed_base,
                           inertia_from_file=settings.inertia_from_file,
                           implicit_cylinder=settings.implicit_cylinder,
                           self_collision=settings.self_collision).flag_names()


if TYPE_CHECKING:
    from urdfkit.engine.api import Simulator

    def _is_a_simulator(engine: PyBulletEngine) -> Simulator:
        """Never called: mypy checks here that the class keeps the whole protocol."""
        return engine
