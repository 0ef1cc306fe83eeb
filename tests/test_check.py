"""Every rule of ``urdfkit check`` on its own small fixture: the code AND the line."""

from __future__ import annotations

import json
import math
from pathlib import Path

import pytest
from typer.testing import CliRunner

from urdfkit.checks.check import check_file, check_paths, discover, parse_codes
from urdfkit.checks.validate import ALL_RULES, CODES
from urdfkit.cli import app
from urdfkit.core.errors import ParameterError
from urdfkit.sources.guard import GUARD_RULES

INERTIAL = ('<inertial><mass value="1"/>'
            '<inertia ixx="0.1" ixy="0" ixz="0" iyy="0.1" iyz="0" izz="0.1"/></inertial>')
BOX = '<collision><geometry><box size="0.5 0.5 0.5"/></geometry></collision>'


def link(name: str, inertial: str = INERTIAL, body: str = BOX) -> str:
    return f'<link name="{name}">{inertial}{body}</link>'


def joint(name: str = "j", parent: str = "a", child: str = "b", jtype: str = "revolute",
          inner: str = '<axis xyz="0 0 1"/><limit lower="-1" upper="1" effort="1" '
                       'velocity="1"/>') -> str:
    return (f'<joint name="{name}" type="{jtype}"><parent link="{parent}"/>'
            f'<child link="{child}"/>{inner}</joint>')


def doc(*lines: str, name: str = "r") -> str:
    """A robot with one element per line; the line marked <!--HERE--> is the expected one."""
    return "\n".join([f'<robot name="{name}">', *lines, "</robot>", ""])


A, B = link("a"), link("b")
MESHES = Path(__file__).parent / "fixtures" / "meshes"
J = joint()

# (code, document); the finding must be on the line that holds <!--HERE-->.
CASES = [
    ("U001", '<model name="m"><!--HERE-->\n<link name="a"/>\n</model>\n'),
    ("U002", '<robot><!--HERE-->\n' + A + "\n</robot>\n"),
    ("U003", '<robot name="r"><!--HERE-->\n</robot>\n'),
    ("U005", doc(link("a", body="<x>" * 97 + "<!--HERE-->" + "</x>" * 97))),
    ("U101", doc(A, '<link><!--HERE-->' + INERTIAL + "</link>")),
    ("U102", doc(A, B, J, link("b") + "<!--HERE-->")),
    ("U103", doc(A, B, link("c"), J, joint("j", "b", "c") + "<!--HERE-->")),
    ("U104", doc(A, link("b%n") + "<!--HERE-->", joint(child="b%n"))),
    ("U105", doc('<material name="m"><color rgba="1 0 0 1"/></material>',
                 '<material name="m"><!--HERE--><color rgba="1 0 0 1"/></material>', A)),
    ("U109", doc('<material><!--HERE-->\n<color rgba="1 0 0 1"/></material>', A)),
    ("U110", doc(link("a", body='<visual><geometry><box size="1 1 1"/></geometry>\n'
                                '<material><color rgba="1 0 0 1"/></material><!--HERE-->\n'
                                '</visual>'))),
    ("U106", doc(A, link("b", "", "") + "\n" + joint("é" * 632) + "<!--HERE-->")),
    ("U107", doc(A, B, joint("j%s%n") + "<!--HERE-->")),
    ("U108", doc(A, link("ロ" * 334) + "<!--HERE-->", joint(child="ロ" * 334))),
    ("U201", doc(A, B, '<joint name="j" type="fixed"><!--HERE--><child link="b"/></joint>')),
    ("U202", doc(A, B, '<joint name="j" type="fixed"><parent link="a"/>\n'
                       '<child link="ghost"/><!--HERE--></joint>')),
    ("U203", doc(A, B, J, joint("k", "b", "b") + "<!--HERE-->")),
    ("U204", doc(A, B, link("c"), joint("j1", "a", "c"), joint("j3", "a", "b"),
                 joint("j2", "b", "c") + "<!--HERE-->")),
    ("U205", doc(A, B + "<!--HERE-->")),
    ("U206", doc(A, B, joint("j1", "a", "b"), joint("j2", "b", "a")).replace(
        '<robot name="r">', '<robot name="r"><!--HERE-->')),
    ("U207", doc(A, B, link("c"), joint("j1", "b", "c"),
                 joint("j2", "c", "b") + "<!--HERE-->")),
    ("U301", doc(A, B, joint(jtype="wobbly") + "<!--HERE-->")),
    ("U302", doc(A, B, joint(inner="") + "<!--HERE-->")),
    ("U303", doc(A, B, '<joint name="j" type="prismatic"><parent link="a"/><child link="b"/>',
                 '<limit lower="0" upper="1" effort="1"/><!--HERE-->', "</joint>")),
    ("U304", doc(A, B, '<joint name="j" type="revolute"><parent link="a"/><child link="b"/>',
                 '<limit lower="1" upper="0" effort="1" velocity="1"/><!--HERE-->', "</joint>")),
    ("U305", doc(A, B, '<joint name="j" type="continuous"><parent link="a"/><child link="b"/>',
                 '<axis xyz="0 0 0"/><!--HERE-->', "</joint>")),
    ("U306", doc(A, B, '<joint name="j" type="continuous"><parent link="a"/><child link="b"/>',
                 '<axis xyz="0 0 2"/><!--HERE-->', "</joint>")),
    ("U307", doc(A, B, '<joint name="j" type="continuous"><parent link="a"/><child link="b"/>',
                 '<mimic joint="nope"/><!--HERE-->', "</joint>")),
    ("U309", doc(A, B, link("c"),
                 '<joint name="j1" type="continuous"><parent link="a"/><child link="b"/>',
                 '<mimic joint="j2"/><!--HERE-->', "</joint>",
                 '<joint name="j2" type="continuous"><parent link="b"/><child link="c"/>',
                 '<mimic joint="j1"/>', "</joint>")),
    ("U310", doc(A, B, link("c"), joint("j1", "a", "b"),
                 '<joint name="j2" type="continuous"><parent link="a"/><child link="c"/>',
                 '<mimic joint="j1" multiplier="-1"/><!--HERE-->', "</joint>")),
    ("U311", doc(A, link("b", '<inertial><mass value="0.01"/><inertia ixx="1e-6" iyy="1e-6" '
                              'izz="1e-6" ixy="0" ixz="0" iyz="0"/></inertial>', ""),
                 '<joint name="j" type="continuous"><parent link="a"/><child link="b"/>',
                 '<axis xyz="0 0 1"/><dynamics damping="0.1"/><!--HERE-->', "</joint>")),
    ("U401", doc(A, B, '<joint name="j" type="fixed"><parent link="a"/><child link="b"/>',
                 '<origin xyz="0 nan 0"/><!--HERE-->', "</joint>")),
    ("U402", doc(A, B, '<joint name="j" type="fixed"><parent link="a"/><child link="b"/>',
                 '<origin xyz="0 0"/><!--HERE-->', "</joint>")),
    ("U501", doc(link("a", body='<collision><geometry>\n<sphere radius="0"/><!--HERE-->\n'
                                '</geometry></collision>'))),
    ("U502", doc(link("a", body='<collision>\n<geometry><!--HERE--></geometry>\n'
                                '</collision>'))),
    ("U507", doc(link("a", body='<collision>\n<geometry><box size="1 1 1"/>\n'
                                '<sphere radius="1"/><!--HERE--></geometry>\n</collision>'))),
    ("U503", doc(link("a", body='<visual><geometry>\n<mesh/><!--HERE-->\n</geometry></visual>'))),
    ("U601", doc(link("a", '<inertial>\n<mass value="-1"/><!--HERE-->\n</inertial>'))),
    ("U602", doc(A, link("b", '<inertial><mass value="0"/></inertial>') + "<!--HERE-->",
                 joint(jtype="continuous", inner=""))),
    ("U603", doc(link("a", '<inertial><mass value="1"/>\n<inertia ixx="1" ixy="0" ixz="0" '
                           'iyy="1" iyz="0" izz="-1"/><!--HERE-->\n</inertial>'))),
    ("U604", doc(link("a", '<inertial><mass value="1"/>\n<inertia ixx="0.1" ixy="0" ixz="0" '
                           'iyy="0.1" iyz="0" izz="1"/><!--HERE-->\n</inertial>'))),
    ("U605", doc(link("a", '<inertial><mass value="1"/>\n<inertia ixx="100" ixy="0" ixz="0" '
                           'iyy="100" iyz="0" izz="100"/><!--HERE-->\n</inertial>'))),
    ("U606", doc(link("a", inertial="") + "<!--HERE-->")),
    ("U607", doc(link("a", '<inertial><mass value="1"/>\n<inertia ixx="0.1" ixy="0" ixz="0" '
                           'iyy="0.1" iyz="0" izz="0.1"/><!--HERE-->\n</inertial>'))),
    ("U608", doc(link("a", '<inertial><mass value="1"/>\n<inertia ixx="0.1" ixy="0" ixz="0" '
                           'iyy="0.1" iyz="0" izz="0"/><!--HERE-->\n</inertial>'))),
    ("U701", doc(link("a", body='<visual><geometry>\n<mesh filename="gone.stl"/><!--HERE-->\n'
                                '</geometry></visual>'))),
    ("U702", doc(link("a", body='<visual><geometry>\n<mesh filename="package://nopkg/m.stl"/>'
                                '<!--HERE-->\n</geometry></visual>'))),
    ("U703", doc(link("a", body='<visual><geometry>\n<mesh filename="r2d2.urdf"/>'
                                '<!--HERE-->\n</geometry></visual>'))),
    ("U704", doc(link("a", body='<visual><geometry>\n<mesh filename="."/>'
                                '<!--HERE-->\n</geometry></visual>'))),
    ("U504", doc(link("a", body='<visual><geometry><box size="1 1 1"/>\n<origin xyz="1 0 0"/>'
                                '<!--HERE-->\n</geometry></visual>'))),
    ("U505", doc(link("a", body='<visual><geometry>\n<origin xyz="1 0 0"/><!--HERE-->'
                                '<box size="1 1 1"/>\n</geometry></visual>'))),
    ("U506", doc(link("a", body='\n<visual><!--HERE--><origin xyz="1 0 0"/></visual>'))),
    ("U609", doc(link("a", '<inertial><!--HERE--><mass value="1"/>\n</inertial>'))),
    ("U610", doc(link("a", '<inertial><mass value="1"/>\n<inertia ixx="0.1" ixy="0" ixz="0" '
                           'iyy="0.1" iyz="0"/><!--HERE-->\n</inertial>'))),
    ("U705", doc(link("a", body='<visual><geometry>\n<mesh filename="robot.urdf"/>'
                                '<!--HERE-->\n</geometry></visual>'))),
    ("U308", doc(A, B, joint(inner='<axis xyz="0 0 1"/>\n<limit effort="1" velocity="1"/>'
                                   '<!--HERE-->\n'))),
    ("U611", doc(link("a", '<inertial><mass value="0"/><inertia ixx="0" ixy="0" ixz="0" '
                           'iyy="0" iyz="0" izz="0"/></inertial>') + "<!--HERE-->", B, J)),
    ("U612", doc(link("a", '<inertial><mass value="1"/><inertia ixx="0.1" ixy="0" ixz="0" '
                           'iyy="0.1" iyz="0" izz="0.1"/></inertial>',
                      f'<collision><geometry>\n<mesh filename="{MESHES / "open_triangle.stl"}"/>'
                      '<!--HERE-->\n</geometry></collision>'))),
    # A 100 mm cube written in millimetres on an arm whose joints are 0.3 m apart.
    ("U613", doc(A, B, link("c", body=f'<visual><geometry>\n<mesh filename='
                                      f'"{MESHES / "cube_mm.obj"}"/><!--HERE-->\n'
                                      '</geometry></visual>'),
                 joint(inner='<origin xyz="0 0 0.3"/><axis xyz="0 0 1"/><limit lower="-1" '
                             'upper="1" effort="1" velocity="1"/>'),
                 joint("k", "b", "c", inner='<origin xyz="0.3 0 0"/><axis xyz="0 0 1"/><limit '
                                           'lower="-1" upper="1" effort="1" velocity="1"/>'))),
    ("U614", doc(A, link("b", body=f'<collision><geometry>\n<mesh filename='
                                   f'"{MESHES / "l_bracket.obj"}" scale="0.1 0.1 0.1"/>'
                                   '<!--HERE-->\n</geometry></collision>'), J)),
    ("U710", doc(link("a", body='<visual><geometry><box size="1 1 1"/></geometry>'
                                '<material name="m"><color rgba="1 0 0 1"/></material></visual>'
                                '<visual><geometry><box size="1 1 1"/></geometry>'
                                '<material name="m">\n<color rgba="0 1 0 1"/><!--HERE-->\n'
                                '</material></visual>'))),
    ("U712", doc(link("a", body=f'<visual><geometry>\n<mesh filename='
                                f'"{MESHES / "no_asset.dae"}"/><!--HERE-->\n</geometry>'
                                '</visual>'))),
    ("U713", doc(link("a", body=f'<collision><geometry>\n<mesh filename='
                                f'"{MESHES / "nan_vertex.stl"}"/><!--HERE-->\n</geometry>'
                                '</collision>'))),
    ("U706", doc(link("a", body='<visual><geometry><box size="1 1 1"/></geometry>\n'
                                '<material name="steel"/><!--HERE-->\n</visual>'))),
    ("U707", doc('<material name="m">\n<texture/><!--HERE-->\n</material>', A)),
    ("U708", doc(link("a", body='<visual><geometry>\n<mesh filename="package:///robot.urdf"/>'
                                '<!--HERE-->\n</geometry></visual>'))),
    ("U709", doc(A, B, J, '<transmission name="t"><type>x</type>\n<joint name="ghost"/>'
                          '<!--HERE-->\n</transmission>')),
    ("U801", doc(link("a", body=BOX + "\n<colision/><!--HERE-->\n"))),
    ("U802", doc(link("a", body='<collision><geometry>\n<box size="1 1 1" colour="red"/>'
                                '<!--HERE-->\n</geometry></collision>'))),
    ("U803", doc(A, '<gazebo reference="a"><!--HERE-->\n<mu1>0.9</mu1></gazebo>')),
    ("U804", doc(link("a", body=BOX + '<contact>\n<stiffness value="0"/><!--HERE-->\n'
                                '<damping value="1"/></contact>'))),
    ("U901", doc(A, B, joint(jtype="spherical", inner="") + "<!--HERE-->")),
]


def _line(text: str) -> int:
    return next(i for i, ln in enumerate(text.splitlines(), 1) if "<!--HERE-->" in ln)


# U008 (a line PyBullet breaks) is tested against raw PyBullet in tests/test_guard.py; U009
# (a .urdf holding xacro) in tests/test_build_unseen.py; U715 (a visual PyBullet draws
# nothing of) against PyBullet's own picture in tests/test_no_silent_misses.py; U712 and U713
# (mesh files PyBullet crashes or hangs on) against raw PyBullet in tests/test_guard_meshes.py.
def test_every_code_has_a_case() -> None:
    # U950 and U951 need PyBullet (check --physics): tests/test_collisions.py.
    # U010 (a fragment) needs its includer in the run: tests/test_fragments.py.
    # U711 needs a package folder of another name: tests/test_packages.py.
    # The T codes (check --target): tests/test_check_targets.py, each against its engine.
    tested = {code for code, _ in CASES} | {"U000", "U004", "U006", "U007", "U008", "U009",
                                            "U010", "U208", "U209", "U711", "U715", "U950", "U951"}
    assert tested == {code for code in CODES if not code.startswith("T")}


@pytest.mark.parametrize(("code", "text"), CASES, ids=[c for c, _ in CASES])
def test_rule_reports_code_and_line(code: str, text: str, tmp_path: Path) -> None:
    path = tmp_path / "robot.urdf"
    path.write_text(text)
    found = [(f.code, f.line) for f in check_file(str(path), path).findings]
    assert (code, _line(text)) in found, found
    level = next(f.level for f in check_file(str(path), path).findings if f.code == code)
    assert level in ("error", "warning", "info")


def test_valid_robot_has_no_errors_or_warnings(simplecar_urdf: Path) -> None:
    findings = check_file(str(simplecar_urdf), simplecar_urdf).findings
    assert [f for f in findings if f.level != "info"] == []


def test_u208_many_links(tmp_path: Path) -> None:
    n = 128
    text = doc(*(link(f"l{i}") for i in range(n)),
               *(joint(f"j{i}", f"l{i}", f"l{i + 1}") for i in range(n - 1)))
    path = tmp_path / "chain.urdf"
    path.write_text(text)
    found = [(f.code, f.line) for f in check_file("chain.urdf", path).findings]
    assert ("U208", 1) in found
    path.write_text(text.replace(link("l127"), "").replace(joint("j126", "l126", "l127"), ""))
    assert "U208" not in {f.code for f in check_file("chain.urdf", path).findings}


def test_u209_huge_body_refused_by_guard(tmp_path: Path) -> None:
    from urdfkit.core.errors import InputError
    from urdfkit.sources.resolve import resolve

    n = 1001
    path = tmp_path / "chain.urdf"
    path.write_text(doc(*(link(f"l{i}") for i in range(n)),
                        *(joint(f"j{i}", f"l{i}", f"l{i + 1}") for i in range(n - 1))))
    assert ("U209", 1) in [(f.code, f.line) for f in check_file("chain.urdf", path).findings]
    with pytest.raises(InputError, match="1001 links"):
        resolve(path)


def test_u000_broken_xml_line(tmp_path: Path) -> None:
    path = tmp_path / "broken.urdf"
    path.write_text('<robot name="r">\n<link name="a">\n</robot>\n')
    [f] = check_file("broken.urdf", path).findings
    assert (f.code, f.level, f.line) == ("U000", "error", 3)
    assert "not well-formed" in f.message


def test_u004_quirks_are_warnings_and_rules_still_run(tmp_path: Path) -> None:
    path = tmp_path / "old.urdf"
    path.write_text('\n\n<?xml version="1.0"?>\n' + doc(link("a", inertial="")))
    codes = [(f.code, f.line) for f in check_file("old.urdf", path).findings]
    assert ("U004", 3) in codes and ("U606", 5) in codes


def test_package_uri_resolved_by_option_and_by_package_xml(tmp_path: Path) -> None:
    pkg = tmp_path / "src" / "mybot_description"
    (pkg / "meshes").mkdir(parents=True)
    (pkg / "meshes" / "m.stl").write_bytes(b"solid x\nendsolid x\n")
    (pkg / "package.xml").write_text("<package><name>mybot_description</name></package>")
    urdf = pkg / "urdf" / "r.urdf"
    urdf.parent.mkdir()
    urdf.write_text(doc(link("a", body='<visual><geometry><mesh filename="package://'
                                       'mybot_description/meshes/m.stl"/></geometry></visual>')))
    assert not [f for f in check_file("r.urdf", urdf).findings if f.code.startswith("U7")]
    elsewhere = tmp_path / "r.urdf"
    elsewhere.write_text(urdf.read_text())
    assert "U702" in {f.code for f in check_file("r.urdf", elsewhere).findings}
    ok = check_file("r.urdf", elsewhere, packages={"mybot_description": pkg}).findings
    assert not [f for f in ok if f.code.startswith("U7")]


def test_relative_mesh_found_beside_file(tmp_path: Path) -> None:
    (tmp_path / "meshes").mkdir()
    (tmp_path / "meshes" / "m.obj").write_text("v 0 0 0\n")
    path = tmp_path / "r.urdf"
    path.write_text(doc(link("a", body='<visual><geometry><mesh filename="meshes/m.obj"/>'
                                       "</geometry></visual>")))
    assert not [f for f in check_file("r.urdf", path).findings if f.code.startswith("U7")]


def test_pybullet_extensions_are_not_unknown(tmp_path: Path) -> None:
    path = tmp_path / "ext.urdf"
    path.write_text(doc(
        link("a", body='<contact><lateral_friction value="1"/><rolling_friction value="0"/>'
                       '<stiffness value="1"/><damping value="1"/><friction_anchor/></contact>'
                       '<collision group="1" mask="1" concave="yes"><geometry>'
                       '<capsule radius="0.1" length="0.2"/></geometry></collision>'),
        '<gazebo reference="a"><mu1>0.2</mu1><anything/></gazebo>',
        '<transmission name="t"><type>x</type></transmission>'))
    found = check_file("ext.urdf", path).findings
    assert not [f for f in found if f.code in ("U801", "U802")]
    # The Gazebo friction differs from the link's own <contact>: PyBullet uses the latter.
    assert [f.code for f in found if f.code.startswith("U8")] == ["U803"]


def test_guard_rules_are_a_subset_of_check() -> None:
    assert set(GUARD_RULES) < set(ALL_RULES)


# --------------------------------------------------------------------------- files, options


def test_folder_is_searched_recursively_and_xacro_expanded(tmp_path: Path) -> None:
    (tmp_path / "a" / "b").mkdir(parents=True)
    (tmp_path / "a" / "b" / "r.urdf").write_text(doc(A))
    (tmp_path / "a" / "notes.txt").write_text("not a robot")
    (tmp_path / "car.urdf.xacro").write_text(
        '<robot name="x" xmlns:xacro="http://www.ros.org/wiki/xacro">\n'
        '<xacro:property name="m" value="2"/>\n'
        '<link name="a"><inertial><mass value="${m * -1}"/><inertia ixx="1" ixy="0" ixz="0" '
        'iyy="1" iyz="0" izz="1"/></inertial></link>\n</robot>\n')
    result = check_paths([tmp_path], jobs=1)
    names = [Path(f.file).name for f in result.files]
    assert sorted(names) == ["car.urdf.xacro", "r.urdf"]
    xacro = next(fr for fr in result.files if fr.file.endswith(".xacro"))
    assert [f.code for f in xacro.findings if f.level == "error"] == ["U601"]


def test_missing_path_is_a_parameter_error(tmp_path: Path) -> None:
    with pytest.raises(ParameterError, match="no such file"):
        discover([tmp_path / "nope"])


def test_select_and_ignore_prefixes() -> None:
    assert parse_codes(["U2,u601", " U8 "], "--select") == ("U2", "U601", "U8")
    with pytest.raises(ParameterError, match="U99"):
        parse_codes(["U99"], "--select")


runner = CliRunner()


def _two_files(tmp_path: Path) -> tuple[Path, Path]:
    good = tmp_path / "good.urdf"
    good.write_text(doc(A))
    bad = tmp_path / "bad.urdf"
    bad.write_text(doc(A, link("a") + "\n", link("b", inertial="")))
    return good, bad


def test_cli_exit_codes_and_grouped_output(tmp_path: Path) -> None:
    good, bad = _two_files(tmp_path)
    r = runner.invoke(app, ["check", str(good)])
    assert r.exit_code == 0, r.output
    assert "1 file(s) checked: 0 error(s)" in r.output
    r = runner.invoke(app, ["check", str(tmp_path)])
    assert r.exit_code == 1
    assert str(bad) in r.output and "U102" in r.output and "U205" in r.output
    r = runner.invoke(app, ["check", str(tmp_path), "--ignore", "U1,U2"])
    assert r.exit_code == 0, r.output
    r = runner.invoke(app, ["check", str(tmp_path), "--ignore", "U1,U2", "--fail-on", "warning"])
    assert r.exit_code == 1 and "U606" in r.output
    r = runner.invoke(app, ["check", str(tmp_path / "missing.urdf")])
    assert r.exit_code == 2 and "missing.urdf" in r.output
    r = runner.invoke(app, ["check", str(good), "--fail-on", "fatal"])
    assert r.exit_code == 2


def test_cli_json(tmp_path: Path) -> None:
    good, bad = _two_files(tmp_path)
    r = runner.invoke(app, ["check", str(tmp_path), "--json", "--select", "U1"])
    assert r.exit_code == 1
    data = json.loads(r.stdout)
    assert sorted(data["files"]) == sorted([str(good), str(bad)])
    assert {f["code"] for f in data["findings"]} == {"U102"}
    [f] = data["findings"]
    assert f == {"file": str(bad), "line": 3, "level": "error", "code": "U102",
                 "message": f["message"], "origin": None}
    assert data["summary"] == {"files": 2, "files_with_errors": 1, "error": 1, "warning": 0,
                               "info": 0}


def test_inertia_messages_read_like_a_fix(tmp_path: Path) -> None:
    inertial = ('<inertial><mass value="2"/><inertia ixx="{}" ixy="0" ixz="0" iyy="0.1" '
                'iyz="0" izz="{}"/></inertial>')
    path = tmp_path / "r.urdf"
    path.write_text(doc(
        link("a", inertial.format("0.1", "-4.2e-22"),
             '<collision><geometry><box size="0.2 0.2 0.2"/></geometry></collision>'),
        link("b", inertial.format("0.01", "0.5"),
             '<collision><geometry><box size="0.2 0.2 0.2"/></geometry></collision>'),
        link("c", inertial.format("0.1", "0.1"),
             '<collision><geometry><sphere radius="0.001"/></geometry></collision>'),
        joint("j1", "a", "b", "fixed", ""), joint("j2", "b", "c", "fixed", "")))
    by_code = {(f.code, f.message.split("'")[1]): f.message
               for f in check_paths([path], jobs=1).findings if f.code in ("U604", "U605", "U608")}
    # Round-off prints as 0, and the message says what would pass.
    singular = by_code[("U608", "a")]
    assert "principal moments 0, 0.1, 0.1" in singular and "e-22" not in singular
    assert "imply a trace of 0.04, e.g. ixx=iyy=izz=0.01333 with products 0" in singular
    triangle = by_code[("U604", "b")]
    assert "lower the largest to at most 0.11" in triangle
    # A 1 mm sphere is a placeholder: the message blames the stub, not the units.
    stub = by_code[("U605", "c")]
    assert "stubs (largest size 0.002 m)" in stub and "units" not in stub


def test_repeated_findings_are_grouped_in_text_and_kept_in_json(tmp_path: Path) -> None:
    bare = [f'<link name="l{i}"/>' for i in range(7)]
    joints = [joint(f"j{i}", "l0", f"l{i}", "fixed", "") for i in range(1, 7)]
    (tmp_path / "many.urdf").write_text(doc(*bare, *joints))
    (tmp_path / "a.urdf").write_text(doc(A))
    (tmp_path / "b.urdf").write_text(doc(A))
    text = CliRunner().invoke(app, ["check", str(tmp_path)]).stdout
    assert text.count("U606  <link name=") == 3
    assert "... and 4 more U606 in this file (--all or --json lists every one)" in text
    doc_json = json.loads(CliRunner().invoke(app, ["check", str(tmp_path), "--json"]).stdout)
    codes = [f["code"] for f in doc_json["findings"]]
    assert codes.count("U606") == 7
    assert codes.count("U607") == 1  # the same advice for every file, said once per run


@pytest.mark.parametrize(("scale", "ixx", "flagged"), [
    (0.2, 0.1 * 0.04 / 6 * 1, False),  # a 0.2 m cube of 0.1 kg: I = m a^2 / 6
    (0.2, 0.5, True),                  # 750x the cube's: flagged
    (200.0, 0.1 * 0.04 / 6, True),     # a mesh in millimetres (200 m across): flagged
])
def test_inertia_is_judged_against_collision_meshes(tmp_path: Path, scale: float, ixx: float,
                                                    flagged: bool) -> None:
    inertial = (f'<inertial><mass value="0.1"/><inertia ixx="{ixx}" ixy="0" ixz="0" '
                f'iyy="{ixx}" iyz="0" izz="{ixx}"/></inertial>')
    mesh = (f'<collision><geometry><mesh filename="{MESHES / "unit_cube.stl"}" '
            f'scale="{scale} {scale} {scale}"/></geometry></collision>')
    path = tmp_path / "r.urdf"
    path.write_text(doc(link("a", inertial, mesh)))
    codes = [f.code for f in check_paths([path], jobs=1).findings]
    assert ("U605" in codes) == flagged, codes


def _codes(tmp_path: Path, text: str) -> list[str]:
    path = tmp_path / "r.urdf"
    path.write_text(text)
    return [f.code for f in check_paths([path], jobs=1).findings]


def test_concave_meshes_are_judged_on_moving_links_only(tmp_path: Path) -> None:
    import pybullet_data

    data = Path(pybullet_data.getDataPath())

    def on(link_name: str, mesh: Path, scale: str = "0.1 0.1 0.1") -> str:
        body = (f'<collision><geometry><mesh filename="{mesh}" scale="{scale}"/></geometry>'
                '</collision>')
        return doc(link("a", body=body if link_name == "a" else BOX),
                   link("b", body=body if link_name == "b" else BOX), J)

    assert "U614" in _codes(tmp_path, on("b", MESHES / "l_bracket.obj"))
    assert "U614" not in _codes(tmp_path, on("a", MESHES / "l_bracket.obj"))  # the base
    assert "U614" not in _codes(tmp_path, on("b", MESHES / "unit_cube.stl"))  # convex
    # A V-HACD decomposition: concave overall, but PyBullet makes one hull per object.
    assert "U614" not in _codes(tmp_path, on("b", data / "duck_vhacd.obj"))
    assert "U614" in _codes(tmp_path, on("b", data / "torus" / "torus_textured.obj"))


def test_a_mesh_first_seen_on_a_static_link_is_still_judged_concave_on_a_moving_one(
        tmp_path: Path) -> None:
    """The concavity depth is worked out only where a rule needs it: a cache entry made for
    a static link (no depth) is completed, not trusted, when a moving link uses the mesh."""
    from urdfkit.sources import meshes, meshstore

    bracket = tmp_path / "bracket.obj"  # a mesh no other test has cached
    bracket.write_bytes((MESHES / "l_bracket.obj").read_bytes())
    body = (f'<collision><geometry><mesh filename="{bracket}" scale="0.1 0.1 0.1"/></geometry>'
            '</collision>')
    static = doc(link("a", body=body), link("b", body=BOX), J)
    moving = doc(link("a", body=BOX), link("b", body=body), J)
    assert "U614" not in _codes(tmp_path, static)
    memory = dict(meshstore._MEMORY)
    (entry,) = [v for k, v in memory.items() if k.startswith(f"{bracket}\0")]
    assert entry is not None and math.isnan(entry.concavity)  # not worked out for the base
    meshstore._MEMORY.clear()  # a new process: only the cache folder remembers
    path = tmp_path / "r.urdf"
    path.write_text(moving)
    found = [f for f in check_paths([path], jobs=1, cache=False).findings if f.code == "U614"]
    assert len(found) == 1
    expected = meshes.read_integrals(bracket)
    assert expected is not None and expected.concavity > 0
    assert f"{expected.concavity * 0.1:.3g} m in front" in found[0].message


def test_millimetre_meshes_are_flagged_until_scaled(tmp_path: Path) -> None:
    arm = [joint(inner='<origin xyz="0 0 0.3"/><axis xyz="0 0 1"/><limit lower="-1" upper="1" '
                       'effort="1" velocity="1"/>'),
           joint("k", "b", "c", inner='<origin xyz="0.3 0 0"/><axis xyz="0 0 1"/><limit '
                                      'lower="-1" upper="1" effort="1" velocity="1"/>')]

    def mesh(scale: str) -> str:
        return (f'<visual><geometry><mesh filename="{MESHES / "cube_mm.obj"}" scale="{scale}"/>'
                '</geometry></visual>')

    def with_scale(scale: str) -> str:
        return doc(A, B, link("c", body=mesh(scale)), *arm)

    assert "U613" in _codes(tmp_path, with_scale("1 1 1"))
    assert "U613" not in _codes(tmp_path, with_scale("0.001 0.001 0.001"))  # 0.1 m: right
    assert "U613" in _codes(tmp_path, with_scale("0.000001 0.000001 0.000001"))  # scaled twice
    # Without two offset joints there is no scale to judge by.
    assert "U613" not in _codes(tmp_path, doc(A, link("b", body=mesh("1 1 1")), J))


@pytest.mark.parametrize("text", [
    # ROS 1's include files: a <root> element (pr2_description's sensors).
    '<root xmlns:xacro="http://wiki.ros.org/xacro"><xacro:macro name="cam" params="p">'
    '<link name="${p}_cam"/></xacro:macro></root>',
    # A named library of macros and properties (franka_description's franka_arm.xacro).
    '<robot name="arm" xmlns:xacro="http://wiki.ros.org/xacro"><xacro:property name="r" '
    'value="0.1"/><xacro:macro name="arm" params="p"><link name="${p}_l"/></xacro:macro>'
    '</robot>'])
def test_xacro_libraries_are_noted_not_errors(text: str, tmp_path: Path) -> None:
    path = tmp_path / "lib.xacro"
    path.write_text(text)
    assert [(f.code, f.level) for f in check_file(str(path), path).findings] == [
        ("U007", "info")]


def test_a_used_but_undeclared_xacro_arg_can_be_given(tmp_path: Path) -> None:
    # unitree_ros uses $(arg DEBUG) without <xacro:arg>; xacro takes DEBUG:=false anyway.
    path = tmp_path / "robot.xacro"
    path.write_text('<robot name="r" xmlns:xacro="http://wiki.ros.org/xacro"><link name="a"/>'
                    '<xacro:if value="$(arg DEBUG)"><link name="debug"/>'
                    '<joint name="j" type="fixed"><parent link="a"/><child link="debug"/>'
                    '</joint></xacro:if></robot>')
    missing = check_file(str(path), path).findings
    assert [f.code for f in missing] == ["U000"] and "DEBUG:=VALUE" in missing[0].message
    given = check_file(str(path), path, xacro_args={"DEBUG": "false"}).findings
    assert not [f for f in given if f.level == "error"]
    from urdfkit.sources.resolve import resolve

    with resolve(path, xacro_args={"DEBUG": "true"}) as r:  # strict: the name is known
        assert [x.get("name") for x in r.root.iter("link")] == ["a", "debug"]


def test_text_groups_repeated_codes_and_all_lists_them(tmp_path: Path) -> None:
    from typer.testing import CliRunner

    from urdfkit.cli import app

    path = tmp_path / "many.urdf"
    path.write_text(doc(*(link(f"l{i}", inertial="") for i in range(7)),  # 7 x U606
                        *(joint(f"j{i}", f"l{i}", f"l{i + 1}") for i in range(6))))
    grouped = CliRunner().invoke(app, ["check", str(path)]).stdout
    every = CliRunner().invoke(app, ["check", str(path), "--all"]).stdout
    assert grouped.count("warning  U606  <link") == 3 and "4 more U606" in grouped
    assert "--all or --json lists every one" in grouped
    assert every.count("warning  U606  <link") == 7 and "more" not in every


def test_a_findings_json_form_is_its_fields_in_order() -> None:
    # CheckResult.to_dict hands the JSON writer each finding's own fields (no copy): they must
    # be exactly Finding.to_dict, keys in the same order.
    from urdfkit.checks.check import CheckResult, FileResult
    from urdfkit.core.finding import Finding

    findings = [Finding("U201", "error", "m", "f.urdf", 3, None),
                Finding("U601", "warning", "n", "g.urdf", None, "inc.xacro:4")]
    data = CheckResult([FileResult("f.urdf", findings)]).to_dict()
    assert [list(d.items()) for d in data["findings"]] == \
        [list(f.to_dict().items()) for f in findings]  # type: ignore[union-attr]


def _cube_stl(path: Path) -> None:
    """A binary STL unit cube (PyBullet reads binary STL)."""
    import struct

    v = [(x, y, z) for x in (0.0, 1.0) for y in (0.0, 1.0) for z in (0.0, 1.0)]
    faces = ((0, 1, 3), (0, 3, 2), (4, 6, 7), (4, 7, 5), (0, 4, 5), (0, 5, 1), (2, 3, 7),
             (2, 7, 6), (0, 2, 6), (0, 6, 4), (1, 5, 7), (1, 7, 3))
    data = b"\0" * 80 + struct.pack("<I", len(faces))
    for face in faces:
        data += struct.pack("<3f", 0, 0, 0) + b"".join(struct.pack("<3f", *v[i]) for i in face)
        data += b"\0\0"
    path.write_bytes(data)


def test_a_missing_mesh_names_the_same_part_in_another_format(tmp_path: Path, pb) -> None:
    """Toyota HSR's hsrb4s.urdf names `torso_v0/torso.std` where the folder holds torso.stl
    (and .dae, .obj): U701 said only "file not found". It now names the files beside it with
    that stem in a mesh format, or the same name in another case; not merely close names
    (link_2.stl is another part than the missing link_1.stl). Raw PyBullet refuses the file as
    written and loads it with the name U701 offers."""
    from urdfkit.engine.session import quiet_stdout

    (tmp_path / "meshes").mkdir()
    for name in ("torso.stl", "link_2.stl"):
        _cube_stl(tmp_path / "meshes" / name)

    def robot(torso: str) -> str:
        return doc(link("a", body=f'<collision><geometry><mesh filename="meshes/{torso}"/>'
                        "</geometry></collision>"),
                   link("b", body='<visual><geometry><mesh filename="meshes/link_1.stl"/>'
                        "</geometry></visual>"), joint())

    path = tmp_path / "r.urdf"
    path.write_text(robot("torso.std"))
    r = runner.invoke(app, ["check", str(path), "--json", "--no-cache"])
    found = {f["message"].split("'")[1]: f["message"] for f in json.loads(r.stdout)["findings"]
             if f["code"] == "U701"}
    assert "; beside it: 'torso.stl';" in found["meshes/torso.std"], found
    assert "beside it" not in found["meshes/link_1.stl"], found
    p, c = pb
    with quiet_stdout(), pytest.raises(p.error):
        p.loadURDF(str(path), physicsClientId=c)  # raw PyBullet refuses it as written
    _cube_stl(tmp_path / "meshes" / "link_1.stl")
    path.write_text(robot("torso.stl"))
    fresh = p.connect(p.DIRECT)  # a fresh client: the same paths failed once in this one
    try:
        with quiet_stdout():
            assert p.loadURDF(str(path), physicsClientId=fresh) >= 0  # and loads it so
    finally:
        p.disconnect(fresh)
