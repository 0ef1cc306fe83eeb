"""`urdfkit export mjcf` never ends 0 with a file MuJoCo refuses (issue 48).

Each case writes a small fixture of its own, exports it as users do (CliRunner), and then loads
the written file in MuJoCo itself: the export is proven by MuJoCo's loader, never by the
writer's own reasoning. What export leaves out is said, one note per thing, naming link and
line; where the note says what PyBullet does, PyBullet is asked.
"""

from __future__ import annotations

import json
from pathlib import Path

import pytest
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
