"""The plain data of a simulation: observations, joints, commands, each robot's state, results.

The public ones are re-exported by :mod:`urdfkit.sim`.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Literal

from urdfkit.motion.scenario import OBSERVATION_FIELDS

if TYPE_CHECKING:
    from urdfkit.engine.api import JointKind
    from urdfkit.motion.scenario_models import Mode

#: Joint kinds with one degree of freedom: what the joint state queries report.
_ACTIVE = ("revolute", "prismatic")


# --------------------------------------------------------------------------- observations

#: A foot's reading: contact (0 or 1), normal (N), and world, local and friction vectors.
FootReading = dict[str, int | float | list[float]]


@dataclass
class Observation:
    """One robot's state at one time: a row of the output.

    Motor fields are keyed by joint name over the robot's active (revolute, continuous and
    prismatic) joints, in the measured frame: ``(q - offset) * direction``. Base fields are
    PyBullet's base frame, which is the root link's centre of mass.

    Attributes:
        t: Simulated time, s.
        step: Physics steps since the start.
        robot: The robot's name in the scenario.
        motor_angles: Joint positions, rad or m.
        motor_velocities: Joint velocities.
        motor_accelerations: Finite difference of the velocities over one physics step.
        base_position: World position, m.
        base_orientation: World orientation, quaternion (x, y, z, w).
        base_lin_vel: World linear velocity, m/s.
        base_ang_vel: World angular velocity, rad/s.
        base_lin_vel_body_frame: ``base_lin_vel`` rotated into the base frame.
        base_ang_vel_body_frame: ``base_ang_vel`` rotated into the base frame.
        contacts: For ``record.contact_links``: ``{link: {"normal_force", "count"}}``.
        joint_forces: For ``record.joint_forces``: reaction ``[fx, fy, fz, mx, my, mz]``.
        motor_torques: With ``record.motor_torques``: the torque each joint's motor applied in
            the last step, in the joint's own frame (not the measured one), never delayed.
        link_poses: For ``record.link_poses``: each link's URDF frame, ``{"position",
            "orientation"}`` (world; quaternion x, y, z, w).
        feet: For ``record.feet``: per foot (its label, else its link name), the contact
            force the foot feels from everything but its own robot: ``{"contact": 0 or 1,
            "normal": N (summed), "world": [fx, fy, fz] (the normal forces, world frame),
            "local": the same in the foot link's frame, "friction_world": the lateral
            friction forces, world frame}``.
    """

    t: float
    step: int
    robot: str
    motor_angles: dict[str, float]
    motor_velocities: dict[str, float]
    motor_accelerations: dict[str, float]
    base_position: list[float]
    base_orientation: list[float]
    base_lin_vel: list[float]
    base_ang_vel: list[float]
    base_lin_vel_body_frame: list[float]
    base_ang_vel_body_frame: list[float]
    contacts: dict[str, dict[str, float]] | None = None
    joint_forces: dict[str, list[float]] | None = None
    motor_torques: dict[str, float] | None = None
    link_poses: dict[str, dict[str, list[float]]] | None = None
    feet: dict[str, FootReading] | None = None

    def to_dict(self) -> dict[str, object]:
        """The JSON row (optional fields only when recorded)."""
        row: dict[str, object] = {"t": self.t, "step": self.step, "robot": self.robot}
        for name in OBSERVATION_FIELDS:
            value = getattr(self, name)
            row[name] = dict(value) if isinstance(value, dict) else list(value)
        if self.contacts is not None:
            row["contacts"] = {k: dict(v) for k, v in self.contacts.items()}
        if self.joint_forces is not None:
            row["joint_forces"] = {k: list(v) for k, v in self.joint_forces.items()}
        if self.motor_torques is not None:
            row["motor_torques"] = dict(self.motor_torques)
        if self.link_poses is not None:
            row["link_poses"] = {k: {"position": list(v["position"]),
                                     "orientation": list(v["orientation"])}
                                 for k, v in self.link_poses.items()}
        if self.feet is not None:
            row["feet"] = _copy_feet(self.feet)
        return row

    def _replace(self, **changes: object) -> Observation:
        data = {**self.__dict__, **changes}
        return Observation(**data)

    def copy(self) -> Observation:
        """A copy whose dicts and lists are its own: changing it changes nothing else."""
        c, f, tq, lp, ft = (self.contacts, self.joint_forces, self.motor_torques,
                            self.link_poses, self.feet)
        return Observation(
            self.t, self.step, self.robot, dict(self.motor_angles),
            dict(self.motor_velocities), dict(self.motor_accelerations),
            list(self.base_position), list(self.base_orientation), list(self.base_lin_vel),
            list(self.base_ang_vel), list(self.base_lin_vel_body_frame),
            list(self.base_ang_vel_body_frame),
            None if c is None else {k: dict(v) for k, v in c.items()},
            None if f is None else {k: list(v) for k, v in f.items()},
            None if tq is None else dict(tq),
            None if lp is None else {k: {"position": list(v["position"]),
                                         "orientation": list(v["orientation"])}
                                     for k, v in lp.items()},
            None if ft is None else _copy_feet(ft))


def _copy_feet(feet: Mapping[str, Mapping[str, int | float | list[float]]]
               ) -> dict[str, FootReading]:
    return {k: {key: list(x) if isinstance(x, list) else x for key, x in v.items()}
            for k, v in feet.items()}


# --------------------------------------------------------------------------- robots


@dataclass
class JointSpec:
    """What the simulation needs to know of one joint of a loaded body.

    Attributes:
        index: The engine's joint index.
        name: The URDF's joint name.
        kind: ``revolute`` (continuous ones too), ``prismatic``, ``spherical``, ``planar``
            or ``fixed``, as the engine loaded it.
        effort: The URDF's effort limit (0: none given).
        child_link: The joint's child link.
    """

    index: int
    name: str
    kind: JointKind
    effort: float
    child_link: str

    @property
    def active(self) -> bool:
        """Whether the joint has one degree of freedom we measure and drive."""
        return self.kind in _ACTIVE

    @property
    def revolute(self) -> bool:
        """Whether the joint turns (revolute or continuous)."""
        return self.kind == "revolute"


#: What a command drives: a car's wheels and hinges, or joints by target.
CommandKind = Literal["drive", "joints"]


@dataclass
class Command:
    """A controller command: a drive (throttle, steer) or joint targets."""

    kind: CommandKind
    throttle: float = 0.0
    steer: float = 0.0
    mode: Mode | dict[str, Mode] = "position"  # one for all targets, or per joint
    targets: dict[str, float] = field(default_factory=dict)
    max_force: float | None = None
    velocities: dict[str, float] = field(default_factory=dict)

    def mode_of(self, joint: str) -> Mode:
        """The control mode of one target joint."""
        return self.mode if isinstance(self.mode, str) else self.mode.get(joint, "position")

    @property
    def any_torque(self) -> bool:
        """Whether some target is a torque (re-applied every step: torques last one step)."""
        if isinstance(self.mode, str):
            return self.mode == "torque" and self.kind == "joints"
        return "torque" in self.mode.values()


@dataclass
class RobotSummary:
    """What a run did to one robot, for the summary table."""

    robot: str
    rows: int
    start: list[float]
    end: list[float]
    distance: float
    top_speed: float
    heading_deg: float
    final_joints: dict[str, float]
    joint_min: dict[str, float] = field(default_factory=dict)
    joint_max: dict[str, float] = field(default_factory=dict)

    def to_dict(self) -> dict[str, object]:
        """The JSON form."""
        return dict(self.__dict__)


@dataclass
class SimResult:
    """The rows a run recorded.

    Attributes:
        rows: Reported observations (noise and delay applied), in time order.
        ideal: The true observations at the same steps (for a robot without noise or
            delay, the very objects in ``rows``: what it reports is the truth).
        time_step: Physics time step, s.
        steps: Physics steps taken.
        interrupted: Ctrl-C (or SIGTERM in the CLI) ended the run early; the rows cover the
            steps simulated.
        row_count: Rows recorded (also when the run kept none: ``keep=False``).
        summaries: Per robot: start, end, distance, top speed, final joints.
    """

    rows: list[Observation]
    ideal: list[Observation]
    time_step: float
    steps: int
    interrupted: bool = False
    row_count: int = 0
    summaries: list[RobotSummary] = field(default_factory=list)

    def to_dicts(self) -> list[dict[str, object]]:
        """The reported rows as JSON-ready dicts."""
        return [r.to_dict() for r in self.rows]


class _Summary:
    """Per robot, from the true rows as they come: first, last, count, top speed."""

    def __init__(self) -> None:
        self.first: dict[str, Observation] = {}
        self.last: dict[str, Observation] = {}
        self.count: dict[str, int] = {}
        self.top: dict[str, float] = {}
        self.low: dict[str, dict[str, float]] = {}
        self.high: dict[str, dict[str, float]] = {}
        self.rows = 0

    def add(self, truth: list[Observation]) -> None:
        for r in truth:
            self.first.setdefault(r.robot, r)
            self.last[r.robot] = r
            self.count[r.robot] = self.count.get(r.robot, 0) + 1
            self.top[r.robot] = max(self.top.get(r.robot, 0.0), math.hypot(*r.base_lin_vel))
            low = self.low.setdefault(r.robot, {})
            high = self.high.setdefault(r.robot, {})
            for joint, angle in r.motor_angles.items():  # the range a joint swept: overshoot
                if angle < low.get(joint, math.inf):
                    low[joint] = angle
                if angle > high.get(joint, -math.inf):
                    high[joint] = angle
        self.rows += len(truth)

    def robots(self) -> list[RobotSummary]:
        out = []
        for name, first in self.first.items():
            last = self.last[name]
            x, y, z, w = last.base_orientation
            heading = math.degrees(math.atan2(2 * (w * z + x * y), 1 - 2 * (y * y + z * z)))
            out.append(RobotSummary(
                robot=name, rows=self.count[name], start=list(first.base_position),
                end=list(last.base_position),
                distance=math.dist(first.base_position, last.base_position),
                top_speed=self.top[name], heading_deg=heading,
                final_joints=dict(last.motor_angles), joint_min=dict(self.low.get(name, {})),
                joint_max=dict(self.high.get(name, {}))))
        return out


def _first(*values: float | None) -> float | None:
    """The first of ``values`` that is given (a robot's own setting, then the world's)."""
    return next((v for v in values if v is not None), None)
