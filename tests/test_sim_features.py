"""The native scenario's newer keys: modes per joint, history, reset overrides, gains, damping.

Each is checked against what PyBullet or physics says should happen.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

from urdfkit.core.errors import InputError, ParameterError
from urdfkit.sim import Simulation

ROOT = Path(__file__).parent.parent
PENDULUM = str(ROOT / "examples" / "pendulum.urdf")
QUADRUPED = str(ROOT / "tests" / "fixtures" / "robots" / "quadruped_like.urdf")


def _pendulum(**robot: object) -> dict:
    return {"physics": {"time_step": 0.001}, "duration": 1.0,
            "robots": [{"name": "pendulum", "urdf": PENDULUM, "base": "fixed",
                        "initial_joints": {"hinge": 0.5}, **robot}]}


def test_one_segment_drives_each_joint_in_its_own_mode():
    doc = {"physics": {"time_step": 1 / 240, "gravity": [0, 0, 0]}, "robots": [{
        "name": "q", "urdf": QUADRUPED, "base": "fixed", "joints": [{
            "until": 5.0, "max_force": 30.0,
            "mode": {"FR_hip_joint": "position", "FR_thigh_joint": "velocity",
                     "FR_calf_joint": "torque"},
            "targets": {"FR_hip_joint": 0.3, "FR_thigh_joint": 1.5, "FR_calf_joint": 0.2}}]}]}
    with Simulation(doc) as s:
        # The torque's effect, not its echo: over the first step the joints' accelerations,
        # put through PyBullet's inverse dynamics, need exactly the 0.2 N m the calf was given
        # (and the hip's position motor at its 30 N m limit).
        p, c, body = s.session.p, s.session.client, s.bodies["q"].body
        movable = [j for j in range(p.getNumJoints(body, physicsClientId=c))
                   if p.getJointInfo(body, j, physicsClientId=c)[2] != p.JOINT_FIXED]
        names = [p.getJointInfo(body, j, physicsClientId=c)[1].decode() for j in movable]
        before = p.getJointStates(body, movable, physicsClientId=c)
        s.step()
        after = p.getJointStates(body, movable, physicsClientId=c)
        qdd = [(b[1] - a[1]) * 240 for a, b in zip(before, after, strict=True)]
        needed = dict(zip(names, p.calculateInverseDynamics(
            body, [a[0] for a in before], [a[1] for a in before], qdd, physicsClientId=c),
            strict=True))
        first = s.motor_torques("q")
        s.step(239)
        q = s.joint_positions("q")
        qd = s.joint_velocities("q")
    assert needed["FR_calf_joint"] == pytest.approx(0.2, abs=1e-6)
    assert first["FR_calf_joint"] == pytest.approx(needed["FR_calf_joint"], abs=1e-6)
    assert first["FR_hip_joint"] == pytest.approx(needed["FR_hip_joint"], abs=1e-6) == 30.0
    assert q["FR_hip_joint"] == pytest.approx(0.3, abs=1e-3)  # held at its target
    assert qd["FR_thigh_joint"] == pytest.approx(1.5, rel=1e-3)  # turning at its speed


def test_a_mode_per_joint_needs_every_target():
    doc = _pendulum(joints=[{"until": 1.0, "mode": {"other": "torque"},
                             "targets": {"hinge": 0.1}}])
    with pytest.raises(InputError, match=r"robots\[0\].joints\[0\].mode: no mode for target "
                                         "'hinge'"):
        Simulation(doc)


def test_history_keeps_the_last_n_steps_in_order():
    with Simulation(_pendulum(history=5, noise={"motor_angles": 0.01})) as s:
        assert [o.step for o in s.history("pendulum")] == [0]
        truth = []
        for _ in range(12):
            s.step()
            truth.append(s.observe("pendulum", ideal=True).motor_angles["hinge"])
        seen = s.history("pendulum")
        ideal = s.history("pendulum", ideal=True)
        assert [o.step for o in seen] == list(range(8, 13))
        assert [o.motor_angles["hinge"] for o in ideal] == truth[-5:]
        # Reported entries are the noisy ones observe() gave, and stay so.
        assert seen[-1].motor_angles == s.observe("pendulum").motor_angles
        assert np.std([a.motor_angles["hinge"] - b.motor_angles["hinge"]
                       for a, b in zip(seen, ideal, strict=True)]) > 0
        seen[-1].motor_angles["hinge"] = 99.0  # a copy
        assert s.history("pendulum")[-1].motor_angles["hinge"] != 99.0


def test_reset_overrides_start_an_episode_elsewhere():
    with Simulation(_pendulum()) as s:
        s.step(100)
        s.reset(overrides={"pendulum": {"initial_joints": {"hinge": {"position": -0.2,
                                                                     "velocity": 1.0}}}})
        assert s.joint_positions("pendulum")["hinge"] == pytest.approx(-0.2)
        assert s.joint_velocities("pendulum")["hinge"] == pytest.approx(1.0)
        assert s.t == 0.0
        s.reset()  # the scenario's start again
        assert s.joint_positions("pendulum")["hinge"] == pytest.approx(0.5)
        with pytest.raises(ParameterError, match="unknown key 'speed'"):
            s.reset(overrides={"pendulum": {"speed": 1}})
        with pytest.raises(ParameterError, match="no active joint named 'elbow'"):
            s.reset(overrides={"pendulum": {"initial_joints": {"elbow": 1.0}}})


def test_reset_overrides_move_a_floating_base_in_its_pose_frame():
    doc = {"robots": [{"name": "q", "urdf": QUADRUPED, "position": [0, 0, 1]}]}
    with Simulation(doc) as s:
        s.reset(overrides={"q": {"position": [1.0, 2.0, 0.5], "orientation_rpy": [0, 0, 1.0],
                                 "base_velocity": [0.5, 0, 0]}})
        at, turn = s.link_pose("q", "base")
        assert at == pytest.approx([1.0, 2.0, 0.5], abs=1e-9)
        assert 2 * math.atan2(turn[2], turn[3]) == pytest.approx(1.0)
        assert s.observe("q", ideal=True).base_lin_vel == pytest.approx([0.5, 0, 0])


def test_set_motor_gains_changes_the_servo_torque():
    doc = _pendulum(motor={"kp": 10.0}, physics={"time_step": 0.001, "gravity": [0, 0, 0]},
                    joints=[{"until": 1.0, "targets": {"hinge": 0.0}}])
    doc["physics"] = doc["robots"][0].pop("physics")
    with Simulation(doc) as s:
        # The servo's torque by its effect: from rest, with no gravity, one step of dt gives
        # the hinge qd = dt * tau / M(q), M from PyBullet's own mass matrix.
        p, c, body = s.session.p, s.session.client, s.bodies["pendulum"].body
        m = p.calculateMassMatrix(body, [0.5], physicsClientId=c)[0][0]
        s.step()
        first = s.joint_velocities("pendulum")["hinge"] * m / 0.001
        assert s.motor_torques("pendulum")["hinge"] == pytest.approx(first, rel=1e-9)
        s.reset()
        s.set_motor_gains("pendulum", kp={"hinge": 40.0})
        s.step()
        assert first == pytest.approx(-10.0 * 0.5, rel=1e-9)  # -kp (q - target)
        assert s.joint_velocities("pendulum")["hinge"] * m / 0.001 == \
            pytest.approx(-40.0 * 0.5, rel=1e-9)
        with pytest.raises(ParameterError, match="drives no joint named 'x'"):
            s.set_motor_gains("pendulum", kd={"x": 1.0})


def test_a_robots_own_zero_damping_keeps_an_undamped_swing():
    # PyBullet's 0.04 link damping costs a pendulum ~40% of its amplitude in 10 s.
    def amplitude_after(**robot: object) -> float:
        doc = _pendulum(**robot)
        doc["physics"]["time_step"] = 1 / 240
        with Simulation(doc) as s:
            s.step(240 * 9)
            peak = 0.0
            for _ in range(240):
                s.step()
                peak = max(peak, abs(s.joint_positions("pendulum")["hinge"]))
        return peak

    assert amplitude_after(linear_damping=0.0, angular_damping=0.0) == \
        pytest.approx(0.5, rel=0.01)
    assert amplitude_after() < 0.4


def test_pose_frame_com_places_the_centre_of_mass():
    # pendulum.urdf's base has its centre of mass 0.5 m above its frame.
    with Simulation(_pendulum(position=[0, 0, 1.5], pose_frame="com")) as s:
        assert s.observe("pendulum", ideal=True).base_position == pytest.approx([0, 0, 1.5])
        assert s.link_pose("pendulum", "base_link")[0] == pytest.approx([0, 0, 1.0])


def test_noise_per_joint_and_per_axis():
    doc = _pendulum(noise={"motor_angles": {"hinge": 0.02}, "base_position": [0.0, 0.1, 0.0],
                           "base_orientation": [0.0, 0.0, 0.05]})
    with Simulation(doc) as s:
        angles, ys, xs, yaws = [], [], [], []
        for _ in range(2000):
            s.step()
            seen, true = s.observe("pendulum"), s.observe("pendulum", ideal=True)
            angles.append(seen.motor_angles["hinge"] - true.motor_angles["hinge"])
            xs.append(seen.base_position[0] - true.base_position[0])
            ys.append(seen.base_position[1] - true.base_position[1])
            q = seen.base_orientation
            yaws.append(2 * math.atan2(q[2], q[3]))
    assert np.std(angles) == pytest.approx(0.02, rel=0.05)
    assert np.std(ys) == pytest.approx(0.1, rel=0.05) and max(map(abs, xs)) == 0.0
    assert np.std(yaws) == pytest.approx(0.05, rel=0.05)


# --------------------------------------------------------------------------- dry joint friction

HOLD = 1.0 * 9.81 * 0.5 * math.sin(0.5)  # the bob's gravity torque at q = 0.5: 2.35 N m


@pytest.mark.parametrize(("friction", "holds"), [(1.1 * HOLD, True), (0.9 * HOLD, False)])
def test_joint_friction_holds_the_pendulum_only_above_its_gravity_torque(friction, holds):
    with Simulation(_pendulum(joint_friction={"hinge": friction})) as s:
        s.step(1000)
        q = s.joint_positions("pendulum")["hinge"]
    if holds:
        assert q == pytest.approx(0.5, abs=1e-4)
    else:
        assert q < 0.45


def test_joint_friction_works_alongside_torque_commands_and_stays_across_reset():
    # Friction 3 N m against gravity's 2.35: a +2 N m push leaves 0.35 (held), a -2 N m one
    # adds up to 4.35 (slips).
    with Simulation(_pendulum()) as s:
        s.set_joint_friction("pendulum", "hinge", 3.0)
        s.set_joint_targets("pendulum", {"hinge": 2.0}, mode="torque")
        s.step(500)
        assert s.joint_positions("pendulum")["hinge"] == pytest.approx(0.5, abs=1e-4)
        s.set_joint_targets("pendulum", {"hinge": -2.0}, mode="torque")
        s.step(500)
        assert s.joint_positions("pendulum")["hinge"] < 0.4
        s.reset()
        s.step(500)  # no command: friction alone holds it
        assert s.joint_positions("pendulum")["hinge"] == pytest.approx(0.5, abs=1e-4)
        s.set_joint_friction("pendulum", "hinge", 0.0)
        s.step(200)
        assert s.joint_positions("pendulum")["hinge"] < 0.45


def test_a_position_command_owns_the_motor_and_friction_returns_after_it():
    with Simulation(_pendulum(joint_friction={"hinge": 3.0})) as s:
        s.set_joint_targets("pendulum", {"hinge": 0.2}, mode="position")
        s.step(1000)
        assert s.joint_positions("pendulum")["hinge"] == pytest.approx(0.2, abs=2e-3)
        s.set_joint_friction("pendulum", "hinge", 3.5)  # does not take the motor over
        s.step(100)
        assert s.joint_positions("pendulum")["hinge"] == pytest.approx(0.2, abs=2e-3)
        s.set_joint_targets("pendulum", {"hinge": 0.0}, mode="torque")
        s.reset(overrides={"pendulum": {"initial_joints": {"hinge": 0.5}}})
        s.set_joint_targets("pendulum", {"hinge": -0.9}, mode="torque")
        s.step(500)  # 2.35 + 0.9 = 3.25: held by the 3.5 set during the command, not by 3
        assert s.joint_positions("pendulum")["hinge"] == pytest.approx(0.5, abs=1e-4)


def test_joint_friction_refuses_bad_names_and_values():
    with pytest.raises(InputError, match=r"robots\[0\].joint_friction.elbow: .*'elbow'"):
        Simulation(_pendulum(joint_friction={"elbow": 1.0}))
    with pytest.raises(InputError, match=r"joint_friction.hinge"):
        Simulation(_pendulum(joint_friction={"hinge": -1.0}))
    with Simulation(_pendulum()) as s:
        with pytest.raises(ParameterError, match="no joint named 'elbow'"):
            s.set_joint_friction("pendulum", "elbow", 1.0)
        with pytest.raises(ParameterError, match=">= 0"):
            s.set_joint_friction("pendulum", "hinge", -1.0)
        with pytest.raises(ParameterError, match=">= 0"):
            s.set_joint_friction("pendulum", "hinge", math.nan)
