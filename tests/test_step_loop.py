"""The one step loop (issue 50): drive, Simulation and both Gymnasium environments step their
worlds through :class:`urdfkit.motion.stepping.StepLoop`, and nothing else outside engine/
calls an engine's step.

Who called each step is read off the call stack while real runs go, on both engines; the
loop's own contract (controllers before each step at its start time, records at multiples of
``every`` and at the end, the three early ends) is held against raw PyBullet and a counting
engine.
"""

from __future__ import annotations

import json
import math
import sys
from collections.abc import Callable, Iterator
from pathlib import Path

import pytest

import urdfkit
from urdfkit.engine.pybullet import PyBulletEngine
from urdfkit.motion import stepping
from urdfkit.motion.stepping import Closed, StepLoop

PACKAGE = Path(urdfkit.__file__).parent
EXAMPLES = Path(__file__).parent.parent / "examples"
LOOP_FILE = str(PACKAGE / "motion" / "stepping.py")

#: Modules outside engine/ allowed to step an engine themselves: agree's swing steps
#: PyBullet and MuJoCo's own model of the file side by side, one step each, to compare them.
LOCKSTEP = {"exchange/agree_swing.py"}


@pytest.fixture
def callers(monkeypatch: pytest.MonkeyPatch) -> Iterator[set[str]]:
    """Every file that called an engine's step during the test."""
    seen: set[str] = set()

    def watched(step: Callable[[], None]) -> Callable[[], None]:
        def step_and_note() -> None:
            seen.add(sys._getframe(1).f_code.co_filename)
            step()
        return step_and_note

    bind = PyBulletEngine._bind

    def bind_watched(self: PyBulletEngine) -> None:
        bind(self)
        self.step = watched(self.step)

    monkeypatch.setattr(PyBulletEngine, "_bind", bind_watched)
    from urdfkit.engine.mujoco import MuJoCoEngine  # [test] installs mujoco

    mujoco_step = MuJoCoEngine.step

    def mujoco_watched(self: MuJoCoEngine) -> None:
        seen.add(sys._getframe(1).f_code.co_filename)
        mujoco_step(self)

    monkeypatch.setattr(MuJoCoEngine, "step", mujoco_watched)
    yield seen


@pytest.mark.parametrize("engine", ["pybullet", "mujoco"])
def test_drive_sim_and_both_environments_step_through_the_one_loop(
        engine: str, callers: set[str]) -> None:
    import gymnasium

    import urdfkit.gym  # noqa: F401  (registers the id)
    from urdfkit.gym import ScenarioEnv
    from urdfkit.motion.drive import DriveConfig, drive
    from urdfkit.sim import Simulation

    result = drive(DriveConfig(throttle=10, steer=0.2, steps=240, engine=engine))
    assert result.steps == 240 and result.distance > 0.1
    assert callers == {LOOP_FILE}
    callers.clear()

    scenario = json.loads((EXAMPLES / "two_cars.json").read_text("utf-8"))
    scenario["physics"].pop("solver_iterations", None)  # PyBullet's alone
    with Simulation(scenario, base_dir=EXAMPLES, engine=engine) as sim:
        sim.step(5)
        run = sim.run(0.1)
        assert sim.step_count == 5 + round(0.1 / sim.time_step) and run.rows
    assert callers == {LOOP_FILE}
    callers.clear()

    env = gymnasium.make("urdfkit/SimpleDriving-v0", engine=engine)
    env.reset(seed=0)
    for _ in range(3):
        env.step([1.0, 0.1])
    env.close()
    assert callers == {LOOP_FILE}
    callers.clear()

    senv = ScenarioEnv(scenario | {"duration": 1.0}, robot="north", engine=engine)
    senv.reset(seed=0)
    senv.step(senv.action_space.sample())
    senv.close()
    assert callers == {LOOP_FILE}


def test_no_module_outside_engine_steps_an_engine_but_the_loop() -> None:
    """Read from the source: ``.step`` of an engine, or PyBullet's stepSimulation, is called
    in stepping.py alone (and agree's lockstep swing)."""
    import ast

    found = set()
    for path in sorted(PACKAGE.rglob("*.py")):
        rel = path.relative_to(PACKAGE).as_posix()
        if rel.startswith("engine/"):
            continue
        for node in ast.walk(ast.parse(path.read_text("utf-8"))):
            if isinstance(node, ast.Attribute) and (
                    node.attr == "stepSimulation" or node.attr == "step" and (
                        isinstance(node.value, ast.Name) and node.value.id in ("e", "engine")
                        or isinstance(node.value, ast.Attribute)
                        and node.value.attr in ("engine", "_engine"))):
                found.add(rel)
    assert found - LOCKSTEP == {"motion/stepping.py"}


# ---- the loop's contract


def _pendulum(engine: PyBulletEngine) -> int:
    from urdfkit.engine.api import LoadSettings

    body = engine.load(str(EXAMPLES / "pendulum.urdf"), LoadSettings(fixed_base=True))
    engine.motors(body, [0], "velocity", [0.0], forces=[0.0])
    return body


def test_controls_run_before_each_step_as_a_hand_written_pybullet_loop() -> None:
    """A torque that follows time, applied by a controller, gives raw PyBullet's swing."""
    from urdfkit.engine.session import import_pybullet

    p = import_pybullet()
    dt = 1 / 240

    def torque(t: float) -> float:
        return 2.0 * math.sin(7.0 * t)

    engine = PyBulletEngine()
    try:
        engine.set_time_step(dt)
        engine.set_gravity((0.0, 0.0, -9.81))
        body = _pendulum(engine)
        loop = StepLoop(engine, dt)
        times: list[float] = []

        def control(t: float) -> None:
            times.append(t)
            engine.motors(body, [0], "torque", [torque(t)])

        loop.step(300, [control])
        ours = engine.joint_states(body, [0])[0]
    finally:
        engine.close()
    assert times == [k * dt for k in range(300)]

    client = p.connect(p.DIRECT)
    try:
        p.setTimeStep(dt, physicsClientId=client)
        p.setGravity(0, 0, -9.81, physicsClientId=client)
        raw = p.loadURDF(str(EXAMPLES / "pendulum.urdf"), useFixedBase=True,
                         physicsClientId=client)
        p.setJointMotorControl2(raw, 0, p.VELOCITY_CONTROL, force=0, physicsClientId=client)
        for k in range(300):
            p.setJointMotorControl2(raw, 0, p.TORQUE_CONTROL, force=torque(k * dt),
                                    physicsClientId=client)
            p.stepSimulation(physicsClientId=client)
        q, v = p.getJointState(raw, 0, physicsClientId=client)[:2]
    finally:
        p.disconnect(client)
    assert (ours.position, ours.velocity) == (q, v)
    assert abs(q) > 0.01  # the torque moved it: a loop that skipped the control would not


class _Counting:
    """An engine that only counts its steps, and can fail at one."""

    class Error(Exception):
        """What its step raises at ``fail_at`` (a closed window's ``pybullet.error``)."""

    error = Error

    def __init__(self, gui: bool = False, fail_at: int | None = None,
                 connected: bool = True) -> None:
        self.gui, self.fail_at, self._connected = gui, fail_at, connected
        self.steps = 0

    def step(self) -> None:
        if self.steps == self.fail_at:
            raise self.Error("closed")
        self.steps += 1

    def connected(self) -> bool:
        return self._connected


def _run(engine: _Counting, end: int, every: int, **kw: object) -> tuple[bool, list[int]]:
    loop = StepLoop(engine, 0.01)  # type: ignore[arg-type]
    taken: list[int] = []
    ended = loop.run(end, every, lambda: taken.append(loop.step_count), **kw)  # type: ignore[arg-type]
    return ended, taken


def test_records_at_every_multiple_the_start_and_the_end() -> None:
    progress: list[tuple[int, int]] = []
    ended, taken = _run(_Counting(), 25, 10, start=True, last=True,
                        progress=lambda done, total: progress.append((done, total)))
    assert (ended, taken) == (False, [0, 10, 20, 25])
    assert progress == [(10, 25), (20, 25), (25, 25)]
    assert _run(_Counting(), 25, 10)[1] == [10, 20]


def test_a_closed_window_or_ctrl_c_ends_the_run_keeping_what_was_recorded() -> None:
    # the engine's step fails once its window is closed
    assert _run(_Counting(gui=True, fail_at=13, connected=False), 40, 5) == (True, [5, 10])
    # the same failure with the window still open is a real error
    with pytest.raises(_Counting.Error):
        _run(_Counting(gui=True, fail_at=13, connected=True), 40, 5)
    with pytest.raises(_Counting.Error):
        _run(_Counting(gui=False, fail_at=13, connected=False), 40, 5)

    def interrupt(n: int) -> None:
        raise KeyboardInterrupt

    def close(t: float) -> None:
        raise Closed

    assert _run(_Counting(), 40, 5, step=interrupt) == (True, [])
    engine = _Counting()
    loop = StepLoop(engine, 0.01)  # type: ignore[arg-type]
    assert loop.run(40, 5, lambda: None, step=lambda n: loop.step(n, [close])) is True
    assert engine.steps == 0


def test_real_time_paces_to_the_wall_clock(monkeypatch: pytest.MonkeyPatch) -> None:
    clock = [0.0]
    slept: list[float] = []
    monkeypatch.setattr(stepping.time, "perf_counter", lambda: clock[0])

    def sleep(s: float) -> None:
        slept.append(s)
        clock[0] += s

    monkeypatch.setattr(stepping.time, "sleep", sleep)
    loop = StepLoop(_Counting(), 1 / 240)  # type: ignore[arg-type]
    loop.run(240, 240, lambda: None, real_time=True)
    # a 60th of a second between waits: 4 steps at 240 Hz, a second in all
    assert len(slept) == 60 and math.isclose(sum(slept), 1.0)
