"""`urdfkit export mjcf`: the file MuJoCo loads, checked against numbers worked out by hand.

Each figure below comes from the fixture's own text and mechanics (masses add, the centre of
mass is the weighted mean, an inertia turned 90 degrees swaps two moments), read back from
MuJoCo's compiled model, never from the writer's code. agree's own tests are test_agree.py.
"""

from __future__ import annotations

import json
import math
import shutil
from pathlib import Path

import numpy as np
import pytest
from typer.testing import CliRunner

from urdfkit.cli import app

mujoco = pytest.importorskip("mujoco")  # in the test extra: CI never skips it

#: A unit cube as COLLADA: MuJoCo cannot read it, so export converts it (scale 2 kept).
CUBE_DAE = """<?xml version="1.0"?>
<COLLADA xmlns="http://www.collada.org/2005/11/COLLADASchema" version="1.4.1">
 <asset><unit meter="1"/><up_axis>Z_UP</up_axis></asset>
 <library_geometries><geometry id="g"><mesh>
  <source id="p"><float_array id="pa" count="24">-0.5 -0.5 -0.5 0.5 -0.5 -0.5 0.5 0.5 -0.5
   -0.5 0.5 -0.5 -0.5 -0.5 0.5 0.5 -0.5 0.5 0.5 0.5 0.5 -0.5 0.5 0.5</float_array>
   <technique_common><accessor source="#pa" count="8" stride="3"><param name="X" type="float"/>
   <param name="Y" type="float"/><param name="Z" type="float"/></accessor></technique_common>
  </source>
  <vertices id="v"><input semantic="POSITION" source="#p"/></vertices>
  <triangles count="12"><input semantic="VERTEX" source="#v" offset="0"/>
   <p>0 2 1 0 3 2 4 5 6 4 6 7 0 1 5 0 5 4 1 2 6 1 6 5 2 3 7 2 7 6 3 0 4 3 4 7</p></triangles>
 </mesh></geometry></library_geometries>
 <library_visual_scenes><visual_scene id="s"><node id="n">
  <instance_geometry url="#g"/></node></visual_scene></library_visual_scenes>
 <scene><instance_visual_scene url="#s"/></scene>
</COLLADA>
"""

#: base (2 kg, inertial turned 90 deg about z) + tool (0.5 kg, fixed 0.5 m above) form one
#: body; arm has no <inertial> (PyBullet: 1 kg, unit inertia); finger_b mimics finger_a.
ROBOT = """<?xml version="1.0"?>
<robot name="fixture">
  <material name="red"><color rgba="1 0 0 1"/></material>
  <link name="base">
    <inertial><origin xyz="0.1 0 0" rpy="0 0 1.5707963267948966"/><mass value="2"/>
      <inertia ixx="1" iyy="2" izz="3" ixy="0" ixz="0" iyz="0"/></inertial>
    <visual><geometry><mesh filename="meshes/cube.dae" scale="2 2 2"/></geometry>
      <material name="red"/></visual>
    <collision><geometry><box size="0.2 0.4 0.6"/></geometry></collision>
  </link>
  <joint name="mount" type="fixed"><parent link="base"/><child link="tool"/>
    <origin xyz="0 0 0.5"/></joint>
  <link name="tool"><inertial><mass value="0.5"/>
    <inertia ixx="0.01" iyy="0.01" izz="0.01" ixy="0" ixz="0" iyz="0"/></inertial></link>
  <joint name="hinge" type="revolute"><parent link="tool"/><child link="arm"/>
    <origin xyz="0 0 0.1"/><axis xyz="0 1 0"/>
    <limit lower="-1" upper="1" effort="5" velocity="2"/><dynamics damping="0.2"/></joint>
  <link name="arm">
    <collision><origin xyz="0 0 0.2"/><geometry><cylinder radius="0.05" length="0.4"/>
      </geometry></collision>
    <contact><lateral_friction value="0.9"/></contact>
  </link>
  <joint name="finger_a" type="prismatic"><parent link="arm"/><child link="fa"/>
    <origin xyz="0 0 0.4"/><axis xyz="1 0 0"/>
    <limit lower="0" upper="0.04" effort="10" velocity="0.1"/></joint>
  <link name="fa"><inertial><mass value="0.1"/>
    <inertia ixx="1e-4" iyy="1e-4" izz="1e-4" ixy="0" ixz="0" iyz="0"/></inertial></link>
  <joint name="finger_b" type="prismatic"><parent link="arm"/><child link="fb"/>
    <origin xyz="0 0 0.4"/><axis xyz="1 0 0"/>
    <limit lower="-0.04" upper="0" effort="10" velocity="0.1"/>
    <mimic joint="finger_a" multiplier="-1" offset="0"/></joint>
  <link name="fb"><inertial><mass value="0.1"/>
    <inertia ixx="1e-4" iyy="1e-4" izz="1e-4" ixy="0" ixz="0" iyz="0"/></inertial></link>
</robot>
"""

runner = CliRunner()


@pytest.fixture
def robot(tmp_path: Path) -> Path:
    (tmp_path / "meshes").mkdir()
    (tmp_path / "meshes" / "cube.dae").write_text(CUBE_DAE)
    path = tmp_path / "fixture.urdf"
    path.write_text(ROBOT)
    return path


def _export(robot: Path, out: Path, *args: str) -> dict:
    r = runner.invoke(app, ["export", "mjcf", str(robot), "-o", str(out), "--json", *args])
    assert r.exit_code == 0, r.output
    return json.loads(r.stdout)


def _moved(out: Path, tmp_path: Path) -> object:
    """The XML and its assets moved to another folder, loaded from a third."""
    elsewhere = tmp_path / "moved"
    elsewhere.mkdir()
    shutil.move(str(out), elsewhere / out.name)
    assets = out.parent / f"{out.stem}_assets"
    if assets.exists():
        shutil.move(str(assets), elsewhere / assets.name)
    third = tmp_path / "third"
    third.mkdir()
    with pytest.MonkeyPatch.context() as mp:
        mp.chdir(third)
        return mujoco.MjModel.from_xml_path(str(elsewhere / out.name))


def _body(m: object, name: str) -> int:
    return mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_BODY, name)


def test_export_loads_from_another_folder_with_the_masses_pybullet_loads(
        robot: Path, tmp_path: Path) -> None:
    (tmp_path / "out").mkdir()
    data = _export(robot, tmp_path / "out" / "robot.xml")
    m = _moved(tmp_path / "out" / "robot.xml", tmp_path)
    # fused: base + tool one body; arm, fa, fb bodies; every link a body or a site
    assert data["bodies"] == ["base", "arm", "fa", "fb"] and data["sites"] == ["tool"]
    assert m.nbody == 5
    # masses: 2 + 0.5 fused, arm's PyBullet default 1 kg, 0.1 + 0.1
    assert m.body_mass[_body(m, "base")] == 2.5
    assert m.body_mass[_body(m, "arm")] == 1.0
    assert math.isclose(m.body_mass.sum(), 3.7, rel_tol=1e-15)
    # the fused centre of mass: (2 * (0.1, 0, 0) + 0.5 * (0, 0, 0.5)) / 2.5
    assert m.body_ipos[_body(m, "base")] == pytest.approx([0.08, 0, 0.1], abs=1e-15)
    # arm: unit inertia, PyBullet's default for a link without <inertial>
    assert m.body_inertia[_body(m, "arm")] == pytest.approx([1, 1, 1], abs=1e-15)
    # inertial rpy applied: diag(1, 2, 3) turned 90 deg about z is diag(2, 1, 3); each mass
    # then moved to the common centre (parallel axes)
    d = mujoco.MjData(m)
    mujoco.mj_forward(m, d)
    b = _body(m, "base")
    r = d.ximat[b].reshape(3, 3)
    world = r @ np.diag(m.body_inertia[b]) @ r.T
    want = np.zeros((3, 3))
    for mass, c, moments in ((2.0, (0.1, 0, 0), (2, 1, 3)),
                             (0.5, (0, 0, 0.5), (0.01, 0.01, 0.01))):
        off = np.subtract(c, (0.08, 0, 0.1))
        want += np.diag(moments) + mass * (off @ off * np.eye(3) - np.outer(off, off))
    assert world == pytest.approx(want, rel=1e-12, abs=1e-14)  # MuJoCo diagonalises it
    # the fixed link kept as a site at its frame; the hinge 0.1 m above it
    s = mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_SITE, "tool")
    assert d.site_xpos[s] == pytest.approx([0, 0, 0.5], abs=1e-15)
    assert d.xpos[_body(m, "arm")] == pytest.approx([0, 0, 0.6], abs=1e-15)


def test_joints_actuators_mimic_contacts_and_the_converted_mesh(
        robot: Path, tmp_path: Path) -> None:
    out = tmp_path / "robot.xml"
    data = _export(robot, out)
    m = mujoco.MjModel.from_xml_path(str(out))
    j = {mujoco.mj_id2name(m, mujoco.mjtObj.mjOBJ_JOINT, i): i for i in range(m.njnt)}
    assert list(j) == [None, "hinge", "finger_a", "finger_b"]  # free joint, then PyBullet's order
    assert m.jnt_type[j[None]] == mujoco.mjtJoint.mjJNT_FREE
    assert m.jnt_range[j["hinge"]].tolist() == [-1, 1] and m.jnt_limited[j["hinge"]]
    assert m.dof_damping[m.jnt_dofadr[j["hinge"]]] == 0.2
    assert m.jnt_type[j["finger_a"]] == mujoco.mjtJoint.mjJNT_SLIDE
    # motors on hinge and finger_a, ctrlrange from the effort; the mimic joint has none
    assert m.nu == 2 and m.actuator_ctrlrange.tolist() == [[-5, 5], [-10, 10]]
    # finger_b = -1 * finger_a + 0
    assert m.neq == 1 and m.eq_data[0][:5].tolist() == [0, -1, 0, 0, 0]
    # collision geoms: friction from <contact> (arm) or PyBullet's 0.5; visuals never collide
    coll = [g for g in range(m.ngeom) if m.geom_contype[g] or m.geom_conaffinity[g]]
    assert sorted(m.geom_friction[g][0] for g in coll) == [0.5, 0.9]
    # the COLLADA cube converted to STL, its scale 2 kept: 2 m on each side
    assert m.nmesh == 1
    v = m.mesh_vert[m.mesh_vertadr[0]:m.mesh_vertadr[0] + m.mesh_vertnum[0]]
    assert (v.max(axis=0) - v.min(axis=0)).tolist() == pytest.approx([2, 2, 2], abs=1e-6)
    notes = " ".join(n["message"] for n in data["notes"])
    assert "cube.dae" in notes and "arm" in notes and "velocity limits" in notes
    # named by its content: cube_<the first 8 hex digits of the STL's SHA-256>.stl
    import hashlib

    (written,) = (tmp_path / "robot_assets").iterdir()
    assert written.name == f"cube_{hashlib.sha256(written.read_bytes()).hexdigest()[:8]}.stl"


def test_fixed_base_welds_and_ground_adds_a_plane(robot: Path, tmp_path: Path) -> None:
    out = tmp_path / "robot.xml"
    _export(robot, out, "--fixed-base", "--ground", "--actuators", "none")
    m = mujoco.MjModel.from_xml_path(str(out))
    assert m.nu == 0 and mujoco.mjtJoint.mjJNT_FREE not in m.jnt_type.tolist()
    ground = mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_GEOM, "ground")
    assert m.geom_type[ground] == mujoco.mjtGeom.mjGEOM_PLANE and m.nlight == 1


def test_refuses_what_mujoco_refuses_with_checks_code_and_line(tmp_path: Path) -> None:
    bad = tmp_path / "massless.urdf"
    bad.write_text(ROBOT.replace('<link name="fa"><inertial><mass value="0.1"/>',
                                 '<link name="fa"><inertial><mass value="0"/>')
                   .replace("meshes/cube.dae", "nothing.stl").replace(
                       "<visual><geometry><mesh filename=\"nothing.stl\" scale=\"2 2 2\"/>"
                       "</geometry>\n      <material name=\"red\"/></visual>", ""))
    out = tmp_path / "out.xml"
    r = runner.invoke(app, ["export", "mjcf", str(bad), "-o", str(out)])
    assert r.exit_code == 2, r.output
    assert "U602" in r.stderr and "massless.urdf:" in r.stderr and "'fa'" in r.stderr
    assert not out.exists()
    # mujoco itself refuses the same body
    lenient = tmp_path / "lenient.urdf"
    lenient.write_text(bad.read_text())
    with pytest.raises(ValueError, match="mass"):
        mujoco.MjModel.from_xml_path(str(lenient))


def test_never_overwrites_without_force(robot: Path, tmp_path: Path) -> None:
    out = tmp_path / "robot.xml"
    out.write_text("mine")
    r = runner.invoke(app, ["export", "mjcf", str(robot), "-o", str(out)])
    assert r.exit_code == 2 and "force" in r.stderr and out.read_text() == "mine"
    r = runner.invoke(app, ["export", "mjcf", str(robot), "-o", str(out), "--force"])
    assert r.exit_code == 0 and out.read_text().startswith("<mujoco")


def test_writer_numbers_round_trip_every_double(robot: Path, tmp_path: Path) -> None:
    from urdfkit.formats.mjcf import num

    for x in (math.pi, 1 / 3, -2.9670597283903604, 1e-300, 0.1 + 0.2, -0.0):
        assert float(num(x)) == x
    assert num(-0.0) == "0"


def test_a_flat_mesh_loads(tmp_path: Path) -> None:
    """plane.urdf's plane.obj has no volume: MuJoCo refuses it unless its inertia is a shell
    (the body's inertia is written, never taken from meshes)."""
    out = tmp_path / "plane.xml"
    r = runner.invoke(app, ["export", "mjcf", "plane.urdf", "-o", str(out)])
    assert r.exit_code == 0, r.output
    m = mujoco.MjModel.from_xml_path(str(out))
    assert m.nmesh == 1 and m.body_mass[1] == 0  # plane.urdf's base: mass 0, welded


def test_xacro_with_an_argument(tmp_path: Path) -> None:
    """tests/data/arm.urdf.xacro: the upper arm's centre of mass sits at L/2 above the
    shoulder, and its cylinder is L long."""
    arm = Path(__file__).parent / "data" / "arm.urdf.xacro"
    out = tmp_path / "arm.xml"
    _export(arm, out, "--arg", "length:=0.8")
    m = mujoco.MjModel.from_xml_path(str(out))
    upper = _body(m, "upper")
    assert m.body_ipos[upper] == pytest.approx([0, 0, 0.4], abs=1e-15)
    cyl = [g for g in range(m.ngeom) if m.geom_bodyid[g] == upper
           and m.geom_type[g] == mujoco.mjtGeom.mjGEOM_CYLINDER]
    assert m.geom_size[cyl[0]][1] == pytest.approx(0.4, abs=1e-15)  # half of 0.8
