"""drive, sim, sweep and the Gymnasium environments on MuJoCo (``--engine mujoco``), held
against physics (the kinematic bicycle, rolling without slip) and against the same run on
PyBullet: the same keys, columns, spaces and detection, each document naming its engine."""

from __future__ import annotations

import json
import math
from pathlib import Path

import pytest
from typer.testing import CliRunner

from urdfkit.cli import app
from urdfkit.core.errors import ParameterError
from urdfkit.motion.drive import DriveConfig, Scenario, drive
from urdfkit.motion.drive_result import DriveResult

pytest.importorskip("mujoco")

EXAMPLES = Path(__file__).resolve().parents[1] / "examples"
WHEEL_RADIUS, WHEELBASE = 0.1, 0.4  # simplecar's defaults


@pytest.fixture(scope="module")
def turning() -> DriveResult:
    return drive(DriveConfig(throttle=10, steer=0.2, seconds=10, engine="mujoco"))


@pytest.fixture(scope="module")
def straight() -> DriveResult:
    return drive(DriveConfig(throttle=10, steer=0, seconds=5, engine="mujoco"))


def test_simplecar_turns_on_the_kinematic_bicycles_circle(turning: DriveResult) -> None:
    # R = wheelbase / tan(steer) from the rear axle (Ackermann, the centre line's radius)
    bicycle = WHEELBASE / math.tan(0.2)
    assert turning.turning_radius is not None
    assert turning.turning_radius == pytest.approx(bicycle, rel=0.05)
    assert turning.simulated["engine"] == "mujoco"
    assert not turning.problems


def test_simplecar_drives_straight_at_wheel_speed_times_radius(straight: DriveResult) -> None:
    # rolling without slip: v = omega r = 1 m/s for 5 s
    assert straight.distance == pytest.approx(10 * WHEEL_RADIUS * 5, rel=0.05)
    x, y, _ = straight.final_position
    assert abs(y) < 0.01 and abs(straight.heading_change) < 0.01
    assert x == pytest.approx(5.0, rel=0.05)


def test_racecar_turns_on_its_bicycles_circle() -> None:
    """Its right steering hinge is `continuous` with a <limit>: taken for a caster on MuJoCo
    (with its wheel) until the engine reported the bounds as PyBullet does; the car then
    turned on a 2.58 m circle for a 1.05 m bicycle."""
    r = drive(DriveConfig(urdf="racecar/racecar.urdf", throttle=10, steer=0.3, seconds=6,
                          engine="mujoco"))
    assert r.expected_radius is not None and r.turning_radius is not None
    assert r.turning_radius == pytest.approx(r.expected_radius, rel=0.05)


def test_drive_json_has_the_same_keys_on_both_engines_and_names_its_engine() -> None:
    runner = CliRunner()
    docs = {}
    for engine in ("pybullet", "mujoco"):
        out = runner.invoke(app, ["drive", "--seconds", "1", "--json", "--engine", engine])
        assert out.exit_code == 0, out.output
        docs[engine] = json.loads(out.stdout)

    def keys(d: object, path: str = "") -> set[str]:
        if isinstance(d, dict):
            return {f"{path}.{k}" for k in d} | {x for k, v in d.items()
                                                 for x in keys(v, f"{path}.{k}")}
        return set()

    assert keys(docs["pybullet"]) == keys(docs["mujoco"])
    assert docs["mujoco"]["simulated"]["engine"] == "mujoco"
    assert docs["pybullet"]["simulated"]["engine"] == "pybullet"
    # MuJoCo has no link damping: said, not PyBullet's 0.04
    assert docs["mujoco"]["simulated"]["link_damping"]["linear"] == 0.0


@pytest.mark.parametrize(("args", "said"), [
    (["--tutorial"], "--tutorial reproduces PyBullet's tutorial loop"),
    (["--engine", "bullet3"], "no engine named 'bullet3'"),
    (["--gui"], None),
])
def test_drive_refuses_what_mujoco_cannot_mean(args: list[str], said: str | None,
                                               monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setenv("DISPLAY", "")
    engine = [] if "--engine" in args else ["--engine", "mujoco"]
    out = CliRunner().invoke(app, ["drive", "--seconds", "1", *engine, *args])
    assert out.exit_code == 2, out.output
    assert "Traceback" not in out.output
    if said is not None:
        assert said in out.output


def test_a_robot_the_export_refuses_names_the_link_and_the_fix(tmp_path: Path) -> None:
    car = tmp_path / "car.urdf"
    # simplecar with a body inertia that breaks the triangle inequality (0.01 + 0.01 < 0.05)
    from urdfkit.model.catalog import build_template

    text = build_template("simplecar").to_bytes().decode()
    start = text.index("<inertia ", text.index('<link name="base_link"'))
    end = text.index("/>", start) + 2
    car.write_text(text[:start] + '<inertia ixx="0.01" iyy="0.01" izz="0.05" ixy="0" ixz="0" '
                   'iyz="0"/>' + text[end:])
    out = CliRunner().invoke(app, ["drive", "--urdf", str(car), "--seconds", "1",
                                   "--engine", "mujoco"])
    assert out.exit_code == 2, out.output
    assert "base_link" in out.output and "urdfkit fix" in out.output
    assert str(car) in out.output or "car.urdf" in out.output


def test_gazebo_stiffness_mujoco_cannot_carry_is_named_and_friction_applied(
        tmp_path: Path) -> None:
    from urdfkit.model.catalog import build_template

    text = build_template("simplecar").to_bytes().decode()
    gazebo = ('<gazebo reference="base_to_left_back_wheel_link"><mu1>0.9</mu1><mu2>0.8</mu2>'
              '<kp>1e6</kp><kd>100</kd></gazebo>')
    wheel = [n for n in ("left_back_wheel", "base_to_left_back_wheel") if
             f'<link name="{n}"' in text][0]
    car = tmp_path / "car.urdf"
    car.write_text(text.replace("</robot>", gazebo.replace(
        "base_to_left_back_wheel_link", wheel) + "</robot>"))
    with Scenario(DriveConfig(urdf=str(car), steps=1, engine="mujoco",
                              gazebo_contacts=True)) as sc:
        assert sc.gazebo_applied == {wheel: {"lateralFriction": 0.8}}
        assert any("contact stiffness not applied on MuJoCo" in w and wheel in w
                   for w in sc.warnings)
        index = sc.engine.link_names(sc.body).index(wheel) - 1
        assert sc.engine.dynamics(sc.body, index).lateral_friction == 0.8


# --------------------------------------------------------------------------- sim


def test_sim_rows_have_the_same_columns_on_both_engines(tmp_path: Path) -> None:
    from urdfkit.sim import Simulation

    source = (EXAMPLES / "two_cars.toml").read_text()
    scenario = tmp_path / "two_cars.toml"
    scenario.write_text(source.replace("solver_iterations = 30", ""))
    rows = {}
    for engine in ("pybullet", "mujoco"):
        with Simulation.from_file(scenario, engine=engine) as s:
            assert s.engine.name == engine
            result = s.run(1.0)
            rows[engine] = result.to_dicts()
    assert [sorted(r) for r in rows["pybullet"]] == [sorted(r) for r in rows["mujoco"]]
    # the driven car goes the same way on both: within 5 cm after 1 s
    last = {e: [r for r in rows[e] if r["robot"] == "north"][-1] for e in rows}
    for k in range(2):
        assert last["mujoco"]["base_position"][k] == pytest.approx(
            last["pybullet"]["base_position"][k], abs=0.05)


def test_sim_names_a_key_mujoco_has_no_meaning_for() -> None:
    out = CliRunner().invoke(app, ["sim", str(EXAMPLES / "two_cars.toml"), "--engine",
                                   "mujoco"])
    assert out.exit_code == 2, out.output
    assert "two_cars.toml" in out.output and "physics.solver_iterations" in out.output
    assert len(out.output.strip().splitlines()) == 1


@pytest.mark.parametrize(("change", "key", "said"), [
    ({"link_dynamics": {"arm": {"restitution": 0.5}}}, "robots[0].link_dynamics.arm",
     "do not bounce"),
    ({"linear_damping": 0.1}, "robots[0].linear_damping", "no per-body velocity damping"),
])
def test_sim_names_a_robot_key_mujoco_cannot_carry(tmp_path: Path, change: dict[str, object],
                                                   key: str, said: str) -> None:
    document = json.loads((EXAMPLES / "pendulum_servo.json").read_text())
    document["physics"] = {"engine": "mujoco"}
    document["robots"][0]["urdf"] = str(EXAMPLES / "pendulum.urdf")
    document["robots"][0].update(change)
    scenario = tmp_path / "p.json"
    scenario.write_text(json.dumps(document))
    out = CliRunner().invoke(app, ["sim", str(scenario)])
    assert out.exit_code == 2, out.output
    line, = out.output.strip().splitlines()
    assert str(scenario) in line and key in line and said in line


def test_sim_json_names_its_engine(tmp_path: Path) -> None:
    scenario = tmp_path / "p.json"
    document = json.loads((EXAMPLES / "pendulum_servo.json").read_text())
    document["physics"] = {**document.get("physics", {}), "engine": "mujoco"}
    document["robots"][0]["urdf"] = str(EXAMPLES / "pendulum.urdf")
    scenario.write_text(json.dumps(document))
    out = CliRunner().invoke(app, ["sim", str(scenario), "--json"])
    assert out.exit_code == 0, out.output
    assert json.loads(out.stdout)["engine"] == "mujoco"


# --------------------------------------------------------------------------- sweep


def test_sweep_varies_the_engine() -> None:
    out = CliRunner().invoke(app, ["sweep", "drive", "--vary", "engine=pybullet,mujoco",
                                   "--seconds", "4", "--steer", "0.2", "--jobs", "1",
                                   "--json"])
    assert out.exit_code == 0, out.output
    rows = json.loads(out.stdout)["rows"]
    assert [r["engine"] for r in rows] == ["pybullet", "mujoco"]
    assert rows[1]["distance"] == pytest.approx(rows[0]["distance"], rel=0.05)


# --------------------------------------------------------------------------- gym


def test_simple_driving_on_mujoco_has_the_same_spaces_and_drives() -> None:
    import numpy as np

    from urdfkit.gym import SimpleDrivingEnv

    envs = [SimpleDrivingEnv(render_mode="rgb_array"),
            SimpleDrivingEnv(render_mode="rgb_array", engine="mujoco")]
    try:
        assert envs[0].action_space == envs[1].action_space
        assert envs[0].observation_space == envs[1].observation_space
        ends = []
        for env in envs:
            obs, _ = env.reset(seed=3, options={"goal": (8.0, 8.0)})
            assert env.observation_space.contains(obs)
            for _ in range(60):  # 2 s at full throttle, straight
                obs, reward, *_ = env.step(np.array([1.0, 0.0], dtype=np.float32))
            ends.append(obs)
            frame = env.render()
            assert frame is not None and frame.shape == (240, 320, 3)
            assert frame.std() > 5  # a picture, not a blank
        # the same car, the same throttle model: x within 10 cm after 2 s
        assert float(ends[1][0]) == pytest.approx(float(ends[0][0]), abs=0.1)
        assert abs(float(ends[1][1])) < 0.05
    finally:
        for env in envs:
            env.close()


def test_scenario_env_takes_an_engine(tmp_path: Path) -> None:
    from urdfkit.gym import ScenarioEnv

    envs = [ScenarioEnv(EXAMPLES / "pendulum_servo.json", engine=e)
            for e in ("pybullet", "mujoco")]
    try:
        assert envs[1].sim.engine.name == "mujoco"
        assert envs[0].observation_space == envs[1].observation_space
        assert envs[0].action_space == envs[1].action_space
        with pytest.raises(ParameterError, match="no engine named"):
            ScenarioEnv(EXAMPLES / "pendulum_servo.json", engine="bullet3")
    finally:
        for env in envs:
            env.close()
