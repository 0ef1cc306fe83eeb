"""The world: loading the ground and the robots, checking the names a scenario gives.

Methods of :class:`urdfkit.sim.Simulation`, split out of :mod:`urdfkit.sim`: each function
takes the simulation as ``self`` and is bound as a method of ``Simulation`` (a class
attribute), so a call costs what a method defined in the class costs.
"""

from __future__ import annotations

import functools
import math
import random
from collections import deque
from collections.abc import Mapping
from pathlib import Path
from typing import Any

from urdfkit.core.errors import EngineError, ParameterError
from urdfkit.engine.session import LoadOptions, prime_resets
from urdfkit.model.spec import UP_AXES, quat_mul
from urdfkit.motion.scenario import JOINT_NOISE_FIELDS
from urdfkit.motion.sim_state import _FIXED, JointSpec, _Body, _first


def _setup(self: Any) -> None:
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


def _load(self: Any, path: str, template: str | None, params: Mapping[str, Any],
          urdf: str | None, options: LoadOptions) -> int:
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
            name = str(build_template(template, params).write(folder / f"{template}.urdf"))
        display = f"{path}: template {template}"
    else:
        assert urdf is not None
        name = self.config.path_of(urdf)
        display = urdf
    resolved = open_input(name)
    self._resolved.append(resolved)
    return self.session.load_urdf(resolved.load_path, options, display=display)


def _add_robot(self: Any, i: int, cfg: Any) -> _Body:
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


def _load_robot(self: Any, path: str, cfg: Any) -> tuple[int, tuple[str, LoadOptions]]:
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


def _new_body(self: Any, i: int, path: str, cfg: Any, body: int,
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


def _active_joint(self: Any, b: _Body, where: str, name: str) -> JointSpec:
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


def _check_joint_names(self: Any, b: _Body) -> None:
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


def _detect_train(self: Any, b: _Body) -> None:
    """The drive train of a driven robot: which joints are wheels, which steer."""
    from urdfkit.motion.vehicle import detect_upright

    cfg, path = b.config, b.path
    v = cfg.vehicle
    # Detection judges axes in the base frame, at load time: before any step.
    try:
        b.train = detect_upright(self.session.bullet, b.body,
                                 UP_AXES[cfg.up], wheels=v.wheels if v else None,
                                 hinges=v.hinges if v else None)
    except ParameterError as e:
        raise self._error(f"{path}.vehicle" if v else f"{path}.drive", e.message) \
            from None


def _check_randomize(self: Any, b: _Body) -> None:
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


def _place(self: Any, b: _Body) -> None:
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


def _having_link(self: Any, where: str, link: str) -> list[_Body]:
    """The robots with a link of that name; an error naming ``where`` if none has one."""
    found = [b for b in self.bodies.values() if link in b.links]
    if not found:
        raise self._error(where, f"no robot has a link named {link!r}")
    return found


def _check_record(self: Any) -> None:
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
