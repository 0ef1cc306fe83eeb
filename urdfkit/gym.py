"""Gymnasium environments: ``urdfkit/SimpleDriving-v0`` and :class:`ScenarioEnv`.

``import urdfkit.gym`` registers ``urdfkit/SimpleDriving-v0``; without the import,
``gymnasium.make("urdfkit.gym:urdfkit/SimpleDriving-v0")`` imports it first. ``docs/gym.md``
describes both environments, where the tutorial's choices were odd, and the figures.

- :class:`SimpleDrivingEnv` is the task of the PyBullet tutorial's part 2 ("Creating OpenAI Gym
  Environments with PyBullet", ``SimpleDriving-v0``): drive urdfkit's simplecar to a goal on
  simpleplane. Same spaces, reward, throttle model and time step; a client of its own, an
  in-place reset, and a lean step (what the tutorial calls, minus the repeats).
- :class:`ScenarioEnv` turns any urdfkit scenario into an environment through
  :class:`~urdfkit.sim.Simulation`: the action space comes from the robot's controller, the
  observation from its (noisy, delayed) observations, and ``reset`` restores in place, with the
  per-episode randomisation the scenario's ``randomize`` tables ask for.
"""

from __future__ import annotations

import math
import time
from collections.abc import Callable, Mapping, Sequence
from pathlib import Path
from typing import TYPE_CHECKING, Any, Literal

from urdfkit.core.errors import MissingDependencyError, ParameterError

try:
    import gymnasium as gym
    import numpy as np
    from gymnasium import spaces
except ImportError as e:  # pragma: no cover - the [gym] extra installs it
    raise MissingDependencyError("urdfkit.gym needs gymnasium: pip install 'urdfkit[gym]'") \
        from e

from urdfkit.engine.api import Camera, LoadSettings
from urdfkit.engine.registry import check as check_engine
from urdfkit.engine.registry import open_engine
from urdfkit.model.spec import quat_to_matrix
from urdfkit.motion.stepping import StepLoop

if TYPE_CHECKING:
    from urdfkit.motion.scenario_models import Mode, Randomize, RobotConfig
    from urdfkit.sim import Observation, SimRobot, Simulation

__all__ = ["SIMPLE_DRIVING_ID", "ScenarioEnv", "SimpleDrivingEnv"]

SIMPLE_DRIVING_ID = "urdfkit/SimpleDriving-v0"
#: How an environment renders: PyBullet's window, or frames as arrays.
RenderMode = Literal["human", "rgb_array"]

#: The tutorial's joint indices of simplecar (urdfkit's template keeps its joint order).
_HINGES = (0, 2)
_WHEELS = (1, 3, 4, 5)
#: simpleplane as the tutorial has it: a 20 x 20 x 0.01 m box (the template's default is a plane).
TUTORIAL_GROUND = {"shape": "box"}
#: The goal marker: a green post, 1 m tall and 1 m across, seen by the cameras and touched by
#: nothing (no collision shape); fixed where each episode's goal is.
GOAL_MARKER = """<?xml version="1.0"?>
<robot name="goal">
  <link name="goal">
    <visual>
      <geometry><cylinder radius="0.5" length="1.0"/></geometry>
      <material name="goal"><color rgba="0 0.925 0 1"/></material>
    </visual>
  </link>
</robot>
"""


def _real(action: object) -> None:
    """Refuse an action of complex numbers, text or objects before numpy casts it silently."""
    kind = np.asarray(action).dtype.kind if not isinstance(action, np.ndarray) else \
        action.dtype.kind
    if kind not in "biuf":
        raise ValueError(f"the action must be real numbers, got {np.asarray(action).dtype} "
                         f"values: {_short(action)}")


def _short(action: object) -> str:
    text = repr(action)
    return text if len(text) <= 200 else text[:200] + f"... ({len(text):,} characters)"


def _open(env: gym.Env) -> None:
    """Refuse a call on a closed env with a clear error, not PyBullet's "Not connected"."""
    if getattr(env, "_closed", False):
        raise RuntimeError(f"this {type(env).__name__} is closed; make a new one")


def _after_end(env: SimpleDrivingEnv | ScenarioEnv) -> None:
    """Warn once per episode when ``step`` is called after it ended, as Gymnasium asks."""
    if getattr(env, "_ended", False) and not getattr(env, "_warned_end", False):
        import warnings

        env._warned_end = True
        warnings.warn(f"{type(env).__name__}.step() called after the episode ended "
                      "(terminated or truncated); call reset() to start a new one",
                      stacklevel=3)


def _finite_pair(action: Any) -> tuple[float, float]:
    try:
        _real(action)
        a, b = action
        first, second = float(a), float(b)
    except (TypeError, ValueError):
        raise ValueError(f"expected an action of two numbers (throttle, steer), got "
                         f"{_short(action)}") from None
    if not (math.isfinite(first) and math.isfinite(second)):
        raise ValueError(f"the action must be finite, got ({first}, {second})")
    return first, second



def _gui(render_mode: RenderMode | None) -> bool:
    """Whether ``render_mode`` opens PyBullet's window: ``human`` where there is a display.

    Headless (CI, a cluster node), ``human`` runs without a window and says so once, rather
    than failing: ``gymnasium.utils.env_checker.check_env`` makes an env in every listed mode.
    """
    if render_mode != "human":
        return False
    from urdfkit.engine.session import has_display

    if has_display():
        return True
    import warnings

    warnings.warn("render_mode='human' needs a display (DISPLAY is not set): running without "
                  "a window", stacklevel=3)
    return False

class SimpleDrivingEnv(gym.Env):
    """Drive the tutorial car to a goal: the tutorial's ``SimpleDriving-v0``, in Gymnasium 1.x.

    Action: ``Box([0, -0.6], [1, 0.6])``, throttle and steering angle (rad), clipped to those
    bounds. The throttle drives a wheel speed integrated as the tutorial does
    (``dv/dt = 20 throttle - v (0.01 v + 0.2)``, never below 0), commanded to all four wheels
    with a 1.2 N m motor; the steering angle goes to both hinges (whose limits are 0.5 rad).

    Observation (float32): car x, y, cos(yaw), sin(yaw), velocity x, y (world), goal x, y.

    Reward: the decrease in distance to the goal, clipped at 0; reaching it (within 1 m)
    gives 50 instead and ends the episode, as does leaving ``|x|, |y| < 10``. The registered
    id truncates at 250 steps (8.3 s), the tutorial's training length.

    Args:
        render_mode: ``"rgb_array"`` (the engine's off-screen frames) or ``"human"``
            (PyBullet's GUI, paced to real time).
        camera: ``"chase"`` (the tutorial's camera on the car, looking ahead) or
            ``"overview"`` (the arena from above).
        width, height: Frame size of ``rgb_array``.
        implicit_cylinder: Roll on true cylinders (``URDF_USE_IMPLICIT_CYLINDER``); on
            PyBullet off by default, as in the tutorial: it costs about 1.35x per physics
            step. MuJoCo's cylinders are true ones (True only).
        engine: The physics engine (:data:`urdfkit.engine.registry.ENGINES`): ``pybullet``,
            or ``mujoco`` (docs/engines.md).

    Attributes:
        engine: The environment's world, behind the engine seam (:mod:`urdfkit.engine.api`).
        car, goal_marker: Their body ids in it.
    """

    metadata = {"render_modes": ["human", "rgb_array"], "render_fps": 30}

    TIME_STEP = 1.0 / 30.0
    GRAVITY = -10.0
    C_THROTTLE = 20.0
    C_ROLLING = 0.2
    C_DRAG = 0.01
    WHEEL_FORCE = 1.2
    ARENA = 10.0
    GOAL_RADIUS = 1.0
    GOAL_BONUS = 50.0

    def __init__(self, render_mode: RenderMode | None = None, *,
                 camera: Literal["chase", "overview"] = "chase",
                 width: int = 320, height: int = 240, implicit_cylinder: bool | None = None,
                 engine: str = "pybullet"):
        check_engine(engine)
        if render_mode is not None and render_mode not in self.metadata["render_modes"]:
            raise ParameterError(f"render_mode must be one of "
                                 f"{', '.join(self.metadata['render_modes'])} or None, got "
                                 f"{render_mode!r}", param="render_mode")
        if camera not in ("chase", "overview"):
            raise ParameterError(f"camera must be chase or overview, got {camera!r}",
                                 param="camera")
        if not (isinstance(width, int) and isinstance(height, int) and width > 0
                and height > 0):
            raise ParameterError(f"width and height must be positive integers, got "
                                 f"{width!r} x {height!r}", param="width")
        self.render_mode = render_mode
        self.camera = camera
        self.width, self.height = width, height
        self.action_space = spaces.Box(np.array([0.0, -0.6], dtype=np.float32),
                                       np.array([1.0, 0.6], dtype=np.float32))
        # The tutorial's bounds, except two: the observation that ends an episode by leaving
        # the arena lies past +-10, by up to one step's travel at the 5 m/s bound; the goal
        # is drawn within +-9.
        edge = self.ARENA + 5.0 * self.TIME_STEP
        self.observation_space = spaces.Box(
            np.array([-edge, -edge, -1, -1, -5, -5, -9, -9], dtype=np.float32),
            np.array([edge, edge, 1, 1, 5, 5, 9, 9], dtype=np.float32))
        self.engine = open_engine(engine, gui=_gui(render_mode))
        try:
            self._setup(implicit_cylinder if implicit_cylinder is not None
                        else engine != "pybullet")
        except BaseException:
            self.close()
            raise
        self.goal = (0.0, 0.0)
        self._speed = self._throttle = self._steer_asked = 0.0
        self._steer: float | None = None
        self._previous_distance = 0.0
        self._last_frame = 0.0

    def _setup(self, implicit_cylinder: bool) -> None:
        import tempfile

        from urdfkit.motion.drive import builtin_file

        e = self.engine
        e.set_time_step(self.TIME_STEP)
        # Sorted overlapping pairs: the solver meets contacts in the same order after every
        # reset (PyBullet's default does not, and single-step episodes then differ).
        e.set_physics(deterministic_pairs=True)
        e.set_gravity((0.0, 0.0, self.GRAVITY))
        self._tmp = tempfile.TemporaryDirectory(prefix="urdfkit-gym-")
        folder = Path(self._tmp.name)
        # The tutorial's own ground, a box centred on its origin (drive's default is the slab).
        plane, car = builtin_file("simpleplane", TUTORIAL_GROUND), builtin_file("simplecar")
        if plane is None or car is None:  # no writable cache: build into the temp folder
            from urdfkit.model.catalog import build_template

            plane = build_template("simpleplane", TUTORIAL_GROUND).write(folder / "plane.urdf")
            car = build_template("simplecar").write(folder / "car.urdf")
        marker = folder / "goal.urdf"
        marker.write_text(GOAL_MARKER, encoding="utf-8")
        e.load(str(plane), LoadSettings(fixed_base=True, scenery=True), display="simpleplane")
        self.car = e.load(str(car), LoadSettings(
            position=(0.0, 0.0, 0.1), inertia_from_file=True,
            implicit_cylinder=implicit_cylinder), display="simplecar")
        self.goal_marker = e.load(str(marker), LoadSettings(
            fixed_base=True, position=(0.0, 0.0, 0.5), scenery=True), display="goal")
        self._start = e.save()  # and primed: the first episode is like every later one
        #: The one step loop (:mod:`urdfkit.motion.stepping`), with the car's controller.
        self._loop = StepLoop(e, self.TIME_STEP)
        self._controls = (self._control,)
        # bound once: a step is short (~80 us), and each lookup shows in it
        self._motors, self._base = e.motors, e.base_state

    # ---- the Gymnasium API

    def reset(self, *, seed: int | None = None, options: dict[str, Any] | None = None
              ) -> tuple[np.ndarray, dict[str, object]]:
        """Start an episode: the car at rest at the origin, a new goal.

        The goal is drawn as the tutorial draws it, from ``np_random``: x and y each from
        ``[5, 9]`` or ``[-9, -5]``, with equal chance. ``options={"goal": (x, y)}`` sets it.
        """
        _open(self)
        super().reset(seed=seed)
        self._ended = self._warned_end = False
        e = self.engine
        e.restore(self._start)
        goal = (options or {}).get("goal")
        if goal is not None:
            gx, gy = _finite_pair(goal)
        else:
            # The tutorial's uniform(-5, -9), which numpy's Generator refuses (low > high):
            # -uniform(5, 9) is the same draw.
            rng = self.np_random
            gx = rng.uniform(5, 9) if rng.integers(2) else -rng.uniform(5, 9)
            gy = rng.uniform(5, 9) if rng.integers(2) else -rng.uniform(5, 9)
        self.goal = (float(gx), float(gy))
        e.reset_base(self.goal_marker, (float(gx), float(gy), 0.5), (0.0, 0.0, 0.0, 1.0))
        self._speed = 0.0
        self._steer = None
        self._loop.step_count = 0
        obs = self._observe()
        self._previous_distance = math.hypot(obs[0] - gx, obs[1] - gy)
        if self.render_mode == "human":
            self._last_frame = time.perf_counter()
        return obs, {"distance": self._previous_distance}

    def step(self, action: object) -> tuple[np.ndarray, float, bool, bool, dict[str, object]]:
        """Apply (throttle, steer) for one 1/30 s physics step.

        Raises:
            ValueError: an action that is not two finite numbers.
        """
        _open(self)
        throttle, steer = _finite_pair(action)
        _after_end(self)
        self._throttle = min(max(throttle, 0.0), 1.0)
        self._steer_asked = max(min(steer, 0.6), -0.6)
        self._loop.step(1, self._controls)
        obs = self._observe()
        x, y = float(obs[0]), float(obs[1])
        gx, gy = self.goal
        distance = math.hypot(x - gx, y - gy)
        reward = max(self._previous_distance - distance, 0.0)
        self._previous_distance = distance
        reached = False
        terminated = True
        if not (-self.ARENA < x < self.ARENA and -self.ARENA < y < self.ARENA):
            pass
        elif distance < self.GOAL_RADIUS:
            reached = True
            reward = self.GOAL_BONUS
        else:
            terminated = False
        if self.render_mode == "human" and self.engine.gui:
            self._follow_in_gui(x, y)
        self._ended = terminated
        return obs, reward, terminated, False, {"distance": distance, "is_success": reached}

    def _control(self, t: float) -> None:
        """The car's controller: hinges at the steering angle, wheels at the throttle's speed.

        The wheel speed the throttle builds up is integrated over the coming step.
        """
        motors, car, steer = self._motors, self.car, self._steer_asked
        if steer != self._steer:  # position motors persist: set on change
            motors(car, _HINGES, "position", [steer, steer])
            self._steer = steer
        v = self._speed
        v += self.TIME_STEP * (self.C_THROTTLE * self._throttle - v * (v * self.C_DRAG
                                                                       + self.C_ROLLING))
        self._speed = v = max(v, 0.0)
        force = self.WHEEL_FORCE
        motors(car, _WHEELS, "velocity", [v, v, v, v], forces=[force, force, force, force])

    def _observe(self) -> np.ndarray:
        base = self._base(self.car)
        pos, (qx, qy, qz, qw), lin = base.position, base.orientation, base.linear
        # cos and sin of PyBullet's yaw, atan2(b, a), without the angle.
        a = qw * qw + qx * qx - qy * qy - qz * qz
        b = 2.0 * (qx * qy + qw * qz)
        h = math.hypot(a, b)
        cos, sin = (a / h, b / h) if h > 0 else (1.0, 0.0)
        return np.array((pos[0], pos[1], cos, sin, lin[0], lin[1], *self.goal),
                        dtype=np.float32)

    def render(self) -> np.ndarray | None:  # type: ignore[override, unused-ignore]
        """An ``rgb_array`` frame (height x width x 3, uint8); None in ``human`` mode."""
        if self.render_mode != "rgb_array":
            return None
        pos, orn = self.engine.base_pose(self.car)
        if self.camera == "chase":
            # The tutorial's camera: at the car, 0.2 m up, looking along its heading.
            m = quat_to_matrix(orn)
            ahead, up = (m[0][0], m[1][0], m[2][0]), (m[0][2], m[1][2], m[2][2])
            eye = (pos[0], pos[1], 0.2)
            camera = Camera(eye, (eye[0] + ahead[0], eye[1] + ahead[1], eye[2] + ahead[2]), up,
                            fov=80.0)
        else:
            camera = Camera((0.0, -13.0, 17.0), (0.0, 0.0, 0.0))
        return _frame(self.engine.camera_image(camera, self.width, self.height),
                      self.width, self.height)

    def _follow_in_gui(self, x: float, y: float) -> None:
        from urdfkit.engine.pybullet_gui import follow

        follow(self.engine, 4.0, -40.0, -35.0, (x, y, 0.0))
        wait = self._last_frame + self.TIME_STEP - time.perf_counter()
        if wait > 0:
            time.sleep(wait)
        self._last_frame = time.perf_counter()

    def close(self) -> None:
        """Disconnect the client (safe to call twice); reset or step after it is an error."""
        self._closed = True
        if "engine" in self.__dict__:
            self.engine.close()
        tmp = self.__dict__.pop("_tmp", None)
        if tmp is not None:
            tmp.cleanup()


# --------------------------------------------------------------------------- ScenarioEnv

#: The observation fields a flat observation takes by default: joints, and a floating base.
JOINT_FIELDS = ("motor_angles", "motor_velocities")
BASE_FIELDS = ("base_position", "base_orientation", "base_lin_vel", "base_ang_vel")
#: Fallback action bounds when the URDF gives no limit (documented in docs/gym.md).
DEFAULT_VELOCITY = 10.0
DEFAULT_TORQUE = 10.0
DEFAULT_THROTTLE = 20.0


class ScenarioEnv(gym.Env):
    """Any urdfkit scenario as a Gymnasium environment (see ``docs/gym.md``).

    The agent commands one robot (``robot``; default the only one with a controller). Its
    action space follows the scenario's controller: for ``drive``, ``[throttle, steer]``
    (wheel rad/s, rad); for ``joints``, one value per joint the segments command, in each
    joint's mode (position within its limits, velocity, or torque), in scenario order. A
    robot with a ``motor`` table and no segments takes positions for every servo joint.

    The observation is the robot's reported observation (the scenario's noise and delay
    apply), flattened to float32 in the order :attr:`observation_names` gives, or a
    ``Dict`` of the fields with ``observation="dict"``.

    Args:
        scenario: A scenario file, a scenario dict, or a :class:`~urdfkit.sim.Simulation`
            (which the environment then owns and closes).
        robot: The robot the agent drives.
        reward: ``reward(obs) -> float``, given the reported :class:`~urdfkit.sim.Observation`
            after each step (named fields: ``obs.motor_angles["knee"]``); default 0.
        terminated: ``terminated(obs) -> bool``; default never.
        max_episode_steps: Truncation; default the scenario's duration.
        frame_skip: Physics steps per environment step (the action holds through them).
        render_mode: ``"rgb_array"`` or ``"human"`` (a GUI window).
        observation: ``"flat"`` or ``"dict"``.
        fields: The observation fields to include; default the joints' angles and
            velocities, plus the base pose and velocities for a floating base.
        action_bounds: Per action name (joint, ``throttle`` or ``steer``), ``(low, high)``
            instead of the defaults.
        engine: The physics engine instead of the scenario's ``physics.engine``
            (``pybullet``, ``mujoco``); not with a :class:`~urdfkit.sim.Simulation`, which
            has its own.
    """

    metadata = {"render_modes": ["human", "rgb_array"], "render_fps": 30}

    def __init__(self, scenario: str | Path | Mapping[str, object] | Simulation,
                 robot: str | None = None,
                 reward: Callable[[Observation], float] | None = None,
                 terminated: Callable[[Observation], bool] | None = None,
                 max_episode_steps: int | None = None, frame_skip: int = 1,
                 render_mode: RenderMode | None = None, *,
                 observation: Literal["flat", "dict"] = "flat",
                 fields: Sequence[str] | None = None,
                 action_bounds: Mapping[str, tuple[float, float]] | None = None,
                 width: int = 320, height: int = 240, engine: str | None = None):
        from urdfkit.sim import OBSERVATION_FIELDS, Simulation

        if render_mode is not None and render_mode not in self.metadata["render_modes"]:
            raise ParameterError(f"render_mode must be rgb_array, human or None, got "
                                 f"{render_mode!r}", param="render_mode")
        if observation not in ("flat", "dict"):
            raise ParameterError(f"observation must be flat or dict, got {observation!r}",
                                 param="observation")
        if max_episode_steps is not None and (isinstance(max_episode_steps, bool) or
                                              not isinstance(max_episode_steps, int) or
                                              max_episode_steps < 1):
            raise ParameterError(f"max_episode_steps must be an integer >= 1, got "
                                 f"{max_episode_steps!r}", param="max_episode_steps")
        if not isinstance(frame_skip, int) or frame_skip < 1:
            raise ParameterError(f"frame_skip must be an integer >= 1, got {frame_skip!r}",
                                 param="frame_skip")
        for name, fn in (("reward", reward), ("terminated", terminated)):
            if fn is not None and not callable(fn):
                raise ParameterError(f"{name} must be a callable taking the observation",
                                     param=name)
        if engine is not None:
            check_engine(engine)
        gui = _gui(render_mode)
        if isinstance(scenario, Simulation):
            if engine is not None and engine != scenario.engine.name:
                raise ParameterError(f"engine={engine!r}: the Simulation given runs on "
                                     f"{scenario.engine.name}", param="engine")
            if gui and not scenario.engine.gui:
                raise ParameterError("render_mode='human' needs a Simulation made with "
                                     "gui=True", param="render_mode")
            self.sim = scenario
        elif isinstance(scenario, Mapping):
            self.sim = Simulation(scenario, gui=gui, engine=engine)
        else:
            self.sim = Simulation.from_file(scenario, gui=gui, engine=engine)
        try:
            self.robot = self._pick_robot(robot)
            self._build_action_space(dict(action_bounds or {}))
            b = self.sim.robot(self.robot)
            chosen = list(fields) if fields is not None else [
                *JOINT_FIELDS, *(BASE_FIELDS if b.config.base == "floating" else ())]
            for f in chosen:
                if f not in OBSERVATION_FIELDS:
                    raise ParameterError(f"no observation field {f!r}; known: "
                                         f"{', '.join(OBSERVATION_FIELDS)}", param="fields")
            self.fields = chosen
            self._build_observation_space(observation)
            self._randomize = self._randomize_plan()
        except BaseException:
            self.sim.close()
            raise
        self.reward_fn = reward
        self.terminated_fn = terminated
        self.frame_skip = frame_skip
        self.render_mode = render_mode
        self.width, self.height = width, height
        duration_steps = self.sim.total_steps
        self.max_episode_steps = max_episode_steps if max_episode_steps is not None else \
            max(1, round(duration_steps / frame_skip))
        self._steps = 0

    # ---- construction

    def _pick_robot(self, robot: str | None) -> str:
        names = self.sim.robot_names()
        if robot is not None:
            if robot not in names:
                raise ParameterError(f"no robot named {robot!r}; robots: {', '.join(names)}",
                                     param="robot")
            return robot
        driven = [n for n in names if self._controller(self.sim.robot(n).config)]
        if len(driven) == 1:
            return driven[0]
        if not driven:
            raise ParameterError("no robot has a controller (drive or joints segments, or a "
                                 "motor table) for the agent to command", param="robot")
        raise ParameterError(f"several robots have controllers ({', '.join(driven)}); say "
                             "which one the agent drives with robot=...", param="robot")

    @staticmethod
    def _controller(cfg: RobotConfig) -> Literal["drive", "joints"] | None:
        if cfg.drive is not None:
            return "drive"
        if cfg.joints is not None or cfg.motor is not None:
            return "joints"
        return None

    def _build_action_space(self, bounds: dict[str, tuple[float, float]]) -> None:
        b = self.sim.robot(self.robot)
        self.controller = self._controller(b.config)
        self.modes: dict[str, Mode] = {}
        if self.controller == "drive":
            names, lows, highs = self._drive_action(b, bounds)
        else:
            self.modes = self._joint_modes(b)
            names, lows, highs = [], [], []
            for name in self.modes:
                lo, hi = self._joint_bounds(b, name, bounds)
                names.append(name)
                lows.append(lo)
                highs.append(hi)
        if bounds:
            raise ParameterError(f"action_bounds names {', '.join(sorted(bounds))}, not in "
                                 f"the action ({', '.join(names)})", param="action_bounds")
        for name, lo, hi in zip(names, lows, highs, strict=True):
            if not (math.isfinite(lo) and math.isfinite(hi) and lo < hi):
                raise ParameterError(f"action bounds of {name} must be finite with low < "
                                     f"high, got ({lo}, {hi})", param="action_bounds")
        self.action_names = names
        self.action_space = spaces.Box(np.array(lows, dtype=np.float32),
                                       np.array(highs, dtype=np.float32))
        self._low, self._high = self.action_space.low, self.action_space.high
        self._by_mode: dict[Mode, list[int]] = {}
        for k, name in enumerate(names if self.controller == "joints" else []):
            self._by_mode.setdefault(self.modes[name], []).append(k)

    def _drive_action(self, b: SimRobot, bounds: dict[str, tuple[float, float]]
                      ) -> tuple[list[str], list[float], list[float]]:
        """Throttle and steer, the steer's range from the drive train unless ``bounds`` says."""
        from urdfkit.motion.vehicle import clamp_steer

        train = b.train
        assert train is not None
        lo, hi = train.steer_range() if train.hinges else (0.0, 0.0)
        steer = bounds.pop("steer", (lo, hi))
        throttle = bounds.pop("throttle", (-DEFAULT_THROTTLE, DEFAULT_THROTTLE))
        self._clamp = clamp_steer
        return ["throttle", "steer"], [throttle[0], steer[0]], [throttle[1], steer[1]]

    def _joint_modes(self, b: SimRobot) -> dict[str, Mode]:
        """The mode each commanded joint is driven in: one per joint, or the servo's joints."""
        modes: dict[str, Mode] = {}
        for seg in b.config.joints or []:
            for name in seg.targets:
                mode = seg.mode if isinstance(seg.mode, str) else seg.mode[name]
                if modes.setdefault(name, mode) != mode:
                    raise ParameterError(f"{self.robot}: joint {name} is commanded in "
                                         f"both {modes[name]} and {mode} mode; an "
                                         "action space needs one", param="scenario")
        if not modes and b.config.motor is not None:
            modes = {j.name: "position" for j in b.servo}
        if not modes:
            raise ParameterError(f"{self.robot} has no joint the agent could command",
                                 param="robot")
        return modes

    def _joint_bounds(self, b: SimRobot, name: str, bounds: dict[str, tuple[float, float]]
                      ) -> tuple[float, float]:
        """A joint's action range: from ``bounds``, else its URDF limits in the measured frame."""
        if name in bounds:
            return bounds.pop(name)
        spec = b.joint(name)
        lower, upper, effort, velocity = b.joint_limits(name)
        mode = self.modes[name]
        sign = b.directions.get(name, 1.0)
        offset = b.offsets.get(name, 0.0)
        if mode == "position":
            if lower < upper:  # measured frame: (q - offset) * direction
                ends = sorted(((lower - offset) * sign, (upper - offset) * sign))
                return ends[0], ends[1]
            if spec.revolute:
                return -math.pi, math.pi
            raise ParameterError(f"{name} has no position limits; give its range in "
                                 "action_bounds", param="action_bounds")
        if mode == "velocity":
            v = velocity if velocity > 0 else DEFAULT_VELOCITY
            return -v, v
        motor = b.config.motor
        limit = effort if effort > 0 else \
            motor.max_torque if motor is not None and isinstance(motor.max_torque, float) \
            else DEFAULT_TORQUE
        return -limit, limit

    def _field_names(self, field: str, value: dict[str, float] | list[float]) -> list[str]:
        if isinstance(value, dict):
            return [f"{field}.{k}" for k in value]
        axes = ("x", "y", "z", "w")[:len(value)]
        return [f"{field}.{a}" for a in axes]

    def _build_observation_space(self, kind: Literal["flat", "dict"]) -> None:
        first = self._observe()
        self.observation_kind = kind
        names: list[str] = []
        boxes: dict[str, spaces.Space[np.ndarray]] = {}
        for f in self.fields:
            these = self._field_names(f, getattr(first, f))
            names.extend(these)
            boxes[f] = spaces.Box(-np.inf, np.inf, shape=(len(these),), dtype=np.float32)
        self.observation_names = names
        self.observation_space = spaces.Dict(boxes) if kind == "dict" else \
            spaces.Box(-np.inf, np.inf, shape=(len(names),), dtype=np.float32)

    def _randomize_plan(self) -> Randomize | None:
        b = self.sim.robot(self.robot)
        r = b.config.randomize
        if r is None:
            return None
        # Nominal masses, for mass_scale: the scenario's, before any episode changed them.
        self._nominal_mass = {link: b.link_mass(link) for link in r.mass_scale}
        return r

    # ---- the Gymnasium API

    def _observe(self) -> Observation:
        """The robot's reported observation now (a copy)."""
        return self.sim.observation(self.robot)

    def _obs(self, o: Observation) -> np.ndarray | dict[str, np.ndarray]:
        if self.observation_kind == "dict":
            return {f: np.fromiter(_values(getattr(o, f)), dtype=np.float32)
                    for f in self.fields}
        out: list[float] = []
        for f in self.fields:
            out.extend(_values(getattr(o, f)))
        return np.array(out, dtype=np.float32)

    def reset(self, *, seed: int | None = None, options: dict[str, Any] | None = None
              ) -> tuple[np.ndarray | dict[str, np.ndarray], dict[str, object]]:
        """Restore the scenario's start in place (``Simulation.reset``), then randomise.

        The noise is reseeded from ``np_random``, so ``reset(seed=s)`` and the same actions
        give the same observations. ``options={"overrides": {...}}`` passes per-robot
        starts to :meth:`Simulation.reset`.
        """
        _open(self)
        super().reset(seed=seed)
        self._ended = self._warned_end = False
        rng = self.np_random
        overrides: dict[str, dict[str, Any]] = {
            k: dict(v) for k, v in ((options or {}).get("overrides") or {}).items()}
        r = self._randomize
        if r is not None:
            mine = overrides.setdefault(self.robot, {})
            cfg = self.sim.robot(self.robot).config
            if r.initial_joints:
                joints = dict(mine.get("initial_joints") or {})
                for name, (lo, hi) in r.initial_joints.items():
                    joints[name] = float(rng.uniform(lo, hi))
                mine["initial_joints"] = joints
            if r.position:
                start = mine.get("position", cfg.position)
                mine["position"] = [float(s + rng.uniform(lo, hi))
                                    for s, (lo, hi) in zip(start, r.position, strict=True)]
            if r.yaw is not None:
                roll, pitch, yaw = mine.get("orientation_rpy", cfg.orientation_rpy or (0, 0, 0))
                low, high = r.yaw
                mine["orientation_rpy"] = [roll, pitch, yaw + float(rng.uniform(low, high))]
        noise_seed = int(rng.integers(2**31 - 1))
        self.sim.reset(seed=noise_seed, overrides=overrides or None)
        if r is not None:
            for link, (lo, hi) in r.lateral_friction.items():
                self.sim.set_friction(self.robot, link, float(rng.uniform(lo, hi)))
            for link, (lo, hi) in r.mass_scale.items():
                self.sim.set_mass(self.robot, link,
                                  self._nominal_mass[link] * float(rng.uniform(lo, hi)))
        self._steps = 0
        self._apply(np.zeros(2) if self.controller == "drive" else None)
        obs = self._observe()
        return self._obs(obs), {}

    def _apply(self, action: np.ndarray | None) -> None:
        if action is None:
            return
        if self.controller == "drive":
            train = self.sim.robot(self.robot).train
            assert train is not None
            throttle, steer = float(action[0]), float(action[1])
            steer = self._clamp(train, steer)[0]
            self.sim.set_drive(self.robot, throttle=throttle, steer=steer)
            return
        for mode, ks in self._by_mode.items():
            self.sim.set_joint_targets(self.robot, {self.action_names[k]: float(action[k])
                                                    for k in ks}, mode=mode)

    def step(self, action: object
             ) -> tuple[np.ndarray | dict[str, np.ndarray], float, bool, bool, dict[str, object]]:
        """Command the action (clipped to the space) for ``frame_skip`` physics steps.

        Raises:
            ValueError: an action of the wrong size, or not finite.
        """
        _open(self)
        _real(action)
        a = np.asarray(action, dtype=np.float64).reshape(-1)
        if a.shape != self._low.shape:
            raise ValueError(f"expected an action of {len(self.action_names)} values "
                             f"({', '.join(self.action_names)}), got shape "
                             f"{np.asarray(action).shape}")
        if not np.all(np.isfinite(a)):
            raise ValueError(f"the action must be finite, got {a.tolist()}")
        _after_end(self)
        a = np.clip(a, self._low, self._high)
        self._apply(a)
        self.sim.step(self.frame_skip)
        self._steps += 1
        o = self._observe()
        reward = float(self.reward_fn(o)) if self.reward_fn is not None else 0.0
        done = bool(self.terminated_fn(o)) if self.terminated_fn is not None else False
        truncated = not done and self._steps >= self.max_episode_steps
        if self.render_mode == "human":
            time.sleep(max(0.0, self.frame_skip * self.sim.time_step))
        self._ended = done or truncated
        return self._obs(o), reward, done, truncated, {"t": o.t}

    def render(self) -> np.ndarray | None:  # type: ignore[override, unused-ignore]
        """An ``rgb_array`` frame looking at the robot (height x width x 3, uint8)."""
        if self.render_mode != "rgb_array":
            return None
        x, y, z = self.sim.robot(self.robot).base_position()
        camera = Camera.orbit((x, y, z), 2.0, 45.0, -30.0)
        return _frame(self.sim.engine.camera_image(camera, self.width, self.height),
                      self.width, self.height)

    def close(self) -> None:
        """Close the simulation (safe to call twice); reset or step after it is an error."""
        self._closed = True
        self.sim.close()


def _frame(rgb: bytes, width: int, height: int) -> np.ndarray:
    """An engine's RGB bytes as Gymnasium's frame: height x width x 3, uint8, writable."""
    return np.frombuffer(rgb, dtype=np.uint8).reshape(height, width, 3).copy()


def _values(value: dict[str, float] | list[float]) -> list[float]:
    return list(value.values()) if isinstance(value, dict) else list(value)


if SIMPLE_DRIVING_ID not in gym.registry:
    gym.register(id=SIMPLE_DRIVING_ID, entry_point="urdfkit.gym:SimpleDrivingEnv",
                 max_episode_steps=250)
