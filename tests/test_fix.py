"""``urdfkit fix``: repairs checked against physics, PyBullet, ``check`` and ``diff``, and the
promise that nothing else in the file changes."""

from __future__ import annotations

import json
import math
import os
import re
import shutil
from collections.abc import Callable
from pathlib import Path
from typing import Any

import pytest
from typer.testing import CliRunner

from urdfkit.checks.check import check_file
from urdfkit.checks.diff import diff_files
from urdfkit.checks.fix import FIXABLE, balanced, fix_file
from urdfkit.cli import app
from urdfkit.core.errors import InputError, ParameterError
from urdfkit.model.spec import rpy_to_matrix

MESHES = Path(__file__).parent / "fixtures" / "meshes"

#: A small arm with every repair ``fix`` makes, written the way people write URDF by hand:
#: single quotes, comments, four-space indents, several elements on one line.
BROKEN = (Path(__file__).parent / "fixtures" / "robots" / "broken_arm.urdf").read_text()


@pytest.fixture
def broken(tmp_path: Path) -> Path:
    """The arm in a ROS package layout (package.xml above it, the mesh in meshes/)."""
    pkg = tmp_path / "arm_description"
    (pkg / "meshes").mkdir(parents=True)
    (pkg / "urdf").mkdir()
    (pkg / "package.xml").write_text("<package><name>arm_description</name></package>")
    shutil.copy(MESHES / "unit_cube.stl", pkg / "meshes" / "unit_cube.stl")
    path = pkg / "urdf" / "arm.urdf"
    path.write_text(BROKEN)
    return path


def _cli(*args: str) -> tuple[int, str, str]:
    result = CliRunner().invoke(app, list(args))
    return result.exit_code, result.stdout, result.stderr


def test_every_fixable_finding_is_fixed_and_listed(broken: Path) -> None:
    result = fix_file(broken, density=1000.0)
    assert sorted({r.code for r in result.repairs}) == ["U602", "U603", "U604", "U606", "U706",
                                                        "U708"]
    assert not result.left and not result.other_errors
    out = broken.with_name("fixed.urdf")
    out.write_bytes(result.fixed)
    after = [f for f in check_file(str(out), out).findings if f.code in FIXABLE]
    assert after == []  # no error, no warning, not even U605's "far from the shapes"


def test_only_what_is_fixed_changes(broken: Path) -> None:
    result = fix_file(broken)
    before = result.original.decode().splitlines()
    after = result.fixed.decode().splitlines()
    # Every original line that is not an edited element survives byte for byte, in order.
    edited = ("<inertia ", "package:///", "<link name=\"tool0\"/>", "<mass value=\"0\"/>")
    kept = [x for x in before if not any(e in x for e in edited)]
    it = iter(after)
    assert all(any(line == a for a in it) for line in kept)
    assert "        <!-- keep this comment -->" in after and after[2] == "<robot name='broken_arm'>"
    # Joints are untouched in meaning: only links (and the new material) differ.
    fixed = broken.with_name("fixed.urdf")
    fixed.write_bytes(result.fixed)
    d = diff_files(broken, fixed)
    assert {c.kind for c in d.changes} == {"link"}
    assert not d.added and not d.removed and not d.renamed and not d.index_shifts
    assert [line for line in after if "<joint" in line] == \
        [line for line in before if "<joint" in line]


def test_derived_inertia_matches_the_closed_forms(broken: Path) -> None:
    from lxml import etree

    root = etree.fromstring(fix_file(broken, density=1000.0).fixed)

    def tensor(link: str) -> list[float]:  # row by row
        i = root.find(f"link[@name='{link}']/inertial/inertia")
        assert i is not None
        g = {k: float(i.get(k, "nan")) for k in ("ixx", "ixy", "ixz", "iyy", "iyz", "izz")}
        return [g["ixx"], g["ixy"], g["ixz"], g["ixy"], g["iyy"], g["iyz"], g["ixz"], g["iyz"],
                g["izz"]]

    # base: a 0.4 x 0.2 x 0.2 box of 2 kg (the mass and the <origin> are the file's).
    assert tensor("base") == pytest.approx([2 / 12 * 0.08, 0, 0, 0, 2 / 12 * 0.2, 0,
                                            0, 0, 2 / 12 * 0.2], rel=1e-6)
    # upper: a cylinder r=0.05 l=0.5 of 1.5 kg, axis z in the link; the file's inertial frame
    # is pitched 90 degrees, so in that frame the axis is x.
    axial, radial = 1.5 * 0.05**2 / 2, 1.5 * (3 * 0.05**2 + 0.5**2) / 12
    flat = tensor("upper")
    t = [flat[0:3], flat[3:6], flat[6:9]]
    rot = rpy_to_matrix((0, 1.5707963, 0))
    back = [sum(rot[i][k] * t[k][m] * rot[j][m] for k in range(3) for m in range(3))
            for i in range(3) for j in range(3)]  # into link axes
    assert back == pytest.approx([radial, 0, 0, 0, radial, 0, 0, 0, axial], abs=1e-7)
    # cube: a 0.1 m cube of water (no <inertial> before): 1 kg, m a^2 / 6 about each axis.
    mass = root.find("link[@name='cube']/inertial/mass")
    assert mass is not None and float(mass.get("value", "nan")) == pytest.approx(1.0)
    assert tensor("cube") == pytest.approx([1 / 600, 0, 0, 0, 1 / 600, 0, 0, 0, 1 / 600],
                                           rel=1e-6)
    assert root.find("link[@name='finger']/inertial/mass").get("value") == "0.001"  # type: ignore[union-attr]
    assert root.find("link[@name='tool0']/inertial/mass").get("value") == "0"  # type: ignore[union-attr]


def test_pybullet_loads_the_fix_with_the_inertia_it_derives_itself(broken: Path,
                                                                   pb: tuple[object, int]) -> None:
    # Without URDF_USE_INERTIA_FROM_FILE PyBullet computes inertia from the collision box
    # itself; with the flag it reads ours. For the box base they must agree.
    p, c = pb
    fixed = broken.with_name("fixed.urdf")
    fixed.write_bytes(fix_file(broken).fixed)
    ours = p.loadURDF(str(fixed), flags=p.URDF_USE_INERTIA_FROM_FILE,  # type: ignore[attr-defined]
                      physicsClientId=c)
    theirs = p.loadURDF(str(fixed), physicsClientId=c)  # type: ignore[attr-defined]
    a = p.getDynamicsInfo(ours, -1, physicsClientId=c)  # type: ignore[attr-defined]
    b = p.getDynamicsInfo(theirs, -1, physicsClientId=c)  # type: ignore[attr-defined]
    assert a[0] == b[0] == 2.0
    assert a[2] == pytest.approx(b[2], rel=1e-4)
    masses = [p.getDynamicsInfo(ours, j, physicsClientId=c)[0]  # type: ignore[attr-defined]
              for j in range(p.getNumJoints(ours, physicsClientId=c))]  # type: ignore[attr-defined]
    assert masses == pytest.approx([1.5, 1.0, 0.001, 0.0])  # tool0: no longer PyBullet's 1 kg


def test_balance_keeps_the_file_values_the_mujoco_way(broken: Path) -> None:
    result = fix_file(broken, balance=True)
    from lxml import etree

    root = etree.fromstring(result.fixed)
    i = root.find("link[@name='base']/inertial/inertia")
    assert i is not None
    mean = (0.01 + 0.01 + 0.5) / 3  # the trace is kept, spread evenly
    assert [float(i.get(k, "nan")) for k in ("ixx", "iyy", "izz", "ixy")] == \
        pytest.approx([mean, mean, mean, 0], rel=1e-8)
    assert balanced([[0.01, 0, 0], [0, 0.01, 0], [0, 0, 0.5]]) == pytest.approx(mean)
    assert balanced([[1, 0, 0], [0, 1, 0], [0, 0, 1.5]]) is None  # valid: left alone
    # Not positive definite cannot be balanced: still derived from the shapes.
    assert any(r.code == "U603" and "derived" in r.message for r in result.repairs)


def test_far_from_shapes_is_derived_unless_balance(tmp_path: Path) -> None:
    path = tmp_path / "far.urdf"
    path.write_text(BROKEN.replace('izz="0.5"', 'izz="0.015"').replace(
        'ixx="0.01" ixy="0" ixz="0" iyy="0.01"', 'ixx="10" ixy="0" ixz="0" iyy="10"')
        .replace('izz="0.015"', 'izz="10"'))
    assert [f.code for f in check_file(str(path), path).findings
            if f.line == 10 and f.code != "U607"] == ["U605"]
    assert any(r.code == "U605" for r in fix_file(path).repairs)
    kept = fix_file(path, balance=True)
    assert [r.code for r in kept.left if r.line == 10] == ["U605"]


def test_one_line_files_and_self_closing_links(tmp_path: Path) -> None:
    path = tmp_path / "flat.urdf"
    path.write_text('<robot name="flat"><link name="a"><collision><geometry><box size="1 1 1"/>'
                    '</geometry></collision></link><link name="b"><collision><geometry><sphere '
                    'radius="0.5"/></geometry></collision></link><link name="c"/><joint name="j" '
                    'type="revolute"><parent link="a"/><child link="b"/><axis xyz="0 0 1"/>'
                    '<limit lower="-1" upper="1" effort="1" velocity="1"/></joint><joint name="f" '
                    'type="fixed"><parent link="b"/><child link="c"/></joint></robot>')
    # By default fix invents no mass: only the frame 'c' gets its mass 0; a and b are left.
    plain = fix_file(path)
    assert [(r.code, r.subject) for r in plain.repairs] == [("U606", "c")]
    assert [r.code for r in plain.left] == ["U606", "U606"]
    assert "root link" in plain.left[0].message and "mass 0 if" not in plain.left[0].message
    result = fix_file(path, density=1000.0)
    assert [r.code for r in result.repairs] == ["U606", "U606", "U606"]
    out = tmp_path / "out.urdf"
    out.write_bytes(result.fixed)
    assert not [f for f in check_file(str(out), out).findings if f.code in FIXABLE]
    from lxml import etree

    root = etree.fromstring(result.fixed)
    sphere = root.find("link[@name='b']/inertial")
    assert sphere is not None
    m = float(sphere.find("mass").get("value", "nan"))  # type: ignore[union-attr]
    assert m == pytest.approx(1000 * 4 / 3 * math.pi * 0.125, rel=1e-5)
    assert float(sphere.find("inertia").get("izz", "nan")) == \
        pytest.approx(0.4 * m * 0.25, rel=1e-5)  # type: ignore[union-attr]


MASS = ("--density", "1000", "--allow-mass-change")  # the fixture's massless links get one


def test_cli_writes_only_where_told(broken: Path, tmp_path: Path) -> None:
    out = tmp_path / "out.urdf"
    code, stdout, _ = _cli("fix", str(broken), *MASS, "-o", str(out))
    assert code == 0 and out.exists() and "fixed U604" in stdout
    original = broken.read_bytes()
    code, _, err = _cli("fix", str(broken), *MASS, "-o", str(out))
    assert code == 2 and "exists" in err  # never overwrite without --force
    assert _cli("fix", str(broken), *MASS, "-o", str(out), "--force")[0] == 0
    code, stdout, err = _cli("fix", str(broken), *MASS, "--diff")
    assert code == 1 and stdout.startswith("--- a/") and "fixed U604" in err
    assert broken.read_bytes() == original  # --diff writes nothing
    code, stdout, _ = _cli("fix", str(broken), *MASS, "-o", "-")
    assert code == 0 and stdout.encode() == out.read_bytes()
    code, stdout, _ = _cli("fix", str(broken), *MASS, "--in-place", "--json")
    data = json.loads(stdout)
    assert code == 0 and data["changed"] and {"code", "line", "message"} <= set(data["fixes"][0])
    assert Path(f"{broken}.orig").read_bytes() == original
    assert broken.read_bytes() == out.read_bytes()
    assert _cli("fix", str(broken), *MASS, "--diff")[0] == 0  # nothing left to fix


def test_bad_input_and_usage(broken: Path, tmp_path: Path) -> None:
    for args, words in [((), "say where"), (("-o", "x.urdf", "--diff"), "say where"),
                        (("--diff", "--select", "U3"), "repairs U601"),
                        (("--diff", "--density", "-5"), "density"),
                        (("--diff", "--json"), "--json describes")]:
        code, _, err = _cli("fix", str(broken), *MASS, *args)
        assert code == 2 and words in err and "Traceback" not in err, (args, err)
    bad = tmp_path / "bad.urdf"
    bad.write_text("<robot name='x'><link name='a'>")
    code, _, err = _cli("fix", str(bad), "--diff")
    assert code == 2 and "bad.urdf" in err
    xacro = tmp_path / "arm.urdf.xacro"
    xacro.write_text("<robot name='x'/>")
    with pytest.raises(InputError, match="xacro"):
        fix_file(xacro)
    with pytest.raises(ParameterError):
        fix_file(broken, density=0)


def test_left_findings_say_why_and_exit_1(tmp_path: Path) -> None:
    path = tmp_path / "capsule.urdf"
    path.write_text('<robot name="c"><link name="a"/><link name="b"><collision><geometry>'
                    '<capsule radius="0.1" length="0.5"/></geometry></collision></link>'
                    '<joint name="j" type="revolute"><parent link="a"/><child link="b"/>'
                    '<axis xyz="0 0 0"/><limit lower="-1" upper="1" effort="1" velocity="1"/>'
                    '</joint></robot>')
    result = fix_file(path)
    assert [r.code for r in result.left] == ["U606", "U606"]
    assert "no collision solid" in result.left[-1].message
    assert [r.code for r in result.other_errors] == ["U305"]  # a zero axis: check's business
    code, stdout, _ = _cli("fix", str(path), "-o", str(tmp_path / "o.urdf"))
    assert code == 1 and "left U606" in stdout and "U305" in stdout


def test_stub_shapes_and_relative_paths(tmp_path: Path) -> None:
    shutil.copy(MESHES / "unit_cube.stl", tmp_path / "cube.stl")
    path = tmp_path / "r.urdf"
    path.write_text('<robot name="r"><link name="footprint"><collision><geometry><box '
                    'size="0.001 0.001 0.001"/></geometry></collision></link><link name="b">'
                    '<collision><geometry><mesh filename="cube.stl" scale="0.1 0.1 0.1"/>'
                    '</geometry></collision></link><joint name="j" type="revolute"><parent '
                    'link="footprint"/><child link="b"/><axis xyz="0 0 1"/><limit lower="-1" '
                    'upper="1" effort="1" velocity="1"/></joint></robot>')
    result = fix_file(path, density=1000.0)
    # A 1 mm placeholder box is no body to weigh (PR2's base_footprint): left, with why.
    assert [(r.code, "stubs" in r.message) for r in result.left] == [("U606", True)]
    assert result.relative_paths == ["cube.stl"]
    elsewhere = tmp_path / "out"
    elsewhere.mkdir()
    code, _, err = _cli("fix", str(path), *MASS, "-o", str(elsewhere / "r.urdf"))
    # PyBullet finds cube.stl from there too (it searches the folders above): kept.
    assert "rewritten" not in err and 'filename="cube.stl"' in (elsewhere / "r.urdf").read_text()
    side = tmp_path.parent / f"{tmp_path.name}-side"
    side.mkdir()
    code, _, err = _cli("fix", str(path), *MASS, "-o", str(side / "r.urdf"))
    assert "1 relative mesh or texture path(s) rewritten" in err
    assert f'filename="../{tmp_path.name}/cube.stl"' in (side / "r.urdf").read_text()
    code, _, err = _cli("fix", str(path), *MASS, "-o", str(tmp_path / "r_fixed.urdf"))
    assert "rewritten" not in err
    assert 'filename="cube.stl"' in (tmp_path / "r_fixed.urdf").read_text()


def _meshes(pb: tuple[Any, int], path: Path) -> tuple[list[str], list[Any]]:
    """What raw PyBullet loads for ``path``: the visual mesh files (real paths), and each
    collision mesh's shape data and its link's bounding box (PyBullet names a collision
    mesh's file "unknown_file": its hull is what tells the meshes apart)."""
    from urdfkit.engine.session import quiet_stdout

    p, c = pb
    with quiet_stdout():
        body = p.loadURDF(str(path), physicsClientId=c)
    visual = [os.path.realpath(v[4].decode()) for v in
              p.getVisualShapeData(body, physicsClientId=c) if v[2] == p.GEOM_MESH]
    collision = [(s[1], s[3], s[5], p.getAABB(body, link, physicsClientId=c))
                 for link in range(-1, p.getNumJoints(body, physicsClientId=c))
                 for s in p.getCollisionShapeData(body, link, physicsClientId=c)
                 if s[2] == p.GEOM_MESH]
    return visual, collision


def test_written_elsewhere_it_loads_the_same_meshes(tmp_path: Path, pb: tuple[Any, int],
                                                    monkeypatch: pytest.MonkeyPatch) -> None:
    # Issue 49: `fix racecar/racecar.urdf --gazebo-contacts -o racecar_fixed.urdf` wrote a file
    # whose 8 mesh paths no longer resolved, and `urdfkit diff` then failed on it.
    import pybullet_data

    src = tmp_path / "src" / "racecar"
    shutil.copytree(Path(pybullet_data.getDataPath()) / "racecar", src)
    original = src / "racecar.urdf"
    beside, elsewhere = src / "beside.urdf", tmp_path / "out" / "deep" / "racecar_fixed.urdf"
    elsewhere.parent.mkdir(parents=True)
    for out in (beside, elsewhere):
        code, _, err = _cli("fix", str(original), "--gazebo-contacts", "-o", str(out))
        assert code == 0, err
    assert "8 relative mesh or texture path(s) rewritten" in err
    # Only the filename attributes differ from the copy written beside the original.
    blank = re.compile(rb'filename="[^"]*"')
    assert blank.sub(b"", elsewhere.read_bytes()) == blank.sub(b"", beside.read_bytes())
    assert elsewhere.read_bytes() != beside.read_bytes()
    # Raw PyBullet loads the very same mesh files from it.
    visual, collision = _meshes(pb, original)
    assert len(visual) == 8 and len(collision) == 4  # 4 links collide as meshes
    assert _meshes(pb, elsewhere) == (visual, collision)
    assert _cli("diff", str(beside), str(elsewhere))[0] == 0  # the same robot
    code, out, err = _cli("diff", str(original), str(elsewhere))
    assert code == 1 and "inertia" in out and "error" not in err
    # As the issue ran it: a pybullet_data name, written in the current folder.
    monkeypatch.chdir(tmp_path)
    code, _, err = _cli("fix", "racecar/racecar.urdf", "--gazebo-contacts", "-o",
                        "racecar_fixed.urdf")
    assert code == 0, err
    here = _meshes(pb, tmp_path / "racecar_fixed.urdf")
    assert here == _meshes(pb, Path(pybullet_data.getDataPath()) / "racecar" / "racecar.urdf")
    code, _, err = _cli("diff", "racecar/racecar.urdf", "racecar_fixed.urdf")
    assert code == 1 and "error" not in err


def test_stdout_keeps_the_paths_and_says_so(tmp_path: Path, monkeypatch: pytest.MonkeyPatch
                                            ) -> None:
    import pybullet_data

    monkeypatch.chdir(tmp_path)
    code, out, err = _cli("fix", "racecar/racecar.urdf", "-o", "-")
    assert 'filename="meshes/chassis.STL"' in out
    assert "8 mesh or texture path(s) are relative to its folder" in err
    monkeypatch.chdir(Path(pybullet_data.getDataPath()) / "racecar")
    code, out, err = _cli("fix", "racecar.urdf", "-o", "-")
    assert "relative to its folder" not in err


def test_a_frame_with_frames_below_gets_mass_0(tmp_path: Path) -> None:
    # A lidar mount with its optical frame under it (unitree a2's front_lidar_link).
    path = tmp_path / "lidar.urdf"
    path.write_text('<robot name="r"><link name="base"><inertial><mass value="5"/><inertia '
                    'ixx="0.1" ixy="0" ixz="0" iyy="0.1" iyz="0" izz="0.1"/></inertial></link>'
                    '<link name="lidar"/><link name="lidar_optical"/>'
                    '<joint name="m" type="fixed"><parent link="base"/><child link="lidar"/>'
                    '</joint><joint name="o" type="fixed"><parent link="lidar"/><child '
                    'link="lidar_optical"/></joint></robot>')
    result = fix_file(path)
    assert [(r.code, "frame" in r.message) for r in result.repairs] == [("U606", True)] * 2
    from lxml import etree

    root = etree.fromstring(result.fixed)
    assert [m.get("value") for m in root.iter("mass")] == ["5", "0", "0"]


def test_docs_u606_row_matches_the_code_and_help(broken: Path) -> None:
    """docs/fix.md's U606 says what fix does: no mass invented without --density."""
    docs = (Path(__file__).parent.parent / "docs" / "fix.md").read_text()
    row = next(line for line in docs.splitlines() if line.startswith("| `U606` |"))
    assert "only with `--density" in row and "invents no mass" in row
    assert "(1000 kg/m^3, water)" not in row  # once the doc's default; the code has none
    code, out, _ = _cli("fix", "--help")
    assert "Without it fix invents no mass" in " ".join(out.replace("\u2502", " ").split())
    left = fix_file(broken)  # no density: the shaped link 'cube' is left, said why
    assert any(r.code == "U606" and "'cube'" in r.message for r in left.left)
    done = fix_file(broken, density=1000.0)  # 0.1 m cube of water: 1 kg
    cube = next(r for r in done.repairs if r.code == "U606" and "'cube'" in r.message)
    assert "1 kg (0.001 m^3 at 1000 kg/m^3)" in cube.message


@pytest.mark.parametrize("name", ["or\tange", "a\nb", "c\rd", " e "])
def test_whitespace_in_a_material_name_is_written_back_exactly(tmp_path: Path,
                                                               name: str) -> None:
    """A name holding a tab or line break (a character reference in the file) is defined
    under that very name: a literal tab in the attribute would read back as a space."""
    from lxml import etree

    ref = name.replace("\t", "&#9;").replace("\n", "&#10;").replace("\r", "&#13;")
    path = tmp_path / "ws.urdf"
    path.write_text(f'<robot name="r"><link name="a"><visual><geometry><box size="1 1 1"/>'
                    f'</geometry><material name="{ref}"/></visual></link></robot>')
    code, out, err = _cli("fix", str(path), "-o", str(tmp_path / "out.urdf"), "--json")
    assert code in (0, 1), err
    assert [f["code"] for f in json.loads(out)["fixes"]] == ["U706"]
    root = etree.parse(str(tmp_path / "out.urdf")).getroot()
    assert [m.get("name") for m in root.iter("material")] == [name, name]


def test_fix_warns_when_raw_pybullet_cannot_reach_a_nested_package(
        tmp_path: Path, raw_loads: Callable[[Path], bool]) -> None:
    # A package one folder deeper than its name (turtlebot4 on create3_sim's
    # irobot_create_common/irobot_create_description), found by its package.xml only: the
    # repaired copy written outside the workspace is out of raw PyBullet's reach.
    pkg = tmp_path / "ws" / "group" / "mypkg"
    (pkg / "meshes").mkdir(parents=True)
    (pkg / "package.xml").write_text("<package><name>mypkg</name></package>")
    shutil.copy(MESHES / "unit_cube.stl", pkg / "meshes" / "cube.stl")
    src = tmp_path / "ws" / "group" / "robot.urdf"
    src.write_text('<robot name="r"><link name="a"><inertial><mass value="1"/>'
                   '<inertia ixx="1" ixy="0" ixz="0" iyy="1" iyz="0" izz="3"/></inertial>'
                   '<collision><geometry><mesh filename="package://mypkg/meshes/cube.stl"/>'
                   '</geometry></collision></link></robot>')
    assert raw_loads(src)
    outside, inside = tmp_path / "out" / "r.urdf", tmp_path / "ws" / "group" / "fixed.urdf"
    outside.parent.mkdir()
    for out in (outside, inside):
        result = CliRunner().invoke(app, ["fix", str(src), "-o", str(out)])
        assert result.exit_code == 0, result.output
        assert 'izz="3"' not in out.read_text()  # the U604 inertia was repaired
        warned = "raw p.loadURDF will not find 1 package:// file(s)" in result.output
        # The warning says exactly what raw PyBullet then does with the written file.
        assert warned == (out == outside) == (not raw_loads(out)), (out, result.output)


def test_a_package_uri_repaired_elsewhere_is_named_from_there(
        tmp_path: Path, raw_loads: Callable[[Path], bool]) -> None:
    # U708 without a package.xml becomes a relative path: relative to where it is written.
    src, out = tmp_path / "src", tmp_path / "out"
    src.mkdir()
    out.mkdir()
    shutil.copy(MESHES / "unit_cube.stl", src / "cube.stl")
    path = src / "r.urdf"
    path.write_text('<robot name="r"><link name="b"><inertial><mass value="1"/><inertia '
                    'ixx="0.1" ixy="0" ixz="0" iyy="0.1" iyz="0" izz="0.1"/></inertial>'
                    '<visual><geometry><mesh filename="package:///cube.stl"/></geometry>'
                    '</visual></link></robot>')
    code, _, err = _cli("fix", str(path), "--select", "U708", "-o", str(out / "r.urdf"))
    assert code == 0, err
    assert 'filename="../src/cube.stl"' in (out / "r.urdf").read_text()
    assert raw_loads(out / "r.urdf")
