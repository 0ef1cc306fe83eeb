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
from urdfkit.engine.session import LoadOptions, Session, quiet_stdout
from urdfkit.model.spec import MAX_STEPS, UP_AXES, finite, quat_mul
from urdfkit.motion.drive_result import (
    SETTLED_FRACTION,
    DriveResult,
    Monitor,
    Stats,
    Trajectory,
    trajectory_format,
)
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
    from urdfkit.engine.pybullet import PyBulletEngine
    from urdfkit.model.gazebo import GazeboContact
    from urdfkit.motion.mimic import Mimic

#: Default simulated samples per second in the trajectory (and for the statistics): enough
#: for a smooth path and a good circle fit, cheap enough to cost nothing next to the physics.
SAMPLES_PER_SECOND = 10
#: PyBullet's linear and angular damping of every link (drive does not change it).
PYBULLET_LINK_DAMPING = 0.04
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
        if self.tutorial:
            self.drivetrain, self.max_force = "locked", None
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


#: The longest run (simulated s) repeated at more force to test the advice to raise it.
PROBE_LIMIT = 60.0


class Scenario:
    """A loaded car on a plane, ready to drive: open it, look at what was detected, run it.

    Use it as a context manager so the PyBullet client and temp files always go away::

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
        self._phantom: list[str] | None = None
        self._gazebo: dict[str, GazeboContact] = {}
        self._mimics: list[Mimic] = []
        #: Mimic followers geared to their leaders: {joint name: constraint id}.
        self.mimic_followers: dict[str, int] = {}
        #: The Gazebo contacts applied at load: {link: {lateralFriction, ...}}.
        self.gazebo_applied: dict[str, dict[str, float]] = {}
        self.session: Session | None = None
        #: The world behind the engine seam, for the shared vehicle, mimic and Gazebo code;
        #: this module's own loop still calls PyBullet through :attr:`session`.
        self.engine: PyBulletEngine | None = None
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

    def _load(self, s: Session, name: str | None, builtin: str, options: LoadOptions,
              params: Mapping[str, str] | None = None) -> int:
        if name is None:
            path = self._builtin(builtin, params)
            self._last_file = str(path)
            return s.load_urdf(path, options, display=builtin)
        from urdfkit.sources.resolve import open_input

        self._last_file = name
        with open_input(name, packages=self.config.packages, xacro_args=self.config.xacro_args,
                        guard=self.config.guard, package_paths=self.config.package_paths) as res:
            self.warnings.extend(res.warnings)
            if self._phantom is None:  # the car, loaded first: links PyBullet gives 1 kg
                # Not the root: mass 0 would fix the base in place, so fix never gives it
                # that, and the advice below would be wrong for it (kobuki's base_footprint).
                children = {c.get("link") for c in res.root.iterfind("joint/child")}
                self._phantom = [el.get("name", "") for el in res.root.iterchildren("link")
                                 if el.find("inertial") is None and el.get("name") in children]
                from urdfkit.motion.gazebo_load import contacts_to_apply
                from urdfkit.motion.mimic import mimic_relations

                self._gazebo = contacts_to_apply(res.root)
                self._mimics = mimic_relations(res.root)
            return s.load_urdf(res.load_path, options, display=res.name)

    def _open(self) -> None:
        from urdfkit.engine.pybullet import PyBulletEngine

        c = self.config
        self.engine = engine = PyBulletEngine(session=Session(gui=c.gui))
        self.session = s = engine.session
        p = s.bullet
        p.setGravity(0, 0, c.gravity)
        p.setTimeStep(c.time_step)
        car = c.urdf or "simplecar"
        upright = UP_AXES[c.up]
        spawn = quat_mul(p.getQuaternionFromEuler(c.base_rpy), upright)
        start = c.base_position or (TUTORIAL_START if c.tutorial else (0.0, 0.0, 0.0))
        # The tutorial's load: no flags. Otherwise implicit cylinders (smooth wheels) and the
        # file's own inertia; see the module docstring.
        self.flags = [] if c.tutorial else ["URDF_USE_IMPLICIT_CYLINDER",
                                            "URDF_USE_INERTIA_FROM_FILE"]
        # The car is loaded first (as the tutorial does), standing up where it starts; it is
        # turned to its spawn tilt only after its wheels are found in its own frame.
        self.body = self._load(s, c.urdf, "simplecar", LoadOptions(
            base_position=start, base_orientation=upright, inertia_from_file=not c.tutorial,
            implicit_cylinder=not c.tutorial), c.template_params)
        #: The car's file, for a viewer to load the same robot (the built-in one's build).
        self.car_file = self._last_file
        s.require_state_queries(self.body, car)
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
        self.plane = self._load(s, c.plane, "simpleplane", LoadOptions(
            fixed_base=not c.tutorial, implicit_cylinder=not c.tutorial), self._ground_params())
        self.ground_top, self.ground_bounds = self._ground()
        if c.base_position is None and not c.tutorial:
            self._rest_on_ground(start)
        self._check_start()
        self.steer, note = clamp_steer(train, c.steer)
        if note:
            self.warnings.append(note)
        self._warn_phantom_mass()
        self._warn_free_swivels()
        self._plan_holds()
        self.columns = list(BASE_COLUMNS)
        for j in train.wheels + train.hinges:
            name = train.joint_names[j]
            self.columns += [f"{name}_angle", f"{name}_speed"]

    def _apply_gazebo(self) -> None:
        """Carry the file's Gazebo contact parameters over with changeDynamics."""
        from urdfkit.motion.gazebo_load import apply_gazebo_contacts

        assert self.engine is not None
        self.gazebo_applied = apply_gazebo_contacts(self.engine, self.body, self._gazebo)

    def gazebo_differences(self) -> list[str]:
        """The file's Gazebo friction where PyBullet uses another, as a user reads it."""
        if not self._gazebo or self.session is None or self.engine is None:
            return []
        from urdfkit.motion.gazebo_load import link_indices

        p = self.session.bullet
        index = link_indices(self.engine, self.body)
        out = []
        for name, g in self._gazebo.items():
            mu = g.lateral_friction
            if mu is None or name not in index:
                continue
            used = p.getDynamicsInfo(self.body, index[name])[1]
            if abs(used - mu) > 1e-9 * max(1.0, mu):
                given = " ".join(f"{k} {v:g}" for k, v in g.given().items()
                                 if k in ("mu1", "mu2"))
                out.append(f"{name} {given}, PyBullet uses {used:g}")
        return out

    def _warn_phantom_mass(self) -> None:
        """Say when PyBullet's 1 kg for each link without <inertial> is much of the robot.

        Frames (camera, IMU, sensor links) usually have no <inertial>; PyBullet makes each a
        1 kg body. On a small robot that is most of its weight, high up: a TurtleBot-sized base
        with five such frames (5 of 8.55 kg) tips over in raw PyBullet with its motors off.
        """
        if not self._phantom:
            return
        assert self.session is not None
        p = self.session.bullet
        total = sum(p.getDynamicsInfo(self.body, k)[0]
                    for k in range(-1, p.getNumJoints(self.body)))
        made_up = float(len(self._phantom))
        if total > 0 and made_up >= 0.1 * total:
            names = ", ".join(self._phantom[:5]) + (", ..." if len(self._phantom) > 5 else "")
            self.warnings.append(
                f"PyBullet gives the {len(self._phantom)} link(s) without <inertial> 1 kg each "
                f"({names}): {made_up:g} of the {total:.4g} kg simulated; if they are frames, "
                "`urdfkit fix` gives them mass 0")

    def _warn_free_swivels(self) -> None:
        """Say so when driven wheels hang from a swivel left free (a caster's).

        Naming only the wheels of a base whose wheels all sit on swivels (youBot's, Toyota
        HSR's drive unit on ``base_roll_joint``) leaves the swivels rolling free: the unit
        turns under the body, and the body's path and yaw are not the wheels'. HSR at
        ``--steer 0.5`` yawed 0.13 rad while its drive unit turned, and the run blamed wheel
        slip.
        """
        assert self.session is not None
        p, train = self.session.bullet, self.drivetrain
        free = set(train.casters)
        swivels: dict[int, list[str]] = {}
        for w in train.wheels:
            k = p.getJointInfo(self.body, w)[16]
            while k >= 0:
                if k in free and k not in train.wheels:
                    swivels.setdefault(k, []).append(train.joint_names[w])
                k = p.getJointInfo(self.body, k)[16]
        if swivels:
            named = ", ".join(train.joint_names[k] for k in swivels)
            wheels = ", ".join(w for ws in swivels.values() for w in ws)
            them = "it" if len(swivels) == 1 else "them"
            self.warnings.append(
                f"the driven wheels {wheels} hang from free swivel(s) {named}, which turn "
                "under the base as the wheels push: the base's path and yaw are not the "
                f"wheels'; give {named} to --hinges to hold {them}")

    def _plan_holds(self) -> None:
        """Which passive joints hold their start angle, with what force, and which go limp.

        A mobile manipulator's arm left limp folds under gravity and can topple the base at
        once; held by a position motor at its start angle with the URDF's effort it stays as
        it was loaded. Casters always roll free; ``limp`` frees the rest too.
        """
        assert self.session is not None
        p, train = self.session.bullet, self.drivetrain
        casters = set(train.casters)
        geared = set(self.mimic_followers)  # moved by their leaders' gears, not held
        candidates = [j for j in train.passive if j not in casters
                      and train.joint_names[j] not in geared]
        self.held: dict[int, tuple[float, float]] = {}  # joint: (angle, force)
        self.limp: list[int] = list(candidates) if self.config.limp else []
        if self.config.limp or not candidates:
            return
        states = p.getJointStates(self.body, candidates)
        weak = []
        for j, st in zip(candidates, states, strict=True):
            force = train.efforts.get(j, 0.0)
            if force > 0 and math.isfinite(force):
                self.held[j] = (st[0], force)
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
        assert self.session is not None
        p = self.session.bullet
        lo, hi = p.getAABB(self.plane, -1)
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

    def _check_start(self) -> None:
        """A static base, or a start inside the ground, make the run meaningless: say so."""
        assert self.session is not None and self.engine is not None
        p = self.session.bullet
        self.problems = []
        self.static_base = p.getDynamicsInfo(self.body, -1)[0] == 0
        root = p.getBodyInfo(self.body)[0].decode("utf-8", "replace")
        if self.static_base and root == "world":
            # PyBullet gives a link named `world` without <inertial> mass 0, not 1 kg
            # (measured on 3.2.7: with a mass of its own it falls like any other).
            self.problems.append("static base: the root link is named `world`, and PyBullet "
                                 "gives a `world` link without <inertial> mass 0, which fixes it "
                                 "where it is loaded: the car cannot move; drop the `world` link "
                                 "and its joint (build without the world frame) to drive it")
        elif self.static_base:
            self.problems.append("static base: the root link has mass 0, so PyBullet fixes it "
                                 "where it is loaded and the car cannot move; give it a mass")
        points = self.engine.closest_points(self.body, self.plane, 0.0)
        depth = min((pt.distance for pt in points), default=0.0)
        if depth < -0.005:
            if self.config.tutorial:  # the tutorial's own start: reproduced, and said
                self.warnings.append(f"the tutorial's start is {-depth * 1000:.0f} mm inside "
                                     "the ground (the contact pushes the car out at once)")
            else:
                self.problems.append(f"started inside the ground: {-depth * 1000:.0f} mm deep "
                                     "(the contact pushes it out with a jolt); leave "
                                     "`base_position` unset to rest it on the ground")

    def close(self) -> None:
        """Disconnect and remove the temp folder."""
        if self.engine is not None:
            self.engine.close()  # and its session
            self.engine = None
        if self.session is not None:
            self.session.close()
            self.session = None
        if self._tmp is not None:
            self._tmp.cleanup()
            self._tmp = None

    def __enter__(self) -> Scenario:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()

    def link_poses(self) -> list[tuple[Sequence[float], Sequence[float]]]:
        """Every URDF link frame's world pose now, base first (``(xyz, xyzw)``)."""
        assert self.session is not None and self.engine is not None
        p, body = self.session.bullet, self.body
        out = [base_link_pose(self.engine, body)]
        for j in range(p.getNumJoints(body)):
            st = p.getLinkState(body, j, computeForwardKinematics=True)
            out.append((st[4], st[5]))
        return out

    def _sampler(self) -> Callable[[float], tuple[float, ...]]:
        assert self.session is not None
        p, body = self.session.bullet, self.body
        joints = self.drivetrain.wheels + self.drivetrain.hinges
        pose, velocity = p.getBasePositionAndOrientation, p.getBaseVelocity
        euler, states = p.getEulerFromQuaternion, p.getJointStates
        # The base link frame's pose and velocity, not the inertial frame's PyBullet reports:
        # with inertia products or an <inertial><origin> they differ (a yaw of -0.16 rad at
        # rest). The local inertial pose is fixed for the run: inverted once.
        local = p.getDynamicsInfo(body, -1)
        inv_pos, inv_orn = p.invertTransform(local[3], local[4])
        compose = p.multiplyTransforms
        offset = any(abs(x) > 0 for x in inv_pos) or any(abs(x) > 0 for x in inv_orn[:3])

        def sample(t: float) -> tuple[float, ...]:
            com, com_orn = pose(body)
            lin, ang = velocity(body)
            if offset:
                pos, orn = compose(com, com_orn, inv_pos, inv_orn)
                r = (pos[0] - com[0], pos[1] - com[1], pos[2] - com[2])
                lin = (lin[0] + ang[1] * r[2] - ang[2] * r[1],
                       lin[1] + ang[2] * r[0] - ang[0] * r[2],
                       lin[2] + ang[0] * r[1] - ang[1] * r[0])
            else:
                pos, orn = com, com_orn
            row = [t, *pos, *euler(orn), *lin]
            if joints:
                for st in states(body, joints):
                    row += (st[0], st[1])
            return tuple(row)

        return sample

    def simulated(self) -> dict[str, object]:
        """What this run simulates, beyond the robot: for the summary and JSON."""
        c = self.config
        return {
            "drivetrain": self.drivetrain.mode, "steering": self.drivetrain.steering,
            # N m; PyBullet's default when no cap is given (the tutorial's).
            "wheel_force": PYBULLET_DEFAULT_FORCE if c.max_force is None else c.max_force,
            "wheel_force_default": c.max_force is None,
            "hinge_force": STEER_FORCE if self.drivetrain.hinges else None,
            "held": [{"index": j, "name": self.drivetrain.joint_names[j],
                      "angle": round(a, 6), "force": f} for j, (a, f) in self.held.items()],
            "limp": [{"index": j, "name": self.drivetrain.joint_names[j]} for j in self.limp],
            "load_flags": self.flags, "time_step": c.time_step, "gravity": c.gravity,
            "link_damping": {"linear": PYBULLET_LINK_DAMPING,
                             "angular": PYBULLET_LINK_DAMPING, "note": "PyBullet's default"},
            "tutorial": c.tutorial,
            "gazebo_contacts": self.gazebo_applied,
            "mimic": sorted(self.mimic_followers),
        }

    def run(self, progress: ProgressFn | None = None,
            sink: Callable[[tuple[float, ...]], None] | None = None) -> DriveResult:
        """Drive for the configured number of steps and measure the run.

        Ctrl-C ends the loop early; the result then covers what was simulated, with
        ``interrupted`` set, so the caller can still write the trajectory.

        Args:
            progress: Called as ``progress(done, total)`` after every sample.
            sink: Called with each trajectory sample as it is taken (to stream it to disk).
        """
        assert self.session is not None and self.engine is not None
        c, s, train, engine = self.config, self.session, self.drivetrain, self.engine
        p, body = s.bullet, self.body
        disable_default_motors(engine, body, [j for j in train.passive if j not in self.held])
        if self.held:
            held = list(self.held)
            p.setJointMotorControlArray(
                body, held, p.POSITION_CONTROL,
                targetPositions=[self.held[j][0] for j in held],
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

        sample(0.0)
        step = p.stepSimulation
        done = 0
        interrupted = False
        gui = _GuiControls(self) if c.gui else None
        start = time.perf_counter()
        with quiet_stdout() as out:
            try:
                while done < total:
                    n = min(period, total - done)
                    if gui is not None:
                        n = gui.steps(n)
                    else:
                        # The hot loop: nothing but the physics step (bound to the client
                        # once, above).
                        for _ in range(n):
                            step()
                    done += n
                    if done % period == 0 or done == total:
                        sample(done * dt)
                    if progress is not None:
                        progress(done, total)
            except KeyboardInterrupt:
                interrupted = True
            except p.error:
                if gui is None:
                    raise
                interrupted = True  # the GUI window was closed
        wall = time.perf_counter() - start
        s.diagnostics.extend(out.lines)
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
        # A base that flipped, fell or left the ground has no yaw rate worth advice on.
        upset = bool(monitor.seen & {"flipped", "fell", "left"})
        if train.yaw_steered and self.steer and rate is not None and not self._probe \
                and not interrupted and c.drivetrain != "locked" and not upset:
            share = rate / self.steer
            if share < 0.9:
                (problems if share < 0.1 else warnings).append(
                    _yaw_shortfall(self, rate, share, sim_time))
        slipping = [m for m in problems + warnings
                    if m.startswith(("wheels slipping", "stuck", "skid steering turns",
                                     "differential steering turns"))]
        differ = self.gazebo_differences() if slipping else []
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
            radius_note=note, simulated=self.simulated(), samples=stats.count,
            problems=problems)


def _yaw_shortfall(sc: Scenario, rate: float, share: float, sim_time: float) -> str:
    """Why the base turns slower than commanded, and advice that was tried before it is said.

    The same drive (same duration, so the same settled half) is run again over what a user
    would reach: ten and a hundred times the wheel force (capped at PyBullet's default), then,
    if no force helps, up to three times the yaw rate (capped where the inner wheels would
    stop: 2 v / track). Advice is given only when its run turns clearly faster (1.5x); it
    names the option as the command line spells it. More yaw rate is then searched for the
    command that turns within 10% of what was asked (:func:`_aim`). At most three re-runs and
    :data:`AIM_RUNS` more, only when this warning is printed; runs over :data:`PROBE_LIMIT` s
    are not repeated.
    """
    c, train = sc.config, sc.drivetrain
    kind = "skid steering" if train.steering == "skid" else "differential steering"
    # round first: a share of -3e-5 is said "0%", not "-0%"
    said = (f"{kind} turns at {rate:.3g} rad/s, {round(share, 2) + 0.0:.0%} of the "
            f"{sc.steer:g} commanded")
    force = PYBULLET_DEFAULT_FORCE if c.max_force is None else c.max_force
    if not 0 < sim_time <= PROBE_LIMIT:
        return (f"{said}; not measured at more force (the run is over {PROBE_LIMIT:g} s): "
                "the wheels slip sideways, or the motors are too weak")

    def probe(**changes: float | None) -> float | None:
        cfg = replace(c, keep_trajectory=False, gui=False, steps=None, seconds=sim_time,
                      **changes)  # type: ignore[arg-type]
        try:
            with Scenario(cfg, probe=True) as run:
                return run.run().yaw_rate
        except UrdfkitError:
            return None

    def better(r: float | None) -> bool:
        return r is not None and abs(r) > 1.5 * abs(rate) and \
            abs(r - rate) > 0.05 * abs(sc.steer)

    def shown(r: float | None) -> str:
        return "failed" if r is None else f"{r:.3g} rad/s"

    tried: list[str] = []
    for factor in (10.0, 100.0):
        higher = min(force * factor, PYBULLET_DEFAULT_FORCE) if force > 0 else factor
        if higher <= force or (tried and tried[-1].startswith(f"--max-force {higher:g}:")):
            break
        r = probe(max_force=higher)
        if better(r):
            assert r is not None
            return (f"{said}; with --max-force {higher:g} it turns at {r:.3g} rad/s "
                    f"({r / sc.steer:.0%}): run with --max-force {higher:g}")
        tried.append(f"--max-force {higher:g}: {shown(r)}")
    widest = 2.0 * abs(c.throttle) * train.reference_radius / train.track \
        if train.track > 0 else math.inf
    more = math.copysign(min(3.0 * abs(sc.steer), widest), sc.steer)
    if abs(more) > 1.2 * abs(sc.steer):
        r = probe(steer=more)
        if better(r):
            assert r is not None
            first = f"more wheel force does not help ({'; '.join(tried)})" if tried \
                else "at PyBullet's default wheel force"
            return f"{said}; {first}: the wheels slip sideways, and " + _aim(
                lambda x: probe(steer=x), sc.steer, (sc.steer, rate), (more, r), widest)
        tried.append(f"--steer {more:.3g}: {shown(r)}")
    return (f"{said}; neither more force nor more yaw rate turns it faster "
            f"({'; '.join(tried)}): the wheels slip sideways")


#: How close advice must land to the yaw rate asked for to be advised as reaching it.
AIM = 0.1
#: Re-runs the search for that command may take (beyond the first at more yaw rate).
AIM_RUNS = 4


def _aim(measure: Callable[[float], float | None], asked: float, start: tuple[float, float],
         more: tuple[float, float], widest: float) -> str:
    """The ``--steer`` to command for the yaw rate ``asked``, found by running it.

    A skid-steered base turns slower than commanded, and not in proportion: three times the
    command may turn it faster than asked (r2d2 at --throttle 5: --steer 0.9 turns at 0.5
    rad/s for 0.3 asked). From the two runs made (``start``, the user's, and ``more``), the
    secant method picks the next command, rounded to the three digits the advice prints,
    and runs it, up to :data:`AIM_RUNS` times, until one lands within :data:`AIM` of
    ``asked`` (capped at ``widest``, where the inner wheels stop). The advice names that
    command and what it measured; if none lands, the nearest, and says it missed.
    """
    runs = [start, more]
    for _ in range(AIM_RUNS):
        (s0, r0), (s1, r1) = runs[-2], runs[-1]
        if abs(r1 - asked) <= AIM * abs(asked) or r1 == r0:
            break
        s = s1 + (asked - r1) * (s1 - s0) / (r1 - r0)
        s = math.copysign(min(abs(s), widest), asked) if s * asked > 0 else s1 / 2
        s = float(f"{s:.3g}")
        if any(s == x for x, _ in runs):
            break
        r = measure(s)
        if r is None:
            break
        runs.append((s, r))
    s, r = min(runs[1:], key=lambda x: abs(x[1] - asked))
    if abs(r - asked) <= AIM * abs(asked):
        return (f"--steer {s:.3g} turns at {r:.3g} rad/s ({r / asked:.0%} of the {asked:g} "
                f"asked): command more yaw rate (--steer {s:.3g})")
    tried = "; ".join(f"--steer {x:.3g}: {y:.3g} rad/s" for x, y in runs[1:])
    return (f"no command tried turns within {AIM:.0%} of the {asked:g} asked ({tried}); "
            f"--steer {s:.3g} comes nearest, at {r:.3g} rad/s ({r / asked:.0%})")


class _GuiControls:
    """The tutorial's Steering and Throttle sliders, read every step, applied on change.

    Runs at real time so a person can drive; the run ends at the configured duration or
    when the window is closed.
    """

    def __init__(self, sc: Scenario):
        assert sc.session is not None and sc.engine is not None
        self.sc, self.p, self.engine = sc, sc.session.bullet, sc.engine
        lo, hi = sc.drivetrain.steer_range()
        lo, hi = max(lo, -1.0), min(hi, 1.0)
        top = max(20.0, abs(sc.config.throttle))
        self.steer_id = self.p.addUserDebugParameter("Steering", lo, hi, sc.steer)
        self.throttle_id = self.p.addUserDebugParameter("Throttle", -top, top,
                                                        sc.config.throttle)
        self.last = (sc.config.throttle, sc.steer)
        self.next_tick = time.perf_counter()

    def steps(self, n: int) -> int:
        p, dt = self.p, self.sc.config.time_step
        for _ in range(n):
            now = (p.readUserDebugParameter(self.throttle_id),
                   p.readUserDebugParameter(self.steer_id))
            if now != self.last:
                self.last = now
                apply_drive(self.engine, self.sc.body, self.sc.drivetrain, now[0], now[1],
                            self.sc.config.max_force)
            p.stepSimulation()
            self.next_tick += dt
            delay = self.next_tick - time.perf_counter()
            if delay > 0:
                time.sleep(delay)
        return n


def drive(config: DriveConfig, progress: ProgressFn | None = None) -> DriveResult:
    """Load, detect, drive and measure in one call (the library entry point)."""
    with Scenario(config) as sc:
        return sc.run(progress)
