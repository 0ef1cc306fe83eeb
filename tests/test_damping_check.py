"""U311: joint damping PyBullet's explicit step cannot carry (the Shadow hand's fingers), judged
against raw PyBullet: its mass matrix, and whether the joint's speed flips sign each step."""

from __future__ import annotations

import json
import re
from pathlib import Path

import numpy as np
import pytest
from typer.testing import CliRunner

from urdfkit.checks.rules_joints import _zero_pose_tree
from urdfkit.cli import app
from urdfkit.formats.fk import link_frames
from urdfkit.formats.robot import read_robot
from urdfkit.model.index import Doc
from urdfkit.sources.resolve import resolve

runner = CliRunner()
ROBOTS = Path(__file__).parent / "fixtures" / "robots"
STIFF = ROBOTS / "stiff_damping.urdf"


def _u311(path: Path) -> list[dict]:
    r = runner.invoke(app, ["check", str(path), "--json"])
    assert r.exit_code in (0, 1), r.output
    return [f for f in json.loads(r.stdout)["findings"] if f["code"] == "U311"]


def test_damping_pybullet_cannot_step_is_found_with_pybullets_inertia(free_swing) -> None:
    inertia, speeds = free_swing(STIFF, 1 / 240)
    # raw PyBullet: the speed flips sign every step and runs to the 100 rad/s cap
    assert all(a * b < 0 for a, b in zip(speeds[1:], speeds[2:], strict=False)), speeds
    assert max(map(abs, speeds)) == pytest.approx(100.0)
    found = _u311(STIFF)
    assert len(found) == 1 and found[0]["level"] == "warning", found
    message = found[0]["message"]
    assert "finger_joint" in message
    said = float(re.search(r"against the ([0-9.e+-]+) kg m\^2", message).group(1))
    assert said == pytest.approx(inertia, rel=5e-3)  # 5e-06: 1e-6 + 0.01 x 0.02^2
    rate = float(re.search(r"by 1 - ([0-9.e+-]+)", message).group(1))
    assert rate == pytest.approx(0.1 / 240 / inertia, rel=5e-3)


def test_damping_pybullet_steps_stably_is_not_found(free_swing, tmp_path: Path) -> None:
    # a hundredth of the damping: 0.83 per step, under 2
    calm = tmp_path / "calm.urdf"
    calm.write_text(STIFF.read_text().replace('damping="0.1"', 'damping="0.001"'))
    inertia, speeds = free_swing(calm, 1 / 240)
    assert 0.001 / 240 / inertia < 2
    assert all(a * b > 0 for a, b in zip(speeds[1:], speeds[2:], strict=False)), speeds
    # it settles at the damped terminal speed, gravity's torque over the damping: m g d / b
    assert abs(speeds[-1]) == pytest.approx(0.01 * 9.81 * 0.02 / 0.001, rel=0.01)
    assert _u311(calm) == []


def test_an_inertia_pybullet_zeroes_counts_as_zero(free_swing, tmp_path: Path) -> None:
    # The finger's izz over ixx + iyy (no rigid body has it): PyBullet's importer warns "Bad
    # inertia tensor properties" and zeroes the tensor (the Allegro hand's fingers in
    # example-robot-data). About the y axis the file says 2e-6 + 0.01 x 0.02^2 = 6e-6 kg m^2;
    # PyBullet moves 4e-6, the mass alone.
    bad = tmp_path / "bad_inertia.urdf"
    bad.write_text(STIFF.read_text().replace(
        'ixx="1e-6" ixy="0" ixz="0" iyy="1e-6" iyz="0" izz="1e-6"',
        'ixx="1e-6" ixy="0" ixz="0" iyy="2e-6" iyz="0" izz="5e-6"'))
    inertia, speeds = free_swing(bad, 1 / 240)
    assert inertia == pytest.approx(0.01 * 0.02**2, rel=1e-6)
    assert max(map(abs, speeds)) == pytest.approx(100.0)
    found = _u311(bad)
    assert len(found) == 1, found
    said = float(re.search(r"against the ([0-9.e+-]+) kg m\^2", found[0]["message"]).group(1))
    assert said == pytest.approx(inertia, rel=5e-3)


COUPLED = Path(__file__).parent / "fixtures" / "robots" / "coupled_damping.urdf"


def _raw_coupled(pb, damping_scale: float) -> tuple[float, list[tuple[float, float]]]:
    """Raw PyBullet on the coupled fixture, base fixed, gravity and motors off: the largest
    eigenvalue of dt M^-1 B from its own mass matrix, and both joints' speeds over 8 steps
    from 0.01 rad/s along the relative motion (the joints turned against each other)."""
    import numpy as np

    from urdfkit.engine.session import quiet_stdout

    p, c = pb
    p.resetSimulation(physicsClientId=c)
    with quiet_stdout():
        body = p.loadURDF(str(COUPLED), useFixedBase=True, flags=p.URDF_USE_INERTIA_FROM_FILE,
                          physicsClientId=c)
    m = np.array(p.calculateMassMatrix(body, [0.0, 0.0], physicsClientId=c))
    b = np.array([p.getJointInfo(body, j, physicsClientId=c)[6] for j in (0, 1)])
    rate = float(np.linalg.eigvals(np.linalg.solve(m, np.diag(b))).real.max()) / 240
    p.setGravity(0, 0, 0, physicsClientId=c)
    p.setTimeStep(1 / 240, physicsClientId=c)
    for j, v in ((0, -0.01), (1, 0.01)):
        p.changeDynamics(body, j, jointDamping=float(b[j]) * damping_scale, linearDamping=0,
                         angularDamping=0, physicsClientId=c)
        p.setJointMotorControl2(body, j, p.VELOCITY_CONTROL, force=0, physicsClientId=c)
        p.resetJointState(body, j, 0.0, v, physicsClientId=c)
    speeds = []
    for _ in range(8):
        p.stepSimulation(physicsClientId=c)
        s = p.getJointStates(body, [0, 1], physicsClientId=c)
        speeds.append((s[0][1], s[1][1]))
    return rate, speeds


def test_joints_unstable_together_though_not_alone_are_found(pb) -> None:
    """HSR's hand: each damped joint alone moves enough inertia (dt b / M_ii 0.13), so the
    joint-by-joint rule was silent, but turned against each other the two carry only the small
    link between them: the largest eigenvalue of dt M^-1 B is 5.46 and raw PyBullet's speeds
    flip sign and grow 4.5x a step. check now judges the whole mass matrix; the figure it gives
    is raw PyBullet's, and its advice (the damping scaled under 2 / eigenvalue) settles it."""
    rate, speeds = _raw_coupled(pb, 1.0)
    finger = [s[1] for s in speeds]
    assert all(a * b < 0 for a, b in zip(finger, finger[1:], strict=False)), finger
    assert abs(finger[3]) > 10 * abs(finger[0])  # grows, as 1 - rate says
    found = _u311(COUPLED)
    assert len(found) == 1, found
    message = found[0]["message"]
    assert "finger_joint" in message and "spring_joint" in message, message
    said = float(re.search(r"eigenvalue of dt M\^-1 B at its default 1/240 s is ([0-9.e+-]+)",
                           message).group(1))
    assert said == pytest.approx(rate, rel=5e-3)
    scale = float(re.search(r"damping under ([0-9.e+-]+) of what it is", message).group(1))
    _, settled = _raw_coupled(pb, 0.9 * scale)
    assert all(abs(s[1]) <= 0.0101 for s in settled), settled  # decays, without flipping


def test_a_damped_joint_without_a_child_is_a_finding_not_a_crash(tmp_path: Path) -> None:
    # Found by the fuzz campaign (10 of 1,500 mutants): U311 walked the links below a joint
    # from its <child>, which the mutant had lost.
    text = STIFF.read_text()
    cut = re.sub(r"<child link=\"[^\"]*\"\s*/>", "", text, count=1)
    assert cut != text and "damping" in cut
    path = tmp_path / "no_child.urdf"
    path.write_text(cut)
    r = runner.invoke(app, ["check", str(path), "--json"])
    assert r.exit_code == 1, r.output
    assert "U201" in {f["code"] for f in json.loads(r.stdout)["findings"]}
    r = runner.invoke(app, ["fix", str(path), "--diff"])
    assert r.exit_code in (0, 1), r.output


@pytest.mark.parametrize("name", [
    "kuka_iiwa/model.urdf", "r2d2.urdf", "quadruped/minitaur.urdf", "xarm/xarm6_robot.urdf",
    "laikago/laikago.urdf", "franka_panda/panda.urdf", str(ROBOTS / "coupled_damping.urdf"),
    str(ROBOTS / "turned_arm.urdf"), str(ROBOTS / "ur_like.urdf"),
    str(ROBOTS / "panda_like.urdf")])
def test_u311_places_every_link_where_formats_fk_does(name: str) -> None:
    """The zero-pose mass matrix U311 judges puts each link at urdfkit.formats.fk's frame (the
    one forward kinematics, which tests/test_export_units.py holds to yourdfpy at 1e-12)."""
    with resolve(name) as r:
        robot = read_robot(r.root, r.name)
        doc = Doc(r.root)
    links = {lv.name: lv for lv in doc.links if lv.name is not None}
    below: dict[str, list] = {}
    for jv in doc.joints:
        parent = jv.parent.get("link") if jv.parent is not None else None
        if parent is not None and jv.child is not None:
            below.setdefault(parent, []).append(jv)
    tree = _zero_pose_tree(doc, links, below)
    assert tree is not None
    _, order, frames, _ = tree
    fk = link_frames(robot, {})
    assert sorted(order) == sorted(fk) == sorted(robot.links)
    for link in order:
        rot, pos = frames[link]
        assert np.array(rot) == pytest.approx(fk[link][:3, :3], abs=1e-12), link
        assert np.array(pos) == pytest.approx(fk[link][:3, 3], abs=1e-12), link
