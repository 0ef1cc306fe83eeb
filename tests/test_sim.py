"""The Simulation library against physics and raw PyBullet: cars, a servo pendulum, noise, delay."""

from __future__ import annotations

import importlib.util
import json
import math
import statistics
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import pytest

from urdfkit.core.errors import MissingDependencyError, OutputError, ParameterError
from urdfkit.sim import (
    Observation,
    SimResult,
    Simulation,
    flatten,
    rows_to_bytes,
    summarize,
    write_rows,
)

EXAMPLES = Path(__file__).parent.parent / "examples"
G = 9.81


def _load_pendulum_module() -> Any:
    spec = importlib.util.spec_from_file_location("pendulum_example", EXAMPLES / "pendulum.py")
    assert spec is not None and spec.loader is not None
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


pendulum_example = _load_pendulum_module()


@pytest.fixture(scope="module")
def two_cars() -> SimResult:
    with Simulation.from_file(EXAMPLES / "two_cars.json") as sim:
        return sim.run()


@pytest.fixture(scope="module")
def pendulum_urdf(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """The example pendulum, built here with the builder API."""
    path = tmp_path_factory.mktemp("pendulum") / "pendulum.urdf"
    pendulum_example.build_pendulum().write(path)
    return path


def pendulum(urdf: Path, **robot: Any) -> dict[str, Any]:
    """A scenario of the builder pendulum on a fixed base; ``robot`` keys override."""
    doc: dict[str, Any] = {"duration": 1.0, "record": {"every": 1},
                           "robots": [{"name": "p", "urdf": str(urdf), "base": "fixed"}]}
    doc["robots"][0].update(robot)
    return doc


def rows_of(result: SimResult, robot: str, ideal: bool = False) -> list[Observation]:
    return [r for r in (result.ideal if ideal else result.rows) if r.robot == robot]


# --------------------------------------------------------------------------- the two cars


def test_example_records_every_12_steps_for_each_robot(two_cars: SimResult) -> None:
    assert two_cars.steps == 720
    assert [r.step for r in rows_of(two_cars, "north")] == list(range(0, 721, 12))
    row = rows_of(two_cars, "north")[1].to_dict()
    assert row["t"] == pytest.approx(12 * 0.0041666667)
    assert set(row["motor_angles"]) == {
        "base_to_left_hinge", "left_hinge_to_left_front_wheel", "base_to_right_hinge",
        "right_hinge_to_right_front_wheel", "base_to_left_back_wheel", "base_to_right_back_wheel"}
    assert set(row) == {"t", "step", "robot", "motor_angles", "motor_velocities",
                        "motor_accelerations", "base_position", "base_orientation",
                        "base_lin_vel", "base_ang_vel", "base_lin_vel_body_frame",
                        "base_ang_vel_body_frame"}


def test_parked_car_stays_within_2_cm(two_cars: SimResult) -> None:
    start = (0.0, -2.0, 0.1)
    assert max(math.dist(r.base_position, start) for r in rows_of(two_cars, "parked")) < 0.02


def test_north_car_moves_along_y_in_the_world_and_x_in_its_body(two_cars: SimResult) -> None:
    cruising = [r for r in rows_of(two_cars, "north") if 0.5 <= r.t < 1.0]
    assert len(cruising) >= 8
    for r in cruising:
        # throttle 10 rad/s on 0.1 m wheels: 1 m/s forward, and forward is +y.
        assert r.base_lin_vel == pytest.approx([0, 1, 0], abs=0.03)
        assert r.base_lin_vel_body_frame == pytest.approx([1, 0, 0], abs=0.03)
    final = rows_of(two_cars, "north")[-1]
    yaw = math.atan2(2 * final.base_orientation[3] * final.base_orientation[2],
                     1 - 2 * final.base_orientation[2] ** 2)
    assert yaw > math.pi / 2 + 0.5  # steer 0.3 turned it left


def test_body_frame_velocities_match_pybullet_rotation() -> None:
    doc = {"duration": 0.5, "record": {"every": 30}, "ground": "simpleplane",
           "robots": [{"template": "simplecar", "position": [0, 0, 0.1],
                       "orientation_rpy": [0, 0, 0.7], "drive": [{"until": 1, "throttle": 8,
                                                                  "steer": 0.4}]}]}
    with Simulation(doc) as sim:
        sim.step(100)
        obs = sim.observe("robot0", ideal=True)
        p, client = sim.session.p, sim.session.client
        body = sim.bodies["robot0"].body
        _, orn = p.getBasePositionAndOrientation(body, physicsClientId=client)
        lin, ang = p.getBaseVelocity(body, physicsClientId=client)
        _, inverse = p.invertTransform((0, 0, 0), orn)
        for world, body_frame in ((lin, obs.base_lin_vel_body_frame),
                                  (ang, obs.base_ang_vel_body_frame)):
            expected, _ = p.multiplyTransforms((0, 0, 0), inverse, world, (0, 0, 0, 1))
            # PyBullet composes transforms in single precision.
            assert body_frame == pytest.approx(list(expected), abs=1e-6)
        assert obs.base_lin_vel == pytest.approx(list(lin))


def test_summary(two_cars: SimResult) -> None:
    by_name = {s.robot: s for s in summarize(two_cars)}
    assert by_name["parked"].distance < 0.02
    assert by_name["north"].top_speed == pytest.approx(1.0, abs=0.05)
    assert by_name["north"].rows == 61


# --------------------------------------------------------------------------- servo pendulum


def test_pd_servo_holds_the_builder_pendulum_at_its_target(pendulum_urdf: Path) -> None:
    kp, target = 300.0, 0.5
    doc = pendulum(pendulum_urdf, motor={"kp": kp, "kd": 8, "viscous_friction": 0.05},
                   joints=[{"until": 2.0, "targets": {"hinge": target}}])
    doc["duration"] = 2.0
    with Simulation(doc) as sim:
        result = sim.run()
        p, client, body = sim.session.p, sim.session.client, sim.bodies["p"].body
        q_raw = p.getJointState(body, 0, physicsClientId=client)[0]
    held = [r.motor_angles["hinge"] for r in rows_of(result, "p", ideal=True) if r.t >= 1.0]
    assert max(abs(q - target) for q in held) < 0.01
    # Steady state of a PD law against gravity: kp * error = m g l sin(q), 1 kg at 0.5 m.
    expected_sag = 1.0 * G * 0.5 * math.sin(target) / kp
    assert target - held[-1] == pytest.approx(expected_sag, rel=0.05)
    assert held[-1] == pytest.approx(q_raw)


def test_servo_torque_is_clipped_to_the_effort_limit(tmp_path: Path) -> None:
    weak = tmp_path / "weak.urdf"
    pendulum_example.build_pendulum(effort=1.0).write(weak)
    doc = pendulum(weak, motor={"kp": 300, "kd": 8},
                   joints=[{"until": 1.0, "targets": {"hinge": 0.5}}])
    doc["duration"] = 3.0
    with Simulation(doc) as sim:
        angles = [r.motor_angles["hinge"] for r in sim.run().ideal]
    # Saturated at 1 N m, the servo is a constant torque: the 1 kg bob at 0.5 m swings about
    # sin(q) = 1 / (m g l), ~0.205 rad, between 0 and twice that, and never reaches 0.5.
    balance = math.asin(1.0 / (G * 0.5))
    assert max(angles) == pytest.approx(2 * balance, abs=0.02)
    assert statistics.mean(angles) == pytest.approx(balance, abs=0.02)


def test_offsets_and_directions_map_measurements_and_commands(pendulum_urdf: Path) -> None:
    doc = pendulum(pendulum_urdf, motor={"kp": 300, "kd": 8},
                   motor_offsets={"hinge": 0.2}, motor_directions={"hinge": -1},
                   initial_joints={"hinge": 0.2},
                   joints=[{"until": 1.0, "targets": {"hinge": 0.3}}])
    with Simulation(doc) as sim:
        first = sim.observe("p", ideal=True)
        p, client, body = sim.session.p, sim.session.client, sim.bodies["p"].body
        # initial 0.2 measured = 0.2 * -1 + 0.2 = 0.0 physical.
        assert p.getJointState(body, 0, physicsClientId=client)[0] == pytest.approx(0.0)
        assert first.motor_angles["hinge"] == pytest.approx(0.2)
        sim.run()
        q = p.getJointState(body, 0, physicsClientId=client)[0]
        qd = p.getJointState(body, 0, physicsClientId=client)[1]
        obs = sim.observe("p", ideal=True)
    assert q == pytest.approx(0.3 * -1 + 0.2, abs=0.01)  # the command mapped back
    assert obs.motor_angles["hinge"] == pytest.approx((q - 0.2) * -1)
    assert obs.motor_velocities["hinge"] == pytest.approx(-qd)


@pytest.mark.parametrize(("mode", "target"), [("velocity", 1.0), ("torque", 0.0)])
def test_joint_modes_without_servo(pendulum_urdf: Path, mode: str, target: float) -> None:
    doc = pendulum(pendulum_urdf, joints=[{"until": 1.0, "mode": mode,
                                           "targets": {"hinge": target}}])
    doc["duration"] = 0.5
    with Simulation(doc) as sim:
        result = sim.run()
    last = rows_of(result, "p", ideal=True)[-1]
    if mode == "velocity":
        assert last.motor_velocities["hinge"] == pytest.approx(1.0, abs=1e-3)
    else:  # no torque, hanging straight down: nothing moves
        assert last.motor_angles["hinge"] == pytest.approx(0.0, abs=1e-6)


def test_position_mode_with_pybullet_motor_and_initial_velocity(pendulum_urdf: Path) -> None:
    doc = pendulum(pendulum_urdf, initial_joints={"hinge": {"position": 0.1, "velocity": 2.0}},
                   joints=[{"until": 1.0, "mode": "position", "targets": {"hinge": -0.4}}])
    with Simulation(doc) as sim:
        first = sim.observe("p", ideal=True)
        assert first.motor_angles["hinge"] == pytest.approx(0.1)
        assert first.motor_velocities["hinge"] == pytest.approx(2.0)
        sim.run()
        assert sim.observe("p", ideal=True).motor_angles["hinge"] == pytest.approx(-0.4,
                                                                                   abs=0.01)


def test_accelerations_are_the_finite_difference_of_velocities(pendulum_urdf: Path) -> None:
    doc = pendulum(pendulum_urdf, initial_joints={"hinge": 1.0})
    doc["duration"] = 0.2
    with Simulation(doc) as sim:
        rows = rows_of(sim.run(), "p", ideal=True)
    assert rows[0].motor_accelerations["hinge"] == 0.0
    for a, b in zip(rows, rows[1:], strict=False):
        diff = (b.motor_velocities["hinge"] - a.motor_velocities["hinge"]) / (1 / 240)
        assert b.motor_accelerations["hinge"] == pytest.approx(diff)
    # A free pendulum released at 1 rad starts with about -g sin(1) / l.
    assert rows[1].motor_accelerations["hinge"] == pytest.approx(-G * math.sin(1.0) / 0.5,
                                                                 rel=0.05)


def test_joint_reaction_force_carries_the_bob(pendulum_urdf: Path) -> None:
    doc = pendulum(pendulum_urdf)
    doc["record"]["joint_forces"] = ["hinge"]
    doc["duration"] = 0.1
    with Simulation(doc) as sim:
        rows = rows_of(sim.run(), "p", ideal=True)
    force = rows[-1].joint_forces["hinge"]
    assert math.hypot(*force[:3]) == pytest.approx(1.0 * G, rel=0.03)
    assert flatten(rows[-1].to_dict())["joint_forces.hinge.fz"] == force[2]


def test_contact_forces_of_the_wheels_carry_the_car() -> None:
    wheels = ["left_front_wheel", "right_front_wheel", "left_back_wheel", "right_back_wheel"]
    doc = {"duration": 0.5, "ground": "simpleplane", "record": {"every": 60,
                                                                "contact_links": wheels},
           "robots": [{"template": "simplecar", "position": [0, 0, 0.1]}]}
    with Simulation(doc) as sim:
        last = sim.run().ideal[-1]
    assert last.contacts is not None
    total = sum(last.contacts[w]["normal_force"] for w in wheels)
    mass = 6.0 + 4 * 0.3 + 2 * 0.01
    assert total == pytest.approx(mass * G, rel=0.03)
    assert all(last.contacts[w]["count"] >= 1 for w in wheels)


# --------------------------------------------------------------------------- noise and delay


@pytest.mark.parametrize("delay", [1, 5])
def test_delay_shifts_the_series_by_exactly_n_steps(pendulum_urdf: Path, delay: int) -> None:
    doc = pendulum(pendulum_urdf, initial_joints={"hinge": 0.8}, delay=delay)
    doc["duration"] = 0.25
    with Simulation(doc) as sim:
        result = sim.run()
    reported, ideal = rows_of(result, "p"), rows_of(result, "p", ideal=True)
    assert len(reported) == len(ideal) == 61
    for k, row in enumerate(reported):
        source = ideal[max(k - delay, 0)]
        assert row.step == k and row.t == ideal[k].t
        assert row.motor_angles == source.motor_angles
        assert row.motor_velocities == source.motor_velocities
        assert row.base_position == source.base_position
    assert reported[delay + 3].motor_angles != ideal[delay + 3].motor_angles  # it swings


def test_noise_has_the_configured_std_for_a_fixed_seed(pendulum_urdf: Path) -> None:
    doc = pendulum(pendulum_urdf, initial_joints={"hinge": 0.5},
                   noise={"motor_angles": 0.05, "base_lin_vel": 0.2})
    doc["duration"] = 4.0
    doc["seed"] = 11
    with Simulation(doc) as sim:
        result = sim.run()
    errors = [r.motor_angles["hinge"] - i.motor_angles["hinge"]
              for r, i in zip(result.rows, result.ideal, strict=True)]
    assert len(errors) == 961
    assert statistics.stdev(errors) == pytest.approx(0.05, rel=0.08)
    assert abs(statistics.mean(errors)) < 0.01
    vel = [r.base_lin_vel[0] - i.base_lin_vel[0] for r, i in zip(result.rows, result.ideal,
                                                                  strict=True)]
    assert statistics.stdev(vel) == pytest.approx(0.2, rel=0.08)
    # Fields without noise are untouched.
    assert all(r.motor_velocities == i.motor_velocities
               for r, i in zip(result.rows, result.ideal, strict=True))
    # The same seed gives the same rows; another seed does not. Physics never sees the noise.
    doc["duration"] = 0.5
    with Simulation(doc) as a, Simulation(doc) as b, Simulation({**doc, "seed": 12}) as c:
        ra, rb, rc = a.run(), b.run(), c.run()
    assert [r.to_dict() for r in ra.rows] == [r.to_dict() for r in rb.rows]
    assert [r.to_dict() for r in ra.rows] != [r.to_dict() for r in rc.rows]
    assert [r.to_dict() for r in ra.ideal] == [r.to_dict() for r in rc.ideal]


def test_observe_repeats_at_one_step_and_all_robots_by_default(pendulum_urdf: Path) -> None:
    doc = pendulum(pendulum_urdf, noise={"motor_angles": 0.1})
    with Simulation(doc) as sim:
        sim.step(3)
        a, b = sim.observe("p"), sim.observe("p")
        assert a == b and a is not b  # the same values, each caller its own copy
        everything = sim.observe()
        assert isinstance(everything, dict) and everything["p"] == a
        sim.step()
        assert sim.observe("p") != a
        assert sim.t == pytest.approx(4 / 240)


# --------------------------------------------------------------------------- library use


def test_two_simulations_in_one_process_do_not_interfere(pendulum_urdf: Path) -> None:
    swing = pendulum(pendulum_urdf, initial_joints={"hinge": 1.2})
    swing["physics"] = {"gravity": [0, 0, -3.0], "time_step": 0.002}

    def final(sim: Simulation) -> dict[str, Any]:
        return {k: v.to_dict() for k, v in sim.observe(ideal=True).items()}  # type: ignore[union-attr]

    with Simulation.from_file(EXAMPLES / "two_cars.json") as cars:
        cars.step(360)
        cars_alone = final(cars)
    with Simulation(swing) as other:
        other.step(210)
        swing_alone = final(other)
    with Simulation.from_file(EXAMPLES / "two_cars.json") as cars, Simulation(swing) as other:
        assert cars.session.client != other.session.client
        for _ in range(30):  # interleave the two worlds
            cars.step(12)
            other.step(7)
        assert final(cars) == cars_alone
        assert final(other) == swing_alone


def test_commands_can_be_overridden_from_python(pendulum_urdf: Path) -> None:
    doc = {"duration": 1.0, "ground": "simpleplane",
           "robots": [{"name": "car", "template": "simplecar", "position": [0, 0, 0.1],
                       "drive": [{"until": 1.0, "throttle": 0}]},
                      {"name": "p", "urdf": str(pendulum_urdf), "base": "fixed",
                       "position": [5, 5, 0], "motor": {"kp": 200, "kd": 5}}]}
    with Simulation(doc) as sim:
        sim.set_drive("car", throttle=-10.0)
        sim.set_joint_targets("p", {"hinge": -0.3})
        sim.step(240)
        car = sim.observe("car", ideal=True)
        assert car.base_lin_vel_body_frame[0] == pytest.approx(-1.0, abs=0.05)
        assert sim.observe("p", ideal=True).motor_angles["hinge"] == pytest.approx(-0.3,
                                                                                   abs=0.02)
        sim.clear_command("car")
        sim.step(240)
        assert math.hypot(*sim.observe("car", ideal=True).base_lin_vel) < 0.05
        with pytest.raises(ParameterError, match="has no drive controller"):
            sim.set_drive("p", 1.0)
        with pytest.raises(ParameterError, match="no robot named 'x'"):
            sim.observe("x")
        with pytest.raises(ParameterError, match="no active joint named 'wheel'"):
            sim.set_joint_targets("p", {"wheel": 1})


def test_close_is_idempotent_and_disconnects() -> None:
    sim = Simulation({"robots": [{"template": "simplecar"}]})
    p, client = sim.session.p, sim.session.client
    sim.close()
    sim.close()
    assert not p.isConnected(physicsClientId=client)


def test_pendulum_example_urdf_is_what_the_builder_script_writes() -> None:
    assert (EXAMPLES / "pendulum.urdf").read_bytes() == \
        pendulum_example.build_pendulum().to_bytes()


def test_pendulum_servo_example_runs() -> None:
    with Simulation.from_file(EXAMPLES / "pendulum_servo.json") as sim:
        result = sim.run()
    ideal = rows_of(result, "pendulum", ideal=True)
    at = {round(r.t, 3): r.motor_angles["hinge"] for r in ideal}
    assert at[1.4] == pytest.approx(0.5, abs=0.01)
    assert at[3.0] == pytest.approx(-0.3, abs=0.01)
    assert ideal[-1].joint_forces is not None


# --------------------------------------------------------------------------- writers


@pytest.fixture
def rows(two_cars: SimResult) -> list[dict[str, Any]]:
    return two_cars.to_dicts()[:6]


def test_jsonl_round_trip(tmp_path: Path, rows: list[dict[str, Any]]) -> None:
    path = write_rows(tmp_path / "o.jsonl", rows, force=False)
    assert [json.loads(line) for line in path.read_text().splitlines()] == rows
    with pytest.raises(OutputError, match="exists; pass `force=True`"):
        write_rows(path, rows, force=False)
    write_rows(path, rows[:1], force=True)
    assert len(path.read_text().splitlines()) == 1


def test_csv_is_flattened(tmp_path: Path, rows: list[dict[str, Any]]) -> None:
    import csv

    path = write_rows(tmp_path / "o.csv", rows, force=False)
    with path.open() as f:
        table = list(csv.DictReader(f))
    assert len(table) == len(rows)
    assert float(table[1]["base_position.y"]) == pytest.approx(rows[1]["base_position"][1])
    assert float(table[1]["base_orientation.w"]) == pytest.approx(rows[1]["base_orientation"][3])
    assert float(table[1]["motor_velocities.base_to_left_back_wheel"]) == pytest.approx(
        rows[1]["motor_velocities"]["base_to_left_back_wheel"])


def test_parquet_needs_pyarrow_or_says_how_to_get_it(tmp_path: Path,
                                                     rows: list[dict[str, Any]]) -> None:
    try:
        import pyarrow.parquet as pq
    except ImportError:
        with pytest.raises(MissingDependencyError, match=r"pip install 'urdfkit\[parquet\]'"):
            write_rows(tmp_path / "o.parquet", rows, force=False)
        assert not (tmp_path / "o.parquet").exists()
        return
    path = write_rows(tmp_path / "o.parquet", rows, force=False)
    table = pq.read_table(path)
    assert table.num_rows == len(rows)
    assert table.column("base_position.y").to_pylist()[1] == rows[1]["base_position"][1]


def test_unknown_output_format(tmp_path: Path, rows: list[dict[str, Any]]) -> None:
    with pytest.raises(OutputError, match="the rows file must end in .jsonl or .csv or .parquet"):
        write_rows(tmp_path / "o.xlsx", rows, force=False)
    with pytest.raises(OutputError):
        rows_to_bytes(rows, ".txt")


@pytest.fixture(autouse=True)
def _no_leaked_clients() -> Iterator[None]:
    """Every Simulation disconnects its client: none outlives its test."""
    from urdfkit.engine.session import import_pybullet

    p = import_pybullet()

    def connected() -> set[int]:
        return {c for c in range(64) if p.isConnected(physicsClientId=c)}

    before = connected()
    yield
    assert connected() <= before


def test_pybullet_data_models_load_by_name() -> None:
    doc = {"ground": "plane.urdf", "duration": 0.1, "record": {"every": 12},
           "robots": [{"urdf": "r2d2.urdf", "position": [0, 0, 0.5], "inertia_from_file": False}]}
    with Simulation(doc) as sim:
        result = sim.run()
    assert len(result.rows) == 3
    assert "head_swivel" in result.rows[-1].motor_angles


def test_bodies_too_large_for_state_queries_are_refused(tmp_path: Path) -> None:
    from urdfkit.builder import Box, Collision, Inertial, Joint, Limit, Link, Origin, Robot
    from urdfkit.core.errors import InputError

    chain = Robot("chain")
    chain.add_link(Link("l0", inertial=Inertial(1.0), collisions=[Collision(Box((0.1,) * 3))]))
    for i in range(1, 130):
        chain.add_link(Link(f"l{i}", inertial=Inertial(0.1),
                            collisions=[Collision(Box((0.05,) * 3))]))
        chain.add_joint(Joint(f"j{i}", "revolute", f"l{i - 1}", f"l{i}", Origin((0, 0, 0.06)),
                              axis=(0, 1, 0), limit=Limit(1, 1, -1, 1)))
    chain.write(tmp_path / "chain.urdf")
    doc = {"robots": [{"name": "snake", "urdf": str(tmp_path / "chain.urdf"), "base": "fixed"}]}
    with pytest.raises(InputError, match=r"robots\[0\]: snake: 130 links: PyBullet cannot "
                                         "report the state"):
        Simulation(doc)
