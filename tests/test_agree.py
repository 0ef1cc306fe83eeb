"""`urdfkit agree`: passes on what export writes, and fails, naming the culprit, on copies
tampered with as users tamper (a mass off by 10%, numbers cut to 6 significant digits, a
joint renamed); the simplecar export drives forward in MuJoCo at drive's wheel speeds."""

from __future__ import annotations

import json
import math
import re
from pathlib import Path

import pytest
from lxml import etree
from typer.testing import CliRunner

from urdfkit.cli import app

mujoco = pytest.importorskip("mujoco")  # in the test extra: CI never skips it

runner = CliRunner()
#: The issue's four, and the bicycle: its base's inertial frame is turned (rpy 1.57 0 0), which
#: PyBullet's calculateInverseDynamics applies to gravity (agree hands it gravity turned back).
ROBOTS = ["r2d2.urdf", "kuka_iiwa/model.urdf", "racecar/racecar.urdf", "husky/husky.urdf",
          "bicycle/bike.urdf"]


def _export(robot: str, out: Path, *args: str) -> None:
    r = runner.invoke(app, ["export", "mjcf", robot, "-o", str(out), *args])
    assert r.exit_code == 0, r.output


def _agree(robot: str, model: Path, *args: str) -> tuple[int, dict]:
    r = runner.invoke(app, ["agree", robot, str(model), "--json", *args])
    assert r.exit_code in (0, 1), r.output
    return r.exit_code, json.loads(r.stdout)


@pytest.mark.parametrize("robot", ROBOTS)
def test_agree_passes_every_row_on_pybullet_data_robots(robot: str, tmp_path: Path) -> None:
    out = tmp_path / "robot.xml"
    _export(robot, out)
    code, data = _agree(robot, out)
    failing = [r for r in data["rows"] if r["status"] == "fail"]
    assert code == 0 and not failing, failing
    rows = {r["check"]: r for r in data["rows"]}
    # the rows are real comparisons, not vacuous: frames were compared, the swing ran
    assert "(0 frames" not in rows["frames vs PyBullet: position"]["detail"]
    assert rows["frames vs exact FK: position"]["tolerance"] == 1e-12
    assert any(k.startswith("free swing") for k in rows)
    assert data["unmatched_links"] == [] and data["unmatched_joints"] == []


@pytest.fixture(scope="module")
def kuka(tmp_path_factory: pytest.TempPathFactory) -> Path:
    out = tmp_path_factory.mktemp("kuka") / "iiwa.xml"
    _export("kuka_iiwa/model.urdf", out)
    return out


def test_a_body_mass_off_by_ten_percent_fails_naming_the_body(kuka: Path,
                                                               tmp_path: Path) -> None:
    doc = etree.parse(str(kuka))
    inertial = doc.find(".//body[@name='lbr_iiwa_link_3']/inertial")
    inertial.set("mass", repr(float(inertial.get("mass")) * 1.1))
    tampered = kuka.parent / "heavier.xml"
    doc.write(str(tampered))
    code, data = _agree("kuka_iiwa/model.urdf", tampered)
    assert code == 1
    failing = {r["check"]: r["detail"] for r in data["rows"] if r["status"] == "fail"}
    assert "lbr_iiwa_link_3" in failing["body masses"]
    # the text table names it too
    r = runner.invoke(app, ["agree", "kuka_iiwa/model.urdf", str(tampered)])
    assert r.exit_code == 1 and "lbr_iiwa_link_3" in r.stdout and "FAIL" in r.stdout


def test_six_significant_digits_fail(kuka: Path) -> None:
    """What mj_saveLastXML writes: limits move by ~5e-6 rad, frames by ~1e-7 m."""
    text = kuka.read_text()
    six = re.sub(r"-?\d+\.\d+(?:e-?\d+)?", lambda m: f"{float(m.group()):.6g}", text)
    assert six != text
    cut = kuka.parent / "six.xml"
    cut.write_text(six)
    code, data = _agree("kuka_iiwa/model.urdf", cut)
    assert code == 1
    failing = {r["check"]: r for r in data["rows"] if r["status"] == "fail"}
    assert "joint limits" in failing and failing["joint limits"]["detail"].startswith("lbr_")
    # PyBullet's float32 frames cannot see it; double-precision kinematics can
    rows = {r["check"]: r for r in data["rows"]}
    assert rows["frames vs PyBullet: position"]["status"] == "pass"


def test_reads_an_mjcf_it_did_not_write_and_lists_what_it_cannot_match(kuka: Path) -> None:
    doc = etree.parse(str(kuka))
    doc.find(".//joint[@name='lbr_iiwa_joint_7']").set("name", "wrist_roll")
    for a in doc.iterfind(".//actuator/*"):
        if a.get("joint") == "lbr_iiwa_joint_7":
            a.set("joint", "wrist_roll")
    doc.find(".//body[@name='lbr_iiwa_link_6']").set("name", "forearm")
    renamed = kuka.parent / "renamed.xml"
    doc.write(str(renamed))
    code, data = _agree("kuka_iiwa/model.urdf", renamed)
    # the two are matched by the tree's shape and frames, and said so; then all agrees
    assert code == 0
    assert {(p["urdf"], p["mjcf"], p["how"]) for p in data["matched_by"]} == {
        ("lbr_iiwa_joint_7", "wrist_roll", "structure"),
        ("lbr_iiwa_link_6", "forearm", "structure")}
    assert data["unmatched_joints"] == [] and data["extra_joints"] == []
    # a body the tree cannot place (moved off its frame) is listed, the rest compared
    doc.find(".//body[@name='forearm']").set("name", "elsewhere")
    doc.find(".//body[@name='elsewhere']").set("pos", "0 0 0.5")
    doc.find(".//joint[@name='lbr_iiwa_joint_6']").set("name", "elbow")
    for a in doc.iterfind(".//actuator/*"):
        if a.get("joint") == "lbr_iiwa_joint_6":
            a.set("joint", "elbow")
    moved = kuka.parent / "moved.xml"
    doc.write(str(moved))
    code, data = _agree("kuka_iiwa/model.urdf", moved)
    assert code == 1
    assert "lbr_iiwa_link_6" in data["unmatched_links"]
    assert data["unmatched_joints"] == ["lbr_iiwa_joint_6"]
    assert data["extra_joints"] == ["elbow"]
    rows = {r["check"]: r for r in data["rows"]}
    assert rows["frames vs PyBullet: position"]["status"] == "fail"  # link_7 hangs lower
    assert rows["free swing"]["detail"] == "not compared: the joints differ"


def test_export_verify_and_bad_model(kuka: Path, tmp_path: Path) -> None:
    r = runner.invoke(app, ["export", "mjcf", "r2d2.urdf", "-o", str(tmp_path / "r.xml"),
                            "--verify", "--json"])
    assert r.exit_code == 0, r.output
    assert json.loads(r.stdout)["agreement"]["ok"] is True
    bad = tmp_path / "bad.xml"
    bad.write_text("<mujoco><worldbody><body><geom type='sphere'/></body></worldbody>")
    r = runner.invoke(app, ["agree", "kuka_iiwa/model.urdf", str(bad)])
    assert r.exit_code == 2 and "bad.xml" in r.stderr and "Traceback" not in r.output


def test_simplecar_velocity_export_drives_forward_in_mujoco(tmp_path: Path) -> None:
    """At the wheel speeds `urdfkit drive` commands (throttle 10 rad/s, no steer)."""
    import numpy as np

    from urdfkit.engine.pybullet import PyBulletEngine
    from urdfkit.engine.session import LoadOptions, Session
    from urdfkit.model.catalog import build_template
    from urdfkit.motion.drive import DriveConfig
    from urdfkit.motion.vehicle import detect_drivetrain

    car = tmp_path / "simplecar.urdf"
    build_template("simplecar").write(car)
    throttle = DriveConfig().throttle
    with Session() as s:
        body = s.load_urdf(car, LoadOptions())
        train = detect_drivetrain(PyBulletEngine(session=s), body)
        speeds = train.wheel_speeds(throttle, 0.0)
        targets = {train.joint_names[w]: speeds[w] * train.wheel_signs.get(w, 1.0)
                   for w in train.wheels if w in speeds}
        forward = np.array([*train.forward, 0.0])
    out = tmp_path / "car.xml"
    _export(str(car), out, "--ground", "--actuators", "velocity", "--gain", "10")
    m = mujoco.MjModel.from_xml_path(str(out))
    d = mujoco.MjData(m)
    d.qpos[2] = 0.3  # drop it onto the plane, then let it settle
    for _ in range(500):
        mujoco.mj_step(m, d)
    start = d.qpos[:3].copy()
    for name, v in targets.items():
        d.ctrl[mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_ACTUATOR, name)] = v
    seconds = 2.0
    for _ in range(round(seconds / m.opt.timestep)):
        mujoco.mj_step(m, d)
    moved = d.qpos[:3] - start
    along = float(moved @ forward)
    # a wheel of radius r at w rad/s rolls r w m/s: drive's own figure for the same car
    radius = np.mean(list(train.radius.values()))
    assert len(targets) >= 2
    assert along > 0.8 * radius * throttle * seconds, moved  # measured: 2.01 m of 2.0
    assert abs(moved[1] if abs(forward[0]) > 0.5 else moved[0]) < 0.1 * along


@pytest.mark.parametrize("flag", ["--self-collision", "--inertia-from-shapes", "--fixed-base"])
def test_each_mirrored_load_agrees_with_its_pybullet_load(flag: str, tmp_path: Path) -> None:
    out = tmp_path / "r2d2.xml"
    _export("r2d2.urdf", out, flag)
    code, data = _agree("r2d2.urdf", out, flag, "--poses", "20")
    assert code == 0, [r for r in data["rows"] if r["status"] == "fail"]
    flags = data["load_flags"]
    assert ("URDF_USE_SELF_COLLISION" in flags) == (flag == "--self-collision")
    assert ("URDF_USE_INERTIA_FROM_FILE" in flags) == (flag != "--inertia-from-shapes")
    rows = {r["check"]: r for r in data["rows"]}
    if flag == "--self-collision":  # r2d2's parts touch: counted, not failed
        assert rows["self-contacts at the poses"]["status"] == "info"
        assert rows["self-contacts at the poses"]["value"] > 0
    if flag == "--fixed-base":
        assert rows["base"]["detail"] == "PyBullet: welded; MJCF: welded"


ID_ASYMMETRIC = Path(__file__).parent / "fixtures" / "robots" / "id_asymmetric.urdf"


def test_a_model_pybullet_cannot_take_the_mass_matrix_of_is_compared_on_the_rest(
        pb, tmp_path: Path) -> None:
    """KUKA KR210's link_2 inertia: raw calculateMassMatrix raises; agree said exit 3."""
    import subprocess
    import sys

    from urdfkit.engine.session import quiet_stdout

    p, c = pb
    with quiet_stdout():
        body = p.loadURDF(str(ID_ASYMMETRIC), useFixedBase=True,
                          flags=p.URDF_USE_INERTIA_FROM_FILE, physicsClientId=c)
        with pytest.raises(SystemError):
            p.calculateMassMatrix(body, [0.0], physicsClientId=c)
    out = tmp_path / "robot.xml"
    _export(str(ID_ASYMMETRIC), out, "--fixed-base")
    proc = subprocess.run([sys.executable, "-m", "urdfkit", "agree", str(ID_ASYMMETRIC),
                           str(out), "--fixed-base", "--json"],
                          capture_output=True, text=True, timeout=120)
    assert proc.returncode == 0, proc.stderr
    data = json.loads(proc.stdout)  # PyBullet's "invalid inertia tensor" is not on stdout
    rows = {r["check"]: r for r in data["rows"]}
    dyn = rows["mass matrix, inverse dynamics"]
    assert dyn["status"] == "known" and "calculateMassMatrix" in dyn["detail"]
    # the other rows still compare: the frames, and the swing
    assert rows["frames vs PyBullet: position"]["status"] == "pass"
    assert any(k.startswith("free swing") and r["status"] == "pass" for k, r in rows.items())


STIFF_DAMPING = Path(__file__).parent / "fixtures" / "robots" / "stiff_damping.urdf"


def test_a_swing_joint_damping_makes_unstable_is_said_so_not_failed(free_swing,
                                                                     tmp_path: Path) -> None:
    """The Shadow hand: its swing "failed" by 1.4 rad in 3 ms, as if the export were wrong.
    Raw PyBullet steps joint damping explicitly: at dt x damping / inertia = 20 the finger's
    speed flips sign every step and runs to PyBullet's 100 rad/s cap (MuJoCo, uncapped, runs
    on). agree now says the swing cannot be compared, and why; below 2 it still compares."""
    _, speeds = free_swing(STIFF_DAMPING, 0.001)
    assert all(a * b < 0 for a, b in zip(speeds[1:], speeds[2:], strict=False)), speeds
    assert max(map(abs, speeds)) == pytest.approx(100.0)  # gravity alone: ~0.4 rad/s

    out = tmp_path / "robot.xml"
    _export(str(STIFF_DAMPING), out, "--fixed-base")
    code, data = _agree(str(STIFF_DAMPING), out, "--fixed-base")
    rows = {r["check"]: r for r in data["rows"]}
    swing = next(r for k, r in rows.items() if k.startswith("free swing"))
    assert code == 0 and swing["status"] == "known", swing
    assert "unstable" in swing["detail"] and "finger_joint" in swing["detail"]
    assert "reaches 20 " in swing["detail"]
    assert rows["mass matrix"]["status"] == "pass"

    # a twentieth of the damping: 1 per step, stable, and the swing is compared
    calm = tmp_path / "calm.urdf"
    calm.write_text(STIFF_DAMPING.read_text().replace('damping="0.1"', 'damping="0.005"'))
    _export(str(calm), out, "--fixed-base", "--force")
    code, data = _agree(str(calm), out, "--fixed-base")
    swing = next(r for r in data["rows"] if r["check"].startswith("free swing"))
    assert code == 0 and swing["status"] == "pass" and swing["check"].startswith(
        "free swing 1 s"), swing


SHORT_FINGER = Path(__file__).parent / "fixtures" / "robots" / "short_finger.urdf"


def test_a_short_finger_does_not_stop_the_swing_at_its_first_step(tmp_path: Path) -> None:
    """youBot's arm: its 11.5 mm finger always started within agree's 0.01 "rad" of a limit,
    so the swing stopped after one step and passed having compared nothing. The margin is now
    an eighth of a short range: the pendulum swings, both engines alike, until the arm itself
    nears its limit."""
    out = tmp_path / "robot.xml"
    _export(str(SHORT_FINGER), out, "--fixed-base")
    code, data = _agree(str(SHORT_FINGER), out, "--fixed-base")
    swing = next(r for r in data["rows"] if r["check"].startswith("free swing"))
    assert code == 0 and swing["status"] == "pass", swing
    seconds = float(re.match(r"free swing ([0-9.e-]+) s", swing["check"]).group(1))
    assert seconds >= 0.2 and "finger_joint within" not in swing["detail"], swing
    # the pendulum moved: the comparison is not of two bodies at rest
    assert swing["detail"].startswith("shoulder"), swing


FLOAT32_QUATERNIONS = Path(__file__).parent / "fixtures" / "robots" / "float32_quaternions.urdf"


def test_pybullets_float32_quaternions_are_read_as_pybullet_reads_them(pb,
                                                                       tmp_path: Path) -> None:
    """youBot's base: agree failed its frames' rotation row (1.4e-6 against 1.2e-6) on an
    export that matches exact kinematics to 1e-15. Raw getLinkState hands quaternions off unit
    length (turned inertial frames, float32); read with the unit formula that adds 2x the
    excess to the matrix. Read as PyBullet's getMatrixFromQuaternion reads them, it passes."""
    import numpy as np

    from urdfkit.engine.session import quiet_stdout

    p, c = pb
    with quiet_stdout():
        body = p.loadURDF(str(FLOAT32_QUATERNIONS), flags=p.URDF_USE_INERTIA_FROM_FILE,
                          physicsClientId=c)
    rng = np.random.default_rng(0)
    worst = 0.0
    for _ in range(200):
        for j in range(p.getNumJoints(body, physicsClientId=c)):
            p.resetJointState(body, j, float(rng.uniform(-np.pi, np.pi)), physicsClientId=c)
        for j in range(p.getNumJoints(body, physicsClientId=c)):
            orn = p.getLinkState(body, j, computeForwardKinematics=True,
                                 physicsClientId=c)[5]
            worst = max(worst, abs(float(np.linalg.norm(orn)) - 1.0))
    assert worst > 1e-7  # raw PyBullet's quaternions are not unit length here

    out = tmp_path / "robot.xml"
    _export(str(FLOAT32_QUATERNIONS), out)
    code, data = _agree(str(FLOAT32_QUATERNIONS), out)
    rows = {r["check"]: r for r in data["rows"]}
    assert code == 0, [r for r in data["rows"] if r["status"] == "fail"]
    rotation = rows["frames vs PyBullet: rotation"]
    assert rotation["status"] == "pass" and rotation["value"] < 1e-6, rotation


NEAR_BODY_SITE = Path(__file__).parent / "fixtures" / "robots" / "near_body_site.urdf"


def test_a_site_mujoco_puts_on_its_body_is_said_so_not_failed(tmp_path: Path) -> None:
    """HSR's head camera frame sits 5.1e-12 rad from its body; agree failed "frames vs exact
    FK: rotation" (7.2e-12 against 1e-12) on an export exact to 3e-17. MuJoCo's compiler, not
    the export, drops the offset: it computes a site within ~1e-6 of its body's frame at that
    frame. The export still writes the file's rotation, MuJoCo still drops it (both checked
    here with MuJoCo itself), and agree now compares such a site where MuJoCo puts it and says
    so in a known row."""
    import mujoco
    import numpy as np

    out = tmp_path / "robot.xml"
    _export(str(NEAR_BODY_SITE), out, "--fixed-base")
    m = mujoco.MjModel.from_xml_path(str(out))
    d = mujoco.MjData(m)
    mujoco.mj_kinematics(m, d)
    i = mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_SITE, "camera_frame")
    w, x, _, _ = m.site_quat[i]
    assert 2 * np.arctan2(abs(x), w) == pytest.approx(1e-7, rel=1e-6)  # written as the file says
    body = int(m.site_bodyid[i])
    assert np.array_equal(d.site_xmat[i], d.xmat[body])  # MuJoCo computes it at its body
    code, data = _agree(str(NEAR_BODY_SITE), out, "--fixed-base")
    rows = {r["check"]: r for r in data["rows"]}
    assert code == 0, [r for r in data["rows"] if r["status"] == "fail"]
    assert rows["frames vs exact FK: rotation"]["value"] < 1e-12
    snapped = rows["sites MuJoCo puts on their body"]
    # the optical frame, 1e-7 about x then -1e-7 about z: sqrt(2) 1e-7 from its body, the worst
    assert snapped["status"] == "known"
    assert snapped["value"] == pytest.approx(math.sqrt(2) * 1e-7, rel=1e-6)
    assert snapped["detail"].startswith("optical_frame and 1 more"), snapped
