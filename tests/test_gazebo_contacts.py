"""Gazebo contact parameters: read in three forms, named by check, carried over by fix.

The oracle is raw PyBullet: its getDynamicsInfo after the fix, and a cart sliding sideways on
plane.urdf (lateral friction 1) that stops in v^2 / (2 mu g), mu the link's coefficient.
"""

from __future__ import annotations

import json
from pathlib import Path

import pytest
from lxml import etree
from typer.testing import CliRunner

from urdfkit.cli import app
from urdfkit.model.gazebo import gazebo_contacts

CART = Path(__file__).parent / "fixtures" / "robots" / "gazebo_wheels.urdf"
WHEELS = ("front_left_wheel", "front_right_wheel", "rear_left_wheel", "rear_right_wheel")
G = 9.81


def _run(*args: str) -> tuple[int, str]:
    r = CliRunner().invoke(app, list(args))
    return r.exit_code, r.stdout


def test_reads_the_three_forms() -> None:
    found = gazebo_contacts(etree.parse(str(CART)).getroot())
    assert set(found) == {*WHEELS, "bumper"}  # base_link's block holds only a material
    front = found["front_left_wheel"]
    assert (front.mu1, front.mu2, front.kp, front.kd) == (0.3, 0.3, 1e6, 100.0)
    assert front.not_carried == ["minDepth"]
    rear = found["rear_left_wheel"]  # element text
    assert (rear.mu1, rear.mu2, rear.kp) == (0.3, 0.3, None)
    assert rear.pybullet() == {"lateral_friction": 0.3}  # no kp/kd: no spring
    bumper = found["bumper"]  # SDF <surface><friction><ode><mu>
    assert (bumper.mu1, bumper.mu2, bumper.lateral_friction) == (0.9, 0.6, 0.6)
    assert bumper.not_carried == ["slip1"]


def test_gazebo_inside_a_link_is_read_not_unknown(tmp_path: Path) -> None:
    path = tmp_path / "inner.urdf"
    path.write_text('<robot name="r"><link name="a"><collision><geometry><box size="1 1 1"/>'
                    '</geometry></collision><gazebo><mu1>2</mu1></gazebo></link></robot>')
    assert gazebo_contacts(etree.parse(str(path)).getroot())["a"].mu1 == 2.0
    codes = [f["code"] for f in json.loads(_run("check", str(path), "--json")[1])["findings"]]
    assert "U801" not in codes and "U803" in codes


def test_check_names_each_wheel() -> None:
    code, out = _run("check", str(CART), "--json")
    found = [f for f in json.loads(out)["findings"] if f["code"] == "U803"]
    assert len(found) == 5
    for wheel in WHEELS:
        message = next(f["message"] for f in found if f"'{wheel}'" in f["message"])
        assert "lateral friction 0.5 where Gazebo's is 0.3" in message
        assert "--gazebo-contacts" in message
    bumper = next(f["message"] for f in found if "'bumper'" in f["message"])
    assert "mu1 and mu2 differ" in bumper and "slip1" in bumper


def _slide(pb, path: Path, v: float = 2.0) -> tuple[float, list[tuple[float, float, float]]]:
    """How far the cart slides sideways from v, and each link's (friction, damping, stiffness)."""
    import pybullet_data

    p, c = pb
    p.resetSimulation(physicsClientId=c)
    p.setGravity(0, 0, -G, physicsClientId=c)
    p.loadURDF(str(Path(pybullet_data.getDataPath()) / "plane.urdf"), physicsClientId=c)
    body = p.loadURDF(str(path), [0, 0, 0.1], physicsClientId=c)
    n = p.getNumJoints(body, physicsClientId=c)
    for i in range(n):
        p.setJointMotorControl2(body, i, p.VELOCITY_CONTROL, force=0, physicsClientId=c)
    for _ in range(240):  # settle on the wheels
        p.stepSimulation(physicsClientId=c)
    y0 = p.getBasePositionAndOrientation(body, physicsClientId=c)[0][1]
    p.resetBaseVelocity(body, [0, v, 0], physicsClientId=c)  # along the wheel axles: no rolling
    for _ in range(240 * 3):
        p.stepSimulation(physicsClientId=c)
    y1 = p.getBasePositionAndOrientation(body, physicsClientId=c)[0][1]
    dyn = [p.getDynamicsInfo(body, i, physicsClientId=c) for i in range(-1, n)]
    return y1 - y0, [(d[1], d[8], d[9]) for d in dyn]


def test_fix_carries_friction_and_the_cart_slides_as_it_says(pb, tmp_path: Path) -> None:
    out = tmp_path / "fixed.urdf"
    code, text = _run("fix", str(CART), "--gazebo-contacts", "-o", str(out), "--json")
    assert code == 0, text
    assert {f["code"] for f in json.loads(text)["fixes"]} == {"U803"}
    # Without the option nothing changes, and nothing is left over.
    code, text = _run("fix", str(CART), "--json", "-o", str(tmp_path / "same.urdf"))
    assert code == 0 and not json.loads(text)["changed"]

    before, dyn_before = _slide(pb, CART)
    after, dyn_after = _slide(pb, out)
    assert all(d[0] == 0.5 for d in dyn_before)
    # Joint order: bumper (0), then the four wheels; -1 is the base.
    wheels = dyn_after[2:]
    assert [round(d[0], 9) for d in wheels] == [0.3] * 4
    assert wheels[0][1:] == (100.0, 1e6) and wheels[1][1:] == (100.0, 1e6)  # kd, kp
    assert dyn_after[1][0] == pytest.approx(0.6)  # the bumper: the smaller of mu and mu2
    # Sliding distance v^2 / (2 mu g) with mu the wheels' coefficient (the plane's is 1).
    assert before == pytest.approx(2.0 ** 2 / (2 * 0.5 * G), rel=0.06)
    assert after == pytest.approx(2.0 ** 2 / (2 * 0.3 * G), rel=0.06)
    # check on the fixed file: the contacts are carried, nothing more to say.
    findings = json.loads(_run("check", str(out), "--json")[1])["findings"]
    assert not [f for f in findings if f["code"] == "U803"]


def test_a_link_without_collision_gets_nothing(tmp_path: Path) -> None:
    """Unitree's imu_link: mu1 on a link that touches nothing is no finding (found on go1)."""
    path = tmp_path / "imu.urdf"
    path.write_text('<robot name="r"><link name="a"><collision><geometry><box size="1 1 1"/>'
                    '</geometry></collision></link><link name="imu"/><joint name="j" '
                    'type="fixed"><parent link="a"/><child link="imu"/></joint>'
                    '<gazebo reference="imu"><mu1>0.2</mu1></gazebo>'
                    '<gazebo reference="a"><mu1>0.2</mu1></gazebo></robot>')
    found = [f for f in json.loads(_run("check", str(path), "--json")[1])["findings"]
             if f["code"] == "U803"]
    assert len(found) == 1 and "'a'" in found[0]["message"]


ONE_WAY = Path(__file__).parent / "fixtures" / "robots" / "one_way_grip.urdf"


def _roll(pb, path: Path, seconds: float = 2.0, omega: float = 5.0) -> tuple[float, list[float]]:
    """Raw PyBullet: all four wheels at omega on plane.urdf; the base's travel in x and each
    wheel's lateral friction."""
    import pybullet_data

    p, c = pb
    p.resetSimulation(physicsClientId=c)
    p.setGravity(0, 0, -G, physicsClientId=c)
    p.loadURDF(str(Path(pybullet_data.getDataPath()) / "plane.urdf"), physicsClientId=c)
    body = p.loadURDF(str(path), [0, 0, 0.07], flags=p.URDF_USE_IMPLICIT_CYLINDER,
                      physicsClientId=c)
    n = p.getNumJoints(body, physicsClientId=c)
    for _ in range(120):  # settle
        p.stepSimulation(physicsClientId=c)
    x0 = p.getBasePositionAndOrientation(body, physicsClientId=c)[0][0]
    for i in range(n):
        p.setJointMotorControl2(body, i, p.VELOCITY_CONTROL, targetVelocity=omega, force=1.5,
                                physicsClientId=c)
    for _ in range(int(240 * seconds)):
        p.stepSimulation(physicsClientId=c)
    x1 = p.getBasePositionAndOrientation(body, physicsClientId=c)[0][0]
    return x1 - x0, [p.getDynamicsInfo(body, i, physicsClientId=c)[1] for i in range(n)]


def test_one_way_grip_is_carried_as_the_larger_so_the_robot_drives(pb, tmp_path: Path) -> None:
    """ROSbot 2R's wheels (mu 1 along fdir1, mu2 0 across): the smaller, 0, stops the robot."""
    out = tmp_path / "fixed.urdf"
    code, text = _run("fix", str(ONE_WAY), "--gazebo-contacts", "-o", str(out), "--json")
    assert code == 0, text
    fixes = json.loads(text)["fixes"]
    assert len(fixes) == 4 and all("the larger of mu1 and mu2" in f["message"] for f in fixes)
    moved, friction = _roll(pb, out)
    assert friction == [1.0] * 4
    # omega r t = 5 x 0.0425 x 2 = 0.425 m; a skid steer rolling straight keeps most of it.
    assert moved > 0.8 * 5.0 * 0.0425 * 2.0
    # What the old rule wrote, lateral_friction 0 on every wheel: raw PyBullet does not move.
    zero = tmp_path / "zero.urdf"
    zero.write_text(out.read_text().replace('<lateral_friction value="1"/>',
                                            '<lateral_friction value="0"/>'))
    stuck, friction0 = _roll(pb, zero)
    assert friction0 == [0.0] * 4 and abs(stuck) < 0.01
    # check says which value fix writes, and why.
    findings = json.loads(_run("check", str(ONE_WAY), "--json")[1])["findings"]
    notes = [f["message"] for f in findings if f["code"] == "U803"]
    assert len(notes) == 4 and all("fix writes the larger, 1" in m for m in notes)


BOX_ON_GAZEBO = """<robot name="box"><link name="box">
  <inertial><mass value="1"/><inertia ixx="0.01" iyy="0.01" izz="0.01" ixy="0" ixz="0" iyz="0"/>
  </inertial>
  <collision><geometry><box size="0.2 0.2 0.2"/></geometry></collision></link>
  <gazebo reference="box"><mu1>{mu}</mu1><mu2>{mu}</mu2><kp>{kp}</kp><kd>{kd}</kd></gazebo>
</robot>
"""


def _rest_height(pb, path: Path, seconds: float = 2.0) -> float:
    """Raw PyBullet: the box set on plane.urdf; its height after ``seconds``."""
    import pybullet_data

    p, c = pb
    p.resetSimulation(physicsClientId=c)
    p.setGravity(0, 0, -G, physicsClientId=c)
    p.loadURDF(str(Path(pybullet_data.getDataPath()) / "plane.urdf"), physicsClientId=c)
    body = p.loadURDF(str(path), [0, 0, 0.1], physicsClientId=c)
    for _ in range(int(240 * seconds)):
        p.stepSimulation(physicsClientId=c)
    return p.getBasePositionAndOrientation(body, physicsClientId=c)[0][2]


@pytest.mark.parametrize(("kp", "kd", "mu"), [("0", "1", "0.8"), ("-1e5", "1", "0.8"),
                                              ("1e-310", "1", "0.8"), ("1e5", "-5", "-0.8")])
def test_values_that_are_no_contact_are_refused_and_named(pb, tmp_path: Path, kp: str, kd: str,
                                                         mu: str) -> None:
    # A fuzzed or mistyped block: fix once wrote stiffness 0 and the box fell 13.7 m through
    # plane.urdf in 2 s, and check was clean afterwards.
    path = tmp_path / "box.urdf"
    path.write_text(BOX_ON_GAZEBO.format(kp=kp, kd=kd, mu=mu))
    out = tmp_path / "fixed.urdf"
    code, text = _run("fix", str(path), "--gazebo-contacts", "-o", str(out), "--json")
    assert code in (0, 1), text
    if out.exists():  # what fix wrote holds the box up, as raw PyBullet shows
        assert _rest_height(pb, out) == pytest.approx(0.1, abs=0.01)
        written = etree.parse(str(out)).getroot().find("link/contact")
        values = {c.tag: float(c.get("value")) for c in written} if written is not None else {}
        assert "stiffness" not in values or values["stiffness"] > 0
        assert all(v >= 0 for v in values.values())
    # check names what it refuses, in the file as written and on the values written by hand
    found = json.loads(_run("check", str(path), "--json")[1])["findings"]
    u803 = " ".join(f["message"] for f in found if f["code"] == "U803")
    assert "not carried" in u803 or "does not carry" in u803
    contact = (f'<contact><stiffness value="{kp}"/><damping value="{kd}"/>'
               f'<lateral_friction value="{mu}"/></contact>')
    hand = tmp_path / "hand.urdf"
    hand.write_text(BOX_ON_GAZEBO.format(kp=kp, kd=kd, mu=mu).replace(
        "<collision>", contact + "<collision>"))
    found = json.loads(_run("check", str(hand), "--json")[1])["findings"]
    u804 = [f for f in found if f["code"] == "U804"]
    assert u804 and all(f["line"] == 4 for f in u804)
    if float(kp) < 2.3e-308:  # PyBullet: the box sinks; check says so
        assert _rest_height(pb, hand) < -1.0
        assert any("sinks" in f["message"] for f in u804)
