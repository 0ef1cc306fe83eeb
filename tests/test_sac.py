"""simulation_and_control configs run as they are (urdfkit/motion/sac.py).

The two configs in tests/fixtures/sac/configs are written in simulation_and_control's format
(a pendulum; a Unitree-like quadruped with foot sensors, noise and delay). The rows urdfkit
gives are compared with a hand-written raw-PyBullet loop that does what SimInterface does
(loads, reset, the servo reading the delayed state, friction scaled by the mass matrix), and
with physics.
"""

from __future__ import annotations

import collections
import json
import math
import os
import shutil
import subprocess
import sys
from pathlib import Path

import numpy as np
import pybullet as p
import pybullet_data
import pytest

from urdfkit.core.errors import InputError
from urdfkit.motion import sac
from urdfkit.motion.scenario import load_scenario
from urdfkit.sim import Simulation

if sys.version_info >= (3, 11):
    import tomllib
else:  # pragma: no cover - Python 3.10
    import tomli as tomllib

FIXTURES = Path(__file__).parent / "fixtures" / "sac"
PENDULUM = FIXTURES / "configs" / "pendulum.json"
QUADRUPED = FIXTURES / "configs" / "quadruped.json"
STANCE = [0.0, 0.8, -1.5] * 4


def _config(tmp_path: Path, source: Path, **changes: object) -> Path:
    """A copy of a fixture config with robot_pybullet keys changed, beside the models."""
    conf = json.loads(source.read_text())
    for key, value in changes.items():
        section, _, name = key.partition("__")
        conf[section][name] = value
    (tmp_path / "configs").mkdir(parents=True, exist_ok=True)
    models = tmp_path / "models"
    if not models.exists():
        models.mkdir()
        for f in (FIXTURES / "models").iterdir():
            shutil.copy(f.resolve(), models / f.name)
    out = tmp_path / "configs" / source.name
    out.write_text(json.dumps(conf))
    return out


# --------------------------------------------------------------------------- the reference


class Reference:
    """SimInterface's loop for one robot, in raw PyBullet (written from its semantics).

    Loads with URDF_USE_INERTIA_FROM_FILE at the origin, on plane.urdf, 30 solver iterations
    and no cone friction; zeroes the damping of the bodies whose ids are joint indices (its
    quirk); resets joints to init_motor_angles and the base (its centre of mass) to the
    configured pose; each step applies the servo to the reported (delayed) state with its
    friction and elastic terms multiplied by the joint-space mass matrix, then steps.
    """

    def __init__(self, config: Path):
        conf = json.loads(config.read_text())
        rp, self.sim = conf["robot_pybullet"], conf["sim"]
        self.rp = rp
        self.c = p.connect(p.DIRECT)
        c = self.c
        self.dt = self.sim["time_step"]
        p.setPhysicsEngineParameter(numSolverIterations=30, physicsClientId=c)
        # Overlapping pairs left unsorted, as SimInterface leaves them (so does urdfkit for a
        # simulation_and_control config; sorted, a quadruped's contacts part after 30 steps).
        p.setTimeStep(self.dt, physicsClientId=c)
        p.setGravity(0, 0, -9.81, physicsClientId=c)
        p.setPhysicsEngineParameter(enableConeFriction=0, physicsClientId=c)
        p.loadURDF(str(Path(pybullet_data.getDataPath()) / "plane.urdf"), physicsClientId=c)
        urdf = config.parent.parent / "models" / rp["urdf_path"][0]
        self.fixed = rp["base_type"][0] == "fixed"
        self.body = p.loadURDF(str(urdf), [0, 0, 0], [0, 0, 0, 1], useFixedBase=self.fixed,
                               flags=p.URDF_USE_INERTIA_FROM_FILE, physicsClientId=c)
        n = p.getNumJoints(self.body, physicsClientId=c)
        infos = [p.getJointInfo(self.body, j, physicsClientId=c) for j in range(n)]
        self.active = [i[0] for i in infos if i[2] != p.JOINT_FIXED]
        for j in range(n):  # SimInterface's _RemoveDefaultJointDamping, body id = joint index
            p.changeDynamics(j, -1, linearDamping=0.0, angularDamping=0.0, physicsClientId=c)
        links = {i[12].decode(): i[0] for i in infos}
        for link in self.sim.get("feet_contact_names", [[]])[0]:
            p.changeDynamics(self.body, links[link], lateralFriction=rp["foot_friction"][0],
                             restitution=rp["foot_restitution"][0], physicsClientId=c)
        for i in infos:
            if i[1].decode() in (rp["enable_feet_joint_force_sensors"][0] or []):
                p.enableJointForceTorqueSensor(self.body, i[0], True, physicsClientId=c)
        vel = rp["init_motor_vel"][0] or [0.0] * len(self.active)
        for k, j in enumerate(self.active):
            p.setJointMotorControl2(self.body, j, p.VELOCITY_CONTROL, targetVelocity=0,
                                    force=0, physicsClientId=c)
            p.resetJointState(self.body, j, rp["init_motor_angles"][0][k], vel[k],
                              physicsClientId=c)
        p.resetBasePositionAndOrientation(self.body, rp["init_link_base_position"][0],
                                          rp["init_link_base_orientation"][0],
                                          physicsClientId=c)
        if not self.fixed and rp["init_link_base_vel"] and rp["init_link_base_ang_vel"]:
            p.resetBaseVelocity(self.body, rp["init_link_base_vel"],
                                rp["init_link_base_ang_vel"], physicsClientId=c)
        delay = rp["delay_measure_steps"][0] if rp["delay_measure_flag"][0] else 0
        self.buffer: collections.deque[tuple[np.ndarray, np.ndarray]] = \
            collections.deque(maxlen=delay + 1)
        self.buffer.append(self.state())

    def state(self) -> tuple[np.ndarray, np.ndarray]:
        st = p.getJointStates(self.body, self.active, physicsClientId=self.c)
        return np.array([s[0] for s in st]), np.array([s[1] for s in st])

    def step(self, command: list[float] | None) -> None:
        rp, n = self.rp, len(self.active)
        q, qd = self.buffer[0]  # the delayed reading (no noise in these runs)
        true_q, _ = self.buffer[-1]
        m = np.array(p.calculateMassMatrix(self.body, true_q.tolist(), physicsClientId=self.c))
        m = m[-n:, -n:]  # the joint block
        extra = np.zeros(n)
        if rp["motor_damping"][0]:
            extra -= np.asarray(rp["motor_damping_coeff"][0]) * qd
        if rp["motor_elastic_torque"][0]:
            extra -= np.asarray(rp["motor_elastic_coeff"][0]) * q
        tau = m @ extra
        if command is not None:
            kp = np.asarray(rp["servo_pos_gains"][0]) * np.ones(n)
            kd = np.asarray(rp["servo_vel_gains"][0]) * np.ones(n)
            tau += -kp * (q - np.asarray(command)) - kd * qd
        p.setJointMotorControlArray(self.body, self.active, p.TORQUE_CONTROL,
                                    forces=tau.tolist(), physicsClientId=self.c)
        p.stepSimulation(physicsClientId=self.c)
        self.buffer.append(self.state())

    def base(self) -> list[float]:
        return list(p.getBasePositionAndOrientation(self.body, physicsClientId=self.c)[0])

    def close(self) -> None:
        p.disconnect(self.c)


def _compare(config: Path, steps: int, command: list[float] | None) -> tuple[float, float]:
    """Largest joint-angle and base-position gaps between urdfkit and the reference."""
    ref = Reference(config)
    worst_q = worst_base = 0.0
    try:
        with Simulation.from_file(config) as s:
            robot = s.robot_names()[0]
            names = list(s.joint_positions(robot))
            if command is not None:
                s.set_joint_targets(robot, dict(zip(names, command, strict=True)))
            for _ in range(steps):
                s.step()
                ref.step(command)
                ours = s.observe(robot, ideal=True)
                theirs_q, _ = ref.buffer[-1]
                worst_q = max(worst_q, max(abs(ours.motor_angles[k] - theirs_q[i])
                                           for i, k in enumerate(names)))
                worst_base = max(worst_base, max(abs(a - b) for a, b in
                                                 zip(ours.base_position, ref.base(),
                                                     strict=True)))
    finally:
        ref.close()
    return worst_q, worst_base


def test_pendulum_rows_are_simulation_and_controls(tmp_path):
    # Zero command: the motor's friction (scaled by the mass matrix) slows the swing.
    config = _config(tmp_path, PENDULUM)
    worst_q, worst_base = _compare(config, 1500, None)
    assert worst_q < 1e-9 and worst_base < 1e-9


def test_pendulum_with_a_spring_and_a_servo_matches(tmp_path):
    config = _config(tmp_path, PENDULUM, robot_pybullet__motor_elastic_torque=[1],
                     robot_pybullet__motor_elastic_coeff=[4.0],
                     robot_pybullet__servo_pos_gains=[30.0], robot_pybullet__servo_vel_gains=[1.0])
    worst_q, _ = _compare(config, 1000, [0.2])
    assert worst_q < 1e-9


def test_quadruped_holding_its_stance_matches(tmp_path):
    # Floating base, 12 motors, the servo reading a 3-step-old state; noise off to compare.
    config = _config(tmp_path, QUADRUPED, robot_pybullet__noise_flag=[0])
    worst_q, worst_base = _compare(config, 300, STANCE)
    # 2.6e-11 measured against this reference (its mass matrix product rounds differently);
    # against the real SimInterface bench/sac_side_by_side.py finds it bit for bit.
    assert worst_q < 1e-9 and worst_base < 1e-9


# --------------------------------------------------------------------------- physics


def _angles(config: Path, seconds: float, mass: float | None = None) -> np.ndarray:
    with Simulation.from_file(config) as s:
        if mass is not None:
            s.set_mass("pendulum", "arm", mass)
        out = [s.joint_positions("pendulum")["hinge"]]
        for _ in range(round(seconds / s.time_step)):
            s.step()
            out.append(s.joint_positions("pendulum")["hinge"])
    return np.array(out)


def _decay_rate(angles: np.ndarray, dt: float) -> float:
    """sigma of A exp(-sigma t), from the swing's successive peaks."""
    peaks = [i for i in range(1, len(angles) - 1)
             if angles[i] > angles[i - 1] and angles[i] >= angles[i + 1] and angles[i] > 0]
    first, last = peaks[0], peaks[-1]
    return math.log(angles[first] / angles[last]) / ((last - first) * dt)


def test_mass_matrix_friction_damps_at_half_its_coefficient_whatever_the_mass(tmp_path):
    # tau = -M c qd: M qdd = -m g l sin q - M c qd, so the swing decays as exp(-c t / 2)
    # (on top of PyBullet's 0.04 link damping, which this 1-joint robot keeps, as in
    # SimInterface) and a heavier bob decays at the same rate.
    still = _config(tmp_path / "a", PENDULUM, robot_pybullet__motor_damping=[0])
    damped = _config(tmp_path / "b", PENDULUM)  # c = 0.8
    base = _decay_rate(_angles(still, 6.0), 0.001)
    rate = _decay_rate(_angles(damped, 6.0), 0.001)
    heavy = _decay_rate(_angles(damped, 6.0, mass=4.0), 0.001)
    assert rate - base == pytest.approx(0.4, rel=0.03)
    assert heavy == pytest.approx(rate, rel=0.03)


def test_mass_matrix_spring_adds_its_coefficient_to_omega_squared(tmp_path):
    def omega(angles: np.ndarray) -> float:
        ups = [i for i in range(1, len(angles)) if angles[i - 1] < 0 <= angles[i]]
        return 2 * math.pi / ((ups[-1] - ups[0]) / (len(ups) - 1) * 0.001)

    plain = _config(tmp_path / "a", PENDULUM, robot_pybullet__motor_damping=[0])
    spring = _config(tmp_path / "b", PENDULUM, robot_pybullet__motor_damping=[0],
                     robot_pybullet__motor_elastic_torque=[1],
                     robot_pybullet__motor_elastic_coeff=[6.0])
    w0 = omega(_angles(plain, 6.0) - 0.0)
    w1 = omega(_angles(spring, 6.0))
    assert w1 ** 2 - w0 ** 2 == pytest.approx(6.0, rel=0.05)


def test_quadruped_feet_carry_its_weight_in_both_frames(tmp_path):
    config = _config(tmp_path, QUADRUPED, robot_pybullet__noise_flag=[0])
    with Simulation.from_file(config) as s:
        robot = s.robot_names()[0]
        names = list(s.joint_positions(robot))
        s.set_joint_targets(robot, dict(zip(names, STANCE, strict=True)))
        s.step(1000)  # 2 s: settled
        obs = s.observe(robot, ideal=True)
        body = s.bodies[robot].body
        client = s.session.client
        mass = sum(p.getDynamicsInfo(body, k, physicsClientId=client)[0]
                   for k in range(-1, p.getNumJoints(body, physicsClientId=client)))
        feet = obs.feet
        assert feet is not None and set(feet) == {"FL", "FR", "RL", "RR"}
        assert all(f["contact"] == 1 for f in feet.values())
        total = sum(f["normal"] for f in feet.values())
        assert total == pytest.approx(mass * 9.81, rel=0.01)
        assert sum(f["world"][2] for f in feet.values()) == pytest.approx(total, rel=1e-6)
        for label, f in feet.items():
            _, orn = s.link_pose(robot, f"{label}_foot")
            rot = np.array(p.getMatrixFromQuaternion(orn)).reshape(3, 3)
            assert np.allclose(rot @ np.array(f["local"]), f["world"], atol=1e-5)
        # The foot joints' force sensors hold each foot: their force is the contact force
        # less the foot's weight (a 0.06 kg foot).
        assert obs.joint_forces is not None
        for label, f in feet.items():
            sensed = np.linalg.norm(obs.joint_forces[f"{label}_foot_fixed"][:3])
            assert sensed == pytest.approx(f["normal"] - 0.06 * 9.81, abs=0.02 * f["normal"])


def test_quadruped_reports_delayed_and_noisy_state(tmp_path):
    # delay 3 steps; joint_cov 0.002 is a standard deviation (as SimInterface draws it).
    with Simulation.from_file(QUADRUPED) as s:
        robot = s.robot_names()[0]
        names = list(s.joint_positions(robot))
        s.set_joint_targets(robot, dict(zip(names, STANCE, strict=True)))
        truth: list[dict[str, float]] = []
        errors: list[float] = []
        for _ in range(600):
            s.step()
            truth.append(s.observe(robot, ideal=True).motor_angles)
            seen = s.observe(robot)
            if len(truth) > 3:
                errors += [seen.motor_angles[k] - truth[-4][k] for k in names]
                q = seen.base_orientation
                assert math.fsum(x * x for x in q) == pytest.approx(1.0, abs=1e-12)
        assert np.std(errors) == pytest.approx(0.002, rel=0.05)
        assert abs(np.mean(errors)) < 0.0002


# --------------------------------------------------------------------------- mapping


def test_every_key_maps_and_the_notes_say_what_follows_simulation_and_control():
    imported = sac.convert(json.loads(QUADRUPED.read_text()), source=QUADRUPED)
    robot = imported.scenario["robots"][0]
    assert robot["base"] == "floating" and robot["pose_frame"] == "com"
    assert robot["position"] == [0.0, 0.0, 0.33] and robot["delay"] == 3
    assert robot["motor"]["scale_by_mass_matrix"] and robot["motor"]["measured_state"]
    assert robot["motor"]["max_torque"] == "unlimited"
    assert robot["motor"]["viscous_friction"] == 0.5 and robot["motor"]["kd"] == 2.0
    assert robot["noise"]["base_orientation"] == [0.001, 0.001, 0.002]
    assert robot["noise"]["base_lin_vel_body_frame"] == 0.01
    assert robot["link_dynamics"]["FL_foot"] == {"lateral_friction": 0.9, "restitution": 0.1}
    assert robot["linear_damping"] == 0.0  # 16 joints: SimInterface's quirk reaches body 1
    record = imported.scenario["record"]
    assert record["feet"]["RR"] == "RR_foot" and record["link_poses"] == ["trunk"]
    assert "FL_foot_fixed" in record["joint_forces"]
    pendulum = sac.convert(json.loads(PENDULUM.read_text()), source=PENDULUM)
    assert "linear_damping" not in pendulum.scenario["robots"][0]
    assert any("0.04" in n for n in pendulum.notes)


@pytest.mark.parametrize(("changes", "message"), [
    ({"env_pybullet__env_script_name": "scene.py"}, "env_pybullet.env_script_name"),
    ({"robot_pybullet__robot_description_model": ["go2"]}, "robot_description_model[0]"),
    ({"robot_pybullet__base_type": ["floating", "fixed"]}, "one entry per robot (1)"),
    ({"robot_pybullet__base_type": ["wheeled"]}, "base_type[0]: expected"),
    ({"robot_pybullet__init_motor_angles": [[0.1, 0.2]]}, "init_motor_angles[0]: expected 1"),
    ({"robot_pybullet__servo_pos_gains": [[1.0, 2.0]]}, "servo_pos_gains[0]: expected 1"),
    ({"robot_pybullet__motor_direction": [[0.5]]}, "1 or -1"),
    ({"robot_pybullet__urdf_path": ["nowhere.urdf"]}, "urdf_path[0]: no such file"),
    ({"robot_pybullet__robot_noise": [{"joint_std": 0.1}]}, "robot_noise[0].joint_std"),
    ({"robot_pybullet__delay_measure_flag": [1],
      "robot_pybullet__delay_measure_steps": [-2]}, "delay_measure_steps[0]"),
])
def test_keys_that_cannot_be_mapped_are_refused_by_name(tmp_path, changes, message):
    conf = json.loads(PENDULUM.read_text())
    conf["robot_pybullet"]["noise_flag"] = [1]
    for key, value in changes.items():
        section, _, name = key.partition("__")
        conf.setdefault(section, {})[name] = value
    with pytest.raises(InputError, match=None) as e:
        sac.convert(conf, source=PENDULUM)
    assert message in str(e.value)
    assert "simulation_and_control" in str(e.value)


def test_keys_simulation_and_control_never_reads_are_warnings_not_refusals():
    conf = json.loads(PENDULUM.read_text())
    conf["extra"] = {}
    conf["robot_pybullet"]["servo_gain"] = [1]
    conf["sim"]["step"] = 0.1
    notes = sac.convert(conf, source=PENDULUM).notes
    for key in ("extra", "robot_pybullet.servo_gain", "sim.step"):
        assert any(n.startswith(f"{key}: not a") and "no effect" in n for n in notes), notes


def test_a_top_level_section_of_theirs_is_recognised():
    assert sac.is_config({"sim": {}}) and not sac.is_config({"robots": []})
    with pytest.raises(InputError, match="robot_pybullet: required section"):
        sac.convert({"sim": {"time_step": 0.01}}, source=PENDULUM)


def test_foot_sensors_need_each_foot_label_as_simulation_and_control_does(tmp_path):
    conf = json.loads(QUADRUPED.read_text())
    conf["sim"]["RR"] = [["somewhere"]]
    with pytest.raises(InputError, match=r"sim.RR\[0\]: names none"):
        sac.convert(conf, source=QUADRUPED)


def test_per_robot_base_velocity_is_ignored_as_theirs_is_and_said():
    conf = json.loads(QUADRUPED.read_text())
    conf["robot_pybullet"]["init_link_base_vel"] = [[1.0, 0.0, 0.0]]
    conf["robot_pybullet"]["init_link_base_ang_vel"] = [[0.0, 0.0, 0.0]]
    imported = sac.convert(conf, source=QUADRUPED)
    assert "base_velocity" not in imported.scenario["robots"][0]
    assert any("init_link_base_vel" in n for n in imported.notes)
    conf["robot_pybullet"]["init_link_base_vel"] = [1.0, 0.0, 0.0]
    conf["robot_pybullet"]["init_link_base_ang_vel"] = [0.0, 0.0, 0.5]
    robot = sac.convert(conf, source=QUADRUPED).scenario["robots"][0]
    assert robot["base_velocity"] == [1.0, 0.0, 0.0]
    assert robot["base_angular_velocity"] == [0.0, 0.0, 0.5]


def test_scenario_loader_imports_and_keeps_the_notes():
    scenario = load_scenario(PENDULUM)
    assert scenario.robots[0].motor.scale_by_mass_matrix
    assert any("robot_pin" in n for n in scenario.notes)


# --------------------------------------------------------------------------- the CLI


def _cli(*args: str, cwd: Path | None = None) -> subprocess.CompletedProcess[str]:
    return subprocess.run([sys.executable, "-m", "urdfkit", *args], capture_output=True,
                          text=True, cwd=cwd, timeout=120,
                          env={**os.environ, "NO_COLOR": "1", "COLUMNS": "200"})


def test_sim_runs_their_config_and_convert_writes_the_same_scenario(tmp_path):
    out = tmp_path / "elsewhere" / "pendulum.toml"
    out.parent.mkdir()
    run = _cli("sim", str(PENDULUM), "-o", str(tmp_path / "a.jsonl"))
    assert run.returncode == 0, run.stderr
    assert "warning: robot_pybullet.urdf_path[0]: keeps PyBullet's link damping" in run.stderr
    conv = _cli("sim", "convert", str(PENDULUM), "-o", str(out))
    assert conv.returncode == 0, conv.stderr
    doc = tomllib.loads(out.read_text())
    assert not Path(doc["robots"][0]["urdf"]).is_absolute()  # relative to the TOML's folder
    assert "# - robot_pin" in out.read_text()
    again = _cli("sim", str(out), "-o", str(tmp_path / "b.jsonl"))
    assert again.returncode == 0, again.stderr
    assert (tmp_path / "a.jsonl").read_text() == (tmp_path / "b.jsonl").read_text()
    refused = _cli("sim", "convert", str(PENDULUM), "-o", str(out))
    assert refused.returncode == 2 and "exists" in refused.stderr
    assert len(refused.stderr.strip().splitlines()) == 1


def test_sim_convert_usage_errors_are_one_line():
    for args, text in ((("sim", "convert"), "convert needs"),
                       (("sim", "a.toml", "b.toml"), "one scenario at a time"),
                       (("sim", "convert", str(Path(__file__).parent.parent / "examples"
                                               / "two_cars.json")), "not a simulation_and")):
        run = _cli(*args)
        assert run.returncode == 2, (args, run.stderr)
        assert text in run.stderr and len(run.stderr.strip().splitlines()) == 1
