"""`urdfkit build` and `urdfkit templates` as users call them."""

from __future__ import annotations

import json
import os
import shutil
import subprocess
import sys
from collections.abc import Callable
from pathlib import Path

import pytest
from typer.testing import CliRunner

from urdfkit.cli import app

DATA = Path(__file__).parent / "data"
GOLDEN = Path(__file__).parent / "golden"


@pytest.fixture
def runner() -> CliRunner:
    return CliRunner()


@pytest.fixture
def in_tmp(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> Path:
    monkeypatch.chdir(tmp_path)
    return tmp_path


def test_build_writes_the_template_in_the_current_folder(runner: CliRunner, in_tmp: Path) -> None:
    result = runner.invoke(app, ["build", "simplecar"])
    assert result.exit_code == 0, result.output
    assert (in_tmp / "simplecar.urdf").read_bytes() == (GOLDEN / "simplecar.urdf").read_bytes()
    assert "wrote simplecar.urdf (7 links, 6 joints)" in result.output


def test_build_twice_is_byte_identical(runner: CliRunner, in_tmp: Path) -> None:
    assert runner.invoke(app, ["build", "simplecar", "-o", "a.urdf"]).exit_code == 0
    assert runner.invoke(app, ["build", "simplecar", "-o", "b.urdf"]).exit_code == 0
    assert (in_tmp / "a.urdf").read_bytes() == (in_tmp / "b.urdf").read_bytes()


def test_build_refuses_to_overwrite_without_force(runner: CliRunner, in_tmp: Path) -> None:
    target = in_tmp / "simplecar.urdf"
    target.write_text("my precious edits")
    result = runner.invoke(app, ["build", "simplecar"])
    assert result.exit_code == 2
    assert "simplecar.urdf: exists; pass --force to overwrite it" in result.output
    assert target.read_text() == "my precious edits"
    result = runner.invoke(app, ["build", "simplecar", "--force"])
    assert result.exit_code == 0
    assert target.read_bytes() == (GOLDEN / "simplecar.urdf").read_bytes()
    assert not [p for p in in_tmp.iterdir() if p.name.endswith(".tmp")]


def test_build_to_stdout(runner: CliRunner, in_tmp: Path) -> None:
    result = runner.invoke(app, ["build", "simpleplane", "-o", "-"])
    assert result.exit_code == 0
    assert result.stdout.encode() == (GOLDEN / "simpleplane.urdf").read_bytes()
    assert not list(in_tmp.iterdir())


def test_build_with_parameters(runner: CliRunner, in_tmp: Path) -> None:
    result = runner.invoke(app, ["build", "simplecar", "--set", "wheel_radius=0.15",
                                 "-s", "body_mass=4", "-o", "-"])
    assert result.exit_code == 0
    assert 'radius="0.15"' in result.stdout
    assert '<mass value="4"/>' in result.stdout


@pytest.mark.parametrize(
    ("args", "message"),
    [
        (["build", "simplecar", "--set", "wheel_radius=-1"],
         "parameter 'wheel_radius' must be > 0"),
        (["build", "simplecar", "--set", "wings=2"], "has no parameter 'wings'"),
        (["build", "simplecar", "--set", "wheel_radius"], "--set expects key=value"),
        (["build", "truck"], "'truck' is neither a template"),
        (["build", "simplecar", "-o", "no/such/dir/car.urdf"], "folder no/such/dir does not exist"),
    ],
)
def test_build_errors_are_one_line(runner: CliRunner, in_tmp: Path, args: list[str],
                                   message: str) -> None:
    result = runner.invoke(app, args)
    assert result.exit_code == 2
    assert message in result.output
    assert len(result.output.strip().splitlines()) == 1
    assert "Traceback" not in result.output


def test_build_a_users_xacro_with_args(runner: CliRunner, in_tmp: Path) -> None:
    shutil.copy(DATA / "arm.urdf.xacro", in_tmp)
    result = runner.invoke(app, ["build", "arm.urdf.xacro", "--arg", "length:=0.8"])
    assert result.exit_code == 0, result.output
    text = (in_tmp / "arm.urdf").read_text()
    assert 'length="0.8"' in text
    assert "xacro:" not in text


def test_build_reports_a_broken_xacro(runner: CliRunner, in_tmp: Path) -> None:
    (in_tmp / "bad.urdf.xacro").write_text(
        '<robot name="r" xmlns:xacro="http://www.ros.org/wiki/xacro">'
        '<link name="${undefined_name}"/></robot>')
    result = runner.invoke(app, ["build", "bad.urdf.xacro"])
    assert result.exit_code == 2
    assert "bad.urdf.xacro: xacro failed:" in result.output
    assert not (in_tmp / "bad.urdf").exists()


def test_build_validates_the_result_before_writing(runner: CliRunner, in_tmp: Path) -> None:
    (in_tmp / "tworoots.urdf.xacro").write_text(
        '<robot name="r" xmlns:xacro="http://www.ros.org/wiki/xacro">'
        '<link name="a"/><link name="b"/></robot>')
    result = runner.invoke(app, ["build", "tworoots.urdf.xacro"])
    assert result.exit_code == 2
    assert "2 root links" in result.output
    assert not (in_tmp / "tworoots.urdf").exists()


#: A xacro whose collision mesh is missing, and one whose inertial has no <inertia>: raw
#: p.loadURDF refuses both; and one with only an error PyBullet loads (a negative mass).
_LINK = ('<robot name="r" xmlns:xacro="http://www.ros.org/wiki/xacro"><link name="a">{}'
         '</link></robot>')
_BUILDS = {
    "mesh": _LINK.format('<inertial><mass value="1"/><inertia ixx="1" ixy="0" ixz="0" iyy="1" '
                        'iyz="0" izz="1"/></inertial><collision><geometry><mesh '
                        'filename="meshes/gone.stl"/></geometry></collision>'),
    "inertia": _LINK.format('<inertial><mass value="1"/></inertial>'),
    "loads": _LINK.format('<inertial><mass value="-1"/><inertia ixx="1" ixy="0" ixz="0" '
                          'iyy="1" iyz="0" izz="1"/></inertial>'),
}


@pytest.mark.parametrize("case", sorted(_BUILDS))
def test_build_writes_only_what_pybullet_loads(runner: CliRunner, in_tmp: Path, pb,
                                               case: str) -> None:
    """Written means raw loadURDF takes it; refused (exit 1, nothing written) means it does not."""
    p, c = pb
    source = in_tmp / f"{case}.urdf.xacro"
    source.write_text(_BUILDS[case])
    plain = in_tmp / f"{case}_plain.urdf"  # the same robot as raw PyBullet would be handed it
    plain.write_text(_BUILDS[case])
    try:
        p.loadURDF(str(plain), physicsClientId=c)
        loads = True
    except p.error:
        loads = False
    result = runner.invoke(app, ["build", source.name])
    written = in_tmp / f"{case}.urdf"
    if loads:
        assert result.exit_code == 0 and "PyBullet loads it as written" in result.output
        p.loadURDF(str(written), physicsClientId=c)  # and it does
    else:
        # 2: the guard's refusal (what crashes or fails PyBullet); 1: what PyBullet refuses.
        assert result.exit_code in (1, 2), result.output
        assert "loads it as written" not in result.output
        if case == "mesh":
            assert result.exit_code == 1 and "PyBullet refuses the expanded file" in \
                result.output and "gone.stl" in result.output
        assert not written.exists()
    assert loads == (case == "loads")


def test_xacro_expansion_is_time_limited(in_tmp: Path) -> None:
    from urdfkit.core.errors import InputError
    from urdfkit.sources.resolve import expand_xacro

    slow = in_tmp / "slow.urdf.xacro"
    slow.write_text('<robot name="r" xmlns:xacro="http://www.ros.org/wiki/xacro">'
                    '<link name="${[x for x in range(10**12)]}"/></robot>')
    with pytest.raises(InputError, match="took longer than 1 s"):
        expand_xacro(slow, timeout=1)


def test_templates_lists_parameters(runner: CliRunner) -> None:
    result = runner.invoke(app, ["templates", "--json"])
    assert result.exit_code == 0
    data = json.loads(result.stdout)
    car = next(t for t in data["templates"] if t["name"] == "simplecar")
    names = {p["name"] for p in car["params"]}
    assert {"wheel_radius", "wheel_width", "wheelbase", "track", "body_size", "body_mass",
            "wheel_mass", "steer_limit", "lateral_friction"} <= names
    table = runner.invoke(app, ["templates"])
    assert "wheel_radius" in table.output and "simpleplane" in table.output


def test_installed_command_runs_as_a_subprocess(tmp_path: Path) -> None:
    exe = shutil.which("urdfkit") or str(Path(sys.executable).parent / "urdfkit")
    out = subprocess.run([exe, "--help"], capture_output=True, text=True, timeout=60)
    assert out.returncode == 0
    assert "build" in out.stdout and "Usage" in out.stdout
    mod = subprocess.run([sys.executable, "-m", "urdfkit", "build", "simplecar", "-o",
                          str(tmp_path / "car.urdf")], capture_output=True, text=True,
                         timeout=60, env={**os.environ, "NO_COLOR": "1"}, cwd=tmp_path)
    assert mod.returncode == 0, mod.stderr
    assert (tmp_path / "car.urdf").read_bytes() == (GOLDEN / "simplecar.urdf").read_bytes()


def test_python_m_urdfkit_works_from_a_source_checkout(tmp_path: Path) -> None:
    # In the repository folder `python -m urdfkit` imports the source tree, where the
    # templates are the top-level folder rather than the installed urdfkit.templates.
    root = Path(__file__).parent.parent
    out = subprocess.run([sys.executable, "-m", "urdfkit", "build", "simplecar", "-o",
                          str(tmp_path / "car.urdf")], capture_output=True, text=True,
                         timeout=60, cwd=root)
    assert out.returncode == 0, out.stderr
    assert (tmp_path / "car.urdf").read_bytes() == (GOLDEN / "simplecar.urdf").read_bytes()


_TETRA_STL = """solid t
facet normal 0 0 -1
 outer loop
  vertex 0 0 0
  vertex 0 0.1 0
  vertex 0.1 0 0
 endloop
endfacet
facet normal 0 -1 0
 outer loop
  vertex 0 0 0
  vertex 0.1 0 0
  vertex 0 0 0.1
 endloop
endfacet
facet normal -1 0 0
 outer loop
  vertex 0 0 0
  vertex 0 0 0.1
  vertex 0 0.1 0
 endloop
endfacet
facet normal 1 1 1
 outer loop
  vertex 0.1 0 0
  vertex 0 0.1 0
  vertex 0 0 0.1
 endloop
endfacet
endsolid t
"""


def test_build_warns_when_raw_pybullet_cannot_reach_a_nested_package(
        tmp_path: Path, raw_loads: Callable[[Path], bool]) -> None:
    # As turtlebot4 includes create3_sim's irobot_create_common/irobot_create_description: a
    # package one folder deeper than its name, found by its package.xml only.
    pkg = tmp_path / "ws" / "group" / "mypkg"
    (pkg / "meshes").mkdir(parents=True)
    (pkg / "package.xml").write_text("<package><name>mypkg</name></package>")
    (pkg / "meshes" / "t.stl").write_text(_TETRA_STL)
    src = tmp_path / "src" / "robot.urdf.xacro"
    src.parent.mkdir()
    src.write_text('<robot name="r" xmlns:xacro="http://www.ros.org/wiki/xacro"><link name="a">'
                   '<inertial><mass value="1"/><inertia ixx="1" ixy="0" ixz="0" iyy="1" iyz="0"'
                   ' izz="1"/></inertial><collision><geometry>'
                   '<mesh filename="package://mypkg/meshes/t.stl"/></geometry></collision>'
                   '</link></robot>')
    outside, inside = tmp_path / "out" / "r.urdf", tmp_path / "ws" / "group" / "r.urdf"
    outside.parent.mkdir()
    for out in (outside, inside):
        done = subprocess.run([sys.executable, "-m", "urdfkit", "build", str(src), "-o",
                               str(out), "--package-path", str(tmp_path / "ws")],
                              capture_output=True, text=True, timeout=120)
        assert done.returncode == 0, done.stderr
        warned = "raw p.loadURDF will not find 1 package:// file(s)" in done.stderr
        # The warning says exactly what raw PyBullet then does with the written file.
        assert warned == (out == outside) == (not raw_loads(out)), (out, done.stderr)
        assert ("package://mypkg/meshes/t.stl" in done.stderr) == warned


def test_build_rewrites_relative_mesh_paths_for_where_it_writes(
        tmp_path: Path, monkeypatch: pytest.MonkeyPatch,
        raw_loads: Callable[[Path], bool]) -> None:
    # Issue 49: a written file must load. A xacro's relative mesh path names a file beside
    # the xacro; written into another folder, the path is rewritten to name the same file.
    src = tmp_path / "src"
    (src / "meshes").mkdir(parents=True)
    (src / "meshes" / "t.stl").write_text(_TETRA_STL)
    xacro = src / "robot.urdf.xacro"
    xacro.write_text('<robot name="r" xmlns:xacro="http://www.ros.org/wiki/xacro"><link name="a">'
                     '<inertial><mass value="1"/><inertia ixx="1" ixy="0" ixz="0" iyy="1" '
                     'iyz="0" izz="1"/></inertial><visual><geometry><mesh '
                     'filename="meshes/t.stl"/></geometry></visual><collision><geometry>'
                     '<mesh filename="meshes/t.stl"/></geometry></collision></link></robot>')
    work = tmp_path / "work"
    work.mkdir()
    monkeypatch.chdir(work)
    result = CliRunner().invoke(app, ["build", str(xacro)])  # robot.urdf, here
    assert result.exit_code == 0, result.output
    assert "2 relative mesh or texture path(s) rewritten" in result.stderr
    written = work / "robot.urdf"
    assert 'filename="../src/meshes/t.stl"' in written.read_text()
    assert raw_loads(written)
    beside = CliRunner().invoke(app, ["build", str(xacro), "-o", str(src / "r.urdf")])
    assert beside.exit_code == 0 and "rewritten" not in beside.stderr
    assert 'filename="meshes/t.stl"' in (src / "r.urdf").read_text()
    piped = CliRunner().invoke(app, ["build", str(xacro), "-o", "-"])
    assert 'filename="meshes/t.stl"' in piped.stdout
    assert "2 mesh or texture path(s) are relative to its folder" in piped.stderr
