"""One robot of a simulation: the typed handle :class:`~urdfkit.sim.Simulation` keeps per body.

A :class:`SimRobot` knows its body as the engine loaded it (joints, links, the measured frame
of offsets and directions), the command it is under, and changes its own physical parameters
(the ``set_*`` setters). What its sensors last read is in :attr:`SimRobot.readings`
(:class:`Readings`, kept by :class:`~urdfkit.motion.sim_sensors.Sensors`).
"""

from __future__ import annotations

import functools
import math
import random
from collections import deque
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from typing import TYPE_CHECKING

from urdfkit.core.errors import ParameterError
from urdfkit.motion.sim_state import Command, JointSpec, Observation

if TYPE_CHECKING:
    from urdfkit.engine.api import LoadSettings, Simulator
    from urdfkit.motion.scenario_models import RobotConfig
    from urdfkit.motion.vehicle import Drivetrain

#: A mass property as changeDynamics takes it: a mass, or an inertia diagonal.
MassValue = float | list[float]


@dataclass
class Readings:
    """What a robot's sensors keep between steps: history, reports, the noise generator.

    Attributes:
        rng: The noise generator (seeded per robot).
        history: True observations, newest last (as many as ``delay`` and ``history`` need).
        reports: The last ``history`` reported observations, when ``history`` > 1.
        reported: The step and the observation last reported (one per step).
        previous_velocities: The active joints' physical velocities when last taken...
        previous_step: ...and the step they were taken at (accelerations span them).
    """

    rng: random.Random
    history: deque[Observation]
    reports: deque[Observation] | None = None
    reported: tuple[int, Observation] | None = None
    previous_velocities: list[float] | None = None
    previous_step: int = -1

    def restart(self, rng: random.Random) -> None:
        """Forget everything read (an episode starts over), with a new generator."""
        self.rng = rng
        self.history.clear()
        if self.reports is not None:
            self.reports.clear()
        self.previous_velocities = None
        self.previous_step = -1
        self.reported = None


@dataclass(eq=False)
class SimRobot:
    """A loaded robot: its joints and links, frames, command and physical parameters.

    Attributes:
        engine: The simulation's world.
        name: The robot's name in the scenario.
        path: ``robots[i]``, for messages.
        config: Its scenario table.
        body: The engine's body id.
        joints: Every joint, in the engine's order.
        links: Link name to index (the root link is -1).
        loaded: The file the engine loaded, and how (the dynamics models load it again).
        readings: What its sensors keep (:class:`Readings`).
        offsets, directions: The measured frame: ``(q - offset) * direction``.
        train: The drive train of a ``drive`` robot.
        servo: The joints the servo model drives (empty: no servo).
        applied: The command in force at the last step; override: one set from Python.
        torques: Torques given in TORQUE_CONTROL for the coming step (physical frame):
            PyBullet reports 0 as a torque-controlled joint's applied torque.
        kp, kd: The servo's gains (:meth:`set_motor_gains` changes them).
        dry_friction: Joint index to dry friction, N m or N.
        changes: ``set_mass``/``set_inertia`` changes, (link, changeDynamics key) to the
            latest value, in the order first made (mass before the inertia it rescales).
        mass_version: Counts those changes (a dynamics model older than it is stale).
        contact_links, force_joints, pose_links, feet: What ``record`` asks of this robot.
    """

    engine: Simulator
    name: str
    path: str
    config: RobotConfig
    body: int
    joints: list[JointSpec]
    links: dict[str, int]
    loaded: tuple[str, LoadSettings]
    readings: Readings
    offsets: dict[str, float] = field(default_factory=dict)
    directions: dict[str, float] = field(default_factory=dict)
    train: Drivetrain | None = None
    servo: list[JointSpec] = field(default_factory=list)
    applied: Command | None = None
    override: Command | None = None
    torques: dict[str, float] = field(default_factory=dict)
    kp: float | dict[str, float] = 0.0
    kd: float | dict[str, float] = 0.0
    dry_friction: dict[int, float] = field(default_factory=dict)
    changes: dict[tuple[int, str], MassValue] = field(default_factory=dict)
    mass_version: int = 0
    contact_links: dict[str, int] = field(default_factory=dict)
    force_joints: dict[str, int] = field(default_factory=dict)
    pose_links: list[str] = field(default_factory=list)
    feet: dict[str, int] = field(default_factory=dict)  # label -> link index

    @functools.cached_property
    def active(self) -> list[JointSpec]:
        """The joints with one degree of freedom: measured and driven."""
        return [j for j in self.joints if j.active]

    @functools.cached_property
    def frame(self) -> tuple[list[int], list[str], list[float], list[float]]:
        """The active joints' indices, names, directions and offsets, in order (fixed)."""
        return ([j.index for j in self.active], [j.name for j in self.active],
                [self.directions.get(j.name, 1.0) for j in self.active],
                [self.offsets.get(j.name, 0.0) for j in self.active])

    # ---- joints and frames

    def joint(self, name: str) -> JointSpec:
        """The joint named ``name`` (KeyError if none)."""
        for j in self.joints:
            if j.name == name:
                return j
        raise KeyError(name)

    def to_physical(self, name: str, measured: float) -> float:
        """A measured joint position as the engine's: ``measured * direction + offset``."""
        return measured * self.directions.get(name, 1.0) + self.offsets.get(name, 0.0)

    def joint_limits(self, name: str) -> tuple[float, float, float, float]:
        """The URDF's lower, upper, effort and velocity limits of a joint, as loaded.

        As the engine read them (PyBullet: a continuous joint's lower 0 and upper -1).
        """
        info = self.engine.joints(self.body)[self.joint(name).index]
        return info.lower, info.upper, info.effort, info.velocity

    def link_mass(self, link: str) -> float:
        """A link's mass now, kg."""
        return float(self.engine.dynamics(self.body, self.link_index(link)).mass)

    def link_index(self, link: str) -> int:
        """The engine's index of a link (-1: the root); ParameterError naming it if none."""
        if link not in self.links:
            from urdfkit.core.suggest import hint

            raise ParameterError(f"`link`: {self.name} has no link named {link!r}"
                                 f"{hint(link, self.links)}", param="link")
        return self.links[link]

    def joint_named(self, joint: str) -> JointSpec:
        """The joint ``joint``; ParameterError naming it if the robot has none."""
        try:
            return self.joint(joint)
        except KeyError:
            raise ParameterError(f"`joint`: {self.name} has no joint named {joint!r}",
                                 param="joint") from None

    # ---- poses

    def base_position(self) -> list[float]:
        """The base's centre of mass, world (the engine's base pose)."""
        return list(self.engine.base_pose(self.body)[0])

    def link_pose(self, link: str) -> tuple[list[float], list[float]]:
        """World position and orientation (x, y, z, w) of a link's URDF frame."""
        index = self.links.get(link)
        if index is None:
            from urdfkit.core.suggest import hint

            raise ParameterError(f"`link`: {self.name} has no link named {link!r}"
                                 f"{hint(link, self.links)}", param="link")
        pos, orn = self.engine.link_frame(self.body, index)
        return list(pos), list(orn)

    def link_frames(self) -> list[tuple[Sequence[float], Sequence[float]]]:
        """Every URDF link frame's world pose now, base first (``(xyz, xyzw)``)."""
        return list(self.engine.link_frames(self.body))

    # ---- commands and motors

    def command(self, t: float) -> Command | None:
        """The command in force at time ``t``: the override, else the scenario's segment."""
        if self.override is not None:
            return self.override
        cfg = self.config
        if cfg.drive is not None:
            segs = cfg.drive
            seg = next((s for s in segs if t < s.until - 1e-9), segs[-1])
            return Command("drive", throttle=seg.throttle, steer=seg.steer)
        if cfg.joints is not None:
            jsegs = cfg.joints
            jseg = next((s for s in jsegs if t < s.until - 1e-9), jsegs[-1])
            mode = dict(jseg.mode) if isinstance(jseg.mode, dict) else jseg.mode
            return Command("joints", mode=mode, targets=dict(jseg.targets),
                           max_force=jseg.max_force, velocities=dict(jseg.velocities))
        return None

    def free(self, indices: Sequence[int] | None = None) -> None:
        """Switch the joints' velocity motors to their dry friction (0: free).

        A velocity motor with target 0 and a force limit is Coulomb friction: it holds the
        joint against up to that much torque and slows it by that much when it moves. It
        works alongside torque commands (the servo); position and velocity commands use the
        same motor and replace it while they drive the joint.
        """
        joints = [j.index for j in self.active] if indices is None else list(indices)
        if joints:
            self.engine.motors(self.body, joints, "velocity", [0.0] * len(joints),
                               forces=[self.dry_friction.get(j, 0.0) for j in joints])

    def release(self) -> None:
        """Before a new command: free every joint the last one drove, forget its torques."""
        if self.applied is not None:
            # A position motor set by the last segment would otherwise keep fighting a
            # torque command.
            self.free()
            self.torques.clear()

    def motor_driven(self, spec: JointSpec) -> bool:
        """Whether a position or velocity command (no servo) holds this joint's motor now."""
        cmd = self.applied
        if cmd is None or self.servo:
            return False
        if cmd.kind == "drive":
            return self.train is not None and spec.index in (*self.train.wheels,
                                                             *self.train.hinges)
        return spec.name in cmd.targets and cmd.mode_of(spec.name) != "torque"

    # ---- setters: physical parameters

    def change(self, link: str | None, **values: float) -> None:
        """Change the dynamics of one link, or of all if ``link`` is None.

        By PyBullet's changeDynamics names (:meth:`~urdfkit.engine.api.Simulator.change_dynamics`).
        """
        links = [self.link_index(link)] if link is not None else \
            [-1, *range(len(self.joints))]
        for index in links:
            self.engine.change_dynamics(self.body, index, **values)

    def _mass_change(self, index: int, values: Mapping[str, MassValue]) -> None:
        self.engine.change_dynamics(self.body, index, **values)
        for key, value in values.items():
            self.changes[(index, key)] = value
        self.mass_version += 1

    def set_mass(self, link: str, mass: float) -> None:
        """A link's mass, kg; its inertia scales with it (the same body, heavier).

        PyBullet's changeDynamics(mass=...) alone throws the inertia away and recomputes it
        from the collision shapes (a link without any gets ~1e-6): not what "heavier" means.
        """
        index = self.link_index(link)
        info = self.engine.dynamics(self.body, index)
        old, diagonal = info.mass, info.inertia
        self._mass_change(index, {"mass": float(mass)})
        if old > 0:
            self._mass_change(index, {"localInertiaDiagonal":
                                      [float(v) * float(mass) / old for v in diagonal]})

    def set_inertia(self, link: str, diagonal: Sequence[float]) -> None:
        """A link's principal moments of inertia, kg m^2 (in its inertial frame)."""
        self._mass_change(self.link_index(link),
                          {"localInertiaDiagonal": [float(v) for v in diagonal]})

    def set_joint_damping(self, joint: str, damping: float) -> None:
        """The joint damping of one joint (N m s/rad; PyBullet's ``jointDamping``)."""
        spec = self.joint_named(joint)
        self.engine.change_dynamics(self.body, spec.index, jointDamping=float(damping))

    def set_joint_friction(self, joint: str, friction: float) -> None:
        """A joint's dry (Coulomb) friction, N m (N for a prismatic joint); 0 removes it.

        The joint holds against up to ``friction`` of torque and is slowed by that much when
        it moves (PyBullet's joint motor at velocity 0 with that force limit). While a
        PyBullet position or velocity command drives the joint (a ``joints`` segment without
        a ``motor`` table, or a car's wheels and hinges), that command owns the motor; the
        friction comes back when it ends. It stays across ``reset()``.
        """
        spec = self.joint_named(joint)
        if spec not in self.active:
            raise ParameterError(f"`joint`: {joint} of {self.name} is fixed", param="joint")
        if not (isinstance(friction, (int, float)) and math.isfinite(friction)
                and friction >= 0):
            raise ParameterError(f"`friction` must be a finite number >= 0, got {friction!r}",
                                 param="friction")
        self.dry_friction[spec.index] = float(friction)
        if not self.motor_driven(spec):
            self.free([spec.index])

    def set_motor_gains(self, kp: float | Mapping[str, float] | None = None,
                        kd: float | Mapping[str, float] | None = None) -> None:
        """The servo's position and velocity gains: one for every joint, or per joint name.

        A gain not given keeps its value. Needs the robot's ``motor`` table (the servo).
        """
        if not self.servo:
            raise ParameterError(f"`robot`: {self.name} has no servo model; give it a 'motor' "
                                 "table in the scenario", param="robot")
        names = {j.name for j in self.servo}
        if kp is not None:
            self.kp = _gain("kp", kp, names, self.name)
        if kd is not None:
            self.kd = _gain("kd", kd, names, self.name)


def _gain(label: str, gain: float | Mapping[str, float], names: set[str], robot: str
          ) -> float | dict[str, float]:
    """A servo gain checked: finite, >= 0, naming only servo joints."""
    values = dict(gain) if isinstance(gain, Mapping) else {"": gain}
    for name, value in values.items():
        if name and name not in names:
            raise ParameterError(f"`{label}`: {robot}'s servo drives no joint named "
                                 f"{name!r}", param=label)
        if not (isinstance(value, (int, float)) and math.isfinite(value) and value >= 0):
            raise ParameterError(f"`{label}` must be a finite number >= 0, got {value!r}",
                                 param=label)
    return {k: float(v) for k, v in values.items()} if isinstance(gain, Mapping) \
        else float(gain)


def new_readings(seed: int, delay: int, history: int) -> Readings:
    """Empty readings for a robot with this ``delay`` and ``history``."""
    return Readings(random.Random(seed), deque(maxlen=max(delay, history - 1) + 1),
                    deque(maxlen=history) if history > 1 else None)
