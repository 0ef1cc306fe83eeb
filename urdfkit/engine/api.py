"""The engine seam: what urdfkit asks of a physics engine, in plain records.

Two protocols, as dm_control's ``Physics`` and robot_descriptions' one loader per engine
suggest, since some engines (Pinocchio, Drake) give only the first:

- :class:`Model`: what a loaded robot *is*: its joints and links as the engine reads them,
  link frames at a configuration, the mass matrix, inverse dynamics and Jacobians. What
  ``agree`` compares, engine against engine.
- :class:`Simulator`: a :class:`Model` that also *moves*: a world with gravity, a ground and
  bodies, a physics step, motors, contacts, save and restore. What ``sim``, ``drive``,
  ``sweep`` and the Gymnasium environments run on.

Every engine is one module of this folder (``engine/pybullet.py``, ``engine/mujoco.py``) and
one entry of :data:`ENGINES`; nothing outside ``engine/`` imports an engine's package or calls
its functions (tests/test_engine_seam.py). Indices are the engine's own, with PyBullet's
conventions kept as the seam's: a body is an ``int``; link -1 is the root link; a link's index
is its parent joint's; joints are numbered depth-first as the URDF lists them. Quaternions are
``(x, y, z, w)``. A link *frame* is the URDF's frame of the link; its *inertial* frame is the
``<inertial><origin>`` (PyBullet's base "position" is the root's inertial frame, not its link
frame: :meth:`Simulator.base_state` says which it returns).
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
        lower, upper: The limits; ``limited`` False where the joint has none.
        effort, velocity: The URDF's effort and velocity limits (0: none given).
        link: The child link's name.
        axis: The joint axis in the child link's frame.
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
class LoadSettings:
    """How a robot is loaded, in the engine's neutral terms.

    Attributes:
        fixed_base: Weld the root to the world.
        inertia_from_file: Use the file's ``<inertia>`` (PyBullet otherwise recomputes it
            from the collision shapes).
        implicit_cylinder: Collide with true cylinders, not meshes of them.
        self_collision: Let the robot's links collide (parent-child pairs excluded).
        position, orientation: Where the root link frame starts, world.
    """

    fixed_base: bool = False
    inertia_from_file: bool = False
    implicit_cylinder: bool = True
    self_collision: bool = False
    position: Vec3 = (0.0, 0.0, 0.0)
    orientation: Quat = (0.0, 0.0, 0.0, 1.0)


class Model(Protocol):
    """A robot as an engine reads it: joints, links, kinematics and dynamics.

    Attributes:
        name: The engine's name in :data:`ENGINES` (``"pybullet"``).
    """

    name: str

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
        """The joint-space mass matrix at ``positions`` (movable joints only)."""
        ...

    def inverse_dynamics(self, body: int, positions: Sequence[float],
                         velocities: Sequence[float],
                         accelerations: Sequence[float]) -> list[float]:
        """The joint torques that give ``accelerations`` at this state, gravity included."""
        ...

    def close(self) -> None:
        """Release the engine (safe to call twice)."""
        ...


class Simulator(Model, Protocol):
    """A :class:`Model` that moves: a world of bodies stepped in time."""

    def load(self, path: str, settings: LoadSettings, display: str | None = None) -> int:
        """Load a URDF that has passed the guard; its body id."""
        ...

    def set_gravity(self, gravity: Vec3) -> None:
        """The world's gravity, m/s^2."""
        ...

    def set_time_step(self, time_step: float) -> None:
        """The physics step, s."""
        ...

    def step(self) -> None:
        """One physics step."""
        ...

    def save(self) -> int:
        """Keep the state now; an id for :meth:`restore`."""
        ...

    def restore(self, state: int) -> None:
        """Back to a saved state, exactly as it was (contacts included)."""
        ...

    def base_state(self, body: int) -> BaseState:
        """The root's inertial frame and velocity, world."""
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
