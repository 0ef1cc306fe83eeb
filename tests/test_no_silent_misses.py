"""Nothing passes by being skipped: upper-case suffixes, empty folders, unreadable visuals."""

from __future__ import annotations

import json
import shutil
from pathlib import Path

import pytest
from typer.testing import CliRunner

from urdfkit.cli import app

runner = CliRunner()


def _r2d2() -> Path:
    import pybullet_data

    return Path(pybullet_data.getDataPath()) / "r2d2.urdf"


@pytest.mark.parametrize("name", ["ROBOT.URDF", "robot.Urdf"])
def test_check_over_a_folder_finds_upper_case_suffixes(name: str, tmp_path: Path) -> None:
    # PyBullet reads a .URDF as any other name: check must too, or CI passes on "files: 0".
    shutil.copy(_r2d2(), tmp_path / name)
    result = runner.invoke(app, ["check", str(tmp_path), "--json", "--no-cache"])
    out = json.loads(result.stdout)
    assert out["files"] == [str(tmp_path / name)]
    assert any(f["code"] == "U801" for f in out["findings"])  # r2d2's <joint_properties>


def test_an_upper_case_xacro_is_expanded(tmp_path: Path) -> None:
    (tmp_path / "ARM.XACRO").write_text(
        '<robot name="a" xmlns:xacro="http://www.ros.org/wiki/xacro">'
        '<xacro:property name="m" value="-1"/>'
        '<link name="base"><inertial><mass value="${m}"/>'
        '<inertia ixx="1" iyy="1" izz="1" ixy="0" ixz="0" iyz="0"/></inertial></link></robot>')
    result = runner.invoke(app, ["check", str(tmp_path), "--json", "--no-cache"])
    out = json.loads(result.stdout)
    assert out["files"] == [str(tmp_path / "ARM.XACRO")]
    # the mass is the property's value: the file was expanded, not parsed as it stands
    assert any("-1" in f["message"] and "mass" in f["message"] for f in out["findings"]), out


def test_a_folder_without_robot_files_is_said_and_strict_refuses_it(tmp_path: Path) -> None:
    (tmp_path / "notes.txt").write_text("no robot here")
    result = runner.invoke(app, ["check", str(tmp_path)])
    assert result.exit_code == 0
    assert f"{tmp_path}: no robot file in this folder" in result.stderr
    result = runner.invoke(app, ["check", str(tmp_path), "--strict"])
    assert result.exit_code == 2 and "--strict" in result.stderr
    # a folder that has one is not warned about, strict or not
    shutil.copy(_r2d2(), tmp_path / "r2d2.urdf")
    result = runner.invoke(app, ["check", str(tmp_path), "--strict"])
    assert result.exit_code == 0 and "no robot file" not in result.stderr


def test_fix_diff_headers_have_one_slash_before_an_absolute_path(tmp_path: Path) -> None:
    shutil.copy(_r2d2(), tmp_path / "r2d2.urdf")
    result = runner.invoke(app, ["fix", str(tmp_path / "r2d2.urdf"), "--diff"])
    head = result.stdout.splitlines()[:2]
    assert head == [f"--- a{tmp_path}/r2d2.urdf", f"+++ b{tmp_path}/r2d2.urdf"], head
