"""Config-driven simulation: a scenario in, per-step observations out.

:class:`Simulation` is a facade over typed parts that meet through small interfaces
(docs/architecture.md draws them):

- :class:`~urdfkit.motion.sim_world.World`: the engine (:mod:`urdfkit.engine.api`), the
  ground, the robots as loaded, time, save and restore;
- :class:`~urdfkit.motion.sim_robot.SimRobot`, one per body: joints, frames, the command in
  force, setters, link poses (the handle :meth:`Simulation.robot` gives);
- :class:`~urdfkit.motion.sim_control.Controller`: applies a robot's command every step
  (the engine's motors, or the servo model);
- :class:`~urdfkit.motion.sim_sensors.Sensors`: measuring, noise, delay, history;
- :class:`~urdfkit.motion.sim_dynamics.Dynamics`: mass matrix, inverse and forward dynamics,
  Jacobians, on shadow models;
- :class:`~urdfkit.motion.sim_record.Recorder`: the run loop and the sinks rows go to.

:mod:`urdfkit.sim` re-exports the public names. Every part calls the engine through the
seam's :class:`~urdfkit.engine.api.Simulator`; :attr:`Simulation.bullet` (and
:attr:`Simulation.session`) hand out PyBullet itself, for what the seam does not cover.
"""

from __future__ import annotations

import functools
from collections.abc import Callable, Mapping, Sequence
from pathlib import Path
from typing import TYPE_CHECKING

from urdfkit.core.errors import EngineError, ParameterError
from urdfkit.motion.scenario import load_scenario, parse_scenario
from urdfkit.motion.sim_control import Controller, MotorControl, ServoControl
from urdfkit.motion.sim_dynamics import Dynamics
from urdfkit.motion.sim_episode import reset_plan
from urdfkit.motion.sim_physics import RobotPhysics
from urdfkit.motion.sim_record import Recorder, Sink, world_total_steps
from urdfkit.motion.sim_robot import SimRobot
from urdfkit.motion.sim_sensors import Sensors
from urdfkit.motion.sim_state import Command, Observation, RobotSummary, SimResult
from urdfkit.motion.sim_world import World, robot_seed
from urdfkit.motion.sim_writers import (
    RowText,
    _ByteSink,
    _columns,
    _pyarrow,
    check_rows_output,
    flatten,
)

if TYPE_CHECKING:

    from urdfkit.engine.api import Simulator
    from urdfkit.engine.session import Bullet, Session
    from urdfkit.motion.scenario_models import Mode, ScenarioConfig


class Simulation(RobotPhysics):
    """A scenario running in a world of its own (a PyBullet client).

    Args:
        config: A validated scenario (:func:`urdfkit.motion.scenario.load_scenario`) or the plain
            dict of one, which is validated here.
        base_dir: Where relative ``urdf`` paths of a dict ``config`` are resolved.
        gui: Open PyBullet's GUI window to watch the run (needs a display).
        engine: The physics engine (:data:`urdfkit.engine.registry.ENGINES`) instead of the
            scenario's ``physics.engine``.

    Raises:
        InputError: the scenario is invalid, or names a joint or link a robot lacks, or
            scales its servo by the mass matrix of a robot PyBullet cannot compute it for.
        EngineError: PyBullet refused a file.
    """

    def __init__(self, config: ScenarioConfig | Mapping[str, object], *,
                 base_dir: str | Path | None = None, gui: bool = False,
                 engine: str | None = None):
        if isinstance(config, Mapping):
            config = parse_scenario(config, base_dir=base_dir)
        self.config = config
        self.world = World(config, gui=gui, engine=engine)
        self.sensors = Sensors(self.world)
        self.dynamics = Dynamics(self.world)
        self.recorder = Recorder(self.world, self.sensors, self.step)
        motors = MotorControl(self.world.engine)
        servo = ServoControl(self.world.engine, self.sensors, self.dynamics)
        #: What applies each robot's command every step: the servo model, or PyBullet's motors.
        self.controllers: dict[str, Controller] = {}
        try:
            self.world.setup()
            for r in self.world.robots.values():
                self.controllers[r.name] = servo if r.servo else motors
                if r.servo and servo.needs_mass_matrix(r):
                    self._require_mass_matrix(r)
            self.sensors.start()
            self.world.save()
        except BaseException:
            self.close()
            raise

    def _require_mass_matrix(self, r: SimRobot) -> None:
        """Refuse, before any step, a servo scaled by a mass matrix PyBullet cannot give.

        PyBullet refuses some models it simulates (the inertia of KUKA KR210's link_2): the
        run would fail at its first step, so the scenario is refused at load, naming why.
        So is a robot with a joint of more than one degree of freedom, which the mass matrix
        is not ordered by.
        """
        try:
            self.dynamics.mass_matrix(r)
        except (EngineError, ParameterError) as e:
            raise self.world.error(f"{r.path}.motor.scale_by_mass_matrix",
                                   f"{e.message}; set scale_by_mass_matrix = false (or "
                                   "viscous_friction and stiffness to 0)") from None

    @classmethod
    def from_file(cls, path: str | Path, *, gui: bool = False, engine: str | None = None
                  ) -> Simulation:
        """Load and validate a ``.json`` or ``.toml`` scenario and set it up.

        A simulation_and_control config is imported (:mod:`urdfkit.motion.sac`); what the import
        had to say is in ``simulation.config.notes``.
        """
        return cls(load_scenario(path), gui=gui, engine=engine)

    # ---- lifecycle

    def __enter__(self) -> Simulation:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()

    def close(self) -> None:
        """Disconnect the client and remove temp files (safe to call twice)."""
        self.dynamics.close()
        self.world.close()

    # ---- the world

    @property
    def engine(self) -> Simulator:
        """The world of this simulation alone, behind the engine seam."""
        return self.world.engine

    @property
    def session(self) -> Session:
        """The PyBullet client of this simulation alone (PyBullet only, as :attr:`bullet`)."""
        return self.world.session

    @property
    def bullet(self) -> Bullet:
        """PyBullet bound to this simulation's client (``sim.bullet.getNumBodies()``).

        The PyBullet-only escape hatch, for what the API does not cover (a camera image, a
        debug line): the simulation itself calls only :attr:`engine`.
        """
        return self.world.bullet

    @property
    def bodies(self) -> dict[str, SimRobot]:
        """The robots by name, in scenario order."""
        return self.world.robots

    @property
    def ground(self) -> int | None:
        """The ground's body id (None: no ground)."""
        return self.world.ground

    @property
    def step_count(self) -> int:
        """Physics steps since the start (or the last reset)."""
        return self.world.step_count

    @property
    def time_step(self) -> float:
        """The physics time step, s."""
        return self.world.time_step

    @property
    def t(self) -> float:
        """Simulated time, s."""
        return self.world.t

    @property
    def total_steps(self) -> int:
        """Steps in the scenario's ``duration``."""
        return world_total_steps(self.world)

    @property
    def robots(self) -> list[str]:
        """Robot names, in scenario order."""
        return list(self.world.robots)

    def robot_names(self) -> list[str]:
        """Robot names, in scenario order."""
        return list(self.world.robots)

    def robot(self, name: str) -> SimRobot:
        """The handle of robot ``name``: its joints, links, frames, setters, config."""
        try:
            return self.world.robots[name]
        except KeyError:
            raise ParameterError(f"no robot named {name!r}; robots: "
                                 f"{', '.join(self.world.robots)}") from None

    # ---- control

    def set_drive(self, robot: str, throttle: float, steer: float = 0.0) -> None:
        """Drive ``robot`` with this throttle and steer until :meth:`clear_command`.

        Overrides the scenario's ``drive`` segments (for an RL policy, say).
        """
        r = self.robot(robot)
        if r.train is None:
            raise ParameterError(f"robot {robot!r} has no drive controller; give it 'drive' "
                                 "segments in the scenario")
        r.override = Command("drive", throttle=throttle, steer=steer)

    def set_joint_targets(self, robot: str, targets: Mapping[str, float],
                          mode: Mode = "position", max_force: float | None = None) -> None:
        """Command joints of ``robot`` (measured frame) until :meth:`clear_command`.

        Args:
            robot: The robot's name.
            targets: Joint name to position, velocity or torque.
            mode: ``position``, ``velocity`` or ``torque``.
            max_force: Motor force limit for position and velocity modes (default: the
                joint's effort limit).
        """
        r = self.robot(robot)
        if mode not in ("position", "velocity", "torque"):
            raise ParameterError(f"mode must be position, velocity or torque, got {mode!r}")
        for name in targets:
            if not any(j.name == name and j.active for j in r.joints):
                raise ParameterError(f"robot {robot!r} has no active joint named {name!r}")
        r.override = Command("joints", mode=mode, targets=dict(targets), max_force=max_force)

    def clear_command(self, robot: str) -> None:
        """Return ``robot`` to the scenario's own controller."""
        self.robot(robot).override = None

    # ---- stepping and observing

    def step(self, n: int = 1) -> None:
        """Advance ``n`` physics steps, applying every robot's controller before each.

        Robots are measured only when an observation is due: every step for a robot with a
        ``delay`` or a ``history`` (what they report comes from it), and otherwise when asked
        (``observe``, a recorded row); the step before a recorded row keeps the joint
        velocities, so the row's accelerations are over one step, as before.
        """
        world, sensors, loop = self.world, self.sensors, self.world.loop
        every = self.config.record.every
        robots = list(world.robots.values())
        delayed = [r for r in robots if r.config.delay > 0 or r.readings.reports is not None]
        lazy = [r for r in robots if r not in delayed and r.active]
        # Robots with nothing to command (no schedule, override, servo or standing command)
        # cost nothing per step.
        controls = [functools.partial(self.controllers[r.name].control, r) for r in robots
                    if r.override is not None or r.applied is not None or r.servo
                    or r.config.drive or r.config.joints]

        def measure() -> None:
            for r in delayed:
                r.readings.history.append(sensors.measure(r))
                if r.readings.reports is not None:
                    sensors.report(r)
            # The step before a row (unless a row is taken now, which keeps them anyway).
            count = loop.step_count
            if lazy and (count + 1) % every == 0 and count % every:
                for r in lazy:
                    sensors.keep_velocities(r)

        loop.step(n, controls, measure if delayed or lazy else None)

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
            return {name: self.sensors.observe(r, ideal=ideal)
                    for name, r in self.world.robots.items()}
        return self.sensors.observe(self.robot(robot), ideal=ideal)

    def observation(self, robot: str, *, ideal: bool = False) -> Observation:
        """:meth:`observe` of one robot (typed as one observation)."""
        return self.sensors.observe(self.robot(robot), ideal=ideal)

    def history(self, robot: str, *, ideal: bool = False) -> list[Observation]:
        """The robot's last ``history`` observations, one per physics step, oldest first.

        Reported ones (delay, noise) unless ``ideal``. Fewer at the start of a run; copies.
        """
        return self.sensors.history(self.robot(robot), ideal=ideal)

    # ---- episodes

    def reset(self, seed: int | None = None,
              overrides: Mapping[str, Mapping[str, object]] | None = None) -> None:
        """Go back to the starting state in place, deterministically.

        Positions, velocities and contacts come back through the engine's save and
        restore (PyBullet's saveState and restoreState); time, observation history,
        delays, commands and noise generators (reseeded with ``seed``, default the
        scenario's) start over, so the same seed and the same actions give the same
        observations. Changes made with the ``set_*`` methods stay: they change the
        robot, not its state.

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
        import random

        plans = {self.robot(robot).name: reset_plan(self.robot(robot), changes)
                 for robot, changes in (overrides or {}).items()}
        self.world.restore()
        base_seed = self.config.seed if seed is None else seed
        for i, r in enumerate(self.world.robots.values()):
            r.readings.restart(random.Random(robot_seed(base_seed, i)))
            r.applied = r.override = None
            r.free()
            r.torques.clear()
            for call in plans.get(r.name, ()):
                call()
            r.readings.history.append(self.sensors.measure(r))

    # ---- state and kinematics (SimInterface's, in Python's manners)

    def joint_positions(self, robot: str) -> dict[str, float]:
        """True joint positions now (measured frame: offsets and directions applied)."""
        return dict(self.sensors.fresh(self.robot(robot)).motor_angles)

    def joint_velocities(self, robot: str) -> dict[str, float]:
        """True joint velocities now (measured frame)."""
        return dict(self.sensors.fresh(self.robot(robot)).motor_velocities)

    def motor_torques(self, robot: str) -> dict[str, float]:
        """The torque each joint's motor applied in the last step, in the joint's own frame.

        As simulation_and_control's ``GetMotorTorques``: the torque applied at the joint (the
        motor's torque times its ``motor_direction``), not in the measured frame the angles
        are reported in, and never delayed. PyBullet's applied motor torque for position and
        velocity motors; for the servo model and torque commands, the torque it applied.
        """
        r = self.robot(robot)
        states = self.world.engine.joint_rows(r.body, [j.index for j in r.active])
        # PyBullet reports 0 for a torque-controlled joint: the torque given is the answer.
        return {j.name: r.torques.get(j.name, st[3])
                for j, st in zip(r.active, states, strict=True)}

    def link_pose(self, robot: str, link: str) -> tuple[list[float], list[float]]:
        """World position and orientation (x, y, z, w) of a link's URDF frame."""
        return self.robot(robot).link_pose(link)

    def link_poses(self) -> list[list[tuple[Sequence[float], Sequence[float]]]]:
        """Every robot's URDF link frames' world poses now, base first (``(xyz, xyzw)``).

        Robots in the scenario's order; the base's pose is its link frame, not the inertial
        frame the engine's base pose is (PyBullet's ``getBasePositionAndOrientation``).
        """
        return self.world.link_poses()

    # ---- recording (urdfkit/motion/sim_record.py)

    def run(self, duration: float | None = None, sink: Sink | None = None, *,
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
        return self.recorder.run(duration, sink, keep=keep, real_time=real_time)


# --------------------------------------------------------------------------- summary and files


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

    check_rows_output(path, force=force)
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

    buffer: list[dict[str, object]] = []
    columns: list[str] = []
    writer: pq.ParquetWriter | None = None
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
        assert writer is not None
        writer.close()  # the footer: a complete file, interrupted or not
    return result, out.path
