"""Simulation's state, dynamics and reset (SimInterface's capabilities) against physics."""

from __future__ import annotations

import math
from pathlib import Path
from typing import Any

import numpy as np
import pytest

from urdfkit.core.errors import EngineError, InputError, ParameterError
from urdfkit.sim import Simulation

M, L, INERTIA = 2.0, 0.5, 0.01  # bob mass (kg), rod length (m), inertia about its centre
G = 9.81


def pendulum(tmp_path: Path) -> Path:
    """A pendulum: a massless rod of length L about y, a bob of mass M and inertia INERTIA."""
    path = tmp_path / "pendulum.urdf"
    path.write_text(f"""<robot name="pendulum">
  <link name="base"><inertial><mass value="1"/>
    <inertia ixx="0.1" ixy="0" ixz="0" iyy="0.1" iyz="0" izz="0.1"/></inertial></link>
  <link name="bob"><inertial><origin xyz="0 0 -{L}"/><mass value="{M}"/>
    <inertia ixx="{INERTIA}" ixy="0" ixz="0" iyy="{INERTIA}" iyz="0" izz="{INERTIA}"/>
  </inertial></link>
  <joint name="hinge" type="continuous"><parent link="base"/><child link="bob"/>
    <axis xyz="0 1 0"/></joint>
</robot>
""")
    return path


def scenario(urdf: Path, q0: float = 0.5, qd0: float = 0.0, damping: float | None = 0.0,
             **robot: Any) -> dict[str, Any]:
    physics: dict[str, Any] = {"gravity": [0, 0, -G]}
    if damping is not None:
        physics.update(linear_damping=damping, angular_damping=damping)
    return {"physics": physics, "duration": 1.0, "robots": [{
        "name": "p", "urdf": str(urdf), "base": "fixed",
        "initial_joints": {"hinge": {"position": q0, "velocity": qd0}}, **robot}]}


@pytest.mark.parametrize("q", [0.0, 0.5, -1.2, 2.5])
def test_mass_matrix_and_gravity_torque_of_a_pendulum(tmp_path: Path, q: float) -> None:
    with Simulation(scenario(pendulum(tmp_path), q0=q)) as sim:
        assert sim.dynamics_joints("p") == ["hinge"]
        assert sim.mass_matrix("p") == pytest.approx(np.array([[M * L * L + INERTIA]]), rel=1e-9)
        # Holding the bob still takes m g l sin q (q about +y swings it towards -x).
        assert sim.gravity_torques("p") == pytest.approx([M * G * L * math.sin(q)], abs=1e-9)


def test_forward_dynamics_matches_one_step_of_the_simulation(tmp_path: Path) -> None:
    tau = 3.0
    with Simulation(scenario(pendulum(tmp_path), q0=0.7, qd0=1.5)) as sim:
        qdd = sim.forward_dynamics("p", [tau])
        # M qdd + C qd + g = tau, by the formula too: C qd is 0 for a single joint.
        assert qdd[0] == pytest.approx((tau - M * G * L * math.sin(0.7)) / (M * L * L + INERTIA))
        assert sim.coriolis_and_gravity("p") == pytest.approx(sim.gravity_torques("p"))
        qd0 = sim.joint_velocities("p")["hinge"]
        sim.set_joint_targets("p", {"hinge": tau}, mode="torque")
        sim.step()
        measured = (sim.joint_velocities("p")["hinge"] - qd0) / sim.time_step
    # PyBullet integrates semi-implicitly: the velocity after one step is qd0 + qdd dt.
    assert measured == pytest.approx(qdd[0], rel=1e-6)


def test_jacobian_of_the_bob_is_the_derivative_of_its_position(tmp_path: Path) -> None:
    q = 0.9
    with Simulation(scenario(pendulum(tmp_path), q0=q)) as sim:
        jac = sim.jacobian("p", "bob", (0.0, 0.0, -L))  # the bob's centre, in the link frame
        assert not sim.jacobian("p", "bob")[:3].any()  # the link frame's origin: the hinge
        # The bob's centre is at (-L sin q, 0, -L cos q) from the hinge.
        assert jac[:3, 0] == pytest.approx([-L * math.cos(q), 0.0, L * math.sin(q)], abs=1e-9)
        assert jac[3:, 0] == pytest.approx([0.0, 1.0, 0.0], abs=1e-9)
        pos, orn = sim.link_pose("p", "bob")
        assert pos == pytest.approx([0.0, 0.0, 0.0], abs=1e-6)  # the link frame is the hinge
        # (PyBullet reports link states rounded to ~1e-7.)
        assert orn == pytest.approx([0.0, math.sin(q / 2), 0.0, math.cos(q / 2)], abs=1e-6)


def test_damping_is_pybullets_unless_set(tmp_path: Path) -> None:
    def amplitude_after(seconds: float, damping: float | None) -> float:
        with Simulation({**scenario(pendulum(tmp_path), q0=0.5, damping=damping),
                         "duration": seconds}) as sim:
            peak = 0.0
            for _ in range(round(seconds / sim.time_step)):
                sim.step()
                if sim.t > seconds - 2.0:  # the last two swings
                    peak = max(peak, abs(sim.joint_positions("p")["hinge"]))
            return peak

    # Without damping energy is kept; with PyBullet's 0.04 on every link a quarter of the
    # amplitude is gone in 10 s (the brief's 40% is for a longer pendulum).
    assert amplitude_after(10.0, 0.0) == pytest.approx(0.5, rel=0.01)
    assert amplitude_after(10.0, None) < 0.8 * 0.5


def test_reset_in_place_is_deterministic(tmp_path: Path) -> None:
    spec = scenario(pendulum(tmp_path), q0=0.3, qd0=0.2,
                    noise={"motor_angles": 0.01}, delay=2)

    def episode(sim: Simulation) -> list[dict[str, Any]]:
        rows = []
        for k in range(60):
            sim.set_joint_targets("p", {"hinge": math.sin(k / 10)}, mode="torque")
            sim.step()
            rows.append(sim.observe("p").to_dict())  # type: ignore[union-attr]
        return rows

    with Simulation(spec) as sim:
        first = episode(sim)
        sim.reset()
        assert sim.t == 0.0 and sim.joint_positions("p")["hinge"] == pytest.approx(0.3)
        again = episode(sim)
        sim.reset(seed=7)
        other_noise = episode(sim)
    assert again == first
    assert other_noise != first  # a new seed draws new noise...
    with Simulation({**spec, "seed": 7}) as fresh:
        assert episode(fresh) == other_noise  # ...the same as a new Simulation with that seed


def test_observations_are_copies(tmp_path: Path) -> None:
    with Simulation(scenario(pendulum(tmp_path), delay=1)) as sim:
        got = sim.observe("p")
        got.motor_angles["hinge"] = 99.0  # type: ignore[union-attr]
        sim.step()
        assert sim.observe("p").motor_angles["hinge"] != 99.0  # type: ignore[union-attr]
        ideal = sim.observe("p", ideal=True)
        ideal.motor_angles.clear()  # type: ignore[union-attr]
        assert sim.joint_positions("p") != {}


def test_setters_change_the_physics(tmp_path: Path) -> None:
    with Simulation(scenario(pendulum(tmp_path), q0=0.5)) as sim:
        assert sim.mass_matrix("p")[0, 0] == pytest.approx(M * L * L + INERTIA)
        # PyBullet's own dynamics model would keep the first mass; ours follows changes.
        sim.set_mass("p", "bob", 2 * M)
        assert sim.gravity_torques("p") == pytest.approx([2 * M * G * L * math.sin(0.5)])
        assert sim.mass_matrix("p")[0, 0] == pytest.approx(2 * M * L * L + 2 * INERTIA)  # scaled
        sim.set_inertia("p", "bob", [0.05, 0.05, 0.05])
        assert sim.mass_matrix("p")[0, 0] == pytest.approx(2 * M * L * L + 0.05)
        # And the simulation moves by them: one step from rest, qdd = -g(q) / M.
        qd0 = sim.joint_velocities("p")["hinge"]
        expected = -(2 * M * G * L * math.sin(0.5)) / (2 * M * L * L + 0.05)
        sim.step()
        assert (sim.joint_velocities("p")["hinge"] - qd0) / sim.time_step == \
            pytest.approx(expected, rel=1e-6)
        sim.set_time_step(0.002)
        assert sim.time_step == 0.002
        with pytest.raises(ParameterError, match="no link named 'bobb'"):
            sim.set_mass("p", "bobb", 1.0)
        with pytest.raises(ParameterError, match="time_step"):
            sim.set_time_step(0.0)


def test_floating_bases_get_a_mass_matrix_but_no_inverse_dynamics(tmp_path: Path) -> None:
    with Simulation(scenario(pendulum(tmp_path), base="floating")) as sim:
        assert sim.mass_matrix("p").shape == (7, 7)  # 6 base coordinates, then the hinge
        with pytest.raises(ParameterError, match="needs a fixed base"):
            sim.gravity_torques("p")
    assert sim.robot_names() == ["p"]


def test_robots_are_measured_only_when_an_observation_is_due(tmp_path: Path,
                                                             monkeypatch: pytest.MonkeyPatch
                                                             ) -> None:
    spec = {**scenario(pendulum(tmp_path), q0=1.0), "duration": 0.5}
    with Simulation({**spec, "record": {"every": 1}}) as sim:
        every_step = [r.to_dict() for r in sim.run().rows]
    from urdfkit.motion.sim_sensors import Sensors

    calls = []
    original = Sensors.measure

    def counted(self: Sensors, b: Any) -> Any:
        calls.append(self.world.step_count)
        return original(self, b)

    monkeypatch.setattr(Sensors, "measure", counted)
    with Simulation({**spec, "record": {"every": 10}}) as sim:
        sparse = [r.to_dict() for r in sim.run().rows]
    # 120 steps: the start and 12 rows, not 121 measurements.
    assert calls == list(range(0, 121, 10))
    # The same values as measuring every step, accelerations (over one step) included.
    assert sparse == every_step[::10]


@pytest.mark.slow
def test_sim_out_streams_with_flat_memory(tmp_path: Path) -> None:
    import json
    import subprocess
    import sys
    from concurrent.futures import ThreadPoolExecutor

    urdf = pendulum(tmp_path)

    def peak(steps: int) -> tuple[int, int]:
        doc = tmp_path / f"s{steps}.json"
        doc.write_text(json.dumps({**scenario(urdf), "duration": steps / 240.0}))
        out = tmp_path / f"rows{steps}.jsonl"
        code = ("import sys\n"
                "from urdfkit.cli import main\n"
                "sys.argv = ['urdfkit', 'sim', *sys.argv[1:]]\n"
                "try:\n    main()\nexcept SystemExit:\n    pass\n"
                "print('PEAK', next(int(line.split()[1]) for line in open('/proc/self/status')\n"
                "                   if line.startswith('VmHWM:')))\n")
        done = subprocess.run([sys.executable, "-c", code, str(doc), "-o", str(out), "--json"],
                              capture_output=True, text=True, timeout=300)
        with out.open() as f:
            rows = sum(1 for _ in f)
        assert json.loads(done.stdout.split("PEAK")[0])["rows"] == rows
        return int(done.stdout.split("PEAK")[-1]), rows

    with ThreadPoolExecutor(2) as pool:
        (small, small_rows), (big, big_rows) = pool.map(peak, (10_000, 100_000))
    assert (small_rows, big_rows) == (10_001, 100_001)
    assert big - small < 8 * 1024, (small, big)  # KiB: 90k more rows, under 8 MB more


def test_parquet_streams_in_row_groups(tmp_path: Path) -> None:
    pq = pytest.importorskip("pyarrow.parquet")
    from urdfkit.motion import simulation

    spec = {**scenario(pendulum(tmp_path)), "duration": 50 / 240}
    with Simulation(spec) as a, Simulation(spec) as b:
        simulation.PARQUET_ROWS, saved = 16, simulation.PARQUET_ROWS
        try:
            result, path = simulation.run_to_file(a, tmp_path / "rows.parquet")
        finally:
            simulation.PARQUET_ROWS = saved
        rows = b.run().to_dicts()
    table = pq.read_table(path)
    assert result.row_count == table.num_rows == len(rows) == 51
    assert pq.ParquetFile(path).num_row_groups == 4  # 16 + 16 + 16 + 3
    assert table.column("motor_angles.hinge").to_pylist() == \
        [r["motor_angles"]["hinge"] for r in rows]


def test_base_velocity_rack_and_link_dynamics(tmp_path: Path) -> None:
    urdf = pendulum(tmp_path)
    # A free body in zero gravity keeps its initial velocity: x = v t.
    free = {"physics": {"gravity": [0, 0, 0], "linear_damping": 0, "angular_damping": 0},
            "duration": 0.5, "robots": [{"name": "p", "urdf": str(urdf),
                                         "base_velocity": [1.0, 0.0, 0.0],
                                         "base_angular_velocity": [0.0, 0.0, 0.5]}]}
    with Simulation(free) as sim:
        sim.run()
        obs = sim.observe("p", ideal=True)
        assert obs.base_position[0] == pytest.approx(0.5, rel=1e-3)  # type: ignore[union-attr]
        assert obs.base_ang_vel[2] == pytest.approx(0.5, rel=1e-3)  # type: ignore[union-attr]
        sim.reset()
        assert sim.observe("p", ideal=True).base_lin_vel[0] == pytest.approx(1.0)  # type: ignore[union-attr]
    # On a rack the base hangs where it starts under gravity; its joints still swing.
    rack = {**scenario(urdf, q0=0.5), "robots": [{
        "name": "p", "urdf": str(urdf), "base": "on_rack", "position": [0, 0, 1.0],
        "initial_joints": {"hinge": 0.5},
        "link_dynamics": {"bob": {"lateral_friction": 0.3, "restitution": 0.2}}}],
        "record": {"motor_torques": True, "link_poses": ["bob"]}}
    with Simulation(rack) as sim:
        rows = sim.run().to_dicts()
        p, client = sim.session.p, sim.session.client
        info = p.getDynamicsInfo(sim.bodies["p"].body, 0, physicsClientId=client)
    assert rows[-1]["base_position"] == pytest.approx([0, 0, 1.0], abs=1e-3)
    assert rows[-1]["motor_angles"]["hinge"] < 0.4  # it swung
    assert info[1] == pytest.approx(0.3) and info[5] == pytest.approx(0.2)
    # The link pose row follows the bob's frame (at the hinge, turned by the swing).
    pose = rows[-1]["link_poses"]["bob"]
    q = rows[-1]["motor_angles"]["hinge"]
    assert pose["position"] == pytest.approx([0, 0, 1.0], abs=1e-3)
    assert pose["orientation"] == pytest.approx([0, math.sin(q / 2), 0, math.cos(q / 2)],
                                                abs=1e-4)
    assert rows[-1]["motor_torques"] == {"hinge": 0.0}  # no motor: it swings free


def test_recorded_motor_torque_holds_the_pendulum_against_gravity(tmp_path: Path) -> None:
    spec = {**scenario(pendulum(tmp_path), q0=0.5), "duration": 2.0,
            "record": {"every": 48, "motor_torques": True}}
    spec["robots"][0]["joints"] = [{"until": 2.0, "mode": "position",
                                    "targets": {"hinge": 0.5}, "max_force": 50}]
    with Simulation(spec) as sim:
        rows = sim.run().to_dicts()
    # Held still at 0.5 rad, the motor supplies the gravity torque (the sign: it pushes back).
    assert rows[-1]["motor_angles"]["hinge"] == pytest.approx(0.5, abs=1e-3)
    assert abs(rows[-1]["motor_torques"]["hinge"]) == pytest.approx(M * G * L * math.sin(0.5),
                                                                    rel=0.01)


def servo_run(tmp_path: Path, motor: dict[str, Any], seconds: float, q0: float = 0.0,
              segment: dict[str, Any] | None = None, gravity: float = G,
              **robot: Any) -> list[dict[str, Any]]:
    spec = scenario(pendulum(tmp_path), q0=q0, motor=motor, **robot)
    spec["physics"]["gravity"] = [0, 0, -gravity]
    spec["duration"] = seconds
    if segment is not None:
        spec["robots"][0]["joints"] = [{"until": seconds, **segment}]
    with Simulation(spec) as sim:
        return sim.run().to_dicts()


def test_servo_gains_per_joint_and_desired_velocity(tmp_path: Path) -> None:
    hold = {"mode": "position", "targets": {"hinge": 0.3}}
    held = servo_run(tmp_path, {"kp": {"hinge": 400.0}, "kd": {"hinge": 20.0}}, 2.0,
                     segment=hold)
    assert held[-1]["motor_angles"]["hinge"] == pytest.approx(0.3, abs=0.03)
    with pytest.raises(InputError, match=r"motor\.kp\.elbow"):
        servo_run(tmp_path, {"kp": {"elbow": 1.0}}, 0.1)
    # kp 0, kd 5: pure velocity tracking of the segment's desired velocity (no gravity).
    track = {"mode": "position", "targets": {"hinge": 0.0}, "velocities": {"hinge": 1.0}}
    rows = servo_run(tmp_path, {"kp": 0.0, "kd": 5.0}, 2.0, segment=track, gravity=0.0)
    assert rows[-1]["motor_velocities"]["hinge"] == pytest.approx(1.0, rel=0.01)


def test_rotor_inertia_slows_the_swing_as_the_formula_says(tmp_path: Path) -> None:
    def period(inertia: float) -> float:
        rows = servo_run(tmp_path, {"inertia": inertia}, 6.0, q0=0.1)
        ts = [r["t"] for r in rows]
        qs = [r["motor_angles"]["hinge"] for r in rows]
        ups = [ts[k] for k in range(1, len(qs)) if qs[k - 1] < 0 <= qs[k]]
        return (ups[-1] - ups[0]) / (len(ups) - 1)

    j = 0.5
    # Small swings: T = 2 pi sqrt((m l^2 + I + J) / (m g l)).
    for rotor in (0.0, j):
        expected = 2 * math.pi * math.sqrt((M * L * L + INERTIA + rotor) / (M * G * L))
        assert period(rotor) == pytest.approx(expected, rel=0.02)


def test_a_servo_on_the_measured_state_feels_the_delay(tmp_path: Path) -> None:
    motor = {"kp": 200.0, "kd": 2.0}
    step = {"mode": "position", "targets": {"hinge": 0.5}}
    true = servo_run(tmp_path, motor, 1.0, segment=step)
    same = servo_run(tmp_path, {**motor, "measured_state": True}, 1.0, segment=step)
    assert same == true  # no delay, no noise: what it reports is the truth

    def overshoot(rows: list[dict[str, Any]]) -> float:
        return max(r["motor_angles"]["hinge"] for r in rows) - 0.5

    late = servo_run(tmp_path, {**motor, "measured_state": True}, 1.0, segment=step, delay=12)
    assert overshoot(late) > 2 * overshoot(true)  # 50 ms late, the PD loop overshoots more


# KUKA KR210's link_2 inertia: PyBullet loads and simulates it, but its inverse-dynamics model
# (calculateMassMatrix, calculateInverseDynamics, calculateJacobian) refuses it.
ID_ASYMMETRIC = Path(__file__).parent / "fixtures" / "robots" / "id_asymmetric.urdf"


def scaled_servo(urdf: Path | str, **motor: Any) -> dict[str, Any]:
    """One fixed-base robot under a servo whose friction and spring go through M(q)."""
    return {"duration": 0.05, "robots": [{
        "name": "kr", "urdf": str(urdf), "base": "fixed",
        "motor": {"kp": 10.0, "kd": 1.0, "viscous_friction": 0.5,
                  "scale_by_mass_matrix": True, **motor}}]}


def test_sim_refuses_a_mass_matrix_servo_pybullet_cannot_compute(tmp_path: Path, pb) -> None:
    """It exited 3 with PyBullet's "invalid inertia tensor" on stdout, at the first step."""
    import json
    import subprocess
    import sys

    from urdfkit.engine.session import quiet_stdout

    p, c = pb
    with quiet_stdout():  # the premise: raw PyBullet refuses this robot's mass matrix
        body = p.loadURDF(str(ID_ASYMMETRIC), useFixedBase=True,
                          flags=p.URDF_USE_INERTIA_FROM_FILE, physicsClientId=c)
        with pytest.raises(SystemError):
            p.calculateMassMatrix(body, [0.0], physicsClientId=c)
    path = tmp_path / "kr210.json"
    path.write_text(json.dumps(scaled_servo(ID_ASYMMETRIC)))
    for flags in ([], ["--json"]):
        proc = subprocess.run([sys.executable, "-m", "urdfkit", "sim", str(path), *flags],
                              capture_output=True, text=True, timeout=120)
        assert proc.returncode == 2, proc.stderr
        assert proc.stdout == ""  # no "b3Error ... invalid inertia tensor" chatter
        lines = proc.stderr.splitlines()
        assert len(lines) == 1 and len(lines[0]) < 500, proc.stderr
        assert lines[0].startswith(f"urdfkit: error: {path}: robots[0].motor."
                                   "scale_by_mass_matrix: PyBullet cannot compute the mass "
                                   "matrix of robot 'kr': ")
        assert "inertia of link 'link_1' asymmetric" in lines[0]
        assert "Traceback" not in proc.stderr


def test_the_api_raises_typed_errors_where_pybullet_refuses_the_dynamics(
        capfd: pytest.CaptureFixture[str]) -> None:
    with pytest.raises(InputError, match=r"robots\[0\]\.motor\.scale_by_mass_matrix: PyBullet "
                                         r"cannot compute the mass matrix of robot 'kr'"):
        Simulation(scaled_servo(ID_ASYMMETRIC))
    # Without friction or a spring the servo never takes M: the scenario runs.
    with Simulation(scaled_servo(ID_ASYMMETRIC, viscous_friction=0.0)) as sim:
        sim.run()
    # Asked directly, each dynamics quantity is an EngineError (not pybullet.error) saying why.
    doc = {"robots": [{"name": "kr", "urdf": str(ID_ASYMMETRIC), "base": "fixed"}]}
    with Simulation(doc) as sim:
        for ask, what in ((sim.mass_matrix, "the mass matrix"),
                          (sim.gravity_torques, "the inverse dynamics"),
                          (lambda r: sim.jacobian(r, "link_1"), "Jacobians"),
                          (sim.mass_matrix, "the mass matrix")):  # again: the same answer
            with pytest.raises(EngineError, match=f"cannot compute {what} of robot 'kr': its "
                                                  "inverse-dynamics model finds the inertia "
                                                  "of link 'link_1' asymmetric by 7.1e-15"):
                ask("kr")
        sim.step()  # the robot itself still simulates
    assert capfd.readouterr().out == ""  # PyBullet's refusal never reached fd 1


def test_a_mass_matrix_servo_applies_pybullets_own_mass_matrix(pb) -> None:
    """KUKA iiwa, which PyBullet accepts: the servo's torque is M(q) e, M from raw PyBullet."""
    import os

    import pybullet_data

    b, k = 0.7, 3.0
    q0 = [0.3, -0.6, 0.9, 1.2, -0.4, 0.5, 0.2]
    qd0 = [0.5, -0.3, 0.8, 0.2, -0.6, 0.4, 1.0]
    names = [f"lbr_iiwa_joint_{i}" for i in range(1, 8)]
    doc = {"physics": {"gravity": [0, 0, 0]}, "robots": [{
        "name": "iiwa", "urdf": "kuka_iiwa/model.urdf", "base": "fixed",
        "initial_joints": {n: {"position": q, "velocity": v}
                           for n, q, v in zip(names, q0, qd0, strict=True)},
        "motor": {"viscous_friction": b, "stiffness": k, "scale_by_mass_matrix": True,
                  "max_torque": "unlimited"}}]}
    p, c = pb
    body = p.loadURDF(os.path.join(pybullet_data.getDataPath(), "kuka_iiwa/model.urdf"),
                      useFixedBase=True, flags=p.URDF_USE_INERTIA_FROM_FILE,
                      physicsClientId=c)
    raw = np.array(p.calculateMassMatrix(body, q0, physicsClientId=c))
    assert abs(raw[0, 1]) > 1e-3  # coupled joints: M is not diagonal
    e = -b * np.array(qd0) - k * np.array(q0)
    with Simulation(doc) as sim:
        assert sim.mass_matrix("iiwa") == pytest.approx(raw, rel=1e-12, abs=1e-15)
        sim.step()
        applied = sim.motor_torques("iiwa")
    assert [applied[n] for n in names] == pytest.approx(raw @ e, rel=1e-9, abs=1e-12)
    # ... which is not the unscaled law's e
    assert not np.allclose([applied[n] for n in names], e, rtol=0.1)
