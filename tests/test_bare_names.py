"""Every command that reads a robot file finds a bare pybullet_data name the same way.

The README says a bare name is looked up in pybullet_data; ``check`` and ``fix`` once said
"no such file" where ``joints`` found it. Each command runs from an empty folder, where the
name can only be found in pybullet_data, and must read the very file there.
"""

from __future__ import annotations

import json
from pathlib import Path

import pytest
from typer.testing import CliRunner

from urdfkit.cli import app

runner = CliRunner()


def _data() -> Path:
    import pybullet_data

    return Path(pybullet_data.getDataPath())


@pytest.mark.parametrize("args", [
    ["joints", "r2d2.urdf", "--json"], ["links", "r2d2.urdf", "--json"],
    ["tree", "r2d2.urdf"], ["info", "r2d2.urdf", "--json"], ["check", "r2d2.urdf", "--json"],
    ["diff", "r2d2.urdf", "r2d2.urdf"], ["fix", "r2d2.urdf", "-o", "out.urdf"],
    ["render", "r2d2.urdf", "-o", "out.png", "--size", "64x48"],
    ["collisions", "r2d2.urdf", "--json"],
    ["drive", "--urdf", "r2d2.urdf", "--seconds", "0.2", "--json"]])
def test_every_command_finds_a_bare_name(args: list[str], tmp_path: Path,
                                         monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.chdir(tmp_path)
    assert not (tmp_path / "r2d2.urdf").exists()
    result = runner.invoke(app, args)
    assert "no such file" not in result.stderr, result.stderr
    assert result.exit_code in (0, 1), result.stderr  # 1: findings (collisions, fix's left)
    if args[0] == "joints":  # the file read is pybullet_data's: its 15 joints
        import xml.etree.ElementTree as ET

        want = len(ET.parse(_data() / "r2d2.urdf").getroot().findall("joint"))
        assert len(json.loads(result.stdout)["joints"]) == want == 15
    if args[0] == "fix":
        assert (tmp_path / "out.urdf").read_bytes() != (_data() / "r2d2.urdf").read_bytes()
    if args[0] == "render":
        assert (tmp_path / "out.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


def test_build_expands_a_bare_name_found_in_pybullet_data(
        tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    # drive and joints say of pybullet_data's husky "holds xacro ...: expand it first: urdfkit
    # build FILE" (U009); build once answered "neither a template nor a file" for that name.
    import xml.etree.ElementTree as ET

    monkeypatch.chdir(tmp_path)
    result = runner.invoke(app, ["build", "husky/husky.urdf"])
    assert result.exit_code == 0, result.stderr
    written = tmp_path / "husky.expanded.urdf"  # here, never beside pybullet_data's file
    links = [el.get("name") for el in ET.parse(written).getroot().iter("link")]
    assert links == [el.get("name") for el in
                     ET.parse(_data() / "husky" / "husky.urdf").getroot().iter("link")]
    imu = next(j for j in ET.parse(written).getroot().iter("joint")
               if j.get("name") == "imu_joint").find("origin")
    assert imu is not None  # $(optenv HUSKY_IMU_XYZ 0.19 0 0.149) expanded to its default
    assert imu.get("xyz") == "0.19 0 0.149" and imu.get("rpy") == "0 -1.5708 3.1416"
    assert not (_data() / "husky" / "husky.expanded.urdf").exists()


def test_fix_in_place_refuses_to_rewrite_pybullet_data(tmp_path: Path,
                                                       monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.chdir(tmp_path)
    before = (_data() / "r2d2.urdf").read_bytes()
    result = runner.invoke(app, ["fix", "r2d2.urdf", "--in-place"])
    assert result.exit_code == 2 and "found in pybullet_data" in result.stderr
    result = runner.invoke(app, ["fix", "simplecar", "--in-place"])
    assert result.exit_code == 2 and "a built-in template" in result.stderr
    assert (_data() / "r2d2.urdf").read_bytes() == before


def test_a_misspelt_bare_name_in_check_gets_a_suggestion(tmp_path: Path,
                                                         monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.chdir(tmp_path)
    result = runner.invoke(app, ["check", "r2d3.urdf"])
    assert result.exit_code == 2 and "did you mean 'r2d2.urdf'?" in result.stderr


@pytest.mark.parametrize("args", [
    ["joints", "simplecar", "--json"], ["links", "simplecar", "--json"], ["tree", "simplecar"],
    ["info", "simplecar", "--json"], ["check", "simplecar", "--json"],
    ["diff", "simplecar", "built.urdf"], ["fix", "simplecar", "-o", "out.urdf"],
    ["render", "simplecar", "-o", "out.png", "--size", "64x48"],
    ["collisions", "simplecar", "--json"], ["export", "mjcf", "simplecar", "-o", "out.xml"],
    ["drive", "--urdf", "simplecar", "--seconds", "0.2", "--json"]])
def test_every_command_reads_a_template_name(args: list[str], tmp_path: Path,
                                             monkeypatch: pytest.MonkeyPatch) -> None:
    # Issue 49: `joints simplecar`, `render simplecar`, `export mjcf simplecar` said "no such
    # file"; a template name is the template built with its defaults, as drive drives it.
    from urdfkit.model.catalog import build_template

    monkeypatch.chdir(tmp_path)
    (tmp_path / "built.urdf").write_bytes(build_template("simplecar").to_bytes())
    result = runner.invoke(app, args)
    assert "no such file" not in result.stderr, result.stderr
    assert result.exit_code == 0, result.stderr
    assert not (tmp_path / "simplecar.urdf").exists()  # nothing written here
    if args[0] == "joints":
        names = [j["jointName"] for j in json.loads(result.stdout)["joints"]]
        assert names == [j.name for j in build_template("simplecar").joints]
    if args[0] == "info":
        assert json.loads(result.stdout)["robot"] == "simplecar"
    if args[0] == "diff":  # the very robot `urdfkit build simplecar` writes
        assert "are the same robot" in result.stdout


def test_a_file_here_wins_over_a_template_and_a_typo_is_told(
        tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.chdir(tmp_path)
    (tmp_path / "simplecar").write_text('<robot name="mine"><link name="only"/></robot>')
    result = runner.invoke(app, ["info", "simplecar", "--json"])
    assert result.exit_code == 0 and json.loads(result.stdout)["robot"] == "mine"
    result = runner.invoke(app, ["joints", "simplecr"])
    assert result.exit_code == 2 and "did you mean 'simplecar'?" in result.stderr
