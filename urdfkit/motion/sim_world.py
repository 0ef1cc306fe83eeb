"""The world of a simulation: the engine, the ground, the robots as loaded, time, save/restore.

:class:`World` loads the ground and every robot of a scenario into its engine
(:class:`~urdfkit.engine.api.Simulator`), checks every joint and link name the scenario gives
against what the engine loaded, and keeps the starting state for :meth:`World.restore`.
"""

from __future__ import annotations

import functools
import math
import tempfile
from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import TYPE_CHECKING

from urdfkit.core.errors import EngineError, InputError, ParameterError
from urdfkit.engine.api import LoadSettings
from urdfkit.engine.registry import open_engine
from urdfkit.model.spec import UP_AXES, quat_mul, rpy_to_unit_quat
from urdfkit.motion.scenario import JOINT_NOISE_FIELDS
from urdfkit.motion.sim_robot import SimRobot, new_readings
from urdfkit.motion.sim_state import JointSpec, _first
from urdfkit.motion.stepping import StepLoop

if TYPE_CHECKING:
    from urdfkit.engine.api import Simulator
    from urdfkit.engine.pybullet import PyBulletEngine
    from urdfkit.engine.session import Bullet, Session
    from urdfkit.motion.scenario_models import RobotConfig, ScenarioConfig
    from urdfkit.sources.resolve import Resolved


def _vec3(v: Sequence[float]) -> tuple[float, float, float]:
    return (v[0], v[1], v[2])


def robot_seed(seed: int, i: int) -> int:
    """The noise seed of robot ``i`` under the scenario's (or an episode's) ``seed``."""
    return seed * 1_000_003 + i


class World:
    """One engine's world holding a scenario's ground and robots.

    Args:
        config: The scenario.
        gui: Open the engine's own window.
        engine: The engine's name (:data:`urdfkit.engine.registry.ENGINES`); default: the
            scenario's ``physics.engine``.

    Attributes:
        config: The scenario.
        engine: The world of this simulation alone, in its engine.
        loop: Its step loop, which counts the steps (``time_step``, ``step_count``).
        ground: The ground's body id (None: no ground).
        robots: The robots by name, in scenario order.
    """

    def __init__(self, config: ScenarioConfig, *, gui: bool = False,
                 engine: str | None = None) -> None:
        self.config = config
        self.ground: int | None = None
        self.robots: dict[str, SimRobot] = {}
        self._resolved: list[Resolved] = []
        self._start_state = -1
        self._tmp = tempfile.TemporaryDirectory(prefix="urdfkit-sim-")
        self.engine: Simulator = open_engine(engine or config.physics.engine, gui=gui)
        #: The one step loop (:mod:`urdfkit.motion.stepping`): the world's clock.
        self.loop = StepLoop(self.engine, config.physics.time_step)

    @property
    def time_step(self) -> float:
        """The physics step, s."""
        return self.loop.time_step

    @property
    def step_count(self) -> int:
        """Physics steps since the start (or the last restore)."""
        return self.loop.step_count

    @property
    def session(self) -> Session:
        """The PyBullet session of this world (PyBullet only, as :attr:`bullet`)."""
        return self._pybullet().session

    @property
    def bullet(self) -> Bullet:
        """PyBullet bound to this world's client: the PyBullet-only escape hatch.

        For what the engine seam does not cover (a camera image, a debug line); the
        simulation itself calls only :attr:`engine`.

        Raises:
            ParameterError: the world runs on another engine.
        """
        return self._pybullet().bullet

    def _pybullet(self) -> PyBulletEngine:
        from urdfkit.engine.pybullet import PyBulletEngine

        if not isinstance(self.engine, PyBulletEngine):
            raise ParameterError(f"`bullet`: this simulation runs on {self.engine.label}, "
                                 "not PyBullet", param="bullet")
        return self.engine

    @property
    def t(self) -> float:
        """Simulated time, s."""
        return self.step_count * self.time_step

    def error(self, path: str, message: str) -> InputError:
        """An error in the scenario at ``path`` (``robots[0].motor``), naming its file."""
        return InputError(f"{path}: {message}", file=self.config.source)

    def close(self) -> None:
        """Close the engine and remove temp files (safe to call twice)."""
        self.engine.close()
        for r in self._resolved:
            r.close()
        self._resolved = []
        self._tmp.cleanup()

    # ---- setup

    def setup(self) -> None:
        """The engine's settings, the ground, every robot where it starts, what is recorded."""
        engine = self.engine
        ph = self.config.physics
        engine.set_time_step(ph.time_step)
        engine.set_gravity(_vec3(ph.gravity))
        # Sorted overlapping pairs: without them the order the solver meets contacts in
        # depends on the engine's history, and a reset in place is not reproducible. A
        # simulation_and_control config turns them off, as SimInterface leaves them (else
        # its contacts are solved in another order and the runs part after a few steps).
        # An iteration count only when the scenario gives one: PyBullet's default is the
        # scenario's (50), and MuJoCo, which has none, names the key given.
        given = ph.model_fields_set
        try:
            engine.set_physics(deterministic_pairs=ph.deterministic_pairs,
                               solver_iterations=ph.solver_iterations
                               if "solver_iterations" in given else None,
                               cone_friction=ph.cone_friction)
        except ParameterError as e:
            raise self.error(f"physics.{e.param or 'engine'}",
                             f"{e.message}; drop it to run on {engine.label}") from None
        if self.config.ground is not None:
            g = self.config.ground
            self.ground = self._load("ground", g.template, g.params, g.urdf,
                                     LoadSettings(fixed_base=True, position=_vec3(g.position),
                                                  scenery=True))
        for i, robot in enumerate(self.config.robots):
            r = self._add_robot(i, robot)
            self.robots[r.name] = r
        self._check_record()
        for r in self.robots.values():
            # A robot's own damping, else the scenario's, else PyBullet's 0.04. PyBullet keeps
            # one value per body (measured: setting any link's sets the whole body's).
            damping = {key: value for key, value in (
                ("linearDamping", _first(r.config.linear_damping, ph.linear_damping)),
                ("angularDamping", _first(r.config.angular_damping, ph.angular_damping)))
                if value is not None}
            if damping:
                try:
                    engine.change_dynamics(r.body, -1, **damping)
                except ParameterError as e:
                    raise self.error(f"{r.path}.linear_damping, angular_damping (or "
                                     "physics')", e.message) from None

    def save(self) -> None:
        """Keep the state now as the start :meth:`restore` returns to.

        A restore is ~100x cheaper than a new Simulation (PyBullet's restoreState).
        """
        self._start_state = self.engine.save()

    def restore(self) -> None:
        """Back to the saved start, contacts and all; time starts over."""
        self.engine.restore(self._start_state)
        self.loop.step_count = 0

    def set_time_step(self, time_step: float) -> None:
        """The physics time step, s (times already recorded keep theirs)."""
        if not 0 < time_step <= 1:
            raise ParameterError(f"`time_step` must be in (0, 1], got {time_step!r}",
                                 param="time_step")
        self.engine.set_time_step(time_step)
        self.loop.time_step = float(time_step)

    def change_ground(self, **values: float) -> None:
        """Set the ground's dynamics (changeDynamics' names): its friction, restitution."""
        if self.ground is None:
            raise ParameterError("the scenario has no ground", param="robot")
        self.engine.change_dynamics(self.ground, -1, **values)

    def link_poses(self) -> list[list[tuple[Sequence[float], Sequence[float]]]]:
        """Every robot's URDF link frames' world poses now, base first (``(xyz, xyzw)``).

        Robots in the scenario's order; the base's pose is its link frame, not the inertial
        frame the engine's base pose is.
        """
        return [r.link_frames() for r in self.robots.values()]

    # ---- loading

    def _load(self, path: str, template: str | None, params: Mapping[str, object],
              urdf: str | None, settings: LoadSettings) -> int:
        from urdfkit.model.catalog import build_template
        from urdfkit.sources.resolve import open_input

        if template is not None:
            from urdfkit.motion.drive import builtin_file

            # Built templates are cached as drive's are (key: source, parameters, version).
            text = {k: v if isinstance(v, str) else
                    " ".join(map(str, v)) if isinstance(v, (list, tuple)) else str(v)
                    for k, v in params.items()}
            cached = builtin_file(template, text)
            if cached is not None:
                name = str(cached)
            else:
                folder = Path(self._tmp.name) / f"{len(self._resolved)}"
                folder.mkdir()
                name = str(build_template(template, params)
                           .write(folder / f"{template}.urdf"))
            display = f"{path}: template {template}"
        else:
            assert urdf is not None
            name = self.config.path_of(urdf)
            display = urdf
        resolved = open_input(name)
        self._resolved.append(resolved)
        return self.engine.load(str(resolved.load_path), settings, display=display)

    def _add_robot(self, i: int, cfg: RobotConfig) -> SimRobot:
        path = f"robots[{i}]"
        body, loaded = self._load_robot(path, cfg)
        r = self._new_robot(i, path, cfg, body, loaded)
        self._check_joint_names(r)
        if cfg.drive is not None:
            self._detect_train(r)
        if cfg.randomize is not None:
            self._check_randomize(r)
        self._place(r)
        return r

    def _load_robot(self, path: str, cfg: RobotConfig) -> tuple[int, tuple[str, LoadSettings]]:
        """Load the robot's URDF where the scenario puts it; refuse a body too big to query."""
        engine = self.engine
        if cfg.orientation_quat is not None:
            norm = math.sqrt(math.fsum(q * q for q in cfg.orientation_quat))
            orientation = tuple(q / norm for q in cfg.orientation_quat)
        else:
            orientation = rpy_to_unit_quat(*(cfg.orientation_rpy or (0.0, 0.0, 0.0)))
        # A Y-up (or X-up) model is first stood up, then turned as the scenario says.
        turn = quat_mul(orientation, UP_AXES[cfg.up])
        settings = LoadSettings(fixed_base=cfg.base == "fixed",
                                inertia_from_file=cfg.inertia_from_file,
                                implicit_cylinder=cfg.implicit_cylinder,
                                self_collision=cfg.self_collision,
                                position=_vec3(cfg.position), orientation=turn)
        body = self._load(path, cfg.template, cfg.params, cfg.urdf, settings)
        if cfg.pose_frame == "com":
            # The pose is the base's centre of mass, as the engine's base pose is.
            engine.reset_base(body, _vec3(cfg.position), turn)
        loaded = (str(self._resolved[-1].load_path), settings)
        if cfg.gazebo_contacts:  # before link_dynamics, which overrides them
            from urdfkit.motion.gazebo_load import apply_gazebo_contacts, contacts_to_apply

            apply_gazebo_contacts(engine, body, contacts_to_apply(self._resolved[-1].root),
                                  self.config.notes)
        if cfg.mimic:  # PyBullet ignores <mimic>: a gear constraint per follower
            from urdfkit.motion.mimic import couple_mimics, mimic_relations

            couple_mimics(engine, body, mimic_relations(self._resolved[-1].root))
        try:
            # PyBullet's state queries all fail on 128+ link bodies.
            engine.require_state_queries(body, str(cfg.name))
        except EngineError as e:
            raise self.error(path, str(e)) from None
        return body, loaded

    def _new_robot(self, i: int, path: str, cfg: RobotConfig, body: int,
                   loaded: tuple[str, LoadSettings]) -> SimRobot:
        """The robot's handle: its joints and links as the engine loaded them."""
        engine = self.engine
        joints = [JointSpec(j.index, j.name, j.kind, j.effort, j.link)
                  for j in engine.joints(body)]
        links = {engine.link_names(body)[0]: -1}
        links.update({j.child_link: j.index for j in joints})
        readings = new_readings(robot_seed(self.config.seed, i), cfg.delay, cfg.history)
        return SimRobot(engine, str(cfg.name), path, cfg, body, joints, links, loaded,
                        readings)

    def _active_joint(self, r: SimRobot, where: str, name: str) -> JointSpec:
        """The movable joint ``name`` of ``r``; an error naming ``where`` otherwise."""
        try:
            spec = r.joint(name)
        except KeyError:
            known = ", ".join(j.name for j in r.active) or "none"
            raise self.error(where, f"no joint named {name!r} in {r.config.name}; active "
                                    f"joints: {known}") from None
        if not spec.active:
            kind = "fixed" if spec.kind == "fixed" else "not a 1-DOF joint"
            raise self.error(where, f"joint {name!r} is {kind} and cannot be moved")
        return spec

    def _check_joint_names(self, r: SimRobot) -> None:
        """Every joint the robot's config names: offsets, directions, schedule, motor, noise."""
        cfg, path, active_joint = r.config, r.path, functools.partial(self._active_joint, r)
        for name, value in cfg.motor_offsets.items():
            r.offsets[active_joint(f"{path}.motor_offsets.{name}", name).name] = value
        for name, direction in cfg.motor_directions.items():
            r.directions[active_joint(f"{path}.motor_directions.{name}", name).name] = \
                direction
        for k, seg in enumerate(cfg.joints or []):
            for name in seg.targets:
                active_joint(f"{path}.joints[{k}].targets.{name}", name)
        if cfg.motor is not None:
            names = cfg.motor.joints
            r.servo = r.active if names is None else [
                active_joint(f"{path}.motor.joints", n) for n in names]
            for gain in ("kp", "kd", "viscous_friction", "stiffness"):
                for name in getattr(cfg.motor, gain) if isinstance(
                        getattr(cfg.motor, gain), dict) else ():
                    active_joint(f"{path}.motor.{gain}.{name}", name)
            r.kp, r.kd = cfg.motor.kp, cfg.motor.kd
        if cfg.noise is not None:
            for key in JOINT_NOISE_FIELDS:
                value = getattr(cfg.noise, key)
                for name in value if isinstance(value, dict) else ():
                    active_joint(f"{path}.noise.{key}.{name}", name)

    def _detect_train(self, r: SimRobot) -> None:
        """The drive train of a driven robot: which joints are wheels, which steer."""
        from urdfkit.motion.vehicle import detect_upright

        cfg, path = r.config, r.path
        v = cfg.vehicle
        # Detection judges axes in the base frame, at load time: before any step.
        try:
            r.train = detect_upright(self.engine, r.body, UP_AXES[cfg.up],
                                     wheels=v.wheels if v else None,
                                     hinges=v.hinges if v else None)
        except ParameterError as e:
            raise self.error(f"{path}.vehicle" if v else f"{path}.drive", e.message) \
                from None

    def _check_randomize(self, r: SimRobot) -> None:
        """The joints and links a ``randomize`` table names exist; a yaw needs an RPY start."""
        cfg, path = r.config, r.path
        rand = cfg.randomize
        assert rand is not None
        for name in rand.initial_joints:
            self._active_joint(r, f"{path}.randomize.initial_joints.{name}", name)
        for label, table in (("lateral_friction", rand.lateral_friction),
                             ("mass_scale", rand.mass_scale)):
            for link in table:
                if link not in r.links:
                    raise self.error(f"{path}.randomize.{label}.{link}",
                                     f"{cfg.name} has no link named {link!r}")
        if rand.yaw is not None and cfg.orientation_quat is not None:
            raise self.error(f"{path}.randomize.yaw", "needs the start given as "
                             "orientation_rpy, not orientation_quat")

    def _place(self, r: SimRobot) -> None:
        """The start the config gives: joint friction, rack, link dynamics, initial joints."""
        engine = self.engine
        cfg, path, body = r.config, r.path, r.body
        for name, friction in cfg.joint_friction.items():
            r.dry_friction[self._active_joint(r, f"{path}.joint_friction.{name}",
                                              name).index] = friction
        # PyBullet holds every joint with a velocity motor (target 0) until told otherwise.
        r.free()
        if any(cfg.base_velocity) or any(cfg.base_angular_velocity):
            engine.reset_base_velocity(body, _vec3(cfg.base_velocity),
                                       _vec3(cfg.base_angular_velocity))
        if cfg.base == "on_rack":
            # Held in the air where it starts (simulation_and_control's rack): a fixed
            # constraint between the base and the world; its joints still move.
            engine.hold_base(body)
        for link, dyn in cfg.link_dynamics.items():
            if link not in r.links:
                raise self.error(f"{path}.link_dynamics.{link}",
                                 f"{cfg.name} has no link named {link!r}")
            values = {key: value for key, value in (
                ("lateralFriction", dyn.lateral_friction), ("restitution", dyn.restitution),
                ("rollingFriction", dyn.rolling_friction),
                ("spinningFriction", dyn.spinning_friction)) if value is not None}
            if values:
                try:
                    engine.change_dynamics(body, r.links[link], **values)
                except ParameterError as e:
                    raise self.error(f"{path}.link_dynamics.{link}", e.message) from None
        for name, init in cfg.initial_joints.items():
            spec = self._active_joint(r, f"{path}.initial_joints.{name}", name)
            engine.reset_joint(body, spec.index, r.to_physical(name, init.position),
                               init.velocity * r.directions.get(name, 1.0))

    def _having_link(self, where: str, link: str) -> list[SimRobot]:
        """The robots with a link of that name; an error naming ``where`` if none has one."""
        found = [r for r in self.robots.values() if link in r.links]
        if not found:
            raise self.error(where, f"no robot has a link named {link!r}")
        return found

    def _check_record(self) -> None:
        rec = self.config.record
        for i, link in enumerate(rec.contact_links):
            for r in self._having_link(f"record.contact_links[{i}]", link):
                r.contact_links[link] = r.links[link]
        for i, link in enumerate(rec.link_poses):
            for r in self._having_link(f"record.link_poses[{i}]", link):
                r.pose_links.append(link)
        feet = rec.feet.items() if isinstance(rec.feet, dict) else \
            ((link, link) for link in rec.feet)
        for i, (label, link) in enumerate(feet):
            where = f"record.feet.{label}" if isinstance(rec.feet, dict) else \
                f"record.feet[{i}]"
            for r in self._having_link(where, link):
                r.feet[label] = r.links[link]
        for i, name in enumerate(rec.joint_forces):
            found = [r for r in self.robots.values() if any(j.name == name for j in r.joints)]
            if not found:
                raise self.error(f"record.joint_forces[{i}]", f"no robot has a joint named "
                                                              f"{name!r}")
            for r in found:
                index = r.joint(name).index
                r.force_joints[name] = index
                self.engine.enable_joint_force_sensor(r.body, index)
