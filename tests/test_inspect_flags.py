"""joints/links/info say which loadURDF flags they used, and --flags matches the user's own call
(issue 24.14-15): checked against raw PyBullet."""

from __future__ import annotations

import json
from pathlib import Path

import pybullet as p
import pybullet_data
import pytest
from typer.testing import CliRunner

from urdfkit.cli import app

R2D2 = str(Path(pybullet_data.getDataPath()) / "r2d2.urdf")


def _json(*args: str) -> dict:
    result = CliRunner().invoke(app, [*args, "--json"])
    assert result.exit_code == 0, result.stderr
    return json.loads(result.stdout)


def _raw_inertia(flags: int) -> dict[str, list[float]]:
    c = p.connect(p.DIRECT)
    try:
        body = p.loadURDF(R2D2, flags=flags, physicsClientId=c)
        names = {i: p.getJointInfo(body, i, physicsClientId=c)[12].decode()
                 for i in range(p.getNumJoints(body, physicsClientId=c))}
        return {names[i]: list(p.getDynamicsInfo(body, i, physicsClientId=c)[2])
                for i in names}
    finally:
        p.disconnect(physicsClientId=c)


@pytest.mark.parametrize(("given", "flags", "names"), [
    (None, p.URDF_USE_IMPLICIT_CYLINDER, ["URDF_USE_IMPLICIT_CYLINDER"]),
    ("none", 0, []),
    ("INERTIA_FROM_FILE,URDF_USE_IMPLICIT_CYLINDER",
     p.URDF_USE_INERTIA_FROM_FILE | p.URDF_USE_IMPLICIT_CYLINDER,
     ["URDF_USE_INERTIA_FROM_FILE", "URDF_USE_IMPLICIT_CYLINDER"]),
])
def test_links_equal_raw_pybullet_under_the_flags_they_state(given: str | None, flags: int,
                                                             names: list[str]) -> None:
    data = _json("links", R2D2, *(["--flags", given] if given else []))
    assert data["load_flags"] == names
    raw = _raw_inertia(flags)
    ours = {link["linkName"]: link["local_inertia_diagonal"] for link in data["links"]
            if link["linkIndex"] >= 0}
    assert ours.keys() == raw.keys()
    for name, diagonal in raw.items():
        assert ours[name] == pytest.approx(diagonal, rel=1e-12), name


def test_the_default_and_a_plain_load_differ_for_a_cylinder() -> None:
    # Not vacuous: r2d2's wheels are cylinders, whose inertia the flag changes.
    plain, implicit = _raw_inertia(0), _raw_inertia(p.URDF_USE_IMPLICIT_CYLINDER)
    assert any(plain[k] != pytest.approx(implicit[k], rel=1e-3) for k in plain)


def test_joints_show_the_files_origin_beside_pybullets_frame() -> None:
    data = _json("joints", R2D2)
    assert data["load_flags"] == ["URDF_USE_IMPLICIT_CYLINDER"]
    from lxml import etree

    written = {j.get("name"): j.find("origin") for j in etree.parse(R2D2).getroot().iter("joint")}
    for j in data["joints"]:
        origin = written[j["jointName"]]
        xyz = [float(x) for x in (origin.get("xyz") if origin is not None
                                  and origin.get("xyz") else "0 0 0").split()]
        assert j["originXyz"] == pytest.approx(xyz)
    # PyBullet's parentFramePos is relative to the parent's centre of mass: not the file's
    assert any(j["parentFramePos"] != pytest.approx(j["originXyz"]) for j in data["joints"])
    text = CliRunner().invoke(app, ["joints", R2D2]).stdout
    assert "loaded with URDF_USE_IMPLICIT_CYLINDER" in text


def test_flags_refuse_a_name_pybullet_lacks_and_a_double_inertia_option() -> None:
    bad = CliRunner().invoke(app, ["info", R2D2, "--flags", "bogus"])
    assert bad.exit_code == 2 and "not a PyBullet loadURDF flag" in bad.stderr
    both = CliRunner().invoke(app, ["links", R2D2, "--flags", "none", "--inertia-from-file"])
    assert both.exit_code == 2 and "not both" in both.stderr


def test_the_axis_column_is_the_files_and_jointaxis_pybullets(tmp_path: Path) -> None:
    """PyBullet's jointAxis is in the child's inertial frame: an <inertial><origin rpy> turns
    it. The table's axis (JSON axisXyz) is the file's; jointAxis stays PyBullet's own."""
    import json
    import subprocess
    import sys

    import pybullet as p

    path = tmp_path / "turned.urdf"
    inertial = ('<inertial><origin rpy="0.9 0 0.6"/><mass value="1"/><inertia ixx="0.01" '
                'iyy="0.01" izz="0.01" ixy="0" ixz="0" iyz="0"/></inertial>')
    path.write_text(f'<robot name="t"><link name="a">{inertial}</link><link name="b">'
                    f'{inertial}</link><joint name="j" type="revolute"><parent link="a"/>'
                    '<child link="b"/><axis xyz="0 1 0"/><limit lower="-1" upper="1" '
                    'effort="1" velocity="1"/></joint></robot>')
    c = p.connect(p.DIRECT)
    try:
        raw = p.getJointInfo(p.loadURDF(str(path), physicsClientId=c), 0,
                             physicsClientId=c)[13]
    finally:
        p.disconnect(physicsClientId=c)
    r = subprocess.run([sys.executable, "-m", "urdfkit", "joints", str(path), "--json"],
                       capture_output=True, text=True, timeout=60)
    joint = json.loads(r.stdout)["joints"][0]
    assert joint["jointAxis"] == list(raw) and abs(raw[1]) < 0.6  # PyBullet's, turned
    assert joint["axisXyz"] == [0.0, 1.0, 0.0]  # the file's
    text = subprocess.run([sys.executable, "-m", "urdfkit", "joints", str(path), "--all"],
                          capture_output=True, text=True, timeout=60, env={
                              **__import__("os").environ, "COLUMNS": "400"}).stdout
    header, row = text.splitlines()[1], text.splitlines()[2]
    assert "jointAxis" in header and " 0 1 0 " in row
