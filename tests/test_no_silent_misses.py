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


def _instance_node_dae(tmp_path: Path) -> tuple[Path, Path]:
    """pybullet_data's cone.dae as it is, and with its node moved into <library_nodes>."""
    import pybullet_data

    text = (Path(pybullet_data.getDataPath()) / "racecar/meshes/cone.dae").read_text()
    start = text.index('<node name="SketchUp">')
    end = text.index("</node>", start) + len("</node>")
    node = text[start:end].replace('<node name="SketchUp">', '<node id="N1" name="SketchUp">')
    moved = (text[:start] + '<node name="top"><instance_node url="#N1"/></node>' + text[end:])
    moved = moved.replace("<library_geometries>",
                          f"<library_nodes>{node}</library_nodes><library_geometries>", 1)
    (tmp_path / "cone.dae").write_text(text)
    (tmp_path / "inode.dae").write_text(moved)
    return tmp_path / "cone.dae", tmp_path / "inode.dae"


def _one_visual(tmp_path: Path, mesh: str) -> Path:
    path = tmp_path / f"{mesh}.urdf"
    path.write_text(f'<robot name="r"><link name="a"><inertial><mass value="1"/><inertia ixx="1" '
                    'iyy="1" izz="1" ixy="0" ixz="0" iyz="0"/></inertial><visual><geometry>'
                    f'<mesh filename="{mesh}" scale="3 3 3"/></geometry></visual>'
                    '<collision><geometry><sphere radius="0.01"/></geometry></collision>'
                    '</link></robot>')
    return path


def _pixels(pb: tuple, urdf: Path) -> int:
    """Pixels of the robot in PyBullet's own TinyRenderer picture."""
    import numpy as np

    p, client = pb
    body = p.loadURDF(str(urdf), physicsClientId=client)
    view = p.computeViewMatrix([2, 2, 2], [0, 0, 0.5], [0, 0, 1])
    proj = p.computeProjectionMatrixFOV(60, 1, 0.01, 10)
    img = p.getCameraImage(64, 64, view, proj, renderer=p.ER_TINY_RENDERER,
                           physicsClientId=client)
    p.removeBody(body, physicsClientId=client)
    return int((np.array(img[4]).reshape(64, 64) == body).sum())


def test_a_collada_through_instance_node_is_a_finding_and_render_says_so(
        tmp_path: Path, pb: tuple) -> None:
    _instance_node_dae(tmp_path)
    good, bad = _one_visual(tmp_path, "cone.dae"), _one_visual(tmp_path, "inode.dae")
    # what the finding claims, seen in PyBullet itself: the same cone, drawn, then not
    assert _pixels(pb, good) > 20 and _pixels(pb, bad) == 0
    out = json.loads(runner.invoke(app, ["check", str(bad), "--json", "--no-cache"]).stdout)
    [u715] = [f for f in out["findings"] if f["code"] == "U715"]
    assert "2 part(s), all placed through <instance_node>" in u715["message"]
    out = json.loads(runner.invoke(app, ["check", str(good), "--json", "--no-cache"]).stdout)
    assert not [f for f in out["findings"] if f["code"] == "U715"]
    result = runner.invoke(app, ["render", str(bad), "-o", str(tmp_path / "r.png"),
                                 "--size", "64x48"])
    assert result.exit_code == 0 and "1 of 1 visual shape(s) cannot be drawn" in result.stderr
    result = runner.invoke(app, ["render", str(good), "-o", str(tmp_path / "g.png"),
                                 "--size", "64x48"])
    assert "cannot be drawn" not in result.stderr


def test_an_empty_visual_mesh_is_a_finding(tmp_path: Path) -> None:
    (tmp_path / "empty.stl").write_bytes(b"")
    out = json.loads(runner.invoke(app, ["check", str(_one_visual(tmp_path, "empty.stl")),
                                         "--json", "--no-cache"]).stdout)
    assert [f["message"] for f in out["findings"] if f["code"] == "U715"] == [
        "visual mesh 'empty.stl' of <link name='a'> is empty: PyBullet draws nothing of it; "
        "the robot looks incomplete in render, view and the GUI (export it with its nodes "
        "flattened, or as .obj/.stl)"]


def test_view_says_how_many_shapes_it_cannot_draw(tmp_path: Path) -> None:
    pytest.importorskip("viser", reason="urdfkit view needs viser (a core dependency)")
    from urdfkit.draw import view_page
    from urdfkit.draw.view import Viewer

    _instance_node_dae(tmp_path)
    v = Viewer(str(_one_visual(tmp_path, "inode.dae")), watch=False)
    try:
        said = view_page.findings(v.model)
        assert "1 of 1 visual shape(s) cannot be drawn" in said and "(U715)" in said
    finally:
        v.close()
