"""`urdfkit export mjcf` never ends 0 with a file MuJoCo refuses (issue 48).

Each case writes a small fixture of its own, exports it as users do (CliRunner), and then loads
the written file in MuJoCo itself: the export is proven by MuJoCo's loader, never by the
writer's own reasoning. What export leaves out is said, one note per thing, naming link and
line; where the note says what PyBullet does, PyBullet is asked.
"""

from __future__ import annotations

import json
import struct
from pathlib import Path

import numpy as np
import pytest
from lxml import etree
from typer.testing import CliRunner

from urdfkit.cli import app

mujoco = pytest.importorskip("mujoco")  # in the test extra: CI never skips it

runner = CliRunner()

#: A unit cube as OBJ (12 triangles, wound outward).
CUBE_OBJ = """v -0.5 -0.5 -0.5
v 0.5 -0.5 -0.5
v 0.5 0.5 -0.5
v -0.5 0.5 -0.5
v -0.5 -0.5 0.5
v 0.5 -0.5 0.5
v 0.5 0.5 0.5
v -0.5 0.5 0.5
f 1 3 2
f 1 4 3
f 5 6 7
f 5 7 8
f 1 2 6
f 1 6 5
f 2 3 7
f 2 7 6
f 3 4 8
f 3 8 7
f 4 1 5
f 4 5 8
"""

INERTIA = '<inertia ixx="0.01" iyy="0.01" izz="0.01" ixy="0" ixz="0" iyz="0"/>'


def urdf(links: dict[str, str], mimics: dict[str, str] | None = None) -> str:
    """A chain of revolute joints, one link per entry (its shapes as given), 1 kg each."""
    names = list(links)
    out = ['<?xml version="1.0"?>', '<robot name="fixture">']
    for k, name in enumerate(names):
        out.append(f'<link name="{name}"><inertial><mass value="1"/>{INERTIA}</inertial>'
                   f"{links[name]}</link>")
        if k:
            mimic = (mimics or {}).get(f"j{k}", "")
            out.append(f'<joint name="j{k}" type="revolute"><parent link="{names[k - 1]}"/>'
                       f'<child link="{name}"/><origin xyz="0 0 0.1"/><axis xyz="0 0 1"/>'
                       f'<limit lower="-1" upper="1" effort="1" velocity="1"/>{mimic}</joint>')
    out.append("</robot>")
    return "\n".join(out) + "\n"


def export(robot: Path, out: Path, *args: str, code: int = 0) -> dict:
    r = runner.invoke(app, ["export", "mjcf", str(robot), "-o", str(out), "--json", *args])
    assert r.exit_code == code, r.output
    return json.loads(r.stdout) if code in (0, 1) else {}


def notes(data: dict, kind: str | None = None) -> list[dict]:
    return [n for n in data["notes"] if kind is None or n["kind"] == kind]


def line_of(text: str, needle: str) -> int:
    """The 1-based line of the first line holding ``needle``."""
    return next(k for k, ln in enumerate(text.splitlines(), 1) if needle in ln)


# ------------------------------------------------------------------ 1. zero-size shapes

ZERO = {
    "base": '<visual><geometry><box size="0.1 0.1 0.1"/></geometry></visual>',
    # atlas_drc's placeholder collision, upkie's placeholder visual
    "atlas": '<collision><geometry><sphere radius="0"/></geometry></collision>',
    "upkie": '<visual><geometry><box size="0 0 0"/></geometry></visual>',
    "rod": '<collision><geometry><cylinder radius="0" length="0"/></geometry></collision>',
    "squashed": '<visual><geometry><mesh filename="cube.obj" scale="0 0 0"/></geometry>'
                '</visual><collision><geometry><mesh filename="cube.obj" scale="1 0 1"/>'
                "</geometry></collision>",
    "ball": '<collision><geometry><capsule radius="0.05" length="0"/></geometry></collision>',
}


def test_zero_size_shapes_are_left_out_said_and_the_file_loads(tmp_path: Path) -> None:
    text = urdf(ZERO)
    (tmp_path / "cube.obj").write_text(CUBE_OBJ)
    robot = tmp_path / "zero.urdf"
    robot.write_text(text)
    out = tmp_path / "zero.xml"
    data = export(robot, out)
    m = mujoco.MjModel.from_xml_path(str(out))  # MuJoCo refused every one of them before
    # the base's box and the capsule of length 0 (a sphere of its radius) are all that is left
    kinds = sorted(int(t) for t in m.geom_type)
    assert kinds == sorted([int(mujoco.mjtGeom.mjGEOM_BOX), int(mujoco.mjtGeom.mjGEOM_SPHERE)])
    ball = [g for g in range(m.ngeom) if m.geom_type[g] == mujoco.mjtGeom.mjGEOM_SPHERE]
    assert m.geom_size[ball[0]][0] == 0.05
    # mass properties are PyBullet's loaded ones, untouched: 1 kg per link
    assert m.body_mass[1:].tolist() == [1.0] * len(ZERO)
    dropped = notes(data, "dropped")
    said = {(n["line"], n["message"].split(":")[0]) for n in dropped
            if "left out (PyBullet keeps it as a point" in n["message"]}
    assert said == {(line_of(text, '"atlas"'), "collision of link 'atlas'"),
                    (line_of(text, '"upkie"'), "visual of link 'upkie'"),
                    (line_of(text, '"rod"'), "collision of link 'rod'"),
                    (line_of(text, '"squashed"'), "visual of link 'squashed'"),
                    (line_of(text, '"squashed"'), "collision of link 'squashed'")}
    assert any("capsule of link 'ball' has length 0" in n["message"] for n in notes(data))


def test_what_pybullet_does_with_a_zero_sphere_is_what_the_note_says(
        tmp_path: Path, pb: tuple) -> None:
    """The note says PyBullet keeps a zero-size shape as a point: its box has no extent."""
    p, client = pb
    robot = tmp_path / "atlas.urdf"
    robot.write_text(urdf({"atlas": ZERO["atlas"]}))
    body = p.loadURDF(str(robot), physicsClientId=client)
    low, high = p.getAABB(body, -1, physicsClientId=client)
    assert low == high  # a point
    assert p.getCollisionShapeData(body, -1, physicsClientId=client)[0][3] == (0.0, 0.0, 0.0)


# ------------------------------------------------------------------ 4. mimics MuJoCo refuses

def test_a_joint_mimicking_itself_or_a_ring_of_mimics_is_not_written(tmp_path: Path) -> None:
    links = {n: '<visual><geometry><box size="0.1 0.1 0.1"/></geometry></visual>'
             for n in ("base", "l1", "l2", "l3", "l4")}
    text = urdf(links, {"j1": '<mimic joint="j1"/>',  # itself
                        "j2": '<mimic joint="j3"/>', "j3": '<mimic joint="j2"/>',  # a ring
                        "j4": '<mimic joint="j2" multiplier="2"/>'})  # follows the ring
    robot = tmp_path / "mimic.urdf"
    robot.write_text(text)
    out = tmp_path / "mimic.xml"
    data = export(robot, out)
    m = mujoco.MjModel.from_xml_path(str(out))  # "element 'j1' is repeated" before
    # j4 = 2 j2 is written; the others are ordinary joints, each with its motor
    assert m.neq == 1
    eq = [mujoco.mj_id2name(m, mujoco.mjtObj.mjOBJ_JOINT, int(m.eq_obj1id[0])),
          mujoco.mj_id2name(m, mujoco.mjtObj.mjOBJ_JOINT, int(m.eq_obj2id[0]))]
    assert eq == ["j4", "j2"] and m.eq_data[0][:2].tolist() == [0, 2]
    assert [mujoco.mj_id2name(m, mujoco.mjtObj.mjOBJ_ACTUATOR, a) for a in range(m.nu)] == \
        ["j1", "j2", "j3"]
    dropped = {n["line"]: n["message"] for n in notes(data, "dropped") if "<mimic>" in n["message"]}
    assert set(dropped) == {line_of(text, f'name="j{k}"') for k in (1, 2, 3)}
    assert "itself" in dropped[line_of(text, 'name="j1"')]
    assert "'j3' -> 'j2' -> 'j3'" in dropped[line_of(text, 'name="j3"')]


# ------------------------------------------------------------------ 2-3. mesh files

def cube_triangles() -> np.ndarray:
    """The unit cube's 12 triangles, (12, 3, 3)."""
    rows = CUBE_OBJ.splitlines()
    v = np.array([[float(x) for x in r.split()[1:]] for r in rows if r.startswith("v ")])
    f = np.array([[int(x) - 1 for x in r.split()[1:]] for r in rows if r.startswith("f ")])
    return v[f]


def binary_stl(triangles: np.ndarray) -> bytes:
    rec = np.zeros(len(triangles), dtype=[("n", "<f4", 3), ("v", "<f4", (3, 3)), ("a", "<u2")])
    rec["v"] = triangles
    return b"fixture".ljust(80) + struct.pack("<I", len(rec)) + rec.tobytes()


def mujoco_mesh(path: Path, collides: bool) -> str | None:
    """MuJoCo's own verdict on a mesh file (None: it loads), in a geom that collides or not."""
    flags = "" if collides else 'contype="0" conaffinity="0"'
    xml = (f'<mujoco><asset><mesh name="m" file="{path}" inertia="shell"/></asset><worldbody>'
           f'<body><freejoint/><inertial pos="0 0 0" mass="1" diaginertia="1 1 1"/>'
           f'<geom type="mesh" mesh="m" density="0" {flags}/></body></worldbody></mujoco>')
    try:
        mujoco.MjModel.from_xml_string(xml)
    except ValueError as e:
        return str(e)
    return None


def test_meshes_mujoco_refuses_are_dropped_or_salvaged_and_the_file_loads(
        tmp_path: Path) -> None:
    cube = cube_triangles()
    nan = cube.copy()
    nan[[1, 4, 7], 0, 2] = np.nan  # three triangles with a NaN vertex
    files = {
        "empty.obj": b"",
        "garbage.obj": b"Lorem ipsum dolor sit amet\n7 8 9 fq\x00\xff\n",
        "nan.stl": binary_stl(nan),
        "all_nan.stl": binary_stl(np.full((4, 3, 3), np.nan)),
        "flat.obj": b"v 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 1 0\nf 1 2 3\nf 2 4 3\n",
        "triangle.obj": b"v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n",
        # legal OBJ, refused by MuJoCo: normals given, faces naming none of them
        "normals.obj": CUBE_OBJ.encode() + b"vn 0 0 1\n",
        "cube.obj": CUBE_OBJ.encode(),
    }
    for name, data in files.items():
        (tmp_path / name).write_bytes(data)
    # what MuJoCo itself says of each, as found: every one but the cube is refused
    verdicts = {n: mujoco_mesh(tmp_path / n, collides=True) for n in files}
    assert [n for n, v in verdicts.items() if v is None] == ["cube.obj"], verdicts
    links = {"base": '<visual><geometry><mesh filename="cube.obj"/></geometry></visual>'}
    for name in files:
        stem = name.split(".")[0]
        links[stem] = f'<visual><geometry><mesh filename="{name}"/></geometry></visual>'
        if "nan" not in name:  # PyBullet 3.2.7 hangs on a collision mesh with a NaN vertex
            links[stem] += f'<collision><geometry><mesh filename="{name}"/></geometry></collision>'
    text = urdf(links)
    robot = tmp_path / "meshes.urdf"
    robot.write_text(text)
    out = tmp_path / "out" / "meshes.xml"
    out.parent.mkdir()
    data = export(robot, out)
    m = mujoco.MjModel.from_xml_path(str(out))
    geoms = {}
    for g in range(m.ngeom):
        body = mujoco.mj_id2name(m, mujoco.mjtObj.mjOBJ_BODY, int(m.geom_bodyid[g]))
        geoms.setdefault(body, []).append("collision" if m.geom_contype[g] else "visual")
    # kept: the cube (copied), the NaN STL's 9 sound triangles, the re-written OBJ, and the
    # flat square as a visual (MuJoCo draws it; it cannot hull it to collide)
    assert geoms == {"base": ["visual"], "nan": ["visual"],
                     "flat": ["visual"], "normals": ["visual", "collision"],
                     "cube": ["visual", "collision"]}
    faces = {mujoco.mj_id2name(m, mujoco.mjtObj.mjOBJ_MESH, k): int(m.mesh_facenum[k])
             for k in range(m.nmesh)}
    assert sorted(faces.values()) == [2, 9, 12, 12]
    said = {n["line"]: n["message"] for n in notes(data) if n["kind"] in ("dropped", "converted")
            and "mesh" in n["message"]}
    at = {stem: line_of(text, f'name="{stem}"') for stem in
          ("empty", "garbage", "nan", "all_nan", "flat", "triangle", "normals")}
    assert "no triangles" in said[at["empty"]] and "no triangles" in said[at["garbage"]]
    assert "3 of its 12 triangles" in said[at["nan"]]
    assert "none of its 4 triangle(s)" in said[at["all_nan"]]
    assert "collision of link 'flat'" in said[at["flat"]] and "no volume" in said[at["flat"]]
    assert "fewer than 4 vertices" in said[at["triangle"]]
    assert "normals" in said[at["normals"]]
    # the copy is the file itself, byte for byte
    copied = [p for p in (out.parent / "meshes_assets").iterdir() if p.name.startswith("cube_")]
    assert [p.read_bytes() for p in copied] == [files["cube.obj"]]


def test_a_mesh_over_mujocos_stl_face_limit_is_written_whole_as_obj(tmp_path: Path) -> None:
    """MuJoCo 4.0 reads at most 200,000 faces from a binary STL, and any number from an OBJ."""
    triangles = cube_triangles()
    limit = binary_stl(triangles[np.arange(200_000) % 12])
    over = binary_stl(triangles[np.arange(200_001) % 12])
    (tmp_path / "limit.stl").write_bytes(limit)
    (tmp_path / "big.stl").write_bytes(over)
    assert mujoco_mesh(tmp_path / "limit.stl", collides=False) is None
    assert "between 1 and 200000" in str(mujoco_mesh(tmp_path / "big.stl", collides=False))
    text = urdf({"base": '<visual><geometry><mesh filename="big.stl"/></geometry></visual>'
                         '<collision><geometry><mesh filename="big.stl"/></geometry>'
                         "</collision>"})
    robot = tmp_path / "big.urdf"
    robot.write_text(text)
    out = tmp_path / "big.xml"
    data = export(robot, out)
    m = mujoco.MjModel.from_xml_path(str(out))
    assert m.nmesh == 1 and m.mesh_facenum.tolist() == [200_001]  # no face lost
    assert m.ngeom == 2
    (note,) = [n for n in notes(data, "converted") if "big.stl" in n["message"]]
    assert "200001 faces" in note["message"] and "OBJ" in note["message"]
    assert note["line"] == line_of(text, "big.stl")


# ------------------------------------------------------------------ 7. nothing from outside

@pytest.mark.parametrize("reference", ["package://pkg/../secret.obj", "../../secret.obj",
                                       "package://pkg/meshes/../../../ws/secret.obj"])
def test_a_mesh_from_outside_its_package_is_refused_by_every_command(
        tmp_path: Path, reference: str) -> None:
    ws = tmp_path / "ws"
    (ws / "pkg" / "urdf").mkdir(parents=True)
    (ws / "pkg" / "meshes").mkdir()
    (ws / "pkg" / "package.xml").write_text("<package><name>pkg</name></package>")
    (ws / "secret.obj").write_text(CUBE_OBJ)  # beside the package, not in it
    (ws / "pkg" / "meshes" / "ok.obj").write_text(CUBE_OBJ)
    text = urdf({"base": '<visual><geometry><mesh filename="../meshes/ok.obj"/></geometry>'
                         '</visual>',
                 "arm": f'<visual><geometry><mesh filename="{reference}"/></geometry></visual>'})
    robot = ws / "pkg" / "urdf" / "robot.urdf"
    robot.write_text(text)
    out = tmp_path / "robot.xml"
    r = runner.invoke(app, ["export", "mjcf", str(robot), "-o", str(out)])
    assert r.exit_code == 2, r.output
    (err,) = r.stderr.strip().splitlines()
    line = line_of(text, 'name="arm"')
    assert f"robot.urdf:{line}:" in err and "climbs out" in err
    assert not out.exists() and not (tmp_path / "robot_assets").exists()
    # one rule for all: the loading commands refuse it, check reports it (U702)
    assert runner.invoke(app, ["joints", str(robot)]).exit_code == 2
    r = runner.invoke(app, ["check", str(robot), "--json"])
    found = json.loads(r.stdout)["findings"]
    assert [f["code"] for f in found if "climbs out" in f["message"]] == ["U702"]
    # a path that climbs only within the package is fine
    robot.write_text(text.replace(reference, "../meshes/../meshes/ok.obj"))
    export(robot, out)
    assert mujoco.MjModel.from_xml_path(str(out)).nmesh == 1


# ------------------------------------------------------------------ 8. a way through U604

def body_tensor(m: object, name: str) -> np.ndarray:
    """A body's inertia about its centre of mass, in the body's axes, as MuJoCo compiled it."""
    b = mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_BODY, name)
    r = np.zeros(9)
    mujoco.mju_quat2Mat(r, m.body_iquat[b])
    r = r.reshape(3, 3)
    return r @ np.diag(m.body_inertia[b]) @ r.T


def inertia_of(urdf_text: bytes, link: str) -> np.ndarray:
    el = etree.fromstring(urdf_text).find(f"link[@name='{link}']/inertial/inertia")
    g = {k: float(el.get(k)) for k in ("ixx", "iyy", "izz", "ixy", "ixz", "iyz")}
    return np.array([[g["ixx"], g["ixy"], g["ixz"]], [g["ixy"], g["iyy"], g["iyz"]],
                     [g["ixz"], g["iyz"], g["izz"]]])


@pytest.mark.parametrize(("robot", "links", "fix_args"), [
    ("xarm/xarm6_robot.urdf", ["link2", "link3"], []),  # derived from its collision shapes
    ("mini_cheetah/mini_cheetah.urdf",  # no closed collision solid: balanced
     ["thigh_fr", "thigh_fl", "thigh_hr", "thigh_hl"], ["--balance"])])
def test_a_tensor_pybullet_zeroes_is_written_as_urdfkit_fix_writes_it(
        tmp_path: Path, pb: tuple, robot: str, links: list[str], fix_args: list[str]) -> None:
    import pybullet_data

    source = Path(pybullet_data.getDataPath()) / robot
    text = source.read_text()
    # PyBullet zeroes those links' tensors (each breaks the triangle inequality)
    p, client = pb
    body = p.loadURDF(str(source), flags=p.URDF_USE_INERTIA_FROM_FILE, physicsClientId=client)
    index = {p.getJointInfo(body, i, physicsClientId=client)[12].decode(): i
             for i in range(p.getNumJoints(body, physicsClientId=client))}
    for name in links:
        assert p.getDynamicsInfo(body, index[name], physicsClientId=client)[2] == (0, 0, 0)
    out = tmp_path / "robot.xml"
    data = export(Path(robot), out)  # refused with U604 before
    assert data["repaired"] == links
    said = {n["line"]: n["message"] for n in notes(data, "repaired")}
    assert sorted(said) == sorted(line_of(text[text.index(f'<link name="{n}"'):], "<inertial")
                                  + text[:text.index(f'<link name="{n}"')].count("\n")
                                  for n in links)
    assert all("PyBullet zeroes it" in s and "known difference" in s for s in said.values())
    m = mujoco.MjModel.from_xml_path(str(out))
    # what was written is what `urdfkit fix` writes into the file for each of them
    fixed = tmp_path / "fixed.urdf"
    r = runner.invoke(app, ["fix", str(source), "-o", str(fixed), *fix_args])
    assert r.exit_code == 0, r.output
    for name in links:
        assert body_tensor(m, name) == pytest.approx(inertia_of(fixed.read_bytes(), name),
                                                     rel=1e-12, abs=1e-18), name


def test_a_zeroed_tensor_fix_cannot_repair_gets_pybullets_own_from_the_shapes(
        tmp_path: Path, pb: tuple) -> None:
    """reachy's r_antenna, romeo's thighs: not positive definite, no collision solid, so fix
    has nothing to write; export writes the tensor PyBullet itself computes without
    URDF_USE_INERTIA_FROM_FILE (read here from raw PyBullet), not a dead end."""
    text = urdf({"base": "", "antenna": ""}).replace(
        f'<link name="antenna"><inertial><mass value="1"/>{INERTIA}',
        '<link name="antenna"><inertial><mass value="1"/><inertia ixx="-0.01" iyy="0.02" '
        'izz="0.02" ixy="0" ixz="0" iyz="0"/>')
    robot = tmp_path / "antenna.urdf"
    robot.write_text(text)
    p, client = pb
    body = p.loadURDF(str(robot), physicsClientId=client)  # without the flag
    index = {p.getJointInfo(body, i, physicsClientId=client)[12].decode(): i
             for i in range(p.getNumJoints(body, physicsClientId=client))}
    own = sorted(p.getDynamicsInfo(body, index["antenna"], physicsClientId=client)[2])
    out = tmp_path / "a.xml"
    data = export(robot, out)
    assert data["repaired"] == ["antenna"]
    (said,) = [n for n in notes(data, "repaired")]
    assert said["line"] == line_of(text, "-0.01") and "URDF_USE_INERTIA_FROM_FILE is off" in \
        said["message"]
    m = mujoco.MjModel.from_xml_path(str(out))
    assert sorted(np.linalg.eigvalsh(body_tensor(m, "antenna"))) == pytest.approx(own,
                                                                                  rel=1e-9)
    r = runner.invoke(app, ["agree", str(robot), str(out), "--json"])
    assert r.exit_code == 0, r.output
    rows = {x["check"]: x for x in json.loads(r.stdout)["rows"]}
    assert rows["inertia MuJoCo cannot take"]["status"] == "known"


HINGE = """<robot name="h">
  <link name="base"><inertial><mass value="1"/>
    <inertia ixx="0.1" iyy="0.1" izz="0.1" ixy="0" ixz="0" iyz="0"/></inertial></link>
  <link name="arm"><inertial><origin xyz="0 0 -0.5"/><mass value="{mass}"/>
    <inertia ixx="0.1" iyy="0.1" izz="0.1" ixy="0" ixz="0" iyz="0"/></inertial></link>
  <joint name="hinge" type="revolute"><parent link="base"/><child link="arm"/>
    <axis xyz="1 0 0"/><limit lower="{lower}" upper="{upper}" effort="1" velocity="1"/></joint>
</robot>
"""


@pytest.mark.parametrize("upper", ["inf", "nan", "1e309"])
def test_a_limit_that_is_not_finite_is_refused(tmp_path: Path, upper: str) -> None:
    """PyBullet loads such a bound as written (read here); MuJoCo's range cannot hold it, and
    export once wrote a different range instead (the default -3 -1)."""
    import pybullet as p

    urdf = tmp_path / "h.urdf"
    urdf.write_text(HINGE.format(mass=1, lower=-3, upper=upper))
    c = p.connect(p.DIRECT)
    try:
        body = p.loadURDF(str(urdf), physicsClientId=c)
        loaded = p.getJointInfo(body, 0, physicsClientId=c)[9]
    finally:
        p.disconnect(c)
    assert not np.isfinite(loaded)
    out = tmp_path / "h.xml"
    r = runner.invoke(app, ["export", "mjcf", str(urdf), "-o", str(out)])
    assert r.exit_code == 2 and not out.exists()
    assert f'h.urdf:6: joint \'hinge\': <limit upper="{upper}">' in r.stderr
    assert len(r.stderr.strip().splitlines()) == 1


def test_a_mass_under_mujocos_floor_is_refused(tmp_path: Path) -> None:
    urdf = tmp_path / "h.urdf"
    urdf.write_text(HINGE.format(mass="1e-320", lower=-1, upper=1))
    # MuJoCo's own verdict on such a body
    xml = ('<mujoco><worldbody><body><joint type="hinge"/><inertial pos="0 0 0" mass="1e-320" '
           'diaginertia="0.1 0.1 0.1"/></body></worldbody></mujoco>')
    with pytest.raises(ValueError, match="mjMINVAL"):
        mujoco.MjModel.from_xml_string(xml)
    out = tmp_path / "h.xml"
    r = runner.invoke(app, ["export", "mjcf", str(urdf), "-o", str(out)])
    assert r.exit_code == 2 and not out.exists()
    assert "h.urdf:4: U602: link 'arm' moves but has mass 1e-320 kg" in r.stderr
