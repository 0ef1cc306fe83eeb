"""Files with foreign elements, as ROS packages ship them (issue 24.8): a <xacro:arg> left in a
.urdf, <gazebo> extensions, <transmission>. No command crashes, and fix keeps them byte for
byte while it repairs the rest."""

from __future__ import annotations

from pathlib import Path

import pytest
from typer.testing import CliRunner

from urdfkit.cli import app

ROBOT = """<?xml version="1.0"?>
<robot name="r" xmlns:xacro="http://ros.org/wiki/xacro">
  <xacro:arg name="prefix" default=""/>
  <link name="base">
    <inertial><mass value="2"/><inertia ixx="1" iyy="1" izz="5" ixy="0" ixz="0" iyz="0"/>
    </inertial>
    <collision><geometry><box size="0.4 0.2 0.2"/></geometry></collision>
  </link>
  <link name="arm">
    <inertial><mass value="1"/>
      <inertia ixx="0.01" iyy="0.01" izz="0.01" ixy="0" ixz="0" iyz="0"/></inertial>
    <collision><geometry><box size="0.1 0.1 0.5"/></geometry></collision>
  </link>
  <joint name="j" type="revolute"><parent link="base"/><child link="arm"/><axis xyz="0 1 0"/>
    <limit lower="-1" upper="1" effort="1" velocity="1"/></joint>
  <gazebo reference="arm"><material>Gazebo/Orange</material><mu1>0.2</mu1></gazebo>
  <gazebo><plugin name="p" filename="libgazebo_ros_control.so"><robotNamespace>/r</robotNamespace>
  </plugin></gazebo>
  <transmission name="t"><type>transmission_interface/SimpleTransmission</type>
    <joint name="j"><hardwareInterface>EffortJointInterface</hardwareInterface></joint>
    <actuator name="m"><mechanicalReduction>1</mechanicalReduction></actuator></transmission>
</robot>
"""
FOREIGN = ('<xacro:arg name="prefix" default=""/>',
           '<gazebo reference="arm"><material>Gazebo/Orange</material><mu1>0.2</mu1></gazebo>',
           '<actuator name="m"><mechanicalReduction>1</mechanicalReduction></actuator>')


@pytest.mark.parametrize("args", [
    ["check", "{F}"], ["joints", "{F}", "--json"], ["links", "{F}"], ["tree", "{F}"],
    ["info", "{F}"], ["collisions", "{F}", "--samples", "3"],
    ["render", "{F}", "-o", "{D}/r.png", "--size", "64x48"], ["fix", "{F}", "--diff"],
    ["diff", "{F}", "{F}"], ["drive", "--urdf", "{F}", "--steps", "10"],
])
def test_no_command_crashes_on_foreign_elements(tmp_path: Path, args: list[str]) -> None:
    path = tmp_path / "r.urdf"
    path.write_text(ROBOT)
    argv = [a.replace("{F}", str(path)).replace("{D}", str(tmp_path)) for a in args]
    result = CliRunner().invoke(app, argv)
    assert result.exit_code in (0, 1, 2), result.output
    assert "Traceback" not in result.stderr and "internal error" not in result.stderr
    if result.exit_code == 2:  # a refusal names the file, in one line
        lines = [ln for ln in result.stderr.splitlines() if "warning" not in ln]
        assert len(lines) == 1 and "r.urdf" in lines[0]


def test_fix_repairs_around_foreign_elements_and_keeps_them(tmp_path: Path) -> None:
    path = tmp_path / "r.urdf"
    path.write_text(ROBOT)
    out = tmp_path / "fixed.urdf"
    result = CliRunner().invoke(app, ["fix", str(path), "-o", str(out)])
    assert result.exit_code == 0, result.output
    assert "fixed U604 link 'base'" in result.stdout  # 1 + 1 < 5: the triangle inequality
    fixed = out.read_text()
    for element in FOREIGN:
        assert element in fixed
    assert fixed.count("\n") == ROBOT.count("\n")  # one <inertia> rewritten in place
