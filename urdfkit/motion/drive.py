"""``urdfkit drive``: run a car headless at a fixed throttle and steer, and measure it.

The scenario is the PyBullet simplecar tutorial without its ``while True`` loop: a car on a
plane, gravity -10, time step 1/240 s, wheels under VELOCITY_CONTROL, steering hinges under
POSITION_CONTROL. The built-in simplecar and simpleplane are built from the templates into a
temp folder (never into the user's folder) on every run.

Load flags, chosen on purpose (see ``docs/drive.md``):

- ``URDF_USE_IMPLICIT_CYLINDER``: without it PyBullet turns a ``<cylinder>`` into a convex
  mesh, and the wheels roll on facets (the car shakes and drifts).
- ``URDF_USE_INERTIA_FROM_FILE``: without it PyBullet throws the file's ``<inertia>`` away and
  recomputes it from the collision shapes. ``drive`` is there to test *the model*, so it
  uses the inertia the model declares (wrong inertia should show up here, not be hidden).

Speed: motors are set once (PyBullet keeps a motor's target until it changes), the loop does
nothing but ``stepSimulation`` between samples, and stdout is quieted once around the whole
loop rather than per call. The physics step is the floor; see ``bench/drive_bench.py``.

Memory: samples stream to the trajectory file as they are taken; the statistics (distance,
heading, the circle fit over a bounded, evenly thinned set of settled samples) are kept as
running sums, so a run's memory does not grow with its length unless the caller keeps the
trajectory (``keep_trajectory``, for a plot).

Sanity: the run watches itself (:class:`Monitor`) and reports, as warnings, a car that left
the ground or fell, flipped, got stuck, spun its wheels, has a static base or started inside
the ground. ``--tutorial`` instead reproduces the PyBullet tutorial's loop exactly.
"""

from __future__ import annotations

import math
import tempfile
import time
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, replace
from pathlib import Path
from typing import TYPE_CHECKING

from urdfkit.core.errors import ParameterError, UrdfkitError
from urdfkit.engine.api import LoadSettings
from urdfkit.engine.registry import check as check_engine
from urdfkit.engine.registry import open_engine
from urdfkit.engine.session import quiet_stdout
from urdfkit.model.spec import (
    MAX_STEPS,
    UP_AXES,
    euler_from_quat,
    finite,
    quat_mul,
    rpy_to_unit_quat,
)
from urdfkit.motion.drive_advice import (
    PYBULLET_LINK_DAMPING,
    free_swivels,
    gazebo_differences,
    phantom_mass,
    start_problems,
    unloaded_wheels,
    yaw_shortfall,
)
from urdfkit.motion.drive_result import (
    SETTLED_FRACTION,
    DriveResult,
    Monitor,
    Stats,
    Trajectory,
    trajectory_format,
)
from urdfkit.motion.stepping import Closed, StepLoop
from urdfkit.motion.vehicle import (
    DRIVETRAINS,
    PYBULLET_DEFAULT_FORCE,
    STEER_FORCE,
    DrivetrainError,
    apply_drive,
    clamp_steer,
    detect_upright,
    disable_default_motors,
)
from urdfkit.motion.vehicle_shapes import base_link_pose, lowest_point, set_base_link_pose
from urdfkit.sources.builtin import builtin_file as builtin_file  # re-exported: gym, sim, tests

if TYPE_CHECKING:
    from urdfkit.engine.api import Simulator
    from urdfkit.engine.session import Session
    from urdfkit.model.gazebo import GazeboContact
    from urdfkit.motion.mimic import Mimic

#: Default simulated samples per second in the trajectory (and for the statistics): enough
#: for a smooth path and a good circle fit, cheap enough to cost nothing next to the physics.
SAMPLES_PER_SECOND = 10
#: The tutorial's start: the car's base 0.1 m up, loaded before the plane.
TUTORIAL_START = (0.0, 0.0, 0.1)
#: The built-in ground is at least this size (m), and larger when the run needs it.
MIN_GROUND = 20.0

BASE_COLUMNS = ("t", "x", "y", "z", "roll", "pitch", "yaw", "vx", "vy", "vz")


def _finite(name: str, value: float) -> float:
    try:
        return finite(value)
    except ValueError as e:
        raise ParameterError(f"`{name}` {str(e).replace('expected', 'must be', 1)}",
                             param=name) from None


@dataclass
class DriveConfig:
    """Everything that defines a drive; checked by :meth:`check`.

    Attributes:
        urdf: The car file (resolved like every input: pybullet_data included); ``None`` for
            the built-in simplecar.
        plane: The ground file; ``None`` for the built-in simpleplane.
        template_params: Parameter values for the built-in simplecar (see ``urdfkit
            templates``).
        packages: ``NAME=PATH`` strings: where ``package://NAME/`` points.
        xacro_args: ``NAME:=VALUE`` strings for a xacro ``urdf``.
        seconds: Simulated duration; ignored when ``steps`` is given.
        steps: Number of physics steps.
        time_step: Physics time step (s).
        throttle: Wheel angular velocity (rad/s), positive = forward: for ``differential``
            and ``rear``, that of a wheel on the car's centre line at the rear axle (the others
            turn as their paths need); for ``locked``, every wheel's.
        steer: Steering angle (rad) of the kinematic bicycle model, positive = left
            (counter-clockwise from above); for a base without hinges (two-wheel differential
            or skid steered), the yaw rate (rad/s).
        max_force: Maximum wheel motor torque (N m); None: PyBullet's default (100000).
        drivetrain: ``differential`` (every wheel at the speed its path needs, Ackermann
            hinges), ``rear`` (rear wheels so, fronts roll free) or ``locked`` (the
            tutorial's: every wheel at ``throttle``, hinges at ``steer``).
        tutorial: Reproduce the PyBullet tutorial's loop exactly: ``locked``, PyBullet's
            default motor force, no load flags, the car loaded before the plane at
            (0, 0, 0.1).
        base_rpy: Spawn tilt (roll, pitch, yaw in rad), after the up axis stands the car up.
        keep_trajectory: Keep every sample in :attr:`DriveResult.trajectory` (for a plot);
            else only the statistics are kept, and memory does not grow with the run.
        wheels: Joint names/indices to drive instead of the detected wheels.
        hinges: Joint names/indices to steer instead of the detected hinges.
        sample_every: Steps between trajectory samples; default: 10 samples per second.
        gravity: Vertical gravity (m/s^2).
        base_position: Where the car's base starts; None: resting on the ground at the
            origin (its lowest point just above the ground's top).
        gui: Open the PyBullet GUI with Steering and Throttle sliders.
        guard: False lifts the guard's refusals that are stricter than PyBullet (they become
            warnings); crash classes are refused either way.
        package_paths: Folders searched for ROS packages (``package.xml``).
        up: The car's up axis (``z``, ``y`` or ``x``), turned onto the world's +Z.
        limp: Let the passive joints (neither wheels, hinges nor casters: an arm on a mobile
            base) go limp; by default each is held at its start angle by a position motor
            with the URDF's effort as its force.
        gazebo_contacts: Apply the file's ``<gazebo reference>`` contact parameters at load
            (PyBullet ignores them): lateral friction from mu1/mu2 (the smaller), contact
            stiffness and damping from kp/kd (both given); see :mod:`urdfkit.model.gazebo`.
        mimic: Honour ``<mimic>`` (a gear constraint per follower, :mod:`urdfkit.motion.mimic`);
            False: raw PyBullet, which ignores it.
        engine: The physics engine (:data:`urdfkit.engine.registry.ENGINES`): ``pybullet``,
            or ``mujoco`` (the export, in memory: docs/engines.md).
    """

    urdf: str | None = None
    plane: str | None = None
    template_params: Mapping[str, str] | None = None
    packages: list[str] | None = None
    xacro_args: list[str] | None = None
    seconds: float | None = 10.0
    steps: int | None = None
    time_step: float = 1.0 / 240.0
    throttle: float = 10.0
    steer: float = 0.0
    max_force: float | None = 10.0
    drivetrain: str = "differential"
    tutorial: bool = False
    base_rpy: tuple[float, float, float] = (0.0, 0.0, 0.0)
    keep_trajectory: bool = True
    wheels: list[str] | None = None
    hinges: list[str] | None = None
    sample_every: int | None = None
    gravity: float = -10.0
    base_position: tuple[float, float, float] | None = None
    gui: bool = False
    guard: bool = True
    package_paths: list[str] | None = None
    up: str = "z"
    limp: bool = False
    gazebo_contacts: bool = False
    mimic: bool = True
    engine: str = "pybullet"

    def check(self) -> None:
        """Refuse values that would make the run meaningless (exit 2 in the CLI)."""
        self.time_step = _finite("time_step", self.time_step)
        if not 0 < self.time_step <= 0.1:
            raise ParameterError(f"`time_step` must be in (0, 0.1] s, got {self.time_step:g}",
                                 param="time_step")
        if self.steps is not None:
            if isinstance(self.steps, bool) or int(self.steps) != self.steps or self.steps < 1:
                raise ParameterError(f"`steps` must be a positive whole number, "
                                     f"got {self.steps!r}", param="steps")
        else:
            if self.seconds is None:
                raise ParameterError("give `seconds` or `steps`", param="seconds")
            self.seconds = _finite("seconds", self.seconds)
            if self.seconds <= 0:
                raise ParameterError(f"`seconds` must be positive, got {self.seconds:g}",
                                     param="seconds")
        steps = self.steps if self.steps is not None else \
            (self.seconds or 0.0) / self.time_step
        if not steps <= MAX_STEPS:
            many = f"{steps:.3g}" if math.isfinite(steps) else "more than 1e308"
            raise ParameterError(
                f"the run would take {many} steps; a run takes at most {MAX_STEPS:,} "
                "(shorten `seconds` or lengthen `time_step`)",
                param="steps" if self.steps is not None else "seconds")
        self.throttle = _finite("throttle", self.throttle)
        self.steer = _finite("steer", self.steer)
        if self.max_force is not None:
            self.max_force = _finite("max_force", self.max_force)
            if self.max_force < 0:
                raise ParameterError(f"`max_force` must be >= 0, got {self.max_force:g}",
                                     param="max_force")
        if self.drivetrain not in DRIVETRAINS:
            raise ParameterError(f"`drivetrain` must be one of {', '.join(DRIVETRAINS)}, got "
                                 f"{self.drivetrain!r}", param="drivetrain")
        self.base_rpy = tuple(_finite("base_rpy", v) for v in self.base_rpy)  # type: ignore[assignment]
        if self.base_position is not None:
            self.base_position = tuple(  # type: ignore[assignment]
                _finite("base_position", v) for v in self.base_position)
        self._check_engine()
        self.gravity = _finite("gravity", self.gravity)
        if self.up not in UP_AXES:
            raise ParameterError(f"`up` must be one of {', '.join(UP_AXES)}, got {self.up!r}",
                                 param="up")
        if self.sample_every is not None and (isinstance(self.sample_every, bool)
                                              or self.sample_every < 1):
            raise ParameterError(f"`sample_every` must be >= 1, got {self.sample_every!r}",
                                 param="sample_every")
        if self.template_params and self.urdf is not None:
            raise ParameterError("`template_params` are for the built-in simplecar; a `urdf` "
                                 "file takes `xacro_args`", param="template_params")

    def _check_engine(self) -> None:
        check_engine(self.engine)
        if self.tutorial:
            if self.engine != "pybullet":
                raise ParameterError(f"`tutorial` reproduces PyBullet's tutorial loop; it has "
                                     f"no meaning on {self.engine}", param="tutorial")
            self.drivetrain, self.max_force = "locked", None

    @property
    def total_steps(self) -> int:
        """How many physics steps the run takes."""
        if self.steps is not None:
            return int(self.steps)
        assert self.seconds is not None
        return max(1, round(self.seconds / self.time_step))

    @property
    def sample_period(self) -> int:
        """Steps between samples."""
        if self.sample_every is not None:
            return int(self.sample_every)
        return max(1, round(1.0 / (SAMPLES_PER_SECOND * self.time_step)))


def drive_to_file(scenario: Scenario, path: str | Path, *, force: bool = False,
                  progress: ProgressFn | None = None,
                  sink: Callable[[tuple[float, ...]], None] | None = None
                  ) -> tuple[DriveResult, Path]:
    """Run ``scenario`` (opened), streaming its trajectory to ``path`` as it is sampled.

    On Ctrl-C (SIGTERM, SIGHUP in the CLI) the file holds every sample taken so far.
    ``sink`` also gets every sample (after it is written).
    """
    from urdfkit.core.output import StreamingFile

    fmt = trajectory_format(path)
    with StreamingFile(path, force=force, keep_on_interrupt=True) as out:
        out.write(Trajectory(scenario.columns).header_bytes(fmt))
        traj = Trajectory(scenario.columns)
        def write(row: tuple[float, ...]) -> None:
            out.write(traj.rows_bytes([row], fmt))
            if sink is not None:
                sink(row)

        result = scenario.run(progress, sink=write)
    return result, out.path


ProgressFn = Callable[[int, int], None]


class Scenario:
    """A loaded car on a plane, ready to drive: open it, look at what was detected, run it.

    Use it as a context manager so the engine's world and temp files always go away::

        with Scenario(DriveConfig(throttle=10, steer=0.2)) as sc:
            print(sc.drivetrain.wheels)
            result = sc.run()
    """

    def __init__(self, config: DriveConfig, probe: bool = False):
        config.check()
        self.config = config
        self._probe = probe  # a run measuring for another's warning: it probes no further
        self.model = config.urdf or "simplecar"
        self.warnings: list[str] = []
        self.problems: list[str] = []
        self.static_base = False
        self._tmp: tempfile.TemporaryDirectory[str] | None = None
        self._last_file = ""
        #: The car's links without <inertial> (PyBullet gives each 1 kg), its root aside.
        self.links_without_inertial: list[str] | None = None
        #: The file's Gazebo contact parameters, by link (``--gazebo-contacts`` applies them).
        self.gazebo: dict[str, GazeboContact] = {}
        self._mimics: list[Mimic] = []
        #: Mimic followers geared to their leaders: {joint name: constraint id}.
        self.mimic_followers: dict[str, int] = {}
        #: The Gazebo contacts applied at load: {link: {lateralFriction, ...}}.
        self.gazebo_applied: dict[str, dict[str, float]] = {}
        #: The world behind the engine seam (PyBullet's or MuJoCo's: ``config.engine``).
        self.engine: Simulator | None = None
        try:
            self._open()
        except BaseException:
            self.close()
            raise

    def _builtin(self, name: str, params: Mapping[str, str] | None) -> Path:
        cached = builtin_file(name, params)
        if cached is not None:
            return cached
        from urdfkit.model.catalog import build_template

        if self._tmp is None:
            self._tmp = tempfile.TemporaryDirectory(prefix="urdfkit-drive-")
        path = Path(self._tmp.name) / f"{name}.urdf"
        path.write_bytes(build_template(name, params).to_bytes())
        return path

    @property
    def session(self) -> Session | None:
        """The PyBullet client of a PyBullet run (None once closed): the escape hatch.

        Raises:
            ParameterError: the run is on another engine.
        """
        from urdfkit.engine.pybullet import PyBulletEngine

        if self.engine is None:
            return None
        if not isinstance(self.engine, PyBulletEngine):
            raise ParameterError(f"`session`: this drive runs on {self.engine.name}, not "
                                 "PyBullet", param="session")
        return self.engine.session

    def _load(self, engine: Simulator, name: str | None, builtin: str, settings: LoadSettings,
              params: Mapping[str, str] | None = None) -> int:
        if name is None:
            path = self._builtin(builtin, params)
            self._last_file = str(path)
            return engine.load(str(path), settings, display=builtin)
        from urdfkit.sources.resolve import open_input

        self._last_file = name
        with open_input(name, packages=self.config.packages, xacro_args=self.config.xacro_args,
                        guard=self.config.guard, package_paths=self.config.package_paths) as res:
            self.warnings.extend(res.warnings)
            if self.links_without_inertial is None:  # the car, loaded first
                # Links PyBullet gives 1 kg. Not the root: mass 0 would fix the base in
                # place, so fix never gives it that, and the advice would be wrong for it
                # (kobuki's base_footprint).
                children = {c.get("link") for c in res.root.iterfind("joint/child")}
                self.links_without_inertial = [
                    el.get("name", "") for el in res.root.iterchildren("link")
                    if el.find("inertial") is None and el.get("name") in children]
                from urdfkit.motion.gazebo_load import contacts_to_apply
                from urdfkit.motion.mimic import mimic_relations

                self.gazebo = contacts_to_apply(res.root)
                self._mimics = mimic_relations(res.root)
            return engine.load(str(res.load_path), settings, display=res.name)

    def _open(self) -> None:
        c = self.config
        self.engine = engine = open_engine(c.engine, gui=c.gui)
        engine.set_gravity((0.0, 0.0, c.gravity))
        engine.set_time_step(c.time_step)
        car = c.urdf or "simplecar"
        upright = UP_AXES[c.up]
        spawn = quat_mul(rpy_to_unit_quat(*c.base_rpy), upright)
        start = c.base_position or (TUTORIAL_START if c.tutorial else (0.0, 0.0, 0.0))
        # The tutorial's load: no flags. Otherwise implicit cylinders (smooth wheels) and the
        # file's own inertia; see the module docstring.
        self.flags = [] if c.tutorial else ["URDF_USE_IMPLICIT_CYLINDER",
                                            "URDF_USE_INERTIA_FROM_FILE"]
        # The car is loaded first (as the tutorial does), standing up where it starts; it is
        # turned to its spawn tilt only after its wheels are found in its own frame.
        self.body = self._load(engine, c.urdf, "simplecar", LoadSettings(
            position=start, orientation=upright, inertia_from_file=not c.tutorial,
            implicit_cylinder=not c.tutorial), c.template_params)
        #: The car's file, for a viewer to load the same robot (the built-in one's build).
        self.car_file = self._last_file
        engine.require_state_queries(self.body, car)
        try:
            self.drivetrain = train = detect_upright(engine, self.body, upright, c.wheels,
                                                     c.hinges, c.drivetrain)
        except DrivetrainError as e:
            raise DrivetrainError(e.message, file=car, param=e.param) from None
        if spawn != upright:  # the link frame, as loadURDF placed it
            set_base_link_pose(engine, self.body, start, spawn)
        if c.gazebo_contacts:
            self._apply_gazebo()
        if c.mimic and self._mimics:
            from urdfkit.motion.mimic import couple_mimics

            self.mimic_followers = couple_mimics(engine, self.body, self._mimics)
        # The tutorial loads its plane as it is (a mass-0 box: static either way).
        self.plane = self._load(engine, c.plane, "simpleplane", LoadSettings(
            fixed_base=not c.tutorial, implicit_cylinder=not c.tutorial, scenery=True),
            self._ground_params())
        self.ground_top, self.ground_bounds = self._ground()
        if c.base_position is None and not c.tutorial:
            self._rest_on_ground(start)
        self.static_base, self.problems, start_said = start_problems(
            engine, self.body, self.plane, c.tutorial)
        self.warnings.extend(start_said)
        self.steer, note = clamp_steer(train, c.steer)
        if note:
            self.warnings.append(note)
        for found in (phantom_mass(engine, self.body, self.links_without_inertial),
                      free_swivels(engine, self.body, train)):
            if found is not None:
                self.warnings.append(found)
        self._plan_holds()
        self.columns = list(BASE_COLUMNS)
        for j in train.wheels + train.hinges:
            name = train.joint_names[j]
            self.columns += [f"{name}_angle", f"{name}_speed"]

    def _apply_gazebo(self) -> None:
        """Carry the file's Gazebo contact parameters over with changeDynamics."""
        from urdfkit.motion.gazebo_load import apply_gazebo_contacts

        assert self.engine is not None
        self.gazebo_applied = apply_gazebo_contacts(self.engine, self.body, self.gazebo,
                                                    self.warnings)

    def _plan_holds(self) -> None:
        """Which passive joints hold their start angle, with what force, and which go limp.

        A mobile manipulator's arm left limp folds under gravity and can topple the base at
        once; held by a position motor at its start angle with the URDF's effort it stays as
        it was loaded. Casters always roll free; ``limp`` frees the rest too.
        """
        assert self.engine is not None
        train = self.drivetrain
        casters = set(train.casters)
        geared = set(self.mimic_followers)  # moved by their leaders' gears, not held
        candidates = [j for j in train.passive if j not in casters
                      and train.joint_names[j] not in geared]
        self.held: dict[int, tuple[float, float]] = {}  # joint: (angle, force)
        self.limp: list[int] = list(candidates) if self.config.limp else []
        if self.config.limp or not candidates:
            return
        states = self.engine.joint_states(self.body, candidates)
        weak = []
        for j, st in zip(candidates, states, strict=True):
            force = train.efforts.get(j, 0.0)
            if force > 0 and math.isfinite(force):
                self.held[j] = (st.position, force)
            else:
                self.limp.append(j)
                weak.append(train.joint_names[j])
        if weak:
            self.warnings.append(f"left limp, with no effort in the URDF to hold them with: "
                                 f"{', '.join(weak[:8])}{', ...' if len(weak) > 8 else ''}")

    def _ground_params(self) -> dict[str, str] | None:
        """The built-in ground: a slab with room for the whole run, or the tutorial's own box.

        The slab's top is z = 0 and its collision box lies below the link origin. Measured on
        PyBullet 3.2.7 with implicit-cylinder wheels: on the tutorial's box, centred on its
        origin, MiR100 veers at steer 0 (0.375 m forward, 0.277 rad of yaw in 3 s); on the slab
        it does not (1.81 m, 5 mm sideways), nor does a six-cylinder base that circles on
        PyBullet's infinite plane (tests/test_drive_ground.py).
        """
        c, train = self.config, self.drivetrain
        if c.plane is not None:
            return None
        if c.tutorial:
            return {"shape": "box"}
        reach = abs(c.throttle) * train.reference_radius * c.total_steps * c.time_step
        size = max(MIN_GROUND, math.ceil(2 * (reach + 5.0)))
        return None if size == MIN_GROUND else {"size": str(size)}

    def _ground(self) -> tuple[float | None, tuple[float, float, float, float] | None]:
        """The ground's top z and its x-y extent (None where unbounded, as a GEOM_PLANE)."""
        assert self.engine is not None
        lo, hi = self.engine.aabb(self.plane, -1)
        top = hi[2] if abs(hi[2]) < 1e6 else None
        bounds = (lo[0], hi[0], lo[1], hi[1]) if max(map(abs, (*lo[:2], *hi[:2]))) < 1e6 \
            else None
        return top, bounds

    def _rest_on_ground(self, start: tuple[float, float, float]) -> None:
        """Lower or raise the car until its lowest point is 1 mm above the ground's top."""
        assert self.engine is not None
        engine = self.engine
        lowest = lowest_point(engine, self.body)  # the shapes' own, not the AABB's
        top = self.ground_top if self.ground_top is not None else 0.0
        pos, orn = base_link_pose(engine, self.body)
        set_base_link_pose(engine, self.body,
                           (pos[0], pos[1], pos[2] + top + 0.001 - lowest), orn)

    def close(self) -> None:
        """Disconnect and remove the temp folder."""
        if self.engine is not None:
            self.engine.close()
            self.engine = None
        if self._tmp is not None:
            self._tmp.cleanup()
            self._tmp = None

    def __enter__(self) -> Scenario:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()

    def link_poses(self) -> list[tuple[Sequence[float], Sequence[float]]]:
        """Every URDF link frame's world pose now, base first (``(xyz, xyzw)``)."""
        assert self.engine is not None
        return list(self.engine.link_frames(self.body))

    def _probe_yaw(self, sim_time: float) -> Callable[..., float | None]:
        """The same drive again with some options changed: its yaw rate (None: it failed)."""
        def probe(**changes: float | None) -> float | None:
            cfg = replace(self.config, keep_trajectory=False, gui=False, steps=None,
                          seconds=sim_time, **changes)  # type: ignore[arg-type]
            try:
                with Scenario(cfg, probe=True) as run:
                    return run.run().yaw_rate
            except UrdfkitError:
                return None
        return probe

    def _sampler(self) -> Callable[[float], tuple[float, ...]]:
        assert self.engine is not None
        engine, body = self.engine, self.body
        joints = self.drivetrain.wheels + self.drivetrain.hinges
        state, frame, states = engine.base_state, engine.link_frame, engine.joint_rows
        # The base link frame's pose and velocity, not the inertial frame the engine reports:
        # with inertia products or an <inertial><origin> they differ (a yaw of -0.16 rad at
        # rest).
        local = engine.dynamics(body, -1)
        offset = any(abs(x) > 0 for x in local.inertial_position) or \
            any(abs(x) > 0 for x in local.inertial_orientation[:3])

        def sample(t: float) -> tuple[float, ...]:
            base = state(body)
            com, com_orn, lin, ang = base.position, base.orientation, base.linear, base.angular
            if offset:
                pos, orn = frame(body, -1)
                r = (pos[0] - com[0], pos[1] - com[1], pos[2] - com[2])
                lin = (lin[0] + ang[1] * r[2] - ang[2] * r[1],
                       lin[1] + ang[2] * r[0] - ang[0] * r[2],
                       lin[2] + ang[0] * r[1] - ang[1] * r[0])
            else:
                pos, orn = com, com_orn
            row = [t, *pos, *euler_from_quat(orn), *lin]
            if joints:
                for st in states(body, joints):
                    row += (st[0], st[1])
            return tuple(row)

        return sample

    def run(self, progress: ProgressFn | None = None,
            sink: Callable[[tuple[float, ...]], None] | None = None) -> DriveResult:
        """Drive for the configured number of steps and measure the run.

        Ctrl-C ends the loop early; the result then covers what was simulated, with
        ``interrupted`` set, so the caller can still write the trajectory.

        Args:
            progress: Called as ``progress(done, total)`` after every sample.
            sink: Called with each trajectory sample as it is taken (to stream it to disk).
        """
        assert self.engine is not None
        c, train, engine, body = self.config, self.drivetrain, self.engine, self.body
        disable_default_motors(engine, body, [j for j in train.passive if j not in self.held])
        if self.held:
            held = list(self.held)
            engine.motors(body, held, "position", [self.held[j][0] for j in held],
                          forces=[self.held[j][1] for j in held])
        apply_drive(engine, body, train, c.throttle, self.steer, c.max_force)
        total, period, dt = c.total_steps, c.sample_period, c.time_step
        take = self._sampler()
        stats = Stats(SETTLED_FRACTION * total * dt)
        monitor = Monitor(self.drivetrain, self.columns, self.ground_bounds, self.ground_top,
                          self.static_base, c.total_steps * c.time_step)
        traj = Trajectory(self.columns) if c.keep_trajectory else None

        def sample(t: float) -> None:
            row = take(t)
            stats.add(row)
            monitor.add(row)
            if traj is not None:
                traj.rows.append(row)
            if sink is not None:
                sink(row)

        loop = StepLoop(engine, dt)
        gui = _GuiControls(self) if c.gui else None
        controls = () if gui is None else (gui.control,)
        start = time.perf_counter()
        with quiet_stdout():  # what the engine prints (PyBullet's C code, on fd 1)
            interrupted = loop.run(
                total, period, lambda: sample(loop.t), progress=progress, start=True,
                last=True, real_time=gui is not None,
                step=None if gui is None else lambda n: loop.step(n, controls))
        wall = time.perf_counter() - start
        done = loop.step_count
        assert stats.last is not None
        if stats.last[0] != done * dt:
            sample(done * dt)
        return self._result(stats, monitor, traj, done, wall, interrupted)

    def _result(self, stats: Stats, monitor: Monitor, traj: Trajectory | None, done: int,
                wall: float, interrupted: bool) -> DriveResult:
        c = self.config
        sim_time = done * c.time_step
        circle, note = stats.circle()
        problems = self.problems + monitor.finish()
        rate = stats.yaw_rate()
        train = self.drivetrain
        warnings = list(self.warnings)
        # A base that flipped, fell or left the ground has no yaw rate worth advice on, nor
        # one whose wheels carry no weight (which is said instead).
        upset = bool(monitor.seen & {"flipped", "fell", "left"})
        if "stuck" in monitor.seen and self.engine is not None:
            bare = unloaded_wheels(self.engine, self.body, self.plane, train)
            if bare is not None:
                problems.append(bare)
                upset = True
        if train.yaw_steered and self.steer and rate is not None and not self._probe \
                and not interrupted and c.drivetrain != "locked" and not upset:
            share = rate / self.steer
            if share < 0.9:
                (problems if share < 0.1 else warnings).append(
                    yaw_shortfall(train, self.steer, c.throttle, c.max_force, rate, share,
                                  sim_time, self._probe_yaw(sim_time)))
        slipping = [m for m in problems + warnings
                    if m.startswith(("wheels slipping", "stuck", "skid steering turns",
                                     "differential steering turns"))]
        differ = gazebo_differences(self.engine, self.body, self.gazebo) \
            if slipping and self.engine is not None else []
        if differ:
            shown = "; ".join(differ[:4]) + ("; ..." if len(differ) > 4 else "")
            warnings.append(f"the file's <gazebo> gives {shown}: --gazebo-contacts applies "
                            f"{'them' if len(differ) > 1 else 'it'}")
        last = stats.last
        assert last is not None
        expected = train.expected_radius(c.throttle, self.steer)
        return DriveResult(
            model=self.model, final_position=(last[1], last[2], last[3]), final_yaw=last[6],
            heading_change=stats.yaw - (stats.first_yaw or 0.0), distance=stats.distance,
            mean_speed=stats.distance / sim_time if sim_time > 0 else 0.0,
            turning_radius=None if circle is None else circle.radius,
            turn_center=None if circle is None else circle.center, sim_time=sim_time,
            steps=done, time_step=c.time_step, wall_time=wall,
            real_time_factor=sim_time / wall if wall > 0 else math.inf,
            throttle=c.throttle, steer=self.steer, interrupted=interrupted,
            drivetrain=self.drivetrain, trajectory=traj,
            warnings=warnings + problems, expected_radius=expected, yaw_rate=rate,
            radius_note=note, simulated=simulated(self), samples=stats.count,
            problems=problems)


class _GuiControls:
    """The tutorial's Steering and Throttle sliders: a controller, read before every step.

    The run paces itself to real time so a person can drive; it ends at the configured duration
    or when the window is closed.
    """

    def __init__(self, sc: Scenario):
        from urdfkit.engine.pybullet_gui import Sliders

        assert sc.engine is not None
        self.sc, self.engine = sc, sc.engine
        lo, hi = sc.drivetrain.steer_range()
        lo, hi = max(lo, -1.0), min(hi, 1.0)
        top = max(20.0, abs(sc.config.throttle))
        self.sliders = Sliders(sc.engine, [("Steering", lo, hi, sc.steer),
                                           ("Throttle", -top, top, sc.config.throttle)])
        self.last: tuple[float, ...] = (sc.steer, sc.config.throttle)

    def control(self, t: float) -> None:
        """Apply the sliders when they moved; :class:`Closed` once the window is closed."""
        now = self.sliders.read()
        if now is None:
            raise Closed
        if now != self.last:
            self.last = now
            apply_drive(self.engine, self.sc.body, self.sc.drivetrain, now[1], now[0],
                        self.sc.config.max_force)


def simulated(sc: Scenario) -> dict[str, object]:
    """What a run simulates, beyond the robot: for the summary and JSON."""
    c = sc.config
    label = sc.engine.label if sc.engine is not None else c.engine
    return {
        "drivetrain": sc.drivetrain.mode, "steering": sc.drivetrain.steering,
        # N m; PyBullet's default when no cap is given (the tutorial's).
        "wheel_force": PYBULLET_DEFAULT_FORCE if c.max_force is None else c.max_force,
        "wheel_force_default": c.max_force is None,
        "hinge_force": STEER_FORCE if sc.drivetrain.hinges else None,
        "held": [{"index": j, "name": sc.drivetrain.joint_names[j],
                  "angle": round(a, 6), "force": f} for j, (a, f) in sc.held.items()],
        "limp": [{"index": j, "name": sc.drivetrain.joint_names[j]} for j in sc.limp],
        "load_flags": sc.flags, "time_step": c.time_step, "gravity": c.gravity,
        "link_damping": {"linear": PYBULLET_LINK_DAMPING,
                         "angular": PYBULLET_LINK_DAMPING, "note": "PyBullet's default"}
        if c.engine == "pybullet" else
        {"linear": 0.0, "angular": 0.0, "note": f"{label} has none"},
        "tutorial": c.tutorial,
        "gazebo_contacts": sc.gazebo_applied,
        "mimic": sorted(sc.mimic_followers),
        "engine": c.engine,
    }


def drive(config: DriveConfig, progress: ProgressFn | None = None) -> DriveResult:
    """Load, detect, drive and measure in one call (the library entry point)."""
    with Scenario(config) as sc:
        return sc.run(progress)
