"""A misspelt tag or attribute gets the nearest URDF name, from check and from the loaders."""

from __future__ import annotations

import json
from pathlib import Path

from typer.testing import CliRunner

from urdfkit.cli import app

runner = CliRunner()

INERTIAL = ('<inertial><mass value="1"/>'
            '<inertia ixx="0.01" iyy="0.01" izz="0.01" ixy="0" ixz="0" iyz="0"/></inertial>')


def _robot(tmp_path: Path, body: str) -> Path:
    path = tmp_path / "typo.urdf"
    path.write_text(f'<robot name="t">\n<link name="a">{INERTIAL}\n{body}\n</link>\n'
                    f'<link name="b">{INERTIAL}</link>\n'
                    '<joint name="j" type="revolute"><parent link="a"/><child link="b"/>'
                    '<limit lower="-1" upper="1" effort="1" velocity="1"/></joint>\n</robot>\n')
    return path


def _box() -> str:
    return '<geometry><box size="0.1 0.1 0.1"/></geometry>'


def test_check_names_the_tag_meant(tmp_path: Path) -> None:
    path = _robot(tmp_path, f"<colision>{_box()}</colision>")
    out = json.loads(runner.invoke(app, ["check", str(path), "--json", "--no-cache"]).stdout)
    [u801] = [f for f in out["findings"] if f["code"] == "U801"]
    assert "<colision>" in u801["message"] and "did you mean <collision>?" in u801["message"]


def test_check_names_the_attribute_meant(tmp_path: Path) -> None:
    path = _robot(tmp_path, f'<visual><origin xyzz="0 0 1"/>{_box()}</visual>')
    out = json.loads(runner.invoke(app, ["check", str(path), "--json", "--no-cache"]).stdout)
    [u802] = [f for f in out["findings"] if f["code"] == "U802"]
    assert "did you mean 'xyz'?" in u802["message"]


def test_an_unknown_tag_nothing_is_near_gets_no_guess(tmp_path: Path) -> None:
    path = _robot(tmp_path, "<sensor_plugin/>")
    out = json.loads(runner.invoke(app, ["check", str(path), "--json", "--no-cache"]).stdout)
    [u801] = [f for f in out["findings"] if f["code"] == "U801"]
    assert "did you mean" not in u801["message"]


def test_joints_warns_of_a_collision_pybullet_drops(tmp_path: Path, pb: tuple) -> None:
    path = _robot(tmp_path, f"<colision>{_box()}</colision>")
    result = runner.invoke(app, ["joints", str(path)])
    assert result.exit_code == 0
    assert f"{path}:3: <colision> is not a URDF tag inside <link>; did you mean " \
           "<collision>?" in result.stderr
    # ... and what it warns of is true: PyBullet built link a without a collision shape
    p, client = pb
    body = p.loadURDF(str(path), physicsClientId=client)
    assert p.getCollisionShapeData(body, -1, physicsClientId=client) == ()


def test_a_misspelt_joint_is_named_where_the_tree_breaks(tmp_path: Path) -> None:
    path = _robot(tmp_path, "")
    path.write_text(path.read_text().replace("<joint ", "<jiont ").replace("</joint>",
                                                                          "</jiont>"))
    result = runner.invoke(app, ["joints", str(path)])
    assert result.exit_code == 2
    assert "2 root links" in result.stderr
    assert "at line 6, <jiont> is not a URDF tag inside <robot>; did you mean <joint>?" \
        in result.stderr


def test_a_correct_file_gets_no_typo_warning(tmp_path: Path) -> None:
    path = _robot(tmp_path, f"<collision>{_box()}</collision>")
    result = runner.invoke(app, ["joints", str(path)])
    assert result.exit_code == 0 and "not a URDF tag" not in result.stderr


def test_check_names_an_arg_the_xacro_does_not_declare(tmp_path: Path) -> None:
    path = tmp_path / "arm.urdf.xacro"
    path.write_text('<robot name="a" xmlns:xacro="http://www.ros.org/wiki/xacro">'
                    '<xacro:arg name="prefix" default=""/>'
                    f'<link name="$(arg prefix)base">{INERTIAL}</link></robot>')
    result = runner.invoke(app, ["check", str(path), "--arg", "prefx:=left_", "--no-cache"])
    assert result.exit_code == 0
    assert "'prefx' is not an argument of this file or its includes; did you mean " \
           "'prefix'?" in result.stderr
    # a declared one is taken without a word; so is any in a folder walk (by design)
    result = runner.invoke(app, ["check", str(path), "--arg", "prefix:=left_", "--no-cache"])
    assert "not an argument" not in result.stderr
    result = runner.invoke(app, ["check", str(tmp_path), "--arg", "prefx:=left_", "--no-cache"])
    assert "not an argument" not in result.stderr
