"""`urdfkit diff`: two robots compared in meaning, the library and the command."""

from __future__ import annotations

import json
import shutil
from pathlib import Path
from typing import Any

import pytest
from typer.testing import CliRunner

from urdfkit.builder import (
    Box,
    Collision,
    Inertia,
    Inertial,
    Joint,
    Limit,
    Link,
    Origin,
    Robot,
    Sphere,
    Visual,
)
from urdfkit.checks.diff import DiffResult, diff_files, diff_robots
from urdfkit.cli import app
from urdfkit.core.errors import InputError, ModelError, ParameterError
from urdfkit.sources.resolve import pybullet_data_path

INERTIAL = ('<inertial><mass value="{m}"/><inertia ixx="0.01" ixy="0" ixz="0" iyy="0.01" '
            'iyz="0" izz="0.01"/></inertial>')


def link(name: str, mass: float = 1.0) -> str:
    return (f'<link name="{name}">{INERTIAL.format(m=mass)}'
            '<visual><geometry><box size="0.1 0.1 0.1"/></geometry></visual>'
            '<collision><geometry><box size="0.1 0.1 0.1"/></geometry></collision></link>')


def joint(name: str, parent: str, child: str, kind: str = "revolute", xyz: str = "0 0 0.1",
          effort: float = 23.7, extra: str = "") -> str:
    limit = (f'<limit lower="-1" upper="1" effort="{effort}" velocity="2"/>'
             if kind in ("revolute", "prismatic") else "")
    axis = '<axis xyz="0 0 1"/>' if kind != "fixed" else ""
    return (f'<joint name="{name}" type="{kind}"><parent link="{parent}"/>'
            f'<child link="{child}"/><origin xyz="{xyz}"/>{axis}{limit}{extra}</joint>')


def arm(*, effort: float = 23.7, names: dict[str, str] | None = None,
        robot: str = "arm") -> str:
    """A three-joint arm; ``names`` renames links and joints (old -> new)."""
    n = {k: k for k in ("base", "l1", "l2", "l3", "shoulder_pan_joint", "shoulder_lift_joint",
                        "elbow_joint")}
    n.update(names or {})
    return (f'<robot name="{robot}">' + link(n["base"], 4) + link(n["l1"]) + link(n["l2"])
            + link(n["l3"], 0.5)
            + joint(n["shoulder_pan_joint"], n["base"], n["l1"], effort=effort)
            + joint(n["shoulder_lift_joint"], n["l1"], n["l2"], xyz="0 0.1 0")
            + joint(n["elbow_joint"], n["l2"], n["l3"], xyz="0.3 0 0") + "</robot>")


def car(*, camera: bool = False) -> str:
    """The tutorial's car shape: four wheels and two steering hinges under the base.

    With ``camera``, a fixed camera mount is declared first under the base: every index after
    it moves, which is what breaks ``wheel_indices = [1, 3, 4, 5]``.
    """
    body = [link("base_link", 5)]
    joints = []
    if camera:
        body.append(link("camera", 0.1))
        joints.append(joint("camera_joint", "base_link", "camera", "fixed", xyz="0.2 0 0.2"))
    for side, y in (("left", 0.2), ("right", -0.2)):
        body += [link(f"{side}_hinge", 0.2), link(f"{side}_front_wheel", 0.3)]
        joints += [joint(f"{side}_hinge_joint", "base_link", f"{side}_hinge",
                         xyz=f"0.3 {y} 0"),
                   joint(f"{side}_front_wheel_joint", f"{side}_hinge", f"{side}_front_wheel",
                         "continuous")]
    for side, y in (("left", 0.2), ("right", -0.2)):
        body.append(link(f"{side}_rear_wheel", 0.3))
        joints.append(joint(f"{side}_rear_wheel_joint", "base_link", f"{side}_rear_wheel",
                            "continuous", xyz=f"-0.3 {y} 0"))
    return '<robot name="car">' + "".join(body + joints) + "</robot>"


def write(tmp_path: Path, name: str, text: str) -> Path:
    path = tmp_path / name
    path.write_text(text)
    return path


def run(*args: str | Path) -> tuple[int, str, str]:
    result = CliRunner().invoke(app, ["diff", *map(str, args)])
    return result.exit_code, result.stdout, result.stderr


def changes(result: DiffResult) -> dict[tuple[str, str], tuple[Any, Any]]:
    return {(c.name, c.field): (c.old, c.new) for c in result.changes}


# --------------------------------------------------------------------------- changed fields


def test_a_changed_effort_limit_is_named_with_old_and_new(tmp_path: Path) -> None:
    a = write(tmp_path, "a.urdf", arm(effort=23.7))
    b = write(tmp_path, "b.urdf", arm(effort=33.5))
    result = diff_files(a, b)
    assert not result.same
    assert [(c.kind, c.name, c.field, c.old, c.new) for c in result.changes] == [
        ("joint", "shoulder_pan_joint", "limit.effort", 23.7, 33.5)]
    assert not (result.added or result.removed or result.renamed or result.index_shifts)

    code, out, err = run(a, b)
    assert code == 1, err
    row = next(line for line in out.splitlines() if "limit.effort" in line)
    assert row.split() == ["changed", "joint", "shoulder_pan_joint", "limit.effort", "23.7",
                           "33.5"]
    assert "1 difference(s)" in out


def test_every_kind_of_field_is_compared() -> None:
    a = Robot.from_string(arm())
    b = Robot.from_string(arm())
    j = b.joint("elbow_joint")
    j.origin = Origin(xyz=(0.3, 0, 0.05))
    j.axis = (0, 1, 0)
    j.limit = Limit(effort=23.7, velocity=3, lower=-2, upper=1)
    lk = b.link("l2")
    lk.inertial = Inertial(mass=2, inertia=Inertia(ixx=0.02, iyy=0.01, izz=0.01))
    lk.collisions[0].geometry = Sphere(radius=0.05)
    from urdfkit.builder import Dynamics, Material

    j.dynamics = Dynamics(damping=0.5)
    lk.visuals[0].material = Material(name="red", color=(1, 0, 0, 1))
    found = changes(diff_robots(a, b))
    assert found[("elbow_joint", "origin.xyz")] == ((0.3, 0, 0), (0.3, 0, 0.05))
    assert found[("elbow_joint", "axis")] == ((0, 0, 1), (0, 1, 0))
    assert found[("elbow_joint", "limit.velocity")] == (2, 3)
    assert found[("elbow_joint", "limit.lower")] == (-1, -2)
    assert found[("elbow_joint", "dynamics.damping")] == (None, 0.5)
    assert ("elbow_joint", "dynamics.friction") not in found  # absent is the default, 0
    assert found[("l2", "inertial.mass")] == (1, 2)
    assert found[("l2", "inertial.inertia.ixx")] == (0.01, 0.02)
    assert found[("l2", "collision[0].geometry")] == ("box", "sphere")
    assert found[("l2", "collision[0].geometry.radius")] == (None, 0.05)
    assert found[("l2", "collision[0].geometry.size")] == ((0.1, 0.1, 0.1), None)
    assert found[("l2", "visual[0].material.color")] == (None, (1, 0, 0, 1))
    assert ("l1", "inertial.mass") not in found


def test_a_visual_only_one_side_has_is_one_change() -> None:
    a = Robot.from_string(arm())
    b = Robot.from_string(arm())
    b.link("l1").visuals.append(Visual(geometry=Box(size=(1, 2, 3)),
                                       origin=Origin(xyz=(0, 0, 0.5))))
    result = diff_robots(a, b)
    [change] = result.changes
    assert (change.name, change.field, change.old) == ("l1", "visual[1]", None)
    assert change.new["geometry"] == "box" and change.new["geometry.size"] == (1, 2, 3)
    assert change.to_dict()["new"]["origin.xyz"] == [0, 0, 0.5]  # JSON: lists


def test_a_material_by_reference_equals_the_same_colour_inline() -> None:
    inline = arm().replace("</geometry></visual>",
                           '</geometry><material name="grey"><color rgba="0.5 0.5 0.5 1"/>'
                           "</material></visual>")
    named = arm().replace('<robot name="arm">', '<robot name="arm"><material name="steel">'
                          '<color rgba="0.5 0.5 0.5 1"/></material>').replace(
        "</geometry></visual>", '</geometry><material name="steel"/></visual>')
    assert diff_robots(Robot.from_string(inline), Robot.from_string(named)).same
    darker = named.replace('rgba="0.5 0.5 0.5 1"', 'rgba="0.4 0.5 0.5 1"')
    found = changes(diff_robots(Robot.from_string(inline), Robot.from_string(darker)))
    assert found[("base", "visual[0].material.color")] == ((0.5, 0.5, 0.5, 1), (0.4, 0.5, 0.5, 1))


def test_meshes_are_compared_by_content(tmp_path: Path) -> None:
    stl = pybullet_data_path() / "l_finger.stl"
    other = pybullet_data_path() / "l_finger_tip.stl"
    text = arm().replace('<visual><geometry><box size="0.1 0.1 0.1"/>',
                         '<visual><geometry><mesh filename="meshes/part.stl"/>', 1)
    for folder, mesh in (("a", stl), ("b", stl), ("c", other)):
        (tmp_path / folder / "meshes").mkdir(parents=True)
        shutil.copy(mesh, tmp_path / folder / "meshes" / "part.stl")
        write(tmp_path / folder, "robot.urdf", text)
    assert diff_files(tmp_path / "a/robot.urdf", tmp_path / "b/robot.urdf").same
    result = diff_files(tmp_path / "a/robot.urdf", tmp_path / "c/robot.urdf")
    [change] = result.changes
    assert change.field == "visual[0].geometry.filename"
    assert change.old.endswith("a/meshes/part.stl") and change.new.endswith("c/meshes/part.stl")


# --------------------------------------------------------------------------- same in meaning


def test_a_reformatted_file_is_the_same_robot(tmp_path: Path) -> None:
    a = write(tmp_path, "a.urdf", arm())
    reformatted = """<?xml version="1.0"?>
<!-- the same arm, written by someone else -->
<robot name="arm">
  <joint type="revolute" name="shoulder_pan_joint">
    <child link="l1"/>   <parent link="base"/>
    <origin rpy="0 0 0" xyz="0 0 1e-1"/>
    <axis xyz="0.0 0.0 1.000"/>
    <limit velocity="2.0" effort="2.37e1" upper="1" lower="-1.0"/>
    <dynamics damping="0" friction="0.0"/>
  </joint>
  <joint name="shoulder_lift_joint" type="revolute"><parent link="l1"/><child link="l2"/>
    <origin xyz="0 0.10 0"/><axis xyz="0 0 1"/>
    <limit lower="-1" upper="1" effort="23.7" velocity="2"/></joint>
  <joint name="elbow_joint" type="revolute"><parent link="l2"/><child link="l3"/>
    <origin xyz="0.3 0 0"/><axis xyz="0 0 1"/>
    <limit lower="-1" upper="1" effort="23.7" velocity="2"/></joint>
""" + "\n".join(link(n, m) for n, m in (("base", 4), ("l1", 1), ("l2", 1), ("l3", 0.5))) \
        .replace('<mass value="4"/>', '<mass value="4.000"/>') + "\n</robot>\n"
    b = write(tmp_path, "b.urdf", reformatted)
    code, out, err = run(a, b)
    assert code == 0, out + err
    assert "are the same robot" in out
    code, out, _ = run(a, b, "--json")
    assert code == 0 and json.loads(out)["same"] is True
    # The check is not blind: a real change in the same file is seen.
    code, out, _ = run(a, write(tmp_path, "c.urdf", reformatted.replace("0 0 1e-1", "0 0 2e-1")))
    assert code == 1 and "origin.xyz" in out


def test_defaults_are_meanings_not_differences() -> None:
    plain = Robot.from_string(arm())
    spelled = Robot.from_string(arm().replace(
        '<axis xyz="0 0 1"/>', '<axis xyz="0 0 1"/><dynamics damping="0"/>'))
    assert diff_robots(plain, spelled).same
    # A fixed joint's axis means nothing; a revolute joint without one turns about x.
    fixed_a = Robot.from_string(arm().replace('type="revolute"', 'type="fixed"'))
    fixed_b = Robot.from_string(arm().replace('type="revolute"', 'type="fixed"')
                                .replace('<axis xyz="0 0 1"/>', '<axis xyz="0 1 0"/>'))
    assert diff_robots(fixed_a, fixed_b).same
    x_axis = Robot.from_string(arm().replace('<axis xyz="0 0 1"/>', '<axis xyz="1 0 0"/>'))
    no_axis = Robot.from_string(arm().replace('<axis xyz="0 0 1"/>', ""))
    assert diff_robots(x_axis, no_axis).same


def test_tolerance(tmp_path: Path) -> None:
    a = write(tmp_path, "a.urdf", arm(effort=23.7))
    b = write(tmp_path, "b.urdf", arm(effort=23.7 + 1e-6))
    assert not diff_files(a, b).same
    assert diff_files(a, b, tolerance=1e-5).same
    assert run(a, b)[0] == 1
    code, out, _ = run(a, b, "--tolerance", "1e-5")
    assert code == 0 and "tolerance 1e-05" in out
    code, out, _ = run(a, b, "--tolerance", "1e-5", "--json")
    assert json.loads(out)["tolerance"] == 1e-5
    # Relative too: a 1e-6 relative change in a large value.
    big_a = write(tmp_path, "c.urdf", arm(effort=1e6))
    big_b = write(tmp_path, "d.urdf", arm(effort=1e6 + 0.5))
    assert diff_files(big_a, big_b, tolerance=1e-6).same
    assert not diff_files(big_a, big_b, tolerance=1e-7).same


def test_a_negative_tolerance_is_bad_input(tmp_path: Path) -> None:
    a = write(tmp_path, "a.urdf", arm())
    with pytest.raises(ParameterError, match="tolerance"):
        diff_files(a, a, tolerance=-1)
    code, out, err = run(a, a, "--tolerance", "-1")
    assert code == 2 and out == ""
    assert err.strip() == "urdfkit: error: --tolerance must be a finite number >= 0, got -1.0"


# --------------------------------------------------------------------------- structure


def test_a_renamed_joint_is_a_rename(tmp_path: Path) -> None:
    a = write(tmp_path, "a.urdf", arm())
    b = write(tmp_path, "b.urdf", arm(names={"shoulder_lift_joint": "shoulder_joint"}))
    result = diff_files(a, b)
    assert [(r.kind, r.old, r.new) for r in result.renamed] == [
        ("joint", "shoulder_lift_joint", "shoulder_joint")]
    assert not (result.added or result.removed or result.changes or result.index_shifts)
    code, out, _ = run(a, b)
    assert code == 1
    row = next(line for line in out.splitlines() if line.startswith("renamed"))
    assert row.split() == ["renamed", "joint", "shoulder_joint", "name", "shoulder_lift_joint",
                           "shoulder_joint"]


def test_a_renamed_joint_with_changed_origin_is_removed_and_added() -> None:
    a = Robot.from_string(arm())
    b = Robot.from_string(arm(names={"elbow_joint": "knee"}).replace(
        '<origin xyz="0.3 0 0"/>', '<origin xyz="0.4 0 0"/>'))
    result = diff_robots(a, b)
    assert [e.name for e in result.removed] == ["elbow_joint"]
    assert [e.name for e in result.added] == ["knee"]


def test_a_link_renamed_with_its_joints() -> None:
    a = Robot.from_string(arm())
    # The link is renamed, and so are the joints on both sides of it.
    b = Robot.from_string(arm(names={"l2": "upper_arm", "shoulder_lift_joint": "lift",
                                     "elbow_joint": "elbow"}))
    result = diff_robots(a, b)
    assert [(r.kind, r.old, r.new) for r in result.renamed] == [
        ("link", "l2", "upper_arm"), ("joint", "shoulder_lift_joint", "lift"),
        ("joint", "elbow_joint", "elbow")]
    assert not (result.added or result.removed or result.changes)
    # A link renamed while its joints keep their names is a rename too, not a parent change.
    c = Robot.from_string(arm(names={"l3": "hand"}))
    result = diff_robots(a, c)
    assert [(r.kind, r.old, r.new) for r in result.renamed] == [("link", "l3", "hand")]
    assert not result.changes


def test_a_robot_renamed_throughout_is_matched_whole() -> None:
    a = Robot.from_string(arm())
    names = {k: f"left_{k}" for k in ("base", "l1", "l2", "l3", "shoulder_pan_joint",
                                       "shoulder_lift_joint", "elbow_joint")}
    b = Robot.from_string(arm(names=names, effort=30))
    result = diff_robots(a, b)
    assert {(r.old, r.new) for r in result.renamed} == set(names.items())
    assert not (result.added or result.removed or result.index_shifts)
    assert changes(result) == {("left_shoulder_pan_joint", "limit.effort"): (23.7, 30)}


def test_a_joint_moved_to_another_parent_is_a_change() -> None:
    a = Robot.from_string(arm())
    b = Robot.from_string(arm().replace('<parent link="l2"/><child link="l3"/>',
                                        '<parent link="l1"/><child link="l3"/>'))
    found = changes(diff_robots(a, b))
    assert found[("elbow_joint", "parent")] == ("l2", "l1")


def test_added_and_removed_links_and_joints() -> None:
    a = Robot.from_string(arm())
    b = Robot.from_string(arm().replace("</robot>", link("tool", 0.2)
                                        + joint("tool_joint", "l3", "tool", "fixed")
                                        + "</robot>"))
    result = diff_robots(a, b)
    assert [(e.kind, e.name, e.index, e.type) for e in result.added] == [
        ("link", "tool", None, None), ("joint", "tool_joint", 3, "fixed")]
    assert not result.removed
    back = diff_robots(b, a)
    assert [(e.kind, e.name) for e in back.removed] == [("link", "tool"), ("joint", "tool_joint")]
    assert back.mass.old == pytest.approx(a_mass(a) + 0.2) and back.mass.changed


def a_mass(robot: Robot) -> float:
    return sum(x.inertial.mass for x in robot.links if x.inertial is not None)


# --------------------------------------------------------------------------- PyBullet indices


def pybullet_indices(p: Any, path: Path) -> dict[str, int]:
    body = p.loadURDF(str(path))
    return {p.getJointInfo(body, i)[1].decode(): i for i in range(p.getNumJoints(body))}


def test_an_inserted_joint_shifts_indices_as_pybullet_does(tmp_path: Path, pb: Any) -> None:
    a = write(tmp_path, "car.urdf", car())
    b = write(tmp_path, "car_camera.urdf", car(camera=True))
    result = diff_files(a, b)
    p, _ = pb
    old, new = pybullet_indices(p, a), pybullet_indices(p, b)
    # The tutorial's hard-coded indices name other joints now.
    assert [j for j, i in sorted(old.items(), key=lambda x: x[1]) if i in (1, 3, 4, 5)] == [
        "left_front_wheel_joint", "right_front_wheel_joint", "left_rear_wheel_joint",
        "right_rear_wheel_joint"]
    shifts = {s.joint: (s.old, s.new) for s in result.index_shifts}
    assert shifts == {name: (old[name], new[name]) for name in old if old[name] != new[name]}
    assert len(shifts) == len(old)  # the camera comes first: every joint moves
    [added_joint] = [e for e in result.added if e.kind == "joint"]
    assert (added_joint.name, added_joint.index) == ("camera_joint", new["camera_joint"])

    code, out, _ = run(a, b, "--json")
    assert code == 1
    doc = json.loads(out)
    assert {s["joint"]: (s["old"], s["new"]) for s in doc["index_shifts"]} == shifts
    code, out, _ = run(a, b)
    row = next(line for line in out.splitlines() if "left_rear_wheel_joint" in line)
    assert row.split() == ["index", "joint", "left_rear_wheel_joint", "jointIndex",
                           str(old["left_rear_wheel_joint"]), str(new["left_rear_wheel_joint"])]


def test_reordering_siblings_shifts_indices_and_nothing_else(tmp_path: Path, pb: Any) -> None:
    text = car()
    first = joint("left_rear_wheel_joint", "base_link", "left_rear_wheel", "continuous",
                  xyz="-0.3 0.2 0")
    swapped = text.replace(first, "").replace('<joint name="left_hinge_joint"',
                                               first + '<joint name="left_hinge_joint"')
    a, b = write(tmp_path, "a.urdf", text), write(tmp_path, "b.urdf", swapped)
    result = diff_files(a, b)
    assert not (result.changes or result.added or result.removed or result.renamed)
    p, _ = pb
    old, new = pybullet_indices(p, a), pybullet_indices(p, b)
    assert {s.joint: (s.old, s.new) for s in result.index_shifts} == {
        n: (old[n], new[n]) for n in old if old[n] != new[n]}
    assert result.index_shifts


def test_a_renamed_joint_keeps_its_index_and_is_no_shift(tmp_path: Path) -> None:
    result = diff_robots(Robot.from_string(car()), Robot.from_string(
        car().replace("left_rear_wheel_joint", "rear_left")))
    assert not result.index_shifts and len(result.renamed) == 1


# --------------------------------------------------------------------------- totals


def test_mass_and_dof_totals() -> None:
    a = Robot.from_string(arm())
    b = Robot.from_string(arm())
    b.add_link(Link(name="ball", inertial=Inertial(mass=1.5, inertia=Inertia(ixx=1, iyy=1,
                                                                             izz=1)),
                    collisions=[Collision(geometry=Sphere(radius=0.1))]))
    b.add_joint(Joint(name="wrist", type="spherical", parent="l3", child="ball"))
    result = diff_robots(a, b)
    assert (result.dof.old, result.dof.new, result.dof.changed) == (3, 6, True)
    assert (result.mass.old, result.mass.new, result.mass.changed) == (6.5, 8.0, True)
    assert result.to_dict()["totals"] == {"mass": {"old": 6.5, "new": 8.0, "changed": True},
                                          "dof": {"old": 3, "new": 6, "changed": True}}


@pytest.mark.parametrize(("kind", "dof"), [("revolute", 1), ("continuous", 1),
                                           ("prismatic", 1), ("fixed", 0), ("planar", 3),
                                           ("floating", 6), ("spherical", 3)])
def test_dof_per_joint_type(kind: str, dof: int) -> None:
    a = Robot.from_string(arm().replace('type="revolute"', 'type="fixed"'))
    b = Robot.from_string(arm().replace('type="revolute"', 'type="fixed"').replace(
        '<joint name="elbow_joint" type="fixed"', f'<joint name="elbow_joint" type="{kind}"'))
    result = diff_robots(a, b)
    assert (result.dof.old, result.dof.new) == (0, dof)
    assert result.dof.changed == (dof != 0)


def test_the_text_shows_totals_that_changed(tmp_path: Path) -> None:
    a = write(tmp_path, "a.urdf", arm())
    b = write(tmp_path, "b.urdf", arm().replace('<mass value="4"/>', '<mass value="5"/>'))
    code, out, _ = run(a, b)
    assert code == 1
    lines = out.splitlines()
    assert next(x for x in lines if "inertial.mass" in x).split()[-2:] == ["4", "5"]
    assert next(x for x in lines if x.startswith("total")).split() == [
        "total", "robot", "arm", "mass", "6.5", "kg", "7.5", "kg"]
    assert not any(" dof " in x for x in lines)


# --------------------------------------------------------------------------- inputs


XACRO = """<?xml version="1.0"?>
<robot name="arm" xmlns:xacro="http://www.ros.org/wiki/xacro">
  <xacro:arg name="effort" default="23.7"/>
  <xacro:property name="e" value="$(arg effort)"/>
  <xacro:macro name="part" params="name mass">
    <link name="${name}"><inertial><mass value="${mass}"/><inertia ixx="0.01" ixy="0" ixz="0"
      iyy="0.01" iyz="0" izz="0.01"/></inertial>
      <visual><geometry><box size="0.1 0.1 0.1"/></geometry></visual>
      <collision><geometry><box size="${0.05 * 2} 0.1 0.1"/></geometry></collision></link>
  </xacro:macro>
  <xacro:part name="base" mass="4"/>
  <xacro:part name="l1" mass="1"/>
  <xacro:part name="l2" mass="1"/>
  <xacro:part name="l3" mass="0.5"/>
  <joint name="shoulder_pan_joint" type="revolute"><parent link="base"/><child link="l1"/>
    <origin xyz="0 0 0.1"/><axis xyz="0 0 1"/>
    <limit lower="-1" upper="1" effort="${e}" velocity="2"/></joint>
  <joint name="shoulder_lift_joint" type="revolute"><parent link="l1"/><child link="l2"/>
    <origin xyz="0 0.1 0"/><axis xyz="0 0 1"/>
    <limit lower="-1" upper="1" effort="23.7" velocity="2"/></joint>
  <joint name="elbow_joint" type="revolute"><parent link="l2"/><child link="l3"/>
    <origin xyz="0.3 0 0"/><axis xyz="0 0 1"/>
    <limit lower="-1" upper="1" effort="23.7" velocity="2"/></joint>
</robot>
"""


def test_xacro_input_and_args(tmp_path: Path) -> None:
    xacro = write(tmp_path, "arm.urdf.xacro", XACRO)
    urdf = write(tmp_path, "arm.urdf", arm())
    code, out, err = run(xacro, urdf)
    assert code == 0, out + err
    result = diff_files(xacro, urdf, xacro_args=["effort:=33.5"])
    assert changes(result) == {("shoulder_pan_joint", "limit.effort"): (33.5, 23.7)}
    code, out, _ = run(urdf, xacro, "--arg", "effort:=33.5", "--json")
    assert code == 1
    [change] = json.loads(out)["changes"]
    assert change == {"kind": "joint", "name": "shoulder_pan_joint", "field": "limit.effort",
                      "old": 23.7, "new": 33.5}


def test_pybullet_data_names_resolve(tmp_path: Path) -> None:
    copy = tmp_path / "kuka_iiwa"
    shutil.copytree(pybullet_data_path() / "kuka_iiwa", copy)
    model = copy / "model.urdf"
    assert diff_files("kuka_iiwa/model.urdf", model).same
    model.write_text(model.read_text().replace('effort="300"', 'effort="320"', 1))
    code, out, _ = run("kuka_iiwa/model.urdf", model)
    assert code == 1
    assert next(x for x in out.splitlines() if "limit.effort" in x).split() == [
        "changed", "joint", "lbr_iiwa_joint_1", "limit.effort", "300", "320"]


@pytest.mark.parametrize("which", [0, 1])
def test_a_missing_file_is_one_line_naming_it(tmp_path: Path, which: int) -> None:
    good = write(tmp_path, "good.urdf", arm())
    missing = tmp_path / "missing.urdf"
    args = [good, missing] if which else [missing, good]
    code, out, err = run(*args)
    assert code == 2 and out == ""
    assert len(err.strip().splitlines()) == 1
    assert err.startswith("urdfkit: error: ") and str(missing) in err and "no such file" in err
    with pytest.raises(InputError):
        diff_files(*args)


def test_malformed_xml_is_one_line_naming_the_file(tmp_path: Path) -> None:
    good = write(tmp_path, "good.urdf", arm())
    bad = write(tmp_path, "bad.urdf", arm().replace("</robot>", "<link name='x'></robot>"))
    code, out, err = run(good, bad)
    assert code == 2 and out == ""
    assert len(err.strip().splitlines()) == 1 and str(bad) in err


def test_a_file_the_model_refuses_is_bad_input_naming_it(tmp_path: Path) -> None:
    good = write(tmp_path, "good.urdf", arm())
    # The guard lets it through, but an <inertial> without <mass> is no value to keep as
    # written: an element is missing (PyBullet refuses it too). The model refuses it, naming
    # the file and the line.
    bad = write(tmp_path, "no_mass.urdf", arm().replace('<mass value="4"/>', "", 1))
    with pytest.raises(ModelError) as caught:
        diff_files(good, bad)
    assert caught.value.file == str(bad) and caught.value.line is not None
    code, out, err = run(good, bad)
    assert code == 2 and out == ""
    assert len(err.strip().splitlines()) == 1 and f"{bad}:" in err and "<mass>" in err


def test_a_guard_refusal_is_still_bad_input(tmp_path: Path) -> None:
    good = write(tmp_path, "good.urdf", arm())
    # What crashes PyBullet or is not URDF stays refused: lenience is the model's, not the
    # guard's.
    bad = write(tmp_path, "loop.urdf", arm().replace('<parent link="l2"/><child link="l3"/>',
                                                     '<parent link="l3"/><child link="l3"/>'))
    with pytest.raises(InputError, match="to itself"):
        diff_files(good, bad)
    code, out, err = run(bad, good)
    assert code == 2 and out == "" and len(err.strip().splitlines()) == 1 and str(bad) in err


def test_a_model_refusal_in_xacro_has_no_false_line(tmp_path: Path) -> None:
    bad = write(tmp_path, "bad.urdf.xacro", XACRO.replace('<mass value="${mass}"/>', "", 1))
    with pytest.raises(ModelError) as caught:
        diff_files(bad, bad)
    assert caught.value.file == str(bad) and caught.value.line is None


# --------------------------------------------------------------------------- JSON


def test_json_schema(tmp_path: Path) -> None:
    a = write(tmp_path, "a.urdf", car())
    b = write(tmp_path, "b.urdf", car(camera=True).replace("right_rear_wheel_joint", "rr")
              .replace('effort="23.7"', 'effort="40"', 1))
    code, out, err = run(a, b, "--json")
    assert code == 1, err
    doc = json.loads(out)
    assert set(doc) == {"a", "b", "same", "tolerance", "links", "joints", "changes",
                        "index_shifts", "totals"}
    assert doc["same"] is False and doc["tolerance"] == 1e-9
    assert doc["a"] == {"file": str(a), "robot": "car", "links": 7, "joints": 6}
    assert doc["b"] == {"file": str(b), "robot": "car", "links": 8, "joints": 7}
    assert doc["links"] == {"added": [{"name": "camera"}], "removed": [], "renamed": []}
    assert doc["joints"]["added"] == [{"name": "camera_joint", "index": 0, "type": "fixed"}]
    assert doc["joints"]["removed"] == []
    assert doc["joints"]["renamed"] == [{"old": "right_rear_wheel_joint", "new": "rr"}]
    assert doc["changes"] == [{"kind": "joint", "name": "left_hinge_joint",
                               "field": "limit.effort", "old": 23.7, "new": 40.0}]
    shift = next(s for s in doc["index_shifts"] if s["joint"] == "rr")
    assert shift == {"joint": "rr", "old_name": "right_rear_wheel_joint", "old": 5, "new": 6}
    assert set(doc["totals"]) == {"mass", "dof"}
    assert doc["totals"]["mass"]["changed"] is True
    assert doc["totals"]["mass"]["new"] == pytest.approx(doc["totals"]["mass"]["old"] + 0.1)
    assert doc["totals"]["dof"] == {"old": 6, "new": 6, "changed": False}


def test_json_of_the_same_robot(tmp_path: Path) -> None:
    a = write(tmp_path, "a.urdf", arm())
    code, out, _ = run(a, a, "--json")
    doc = json.loads(out)
    assert code == 0 and doc["same"] is True and doc["changes"] == []
    assert doc["joints"] == {"added": [], "removed": [], "renamed": []}


def test_a_mimic_follows_its_joint_through_a_rename() -> None:
    elbow_limit = '<limit lower="-1" upper="1" effort="23.7" velocity="2"/></joint>'
    text = arm()
    last = text.rindex(elbow_limit)  # the elbow joint is declared last
    text = (text[:last] + elbow_limit.replace(
        "</joint>", '<mimic joint="shoulder_lift_joint" multiplier="2"/></joint>')
        + text[last + len(elbow_limit):])
    a = Robot.from_string(text)
    assert a.joint("elbow_joint").mimic is not None
    renamed = diff_robots(a, Robot.from_string(text.replace('"shoulder_lift_joint"', '"lift"')))
    assert [(r.old, r.new) for r in renamed.renamed] == [("shoulder_lift_joint", "lift")]
    assert not renamed.changes
    retargeted = diff_robots(a, Robot.from_string(text.replace(
        '<mimic joint="shoulder_lift_joint"', '<mimic joint="shoulder_pan_joint"')))
    assert changes(retargeted) == {("elbow_joint", "mimic.joint"): ("shoulder_lift_joint",
                                                                   "shoulder_pan_joint")}


def test_the_robot_name_is_a_change() -> None:
    result = diff_robots(Robot.from_string(arm()), Robot.from_string(arm(robot="arm2")))
    assert [(c.kind, c.name, c.field, c.old, c.new) for c in result.changes] == [
        ("robot", "arm2", "name", "arm", "arm2")]


def test_help_names_the_input_options() -> None:
    result = CliRunner().invoke(app, ["diff", "--help"], env={"COLUMNS": "200"})
    assert result.exit_code == 0
    for flag in ("--json", "--tolerance", "--package", "--package-path", "--arg", "--no-guard"):
        assert flag in result.stdout


def test_a_new_world_link_above_a_renamed_base_is_not_taken_for_the_root(
        tmp_path: Path) -> None:
    a = Robot.from_string(arm())
    b = Robot.from_string(arm(names={"base": "base_link"}).replace(
        "</robot>", '<link name="world"/>' + joint("world_joint", "world", "base_link", "fixed")
        + "</robot>"))
    result = diff_robots(a, b)
    assert [(r.kind, r.old, r.new) for r in result.renamed] == [("link", "base", "base_link")]
    assert [(e.kind, e.name) for e in result.added] == [("link", "world"),
                                                        ("joint", "world_joint")]
    assert {s.joint: (s.old, s.new) for s in result.index_shifts} == {
        "shoulder_pan_joint": (0, 1), "shoulder_lift_joint": (1, 2), "elbow_joint": (2, 3)}


# --------------------------------------------------------------------------- refused values


def edit(text: str, after: str, old: str, new: str) -> str:
    """``text`` with the first ``old`` after ``after`` replaced by ``new``."""
    start = text.index(after)
    at = text.index(old, start)
    return text[:at] + new + text[at + len(old):]


ELBOW = '<joint name="elbow_joint"'
L1, L3 = '<link name="l1">', '<link name="l3">'
GEOMETRY_END = "</geometry></visual>"
LIMIT = 'lower="-1" upper="1" effort="23.7" velocity="2"'
SPHERE = '<collision><geometry><sphere radius="{r}"/>'
BOX = '<collision><geometry><box size="0.1 0.1 0.1"/>'

#: Values the model refuses to build from, modelled on pybullet_data robots PyBullet loads:
#: (case, the file with the refused value, a second version, the one change between them).
REFUSED = [
    # franka_panda/panda.urdf: an axis of zeros
    ("zero_axis", edit(arm(), ELBOW, '<axis xyz="0 0 1"/>', '<axis xyz="0 0 0"/>'), arm(),
     ("elbow_joint", "axis", (0.0, 0.0, 0.0), (0.0, 0.0, 1.0))),
    # bicycle/bike.urdf (commas), husky/husky.urdf ($(optenv ...)): not numbers, so text
    ("malformed_vector", edit(arm(), ELBOW, 'xyz="0.3 0 0"', 'xyz="0.3, 0, 0"'), arm(),
     ("elbow_joint", "origin.xyz", "0.3, 0, 0", (0.3, 0.0, 0.0))),
    # quadruped/microtaur/microtaur.urdf: four numbers where three belong
    ("four_numbers", edit(arm(), ELBOW, 'xyz="0.3 0 0"', 'xyz="0.3 0 0" rpy="0 0 0 0"'),
     arm(), ("elbow_joint", "origin.rpy", (0.0, 0.0, 0.0, 0.0), (0.0, 0.0, 0.0))),
    # racecar/racecar.urdf: a <material> inside <geometry>, which PyBullet ignores; the shape
    # before it is still compared
    ("material_inside_geometry",
     edit(arm(), L1, GEOMETRY_END, '<material name="grey"/>' + GEOMETRY_END),
     edit(edit(arm(), L1, GEOMETRY_END, '<material name="grey"/>' + GEOMETRY_END), L1,
          'size="0.1 0.1 0.1"', 'size="0.2 0.1 0.1"'),
     ("l1", "visual[0].geometry.size", (0.1, 0.1, 0.1), (0.2, 0.1, 0.1))),
    # biped/biped2d_pybullet.urdf: lower above upper, in both versions
    ("lower_above_upper", edit(arm(), ELBOW, LIMIT, LIMIT.replace('lower="-1" upper="1"',
                                                                 'lower="1" upper="-1"')),
     edit(arm(), ELBOW, LIMIT, LIMIT.replace('lower="-1" upper="1"', 'lower="1" upper="-0.5"')),
     ("elbow_joint", "limit.upper", -1.0, -0.5)),
    # biped/biped2d_pybullet.urdf: lower="-1.57." is no number: compared as its text
    ("not_a_number", edit(arm(), ELBOW, 'lower="-1"', 'lower="-1.57."'),
     edit(arm(), ELBOW, 'lower="-1"', 'lower="-1.57"'),
     ("elbow_joint", "limit.lower", "-1.57.", -1.57)),
    # laikago/laikago_toes.urdf: a sphere of radius 0
    ("zero_radius", edit(arm(), L3, BOX, SPHERE.format(r="0.0")),
     edit(arm(), L3, BOX, SPHERE.format(r="0.01")),
     ("l3", "collision[0].geometry.radius", 0.0, 0.01)),
    # spherical_joint_limit.urdf: a <limit> without velocity
    ("missing_velocity", edit(arm(), ELBOW, ' velocity="2"', ""), arm(),
     ("elbow_joint", "limit.velocity", None, 2.0)),
]


@pytest.mark.parametrize(("broken", "other", "expected"), [c[1:] for c in REFUSED],
                         ids=[c[0] for c in REFUSED])
def test_a_value_the_model_refuses_is_compared_as_written(
        tmp_path: Path, broken: str, other: str, expected: tuple[Any, ...]) -> None:
    with pytest.raises(ModelError):  # building from it is still refused
        Robot.from_string(broken)
    a = write(tmp_path, "a.urdf", broken)
    b = write(tmp_path, "b.urdf", other)
    assert diff_files(a, a).same
    result = diff_files(a, b)
    assert [(c.name, c.field, c.old, c.new) for c in result.changes] == [expected]
    assert result.count == 1

    code, out, err = run(a, b, "--json")
    assert code == 1, err
    [change] = json.loads(out)["changes"]
    name, path, old, new = expected
    assert (change["name"], change["field"]) == (name, path)
    assert change["old"] == (list(old) if isinstance(old, tuple) else old)
    assert run(a, write(tmp_path, "copy.urdf", broken))[0] == 0


def test_a_material_inside_geometry_is_ignored_as_pybullet_ignores_it() -> None:
    inside = edit(arm(), L1, GEOMETRY_END, '<material name="grey"><color rgba="1 0 0 1"/>'
                  "</material>" + GEOMETRY_END)
    assert diff_robots(Robot.from_string(inside, strict=False), Robot.from_string(arm())).same


def test_refused_values_spelled_differently_are_the_same() -> None:
    def same(x: str, y: str) -> bool:
        return diff_robots(Robot.from_string(x, strict=False),
                           Robot.from_string(y, strict=False)).same

    # Numbers compare as numbers, text with its whitespace normalised.
    assert same(edit(arm(), ELBOW, '<axis xyz="0 0 1"/>', '<axis xyz="0 0 0"/>'),
                edit(arm(), ELBOW, '<axis xyz="0 0 1"/>', '<axis xyz="0.0  -0 0e0"/>'))
    assert same(edit(arm(), ELBOW, 'xyz="0.3 0 0"', 'xyz="0.3, 0, 0"'),
                edit(arm(), ELBOW, 'xyz="0.3 0 0"', 'xyz=" 0.3,  0,\n   0"'))
    assert same(edit(arm(), ELBOW, 'effort="23.7"', 'effort="inf"'),
                edit(arm(), ELBOW, 'effort="23.7"', 'effort="+Infinity"'))
    assert not same(edit(arm(), ELBOW, 'xyz="0.3 0 0"', 'xyz="0.3, 0, 0"'),
                    edit(arm(), ELBOW, 'xyz="0.3 0 0"', 'xyz="0.3,0,0"'))


def test_refused_values_in_the_text_report(tmp_path: Path) -> None:
    a = write(tmp_path, "a.urdf", edit(arm(), ELBOW, 'xyz="0.3 0 0"', 'xyz="0.3, 0, 0"'))
    b = write(tmp_path, "b.urdf", arm())
    code, out, err = run(a, b)
    assert code == 1 and err == ""
    row = next(line for line in out.splitlines() if "origin.xyz" in line)
    assert row.split() == ["changed", "joint", "elbow_joint", "origin.xyz", "0.3,", "0,", "0",
                           "0.3", "0", "0"]


def test_a_mass_that_is_no_number_counts_nothing_in_the_total() -> None:
    a = Robot.from_string(arm())
    b = Robot.from_string(arm().replace('<mass value="4"/>', '<mass value="4 kg"/>'),
                          strict=False)
    result = diff_robots(a, b)
    assert changes(result) == {("base", "inertial.mass"): (4.0, "4 kg")}
    assert (result.mass.old, result.mass.new) == (6.5, 2.5)


def test_nameless_inline_materials_of_cad_exports_are_compared_by_colour(tmp_path: Path) -> None:
    # The SolidWorks exporter writes <material name=""> with the colour inline.
    def robot(rgba: str) -> Path:
        path = tmp_path / f"cad_{rgba.replace(' ', '_')}.urdf"
        path.write_text(f'<robot name="cad"><link name="base"><visual><geometry><box size="1 1 1"/>'
                        f'</geometry><material name=""><color rgba="{rgba}"/></material>'
                        '</visual></link></robot>')
        return path

    grey, red = robot("0.7 0.7 0.7 1"), robot("1 0 0 1")
    assert diff_files(grey, grey).same
    changes = diff_files(grey, red).changes
    assert len(changes) == 1 and changes[0].new == (1.0, 0.0, 0.0, 1.0)


def test_two_spellings_of_one_rotation_or_axis_are_not_differences(tmp_path: Path) -> None:
    def robot(rpy: str, axis: str) -> Path:
        path = tmp_path / f"r_{len(list(tmp_path.iterdir()))}.urdf"
        path.write_text(f'<robot name="r"><link name="a"/><link name="b"/><joint name="j" '
                        f'type="revolute"><parent link="a"/><child link="b"/><origin '
                        f'rpy="{rpy}"/><axis xyz="{axis}"/><limit lower="-1" upper="1" '
                        'effort="1" velocity="1"/></joint></robot>')
        return path

    base = robot("0 0 3.141592653589793", "0 0 1")
    assert diff_files(base, robot("0 0 -3.141592653589793", "0 0 2")).same
    flipped = diff_files(base, robot("0 0 3.141592653589793", "0 0 -1"))  # the other way
    assert [c.field for c in flipped.changes] == ["axis"]
    turned = diff_files(base, robot("0 0 1.5707963267948966", "0 0 1"))
    assert [c.field for c in turned.changes] == ["origin.rpy"]


def test_masses_whose_sum_overflows(tmp_path: Path) -> None:
    """Two links of 1e308 kg: each is a float, their sum is not; the total reads inf."""
    huge = ('<robot name="r">' + link("base", 1e308) + link("l1", 1e308)
            + joint("j", "base", "l1") + "</robot>")
    a = write(tmp_path, "a.urdf", huge)
    code, out, err = run(a, a)
    assert (code, err) == (0, "") and "same robot" in out
    b = write(tmp_path, "b.urdf", huge.replace('value="1e+308"', 'value="2"'))
    assert 'value="2"' in b.read_text()
    code, out, err = run(a, b, "--json")
    assert code == 1 and "Traceback" not in err
    doc = json.loads(out)
    assert doc["totals"]["mass"]["old"] is None  # inf has no JSON number: null, and said so
    assert doc["totals"]["mass"]["new"] == pytest.approx(4.0)
    assert "non-finite" in err and len(err.strip().splitlines()) == 1


def test_the_same_robot_is_counted_in_words_of_the_right_number(tmp_path: Path) -> None:
    path = tmp_path / "two.urdf"
    path.write_text('<robot name="t"><link name="a"/><link name="b"/><joint name="j" '
                    'type="fixed"><parent link="a"/><child link="b"/></joint></robot>')
    result = CliRunner().invoke(app, ["diff", str(path), str(path)])
    assert result.exit_code == 0 and "(2 links, 1 joint;" in result.stdout, result.stdout
