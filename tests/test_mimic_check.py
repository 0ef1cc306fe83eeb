"""``<mimic>``: PyBullet ignores it (measured here), check says so per joint, joints shows it."""

from __future__ import annotations

import json
from pathlib import Path

from typer.testing import CliRunner

from urdfkit.cli import app

GRIPPER = Path(__file__).parent / "fixtures" / "robots" / "mimic_gripper.urdf"


def _run(*args: str) -> tuple[int, str]:
    r = CliRunner().invoke(app, list(args))
    return r.exit_code, r.stdout


def test_raw_pybullet_ignores_mimic(pb) -> None:
    """Drive the leader: the followers stay where they are, nowhere near the relation."""
    p, c = pb
    body = p.loadURDF(str(GRIPPER), physicsClientId=c)
    p.setGravity(0, 0, 0, physicsClientId=c)
    p.setJointMotorControl2(body, 0, p.POSITION_CONTROL, targetPosition=0.015, force=20,
                            physicsClientId=c)
    for _ in range(1000):
        p.stepSimulation(physicsClientId=c)
    leader = p.getJointState(body, 0, physicsClientId=c)[0]
    right = p.getJointState(body, 1, physicsClientId=c)[0]
    assert abs(leader - 0.015) < 1e-3
    assert abs(right - (-1 * leader + 0.01)) > 4e-3  # the mimic would put it at -0.005


def test_check_names_every_mimic() -> None:
    code, out = _run("check", str(GRIPPER), "--json")
    found = [f for f in json.loads(out)["findings"] if f["code"] == "U310"]
    assert len(found) == 2 and all(f["level"] == "info" for f in found)
    right = next(f["message"] for f in found if "right_finger_joint" in f["message"])
    assert "'left_finger_joint'" in right and "x -1 + 0.01" in right
    assert "gearRatio 1" in right  # -1 / multiplier
    thumb = next(f["message"] for f in found if "thumb_joint" in f["message"])
    assert "x 1 + 0" in thumb and "gearRatio -1" in thumb
    assert code == 0  # notes only


def test_gear_ratio_advice_is_right(pb) -> None:
    """The gear the note advises keeps the follower's velocity at multiplier x the leader's."""
    p, c = pb
    body = p.loadURDF(str(GRIPPER), physicsClientId=c)
    for i in range(3):
        p.setJointMotorControl2(body, i, p.VELOCITY_CONTROL, force=0, physicsClientId=c)
    gear = p.createConstraint(body, 0, body, 1, p.JOINT_GEAR, [1, 0, 0], [0, 0, 0], [0, 0, 0],
                              physicsClientId=c)
    p.changeConstraint(gear, gearRatio=1.0, maxForce=100, physicsClientId=c)  # -1 / -1
    p.setJointMotorControl2(body, 0, p.POSITION_CONTROL, targetPosition=0.015, force=20,
                            physicsClientId=c)
    for _ in range(1000):
        p.stepSimulation(physicsClientId=c)
    leader = p.getJointState(body, 0, physicsClientId=c)[0]
    right = p.getJointState(body, 1, physicsClientId=c)[0]
    assert abs(right - (-1 * leader)) < 1e-3  # velocities tied from 0: position x -1


def test_joints_shows_the_relation() -> None:
    code, out = _run("joints", str(GRIPPER), "--json")
    joints = {j["jointName"]: j for j in json.loads(out)["joints"]}
    assert joints["right_finger_joint"]["mimic"] == {
        "joint": "left_finger_joint", "multiplier": -1.0, "offset": 0.01}
    assert joints["thumb_joint"]["mimic"] == {
        "joint": "left_finger_joint", "multiplier": 1.0, "offset": 0.0}
    assert joints["left_finger_joint"]["mimic"] is None
    code, text = _run("joints", str(GRIPPER), "--all")
    assert "left_finger_joint x -1 + 0.01" in text and "PyBullet ignores it" in text
