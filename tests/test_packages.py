"""ROS description packages without ROS: $(find) across packages, yaml limits, args, and
package:// meshes, found through --package, --package-path, ROS_PACKAGE_PATH and
AMENT_PREFIX_PATH (fixtures in tests/fixtures/packages, modelled on ur_description)."""

from __future__ import annotations

import json
import shutil
from pathlib import Path

import pytest
from typer.testing import CliRunner

from urdfkit.cli import app
from urdfkit.sources.uris import PackageIndex

runner = CliRunner()
PACKAGES = Path(__file__).parent / "fixtures" / "packages"


@pytest.fixture
def workspaces(tmp_path: Path) -> tuple[Path, Path]:
    """The arm in one workspace, the macros it $(find)s in another: no walking up finds them."""
    arm_ws, macros_ws = tmp_path / "arm_ws" / "src", tmp_path / "macros_ws"
    shutil.copytree(PACKAGES / "arm_like_description", arm_ws / "arm_like_description")
    shutil.copytree(PACKAGES / "common_macros", macros_ws / "nested" / "common_macros")
    return arm_ws / "arm_like_description" / "urdf" / "arm.urdf.xacro", macros_ws


def joints(args: list[str], env: dict[str, str] | None = None) -> dict[str, object]:
    result = runner.invoke(app, ["joints", *args, "--json"], env=env)
    assert result.exit_code == 0, result.stderr
    return json.loads(result.stdout)


def test_find_fails_with_one_line_saying_how_to_fix(workspaces: tuple[Path, Path]) -> None:
    arm, _ = workspaces
    result = runner.invoke(app, ["joints", str(arm)], env={"ROS_PACKAGE_PATH": "",
                                                             "AMENT_PREFIX_PATH": ""})
    assert result.exit_code == 2
    (line,) = result.stderr.strip().splitlines()
    assert line.startswith(f"urdfkit: error: {arm}: xacro failed: $(find common_macros)")
    assert "--package (common_macros=PATH)" in line and "--package-path" in line


@pytest.mark.parametrize("how", ["package-path", "package", "ROS_PACKAGE_PATH",
                                 "AMENT_PREFIX_PATH"])
def test_find_resolves_without_ros(workspaces: tuple[Path, Path], tmp_path: Path,
                                   how: str) -> None:
    arm, macros_ws = workspaces
    env = {"ROS_PACKAGE_PATH": "", "AMENT_PREFIX_PATH": ""}
    args = [str(arm)]
    if how == "package-path":
        args += ["--package-path", str(macros_ws)]
    elif how == "package":
        args += ["--package", f"common_macros={macros_ws / 'nested' / 'common_macros'}"]
    elif how == "ROS_PACKAGE_PATH":
        env["ROS_PACKAGE_PATH"] = str(macros_ws)
    else:  # an install prefix: PREFIX/share/NAME
        share = tmp_path / "prefix" / "share"
        shutil.copytree(macros_ws / "nested" / "common_macros", share / "common_macros")
        env["AMENT_PREFIX_PATH"] = str(tmp_path / "prefix")
    doc = joints(args, env)
    by_name = {j["jointName"]: j for j in doc["joints"]}  # type: ignore[union-attr]
    assert list(by_name) == ["shoulder_pan_joint", "shoulder_lift_joint", "elbow_joint"]
    # Limits come from config/joint_limits.yaml through xacro.load_yaml.
    assert (by_name["elbow_joint"]["jointLowerLimit"],
            by_name["elbow_joint"]["jointUpperLimit"]) == (-2.8, 2.8)
    assert by_name["elbow_joint"]["jointMaxForce"] == 28.0


def test_args_with_defaults_and_a_typo(workspaces: tuple[Path, Path]) -> None:
    arm, macros_ws = workspaces
    doc = joints([str(arm), "--package-path", str(macros_ws), "--arg", "prefix:=left_"])
    assert doc["base_link"] == "left_base_link"
    result = runner.invoke(app, ["joints", str(arm), "--package-path", str(macros_ws),
                                 "--arg", "prefx:=left_"])
    assert result.exit_code == 2
    assert "--arg: 'prefx' is not an argument of this file or its includes; did you mean " \
           "'prefix'?" in result.stderr


def test_meshes_through_package_uris_load_check_and_render(workspaces: tuple[Path, Path],
                                                           tmp_path: Path) -> None:
    arm, macros_ws = workspaces
    info = runner.invoke(app, ["info", str(arm), "--package-path", str(macros_ws), "--json"])
    assert info.exit_code == 0, info.stderr
    assert "cannot" not in info.stderr  # PyBullet found and read every mesh
    assert json.loads(info.stdout)["links"] == 4
    checked = runner.invoke(app, ["check", str(arm.parent.parent), "--package-path",
                                  str(macros_ws), "--json"])
    findings = json.loads(checked.stdout)["findings"]
    assert not [f for f in findings if f["level"] == "error"], findings
    picture = tmp_path / "arm.png"
    drawn = runner.invoke(app, ["render", str(arm), "--package-path", str(macros_ws), "-o",
                                str(picture), "--size", "160x120"])
    assert drawn.exit_code == 0, drawn.stderr
    assert picture.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    built = tmp_path / "arm.urdf"
    made = runner.invoke(app, ["build", str(arm), "--package-path", str(macros_ws), "-o",
                               str(built), "--arg", "use_mesh:=false"])
    assert made.exit_code == 0, made.stderr
    assert "package://" not in built.read_text() and "<box" in built.read_text()


def test_the_index_finds_packages_once_and_in_order(tmp_path: Path) -> None:
    for where, version in (("a", "1"), ("b", "2")):
        pkg = tmp_path / where / "deep" / "pkg"
        pkg.mkdir(parents=True)
        (pkg / "package.xml").write_text(f"<package><name>pkg</name><version>{version}"
                                         "</version></package>")
    index = PackageIndex({}, [str(tmp_path / "b"), str(tmp_path / "a")], env=False)
    assert index["pkg"] == tmp_path / "b" / "deep" / "pkg"  # the first search path wins
    explicit = PackageIndex({"pkg": tmp_path / "a"}, [str(tmp_path / "b")], env=False)
    assert explicit["pkg"] == tmp_path / "a"
    assert PackageIndex.from_json(index.to_json())["pkg"] == index["pkg"]
    assert index.get("nope") is None


@pytest.mark.parametrize(("mesh", "expected"), [
    ("gone.stl", "file not found"), ("notes.ply", "PyBullet reads .stl, .obj, .dae meshes"),
    ("package://nopkg/m.stl", "package 'nopkg' not found")])
def test_meshes_pybullet_cannot_load_are_one_line_before_it_sees_them(
        tmp_path: Path, mesh: str, expected: str) -> None:
    (tmp_path / "notes.ply").write_text("ply\n")
    urdf = tmp_path / "r.urdf"
    urdf.write_text('<robot name="r">\n<link name="a">\n<visual><geometry>\n'
                    f'<mesh filename="{mesh}"/>\n</geometry></visual></link>\n</robot>\n')
    for command in ("joints", "render"):
        result = runner.invoke(app, [command, str(urdf), *(["-o", "-"] if command == "render"
                                                              else [])])
        assert result.exit_code == 2
        (line,) = result.stderr.strip().splitlines()
        assert line.startswith(f"urdfkit: error: {urdf}:4: <mesh filename=")
        assert expected in line and "b3Error" not in line


def test_a_mesh_pybullet_finds_on_its_search_path_loads(tmp_path: Path) -> None:
    # `p.loadURDF` after setAdditionalSearchPath(pybullet_data) finds "duck.obj" there.
    urdf = tmp_path / "r.urdf"
    urdf.write_text('<robot name="r"><link name="a"><collision><geometry>'
                    '<mesh filename="duck.obj"/></geometry></collision></link></robot>')
    result = runner.invoke(app, ["info", str(urdf), "--json"])
    assert result.exit_code == 0, result.stderr
    size = json.loads(result.stdout)["aabb"]["size"]
    assert max(size) > 0.05  # the duck's extent, not an empty body
    checked = runner.invoke(app, ["check", str(urdf), "--json"])
    assert "U703" in [f["code"] for f in json.loads(checked.stdout)["findings"]]


def test_findings_in_xacro_input_claim_no_false_line(tmp_path: Path) -> None:
    path = tmp_path / "r.urdf.xacro"
    path.write_text('<robot name="r" xmlns:xacro="http://www.ros.org/wiki/xacro">\n'
                    '<xacro:property name="m" value="-2"/>\n\n\n'
                    '<link name="a"><inertial><mass value="${m}"/><inertia ixx="1" ixy="0" '
                    'ixz="0" iyy="1" iyz="0" izz="1"/></inertial></link>\n</robot>\n')
    result = runner.invoke(app, ["check", str(path), "--json"])
    (finding,) = [f for f in json.loads(result.stdout)["findings"] if f["code"] == "U601"]
    assert finding["line"] is None and "<link name='a'>" in finding["message"]


def test_env_substitutions_work_and_ros_only_ones_say_so(tmp_path: Path) -> None:
    ns = 'xmlns:xacro="http://www.ros.org/wiki/xacro"'
    env_file = tmp_path / "env.urdf.xacro"
    env_file.write_text(f'<robot name="r" {ns}><link name="a_$(env ROBOT_SIDE)_'
                        '$(optenv ROBOT_NOPE dflt)"/></robot>')
    result = runner.invoke(app, ["tree", str(env_file), "--json"], env={"ROBOT_SIDE": "left"})
    assert result.exit_code == 0, result.stderr
    assert json.loads(result.stdout)["base_link"] == "a_left_dflt"
    ros = tmp_path / "ros.urdf.xacro"
    ros.write_text(f'<robot name="r" {ns}><link name="a$(exec rospack list)"/></robot>')
    result = runner.invoke(app, ["tree", str(ros)])
    assert result.exit_code == 2
    (line,) = result.stderr.strip().splitlines()
    assert f"{ros}: xacro failed: $(exec rospack list) is a ROS substitution" in line
    broken = tmp_path / "broken.urdf.xacro"
    broken.write_text(f'<robot name="r" {ns}><link name="${{1/0}}"/></robot>')
    (line,) = runner.invoke(app, ["tree", str(broken)]).stderr.strip().splitlines()
    assert line.endswith("xacro failed: division by zero (when evaluating expression '1/0')")


def test_check_over_a_workspace_with_macro_libraries_and_args(workspaces: tuple[Path, Path]
                                                              ) -> None:
    arm, macros_ws = workspaces
    result = runner.invoke(app, ["check", str(arm.parents[2]), str(macros_ws), "--package-path",
                                 str(macros_ws), "--arg", "prefix:=right_", "--json"])
    doc = json.loads(result.stdout)
    by_file = {Path(f["file"]).name: f for f in doc["findings"] if f["code"] == "U007"}
    assert set(by_file) == {"macros.xacro"}  # a library of macros, not a broken robot
    assert by_file["macros.xacro"]["level"] == "info"
    assert result.exit_code == 0, doc["findings"]  # no errors anywhere, the arg applied


def test_findings_in_xacro_input_name_where_the_element_was_written(tmp_path: Path) -> None:
    ns = 'xmlns:xacro="http://wiki.ros.org/xacro"'  # ur_description's spelling of the URI
    (tmp_path / "parts.xacro").write_text(
        f'<robot {ns}>\n'
        '  <xacro:macro name="part" params="prefix">\n'
        '    <link name="${prefix}part">\n'
        '      <inertial><mass value="-1"/><inertia ixx="1" ixy="0" ixz="0" iyy="1" iyz="0" '
        'izz="1"/></inertial>\n'
        '    </link>\n'
        '  </xacro:macro>\n'
        '</robot>\n')
    main = tmp_path / "robot.urdf.xacro"
    main.write_text(
        f'<robot name="r" {ns}>\n'
        '  <xacro:include filename="parts.xacro"/>\n'
        '  <link name="base"><inertial><mass value="-2"/><inertia ixx="1" ixy="0" ixz="0" '
        'iyy="1" iyz="0" izz="1"/></inertial></link>\n'
        '  <xacro:part prefix="a_"/>\n'
        '  <xacro:part prefix="b_"/>\n'
        '  <joint name="ja" type="fixed"><parent link="base"/><child link="a_part"/></joint>\n'
        '  <joint name="jb" type="fixed"><parent link="base"/><child link="b_part"/></joint>\n'
        '</robot>\n')
    result = runner.invoke(app, ["check", str(main), "--json", "--select", "U601"])
    found = sorted((f["message"].split("'")[1], f["origin"], f["line"])
                   for f in json.loads(result.stdout)["findings"])
    parts = str(tmp_path / "parts.xacro")
    # The mass element of each macro expansion was written on line 4 of parts.xacro.
    assert found == [("a_part", f"{parts}:4", None), ("b_part", f"{parts}:4", None),
                     ("base", f"{main}:3", None)]
    text = runner.invoke(app, ["check", str(main), "--select", "U601"]).stdout
    assert f"(written at {parts}:4)" in text
    # The tags never reach an output: the expansion is plain URDF.
    from urdfkit.sources.expand import expand_xacro

    expanded = expand_xacro(main)
    assert b"urdfkit-origin" not in expanded and b"a_part" in expanded
    assert len(expanded.origins) == expanded.count(b"<") - expanded.count(b"</") \
        - expanded.count(b"<!--") - expanded.count(b"<?")


def test_a_refusal_of_xacro_input_names_where_the_element_was_written(tmp_path: Path) -> None:
    main = tmp_path / "robot.urdf.xacro"
    main.write_text('<robot name="r" xmlns:xacro="http://www.ros.org/wiki/xacro">\n'
                    '  <link name="a"/>\n'
                    '  <link name="b"/>\n'
                    '  <joint name="j" type="fixed"><parent link="a"/><child link="b"/></joint>\n'
                    '  <joint name="j" type="fixed"><parent link="b"/><child link="a"/></joint>\n'
                    '</robot>\n')
    result = runner.invoke(app, ["joints", str(main)])
    assert result.exit_code == 2
    (line,) = result.stderr.strip().splitlines()
    assert line.startswith(f"urdfkit: error: {main}: ") and f"(written at {main}:5)" in line


def test_a_package_lookup_is_kept_only_while_settled_and_still_noted(tmp_path: Path) -> None:
    # check walks up to "/" for each package:// mesh of every file: within one run (settled)
    # the answer is kept, yet every answer notes the paths looked at, for the result cache;
    # outside a run (view's reloads) a package that appears since is found.
    from urdfkit.core import deps
    from urdfkit.sources import uris

    deep = tmp_path / "a" / "b" / "c"
    deep.mkdir(parents=True)
    assert uris.find_package("pkg_x", deep) is None
    with uris.settled():
        with deps.record() as first:
            assert uris.find_package("pkg_x", deep) is None
        (tmp_path / "package.xml").write_text("<package><name>pkg_x</name></package>")
        with deps.record() as again:  # kept: the run takes the file system as settled
            assert uris.find_package("pkg_x", deep) is None
        assert set(again) == set(first) and str(tmp_path / "package.xml") in again
        assert again[str(tmp_path / "package.xml")] is not None  # signed as it is now
    assert uris.find_package("pkg_x", deep) == tmp_path  # not settled: looked up again
    with uris.settled():
        assert uris.find_package("pkg_x", deep) == tmp_path
        (tmp_path / "package.xml").unlink()
        assert uris.find_package("pkg_x", deep) == tmp_path
    assert uris.find_package("pkg_x", deep) is None


def test_package_path_follows_symlinked_packages_and_survives_a_loop(
        workspaces: tuple[Path, Path], tmp_path: Path) -> None:
    """A workspace whose src/ links its packages in (as ROSbot's did in the real-package
    trials): catkin_pkg and rospack follow the links, and so does --package-path."""
    arm, macros_ws = workspaces
    linked = tmp_path / "linked_ws" / "src"
    linked.mkdir(parents=True)
    (linked / "common_macros").symlink_to(macros_ws / "nested" / "common_macros",
                                          target_is_directory=True)
    (linked / "loop").symlink_to(tmp_path / "linked_ws", target_is_directory=True)
    env = {"ROS_PACKAGE_PATH": "", "AMENT_PREFIX_PATH": ""}
    doc = joints([str(arm), "--package-path", str(tmp_path / "linked_ws")], env)
    names = [j["jointName"] for j in doc["joints"]]  # type: ignore[union-attr]
    assert names == ["shoulder_pan_joint", "shoulder_lift_joint", "elbow_joint"]
    index = PackageIndex({}, [str(tmp_path / "linked_ws")], env=False)
    assert index["common_macros"] == linked / "common_macros"
    assert list(index) == ["common_macros"]  # the loop is entered once, nothing found twice


def test_a_package_found_only_through_package_xml_is_said_where_raw_pybullet_refuses(
        pb, tmp_path: Path) -> None:
    """poppy_ergo_jr_description unpacked as poppy-project+poppy_ergo_jr_description: urdfkit
    found its meshes through package.xml and loaded it; raw p.loadURDF refused it."""
    from urdfkit.engine.session import quiet_stdout

    p, c = pb
    repo = tmp_path / "owner+arm_like_description"  # the package at a repository's root
    shutil.copytree(PACKAGES / "arm_like_description", repo)
    robot = repo / "urdf" / "arm.urdf"
    robot.write_text(
        '<robot name="arm"><link name="base"><visual><geometry>'
        '<mesh filename="package://arm_like_description/meshes/segment.stl"/>'
        '</geometry></visual></link></robot>')
    with quiet_stdout(), pytest.raises(p.error):
        p.loadURDF(str(robot), physicsClientId=c)
    result = runner.invoke(app, ["check", str(robot), "--json"],
                           env={"ROS_PACKAGE_PATH": "", "AMENT_PREFIX_PATH": ""})
    codes = [f["code"] for f in json.loads(result.stdout)["findings"]]
    assert "U711" in codes
    assert joints([str(robot)])["joints"] == []  # urdfkit still loads it
    # Given the package on the command line, the user has said where it is: no U711.
    given = runner.invoke(app, ["check", str(robot), "--json", "--package-path", str(tmp_path)])
    assert "U711" not in [f["code"] for f in json.loads(given.stdout)["findings"]]
    # Under its own name raw PyBullet finds the mesh, and check says nothing of it.
    named = tmp_path / "ws" / "arm_like_description"
    shutil.copytree(repo, named)
    with quiet_stdout():
        p.loadURDF(str(named / "urdf" / "arm.urdf"), physicsClientId=c)
    result = runner.invoke(app, ["check", str(named / "urdf" / "arm.urdf"), "--json"],
                           env={"ROS_PACKAGE_PATH": "", "AMENT_PREFIX_PATH": ""})
    assert "U711" not in [f["code"] for f in json.loads(result.stdout)["findings"]]
