"""simulation_and_control configs: recognised and mapped, key by key, onto a native scenario.

simulation_and_control's ``SimInterface`` reads a JSON config with four sections: ``sim``,
``robot_pybullet``, ``env_pybullet`` and ``robot_pin``. Most ``robot_pybullet`` keys hold one
entry per robot. :func:`convert` turns such a document into a native scenario document (the
one ``docs/scenario.md`` describes), so it runs through the same checks and the same
:class:`~urdfkit.sim.Simulation` as every scenario, and ``urdfkit sim convert`` can write it
out. Every key is either mapped or refused with a message that names it; where SimInterface's
behaviour is odd, the import follows it and says so in a note (``Imported.notes``), which the
CLI prints as warnings. ``docs/scenario.md`` ("Coming from simulation_and_control") lists the
mapping.

What SimInterface does that a native scenario then does too:

- Its servo (``ServoMotorModel.compute_torque``) reads the *reported* state (delayed, noisy),
  is never clipped, and multiplies its friction and elastic terms by the joint-space mass
  matrix: ``motor.measured_state``, ``max_torque = "unlimited"``, ``scale_by_mass_matrix``.
- Its noise values (``*_cov``) are used as standard deviations, not variances; the
  orientation's is a roll-pitch-yaw rotation.
- It loads with ``URDF_USE_INERTIA_FROM_FILE`` only (cylinders become meshes), on
  ``plane.urdf``, 30 solver iterations, no cone friction.
"""

from __future__ import annotations

import math
import os
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, Any

from urdfkit.core.errors import InputError

if TYPE_CHECKING:
    from urdfkit.engine.api import JointKind

#: The top-level sections of a simulation_and_control config.
SECTIONS = ("sim", "robot_pybullet", "env_pybullet", "robot_pin")

#: robot_pybullet keys, each a list with one entry per robot (except the two velocities).
ROBOT_KEYS = (
    "urdf_path", "robot_description_model", "floating_base_name", "base_type",
    "collision_enable", "init_link_base_position", "init_link_base_orientation",
    "init_link_base_vel", "init_link_base_ang_vel", "init_motor_angles", "init_motor_vel",
    "motor_offset", "motor_direction", "servo_pos_gains", "servo_vel_gains", "motor_damping",
    "motor_damping_coeff", "motor_elastic_torque", "motor_elastic_coeff", "motor_inertia",
    "motor_inertia_coeff", "foot_friction", "foot_restitution",
    "enable_feet_joint_force_sensors", "noise_flag", "robot_noise", "delay_measure_flag",
    "delay_measure_steps",
)
SIM_KEYS = ("time_step", "experiment_duration", "feet_contact_names", "FL", "FR", "RL", "RR")
ENV_KEYS = ("env_script_name",)
PIN_KEYS = ("urdf_path", "robot_description_model", "base_type",
            "joint_state_conversion_active", "control_groups")
FOOT_LABELS = ("FL", "FR", "RL", "RR")
#: robot_pybullet keys SimInterface's constructor indexes directly (a missing one stops it
#: with a KeyError), each with what urdfkit runs with instead: the value that means "off".
#: (urdf_path, init_motor_angles and the servo gains have no such value: urdfkit needs them.)
SIM_INDEXES: dict[str, str] = {
    "robot_description_model": "none", "floating_base_name": "none",
    "base_type": "floating", "collision_enable": "off", "init_link_base_orientation": "as loaded",
    "init_link_base_vel": "at rest", "init_link_base_ang_vel": "at rest",
    "init_motor_vel": "at rest", "motor_offset": "0", "motor_direction": "1",
    "motor_damping": "off", "motor_damping_coeff": "0", "motor_elastic_torque": "off",
    "motor_elastic_coeff": "0", "motor_inertia": "off", "motor_inertia_coeff": "0",
    "foot_friction": "1", "foot_restitution": "0", "enable_feet_joint_force_sensors": "none",
    "noise_flag": "off", "robot_noise": "none", "delay_measure_flag": "off",
}

#: robot_noise key -> the native noise fields it sets.
NOISE_KEYS: dict[str, tuple[str, ...]] = {
    "joint_cov": ("motor_angles",), "joint_vel_cov": ("motor_velocities",),
    "joint_acc_cov": ("motor_accelerations",), "joint_torque_cov": ("motor_torques",),
    "base_pos_cov": ("base_position",), "base_ori_cov": ("base_orientation",),
    "base_lin_vel_cov": ("base_lin_vel", "base_lin_vel_body_frame"),
    "base_ang_vel_cov": ("base_ang_vel", "base_ang_vel_body_frame"),
}


def is_config(data: object) -> bool:
    """Whether a document is a simulation_and_control config (a section of theirs on top).

    No native scenario key is one of their section names.
    """
    return isinstance(data, Mapping) and any(key in data for key in SECTIONS)


@dataclass
class Imported:
    """A simulation_and_control config as a native scenario.

    Attributes:
        scenario: The native scenario document (plain data; ``urdf`` paths absolute).
        notes: Where the import follows SimInterface's odd behaviour, or drops what
            SimInterface drops: one line each, naming the key.
    """

    scenario: dict[str, Any]  # the JSON document: a native scenario's tables
    notes: list[str] = field(default_factory=list)


@dataclass
class _Robot:
    """What the import needs to know of one robot's URDF (from PyBullet itself)."""

    path: Path
    joints: list[str]  # every joint, in PyBullet's index order
    active: list[str]  # the non-fixed ones: SimInterface's motors, in its order
    links: dict[str, str]  # child link -> joint
    types: dict[str, JointKind]


class _Reader:
    """The document, with errors that name the key (``robot_pybullet.base_type[1]``)."""

    def __init__(self, data: Mapping[str, object], source: str | None):
        self.data = data
        self.source = source
        self.notes: list[str] = []

    def fail(self, where: str, message: str) -> InputError:
        return InputError(f"{where}: {message} (a simulation_and_control config)",
                          file=self.source)

    def section(self, name: str, known: Sequence[str]) -> Mapping[str, object]:
        value = self.data.get(name, {})
        if not isinstance(value, Mapping):
            raise self.fail(name, "expected an object")
        for key in value:
            if key not in known:  # SimInterface never looks at it: say so, and go on
                self.notes.append(f"{name}.{key}: not a key SimInterface reads, so it has no "
                                  "effect there, nor here")
        return value

    def per_robot(self, section: Mapping[str, object], where: str, key: str, count: int,
                  default: object = None) -> list[object]:
        """The key's list, one entry per robot (a missing key: ``default`` for each)."""
        if key not in section:
            if default is None:
                raise self.fail(f"{where}.{key}", "required key is missing")
            return [default] * count
        value = section[key]
        if not isinstance(value, list) or len(value) != count:
            got = f"{len(value)} entries" if isinstance(value, list) else type(value).__name__
            raise self.fail(f"{where}.{key}", f"expected a list with one entry per robot "
                                              f"({count}), got {got}")
        return value


def _number(reader: _Reader, where: str, value: object) -> float:
    if isinstance(value, bool) or not isinstance(value, (int, float)) or \
            not math.isfinite(value):
        raise reader.fail(where, f"expected a finite number, got {value!r}")
    return float(value)


def _flag(reader: _Reader, where: str, value: object) -> bool:
    if isinstance(value, bool) or value in (0, 1):
        return bool(value)
    raise reader.fail(where, f"expected true/false (or 0/1), got {value!r}")


def _vector(reader: _Reader, where: str, value: object, size: int) -> list[float]:
    if not isinstance(value, list) or len(value) != size:
        raise reader.fail(where, f"expected {size} numbers, got {value!r}")
    return [_number(reader, f"{where}[{k}]", v) for k, v in enumerate(value)]


def _per_joint(reader: _Reader, where: str, value: object, names: Sequence[str], *,
               one_ok: bool, non_negative: bool = False) -> float | dict[str, float]:
    """A scalar, or a list over the motors (a 1-list too when ``one_ok``, as adjust_value)."""
    if isinstance(value, list):
        if one_ok and len(value) == 1:
            value = value[0]
        elif len(value) != len(names):
            raise reader.fail(where, f"expected {len(names)} values, one per motor "
                                     f"({', '.join(names) or 'none'}), got {len(value)}")
        else:
            out = {n: _number(reader, f"{where}[{k}]", v)
                   for k, (n, v) in enumerate(zip(names, value, strict=True))}
            if non_negative and any(v < 0 for v in out.values()):
                raise reader.fail(where, "must be >= 0")
            return out
    number = _number(reader, where, value)
    if non_negative and number < 0:
        raise reader.fail(where, "must be >= 0")
    return number


def _resolve_urdf(reader: _Reader, where: str, name: object, base: Path) -> Path:
    """Where SimInterface finds ``urdf_path``: ``<configs>/../models/<name>``.

    SimInterface reads its configs from ``<root>/configs`` and URDFs from ``<root>/models``.
    The folder of the config itself and an absolute path are tried too.
    """
    if not isinstance(name, str) or not name:
        raise reader.fail(where, f"expected a file name, got {name!r}")
    import stat

    given = Path(name).expanduser()
    for candidate in (base.parent / "models" / given, base / "models" / given, base / given,
                      given):
        try:
            mode = os.stat(candidate).st_mode
        except FileNotFoundError:
            continue
        except (OSError, ValueError) as e:  # too long a name, a NUL byte, a loop
            raise reader.fail(where, f"cannot read {name}: "
                                     f"{getattr(e, 'strerror', None) or e}") from None
        if stat.S_ISREG(mode):
            return Path(os.path.abspath(candidate))
        what = ("a directory" if stat.S_ISDIR(mode) else "a FIFO (named pipe)"
                if stat.S_ISFIFO(mode) else "a device or socket")
        raise reader.fail(where, f"{candidate} is {what}, not a URDF file")
    raise reader.fail(where, f"no such file: {name} (looked in {base.parent / 'models'}, "
                             f"{base / 'models'} and {base})")


def _inspect(path: Path, display: str) -> _Robot:
    """Joint names and order as PyBullet indexes them (through urdfkit's guarded loader)."""
    from urdfkit.engine.api import LoadSettings
    from urdfkit.engine.registry import open_engine
    from urdfkit.sources.resolve import open_input

    with open_input(str(path)) as resolved:
        engine = open_engine("pybullet")
        try:
            body = engine.load(str(resolved.load_path), LoadSettings(fixed_base=True),
                               display=display)
            infos = engine.joints(body)
        finally:
            engine.close()
    joints: list[str] = []
    active: list[str] = []
    links: dict[str, str] = {}
    types: dict[str, JointKind] = {}
    for info in infos:
        joints.append(info.name)
        types[info.name] = info.kind
        links[info.link] = info.name
        if info.kind != "fixed":
            active.append(info.name)
    return _Robot(path, joints, active, links, types)


def convert(data: Mapping[str, object], *, source: str | Path | None = None) -> Imported:
    """Map a simulation_and_control config onto a native scenario document.

    Args:
        data: The parsed JSON.
        source: The config file; ``urdf_path`` is resolved against its folder as
            SimInterface does (``../models/<urdf_path>``), and messages name it.

    Raises:
        InputError: a key that cannot be mapped (naming it and why), a malformed value, or a
            URDF that cannot be found or loaded.
    """
    src = None if source is None else str(source)
    reader = _Reader(data, src)
    for key in data:
        if key not in SECTIONS:  # SimInterface never looks at it
            reader.notes.append(f"{key}: not a section SimInterface reads (it reads "
                                f"{', '.join(SECTIONS)}), so it has no effect there, nor here")
    base = Path(source).resolve().parent if source is not None else Path.cwd()
    sim = reader.section("sim", SIM_KEYS)
    rp = reader.section("robot_pybullet", ROBOT_KEYS)
    env = reader.section("env_pybullet", ENV_KEYS)
    pin = reader.section("robot_pin", PIN_KEYS)
    for key, off in SIM_INDEXES.items():
        if key not in rp:
            reader.notes.append(f"robot_pybullet.{key}: missing; SimInterface stops with a "
                                f"KeyError without it, urdfkit runs with {off}")
    time_step = _time_step(reader, sim, env)
    if "robot_pybullet" not in data:
        raise reader.fail("robot_pybullet", "required section is missing")
    robots = _load_robots(reader, rp, base)
    conv = _Converter(reader, sim, rp, len(robots))
    out_robots = [conv.robot(i, robot) for i, robot in enumerate(robots)]
    _damping(robots, out_robots, reader.notes)
    if pin:
        reader.notes.append("robot_pin: the Pinocchio model is not simulated; Simulation's "
                            "mass_matrix, gravity_torques, coriolis_and_gravity and jacobian "
                            "give PyBullet's own")
    scenario: dict[str, object] = {
        # SimInterface's engine settings; contacts in the engine's own order, not sorted.
        "physics": {"time_step": time_step, "gravity": [0.0, 0.0, -9.81],
                    "solver_iterations": 30, "cone_friction": False,
                    "deterministic_pairs": False},
        "ground": "plane.urdf",
        "record": conv.record(),
        "robots": out_robots,
    }
    if "experiment_duration" in sim:
        duration = _number(reader, "sim.experiment_duration", sim["experiment_duration"])
        if duration <= 0:
            raise reader.fail("sim.experiment_duration", "must be > 0 s")
        scenario["duration"] = duration
    return Imported(scenario, reader.notes)


def _time_step(reader: _Reader, sim: Mapping[str, object], env: Mapping[str, object]) -> float:
    """``sim.time_step``, after refusing an ``env_script_name`` (code urdfkit never runs)."""
    script = env.get("env_script_name", "")
    if script:
        raise reader.fail("env_pybullet.env_script_name",
                          f"{script!r} is a Python script SimInterface runs line by line with "
                          "exec; urdfkit runs no code from a config. Remove it and add what it "
                          "builds as robots (or a ground) of the scenario")
    if "time_step" not in sim:
        raise reader.fail("sim.time_step", "required key is missing")
    time_step = _number(reader, "sim.time_step", sim["time_step"])
    if not 0 < time_step <= 1:
        raise reader.fail("sim.time_step", "must be in (0, 1] s")
    return time_step


def _load_robots(reader: _Reader, rp: Mapping[str, object], base: Path) -> list[_Robot]:
    """Each ``urdf_path``, found as SimInterface finds it and loaded to read its joints."""
    paths = rp.get("urdf_path")
    if not isinstance(paths, list) or not paths:
        raise reader.fail("robot_pybullet.urdf_path", "expected a list of URDF files, one per "
                                                      "robot (SimInterface requires a list)")
    models = reader.per_robot(rp, "robot_pybullet", "robot_description_model", len(paths), "")
    robots: list[_Robot] = []
    for i, name in enumerate(paths):
        if models[i]:
            raise reader.fail(f"robot_pybullet.robot_description_model[{i}]",
                              f"{models[i]!r} names a robot_descriptions package, which "
                              "urdfkit does not download; set it to \"\" and give the file in "
                              "urdf_path")
        where = f"robot_pybullet.urdf_path[{i}]"
        path = _resolve_urdf(reader, where, name, base)
        try:
            robot = _inspect(path, f"{where} ({name})")
        except InputError as e:
            raise reader.fail(where, str(e)) from None
        odd = [n for n in robot.active if robot.types[n] not in ("revolute", "prismatic")]
        if odd:
            raise reader.fail(where, f"joint {odd[0]!r} is neither revolute nor prismatic: "
                                     "SimInterface's motors need 1-DOF joints")
        robots.append(robot)
    return robots


class _Converter:
    """The per-robot part of :func:`convert`: one native robot document per config robot."""

    def __init__(self, reader: _Reader, sim: Mapping[str, object], rp: Mapping[str, object],
                 count: int) -> None:
        self.reader, self.sim, self.rp, self.count = reader, sim, rp, count
        self.notes = reader.notes
        self.feet_names = reader.per_robot(sim, "sim", "feet_contact_names", count, [])
        self.labels = {label: reader.per_robot(sim, "sim", label, count, [])
                       for label in FOOT_LABELS}
        self.base_types = self.get("base_type", "floating")
        self.feet_record: dict[str, str] = {}
        self.joint_forces: list[str] = []
        self.link_poses: list[str] = []
        self.used_names: set[str] = set()

    def get(self, key: str, default: object = None) -> list[object]:
        """A ``robot_pybullet`` key, one value per robot."""
        return self.reader.per_robot(self.rp, "robot_pybullet", key, self.count, default)

    def record(self) -> dict[str, object]:
        """What the scenario records: torques, and the feet, forces and poses met."""
        record: dict[str, object] = {"motor_torques": True}
        if self.feet_record:
            record["feet"] = self.feet_record
        if self.joint_forces:
            record["joint_forces"] = self.joint_forces
        if self.link_poses:
            record["link_poses"] = self.link_poses
        return record

    def robot(self, i: int, robot: _Robot) -> dict[str, object]:
        """The native document of robot ``i``."""
        w = f"robot_pybullet.{{}}[{i}]"
        doc = self._body(i, robot, w)
        self._motors(doc, i, robot.active, w)
        self._feet(doc, i, robot, w)
        self._sensors(i, robot, w)
        self._base_link(i, robot, w)
        reader = self.reader
        if _flag(reader, w.format("noise_flag"), self.get("noise_flag", False)[i]):
            doc["noise"] = _noise(reader, w.format("robot_noise"),
                                  self.get("robot_noise", {})[i], robot.active)
        if _flag(reader, w.format("delay_measure_flag"),
                 self.get("delay_measure_flag", False)[i]):
            steps = self.get("delay_measure_steps")[i]
            if isinstance(steps, bool) or not isinstance(steps, int) or steps < 0:
                raise reader.fail(w.format("delay_measure_steps"),
                                  f"expected an integer >= 0, got {steps!r}")
            doc["delay"] = steps
        return doc

    def _body(self, i: int, robot: _Robot, w: str) -> dict[str, object]:
        """Name, file, base type, self-collision, start pose and base velocity."""
        reader, get = self.reader, self.get
        doc: dict[str, object] = {}
        stem = robot.path.stem or f"robot{i}"
        name = stem if stem not in self.used_names else f"{stem}_{i}"
        self.used_names.add(name)
        doc["name"] = name
        doc["urdf"] = str(robot.path)
        doc["implicit_cylinder"] = False  # SimInterface loads with URDF_USE_INERTIA_FROM_FILE
        base_type = self.base_types[i]
        if base_type not in ("fixed", "floating", "on_rack"):
            raise reader.fail(w.format("base_type"),
                              f"expected \"fixed\", \"floating\" or \"on_rack\", got "
                              f"{base_type!r}")
        doc["base"] = base_type
        if base_type == "on_rack":
            self.notes.append(f"{w.format('base_type')}: on_rack: SimInterface pins its rack at "
                              "the world origin and its Step then fails (no mass matrix for "
                              "on_rack); urdfkit holds the base where it starts")
        doc["self_collision"] = _flag(reader, w.format("collision_enable"),
                                      get("collision_enable", False)[i])
        # Pose: SimInterface's is the base's centre of mass (resetBasePositionAndOrientation).
        orientation = get("init_link_base_orientation", [])[i]
        if orientation:
            doc["orientation_quat"] = _vector(reader, w.format("init_link_base_orientation"),
                                              orientation, 4)
            doc["position"] = _vector(reader, w.format("init_link_base_position"),
                                      get("init_link_base_position")[i], 3)
            doc["pose_frame"] = "com"
        if base_type == "floating":
            doc.update(_base_velocity(reader, self.rp, self.notes))
        return doc

    def _motors(self, doc: dict[str, object], i: int, names: list[str], w: str) -> None:
        """Offsets, directions, initial joints (in the measured frame) and the servo."""
        reader, get, n = self.reader, self.get, len(names)
        offsets = get("motor_offset", [])[i]
        directions = get("motor_direction", [])[i]
        offset = [0.0] * n if not offsets else \
            _vector(reader, w.format("motor_offset"), offsets, n)
        direction = [1.0] * n if not directions else \
            _vector(reader, w.format("motor_direction"), directions, n)
        if any(d not in (1.0, -1.0) for d in direction):
            raise reader.fail(w.format("motor_direction"), "urdfkit takes 1 or -1 per motor")
        if any(offset):
            doc["motor_offsets"] = {k: v for k, v in zip(names, offset, strict=True) if v}
        if any(d < 0 for d in direction):
            doc["motor_directions"] = {k: int(v) for k, v in zip(names, direction,
                                                                 strict=True) if v < 0}
        angles = get("init_motor_angles", [])[i]
        if n and not angles:
            raise reader.fail(w.format("init_motor_angles"),
                              f"needs {n} angles, one per motor ({', '.join(names)})")
        angles = _vector(reader, w.format("init_motor_angles"), angles, n) if n else []
        velocities = get("init_motor_vel", [])[i]
        velocities = _vector(reader, w.format("init_motor_vel"), velocities, n) \
            if velocities else [0.0] * n
        # SimInterface sets the joints to init_motor_angles as they are (physical angles);
        # native initial_joints are in the measured frame: (q - offset) * direction.
        doc["initial_joints"] = {
            k: {"position": (q - off) * d, "velocity": v * d}
            for k, q, v, off, d in zip(names, angles, velocities, offset, direction,
                                       strict=True)}
        doc["motor"] = self._servo(i, names, w, any(offset) or any(d < 0 for d in direction))

    def _servo(self, i: int, names: list[str], w: str, adjusted: bool) -> dict[str, object]:
        """The servo: gains through the mass matrix, friction and spring if enabled."""
        reader, get = self.reader, self.get
        motor: dict[str, object] = {
            "kp": _per_joint(reader, w.format("servo_pos_gains"), get("servo_pos_gains")[i],
                             names, one_ok=False, non_negative=True),
            "kd": _per_joint(reader, w.format("servo_vel_gains"), get("servo_vel_gains")[i],
                             names, one_ok=False, non_negative=True),
            "scale_by_mass_matrix": True, "mass_matrix_angles": "measured",
            "max_torque": "unlimited", "measured_state": True}
        for flag_key, coeff_key, native in (
                ("motor_damping", "motor_damping_coeff", "viscous_friction"),
                ("motor_elastic_torque", "motor_elastic_coeff", "stiffness")):
            if _flag(reader, w.format(flag_key), get(flag_key, False)[i]):
                motor[native] = _per_joint(reader, w.format(coeff_key), get(coeff_key, 0.0)[i],
                                           names, one_ok=True, non_negative=True)
        if ("viscous_friction" in motor or "stiffness" in motor) and adjusted:
            self.notes.append(f"{w.format('motor_damping')}: SimInterface multiplies the "
                              "friction and spring torques by a mass matrix it computes at the "
                              "offset and direction-adjusted angles, as if they were joint "
                              "angles; urdfkit follows it for parity (the physical one is at "
                              "the joint angles)")
        if _flag(reader, w.format("motor_inertia"), get("motor_inertia", False)[i]):
            coeff = _per_joint(reader, w.format("motor_inertia_coeff"),
                               get("motor_inertia_coeff", 0.0)[i], names, one_ok=True)
            if coeff:
                self.notes.append(f"{w.format('motor_inertia')}: SimInterface's servo stores "
                                  "the motor inertia but never applies it; not applied here "
                                  "either (the native motor.inertia applies one)")
        return motor

    def _feet(self, doc: dict[str, object], i: int, robot: _Robot, w: str) -> None:
        """Foot friction and restitution, and the feet recorded under their labels."""
        reader, get = self.reader, self.get
        feet = self.feet_names[i]
        if not isinstance(feet, list):
            raise reader.fail(f"sim.feet_contact_names[{i}]", "expected a list of link names")
        friction = _number(reader, w.format("foot_friction"), get("foot_friction", 1.0)[i])
        restitution = _number(reader, w.format("foot_restitution"),
                              get("foot_restitution", 0.0)[i])
        dynamics: dict[str, object] = {}
        for link in feet:
            if link not in robot.links:
                self.notes.append(f"sim.feet_contact_names[{i}]: {robot.path.name} has no "
                                  f"moving link named {link!r}; SimInterface skips it, and so "
                                  "does urdfkit")
                continue
            dynamics[link] = {"lateral_friction": friction, "restitution": restitution}
            label = next((lab for lab in FOOT_LABELS if _listed(link, self.labels[lab][i])),
                         link)
            if self.count > 1:
                label = f"{doc['name']}.{label}"
            self.feet_record[label] = link
        if dynamics:
            doc["link_dynamics"] = dynamics

    def _sensors(self, i: int, robot: _Robot, w: str) -> None:
        """The joints whose reaction forces are recorded (SimInterface's foot sensors)."""
        reader = self.reader
        sensors = self.get("enable_feet_joint_force_sensors", [])[i]
        if not sensors:
            return
        if not isinstance(sensors, list):
            raise reader.fail(w.format("enable_feet_joint_force_sensors"),
                              "expected a list of joint names")
        for lab in FOOT_LABELS:
            frames = self.labels[lab][i]
            if not (isinstance(frames, list) and set(frames) & set(sensors)):
                raise reader.fail(f"sim.{lab}[{i}]",
                                  "names none of enable_feet_joint_force_sensors' joints "
                                  "(SimInterface raises ValueError here too)")
        for joint in sensors:
            if joint not in robot.joints:  # SimInterface finds none and reads nothing
                self.notes.append(f"{w.format('enable_feet_joint_force_sensors')}: "
                                  f"{robot.path.name} has no joint named {joint!r}; "
                                  "SimInterface puts no sensor there, and neither does urdfkit")
                continue
            if joint not in self.joint_forces:
                self.joint_forces.append(joint)

    def _base_link(self, i: int, robot: _Robot, w: str) -> None:
        """The floating-base link whose pose is recorded, named by its joint."""
        base_joint = self.get("floating_base_name", "")[i]
        if not base_joint:
            return
        link = next((lk for lk, j in robot.links.items() if j == base_joint), None)
        if link is None:  # SimInterface matches no joint and records no base link
            self.notes.append(f"{w.format('floating_base_name')}: {robot.path.name} has no "
                              f"joint named {base_joint!r}; SimInterface then records no "
                              "floating-base link, and neither does urdfkit")
        elif link not in self.link_poses:
            self.link_poses.append(link)


def _listed(link: str, names: object) -> bool:
    return isinstance(names, list) and link in names


def _base_velocity(reader: _Reader, rp: Mapping[str, object], notes: list[str]
                   ) -> dict[str, object]:
    """SimInterface's initial base velocity: one 3-vector pair shared by floating robots.

    It reads ``init_link_base_vel`` and ``init_link_base_ang_vel`` without a robot index
    and sets them only when both are non-empty; PyBullet silently ignores a list of lists.
    """
    lin, ang = rp.get("init_link_base_vel", []), rp.get("init_link_base_ang_vel", [])
    if not lin or not ang:
        return {}
    if isinstance(lin, list) and isinstance(ang, list) and \
            any(isinstance(v, list) for v in (*lin, *ang)):
        notes.append("robot_pybullet.init_link_base_vel: a list per robot; SimInterface "
                     "passes the whole list to resetBaseVelocity, which ignores it (the robot "
                     "starts at rest); so does urdfkit. Give one 3-vector to set it")
        return {}
    return {"base_velocity": _vector(reader, "robot_pybullet.init_link_base_vel", lin, 3),
            "base_angular_velocity": _vector(reader, "robot_pybullet.init_link_base_ang_vel",
                                             ang, 3)}


def _noise(reader: _Reader, where: str, value: object, names: Sequence[str]) -> dict[str, object]:
    """robot_noise -> native noise (SimInterface draws N(0, value): standard deviations)."""
    if not isinstance(value, Mapping):
        raise reader.fail(where, "expected an object of *_cov values")
    out: dict[str, object] = {}
    for key, std in value.items():
        if key not in NOISE_KEYS:
            raise reader.fail(f"{where}.{key}", f"not a noise key SimInterface reads; known "
                                                f"keys: {', '.join(NOISE_KEYS)}")
        fields = NOISE_KEYS[key]
        if fields[0].startswith("motor"):
            native: object = _per_joint(reader, f"{where}.{key}", std, names, one_ok=True,
                                     non_negative=True)
        elif isinstance(std, list) and len(std) != 1:
            native = _vector(reader, f"{where}.{key}", std, 3)
            if any(v < 0 for v in native):
                raise reader.fail(f"{where}.{key}", "must be >= 0")
        else:
            native = _number(reader, f"{where}.{key}", std[0] if isinstance(std, list)
                             else std)
            if native < 0:
                raise reader.fail(f"{where}.{key}", "must be >= 0")
        for f in fields:
            out[f] = native
    return out


def _damping(robots: Sequence[_Robot], docs: list[dict[str, object]], notes: list[str]) -> None:
    """The link damping SimInterface ends up with, robot by robot.

    SimInterface means to zero PyBullet's default link damping (0.04) but passes each joint
    *index* where the body id goes: loading robot ``i`` zeroes the damping of bodies
    ``0 .. num_joints - 1`` that exist by then (the plane is body 0, robot ``k`` body
    ``k + 1``). A robot's damping is zero when some robot loaded with or after it has more
    joints than its body id; otherwise it keeps 0.04.
    """
    for k, doc in enumerate(docs):
        zeroed = any(len(robots[i].joints) >= k + 2 for i in range(k, len(robots)))
        if zeroed:
            doc["linear_damping"] = 0.0
            doc["angular_damping"] = 0.0
        else:
            notes.append(f"robot_pybullet.urdf_path[{k}]: keeps PyBullet's link damping 0.04, "
                         "as in SimInterface, which means to zero it but passes joint indices "
                         "as body ids and misses this robot")


def to_toml(imported: Imported, *, source: str | Path, out_dir: str | Path | None) -> str:
    """The native scenario as TOML, ``urdf`` paths relative to ``out_dir`` (else absolute).

    The notes head the file as comments, so what the import follows or drops stays said.
    """
    from urdfkit import __version__
    from urdfkit.model.tomlio import dumps as write

    document = dict(imported.scenario)
    if out_dir is not None:
        folder = os.path.abspath(out_dir)
        document["robots"] = [
            {**r, "urdf": os.path.relpath(r["urdf"], folder)} if "urdf" in r else r
            for r in document["robots"]]
    header = [f"Converted by urdfkit {__version__} from the simulation_and_control config "
              f"{source}.", "See docs/scenario.md, \"Coming from simulation_and_control\"."]
    if imported.notes:
        header += ["", "Notes from the import:"] + [f"- {n}" for n in imported.notes]
    return write(document, header)
