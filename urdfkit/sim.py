"""Config-driven simulation: a scenario in, per-step observations out.

:class:`Simulation` sets up one PyBullet client of its own (a :class:`~urdfkit.session.Session`,
so several simulations in one process never share a world: every call passes
``physicsClientId``), loads the ground and the robots of a scenario, and steps them under their
controllers. It is the library behind ``urdfkit sim`` and is meant to be driven from a notebook
or an RL environment too::

    with Simulation.from_file("examples/two_cars.json") as sim:
        sim.step(10)
        obs = sim.observe("north")        # what a sensor reports (noise, delay)
        true = sim.observe("north", ideal=True)
        result = sim.run()                # to the scenario's duration, recording rows

Observations are measured through each robot's motor offsets and directions; the *reported*
ones then go through delay and noise. Neither touches the physics: the controllers and the
servo model read the true joint state.
"""

from __future__ import annotations

import functools
import math
import random
import tempfile
import time
from collections import deque
from collections.abc import Callable, Mapping, Sequence
from pathlib import Path
from typing import Any

from . import sim_control
from .errors import EngineError, InputError, ParameterError
from .scenario import JOINT_NOISE_FIELDS, OBSERVATION_FIELDS, load_scenario, parse_scenario
from .session import LoadOptions, Session, prime_resets, restore_clean
from .sim_dynamics import Shadows
from .sim_state import (  # noqa: F401  (re-exported: urdfkit.sim's public names)
    _ACTIVE,
    _FIXED,
    JointSpec,
    Observation,
    RobotSummary,
    SimResult,
    _Body,
    _Command,
    _copy_feet,
    _first,
    _Summary,
)
from .sim_writers import (  # noqa: F401  (re-exported: urdfkit.sim's public names)
    OUTPUT_FORMATS,
    RowText,
    _ByteSink,
    _columns,
    _pyarrow,
    check_output,
    flatten,
    rows_to_bytes,
    write_rows,
)
from .spec import UP_AXES, quat_mul, quat_to_matrix, rotate_back, rpy_to_quat

# --------------------------------------------------------------------------- the simulation


class Simulation:
    """A scenario running in its own PyBullet client.

    Args:
        config: A validated scenario (:func:`urdfkit.scenario.load_scenario`) or the plain
            dict of one, which is validated here.
        base_dir: Where relative ``urdf`` paths of a dict ``config`` are resolved.
        gui: Open PyBullet's GUI window to watch the run (needs a display).

    Raises:
        InputError: the scenario is invalid, or names a joint or link a robot lacks.
        EngineError: PyBullet refused a file.
    """

    def __init__(self, config: Any, *, base_dir: str | Path | None = None, gui: bool = False):
        if isinstance(config, Mapping):
            config = parse_scenario(config, base_dir=base_dir)
        self.config = config
        self.time_step: float = config.physics.time_step
        self.step_count = 0
        self.ground: int | None = None
        self.bodies: dict[str, _Body] = {}
        self._resolved: list[Any] = []
        #: The robots' dynamics models, each in a client of its own (:mod:`.sim_dynamics`).
        self._shadows = Shadows()
        self._tmp = tempfile.TemporaryDirectory(prefix="urdfkit-sim-")
        self.session = Session(gui=gui)
        try:
            self._setup()
        except BaseException:
            self.close()
            raise

    @classmethod
    def from_file(cls, path: str | Path, *, gui: bool = False) -> Simulation:
        """Load and validate a ``.json`` or ``.toml`` scenario and set it up.

        A simulation_and_control config is imported (:mod:`urdfkit.sac`); what the import
        had to say is in ``simulation.config.notes``.
        """
        return cls(load_scenario(path), gui=gui)

    # ---- lifecycle

    def __enter__(self) -> Simulation:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()

    def close(self) -> None:
        """Disconnect the client and remove temp files (safe to call twice)."""
        self._shadows.close()
        if hasattr(self, "session"):
            self.session.close()
        for r in self._resolved:
            r.close()
        self._resolved = []
        self._tmp.cleanup()

    @property
    def t(self) -> float:
        """Simulated time, s."""
        return self.step_count * self.time_step

    @property
    def total_steps(self) -> int:
        """Steps in the scenario's ``duration``."""
        return max(1, round(self.config.duration / self.time_step))

    @property
    def robots(self) -> list[str]:
        """Robot names, in scenario order."""
        return list(self.bodies)

    def _error(self, path: str, message: str) -> InputError:
        return InputError(f"{path}: {message}", file=self.config.source)

    # ---- setup

    def _setup(self) -> None:
        p, client = self.session.p, self.session.client
        ph = self.config.physics
        p.setTimeStep(ph.time_step, physicsClientId=client)
        p.setGravity(*ph.gravity, physicsClientId=client)
        # Sorted overlapping pairs: without them the order the solver meets contacts in
        # depends on the engine's history, and a reset in place is not reproducible. A
        # simulation_and_control config turns them off, as SimInterface leaves them (else
        # its contacts are solved in another order and the runs part after a few steps).
        p.setPhysicsEngineParameter(deterministicOverlappingPairs=int(ph.deterministic_pairs),
                                    physicsClientId=client)
        p.setPhysicsEngineParameter(numSolverIterations=ph.solver_iterations,
                                    enableConeFriction=int(ph.cone_friction),
                                    physicsClientId=client)
        if self.config.ground is not None:
            g = self.config.ground
            self.ground = self._load("ground", g.template, g.params, g.urdf,
                                     LoadOptions(fixed_base=True,
                                                 base_position=tuple(g.position)))
        for i, robot in enumerate(self.config.robots):
            self.bodies[robot.name] = self._add_robot(i, robot)
        self._check_record()
        for b in self.bodies.values():
            # A robot's own damping, else the scenario's, else PyBullet's 0.04. PyBullet keeps
            # one value per body (measured: setting any link's sets the whole body's).
            damping = {key: value for key, value in (
                ("linearDamping", _first(b.config.linear_damping, ph.linear_damping)),
                ("angularDamping", _first(b.config.angular_damping, ph.angular_damping)))
                if value is not None}
            if damping:
                p.changeDynamics(b.body, -1, physicsClientId=client, **damping)
        for b in self.bodies.values():
            b.history.append(self._measure(b))
        # The starting state, for reset() in place (restoreState is ~100x cheaper than a new
        # Simulation).
        self._start_state = p.saveState(physicsClientId=client)
        prime_resets(p, client, self._start_state, [b.body for b in self.bodies.values()])

    def _load(self, path: str, template: str | None, params: Mapping[str, Any],
              urdf: str | None, options: LoadOptions) -> int:
        from .catalog import build_template
        from .resolve import open_input

        if template is not None:
            from .drive import builtin_file

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
                name = str(build_template(template, params).write(folder / f"{template}.urdf"))
            display = f"{path}: template {template}"
        else:
            assert urdf is not None
            name = self.config.path_of(urdf)
            display = urdf
        resolved = open_input(name)
        self._resolved.append(resolved)
        return self.session.load_urdf(resolved.load_path, options, display=display)

    def _add_robot(self, i: int, cfg: Any) -> _Body:
        path = f"robots[{i}]"
        body, loaded = self._load_robot(path, cfg)
        b = self._new_body(i, path, cfg, body, loaded)
        self._check_joint_names(b)
        if cfg.drive is not None:
            self._detect_train(b)
        if cfg.randomize is not None:
            self._check_randomize(b)
        self._place(b)
        return b

    def _load_robot(self, path: str, cfg: Any) -> tuple[int, tuple[str, LoadOptions]]:
        """Load the robot's URDF where the scenario puts it; refuse a body too big to query."""
        p, client = self.session.p, self.session.client
        if cfg.orientation_quat is not None:
            norm = math.sqrt(math.fsum(q * q for q in cfg.orientation_quat))
            orientation = tuple(q / norm for q in cfg.orientation_quat)
        else:
            orientation = tuple(p.getQuaternionFromEuler(cfg.orientation_rpy or (0, 0, 0)))
        # A Y-up (or X-up) model is first stood up, then turned as the scenario says.
        orientation = quat_mul(orientation, UP_AXES[cfg.up])
        options = LoadOptions(fixed_base=cfg.base == "fixed",
                              inertia_from_file=cfg.inertia_from_file,
                              implicit_cylinder=cfg.implicit_cylinder,
                              self_collision=cfg.self_collision,
                              base_position=tuple(cfg.position), base_orientation=orientation)
        body = self._load(path, cfg.template, cfg.params, cfg.urdf, options)
        if cfg.pose_frame == "com":
            # The pose is the base's centre of mass, as resetBasePositionAndOrientation takes it.
            p.resetBasePositionAndOrientation(body, cfg.position, orientation,
                                              physicsClientId=client)
        loaded = (str(self._resolved[-1].load_path), options)
        try:
            # getBasePositionAndOrientation, getJointStates... all fail on 128+ link bodies.
            self.session.require_state_queries(body, cfg.name)
        except EngineError as e:
            raise self._error(path, str(e)) from None
        return body, loaded

    def _new_body(self, i: int, path: str, cfg: Any, body: int,
                  loaded: tuple[str, LoadOptions]) -> _Body:
        """The robot's record: its joints and links as PyBullet loaded them."""
        p, client = self.session.p, self.session.client
        joints: list[JointSpec] = []
        for j in range(p.getNumJoints(body, physicsClientId=client)):
            info = p.getJointInfo(body, j, physicsClientId=client)
            joints.append(JointSpec(j, info[1].decode("utf-8", "replace"), info[2],
                                    float(info[10]), info[12].decode("utf-8", "replace")))
        active = [j for j in joints if j.active]
        links = {p.getBodyInfo(body, physicsClientId=client)[0].decode("utf-8", "replace"): -1}
        links.update({j.child_link: j.index for j in joints})
        seed = self._robot_seed(self.config.seed, i)
        b = _Body(cfg.name, path, cfg, body, joints, active, links, {}, {},
                  random.Random(seed), deque(maxlen=max(cfg.delay, cfg.history - 1) + 1),
                  loaded=loaded)
        if cfg.history > 1:
            b.reports = deque(maxlen=cfg.history)
        return b

    def _active_joint(self, b: _Body, where: str, name: str) -> JointSpec:
        """The movable joint ``name`` of ``b``; an error naming ``where`` otherwise."""
        try:
            spec = b.joint(name)
        except KeyError:
            known = ", ".join(j.name for j in b.active) or "none"
            raise self._error(where, f"no joint named {name!r} in {b.config.name}; active "
                                     f"joints: {known}") from None
        if not spec.active:
            kind = "fixed" if spec.type == _FIXED else "not a 1-DOF joint"
            raise self._error(where, f"joint {name!r} is {kind} and cannot be moved")
        return spec

    def _check_joint_names(self, b: _Body) -> None:
        """Every joint the robot's config names: offsets, directions, schedule, motor, noise."""
        cfg, path, active_joint = b.config, b.path, functools.partial(self._active_joint, b)
        for name, value in cfg.motor_offsets.items():
            b.offsets[active_joint(f"{path}.motor_offsets.{name}", name).name] = value
        for name, value in cfg.motor_directions.items():
            b.directions[active_joint(f"{path}.motor_directions.{name}", name).name] = value
        for k, seg in enumerate(cfg.joints or []):
            for name in seg.targets:
                active_joint(f"{path}.joints[{k}].targets.{name}", name)
        if cfg.motor is not None:
            names = cfg.motor.joints
            b.servo = b.active if names is None else [
                active_joint(f"{path}.motor.joints", n) for n in names]
            for gain in ("kp", "kd", "viscous_friction", "stiffness"):
                for name in getattr(cfg.motor, gain) if isinstance(
                        getattr(cfg.motor, gain), dict) else ():
                    active_joint(f"{path}.motor.{gain}.{name}", name)
            b.kp, b.kd = cfg.motor.kp, cfg.motor.kd
        if cfg.noise is not None:
            for key in JOINT_NOISE_FIELDS:
                value = getattr(cfg.noise, key)
                for name in value if isinstance(value, dict) else ():
                    active_joint(f"{path}.noise.{key}.{name}", name)

    def _detect_train(self, b: _Body) -> None:
        """The drive train of a driven robot: which joints are wheels, which steer."""
        from .vehicle import detect_upright

        cfg, path = b.config, b.path
        v = cfg.vehicle
        # Detection judges axes in the base frame, at load time: before any step.
        try:
            b.train = detect_upright(self.session.p, b.body, self.session.client,
                                     UP_AXES[cfg.up], wheels=v.wheels if v else None,
                                     hinges=v.hinges if v else None)
        except ParameterError as e:
            raise self._error(f"{path}.vehicle" if v else f"{path}.drive", e.message) \
                from None

    def _check_randomize(self, b: _Body) -> None:
        """The joints and links a ``randomize`` table names exist; a yaw needs an RPY start."""
        cfg, path = b.config, b.path
        r = cfg.randomize
        for name in r.initial_joints:
            self._active_joint(b, f"{path}.randomize.initial_joints.{name}", name)
        for label, table in (("lateral_friction", r.lateral_friction),
                             ("mass_scale", r.mass_scale)):
            for link in table:
                if link not in b.links:
                    raise self._error(f"{path}.randomize.{label}.{link}",
                                      f"{cfg.name} has no link named {link!r}")
        if r.yaw is not None and cfg.orientation_quat is not None:
            raise self._error(f"{path}.randomize.yaw", "needs the start given as "
                              "orientation_rpy, not orientation_quat")

    def _place(self, b: _Body) -> None:
        """The start the config gives: joint friction, rack, link dynamics, initial joints."""
        p, client = self.session.p, self.session.client
        cfg, path, body = b.config, b.path, b.body
        for name, friction in cfg.joint_friction.items():
            b.dry_friction[self._active_joint(b, f"{path}.joint_friction.{name}",
                                              name).index] = friction
        # PyBullet holds every joint with a velocity motor (target 0) until told otherwise.
        self._free(b)
        if any(cfg.base_velocity) or any(cfg.base_angular_velocity):
            p.resetBaseVelocity(body, cfg.base_velocity, cfg.base_angular_velocity,
                                physicsClientId=client)
        if cfg.base == "on_rack":
            # Held in the air where it starts (simulation_and_control's rack): a fixed
            # constraint between the base and the world; its joints still move.
            pos, orn = p.getBasePositionAndOrientation(body, physicsClientId=client)
            p.createConstraint(body, -1, -1, -1, p.JOINT_FIXED, [0, 0, 0], [0, 0, 0],
                               pos, childFrameOrientation=orn, physicsClientId=client)
        for link, dyn in cfg.link_dynamics.items():
            if link not in b.links:
                raise self._error(f"{path}.link_dynamics.{link}",
                                  f"{cfg.name} has no link named {link!r}")
            values = {key: value for key, value in (
                ("lateralFriction", dyn.lateral_friction), ("restitution", dyn.restitution),
                ("rollingFriction", dyn.rolling_friction),
                ("spinningFriction", dyn.spinning_friction)) if value is not None}
            if values:
                p.changeDynamics(body, b.links[link], physicsClientId=client, **values)
        for name, init in cfg.initial_joints.items():
            spec = self._active_joint(b, f"{path}.initial_joints.{name}", name)
            p.resetJointState(body, spec.index, self._to_physical(b, name, init.position),
                              init.velocity * b.directions.get(name, 1.0),
                              physicsClientId=client)

    def _having_link(self, where: str, link: str) -> list[_Body]:
        """The robots with a link of that name; an error naming ``where`` if none has one."""
        found = [b for b in self.bodies.values() if link in b.links]
        if not found:
            raise self._error(where, f"no robot has a link named {link!r}")
        return found

    def _check_record(self) -> None:
        p, client = self.session.p, self.session.client
        rec = self.config.record
        for i, link in enumerate(rec.contact_links):
            for b in self._having_link(f"record.contact_links[{i}]", link):
                b.contact_links[link] = b.links[link]
        for i, link in enumerate(rec.link_poses):
            for b in self._having_link(f"record.link_poses[{i}]", link):
                b.pose_links.append(link)
        feet = rec.feet.items() if isinstance(rec.feet, dict) else \
            ((link, link) for link in rec.feet)
        for i, (label, link) in enumerate(feet):
            where = f"record.feet.{label}" if isinstance(rec.feet, dict) else \
                f"record.feet[{i}]"
            for b in self._having_link(where, link):
                b.feet[label] = b.links[link]
        for i, name in enumerate(rec.joint_forces):
            found = [b for b in self.bodies.values() if any(j.name == name for j in b.joints)]
            if not found:
                raise self._error(f"record.joint_forces[{i}]", f"no robot has a joint named "
                                                               f"{name!r}")
            for b in found:
                index = b.joint(name).index
                b.force_joints[name] = index
                p.enableJointForceTorqueSensor(b.body, index, True, physicsClientId=client)

    # ---- frames

    @staticmethod
    def _to_physical(b: _Body, name: str, measured: float) -> float:
        return measured * b.directions.get(name, 1.0) + b.offsets.get(name, 0.0)

    # ---- control

    def set_drive(self, robot: str, throttle: float, steer: float = 0.0) -> None:
        """Drive ``robot`` with this throttle and steer until :meth:`clear_command`.

        Overrides the scenario's ``drive`` segments (for an RL policy, say).
        """
        b = self._body(robot)
        if b.train is None:
            raise ParameterError(f"robot {robot!r} has no drive controller; give it 'drive' "
                                 "segments in the scenario")
        b.override = _Command("drive", throttle=throttle, steer=steer)

    def set_joint_targets(self, robot: str, targets: Mapping[str, float],
                          mode: str = "position", max_force: float | None = None) -> None:
        """Command joints of ``robot`` (measured frame) until :meth:`clear_command`.

        Args:
            robot: The robot's name.
            targets: Joint name to position, velocity or torque.
            mode: ``position``, ``velocity`` or ``torque``.
            max_force: Motor force limit for position and velocity modes (default: the
                joint's effort limit).
        """
        b = self._body(robot)
        if mode not in ("position", "velocity", "torque"):
            raise ParameterError(f"mode must be position, velocity or torque, got {mode!r}")
        for name in targets:
            if not any(j.name == name and j.active for j in b.joints):
                raise ParameterError(f"robot {robot!r} has no active joint named {name!r}")
        b.override = _Command("joints", mode=mode, targets=dict(targets), max_force=max_force)

    def clear_command(self, robot: str) -> None:
        """Return ``robot`` to the scenario's own controller."""
        self._body(robot).override = None

    def _body(self, robot: str) -> _Body:
        try:
            return self.bodies[robot]
        except KeyError:
            raise ParameterError(f"no robot named {robot!r}; robots: "
                                 f"{', '.join(self.bodies)}") from None

    # ---- control: the schedule, the motors, the servo model (urdfkit/sim_control.py)
    _scheduled = sim_control._scheduled
    _control = sim_control._control
    _free = sim_control._free
    _apply_motors = sim_control._apply_motors
    _apply_servo = sim_control._apply_servo
    _times_mass_matrix = sim_control._times_mass_matrix


    # ---- stepping and measuring

    def step(self, n: int = 1) -> None:
        """Advance ``n`` physics steps, applying every robot's controller before each.

        Robots are measured only when an observation is due: every step for a robot with a
        ``delay`` or a ``history`` (what they report comes from it), and otherwise when asked
        (``observe``, a recorded row); the step before a recorded row keeps the joint
        velocities, so the row's accelerations are over one step, as before.
        """
        p, client = self.session.p, self.session.client
        every = self.config.record.every
        bodies = list(self.bodies.values())
        delayed = [b for b in bodies if b.config.delay > 0 or b.reports is not None]
        lazy = [b for b in bodies if b not in delayed and b.active]
        # Robots with nothing to command (no schedule, override, servo or standing command)
        # cost nothing per step.
        controlled = [b for b in bodies if b.override is not None or b.applied is not None
                      or b.servo or b.config.drive or b.config.joints]
        for _ in range(n):
            for b in controlled:
                self._control(b)
            p.stepSimulation(physicsClientId=client)
            self.step_count += 1
            for b in delayed:
                b.history.append(self._measure(b))
                if b.reports is not None:
                    self._report(b)
            # The step before a row (unless a row is taken now, which keeps them anyway).
            if lazy and (self.step_count + 1) % every == 0 and self.step_count % every:
                for b in lazy:
                    self._keep_velocities(b)

    def _keep_velocities(self, b: _Body) -> None:
        """Remember the joint velocities now, for the next measurement's accelerations."""
        p, client = self.session.p, self.session.client
        states = p.getJointStates(b.body, b.frame[0], physicsClientId=client)
        b.previous_velocities = [st[1] for st in states]
        b.previous_step = self.step_count

    def _fresh(self, b: _Body) -> Observation:
        """The true observation at this step, measuring it now if it was not yet."""
        if b.history[-1].step != self.step_count:
            b.history.append(self._measure(b))
        return b.history[-1]

    def _measure(self, b: _Body) -> Observation:
        """The true observation now, in the measured joint frame."""
        p, client = self.session.p, self.session.client
        pos, orn = p.getBasePositionAndOrientation(b.body, physicsClientId=client)
        lin, ang = p.getBaseVelocity(b.body, physicsClientId=client)
        matrix = quat_to_matrix(orn)
        angles: dict[str, float] = {}
        velocities: dict[str, float] = {}
        accelerations: dict[str, float] = {}
        forces: dict[str, list[float]] | None = None
        torques: dict[str, float] | None = None
        if b.active:
            indices, names, signs, offsets = b.frame
            states = p.getJointStates(b.body, indices, physicsClientId=client)
            if self.config.record.motor_torques:  # the joint's own frame, as applied
                torques = {n: b.torques.get(n, st[3]) for n, st in zip(names, states, strict=True)}
            qd = [st[1] for st in states]
            angles = {n: (st[0] - o) * s
                      for n, st, s, o in zip(names, states, signs, offsets, strict=True)}
            velocities = {n: v * s for n, v, s in zip(names, qd, signs, strict=True)}
            # Over the time since the velocities were last taken (one step, when recording).
            span = (self.step_count - b.previous_step) * self.time_step
            before = b.previous_velocities
            if before is None or span <= 0:
                accelerations = dict.fromkeys(names, 0.0)
            else:
                accelerations = {n: (v - v0) * s / span for n, v, v0, s
                                 in zip(names, qd, before, signs, strict=True)}
            b.previous_velocities = qd
            b.previous_step = self.step_count
        if b.force_joints:
            forces = {}
            for name, index in b.force_joints.items():
                state = p.getJointState(b.body, index, physicsClientId=client)
                forces[name] = [float(x) for x in state[2]]
        contacts = None
        if b.contact_links:
            contacts = {}
            for link, index in b.contact_links.items():
                kwargs: dict[str, Any] = {"bodyA": b.body, "linkIndexA": index}
                if self.ground is not None:
                    kwargs["bodyB"] = self.ground
                points = p.getContactPoints(physicsClientId=client, **kwargs)
                contacts[link] = {"normal_force": float(sum(pt[9] for pt in points)),
                                  "count": len(points)}
        feet = self._feet(b) if b.feet else None
        poses = None
        if b.pose_links:
            poses = {}
            for link in b.pose_links:
                at, turn = self.link_pose(b.name, link)
                poses[link] = {"position": at, "orientation": turn}
        return Observation(
            t=self.t, step=self.step_count, robot=b.name, motor_angles=angles,
            motor_velocities=velocities, motor_accelerations=accelerations,
            base_position=list(pos), base_orientation=list(orn), base_lin_vel=list(lin),
            base_ang_vel=list(ang), base_lin_vel_body_frame=list(rotate_back(matrix, lin)),
            base_ang_vel_body_frame=list(rotate_back(matrix, ang)), contacts=contacts,
            joint_forces=forces, motor_torques=torques, link_poses=poses, feet=feet)

    def _feet(self, b: _Body) -> dict[str, dict[str, Any]]:
        """Each foot's contact forces from everything but its own robot (world and local)."""
        p, client = self.session.p, self.session.client
        out: dict[str, dict[str, Any]] = {}
        for label, index in b.feet.items():
            normal = [0.0, 0.0, 0.0]
            friction = [0.0, 0.0, 0.0]
            total = 0.0
            count = 0
            for pt in p.getContactPoints(bodyA=b.body, linkIndexA=index,
                                         physicsClientId=client):
                if pt[2] == b.body:
                    continue  # self-contact: not a ground reaction
                count += 1
                total += pt[9]
                # contactNormalOnB points from B to A: the push on the foot (A). The lateral
                # friction directions are those of the force on B (measured: a box sliding
                # along +x reads +mu m g), so the foot feels their opposite.
                for k in range(3):
                    normal[k] += pt[9] * pt[7][k]
                    friction[k] -= pt[10] * pt[11][k] + pt[12] * pt[13][k]
            if index == -1:  # the URDF frame, not the centre of mass
                orn = self.link_pose(b.name, next(k for k, v in b.links.items() if v == -1))[1]
            else:
                orn = p.getLinkState(b.body, index, computeForwardKinematics=True,
                                     physicsClientId=client)[5]
            local = rotate_back(quat_to_matrix(orn), normal)
            out[label] = {"contact": int(count > 0), "normal": total, "world": normal,
                          "local": list(local), "friction_world": friction}
        return out

    def _observe_one(self, robot: str, ideal: bool = False) -> Observation:
        out = self.observe(robot, ideal=ideal)
        assert isinstance(out, Observation)
        return out

    def observe(self, robot: str | None = None, *, ideal: bool = False
                ) -> Observation | dict[str, Observation]:
        """The observation now: as reported (delay, then noise) or ``ideal``.

        For the first ``delay`` steps a delayed robot reports its initial state. Asking twice
        at the same step returns the same noisy values. What is returned is a copy: changing
        it changes no later observation.

        Args:
            robot: One robot's name; default: all, as a dict keyed by name.
            ideal: The true values, without noise or delay.
        """
        if robot is None:
            return {name: self.observe(name, ideal=ideal)  # type: ignore[misc]
                    for name in self.bodies}
        b = self._body(robot)
        self._fresh(b)
        if ideal:
            return b.history[-1].copy()
        # A copy: a caller changing what it got must not change later observations.
        return self._report(b).copy()

    def _report(self, b: _Body) -> Observation:
        """What the robot reports now (delay, then noise); the same object all this step."""
        if b.reported is None or b.reported[0] != self.step_count:
            self._fresh(b)
            # history ends with the current observation; the delayed one is `delay` before.
            source = b.history[max(0, len(b.history) - 1 - b.config.delay)]
            if b.config.delay:  # angles and velocities are delayed; torques are not
                source = source._replace(motor_torques=b.history[-1].motor_torques)
            if b.config.delay or b.config.noise is not None:
                source = self._add_noise(b, source._replace(t=self.t, step=self.step_count))
            b.reported = (self.step_count, source)
            if b.reports is not None:
                b.reports.append(b.reported[1])
        return b.reported[1]

    def history(self, robot: str, *, ideal: bool = False) -> list[Observation]:
        """The robot's last ``history`` observations, one per physics step, oldest first.

        Reported ones (delay, noise) unless ``ideal``. Fewer at the start of a run; copies.
        """
        b = self._body(robot)
        n = b.config.history
        if ideal:
            self._fresh(b)
            return [o.copy() for o in list(b.history)[-n:]]
        self._report(b)
        if b.reports is None:
            return [b.reported[1].copy()] if b.reported is not None else []
        return [o.copy() for o in b.reports]

    # ---- reset in place

    @staticmethod
    def _robot_seed(seed: int, i: int) -> int:
        return seed * 1_000_003 + i

    def reset(self, seed: int | None = None,
              overrides: Mapping[str, Mapping[str, Any]] | None = None) -> None:
        """Go back to the starting state in place, deterministically.

        Positions, velocities and contacts come back through PyBullet's saveState and
        restoreState; time, observation history, delays, commands and noise generators
        (reseeded with ``seed``, default the scenario's) start over, so the same seed and the
        same actions give the same observations. Changes made with the ``set_*`` methods
        stay: they change the robot, not its state.

        Args:
            seed: Reseeds the noise; default: the scenario's ``seed``.
            overrides: Per robot name, a different start for this episode, with the
                scenario's keys and meanings: ``initial_joints`` (joint -> position, or ->
                ``{"position", "velocity"}``; measured frame), ``position`` and
                ``orientation_rpy`` or ``orientation_quat`` (in the robot's ``pose_frame``),
                ``base_velocity`` and ``base_angular_velocity``. What is not given is the
                scenario's start.

        Raises:
            ParameterError: an unknown robot, key or joint, or a value of the wrong shape;
                nothing is reset then.
        """
        p, client = self.session.p, self.session.client
        plans = {self._body(robot).name: self._reset_plan(self._body(robot), changes)
                 for robot, changes in (overrides or {}).items()}
        restore_clean(p, client, self._start_state, [b.body for b in self.bodies.values()])
        self.step_count = 0
        base_seed = self.config.seed if seed is None else seed
        for i, b in enumerate(self.bodies.values()):
            b.rng = random.Random(self._robot_seed(base_seed, i))
            b.history.clear()
            if b.reports is not None:
                b.reports.clear()
            b.previous_velocities = None
            b.previous_step = -1
            b.applied = b.override = None
            b.reported = None
            self._free(b)
            b.torques.clear()
            for call in plans.get(b.name, ()):
                call()
            b.history.append(self._measure(b))

    def _reset_plan(self, b: _Body, changes: Mapping[str, Any]) -> list[Callable[[], None]]:
        """The PyBullet calls that start ``b`` as ``changes`` says, checked before any runs."""
        p, client = self.session.p, self.session.client
        known = ("initial_joints", "position", "orientation_rpy", "orientation_quat",
                 "base_velocity", "base_angular_velocity")
        for key in changes:
            if key not in known:
                raise ParameterError(f"`overrides`: unknown key {key!r} for {b.name}; known "
                                     f"keys: {', '.join(known)}", param="overrides")

        def vector(key: str, size: int) -> list[float] | None:
            value = changes.get(key)
            if value is None:
                return None
            try:
                out = [float(v) for v in value]
            except (TypeError, ValueError):
                out = []
            if len(out) != size or not all(math.isfinite(v) for v in out):
                raise ParameterError(f"`overrides`: {b.name}.{key} needs {size} finite "
                                     "numbers", param="overrides")
            return out

        calls: list[Callable[[], None]] = []
        for name, value in (changes.get("initial_joints") or {}).items():
            spec = next((j for j in b.active if j.name == name), None)
            if spec is None:
                raise ParameterError(f"`overrides`: {b.name} has no active joint named "
                                     f"{name!r}", param="overrides")
            position, velocity = (value.get("position", 0.0), value.get("velocity", 0.0)) \
                if isinstance(value, Mapping) else (value, 0.0)
            q = self._to_physical(b, name, float(position))
            qd = float(velocity) * b.directions.get(name, 1.0)
            calls.append(functools.partial(p.resetJointState, b.body, spec.index, q, qd,
                                           physicsClientId=client))
        position = vector("position", 3)
        rpy = vector("orientation_rpy", 3)
        quat = vector("orientation_quat", 4)
        if rpy is not None and quat is not None:
            raise ParameterError(f"`overrides`: give {b.name} orientation_rpy or "
                                 "orientation_quat, not both", param="overrides")
        if position is not None or rpy is not None or quat is not None:
            cfg = b.config
            if quat is None:
                quat = list(rpy_to_quat(*rpy)) if rpy is not None else \
                    list(cfg.orientation_quat) if cfg.orientation_quat is not None else \
                    list(rpy_to_quat(*(cfg.orientation_rpy or (0.0, 0.0, 0.0))))
            norm = math.sqrt(math.fsum(v * v for v in quat))
            if norm < 1e-12:
                raise ParameterError(f"`overrides`: {b.name}.orientation_quat must not be all "
                                     "zeros", param="overrides")
            orn = quat_mul([v / norm for v in quat], UP_AXES[cfg.up])
            at = position if position is not None else list(cfg.position)
            if cfg.pose_frame == "link":
                # resetBasePositionAndOrientation places the centre of mass.
                dyn = p.getDynamicsInfo(b.body, -1, physicsClientId=client)
                at, orn = p.multiplyTransforms(at, orn, dyn[3], dyn[4])
            calls.append(lambda: p.resetBasePositionAndOrientation(
                b.body, at, orn, physicsClientId=client))
        lin = vector("base_velocity", 3)
        ang = vector("base_angular_velocity", 3)
        if lin is not None or ang is not None:
            velocity = (lin if lin is not None else list(b.config.base_velocity),
                        ang if ang is not None else list(b.config.base_angular_velocity))
            calls.append(lambda: p.resetBaseVelocity(b.body, *velocity,
                                                     physicsClientId=client))
        return calls

    # ---- state, kinematics and dynamics of one robot (SimInterface's, in Python's manners)

    def robot_names(self) -> list[str]:
        """Robot names, in scenario order."""
        return list(self.bodies)

    def joint_positions(self, robot: str) -> dict[str, float]:
        """True joint positions now (measured frame: offsets and directions applied)."""
        return dict(self._fresh(self._body(robot)).motor_angles)

    def joint_velocities(self, robot: str) -> dict[str, float]:
        """True joint velocities now (measured frame)."""
        return dict(self._fresh(self._body(robot)).motor_velocities)

    def motor_torques(self, robot: str) -> dict[str, float]:
        """The torque each joint's motor applied in the last step, in the joint's own frame.

        As simulation_and_control's ``GetMotorTorques``: the torque applied at the joint (the
        motor's torque times its ``motor_direction``), not in the measured frame the angles
        are reported in, and never delayed. PyBullet's applied motor torque for position and
        velocity motors; for the servo model and torque commands, the torque it applied.
        """
        b = self._body(robot)
        p, client = self.session.p, self.session.client
        states = p.getJointStates(b.body, [j.index for j in b.active], physicsClientId=client)
        # PyBullet reports 0 for a torque-controlled joint: the torque given is the answer.
        return {j.name: b.torques.get(j.name, st[3])
                for j, st in zip(b.active, states, strict=True)}

    def link_pose(self, robot: str, link: str) -> tuple[list[float], list[float]]:
        """World position and orientation (x, y, z, w) of a link's URDF frame."""
        b = self._body(robot)
        p, client = self.session.p, self.session.client
        index = b.links.get(link)
        if index is None:
            from .suggest import hint

            raise ParameterError(f"`link`: {robot} has no link named {link!r}"
                                 f"{hint(link, b.links)}", param="link")
        if index == -1:
            pos, orn = p.getBasePositionAndOrientation(b.body, physicsClientId=client)
            dyn = p.getDynamicsInfo(b.body, -1, physicsClientId=client)
            inv = p.invertTransform(dyn[3], dyn[4])
            pos, orn = p.multiplyTransforms(pos, orn, inv[0], inv[1])
        else:
            st = p.getLinkState(b.body, index, computeForwardKinematics=True,
                                physicsClientId=client)
            pos, orn = st[4], st[5]
        return list(pos), list(orn)

    def dynamics_joints(self, robot: str) -> list[str]:
        """The joints the dynamics quantities are ordered by (PyBullet's order).

        The movable joints; a floating base adds 6 base coordinates before them in
        :meth:`mass_matrix`.
        """
        return [j.name for j in self._dynamics_joints(self._body(robot))]

    def _dynamics_joints(self, b: _Body) -> list[JointSpec]:
        movable = [j for j in b.joints if j.type != _FIXED]
        odd = [j.name for j in movable if not j.active]
        if odd:
            raise ParameterError(f"{b.name}: the dynamics need 1-DOF joints; {odd[0]!r} is not",
                                 param="robot")
        return movable

    def _physical_state(self, b: _Body) -> tuple[list[float], list[float]]:
        p, client = self.session.p, self.session.client
        states = p.getJointStates(b.body, [j.index for j in self._dynamics_joints(b)],
                                  physicsClientId=client)
        return [float(st[0]) for st in states], [float(st[1]) for st in states]

    def _fixed(self, b: _Body, what: str) -> None:
        p, client = self.session.p, self.session.client
        moving_base = b.config.base != "fixed" and \
            p.getDynamicsInfo(b.body, -1, physicsClientId=client)[0] > 0
        if moving_base:
            raise ParameterError(f"{b.name}: {what} needs a fixed base (PyBullet's "
                                 "calculateInverseDynamics does not take a floating one); "
                                 "use base = \"fixed\"", param="robot")

    def _model(self, b: _Body) -> tuple[Any, int, int]:
        """``(p, client, body)`` of the robot's dynamics model, as the robot is now.

        PyBullet builds the model its calculateMassMatrix, calculateInverseDynamics and
        calculateJacobian use once, at the first call, and never updates it: a mass changed
        later is ignored (measured on 3.2.7). So the dynamics run on a copy of the robot in a
        client of their own, rebuilt after every ``set_mass``/``set_inertia``.
        """
        assert b.loaded is not None
        return self._shadows.model(b.name, b.loaded, self.config.physics.gravity, b.changes)

    def _changed(self, b: _Body, link: int, values: dict[str, Any]) -> None:
        """Remember a change to a robot's mass properties; its dynamics model is stale."""
        for key, value in values.items():
            b.changes[(link, key)] = value
        self._shadows.stale(b.name)

    def mass_matrix(self, robot: str) -> Any:
        """The joint-space mass matrix M(q) now (numpy, PyBullet's calculateMassMatrix).

        Physical joint coordinates, in :meth:`dynamics_joints` order; a floating base puts its
        6 coordinates first, as PyBullet does.
        """
        import numpy as np

        b = self._body(robot)
        q, _ = self._physical_state(b)
        p, client, body = self._model(b)
        return np.array(p.calculateMassMatrix(body, q, physicsClientId=client))

    def coriolis_and_gravity(self, robot: str) -> Any:
        """C(q, qd) qd + g(q) now: the torques that hold the current motion (numpy)."""
        import numpy as np

        b = self._body(robot)
        self._fixed(b, "coriolis_and_gravity")
        q, qd = self._physical_state(b)
        p, client, body = self._model(b)
        return np.array(p.calculateInverseDynamics(body, q, qd, [0.0] * len(q),
                                                   physicsClientId=client))

    def gravity_torques(self, robot: str) -> Any:
        """g(q) now: the torques that hold the robot still against gravity (numpy)."""
        import numpy as np

        b = self._body(robot)
        self._fixed(b, "gravity_torques")
        q, _ = self._physical_state(b)
        p, client, body = self._model(b)
        zero = [0.0] * len(q)
        return np.array(p.calculateInverseDynamics(body, q, zero, zero,
                                                   physicsClientId=client))

    def forward_dynamics(self, robot: str, tau: Sequence[float]) -> Any:
        """The joint accelerations ``tau`` would cause now, without contacts (numpy).

        qdd = M^-1 (tau - C qd - g).
        """
        import numpy as np

        b = self._body(robot)
        torque = np.asarray(tau, dtype=float)
        n = len(self._dynamics_joints(b))
        if torque.shape != (n,):
            raise ParameterError(f"`tau` needs {n} torques, one per dynamics joint of "
                                 f"{robot}, got {torque.shape}", param="tau")
        return np.linalg.solve(self.mass_matrix(robot), torque - self.coriolis_and_gravity(robot))

    def jacobian(self, robot: str, link: str, point: Sequence[float] = (0.0, 0.0, 0.0)
                 ) -> Any:
        """The 6 x n Jacobian (linear rows, then angular) of a point of a link now (numpy).

        ``point`` is in the link's URDF frame (the joint frame): PyBullet 3.2.7's
        calculateJacobian takes it so, whatever its docs say of the centre of mass (measured:
        the point (0, 0, 0) of a pendulum's bob link is on the hinge, J = 0).
        """
        import numpy as np

        b = self._body(robot)
        index = b.links.get(link)
        if index is None or index == -1:
            raise ParameterError(f"`link`: {robot} has no moving link named {link!r}",
                                 param="link")
        q, qd = self._physical_state(b)
        p, client, body = self._model(b)
        lin, ang = p.calculateJacobian(body, index, list(point), q, qd, [0.0] * len(q),
                                       physicsClientId=client)
        return np.vstack([np.array(lin), np.array(ang)])

    # ---- setters: the robot's physical parameters

    def _link_index(self, b: _Body, link: str) -> int:
        if link not in b.links:
            from .suggest import hint

            raise ParameterError(f"`link`: {b.name} has no link named {link!r}"
                                 f"{hint(link, b.links)}", param="link")
        return b.links[link]

    def _change(self, target: str, link: str | None, **values: Any) -> None:
        p, client = self.session.p, self.session.client
        if target == "ground":
            if self.ground is None:
                raise ParameterError("the scenario has no ground", param="robot")
            p.changeDynamics(self.ground, -1, physicsClientId=client, **values)
            return
        b = self._body(target)
        links = [self._link_index(b, link)] if link is not None else \
            [-1, *range(len(b.joints))]
        for index in links:
            p.changeDynamics(b.body, index, physicsClientId=client, **values)

    def set_mass(self, robot: str, link: str, mass: float) -> None:
        """A link's mass, kg; its inertia scales with it (the same body, heavier).

        PyBullet's changeDynamics(mass=...) alone throws the inertia away and recomputes it
        from the collision shapes (a link without any gets ~1e-6): not what "heavier" means.
        """
        b = self._body(robot)
        index = self._link_index(b, link)
        p, client = self.session.p, self.session.client
        info = p.getDynamicsInfo(b.body, index, physicsClientId=client)
        old, diagonal = info[0], info[2]
        scaled = [float(v) * float(mass) / old for v in diagonal] if old > 0 else None
        for values in ({"mass": float(mass)},
                       {"localInertiaDiagonal": scaled} if scaled is not None else {}):
            if values:
                p.changeDynamics(b.body, index, physicsClientId=client, **values)
                self._changed(b, index, values)

    def set_inertia(self, robot: str, link: str, diagonal: Sequence[float]) -> None:
        """A link's principal moments of inertia, kg m^2 (in its inertial frame)."""
        b = self._body(robot)
        index = self._link_index(b, link)
        values = {"localInertiaDiagonal": [float(v) for v in diagonal]}
        p, client = self.session.p, self.session.client
        p.changeDynamics(b.body, index, physicsClientId=client, **values)
        self._changed(b, index, values)

    def set_friction(self, robot: str, link: str | None, lateral: float) -> None:
        """Lateral friction of a link (every link when ``link`` is None).

        Robot ``"ground"`` is the floor.
        """
        self._change(robot, link, lateralFriction=float(lateral))

    def set_restitution(self, robot: str, link: str | None, restitution: float) -> None:
        """Restitution (bounciness) of a link, or of the floor with robot ``"ground"``."""
        self._change(robot, link, restitution=float(restitution))

    @staticmethod
    def _joint_named(b: _Body, joint: str) -> JointSpec:
        try:
            return b.joint(joint)
        except KeyError:
            raise ParameterError(f"`joint`: {b.name} has no joint named {joint!r}",
                                 param="joint") from None

    def set_joint_damping(self, robot: str, joint: str, damping: float) -> None:
        """PyBullet's joint damping of one joint (N m s/rad)."""
        b = self._body(robot)
        spec = self._joint_named(b, joint)
        p, client = self.session.p, self.session.client
        p.changeDynamics(b.body, spec.index, jointDamping=float(damping),
                         physicsClientId=client)

    def set_joint_friction(self, robot: str, joint: str, friction: float) -> None:
        """A joint's dry (Coulomb) friction, N m (N for a prismatic joint); 0 removes it.

        The joint holds against up to ``friction`` of torque and is slowed by that much when
        it moves (PyBullet's joint motor at velocity 0 with that force limit). While a
        PyBullet position or velocity command drives the joint (a ``joints`` segment without
        a ``motor`` table, or a car's wheels and hinges), that command owns the motor; the
        friction comes back when it ends. It stays across ``reset()``.
        """
        b = self._body(robot)
        spec = self._joint_named(b, joint)
        if spec not in b.active:
            raise ParameterError(f"`joint`: {joint} of {robot} is fixed", param="joint")
        if not (isinstance(friction, (int, float)) and math.isfinite(friction)
                and friction >= 0):
            raise ParameterError(f"`friction` must be a finite number >= 0, got {friction!r}",
                                 param="friction")
        b.dry_friction[spec.index] = float(friction)
        if not self._motor_driven(b, spec):
            self._free(b, [spec.index])

    def _motor_driven(self, b: _Body, spec: JointSpec) -> bool:
        """Whether a PyBullet position or velocity command holds this joint's motor now."""
        cmd = b.applied
        if cmd is None or b.servo:
            return False
        if cmd.kind == "drive":
            return b.train is not None and spec.index in (*b.train.wheels, *b.train.hinges)
        return spec.name in cmd.targets and cmd.mode_of(spec.name) != "torque"

    def set_link_damping(self, robot: str, linear: float, angular: float) -> None:
        """Every link's linear and angular velocity damping (PyBullet's default is 0.04)."""
        self._change(robot, None, linearDamping=float(linear), angularDamping=float(angular))

    def set_motor_gains(self, robot: str, kp: float | Mapping[str, float] | None = None,
                        kd: float | Mapping[str, float] | None = None) -> None:
        """The servo's position and velocity gains: one for every joint, or per joint name.

        A gain not given keeps its value. Needs the robot's ``motor`` table (the servo).
        """
        b = self._body(robot)
        if not b.servo:
            raise ParameterError(f"`robot`: {robot} has no servo model; give it a 'motor' "
                                 "table in the scenario", param="robot")
        names = {j.name for j in b.servo}
        for label, gain in (("kp", kp), ("kd", kd)):
            if gain is None:
                continue
            values = dict(gain) if isinstance(gain, Mapping) else {"": gain}
            for name, value in values.items():
                if name and name not in names:
                    raise ParameterError(f"`{label}`: {robot}'s servo drives no joint named "
                                         f"{name!r}", param=label)
                if not (isinstance(value, (int, float)) and math.isfinite(value)
                        and value >= 0):
                    raise ParameterError(f"`{label}` must be a finite number >= 0, got "
                                         f"{value!r}", param=label)
            setattr(b, label, {k: float(v) for k, v in values.items()}
                    if isinstance(gain, Mapping) else float(gain))

    def set_time_step(self, time_step: float) -> None:
        """The physics time step, s (times already recorded keep theirs)."""
        if not 0 < time_step <= 1:
            raise ParameterError(f"`time_step` must be in (0, 1], got {time_step!r}",
                                 param="time_step")
        p, client = self.session.p, self.session.client
        p.setTimeStep(time_step, physicsClientId=client)
        self.time_step = float(time_step)

    def _add_noise(self, b: _Body, obs: Observation) -> Observation:
        """Independent Gaussian samples on the reported fields (standard deviations).

        Joint fields take one value for every joint or one per joint; base vectors one for
        every axis or one per axis. ``base_orientation`` is turned by a random rotation
        (roll, pitch, yaw drawn with those deviations), so it stays a unit quaternion.
        """
        noise = b.config.noise
        if noise is None:
            return obs
        gauss = b.rng.gauss
        changes: dict[str, Any] = {}
        for name in (*OBSERVATION_FIELDS, "motor_torques"):
            std = getattr(noise, name)
            value = getattr(obs, name)
            if value is None or not std:
                continue
            if isinstance(value, dict):
                changes[name] = {k: v + gauss(0.0, std.get(k, 0.0) if isinstance(std, dict)
                                              else std) for k, v in value.items()}
                continue
            axes = std if isinstance(std, list) else [std] * 3
            if name == "base_orientation":
                turn = rpy_to_quat(*(gauss(0.0, a) if a > 0 else 0.0 for a in axes))
                changes[name] = list(quat_mul(turn, value))
            else:
                changes[name] = [v + (gauss(0.0, a) if a > 0 else 0.0)
                                 for v, a in zip(value, axes, strict=True)]
        return obs._replace(**changes)

    def link_poses(self) -> list[list[tuple[Any, Any]]]:
        """Every robot's URDF link frames' world poses now, base first (``(xyz, xyzw)``).

        Robots in the scenario's order; the base's pose is its link frame, not the inertial
        frame ``getBasePositionAndOrientation`` reports.
        """
        p, client = self.session.p, self.session.client
        out = []
        for b in self.bodies.values():
            pos, orn = p.getBasePositionAndOrientation(b.body, physicsClientId=client)
            local = p.getDynamicsInfo(b.body, -1, physicsClientId=client)
            inv = p.invertTransform(local[3], local[4])
            poses = [p.multiplyTransforms(pos, orn, inv[0], inv[1])]
            for j in range(p.getNumJoints(b.body, physicsClientId=client)):
                st = p.getLinkState(b.body, j, computeForwardKinematics=True,
                                    physicsClientId=client)
                poses.append((st[4], st[5]))
            out.append(poses)
        return out

    def run(self, duration: float | None = None,
            sink: Callable[[list[Observation]], None] | None = None, *,
            keep: bool = True, real_time: bool = False) -> SimResult:
        """Step to ``duration`` (default: the scenario's), recording every ``record.every``.

        Rows are taken at every step that is a multiple of ``record.every``, the starting
        state included when the run starts at step 0. ``sink`` gets each batch of rows (one
        per robot) as it is recorded, to stream them to disk; with ``keep=False`` the result
        then holds no rows, only their count and the per-robot summary, so a run's memory
        does not grow with its length. Ctrl-C ends the run early with ``interrupted`` set;
        the rows so far are kept, as they are when the GUI window is closed. ``real_time``
        paces the steps to the wall clock (to watch the run in the GUI).
        """
        end = self.total_steps if duration is None else \
            self.step_count + max(0, round(duration / self.time_step))
        every = self.config.record.every
        rows: list[Observation] = []
        ideal: list[Observation] = []
        summary = _Summary()

        bodies = list(self.bodies.values())

        def record() -> None:
            # As observe() gives them (copies), without its per-call lookups; one copy when
            # what a robot reports is its true state.
            truth = [self._fresh(b) for b in bodies]
            batch = [self._report(b) for b in bodies]
            for k, (seen, true) in enumerate(zip(batch, truth, strict=True)):
                batch[k] = seen.copy()
                truth[k] = batch[k] if seen is true else true.copy()
            # Only whole batches count: an interrupt above drops this one entirely.
            if keep:
                rows.extend(batch)
                ideal.extend(truth)
            summary.add(truth)
            if sink is not None:
                sink(batch)

        interrupted = False
        p, client = self.session.p, self.session.client
        # Real time: at most a 60th of a second of simulated time between two waits.
        chunk = max(1, round(1 / 60 / self.time_step)) if real_time else end
        start_wall, start_step = time.perf_counter(), self.step_count
        try:
            if self.step_count % every == 0:
                record()
            while self.step_count < end:
                self.step(min(every - self.step_count % every, end - self.step_count, chunk))
                if self.step_count % every == 0:
                    record()
                if real_time:
                    ahead = start_wall + (self.step_count - start_step) * self.time_step \
                        - time.perf_counter()
                    if ahead > 0:
                        time.sleep(ahead)
        except KeyboardInterrupt:
            interrupted = True
        except p.error:
            if not self.session.gui or p.isConnected(physicsClientId=client):
                raise
            interrupted = True  # the GUI window was closed
        kept = min(len(rows), len(ideal))
        whole = kept - kept % max(1, len(self.bodies))
        return SimResult(rows[:whole], ideal[:whole], self.time_step, self.step_count,
                         interrupted, summary.rows, summary.robots())


# --------------------------------------------------------------------------- summary


def summarize(result: SimResult) -> list[RobotSummary]:
    """Per robot: where it started and ended, how far and fast it went, its final joints."""
    return list(result.summaries)

def run_to_file(simulation: Simulation, path: str | Path, *, force: bool = False,
                duration: float | None = None, real_time: bool = False,
                also: Callable[[list[Observation]], None] | None = None
                ) -> tuple[SimResult, Path]:
    """Run ``simulation``, writing its rows to ``path`` as they are recorded.

    Every format streams: ``.jsonl`` and ``.csv`` row by row, ``.parquet`` in row groups of
    :data:`PARQUET_ROWS`. The result keeps no rows (their count and the summary only), so
    memory does not grow with the run. On Ctrl-C (SIGTERM, SIGHUP in the CLI) the file holds
    every complete row so far (a parquet file gets its footer). Nothing is replaced without
    ``force``. ``also`` gets every batch too, after it is written.
    """
    from .output import StreamingFile

    check_output(path, force=force)
    fmt = Path(path).suffix.lower()
    if fmt == ".parquet":
        return _run_to_parquet(simulation, path, force=force, duration=duration,
                               real_time=real_time, also=also)
    text = RowText(fmt)
    with StreamingFile(path, force=force, keep_on_interrupt=True) as out:
        def write(batch: list[Observation]) -> None:
            out.write(text.encode([r.to_dict() for r in batch]))
            if also is not None:
                also(batch)

        result = simulation.run(duration, sink=write, keep=False, real_time=real_time)
    return result, out.path


#: Rows per parquet row group when streaming.
PARQUET_ROWS = 4096


def _run_to_parquet(simulation: Simulation, path: str | Path, *, force: bool,
                    duration: float | None, real_time: bool,
                    also: Callable[[list[Observation]], None] | None = None
                    ) -> tuple[SimResult, Path]:
    from .output import StreamingFile

    pa = _pyarrow()
    import pyarrow.parquet as pq

    buffer: list[dict[str, Any]] = []
    columns: list[str] = []
    writer: Any = None
    with StreamingFile(path, force=force, keep_on_interrupt=True) as out:
        sink = _ByteSink(out)

        def flush() -> None:
            nonlocal writer
            table = pa.table({c: [r.get(c) for r in buffer] for c in columns})
            if writer is None:
                writer = pq.ParquetWriter(pa.PythonFile(sink, mode="w"), table.schema)
            writer.write_table(table)
            buffer.clear()

        def take(batch: list[Observation]) -> None:
            flat = [flatten(r.to_dict()) for r in batch]
            if not columns:
                columns.extend(_columns(flat))
            buffer.extend(flat)
            if len(buffer) >= PARQUET_ROWS:
                flush()
            if also is not None:
                also(batch)

        result = simulation.run(duration, sink=take, keep=False, real_time=real_time)
        if buffer or writer is None:
            flush()
        writer.close()  # the footer: a complete file, interrupted or not
    return result, out.path
