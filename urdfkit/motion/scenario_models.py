"""The pydantic models of a scenario file (``docs/scenario.md`` documents every key).

Imported only when a scenario is read (:func:`urdfkit.motion.scenario.schema`): pydantic costs about
0.1 s, which ``urdfkit --help`` and ``urdfkit joints`` must not pay. Defined at module level so
that mypy checks the code that uses them.
"""

from __future__ import annotations

import os
from pathlib import Path
from typing import Annotated, Any, Literal

# This module is the lazy import itself: scenario.py imports it only when a scenario is read.
from pydantic import (  # noqa: TID253
    BaseModel,
    ConfigDict,
    Field,
    PrivateAttr,
    field_validator,
    model_validator,
)


class ConfigModel(BaseModel):
    """Every model: strict types, no unknown keys, no NaN or infinity."""

    # strict: "3" is not a number and 1 is not true; a typo must not pass silently.
    # forbid: an unknown key is almost always a misspelt known one.
    model_config = ConfigDict(extra="forbid", strict=True, allow_inf_nan=False)

vec3 = Annotated[list[float], Field(min_length=3, max_length=3)]
vec4 = Annotated[list[float], Field(min_length=4, max_length=4)]
positive = Annotated[float, Field(gt=0)]
non_negative = Annotated[float, Field(ge=0)]


class Physics(ConfigModel):
    """The engine: which, time step, gravity, solver, damping (``physics``)."""

    # urdfkit/engine/registry.py's ENGINES: "pybullet", or "mujoco" (the export, in memory).
    engine: str = "pybullet"
    time_step: Annotated[float, Field(gt=0, le=1)] = 1.0 / 240.0
    gravity: vec3 = Field(default_factory=lambda: [0.0, 0.0, -9.81])
    solver_iterations: Annotated[int, Field(ge=1)] = 50
    cone_friction: bool = True
    # None: PyBullet's own 0.04 on every link (an undamped pendulum needs 0).
    linear_damping: non_negative | None = None
    angular_damping: non_negative | None = None
    # PyBullet's deterministicOverlappingPairs: contacts met in a sorted order, so a
    # reset in place replays the same run. simulation_and_control leaves it off.
    deterministic_pairs: bool = True

    @field_validator("engine")
    @classmethod
    def _known_engine(cls, name: str) -> str:
        from urdfkit.core.errors import ParameterError
        from urdfkit.engine.registry import check

        try:
            check(name)
        except ParameterError as e:
            raise ValueError(e.message.removeprefix("`engine`: ")) from None
        return name


class Ground(ConfigModel):
    """What the robots stand on: a template or a URDF (``ground``; a bare string is either)."""

    template: str | None = None
    params: dict[str, Any] = Field(default_factory=dict)
    urdf: str | None = None
    position: vec3 = Field(default_factory=lambda: [0.0, 0.0, 0.0])

    @model_validator(mode="before")
    @classmethod
    def _shorthand(cls, data: Any) -> Any:
        # "ground": "simpleplane" or "ground": "plane.urdf".
        if isinstance(data, str):
            from urdfkit.model.catalog import TEMPLATES

            return {"template": data} if data in TEMPLATES else {"urdf": data}
        return data


class RecordConfig(ConfigModel):
    """What is recorded every ``every`` steps besides the base (``record``)."""

    every: Annotated[int, Field(ge=1)] = 1
    contact_links: list[str] = Field(default_factory=list)
    joint_forces: list[str] = Field(default_factory=list)
    motor_torques: bool = False
    link_poses: list[str] = Field(default_factory=list)
    # Feet: link names, or label -> link name ({"FL": "fl_foot", ...}).
    feet: list[str] | dict[str, str] = Field(default_factory=list)


class LinkDynamics(ConfigModel):
    """A link's contact and friction settings (``link_dynamics``)."""

    lateral_friction: non_negative | None = None
    restitution: non_negative | None = None
    rolling_friction: non_negative | None = None
    spinning_friction: non_negative | None = None


class DriveSegment(ConfigModel):
    """Throttle and steer until a time (``drive``)."""

    until: positive
    throttle: float = 0.0
    steer: float = 0.0


class Vehicle(ConfigModel):
    """Which joints drive and steer, and the wheel force (``vehicle``)."""

    wheels: list[str] | None = None
    hinges: list[str] | None = None
    max_force: positive = 10.0


Mode = Literal["position", "velocity", "torque"]


class JointSegment(ConfigModel):
    """Joint targets until a time, by position, velocity or torque (``joints``)."""

    until: positive
    # One mode for every target, or joint name -> mode (every target named).
    mode: Mode | dict[str, Mode] = "position"
    targets: dict[str, float]
    # Position mode: the velocity to track alongside each position (default 0).
    velocities: dict[str, float] = Field(default_factory=dict)
    max_force: positive | None = None


class Motor(ConfigModel):
    """The servo model between targets and torques (``motor``)."""

    # One gain for every joint, or joint name -> gain (joints not named get 0).
    kp: non_negative | dict[str, non_negative] = 0.0
    kd: non_negative | dict[str, non_negative] = 0.0
    viscous_friction: non_negative | dict[str, non_negative] = 0.0
    stiffness: non_negative | dict[str, non_negative] = 0.0
    # The friction and spring torques multiplied by the joint-space mass matrix M(q)
    # (simulation_and_control's servo): the coefficients are then accelerations' gains.
    scale_by_mass_matrix: bool = False
    # Where that M is taken: "joint" (the robot's joint angles, in the joint frame, D M D:
    # the physics), or "measured" (simulation_and_control's: calculateMassMatrix given the
    # offset/direction-adjusted angles as if they were joint angles, and no D).
    mass_matrix_angles: Literal["joint", "measured"] = "joint"
    inertia: non_negative = 0.0  # rotor inertia reflected to the joint, kg m^2
    # None: the joint's effort limit; "unlimited": no clip.
    max_torque: positive | Literal["unlimited"] | None = None
    joints: list[str] | None = None
    # The servo reads what the robot reports (delayed, noisy), as on a real robot.
    measured_state: bool = False


class InitialJoint(ConfigModel):
    """A joint's start (``initial_joints``; a bare number is a position)."""

    position: float = 0.0
    velocity: float = 0.0

    @model_validator(mode="before")
    @classmethod
    def _shorthand(cls, data: Any) -> Any:
        # "initial_joints": {"hinge": 0.3} means a position.
        if isinstance(data, (int, float)) and not isinstance(data, bool):
            return {"position": data}
        if not isinstance(data, dict):
            raise ValueError("expected a number, or an object with position and velocity")
        return data


per_joint = non_negative | dict[str, non_negative]
per_axis = non_negative | Annotated[list[non_negative], Field(min_length=3, max_length=3)]


class Noise(ConfigModel):
    """Standard deviations of the noise on what the robot reports (``noise``)."""

    # Standard deviations: one for every joint, or joint name -> value (others 0) ...
    motor_angles: per_joint = 0.0
    motor_velocities: per_joint = 0.0
    motor_accelerations: per_joint = 0.0
    motor_torques: per_joint = 0.0
    # ... one for every axis, or [x, y, z]; base_orientation: a rotation's roll, pitch, yaw.
    base_position: per_axis = 0.0
    base_orientation: per_axis = 0.0
    base_lin_vel: per_axis = 0.0
    base_ang_vel: per_axis = 0.0
    base_lin_vel_body_frame: per_axis = 0.0
    base_ang_vel_body_frame: per_axis = 0.0


span = Annotated[list[float], Field(min_length=2, max_length=2)]


class Randomize(ConfigModel):
    """What a ScenarioEnv reset draws anew, uniformly in [low, high] (``randomize``)."""

    # Drawn anew at every ScenarioEnv reset, uniformly in [low, high]:
    initial_joints: dict[str, span] = Field(default_factory=dict)  # measured frame
    position: Annotated[list[span], Field(min_length=3, max_length=3)] | None = None
    yaw: span | None = None  # rad, added to orientation_rpy's yaw
    lateral_friction: dict[str, span] = Field(default_factory=dict)  # link -> mu
    mass_scale: dict[str, span] = Field(default_factory=dict)  # link -> factor

    @model_validator(mode="after")
    def _ranges(self) -> Randomize:
        groups: list[tuple[str, Any, float | None]] = [
            ("initial_joints", self.initial_joints, None),
            ("lateral_friction", self.lateral_friction, 0.0),
            ("mass_scale", self.mass_scale, 1e-9)]
        for label, table, floor in groups:
            for key, (lo, hi) in table.items():
                if lo > hi:
                    raise ValueError(f"{label}.{key}: low {lo} is above high {hi}")
                if floor is not None and lo < floor:
                    raise ValueError(f"{label}.{key}: must be "
                                     f"{'> 0' if floor else '>= 0'}, got {lo}")
        for label, pair in (("yaw", self.yaw), *(
                (f"position[{i}]", r) for i, r in enumerate(self.position or []))):
            if pair is not None and pair[0] > pair[1]:
                raise ValueError(f"{label}: low {pair[0]} is above high {pair[1]}")
        return self


class RobotConfig(ConfigModel):
    """One robot: its file, pose, controller, servo, sensors (``robots[i]``)."""

    name: Annotated[str, Field(min_length=1)] | None = None
    template: str | None = None
    params: dict[str, Any] = Field(default_factory=dict)
    urdf: str | None = None
    position: vec3 = Field(default_factory=lambda: [0.0, 0.0, 0.0])
    orientation_rpy: vec3 | None = None
    orientation_quat: vec4 | None = None
    up: Literal["z", "y", "x"] = "z"
    # What position/orientation place: the root link's URDF frame, or its centre of mass
    # (PyBullet's base frame, as resetBasePositionAndOrientation takes it).
    pose_frame: Literal["link", "com"] = "link"
    base: Literal["floating", "fixed", "on_rack"] = "floating"
    base_velocity: vec3 = Field(default_factory=lambda: [0.0, 0.0, 0.0])
    base_angular_velocity: vec3 = Field(default_factory=lambda: [0.0, 0.0, 0.0])
    link_dynamics: dict[str, LinkDynamics] = Field(default_factory=dict)
    # Apply the file's <gazebo reference> mu1/mu2/kp/kd (PyBullet ignores them) at load;
    # link_dynamics overrides them.
    gazebo_contacts: bool = False
    # Honour <mimic> (a gear constraint per follower); false: raw PyBullet, which ignores it.
    mimic: bool = True
    inertia_from_file: bool = True
    implicit_cylinder: bool = True
    self_collision: bool = False
    # None: physics.linear_damping / angular_damping.
    linear_damping: non_negative | None = None
    angular_damping: non_negative | None = None
    # Dry (Coulomb) friction per joint, N m or N: PyBullet's joint motor at velocity 0.
    joint_friction: dict[str, non_negative] = Field(default_factory=dict)
    initial_joints: dict[str, InitialJoint] = Field(default_factory=dict)
    drive: list[DriveSegment] | None = None
    vehicle: Vehicle | None = None
    joints: list[JointSegment] | None = None
    motor: Motor | None = None
    motor_offsets: dict[str, float] = Field(default_factory=dict)
    motor_directions: dict[str, Literal[1, -1]] = Field(default_factory=dict)
    noise: Noise | None = None
    delay: Annotated[int, Field(ge=0)] = 0
    # Simulation.history keeps the last N reported observations, one per physics step.
    history: Annotated[int, Field(ge=1, le=100_000)] = 1
    # Per-episode randomisation, used by urdfkit.gym.ScenarioEnv's reset.
    randomize: Randomize | None = None


class ScenarioConfig(ConfigModel):
    """A whole scenario document."""

    physics: Physics = Field(default_factory=Physics)
    ground: Ground | None = None
    duration: positive = 1.0
    seed: int = 0
    record: RecordConfig = Field(default_factory=RecordConfig)
    robots: Annotated[list[RobotConfig], Field(min_length=1)]

    _source: str | None = PrivateAttr(default=None)
    _base_dir: Path = PrivateAttr(default_factory=Path.cwd)
    _notes: list[str] = PrivateAttr(default_factory=list)

    @property
    def notes(self) -> list[str]:
        """What importing a simulation_and_control config had to say (warnings)."""
        return self._notes

    @property
    def source(self) -> str | None:
        """The file this scenario came from (for messages), if any."""
        return self._source

    @property
    def base_dir(self) -> Path:
        """The folder relative ``urdf`` paths are resolved against."""
        return self._base_dir

    def path_of(self, name: str) -> str:
        """A ``urdf`` value as a path: next to the scenario if there, else as given.

        "As given" lets :func:`urdfkit.sources.resolve.locate` find ``plane.urdf`` in pybullet_data.
        """
        candidate = self._base_dir / Path(name).expanduser()
        try:
            return str(candidate) if os.path.lexists(candidate) else name
        except (OSError, ValueError):  # too long a name, a NUL byte: locate says so
            return name
