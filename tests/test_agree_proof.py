"""`urdfkit agree` cannot be fooled: exports tampered so that MuJoCo behaves differently fail,
naming the body; honest models whose names, keyframes, locked joints or axes differ from the
export's are read truthfully, each row saying what it compared (issue 48)."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest
from lxml import etree
from test_agree import _agree, _export
from typer.testing import CliRunner

from urdfkit.cli import app

mujoco = pytest.importorskip("mujoco")  # in the test extra: CI never skips it
pybullet = pytest.importorskip("pybullet")

runner = CliRunner()


def _rows(data: dict) -> dict[str, dict]:
    return {r["check"]: r for r in data["rows"]}


def _failing(data: dict) -> dict[str, str]:
    return {r["check"]: r["detail"] for r in data["rows"] if r["status"] == "fail"}


def _tamper(src: Path, name: str, edit) -> Path:
    doc = etree.parse(str(src))
    edit(doc)
    out = src.parent / name
    doc.write(str(out))
    return out


@pytest.fixture(scope="module")
def exports(tmp_path_factory: pytest.TempPathFactory) -> dict[str, Path]:
    out = {}
    for robot in ("racecar/racecar.urdf", "r2d2.urdf"):
        path = tmp_path_factory.mktemp("export") / "robot.xml"
        _export(robot, path)
        out[robot] = path
    return out


ROBOTS = ["racecar/racecar.urdf", "r2d2.urdf"]


def _detach(doc: etree._ElementTree) -> list[str]:
    """Every child body of the free root moved under the world, where it was."""
    world = doc.find("worldbody")
    root = world.find("body")
    moved = []
    for b in root.findall("body"):
        root.remove(b)
        world.append(b)
        moved.append(b.get("name"))
    return moved


@pytest.mark.parametrize("robot", ROBOTS)
def test_children_welded_to_the_world_fail_naming_the_body(robot: str,
                                                           exports: dict[str, Path]) -> None:
    moved: list[str] = []
    tampered = _tamper(exports[robot], "detached.xml", lambda d: moved.extend(_detach(d)))
    # MuJoCo itself behaves differently: its free chassis falls, a detached body stays put
    m = mujoco.MjModel.from_xml_path(str(tampered))
    d = mujoco.MjData(m)
    body = mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_BODY, moved[0])
    root = mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_BODY, m.body(1).name)
    start = (d.xpos[root].copy(), d.xpos[body].copy())
    mujoco.mj_forward(m, d)
    start = (d.xpos[root].copy(), d.xpos[body].copy())
    m.opt.disableflags |= mujoco.mjtDisableBit.mjDSBL_CONTACT
    for _ in range(500):
        mujoco.mj_step(m, d)
    assert start[0][2] - d.xpos[root][2] > 1.0 and abs(d.xpos[body][2] - start[1][2]) < 1e-6
    code, data = _agree(robot, tampered)
    assert code == 1
    failing = _failing(data)
    assert any(name in failing["body tree"] for name in moved), failing
    assert "world" in failing["body tree"]


@pytest.mark.parametrize("robot", ROBOTS)
def test_collision_geoms_deleted_fail_naming_the_link(robot: str,
                                                      exports: dict[str, Path]) -> None:
    def strip(doc: etree._ElementTree) -> None:
        for g in doc.iterfind(".//geom[@group='3']"):
            g.getparent().remove(g)

    code, data = _agree(robot, _tamper(exports[robot], "nogeoms.xml", strip))
    assert code == 1
    detail = _failing(data)["collision shapes"]
    links = {b.get("name") for b in etree.parse(str(exports[robot])).iter("body", "site")}
    assert detail.startswith("missing in the MJCF: ") and detail[21:].split(" (")[0] in links


@pytest.mark.parametrize("robot", ROBOTS)
def test_friction_zeroed_fails_naming_the_link(robot: str, exports: dict[str, Path]) -> None:
    def zero(doc: etree._ElementTree) -> None:
        for g in doc.iterfind(".//geom[@group='3']"):
            g.set("friction", "0 0 0")

    code, data = _agree(robot, _tamper(exports[robot], "nofriction.xml", zero))
    assert code == 1
    detail = _failing(data)["contact parameters"]
    # PyBullet's default lateral friction, read from PyBullet, is named beside MuJoCo's 0
    links = {b.get("name") for b in etree.parse(str(exports[robot])).iter("body", "site")}
    assert "friction 0, PyBullet's lateral 0.5" in detail and detail.split(" (")[0] in links


@pytest.mark.parametrize("robot", ROBOTS)
def test_collision_sizes_times_ten_fail(robot: str, exports: dict[str, Path]) -> None:
    def grow(doc: etree._ElementTree) -> None:
        for g in doc.iterfind(".//geom[@group='3']"):
            if g.get("size"):
                g.set("size", " ".join(repr(float(x) * 10) for x in g.get("size").split()))
        for mesh in doc.iterfind(".//asset/mesh"):
            mesh.set("scale", "10 10 10")

    code, data = _agree(robot, _tamper(exports[robot], "big.xml", grow))
    assert code == 1
    failing = _failing(data)
    assert "collision shapes" in failing
    assert failing["collision shapes"].split(" (")[0] in \
        {b.get("name") for b in etree.parse(str(exports[robot])).iter("body", "site")}


def test_priority_and_ground_bits_are_contact_parameters(exports: dict[str, Path]) -> None:
    def edit(doc: etree._ElementTree) -> None:
        for g in doc.iterfind(".//geom[@group='3']"):
            g.set("priority", "0")
            g.set("contype", "2")
            g.set("conaffinity", "2")

    code, data = _agree("racecar/racecar.urdf",
                        _tamper(exports["racecar/racecar.urdf"], "bits.xml", edit))
    assert code == 1
    detail = _failing(data)["contact parameters"]
    assert "falls through a ground" in detail and "priority 0" in detail


@pytest.mark.parametrize("robot", ["racecar/racecar.urdf", "r2d2.urdf", "husky/husky.urdf",
                                   "bicycle/bike.urdf"])
def test_a_free_base_gets_a_floating_swing(robot: str, tmp_path: Path) -> None:
    out = tmp_path / "robot.xml"
    _export(robot, out)
    code, data = _agree(robot, out)
    rows = _rows(data)
    assert code == 0, _failing(data)
    floating = [k for k in rows if k.startswith("floating swing")]
    assert len(floating) == 2, rows.keys()
    base = rows["floating swing: base frame"]
    assert base["status"] == "pass" and base["value"] < 1e-9


def test_a_heavier_wheel_moves_the_floating_base_otherwise(exports: dict[str, Path]) -> None:
    """The floating rows see what the base-fixed swing cannot: the base's reaction."""
    def heavier(doc: etree._ElementTree) -> None:
        el = doc.find(".//body[@name='base_link']/inertial")
        el.set("mass", repr(float(el.get("mass")) * 1.5))

    code, data = _agree("racecar/racecar.urdf",
                        _tamper(exports["racecar/racecar.urdf"], "heavy.xml", heavier))
    failing = _failing(data)
    assert code == 1 and "floating swing: base frame" in failing
    assert "base_link" in failing["floating swing: base frame"]


# ---------------------------------------------------------------- honest models, read truly

def test_a_keyframe_with_a_free_joint_loads(tmp_path: Path) -> None:
    out = tmp_path / "a1.xml"
    _export("a1/a1.urdf", out)
    doc = etree.parse(str(out))
    m = mujoco.MjModel.from_xml_path(str(out))
    key = etree.SubElement(doc.getroot(), "keyframe")
    qpos = [0.0, 0.0, 0.4, 1.0, 0.0, 0.0, 0.0] + [0.1] * (m.nq - 7)
    etree.SubElement(key, "key", name="home", qpos=" ".join(map(repr, qpos)))
    keyed = tmp_path / "keyed.xml"
    doc.write(str(keyed))
    assert mujoco.MjModel.from_xml_path(str(keyed)).nkey == 1  # MuJoCo loads it
    code, data = _agree("a1/a1.urdf", keyed)
    assert code == 0, _failing(data)


def _renamed(src: Path, name: str, rename) -> Path:
    def edit(doc: etree._ElementTree) -> None:
        for el in doc.iter("joint", "body", "site"):
            if el.get("name"):
                el.set("name", rename(el.get("name")))
        for a in doc.iterfind(".//actuator/*"):
            a.set("joint", rename(a.get("joint")))
            a.set("name", rename(a.get("name")))

    return _tamper(src, name, edit)


@pytest.fixture(scope="module")
def kuka(tmp_path_factory: pytest.TempPathFactory) -> Path:
    out = tmp_path_factory.mktemp("kuka") / "iiwa.xml"
    _export("kuka_iiwa/model.urdf", out)
    return out


def test_names_that_share_nothing_match_by_the_tree(kuka: Path) -> None:
    """Menagerie's panda (`joint1`, `link1`) against `panda_joint1`, `panda_link1`."""
    plain = _renamed(kuka, "plain.xml", lambda n: n.replace("lbr_iiwa_joint_", "joint")
                     .replace("lbr_iiwa_link_", "link"))
    code, data = _agree("kuka_iiwa/model.urdf", plain)
    assert code == 0, _failing(data)
    pairs = {p["urdf"]: (p["mjcf"], p["how"]) for p in data["matched_by"]}
    assert pairs["lbr_iiwa_joint_4"] == ("joint4", "structure")
    assert pairs["lbr_iiwa_link_7"] == ("link7", "structure")
    assert data["unmatched_joints"] == [] and data["extra_joints"] == []
    rows = _rows(data)
    assert rows["joint order"]["detail"] == "7 joints"
    assert rows["frames vs exact FK: position"]["value"] < 1e-12


def test_a_limit_difference_is_found_where_names_differ(kuka: Path) -> None:
    """h1 drops the URDF's `_joint` suffixes; a real limit difference must still show."""
    def edit(doc: etree._ElementTree) -> None:
        for el in doc.iter("joint"):
            if el.get("name"):
                el.set("name", el.get("name").replace("_joint_", "_"))
        for a in doc.iterfind(".//actuator/*"):
            a.set("joint", a.get("joint").replace("_joint_", "_"))
        j = doc.find(".//joint[@name='lbr_iiwa_3']")
        lo, hi = map(float, j.get("range").split())
        j.set("range", f"{lo!r} {hi - 1.57!r}")

    code, data = _agree("kuka_iiwa/model.urdf", _tamper(kuka, "h1like.xml", edit))
    assert code == 1
    failing = _failing(data)
    assert list(failing) == ["joint limits"] and failing["joint limits"] == "lbr_iiwa_joint_3"
    assert {p["how"] for p in data["matched_by"]} == {"structure"}
    assert len(data["matched_by"]) == 7  # the joints only: the bodies kept their names


def test_map_pairs_names_by_hand_and_refuses_unknown_ones(kuka: Path, tmp_path: Path) -> None:
    def flip(doc: etree._ElementTree) -> None:
        # a renamed joint about the opposite axis: the tree's shape cannot match it
        j = doc.find(".//joint[@name='lbr_iiwa_joint_2']")
        j.set("name", "shoulder")
        j.set("axis", " ".join(repr(-float(x)) for x in j.get("axis").split()))
        lo, hi = map(float, j.get("range").split())
        j.set("range", f"{-hi!r} {-lo!r}")
        for a in doc.iterfind(".//actuator/*"):
            if a.get("joint") == "lbr_iiwa_joint_2":
                a.set("joint", "shoulder")

    flipped = _tamper(kuka, "flipped.xml", flip)
    code, data = _agree("kuka_iiwa/model.urdf", flipped)
    assert code == 1 and data["unmatched_joints"] == ["lbr_iiwa_joint_2"]
    rows = _rows(data)
    assert rows["swing"]["detail"] == "not compared: the joints differ" if "swing" in rows \
        else rows["free swing"]["detail"] == "not compared: the joints differ"
    code, data = _agree("kuka_iiwa/model.urdf", flipped, "--map", "lbr_iiwa_joint_2=shoulder")
    assert data["matched_by"][0] == {"urdf": "lbr_iiwa_joint_2", "mjcf": "shoulder",
                                     "how": "map"}
    # matched, the flipped joint is compared: the frames it moves are elsewhere
    assert code == 1 and "frames vs exact FK: position" in _failing(data)
    assert _rows(data)["joint limits"]["status"] == "pass"  # the range was flipped too
    r = runner.invoke(app, ["agree", "kuka_iiwa/model.urdf", str(flipped), "--map",
                            "lbr_iiwa_joint_2=elbow"])
    assert r.exit_code == 2 and "elbow" in r.stderr and len(r.stderr.strip().splitlines()) == 1


PENDULUM = """<robot name="p">
 <link name="base"/>
 {links}
 {joints}
</robot>"""
LINK = ('<link name="l{i}"><inertial><origin xyz="0 0 -0.25"/><mass value="1"/>'
        '<inertia ixx="0.02" iyy="0.02" izz="0.001" ixy="0" ixz="0" iyz="0"/></inertial>'
        '<collision><origin xyz="0 0 -0.25"/><geometry><box size="0.05 0.05 0.5"/></geometry>'
        '</collision>{dynamics}</link>')
JOINT = ('<joint name="j{i}" type="revolute"><parent link="{parent}"/><child link="l{i}"/>'
         '<origin xyz="0 0 {z}"/><axis xyz="{axis}"/>'
         '<limit lower="{lo}" upper="{hi}" effort="1" velocity="1"/>{dynamics}</joint>')


def _pendulum(tmp_path: Path, name: str, limits=((-3, 3),) * 3, axes=("1 0 0",) * 3,
              friction: float = 0.0) -> Path:
    links = "\n ".join(LINK.format(i=i, dynamics="") for i in range(3))
    dyn = f'<dynamics friction="{friction!r}"/>' if friction else ""
    joints = "\n ".join(JOINT.format(i=i, parent="base" if i == 0 else f"l{i - 1}",
                                     z=0 if i == 0 else -0.5, axis=axes[i], lo=limits[i][0],
                                     hi=limits[i][1], dynamics=dyn) for i in range(3))
    path = tmp_path / name
    path.write_text(PENDULUM.format(links=links, joints=joints))
    return path


def test_a_locked_joint_swings_as_pybullet_holds_it(tmp_path: Path) -> None:
    """lower == upper: PyBullet holds the joint at 0.3 exactly (checked here), the export
    with an equality, which the swing turns off: agree welds it for the swing instead."""
    urdf = _pendulum(tmp_path, "locked.urdf", limits=((-3, 3), (0.3, 0.3), (-3, 3)))
    p = pybullet
    c = p.connect(p.DIRECT)
    try:
        body = p.loadURDF(str(urdf), useFixedBase=True, physicsClientId=c)
        p.setGravity(0, 0, -9.81, physicsClientId=c)
        p.resetJointState(body, 1, 0.3, physicsClientId=c)
        p.resetJointState(body, 0, 0.5, physicsClientId=c)
        p.setJointMotorControlArray(body, [0, 1, 2], p.VELOCITY_CONTROL, forces=[0] * 3,
                                    physicsClientId=c)
        for _ in range(200):
            p.stepSimulation(physicsClientId=c)
        assert p.getJointState(body, 1, physicsClientId=c)[0] == 0.3
    finally:
        p.disconnect(c)
    out = tmp_path / "locked.xml"
    _export(str(urdf), out)
    code, data = _agree(str(urdf), out)
    assert code == 0, _failing(data)
    swing = next(r for r in data["rows"] if r["check"].startswith("free swing"))
    assert swing["value"] < 1e-9 and "locked joints welded" in swing["detail"]
    assert swing["check"].startswith("free swing 1 s") or "stopped" in swing["detail"]


def test_an_axis_off_unit_length_is_said(tmp_path: Path) -> None:
    """PyBullet steps a joint about its axis as written (1.5e-6 long) while its own mass
    matrix normalises it: measured here in raw PyBullet, and said by the swing row."""
    urdf = _pendulum(tmp_path, "skew.urdf", axes=("1 0 0", "1 0 0", "1.0000015 0 0"))
    unit = _pendulum(tmp_path, "unit.urdf")
    p = pybullet
    c = p.connect(p.DIRECT)
    try:
        p.setGravity(0, 0, -9.81, physicsClientId=c)
        bodies = [p.loadURDF(str(f), useFixedBase=True, physicsClientId=c,
                             flags=p.URDF_USE_INERTIA_FROM_FILE) for f in (urdf, unit)]
        for b in bodies:
            p.setJointMotorControlArray(b, [0, 1, 2], p.VELOCITY_CONTROL, forces=[0] * 3,
                                        physicsClientId=c)
            for i, q in enumerate((0.5, 0.3, -0.4)):
                p.resetJointState(b, i, q, physicsClientId=c)
        for _ in range(500):
            p.stepSimulation(physicsClientId=c)
        apart = max(abs(p.getJointState(bodies[0], i, physicsClientId=c)[0]
                        - p.getJointState(bodies[1], i, physicsClientId=c)[0]) for i in range(3))
        assert apart > 1e-8
        m = [np.array(p.calculateMassMatrix(b, [0.5, 0.3, -0.4], physicsClientId=c))
             for b in bodies]
        assert np.abs(m[0] - m[1]).max() == 0.0
    finally:
        p.disconnect(c)
    out = tmp_path / "skew.xml"
    _export(str(urdf), out)
    code, data = _agree(str(urdf), out)
    swing = next(r for r in data["rows"] if r["check"].startswith("free swing"))
    assert swing["status"] == "known" and "off unit length" in swing["detail"]
    assert "j2" in swing["detail"] and code == 0


def test_armature_and_frictionloss_rows(kuka: Path, tmp_path: Path) -> None:
    def rotor(doc: etree._ElementTree) -> None:
        doc.find(".//joint[@name='lbr_iiwa_joint_4']").set("armature", "0.01")
        doc.find(".//joint[@name='lbr_iiwa_joint_5']").set("frictionloss", "0.2")

    code, data = _agree("kuka_iiwa/model.urdf", _tamper(kuka, "rotor.xml", rotor))
    failing = _failing(data)
    assert code == 1
    assert failing["joint armature"].startswith("lbr_iiwa_joint_4")
    assert failing["joint frictionloss"].startswith("lbr_iiwa_joint_5")
    # the URDF's own <dynamics friction>, written as frictionloss: a known difference
    urdf = _pendulum(tmp_path, "friction.urdf", friction=0.25)
    out = tmp_path / "friction.xml"
    _export(str(urdf), out)

    def loss(doc: etree._ElementTree) -> None:
        for j in doc.iter("joint"):
            j.set("frictionloss", "0.25")

    code, data = _agree(str(urdf), _tamper(out, "loss.xml", loss))
    rows = _rows(data)
    assert rows["joint friction of the URDF"]["status"] == "known"
    assert rows["joint frictionloss"]["status"] == "pass"


def test_a_mass_difference_names_pybullets_default_mass(tmp_path: Path) -> None:
    urdf = tmp_path / "default.urdf"
    urdf.write_text(PENDULUM.format(links=(
        '<link name="l0"><inertial><mass value="2"/><inertia ixx="0.1" iyy="0.1" izz="0.1" '
        'ixy="0" ixz="0" iyz="0"/></inertial></link><link name="l1"/>'),
        joints=JOINT.format(i=0, parent="base", z=0, axis="1 0 0", lo=-1, hi=1, dynamics="")
        + '<joint name="f" type="fixed"><parent link="l0"/><child link="l1"/></joint>'))
    out = tmp_path / "default.xml"
    _export(str(urdf), out)
    doc = etree.parse(str(out))
    el = doc.find(".//body[@name='l0']/inertial")
    assert float(el.get("mass")) == 3.0  # PyBullet's 1 kg for l1, fused in
    el.set("mass", "2")
    doc.write(str(out))
    code, data = _agree(str(urdf), out)
    assert code == 1
    detail = _failing(data)["body masses"]
    assert detail.startswith("l0") and "l1" in detail and "default 1 kg" in detail


def test_a_ground_on_the_world_is_not_the_robot(tmp_path: Path) -> None:
    """pendulum5's root is `world`: its shapes are compared on MuJoCo's world body, where
    `--ground` also puts a plane, which is the scene, not an extra collision shape."""
    out = tmp_path / "p5.xml"
    _export("pendulum5.urdf", out, "--ground")
    code, data = _agree("pendulum5.urdf", out)
    assert code == 0, _failing(data)
    assert _rows(data)["collision shapes"]["value"] < 1e-9


def test_a_second_free_body_is_extra(exports: dict[str, Path]) -> None:
    def box(doc: etree._ElementTree) -> None:
        b = etree.SubElement(doc.find("worldbody"), "body", pos="3 0 1")
        etree.SubElement(b, "freejoint")
        etree.SubElement(b, "geom", type="ellipsoid", size="0.1 0.2 0.3", mass="25")

    code, data = _agree("r2d2.urdf", _tamper(exports["r2d2.urdf"], "second.xml", box))
    failing = _failing(data)
    assert code == 1 and failing["bodies"].startswith("+body ")
    assert "extra in the MJCF" in failing["collision shapes"] and "total mass" in failing
    assert "body masses" not in failing  # the robot's own bodies still weigh the same


def test_a_zero_size_shape_is_a_known_difference(tmp_path: Path) -> None:
    urdf = tmp_path / "zero.urdf"
    urdf.write_text(PENDULUM.format(links=LINK.format(i=0, dynamics="").replace(
        "</collision>", '</collision><collision><geometry><sphere radius="0"/></geometry>'
        "</collision>"), joints=JOINT.format(i=0, parent="base", z=0, axis="1 0 0", lo=-1,
                                            hi=1, dynamics="")))
    p = pybullet
    c = p.connect(p.DIRECT)
    try:  # PyBullet loads the sphere of radius 0 as a shape of its own
        body = p.loadURDF(str(urdf), physicsClientId=c)
        kinds = [s[2] for s in p.getCollisionShapeData(body, 0, physicsClientId=c)]
        assert kinds.count(p.GEOM_SPHERE) == 1
    finally:
        p.disconnect(c)
    out = tmp_path / "zero.xml"
    _export(str(urdf), out)
    mujoco.MjModel.from_xml_path(str(out))
    code, data = _agree(str(urdf), out)
    assert code == 0, _failing(data)
    row = _rows(data)["shapes MuJoCo cannot hold"]
    assert row["status"] == "known" and row["detail"].startswith("l0: a zero-size shape")


def test_an_inertial_frame_mujoco_snaps_to_its_body_is_said(tmp_path: Path) -> None:
    """A product of inertia of 3.6e-13 on moments of ~1e-5 (toddlerbot's sho_yaw_link) turns
    the principal axes by ~1e-7 rad: MuJoCo's compiler takes that frame as the body's
    (body_sameframe) and simulates the tensor without the product."""
    link = ('<link name="l0"><inertial><origin xyz="0 0 -0.02"/><mass value="0.0145"/>'
            '<inertia ixx="9.2365904614004e-06" iyy="5.8163826335079e-06" '
            'izz="4.5074356741562e-06" ixy="3.5862833440690e-13" ixz="0" iyz="0"/>'
            '</inertial></link>')
    urdf = tmp_path / "snap.urdf"
    urdf.write_text(PENDULUM.format(links=link, joints=JOINT.format(
        i=0, parent="base", z=0, axis="0 0 1", lo=-1, hi=1, dynamics="")))
    out = tmp_path / "snap.xml"
    _export(str(urdf), out)
    m = mujoco.MjModel.from_xml_path(str(out))
    b = mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_BODY, "l0")
    assert m.body_sameframe[b] != 0 and abs(m.body_iquat[b][3]) > 1e-9
    code, data = _agree(str(urdf), out)
    assert code == 0, _failing(data)
    row = _rows(data)["inertial frames MuJoCo puts on their body"]
    assert row["status"] == "known" and row["detail"].startswith("l0") and row["value"] > 1e-9


@pytest.mark.parametrize("fixed", [False, True])
def test_a_tensor_pybullet_zeroes_exports_and_is_a_known_difference(tmp_path: Path,
                                                                     fixed: bool) -> None:
    """xarm6's link2 and link3 break the triangle inequality: PyBullet zeroes them (read here
    from raw PyBullet), export writes fix's tensor (MuJoCo refuses a moving body without
    one), and agree says which rows it cannot compare, comparing the rest."""
    p = pybullet
    c = p.connect(p.DIRECT)
    try:
        import pybullet_data

        body = p.loadURDF(f"{pybullet_data.getDataPath()}/xarm/xarm6_robot.urdf",
                          flags=p.URDF_USE_INERTIA_FROM_FILE, physicsClientId=c)
        zeroed = [p.getJointInfo(body, i, physicsClientId=c)[12].decode()
                  for i in range(p.getNumJoints(body, physicsClientId=c))
                  if p.getDynamicsInfo(body, i, physicsClientId=c)[2] == (0.0, 0.0, 0.0)
                  and p.getDynamicsInfo(body, i, physicsClientId=c)[0] > 0]
    finally:
        p.disconnect(c)
    assert zeroed == ["link2", "link3"]
    out = tmp_path / "xarm.xml"
    flag = ["--fixed-base"] if fixed else []
    r = runner.invoke(app, ["export", "mjcf", "xarm/xarm6_robot.urdf", "-o", str(out),
                            "--json", *flag])
    assert r.exit_code == 0, r.output
    assert sorted(json.loads(r.stdout)["repaired"]) == zeroed
    mujoco.MjModel.from_xml_path(str(out))
    code, data = _agree("xarm/xarm6_robot.urdf", out, *flag)
    assert code == 0, _failing(data)
    rows = _rows(data)
    assert rows["inertia MuJoCo cannot take"]["status"] == "known"
    assert rows["inertia MuJoCo cannot take"]["detail"].startswith("link2, link3")
    assert rows["mass matrix, inverse dynamics"]["status"] == "known"
    assert rows["body masses"]["status"] == "pass" and rows["centres of mass"]["status"] == "pass"
    # a mass tampered on a repaired body still fails
    doc = etree.parse(str(out))
    el = doc.find(".//body[@name='link2']/inertial")
    el.set("mass", repr(float(el.get("mass")) * 1.1))
    doc.write(str(out))
    code, data = _agree("xarm/xarm6_robot.urdf", out, *flag)
    assert code == 1 and _failing(data)["body masses"].startswith("link2")


@pytest.mark.parametrize(("edit", "said"), [
    (lambda doc: doc.find(".//joint[@name='lbr_iiwa_joint_3']").set("stiffness", "5"),
     "joint lbr_iiwa_joint_3 stiffness 5"),
    (lambda doc: doc.find(".//body[@name='lbr_iiwa_link_4']").set("gravcomp", "1"),
     "body lbr_iiwa_link_4 gravcomp 1"),
    (lambda doc: etree.SubElement(doc.getroot(), "option", gravity="0 0 0"), "gravity 0 0 0"),
    (lambda doc: etree.SubElement(doc.getroot(), "option", density="1.2", viscosity="1e-5"),
     "density 1.2; viscosity 1e-05"),
])
def test_forces_only_mujoco_applies_fail(kuka: Path, edit, said: str) -> None:
    code, data = _agree("kuka_iiwa/model.urdf", _tamper(kuka, "forces.xml", edit))
    assert code == 1
    assert _failing(data)["forces MuJoCo alone applies"].startswith(said)


STRAY_CUBE = "".join(f"v {x} {y} {z}\n" for z in (-0.5, 0.5) for y, x in (
    (-0.5, -0.5), (-0.5, 0.5), (0.5, 0.5), (0.5, -0.5))) + "v 5 5 5\n" + "".join(
    f"f {a} {b} {c}\n" for a, b, c in ((1, 3, 2), (1, 4, 3), (5, 6, 7), (5, 7, 8), (1, 2, 6),
                                       (1, 6, 5), (2, 3, 7), (2, 7, 6), (3, 4, 8), (3, 8, 7),
                                       (4, 1, 5), (4, 5, 8)))


def test_a_vertex_no_triangle_uses_is_left_out_and_caught(tmp_path: Path) -> None:
    """PyBullet's hull of an OBJ leaves out a vertex no face uses (its box, read from raw
    PyBullet, is the cube's); MuJoCo's takes it. export writes the used vertices only, and
    agree fails the file that keeps the stray vertex."""
    (tmp_path / "c.obj").write_text(STRAY_CUBE)
    urdf = tmp_path / "r.urdf"
    urdf.write_text('<robot name="r"><link name="a"><inertial><mass value="1"/><inertia '
                    'ixx="1" iyy="1" izz="1" ixy="0" ixz="0" iyz="0"/></inertial><collision>'
                    '<geometry><mesh filename="c.obj"/></geometry></collision></link></robot>')
    p = pybullet
    c = p.connect(p.DIRECT)
    try:
        body = p.loadURDF(str(urdf), physicsClientId=c)
        assert max(p.getAABB(body, -1, physicsClientId=c)[1]) < 0.51
    finally:
        p.disconnect(c)
    out = tmp_path / "r.xml"
    _export(str(urdf), out)
    m = mujoco.MjModel.from_xml_path(str(out))
    assert int(m.mesh_vertnum[0]) == 8
    code, data = _agree(str(urdf), out)
    assert code == 0, _failing(data)
    # the same MJCF with the file as it was: MuJoCo's hull reaches 5 5 5
    doc = etree.parse(str(out))
    mesh = doc.find(".//asset/mesh")
    (tmp_path / "r_assets" / "c.obj").write_text(STRAY_CUBE)
    mesh.set("file", "c.obj")
    doc.write(str(out))
    code, data = _agree(str(urdf), out)
    assert code == 1 and _failing(data)["collision meshes"] == "a (mesh)"


@pytest.mark.parametrize("robot", ["laikago/laikago.urdf", "biped/biped2d_pybullet.urdf"])
def test_a_singular_tensor_in_the_file_exports_and_agrees(tmp_path: Path, robot: str) -> None:
    """laikago's legs have inertia 0 0 0 in the file, biped2d's a moment of 5e-18 (read here
    from raw PyBullet, which simulates them so); biped2d's `lower="-1.57."` PyBullet reads
    as -1.57. Both were refused; now each exports and agrees on every row it can compare."""
    import pybullet_data

    p = pybullet
    c = p.connect(p.DIRECT)
    try:
        body = p.loadURDF(f"{pybullet_data.getDataPath()}/{robot}",
                          flags=p.URDF_USE_INERTIA_FROM_FILE, physicsClientId=c)
        singular = [i for i in range(-1, p.getNumJoints(body, physicsClientId=c))
                    if min(p.getDynamicsInfo(body, i, physicsClientId=c)[2]) <= 1e-15
                    and p.getDynamicsInfo(body, i, physicsClientId=c)[0] > 0]
        limits = {p.getJointInfo(body, i, physicsClientId=c)[1].decode():
                  p.getJointInfo(body, i, physicsClientId=c)[8:10]
                  for i in range(p.getNumJoints(body, physicsClientId=c))}
    finally:
        p.disconnect(c)
    assert singular
    out = tmp_path / "robot.xml"
    _export(robot, out)
    m = mujoco.MjModel.from_xml_path(str(out))
    for name, (lo, hi) in limits.items():
        k = mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_JOINT, name)
        if k >= 0 and m.jnt_limited[k]:
            assert tuple(m.jnt_range[k]) == (lo, hi), name
    code, data = _agree(robot, out)
    assert code == 0, _failing(data)
    assert _rows(data)["inertia MuJoCo cannot take"]["status"] == "known"


# ---------------------------------------------------------------- found by review (stop 47)

def test_one_mjcf_name_for_two_urdf_names_is_refused(exports: dict[str, Path]) -> None:
    r = runner.invoke(app, ["agree", "r2d2.urdf", str(exports["r2d2.urdf"]), "--map",
                            "head_swivel=gripper_extension", "--map",
                            "gripper_extension=gripper_extension"])
    assert r.exit_code == 2 and "named for two URDF names" in r.stderr
    assert len(r.stderr.strip().splitlines()) == 1


@pytest.mark.parametrize(("edit", "row"), [
    (lambda doc: next(doc.iterfind(".//geom[@group='3']")).set("friction", "nan 0 0"),
     "contact parameters"),
    (lambda doc: doc.find(".//body[@name='head']").set("quat", "nan 0 0 0"),
     "frames vs exact FK: position"),
])
def test_a_nan_in_the_mjcf_fails(exports: dict[str, Path], edit, row: str) -> None:
    code, data = _agree("r2d2.urdf", _tamper(exports["r2d2.urdf"], "nan.xml", edit))
    assert code == 1 and row in _failing(data)


def test_an_equality_the_urdf_has_not_fails(exports: dict[str, Path]) -> None:
    def weld(doc: etree._ElementTree) -> None:
        eq = etree.SubElement(doc.getroot(), "equality")
        etree.SubElement(eq, "weld", name="glued", body1="left_gripper", body2="right_gripper")

    code, data = _agree("r2d2.urdf", _tamper(exports["r2d2.urdf"], "weld.xml", weld))
    assert code == 1 and "weld glued" in _failing(data)["forces MuJoCo alone applies"]


def test_a_range_on_a_ball_joint_fails(tmp_path: Path) -> None:
    """PyBullet's spherical joint has no limit: a ranged ball in the MJCF is another robot."""
    out = tmp_path / "humanoid.xml"
    _export("humanoid/humanoid.urdf", out)
    doc = etree.parse(str(out))
    ball = doc.find(".//joint[@type='ball']")
    ball.set("range", "0 0.05")
    doc.write(str(out))
    code, data = _agree("humanoid/humanoid.urdf", out)
    assert code == 1 and _failing(data)["joint limits"] == ball.get("name")


def test_a_loose_free_body_is_no_base(exports: dict[str, Path]) -> None:
    def weld_root(doc: etree._ElementTree) -> None:
        root = doc.find("worldbody/body")
        root.remove(root.find("freejoint"))
        loose = etree.SubElement(doc.find("worldbody"), "body", name="loose", pos="3 0 1")
        etree.SubElement(loose, "freejoint")
        etree.SubElement(loose, "geom", type="box", size=".1 .1 .1", mass="1e-9",
                         contype="0", conaffinity="0")

    code, data = _agree("r2d2.urdf", _tamper(exports["r2d2.urdf"], "loose.xml", weld_root))
    assert code == 1 and _rows(data)["base"]["detail"] == "PyBullet: free joint; MJCF: welded"
    assert not any(k.startswith("floating swing") for k in _rows(data))


def test_bodies_below_fused_links_match_by_the_tree(exports: dict[str, Path]) -> None:
    """r2d2's wheels hang from right_base and left_base, fixed links fused into base_link with
    no site once sites are gone: renamed, they are found below base_link's body."""
    def rename(doc: etree._ElementTree) -> None:
        for site in list(doc.iter("site")):
            site.getparent().remove(site)
        for el in doc.iter("body", "joint"):
            if "wheel" in (el.get("name") or ""):
                el.set("name", el.get("name").replace("wheel", "roller"))
        act = doc.find("actuator")
        if act is not None:
            act.getparent().remove(act)

    code, data = _agree("r2d2.urdf", _tamper(exports["r2d2.urdf"], "rollers.xml", rename))
    assert data["unmatched_joints"] == [] and data["extra_joints"] == []
    assert any(p["mjcf"] == "right_front_roller_joint" for p in data["matched_by"])
    assert code == 0, _failing(data)
    # the fused links' own frames have no site left to compare: listed, not passed over
    assert "right_base" in data["unmatched_links"]


def test_an_unnamed_locked_joint_is_welded_by_its_place(tmp_path: Path) -> None:
    urdf = _pendulum(tmp_path, "locked.urdf", limits=((-3, 3), (0.3, 0.3), (-3, 3)))
    out = tmp_path / "locked.xml"
    _export(str(urdf), out)

    def unname(doc: etree._ElementTree) -> None:
        for tag in ("equality", "actuator"):
            el = doc.find(tag)
            if el is not None:
                el.getparent().remove(el)
        for j in doc.iter("joint"):
            if j.get("name") in ("j1", "j2"):
                del j.attrib["name"]

    code, data = _agree(str(urdf), _tamper(out, "unnamed.xml", unname))
    swing = next(r for r in data["rows"] if r["check"].startswith("free swing"))
    assert swing["value"] < 1e-9, swing
