"""Config-driven simulation: a scenario in, per-step observations out.

:class:`Simulation` sets up one PyBullet client of its own (a
:class:`~urdfkit.engine.session.Session`,
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

import tempfile
from collections.abc import Callable, Mapping
from pathlib import Path
from typing import Any

from urdfkit.core.errors import InputError, ParameterError
from urdfkit.engine.session import Session
from urdfkit.motion import (
    sim_control,
    sim_dynamics,
    sim_episode,
    sim_record,
    sim_sensors,
    sim_setters,
    sim_world,
)
from urdfkit.motion.scenario import (  # noqa: F401 (re-exported)
    OBSERVATION_FIELDS,
    load_scenario,
    parse_scenario,
)
from urdfkit.motion.sim_state import (  # noqa: F401  (re-exported: urdfkit.sim's public names)
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
from urdfkit.motion.sim_writers import (  # noqa: F401  (re-exported: urdfkit.sim's public names)
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

# --------------------------------------------------------------------------- the simulation


class Simulation:
    """A scenario running in its own PyBullet client.

    Args:
        config: A validated scenario (:func:`urdfkit.motion.scenario.load_scenario`) or the plain
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
        self._shadows = sim_dynamics.Shadows()
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

        A simulation_and_control config is imported (:mod:`urdfkit.motion.sac`); what the import
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

    # ---- setup: loading the ground and the robots, checking names (urdfkit/sim_world.py)
    _setup = sim_world._setup
    _load = sim_world._load
    _add_robot = sim_world._add_robot
    _load_robot = sim_world._load_robot
    _new_body = sim_world._new_body
    _active_joint = sim_world._active_joint
    _check_joint_names = sim_world._check_joint_names
    _detect_train = sim_world._detect_train
    _check_randomize = sim_world._check_randomize
    _place = sim_world._place
    _having_link = sim_world._having_link
    _check_record = sim_world._check_record


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

    # ---- sensors: measuring, feet, noise, delay and history (urdfkit/sim_sensors.py)
    _keep_velocities = sim_sensors._keep_velocities
    _fresh = sim_sensors._fresh
    _measure = sim_sensors._measure
    _feet = sim_sensors._feet
    _report = sim_sensors._report
    _add_noise = sim_sensors._add_noise


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

    # ---- episodes: reset in place and randomisation (urdfkit/sim_episode.py)
    _robot_seed = staticmethod(sim_episode._robot_seed)
    reset = sim_episode.reset
    _reset_plan = sim_episode._reset_plan


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
            from urdfkit.core.suggest import hint

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

    # ---- dynamics on shadow models (urdfkit/sim_dynamics.py)
    dynamics_joints = sim_dynamics.dynamics_joints
    _dynamics_joints = sim_dynamics._dynamics_joints
    _physical_state = sim_dynamics._physical_state
    _fixed = sim_dynamics._fixed
    _model = sim_dynamics._model
    _changed = sim_dynamics._changed
    mass_matrix = sim_dynamics.mass_matrix
    coriolis_and_gravity = sim_dynamics.coriolis_and_gravity
    gravity_torques = sim_dynamics.gravity_torques
    forward_dynamics = sim_dynamics.forward_dynamics
    jacobian = sim_dynamics.jacobian


    # ---- setters: a robot's physical parameters (urdfkit/sim_setters.py)
    _link_index = sim_setters._link_index
    _change = sim_setters._change
    set_mass = sim_setters.set_mass
    set_inertia = sim_setters.set_inertia
    set_friction = sim_setters.set_friction
    set_restitution = sim_setters.set_restitution
    _joint_named = staticmethod(sim_setters._joint_named)
    set_joint_damping = sim_setters.set_joint_damping
    set_joint_friction = sim_setters.set_joint_friction
    _motor_driven = sim_setters._motor_driven
    set_link_damping = sim_setters.set_link_damping
    set_motor_gains = sim_setters.set_motor_gains


    def set_time_step(self, time_step: float) -> None:
        """The physics time step, s (times already recorded keep theirs)."""
        if not 0 < time_step <= 1:
            raise ParameterError(f"`time_step` must be in (0, 1], got {time_step!r}",
                                 param="time_step")
        p, client = self.session.p, self.session.client
        p.setTimeStep(time_step, physicsClientId=client)
        self.time_step = float(time_step)


    # ---- recording: the run loop and the link poses a viewer draws (urdfkit/sim_record.py)
    link_poses = sim_record.link_poses
    run = sim_record.run


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
    from urdfkit.core.output import StreamingFile

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
    from urdfkit.core.output import StreamingFile

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
