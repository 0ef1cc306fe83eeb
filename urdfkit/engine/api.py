"""The engine seam: what urdfkit asks of a physics engine, in plain records.

Two protocols, as dm_control's ``Physics`` and robot_descriptions' one loader per engine
suggest, since some engines (Pinocchio, Drake) give only the first:

- :class:`Model`: what a loaded robot *is*: its joints and links as the engine reads them,
  link frames at a configuration, the mass matrix, inverse dynamics and Jacobians. What
  ``agree`` compares, engine against engine.
- :class:`Simulator`: a :class:`Model` that also *moves*: a world with gravity, a ground and
  bodies, a physics step, motors, contacts, save and restore. What ``sim``, ``drive``,
  ``sweep`` and the Gymnasium environments run on.

Every engine is one module of this folder (``engine/pybullet.py``, ``engine/mujoco.py``) and one
entry of :data:`urdfkit.engine.registry.ENGINES`; nothing outside ``engine/`` imports an
engine's package or calls its functions (tests/test_engine_seam.py). Indices are the engine's
own, with PyBullet's conventions kept as the seam's: a body is an ``int``; link -1 is the root
link; a link's index is its parent joint's; joints are numbered depth-first as the URDF lists
them. Quaternions are ``(x, y, z, w)``. A link *frame* is the URDF's frame of the link; its
*inertial* frame is the ``<inertial><origin>`` (PyBullet's base "position" is the root's
inertial frame, not its link frame: :meth:`Simulator.base_state` says which it returns).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from typing import Literal, Protocol

Vec3 = tuple[float, float, float]
Quat = tuple[float, float, float, float]
#: How a joint motor is driven: to a velocity or a position under a force cap, or by a
#: torque applied for the next step only.
MotorMode = Literal["velocity", "position", "torque"]
#: The joint kinds the seam knows, as URDF names them (PyBullet's continuous joints are
#: revolute joints without limits: ``limited`` says which).
JointKind = Literal["revolute", "prismatic", "spherical", "planar", "fixed"]
#: One joint's state as a plain tuple: :class:`JointState`'s fields in its order (position,
#: velocity, reaction wrench, applied motor torque). What :meth:`Simulator.joint_rows` gives.
JointRow = tuple[float, float, Sequence[float], float]
#: The collision shape kinds the seam knows (``other``: one it has no outline for).
ShapeKind = Literal["sphere", "box", "cylinder", "capsule", "mesh", "plane", "other"]


@dataclass(frozen=True)
class JointInfo:
    """One joint as the engine loaded it (PyBullet's ``getJointInfo``, by name).

    Attributes:
        index: The engine's joint (and child link) index.
        name: The URDF's joint name.
        kind: Its kind; ``limited`` tells revolute from continuous.
        q_index, v_index: Its first position and velocity index in the engine's state
            vectors, -1 for a fixed joint.
        damping, friction: The URDF's ``<dynamics>`` (N m s/rad; N m).
        lower, upper: The limits; ``limited`` False where the joint has none. As PyBullet
            reports them: a continuous joint with a ``<limit>`` has its bounds (limited),
            though no engine holds it there.
        effort, velocity: The URDF's effort and velocity limits (0: none given).
        link: The child link's name.
        axis: The joint axis in the child link's inertial frame, as PyBullet's getJointInfo
            gives it (the link frame's axes unless the ``<inertial>`` is turned).
        parent: The parent link's index (-1: the root).
    """

    index: int
    name: str
    kind: JointKind
    q_index: int
    v_index: int
    damping: float
    friction: float
    lower: float
    upper: float
    limited: bool
    effort: float
    velocity: float
    link: str
    axis: Vec3
    parent: int


@dataclass(frozen=True)
class LinkDynamics:
    """One link's mass properties and contact parameters now (``getDynamicsInfo``).

    Attributes:
        mass: kg (0 on a static root).
        inertia: The principal moments, kg m^2, in the inertial frame.
        inertial_position, inertial_orientation: The inertial frame in the link frame.
        lateral_friction, rolling_friction, spinning_friction, restitution: Contact
            coefficients.
        contact_stiffness, contact_damping: The contact spring (-1: rigid).
    """

    mass: float
    inertia: Vec3
    inertial_position: Vec3
    inertial_orientation: Quat
    lateral_friction: float
    rolling_friction: float
    spinning_friction: float
    restitution: float
    contact_stiffness: float
    contact_damping: float


@dataclass(frozen=True)
class JointState:
    """One joint's state now.

    Its position, velocity, the reaction wrench on it (6, where the engine measures it; zeros
    elsewhere) and the motor torque applied in the last step.
    """

    position: float
    velocity: float
    reaction: tuple[float, float, float, float, float, float]
    applied: float


@dataclass(frozen=True)
class BaseState:
    """The root link's pose and velocity now: its inertial frame, world coordinates."""

    position: Vec3
    orientation: Quat
    linear: Vec3
    angular: Vec3


@dataclass(frozen=True)
class ContactPoint:
    """One contact point between two bodies (``getContactPoints``).

    ``normal`` points from B to A, ``normal_force`` pushes A off B (N); ``friction1`` along
    ``direction1`` and ``friction2`` along ``direction2`` are the lateral forces on B.
    """

    body_a: int
    body_b: int
    link_a: int
    link_b: int
    position_a: Vec3
    position_b: Vec3
    normal: Vec3
    distance: float
    normal_force: float
    friction1: float
    direction1: Vec3
    friction2: float
    direction2: Vec3


@dataclass(frozen=True)
class LinkPose:
    """One link's two world frames now: its inertial frame and its URDF link frame.

    For the root the inertial frame is :meth:`Simulator.base_pose`'s; for another link both
    come from one query (PyBullet's ``getLinkState`` with forward kinematics).
    """

    inertial_position: Vec3
    inertial_orientation: Quat
    position: Vec3
    orientation: Quat


@dataclass(frozen=True)
class CollisionShape:
    """One collision shape of a link (PyBullet's ``getCollisionShapeData``).

    Attributes:
        kind: What it is.
        dimensions: ``box``: the full sizes x, y, z; ``sphere``: the radius first;
            ``cylinder`` and ``capsule``: the length, then the radius; ``mesh``: the scale.
        position, orientation: Its frame in the link's inertial frame.
        vertices: A mesh's vertices in the link's inertial frame (empty when the engine
            gives none); None for the other kinds.
        filename: A mesh's file as the engine read it ("" for the other kinds, and where the
            engine has no file to name: a cylinder PyBullet made a mesh of, a mesh MuJoCo's
            export converted).
    """

    kind: ShapeKind
    dimensions: Sequence[float]
    position: Vec3
    orientation: Quat
    vertices: Sequence[Vec3] | None = None
    filename: str = ""


@dataclass(frozen=True)
class VisualShape:
    """One visual shape of a body, what pictures draw (PyBullet's ``getVisualShapeData``).

    Attributes:
        link: Its link (-1: the root).
        kind: What it is.
        dimensions: As :attr:`CollisionShape.dimensions`: a box's full sizes, a sphere's
            radius first, a cylinder's or capsule's length, then its radius, a mesh's scale.
        filename: A mesh's file as the engine read it ("" as for :class:`CollisionShape`).
        position, orientation: Its frame in the link's URDF frame (not the inertial frame,
            unlike a collision shape's).
        rgba: Its colour, 0..1, as the engine holds it (PyBullet's material rules applied).
    """

    link: int
    kind: ShapeKind
    dimensions: Sequence[float]
    filename: str
    position: Vec3
    orientation: Quat
    rgba: tuple[float, float, float, float]


@dataclass(frozen=True)
class Camera:
    """A pinhole camera for :meth:`Simulator.camera_image`, world coordinates.

    Attributes:
        eye: Where it is.
        target: The point it looks at.
        up: Which way is up in the picture.
        fov: The vertical field of view, degrees.
        near, far: The clipping distances, m.
    """

    eye: Vec3
    target: Vec3
    up: Vec3 = (0.0, 0.0, 1.0)
    fov: float = 60.0
    near: float = 0.01
    far: float = 100.0

    @classmethod
    def orbit(cls, target: Vec3, distance: float, yaw: float, pitch: float,
              fov: float = 60.0) -> Camera:
        """Looking at ``target`` from ``distance`` away, from ``yaw`` and ``pitch`` degrees.

        Turned ``yaw`` about +Z and tilted ``pitch`` (negative: from above), as PyBullet's
        ``computeViewMatrixFromYawPitchRoll`` (its view matrix to float32's precision).
        """
        import math

        y, p = math.radians(yaw), math.radians(pitch)
        eye = (target[0] + distance * math.cos(p) * math.sin(y),
               target[1] - distance * math.cos(p) * math.cos(y),
               target[2] - distance * math.sin(p))
        return cls(eye, target, fov=fov)


@dataclass(frozen=True)
class Light:
    """The one directional light of a :meth:`Simulator.picture`.

    Attributes:
        direction: Towards the light from the scene, world (any length).
        ambient, diffuse, specular: How much each term lights, 0..1 (PyBullet's defaults).
        shadows: Whether shapes cast shadows.
    """

    direction: Vec3
    ambient: float = 0.6
    diffuse: float = 0.35
    specular: float = 0.05
    shadows: bool = False


@dataclass(frozen=True)
class Picture:
    """What a :meth:`Simulator.picture` saw, and how to find a world point in it.

    Attributes:
        width, height: Its size in pixels.
        rgb: ``height`` rows of ``width`` RGB pixels, top row first.
        bodies: The body drawn at each pixel, in the same order, a little-endian int32
            each (``numpy.frombuffer(bodies, "<i4")``); -1 where none is.
        view, projection: The view and projection matrices it was drawn with, 16 numbers
            each, column-major (OpenGL's): a world point ``p`` is at clip coordinates
            ``c = projection @ view @ (p, 1)``, pixel ``((c_x / c_w + 1) width / 2,
            (1 - c_y / c_w) height / 2)`` from the top left corner.
    """

    width: int
    height: int
    rgb: bytes
    bodies: bytes
    view: tuple[float, ...]
    projection: tuple[float, ...]


@dataclass(frozen=True)
class LoadSettings:
    """How a robot is loaded, in the engine's neutral terms.

    Attributes:
        fixed_base: Weld the root to the world.
        inertia_from_file: Use the file's ``<inertia>`` (PyBullet otherwise recomputes it
            from the collision shapes).
        implicit_cylinder: Collide with true cylinders, not meshes of them.
        self_collision: Let the robot's links collide (parent-child pairs excluded).
        position, orientation: Where the root link frame starts, world.
        scenery: The world's ground (or a fixture): :meth:`Simulator.restore` leaves it
            where it is. PyBullet's exact restore moves every other body apart once (an
            infinite plane moved with them would still touch them).
    """

    fixed_base: bool = False
    inertia_from_file: bool = False
    implicit_cylinder: bool = True
    self_collision: bool = False
    position: Vec3 = (0.0, 0.0, 0.0)
    orientation: Quat = (0.0, 0.0, 0.0, 1.0)
    scenery: bool = False


class Model(Protocol):
    """A robot as an engine reads it: joints, links, kinematics and dynamics.

    Attributes:
        name: The engine's name in :data:`~urdfkit.engine.registry.ENGINES` (``"pybullet"``).
        label: Its name as messages write it (``"PyBullet"``).
    """

    name: str
    label: str

    def joints(self, body: int) -> list[JointInfo]:
        """Every joint of ``body``, fixed ones included, in the engine's order."""
        ...

    def link_names(self, body: int) -> list[str]:
        """Every link's name, the root first, then by index."""
        ...

    def dynamics(self, body: int, link: int) -> LinkDynamics:
        """A link's mass properties and contact parameters now."""
        ...

    def set_joint_positions(self, body: int, positions: Sequence[float],
                            velocities: Sequence[float] | None = None) -> None:
        """Put every movable joint (in :meth:`joints` order) at these values, at rest."""
        ...

    def link_frames(self, body: int) -> list[tuple[Vec3, Quat]]:
        """Every link frame's world pose now, the root first."""
        ...

    def mass_matrix(self, body: int, positions: Sequence[float]) -> list[list[float]]:
        """The joint-space mass matrix at ``positions`` (movable joints only).

        A floating base's 6 coordinates come first, in the engine's order (PyBullet:
        angular, then linear).
        """
        ...

    def inverse_dynamics(self, body: int, positions: Sequence[float],
                         velocities: Sequence[float],
                         accelerations: Sequence[float]) -> list[float]:
        """The joint torques that give ``accelerations`` at this state, gravity included."""
        ...

    def floating_mass_matrix(self, body: int, position: Vec3, orientation: Quat,
                             positions: Sequence[float]) -> list[list[float]]:
        """:meth:`mass_matrix` of a floating-base body with its root at this pose.

        The root's inertial frame, as :meth:`Simulator.base_pose` gives it; its 6
        coordinates come first, in the engine's order (PyBullet: linear, then angular,
        unlike its :meth:`mass_matrix`).
        """
        ...

    def jacobian(self, body: int, link: int, point: Vec3, positions: Sequence[float]
                 ) -> tuple[list[list[float]], list[list[float]]]:
        """The linear and angular Jacobians (3 x n each) of a point of a link at ``positions``.

        ``point`` is from the link's URDF frame's origin along the link's inertial frame's axes,
        as PyBullet's calculateJacobian takes it (measured on 3.2.7; the URDF frame's axes
        unless the ``<inertial>`` is turned). A floating base's 6 columns come first, as
        :meth:`mass_matrix`'s coordinates; the rows are in the root's inertial frame (PyBullet
        computes with the base at the origin, unturned). The dynamics methods raise
        :class:`urdfkit.core.errors.EngineError` when the engine cannot build its model of
        the body, with why as a clause (a caller names the robot before it).
        """
        ...

    def close(self) -> None:
        """Release the engine (safe to call twice)."""
        ...


class Simulator(Model, Protocol):
    """A :class:`Model` that moves: a world of bodies stepped in time.

    Attributes:
        gui: Whether the world shows in a window of the engine's own.
        error: The exception the engine's calls raise when it fails (``pybullet.error``;
            a closed window makes every call raise it).
    """

    gui: bool
    error: type[Exception]

    def load(self, path: str, settings: LoadSettings, display: str | None = None) -> int:
        """Load a URDF that has passed the guard; its body id."""
        ...

    def set_gravity(self, gravity: Vec3) -> None:
        """The world's gravity, m/s^2."""
        ...

    def set_time_step(self, time_step: float) -> None:
        """The physics step, s."""
        ...

    def set_physics(self, *, deterministic_pairs: bool | None = None,
                    solver_iterations: int | None = None,
                    cone_friction: bool | None = None) -> None:
        """The solver's settings; None leaves one as it is.

        Args:
            deterministic_pairs: Meet contacts in a sorted order, so a restore replays a
                run exactly.
            solver_iterations: Constraint solver iterations per step.
            cone_friction: A friction cone (True) or its pyramid approximation.
        """
        ...

    def require_state_queries(self, body: int, display: str) -> None:
        """Refuse a body whose state the engine cannot report (PyBullet: 128 links or more).

        Raises:
            EngineError: naming ``display``.
        """
        ...

    def connected(self) -> bool:
        """Whether the engine still runs (False once its window is closed)."""
        ...

    def step(self) -> None:
        """One physics step (an engine may make it a callable attribute: loops bind it)."""
        ...

    def save(self) -> int:
        """Keep the state now; an id for :meth:`restore`.

        The world may be stepped and restored to it here, so that the first restore
        continues as every later one does (PyBullet's contact bookkeeping differs after its
        first step and reset); it is at the saved state when this returns.
        """
        ...

    def restore(self, state: int) -> None:
        """Back to a saved state, exactly as it was (contacts included).

        Bodies loaded as ``scenery`` stay where they are while the engine drops what it
        carried over (PyBullet moves the others apart once).
        """
        ...

    def base_state(self, body: int) -> BaseState:
        """The root's inertial frame and velocity, world."""
        ...

    def base_pose(self, body: int) -> tuple[Vec3, Quat]:
        """The root's inertial frame, world (:meth:`base_state` without the velocity)."""
        ...

    def link_pose(self, body: int, link: int) -> LinkPose:
        """One link's inertial and URDF frames now, world (link -1: the root)."""
        ...

    def link_frame(self, body: int, link: int) -> tuple[Vec3, Quat]:
        """One link's URDF frame now, world (link -1: the root).

        :meth:`link_pose` without the record, for the rows that record feet and link poses.
        """
        ...

    def reset_base_frame(self, body: int, position: Vec3, orientation: Quat) -> None:
        """Move the root's URDF link frame there, at rest.

        :meth:`reset_base` places the inertial frame; a robot's start is its link frame.
        """
        ...

    def reset_base(self, body: int, position: Vec3, orientation: Quat) -> None:
        """Move the root's inertial frame there, at rest."""
        ...

    def reset_base_velocity(self, body: int, linear: Vec3, angular: Vec3) -> None:
        """Set the root's velocity."""
        ...

    def joint_states(self, body: int, joints: Sequence[int]) -> list[JointState]:
        """The state of these joints (by index) now."""
        ...

    def joint_rows(self, body: int, joints: Sequence[int]) -> Sequence[JointRow]:
        """:meth:`joint_states` as plain tuples (:data:`JointRow`), one per joint.

        The call the measuring and control loops make every step: no record per joint (an
        engine may hand out its own tuples; PyBullet's ``getJointStates`` are these).
        """
        ...

    def reset_joint(self, body: int, joint: int, position: float, velocity: float = 0.0
                    ) -> None:
        """Put one joint at a position and velocity."""
        ...

    def motors(self, body: int, joints: Sequence[int], mode: MotorMode,
               targets: Sequence[float], forces: Sequence[float] | None = None,
               velocities: Sequence[float] | None = None) -> None:
        """Drive joints.

        To target velocities or positions under force caps (kept until changed), or by
        torques (``targets``, for the next step only).
        """
        ...

    def change_dynamics(self, body: int, link: int, **values: float | Sequence[float]
                        ) -> None:
        """Change a link's (or the body's) dynamics.

        By PyBullet's ``changeDynamics`` names (``lateralFriction``, ``mass``,
        ``localInertiaDiagonal``, ``jointDamping``, ``linearDamping``, ``contactStiffness``
        ...); an engine that cannot carry one raises
        :class:`urdfkit.core.errors.ParameterError` naming it.
        """
        ...

    def contacts(self, body: int, link: int | None = None, other: int | None = None
                 ) -> list[ContactPoint]:
        """The contact points of ``body`` (one link of it, or all) with ``other`` (or any)."""
        ...

    def closest_points(self, body: int, other: int, distance: float, link: int | None = None,
                       other_link: int | None = None) -> list[ContactPoint]:
        """The points of ``body`` and ``other`` nearer than ``distance`` now.

        PyBullet's ``getClosestPoints``, of one link of each or of all. Fields as
        :meth:`contacts` fills them, A ``body``: a negative ``distance`` is a penetration; no
        forces. Measured at the positions now, not in the last step.
        """
        ...

    def enable_joint_force_sensor(self, body: int, joint: int) -> None:
        """Measure the reaction wrench on a joint (:attr:`JointState.reaction`) from now on."""
        ...

    def hold_base(self, body: int) -> int:
        """Hold the root where it is now, its joints still free; the constraint's id.

        A fixed constraint to the world: simulation_and_control's rack.
        """
        ...

    def couple_joints(self, body: int, leader: int, follower: int, multiplier: float,
                      offset: float, max_force: float) -> int:
        """Hold ``follower`` at ``multiplier * leader + offset`` (URDF's ``<mimic>``).

        With up to ``max_force`` (N or N m); the coupling's id. The follower is not moved
        onto the relation here.
        """
        ...

    def collision_shapes(self, body: int, link: int) -> list[CollisionShape]:
        """A link's collision shapes (link -1: the root), in the engine's order."""
        ...

    def aabb(self, body: int, link: int) -> tuple[Vec3, Vec3]:
        """A link's axis-aligned bounding box now, world: its lower and upper corner."""
        ...

    def camera_image(self, camera: Camera, width: int, height: int) -> bytes:
        """What ``camera`` sees now: ``height`` rows of ``width`` RGB pixels, top row first.

        Off screen (PyBullet's TinyRenderer; MuJoCo's renderer, which needs OpenGL: EGL
        headless).
        """
        ...

    def picture(self, camera: Camera, width: int, height: int, light: Light | None = None
                ) -> Picture:
        """What ``camera`` sees now, which body each pixel shows, and the matrices it used.

        As :meth:`camera_image`, lit by ``light`` (None: the engine's own light), with the
        camera's ``near`` and ``far``.
        """
        ...

    def visual_shapes(self, body: int) -> list[VisualShape]:
        """Every visual shape of ``body``, by link (the root first), in the engine's order."""
        ...

    def reset_spherical_joint(self, body: int, joint: int, orientation: Quat) -> None:
        """Put a spherical joint at an orientation (x, y, z, w), at rest."""
        ...
