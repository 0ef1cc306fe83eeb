"""simulation_and_control parity (issue 25): configs as users have them run, with warnings for
what SimInterface never reads or would stop on, and the same run as the complete config."""

from __future__ import annotations

import copy
import json
import shutil
from pathlib import Path

import pytest
from typer.testing import CliRunner

from urdfkit.cli import app
from urdfkit.motion import sac
from urdfkit.sim import Simulation

FIXTURES = Path(__file__).parent / "fixtures" / "sac"
README_KEYS = FIXTURES / "configs" / "readme_keys.json"
#: Keys the README example carries that SimInterface's code never reads.
UNREAD = ["robot_pybullet.ros_urdf_path", "robot_pybullet.motor_friction",
          "robot_pybullet.motor_friction_coeff", "robot_pin.ros_urdf_path",
          "robot_pin.floating_base_name"]
#: Keys SimInterface indexes that the README example lacks, with the value meaning "off".
MISSING = {"motor_damping": [0], "motor_damping_coeff": [0.0], "motor_elastic_torque": [0],
           "motor_elastic_coeff": [0.0], "motor_inertia": [0], "motor_inertia_coeff": [0.0],
           "noise_flag": [0], "robot_noise": [{}], "delay_measure_flag": [0]}


def _setup(tmp_path: Path) -> Path:
    shutil.copytree(FIXTURES / "models", tmp_path / "models")
    (tmp_path / "configs").mkdir()
    target = tmp_path / "configs" / README_KEYS.name
    shutil.copy(README_KEYS, target)
    return target


def test_the_readme_example_keys_run_with_warnings_only(tmp_path: Path) -> None:
    config = _setup(tmp_path)
    result = CliRunner().invoke(app, ["sim", str(config), "-o", str(tmp_path / "rows.csv")])
    assert result.exit_code == 0, result.stderr
    warnings = [ln for ln in result.stderr.splitlines() if ln.startswith("urdfkit: warning:")]
    assert not [ln for ln in result.stderr.splitlines()
                if ln.strip() and not ln.startswith(("urdfkit: warning:", "wrote "))]
    for key in UNREAD:
        assert any(f"warning: {key}: not a key SimInterface reads" in w for w in warnings), key
    for key in MISSING:
        assert any(f"warning: robot_pybullet.{key}: missing; SimInterface stops with a "
                   "KeyError" in w for w in warnings), key


def test_unread_keys_change_nothing_and_missing_keys_run_as_off(tmp_path: Path) -> None:
    config = _setup(tmp_path)
    as_given = json.loads(config.read_text())
    complete = copy.deepcopy(as_given)
    for key in UNREAD:
        section, name = key.split(".")
        del complete[section][name]
    complete["robot_pybullet"].update(MISSING)
    complete_path = config.with_name("complete.json")
    complete_path.write_text(json.dumps(complete))
    quiet = sac.convert(complete, source=complete_path).notes
    assert not [n for n in quiet if "not a key" in n or "missing;" in n]

    def run(path: Path) -> list[list[float]]:
        sim = Simulation.from_file(path)
        try:
            out = []
            for _ in range(300):
                sim.step()
                o = sim.observe(sim.robot_names()[0])
                out.append([*o.motor_angles.values(), *o.motor_velocities.values()])
            return out
        finally:
            sim.close()

    a, b = run(config), run(complete_path)
    assert a == b  # bit for bit
    assert a[-1] != a[0]  # not vacuous: the arm moved under its servo and gravity


@pytest.mark.parametrize("where", ["robot_pybullet", "sim", "top"])
def test_an_unknown_key_is_a_warning_never_a_refusal(tmp_path: Path, where: str) -> None:
    config = _setup(tmp_path)
    conf = json.loads(config.read_text())
    (conf if where == "top" else conf[where])["made_up_key"] = 1
    notes = sac.convert(conf, source=config).notes
    name = "made_up_key" if where == "top" else f"{where}.made_up_key"
    assert any(n.startswith(f"{name}: not a") and "no effect" in n for n in notes)


# --------------------------------------------------------------------------- the reference


import collections  # noqa: E402

import numpy as np  # noqa: E402
import pybullet as p  # noqa: E402
import pybullet_data  # noqa: E402

OFFSETS, DIRECTIONS = [0.2, -0.1], [-1, 1]


def _arm_config(tmp_path: Path, *, delay: int, damping: float, spring: float) -> Path:
    shutil.copytree(FIXTURES / "models", tmp_path / "models", dirs_exist_ok=True)
    (tmp_path / "configs").mkdir(exist_ok=True)
    conf = json.loads((FIXTURES / "configs" / "pendulum.json").read_text())
    rp = conf["robot_pybullet"]
    rp.update({
        "urdf_path": ["arm2.urdf"], "init_link_base_position": [[0.0, 0.0, 0.0]],
        "init_motor_angles": [[0.4, -0.7]], "init_motor_vel": [[0.0, 0.0]],
        "motor_offset": [OFFSETS], "motor_direction": [DIRECTIONS],
        "servo_pos_gains": [60.0], "servo_vel_gains": [4.0],
        "motor_damping": [int(damping > 0)], "motor_damping_coeff": [damping],
        "motor_elastic_torque": [int(spring > 0)], "motor_elastic_coeff": [spring],
        "delay_measure_flag": [int(delay > 0)], "delay_measure_steps": [delay]})
    conf["robot_pin"]["urdf_path"] = ["arm2.urdf"]
    path = tmp_path / "configs" / f"arm_{delay}_{damping}_{spring}.json"
    path.write_text(json.dumps(conf))
    return path


class SimInterfaceArm:
    """SimInterface's semantics for one fixed-base robot, in raw PyBullet (from its code):

    motor angles ``(q - offset) * direction`` and velocities ``qd * direction`` (offsets not
    applied to velocities), delayed by ``delay`` steps; the servo reads the delayed state, its
    friction and spring terms multiplied by ``calculateMassMatrix`` at the *current* adjusted
    angles passed as joint angles; the torque applied is the servo's times ``direction``, and
    GetMotorTorques reports that applied torque, undelayed.
    """

    def __init__(self, config: Path):
        conf = json.loads(config.read_text())
        rp = self.rp = conf["robot_pybullet"]
        c = self.c = p.connect(p.DIRECT)
        p.setPhysicsEngineParameter(numSolverIterations=30, physicsClientId=c)
        p.setTimeStep(conf["sim"]["time_step"], physicsClientId=c)
        p.setGravity(0, 0, -9.81, physicsClientId=c)
        p.setPhysicsEngineParameter(enableConeFriction=0, physicsClientId=c)
        p.loadURDF(str(Path(pybullet_data.getDataPath()) / "plane.urdf"), physicsClientId=c)
        urdf = config.parent.parent / "models" / rp["urdf_path"][0]
        self.body = p.loadURDF(str(urdf), [0, 0, 0], [0, 0, 0, 1], useFixedBase=True,
                               flags=p.URDF_USE_INERTIA_FROM_FILE, physicsClientId=c)
        n = p.getNumJoints(self.body, physicsClientId=c)
        for j in range(n):  # SimInterface's quirk: body id = joint index
            p.changeDynamics(j, -1, linearDamping=0.0, angularDamping=0.0, physicsClientId=c)
        self.active = [j for j in range(n)
                       if p.getJointInfo(self.body, j, physicsClientId=c)[2] != p.JOINT_FIXED]
        self.off, self.dir = np.array(rp["motor_offset"][0]), np.array(rp["motor_direction"][0])
        for k, j in enumerate(self.active):
            p.setJointMotorControl2(self.body, j, p.VELOCITY_CONTROL, targetVelocity=0,
                                    force=0, physicsClientId=c)
            p.resetJointState(self.body, j, rp["init_motor_angles"][0][k], 0.0,
                              physicsClientId=c)
        delay = rp["delay_measure_steps"][0] if rp["delay_measure_flag"][0] else 0
        self.buffer: collections.deque[tuple[np.ndarray, np.ndarray]] = \
            collections.deque(maxlen=delay + 1)
        self.buffer.append(self.state())
        self.applied = np.zeros(len(self.active))

    def state(self) -> tuple[np.ndarray, np.ndarray]:
        st = p.getJointStates(self.body, self.active, physicsClientId=self.c)
        q = np.array([s[0] for s in st])
        qd = np.array([s[1] for s in st])
        return (q - self.off) * self.dir, qd * self.dir

    def step(self, command: list[float] | None) -> None:
        rp, n = self.rp, len(self.active)
        q, qd = self.buffer[0]  # delayed
        now_q, _ = self.buffer[-1]  # current, adjusted: what ComputeMassMatrix is given
        m = np.array(p.calculateMassMatrix(self.body, now_q.tolist(), physicsClientId=self.c))
        extra = np.zeros(n)
        if rp["motor_damping"][0]:
            extra -= rp["motor_damping_coeff"][0] * qd
        if rp["motor_elastic_torque"][0]:
            extra -= rp["motor_elastic_coeff"][0] * q
        tau = m @ extra
        if command is not None:
            tau += -rp["servo_pos_gains"][0] * (q - np.asarray(command)) \
                - rp["servo_vel_gains"][0] * qd
        self.applied = tau * self.dir
        p.setJointMotorControlArray(self.body, self.active, p.TORQUE_CONTROL,
                                    forces=self.applied.tolist(), physicsClientId=self.c)
        p.stepSimulation(physicsClientId=self.c)
        self.buffer.append(self.state())

    def close(self) -> None:
        p.disconnect(self.c)


@pytest.mark.parametrize(("delay", "damping", "spring", "command"), [
    (0, 0.0, 0.0, None),          # free: gravity only
    (3, 0.0, 0.0, [0.3, 0.5]),    # the servo, on a 3-step-delayed reading
    (3, 0.8, 2.0, [0.3, 0.5]),    # and friction and spring through the mass matrix
])
def test_an_arm_with_offsets_directions_delay_and_servo_reports_what_siminterface_does(
        tmp_path: Path, delay: int, damping: float, spring: float,
        command: list[float] | None) -> None:
    config = _arm_config(tmp_path, delay=delay, damping=damping, spring=spring)
    ref = SimInterfaceArm(config)
    try:
        with Simulation.from_file(config) as s:
            robot = s.robot_names()[0]
            names = list(s.joint_positions(robot))
            if command is not None:
                s.set_joint_targets(robot, dict(zip(names, command, strict=True)))
            moved = 0.0
            for step in range(400):
                s.step()
                ref.step(command)
                seen = s.observe(robot)
                q, qd = ref.buffer[0]  # what SimInterface's getters report (delayed)
                assert [seen.motor_angles[k] for k in names] == pytest.approx(q, abs=1e-9)
                assert [seen.motor_velocities[k] for k in names] == pytest.approx(qd, abs=1e-9)
                torques = s.motor_torques(robot)
                # the applied torque, in the joint's own frame, never delayed
                assert [torques[k] for k in names] == pytest.approx(ref.applied.tolist(),
                                                                    abs=1e-9), step
                moved = max(moved, float(np.max(np.abs(ref.buffer[-1][0] - ref.buffer[0][0]))))
            if delay:
                assert moved > 1e-4  # the delay is visible: the test can tell it apart
    finally:
        ref.close()


def test_a_direction_of_minus_one_is_not_a_sign_flip_of_the_torque(tmp_path: Path) -> None:
    # The torque reported is the one PyBullet applied at the joint: after one step from rest
    # its sign is the sign of the joint's acceleration (gravity held off by the servo aside).
    config = _arm_config(tmp_path, delay=0, damping=0.0, spring=0.0)
    with Simulation.from_file(config) as s:
        robot = s.robot_names()[0]
        s.set_joint_targets(robot, {"shoulder": 1.5, "elbow": 0.0})
        s.step()
        applied = s.motor_torques(robot)["shoulder"]
        ps, c = s.session.p, s.session.client
        body = s.bodies[robot].body
        m = np.array(ps.calculateMassMatrix(body, [0.4, -0.7], physicsClientId=c))
        g = np.array(ps.calculateInverseDynamics(body, [0.4, -0.7], [0.0, 0.0], [0.0, 0.0],
                                                 physicsClientId=c))
        qdd = np.linalg.solve(m, np.array([applied, s.motor_torques(robot)["elbow"]]) - g)
        joint_qd = ps.getJointState(body, 0, physicsClientId=c)[1]
        dt = s.time_step
        assert joint_qd == pytest.approx(qdd[0] * dt, rel=0.02)
