"""`urdfkit joints/links/tree/info` as users call them: JSON contract, tables, error paths."""

from __future__ import annotations

import json
import os
import re
import subprocess
import sys
from pathlib import Path

import pytest
from typer.testing import CliRunner

from urdfkit.cli import app
from urdfkit.commands import present as show
from urdfkit.engine.session import LoadOptions
from urdfkit.inspect import JOINT_INFO_FIELDS
from urdfkit.model.spec import PYBULLET_JOINT_CODES as JOINT_TYPE_NAMES
from urdfkit.sources.resolve import pybullet_data_path

ROOT = Path(__file__).resolve().parent.parent
GOLDEN = Path(__file__).parent / "golden"
XACRO = ROOT / "templates" / "simplecar.urdf.xacro"

#: pybullet_data's own robots: every joint type PyBullet knows, meshes, quirky XML.
CORPUS = [
    "r2d2.urdf", "racecar/racecar.urdf", "kuka_iiwa/model.urdf", "humanoid/humanoid.urdf",
    "quadruped/minitaur.urdf", "husky/husky.urdf", "franka_panda/panda.urdf",
    "xarm/xarm6_robot.urdf", "laikago/laikago.urdf", "a1/a1.urdf", "cartpole.urdf",
    "quadruped/vision60.urdf", "biped/biped2d_pybullet.urdf",
]

# Two links PyBullet complains about on C-level stdout: neither has <inertial>.
CHATTY = """<robot name="chatty">
  <link name="base"><collision><geometry><box size="1 1 1"/></geometry></collision></link>
  <link name="arm"/>
  <joint name="j" type="revolute"><parent link="base"/><child link="arm"/>
    <limit lower="-1" upper="1" effort="1" velocity="1"/></joint>
</robot>
"""


def run(*args: str, env: dict[str, str] | None = None) -> tuple[int, str, str]:
    result = CliRunner().invoke(app, list(args), env=env)
    return result.exit_code, result.stdout, result.stderr


def subprocess_run(*args: str, env: dict[str, str] | None = None,
                   cwd: Path | None = None) -> subprocess.CompletedProcess[str]:
    full_env = {**os.environ, **(env or {})}
    return subprocess.run([sys.executable, "-m", "urdfkit", *args], capture_output=True,
                          text=True, timeout=60, env=full_env, cwd=cwd)


@pytest.mark.parametrize("name", CORPUS)
def test_json_agrees_with_raw_getjointinfo(name: str, pb) -> None:
    """The JSON contract: the 17 Quickstart Guide keys, with PyBullet's own values."""
    code, out, err = run("joints", name, "--json")
    assert code == 0, err
    data = json.loads(out)
    path = pybullet_data_path() / name  # type: ignore[operator]
    assert data["file"] == name and Path(data["path"]) == path
    p, client = pb
    body = p.loadURDF(str(path), flags=LoadOptions().flags(p), physicsClientId=client)
    assert data["base_link"] == p.getBodyInfo(body, physicsClientId=client)[0].decode()
    assert len(data["joints"]) == p.getNumJoints(body, physicsClientId=client)
    for joint in data["joints"]:
        raw = p.getJointInfo(body, joint["jointIndex"], physicsClientId=client)
        assert list(joint)[:17] == list(JOINT_INFO_FIELDS)
        for key, value in zip(JOINT_INFO_FIELDS, raw, strict=False):
            if isinstance(value, bytes):
                value = value.decode()
            elif isinstance(value, tuple):
                value = list(value)
            if key == "jointType":
                value = JOINT_TYPE_NAMES[value]
            assert joint[key] == value, f"{name} joint {joint['jointIndex']} {key}"
        parent = raw[16]
        expected_parent = data["base_link"] if parent < 0 else \
            p.getJointInfo(body, parent, physicsClientId=client)[12].decode()
        assert joint["parentLinkName"] == expected_parent


def test_json_marks_continuous_joints() -> None:
    code, out, _ = run("joints", "r2d2.urdf", "--json", "--type", "continuous")
    assert code == 0
    joints = json.loads(out)["joints"]
    assert [j["jointName"] for j in joints] == [
        "right_front_wheel_joint", "right_back_wheel_joint", "left_front_wheel_joint",
        "left_back_wheel_joint", "head_swivel"]
    for j in joints:
        assert (j["jointType"], j["urdfType"], j["limited"]) == ("REVOLUTE", "continuous", False)
    assert (joints[0]["jointLowerLimit"], joints[0]["jointUpperLimit"]) == (0.0, -1.0)
    # head_swivel is continuous with a <limit>: PyBullet reports the numbers but enforces no
    # limit on a continuous joint, so it is still not "limited".
    assert (joints[4]["jointLowerLimit"], joints[4]["jointUpperLimit"]) == (-0.38, 0.0)


def test_movable_filter() -> None:
    code, out, _ = run("joints", "r2d2.urdf", "--json", "--movable")
    assert code == 0
    assert {j["jointType"] for j in json.loads(out)["joints"]} == {"REVOLUTE", "PRISMATIC"}


def test_unknown_type_is_an_error() -> None:
    code, out, err = run("joints", "r2d2.urdf", "--type", "hinge")
    assert code == 2 and out == ""
    assert "'hinge' is not a joint type" in err


def test_golden_simplecar_table(simplecar_urdf: Path) -> None:
    # Piped (as here): plain aligned columns.
    code, out, err = run("joints", str(simplecar_urdf), env={"COLUMNS": "140", "NO_COLOR": "1"})
    assert code == 0, err
    assert out == (GOLDEN / "simplecar_joints.txt").read_text()
    assert "│" not in out and "…" not in out


def test_golden_simplecar_table_on_a_terminal(simplecar_urdf: Path,
                                              monkeypatch: pytest.MonkeyPatch) -> None:
    # On a terminal: the rich table, with the same columns as the plain one.
    monkeypatch.setattr(show, "styled", lambda stream: True)
    code, out, err = run("joints", str(simplecar_urdf), env={"COLUMNS": "140", "NO_COLOR": "1"})
    assert code == 0, err
    assert out == (GOLDEN / "simplecar_joints_terminal.txt").read_text()
    plain = (GOLDEN / "simplecar_joints.txt").read_text().splitlines()
    rich_headers = [h.strip() for h in out.splitlines()[1].split("┃")]
    plain_headers = re.split(r"\s{2,}", plain[1].strip())
    assert rich_headers == plain_headers[:len(rich_headers)]
    assert rich_headers[:3] == ["#", "joint", "type"] and len(rich_headers) > 5


def test_golden_simplecar_tree(simplecar_urdf: Path) -> None:
    code, out, err = run("tree", str(simplecar_urdf), env={"COLUMNS": "100", "NO_COLOR": "1"})
    assert code == 0, err
    assert out == (GOLDEN / "simplecar_tree.txt").read_text()


def test_table_fits_the_terminal(simplecar_urdf: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setattr(show, "styled", lambda stream: True)
    for width in (60, 90, 200):
        code, out, _ = run("joints", str(simplecar_urdf), env={"COLUMNS": str(width)})
        assert code == 0
        assert max(len(line) for line in out.splitlines()) <= width
        assert "base_to_right_back_wheel" in out
    _, narrow, _ = run("joints", str(simplecar_urdf), env={"COLUMNS": "60"})
    _, wide, _ = run("joints", str(simplecar_urdf), env={"COLUMNS": "200"})
    assert "child link" not in narrow and "child link" in wide and "unlimited" in wide
    # What does not fit is announced, not silently dropped.
    assert "column(s) hidden" in narrow and "--all" in narrow
    hidden = [int(x) for x in re.findall(r"(\d+) column\(s\) hidden", wide + narrow)]
    assert len(hidden) == 2 and 0 < hidden[0] < hidden[1]  # fewer hidden when wider


def test_piped_tables_keep_every_column(simplecar_urdf: Path) -> None:
    # Piped, a narrow $COLUMNS does not cut columns: a log or `| grep` loses nothing.
    _, narrow, _ = run("joints", str(simplecar_urdf), env={"COLUMNS": "40"})
    _, wide, _ = run("joints", str(simplecar_urdf), env={"COLUMNS": "300"})
    assert narrow == wide
    header = narrow.splitlines()[1]
    for column in ("child link", "parent", "axis", "max vel", "damping", "friction"):
        assert column in header
    assert "quat" not in header  # --all only, as on the widest terminal
    _, everything, _ = run("joints", str(simplecar_urdf), "--all", env={"COLUMNS": "40"})
    assert "quat" in everything.splitlines()[1] and "flags" in everything.splitlines()[1]


def test_all_shows_every_field(simplecar_urdf: Path) -> None:
    _, wide, _ = run("joints", str(simplecar_urdf), "--all", env={"COLUMNS": "400"})
    _, narrow, _ = run("joints", str(simplecar_urdf), "--all", env={"COLUMNS": "80"})
    for out in (wide, narrow):
        for header in ("quat", "flags", "damping", "friction", "max vel", "rpy"):
            assert header in out
        assert "…" not in out


def test_clean_stdout_on_a_chatty_file(tmp_path: Path) -> None:
    """PyBullet prints on C-level stdout; that must never reach urdfkit's stdout."""
    path = tmp_path / "chatty.urdf"
    path.write_text(CHATTY)
    for command in ("joints", "links", "info"):
        proc = subprocess_run(command, str(path), "--json")
        assert proc.returncode == 0, proc.stderr
        data = json.loads(proc.stdout)
        assert "No inertial data for link 'arm', using mass=1, localinertiadiagonal = 1,1,1, " \
            "identity local inertial frame" in data["diagnostics"]
        assert "b3Warning" not in proc.stdout + proc.stderr
        assert "pybullet build time" not in proc.stdout + proc.stderr
    # Tables: PyBullet's words go to stderr as warnings.
    proc = subprocess_run("joints", str(path))
    assert proc.returncode == 0
    assert "No inertial data" not in proc.stdout
    assert "urdfkit: warning: pybullet: No inertial data for link 'arm'" in proc.stderr


CRASHERS = {
    "two_roots": '<robot name="r"><link name="a"/><link name="b"/></robot>',
    "two_parents": '<robot name="r"><link name="a"/><link name="b"/><link name="c"/>'
                   '<joint name="j1" type="fixed"><parent link="a"/><child link="c"/></joint>'
                   '<joint name="j2" type="fixed"><parent link="b"/><child link="c"/></joint>'
                   '</robot>',
    "cycle": '<robot name="r"><link name="a"/><link name="b"/><link name="c"/>'
             '<joint name="j0" type="fixed"><parent link="a"/><child link="b"/></joint>'
             '<joint name="j1" type="fixed"><parent link="b"/><child link="c"/></joint>'
             '<joint name="j2" type="fixed"><parent link="c"/><child link="b"/></joint></robot>',
    "duplicate_joints": '<robot name="r"><link name="a"/><link name="b"/><link name="c"/>'
                        '<joint name="j" type="fixed"><parent link="a"/><child link="b"/>'
                        '</joint><joint name="j" type="fixed"><parent link="a"/>'
                        '<child link="c"/></joint></robot>',
    "percent": '<robot name="r"><link name="a%s%n"/></robot>',
    "not_xml": '<robot name="r"><link name="a">',
}


@pytest.mark.parametrize("case", sorted(CRASHERS))
def test_crash_guard(case: str, tmp_path: Path) -> None:
    """Files that segfault PyBullet get one line naming the file, and exit code 2."""
    path = tmp_path / f"{case}.urdf"
    path.write_text(CRASHERS[case])
    proc = subprocess_run("joints", str(path), "--json")
    assert proc.returncode == 2, proc.stderr
    assert proc.stdout == ""
    lines = proc.stderr.splitlines()
    assert len(lines) == 1 and lines[0].startswith(f"urdfkit: error: {path}")


@pytest.mark.parametrize("command", ["joints", "links", "tree", "info"])
def test_errors_exit_2_with_one_line(command: str, tmp_path: Path) -> None:
    code, out, err = run(command, str(tmp_path))
    assert (code, out) == (2, "")
    assert err == f"urdfkit: error: {tmp_path}: is a directory, not a URDF file\n"
    code, _, err = run(command, "no/such/robot.urdf")
    assert code == 2 and err.startswith("urdfkit: error: no/such/robot.urdf: no such file")


def test_bare_name_is_found_in_pybullet_data(tmp_path: Path) -> None:
    proc = subprocess_run("joints", "r2d2.urdf", cwd=tmp_path, env={"COLUMNS": "100"})
    assert proc.returncode == 0, proc.stderr
    assert "head_swivel" in proc.stdout and "physics: 15 joints" in proc.stdout


def test_xacro_input_with_args() -> None:
    code, out, err = run("joints", str(XACRO), "--json", "--arg", "wheelbase:=0.6")
    assert code == 0, err
    pos = {j["jointName"]: j["parentFramePos"] for j in json.loads(out)["joints"]}
    assert pos["base_to_left_hinge"][0] == pytest.approx(0.3)
    assert pos["base_to_left_back_wheel"][0] == pytest.approx(-0.3)
    code, out, _ = run("tree", str(XACRO), "--json")
    assert code == 0
    assert json.loads(out)["joints"][0]["xyz"] == [0.2, 0.0, 0.0]
    code, _, err = run("joints", str(XACRO), "--arg", "wheelbase")
    assert code == 2 and "wheelbase" in err


# A 2 x 2 x 2 cube as a mesh, and a robot that reaches it through package://.
CUBE_OBJ = "\n".join(
    [f"v {x} {y} {z}" for x in (-1, 1) for y in (-1, 1) for z in (-1, 1)]
    + ["f 1 3 4 2", "f 5 6 8 7", "f 1 2 6 5", "f 3 7 8 4", "f 1 5 7 3", "f 2 4 8 6"]) + "\n"
MESH_ROBOT = """<robot name="meshy">
  <link name="base">
    <inertial><mass value="1"/><inertia ixx="1" ixy="0" ixz="0" iyy="1" iyz="0" izz="1"/>
    </inertial>
    <collision><geometry><mesh filename="package://meshpkg/meshes/cube.obj"/></geometry>
    </collision>
  </link>
</robot>
"""


def _aabb_size(out: str) -> list[float]:
    return json.loads(out)["aabb"]["size"]


def test_package_uris(tmp_path: Path) -> None:
    # Walking up: the robot lives inside the package folder.
    pkg = tmp_path / "src" / "meshpkg"
    (pkg / "meshes").mkdir(parents=True)
    (pkg / "urdf").mkdir()
    (pkg / "meshes" / "cube.obj").write_text(CUBE_OBJ)
    inside = pkg / "urdf" / "meshy.urdf"
    inside.write_text(MESH_ROBOT)
    code, out, err = run("info", str(inside), "--json")
    assert code == 0, err
    assert _aabb_size(out) == pytest.approx([2, 2, 2], abs=0.05)
    # Elsewhere: found only through --package.
    outside = tmp_path / "elsewhere" / "meshy.urdf"
    outside.parent.mkdir()
    outside.write_text(MESH_ROBOT)
    code, _, err = run("info", str(outside), "--json")
    assert code == 2 and "package 'meshpkg' not found" in err
    code, out, err = run("info", str(outside), "--json", "--package", f"meshpkg={pkg}")
    assert code == 0, err
    assert _aabb_size(out) == pytest.approx([2, 2, 2], abs=0.05)


def test_links_command(simplecar_urdf: Path) -> None:
    code, out, _ = run("links", str(simplecar_urdf), "--json")
    assert code == 0
    data = json.loads(out)
    assert data["inertia_from_file"] is False
    links = {link["linkName"]: link for link in data["links"]}
    assert list(links)[0] == "base_link" and links["base_link"]["linkIndex"] == -1
    wheel = links["left_front_wheel"]
    assert wheel["lateral_friction"] == 1.0  # from the file's <contact>
    assert wheel["file"]["mass"] == wheel["mass"] == 0.3
    code, out, _ = run("links", str(simplecar_urdf), "--json", "--inertia-from-file")
    base = json.loads(out)["links"][0]
    assert sorted(base["local_inertia_diagonal"]) == pytest.approx([0.05, 0.13, 0.17])
    assert base["inertia_differs"] is False
    code, out, _ = run("links", str(simplecar_urdf), env={"COLUMNS": "120"})
    assert code == 0 and "left_front_wheel" in out and "recomputed by PyBullet" in out


def test_info_command(simplecar_urdf: Path) -> None:
    code, out, _ = run("info", str(simplecar_urdf), "--json", "--fixed-base")
    assert code == 0
    data = json.loads(out)
    assert (data["robot"], data["base_link"], data["links"], data["joints"], data["dof"]) == \
        ("simplecar", "base_link", 7, 6, 6)
    assert data["fixed_base"] is True
    code, out, _ = run("info", str(simplecar_urdf), env={"COLUMNS": "120"})
    assert code == 0
    assert "6 (2 revolute, 4 continuous)" in out or "6 (4 continuous, 2 revolute)" in out
    assert "+ 6 (floating base)" in out


def test_no_color_and_non_tty(simplecar_urdf: Path) -> None:
    """Piped output has no escape codes, even when the terminal would support colour."""
    for env in ({"NO_COLOR": "1", "TERM": "xterm-256color"}, {"TERM": "xterm-256color"}):
        for command in ("joints", "tree", "info"):
            proc = subprocess_run(command, str(simplecar_urdf), env=env)
            assert proc.returncode == 0
            assert "\x1b[" not in proc.stdout and "\x1b[" not in proc.stderr
    proc = subprocess_run("joints", "/nonexistent.urdf", env={"NO_COLOR": "1"})
    assert "\x1b[" not in proc.stderr and proc.returncode == 2


def test_tree_handles_chains_deeper_than_the_recursion_limit(tmp_path: Path) -> None:
    # The guard admits up to 1000 links; a 999-link chain is deeper than Python's default
    # recursion limit, which the tree code once hit.
    n = 999
    links = "".join(f'<link name="l{i}"/>' for i in range(n))
    joints = "".join(f'<joint name="j{i}" type="fixed"><parent link="l{i - 1}"/>'
                     f'<child link="l{i}"/></joint>' for i in range(1, n))
    path = tmp_path / "chain.urdf"
    path.write_text(f'<robot name="chain">{links}{joints}</robot>')
    for extra in ([], ["--dot"]):
        result = CliRunner().invoke(app, ["tree", str(path), *extra])
        assert result.exit_code == 0, result.output[-500:]
    result = CliRunner().invoke(app, ["tree", str(path), "--json"])
    assert result.exit_code == 0
    doc = json.loads(result.stdout)
    assert [j["index"] for j in doc["joints"]] == list(range(n - 1))
    assert doc["joints"][-1] == {**doc["joints"][-1], "parent": f"l{n - 2}", "child": f"l{n - 1}"}
    # Flat and linear: no indentation that grows with depth.
    assert len(result.stdout) < 400 * n
    # Piped text shows every joint, however deep.
    text = CliRunner().invoke(app, ["tree", str(path)]).stdout
    assert text.count("->") == n - 1 and f"[{n - 2}] j{n - 1} (fixed) -> l{n - 1}" in text
