"""Files PyBullet loads that urdfkit used to refuse (issue 24, items 17-19), each measured
against raw PyBullet on a small robot written here."""

from __future__ import annotations

import contextlib
import json
import subprocess
import sys
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import pytest

from urdfkit.engine.session import quiet_stdout

INERTIAL = ('<inertial><mass value="1"/><inertia ixx="0.01" iyy="0.01" izz="0.01" ixy="0" '
            'ixz="0" iyz="0"/></inertial>')


def _cli(*args: str) -> subprocess.CompletedProcess[str]:
    return subprocess.run([sys.executable, "-m", "urdfkit", *args], capture_output=True,
                          text=True, timeout=120)


@contextlib.contextmanager
def _raw(path: Path, flags: int = 0) -> Iterator[tuple[Any, int, int]]:
    """``(pybullet, client, body)``: the file as raw ``p.loadURDF`` loads it, quietly.

    A refusal raises ``pybullet.error``, as raw PyBullet does.
    """
    import pybullet as p

    with quiet_stdout():
        c = p.connect(p.DIRECT)
    try:
        with quiet_stdout():
            body = p.loadURDF(str(path), flags=flags, physicsClientId=c)
        yield p, c, body
    finally:
        p.disconnect(physicsClientId=c)


def _raw_shapes(path: Path) -> tuple[list, list]:
    """(collision, visual) shape data of the base as raw PyBullet loads the file."""
    with _raw(path) as (p, c, body):
        return (list(p.getCollisionShapeData(body, -1, physicsClientId=c)),
                list(p.getVisualShapeData(body, physicsClientId=c)))


def _raw_joint_names(path: Path) -> list[str]:
    with _raw(path) as (p, c, body):
        return [p.getJointInfo(body, j, physicsClientId=c)[1].decode()
                for j in range(p.getNumJoints(body, physicsClientId=c))]


@pytest.mark.parametrize(("first", "second", "geom"), [
    ('<box size="0.1 0.2 0.3"/>', '<sphere radius="0.5"/>', 3),
    ('<sphere radius="0.5"/>', '<box size="0.1 0.2 0.3"/>', 2),
])
def test_two_shapes_in_one_geometry_load_as_pybullet_loads_them(
        tmp_path: Path, first: str, second: str, geom: int) -> None:
    path = tmp_path / "two.urdf"
    path.write_text(f'<robot name="t"><link name="a">{INERTIAL}<visual><geometry>{first}'
                    f'{second}</geometry></visual><collision><geometry>{first}{second}'
                    '</geometry></collision></link></robot>')
    collision, visual = _raw_shapes(path)
    # Measured: PyBullet builds both from the first shape and ignores the second.
    assert [s[2] for s in collision] == [geom] and [s[2] for s in visual] == [geom]
    check = _cli("check", str(path), "--json")
    assert check.returncode == 0, check.stdout
    found = [f for f in json.loads(check.stdout)["findings"] if f["code"] in ("U502", "U507")]
    assert [(f["code"], f["level"], f["line"]) for f in found] == [
        ("U507", "warning", 1), ("U507", "warning", 1)]
    assert f"uses the first, {first.split()[0]}>" in found[0]["message"]
    links = _cli("links", str(path), "--json")
    assert links.returncode == 0, links.stderr
    assert links.stderr.count("U507") == 2  # said by every loader, once per <geometry>
    # The same body as raw PyBullet's: the collision shape's kind and size.
    data = json.loads(links.stdout)["links"][0]
    raw_inertia = _raw_inertia(path)
    assert data["local_inertia_diagonal"] == pytest.approx(raw_inertia)


def _raw_inertia(path: Path) -> list[float]:
    import pybullet

    with _raw(path, pybullet.URDF_USE_IMPLICIT_CYLINDER) as (p, c, body):
        return list(p.getDynamicsInfo(body, -1, physicsClientId=c)[2])


def test_a_geometry_without_a_shape_is_still_refused(tmp_path: Path) -> None:
    path = tmp_path / "empty.urdf"
    path.write_text(f'<robot name="t"><link name="a">{INERTIAL}<collision><geometry/>'
                    '</collision></link></robot>')
    import pybullet as p

    with pytest.raises(p.error, match="Cannot load URDF"), _raw(path) as (_, _, body):
        pytest.fail(f"raw PyBullet loaded a <geometry> with no shape (body {body})")
    r = _cli("joints", str(path))
    assert r.returncode == 2 and "holds no shape" in r.stderr and r.stderr.count("\n") == 1


NS = """<robot name="t">
  <link name="a">{inertial}</link>
  <gazebo reference="a">
    <sensor:camera name="cam"><sensor:fov>1.0</sensor:fov></sensor:camera>
    <plugin:ros name="p"/>
  </gazebo>
  <link name="b"><inertial><mass value="2"/><inertia ixx="0.01" iyy="0.01" izz="-0.01" ixy="0"
    ixz="0" iyz="0"/></inertial><collision><geometry><box size="0.1 0.1 0.1"/></geometry>
    </collision></link>
  <joint name="j" type="revolute"><parent link="a"/><child link="b"/><axis xyz="0 0 1"/>
    <limit lower="-1" upper="1" effort="1" velocity="1"/></joint>
</robot>
"""


def test_undeclared_namespace_prefixes_are_read_as_pybullet_reads_them(tmp_path: Path) -> None:
    from lxml import etree

    path = tmp_path / "gazebo.urdf"
    path.write_text(NS.format(inertial=INERTIAL))
    with pytest.raises(etree.XMLSyntaxError, match="Namespace prefix sensor"):
        etree.fromstring(path.read_bytes())  # libxml2 refuses it...
    raw = _raw_joint_names(path)  # ...PyBullet loads it
    joints = _cli("joints", str(path), "--json")
    assert joints.returncode == 0, joints.stderr
    assert [j["jointName"] for j in json.loads(joints.stdout)["joints"]] == raw == ["j"]
    warned = [ln for ln in joints.stderr.splitlines() if "where it is not declared" in ln]
    assert [ln.split(": namespace prefix ")[1].split()[0] for ln in warned] == ["'sensor'",
                                                                                 "'plugin'"]
    assert all(f"{path}:4:" in ln or f"{path}:5:" in ln for ln in warned)
    check = json.loads(_cli("check", str(path), "--json").stdout)
    assert [(f["code"], f["line"]) for f in check["findings"] if f["code"] == "U004"] == [
        ("U004", 4), ("U004", 5)]
    # fix repairs the inertia and leaves every other byte as it was: no declaration added.
    out = tmp_path / "fixed.urdf"
    fixed = _cli("fix", str(path), "-o", str(out))
    assert fixed.returncode in (0, 1), fixed.stderr
    before, after = path.read_text(), out.read_text()
    assert "xmlns" not in after and "<sensor:camera" in after and before != after
    assert before.splitlines()[:6] == after.splitlines()[:6]
    # Byte for byte outside the one <inertia> fix rewrote.
    import re

    inertia = re.compile(r"<inertia\b[^>]*/>")
    assert len(inertia.findall(before)) == 2 and inertia.findall(before)[0] in after
    assert inertia.sub("", before) == inertia.sub("", after)


def test_a_prefix_declared_on_a_sibling_is_not_declared(tmp_path: Path) -> None:
    path = tmp_path / "scope.urdf"
    path.write_text(f'<robot name="t">\n<link name="a">{INERTIAL}</link>\n'
                    '<gazebo xmlns:sensor="urn:s"><sensor:a/></gazebo>\n'
                    '<gazebo><sensor:b/></gazebo>\n</robot>\n')
    from lxml import etree

    with pytest.raises(etree.XMLSyntaxError, match="Namespace prefix sensor on b"):
        etree.fromstring(path.read_bytes())
    assert _raw_shapes(path) == ([], [])  # PyBullet loads it (a link with no shapes)
    check = json.loads(_cli("check", str(path), "--json").stdout)
    assert [(f["code"], f["line"]) for f in check["findings"] if f["level"] == "error"
            or f["code"] == "U004"] == [("U004", 4)]
    r = _cli("tree", str(path))
    assert r.returncode == 0 and f"{path}:4: namespace prefix 'sensor'" in r.stderr, r.stderr


def test_prefixes_in_comments_and_attributes(tmp_path: Path) -> None:
    path = tmp_path / "attrs.urdf"
    path.write_text(f'<robot name="t">\n<!-- <xacro:include filename="x.xacro"/> -->\n'
                    f'<link name="a" sensor:id="3">{INERTIAL}</link>\n'
                    '<link name="b"><![CDATA[ <plugin:x/> ]]></link>\n'
                    '<joint name="j" type="fixed"><parent link="a"/><child link="b"/></joint>\n'
                    '</robot>\n')
    raw = _raw_joint_names(path)  # the attribute is ignored
    joints = _cli("joints", str(path), "--json")
    assert joints.returncode == 0, joints.stderr
    assert [j["jointName"] for j in json.loads(joints.stdout)["joints"]] == raw == ["j"]
    check = json.loads(_cli("check", str(path), "--json").stdout)
    # Only the attribute's prefix: a commented-out element or CDATA text uses none.
    assert [(f["line"], f["message"].split(" is used")[0]) for f in check["findings"]
            if f["code"] == "U004"] == [(3, "namespace prefix 'sensor'")]


# --------------------------------------------------------------------------- item 17

TETRA = "v 0 0 0\nv 0.1 0 0\nv 0 0.1 0\nv 0 0 0.1\nf 1 2 3\nf 1 2 4\nf 1 3 4\nf 2 3 4\n"


def _mesh_robot(folder: Path, filename: str, name: str = "r.urdf") -> Path:
    folder.mkdir(parents=True, exist_ok=True)
    path = folder / name
    shape = f'<geometry><mesh filename="{filename}"/></geometry>'
    path.write_text(f'<robot name="r"><link name="l">{INERTIAL}<visual>{shape}</visual>'
                    f'<collision>{shape}</collision></link></robot>')
    return path


def _raw_mesh_file(path: Path) -> str | None:
    """The mesh file raw PyBullet loaded for the base's visual, or None if it refused."""
    import pybullet

    try:
        with _raw(path) as (p, c, body):
            shape = p.getVisualShapeData(body, physicsClientId=c)[0][4].decode()
    except pybullet.error:
        return None
    return str(Path(shape).resolve())


@pytest.mark.parametrize(("written", "placed", "up"), [
    ("meshes/tetra_rel3.obj", "meshes/tetra_rel3.obj", 3),      # relative, 3 folders up
    ("meshes/tetra_rel8.obj", "meshes/tetra_rel8.obj", 8),      # and 8: no depth limit
    ("package:///meshes/tetra_p7.obj", "meshes/tetra_p7.obj", 7),  # three slashes, 7 up
    # A package urdfkit cannot find by package.xml: PyBullet drops "package://" and
    # searches for pkg_x/... in every folder above.
    ("package://pkg_x/meshes/tetra_pkg.obj", "pkg_x/meshes/tetra_pkg.obj", 4),
])
def test_mesh_paths_are_found_where_pybullet_finds_them(tmp_path: Path, written: str,
                                                         placed: str, up: int) -> None:
    deep = tmp_path.joinpath(*[f"d{k}" for k in range(9)])
    top = deep.parents[up - 1]
    (top / placed).parent.mkdir(parents=True, exist_ok=True)
    (top / placed).write_text(TETRA)
    path = _mesh_robot(deep, written)
    raw = _raw_mesh_file(path)
    assert raw == str((top / placed).resolve())  # PyBullet finds it there
    check = json.loads(_cli("check", str(path), "--json").stdout)
    assert not [f for f in check["findings"] if f["code"] in ("U701", "U702")], check
    links = _cli("links", str(path), "--json")
    assert links.returncode == 0, links.stderr
    # urdfkit's own load draws the same mesh file as raw PyBullet's.
    from urdfkit.engine.session import Session
    from urdfkit.sources.resolve import open_input

    with open_input(str(path)) as res, Session() as s:
        body = s.load_urdf(res.load_path)
        ours = s.p.getVisualShapeData(body, physicsClientId=s.client)[0][4].decode()
    assert str(Path(ours).resolve()) == raw


def test_the_deepest_match_wins_and_a_mesh_nowhere_is_still_refused(tmp_path: Path) -> None:
    deep = tmp_path / "a" / "b" / "c"
    for folder, scale in ((tmp_path / "a", "0.1"), (deep, "0.2")):
        (folder / "m").mkdir(parents=True, exist_ok=True)
        (folder / "m" / "w.obj").write_text(TETRA.replace("0.1", scale))
    path = _mesh_robot(deep, "m/w.obj")
    assert _raw_mesh_file(path) == str((deep / "m" / "w.obj").resolve())
    from urdfkit.sources.uris import resolve_uri

    assert resolve_uri("m/w.obj", deep).path == deep / "m" / "w.obj"
    (deep / "m" / "w.obj").unlink()  # now only the one two folders up
    assert _raw_mesh_file(path) == str((tmp_path / "a" / "m" / "w.obj").resolve())
    assert resolve_uri("m/w.obj", deep).path == tmp_path / "a" / "m" / "w.obj"
    missing = _mesh_robot(deep, "m/not_there_anywhere_q7.obj", "missing.urdf")
    assert _raw_mesh_file(missing) is None
    r = _cli("joints", str(missing))
    assert r.returncode == 2 and "not_there_anywhere_q7.obj" in r.stderr
    assert r.stderr.count("\n") == 1


def test_a_package_folder_without_the_mesh_falls_back_to_pybullets_search(
        tmp_path: Path) -> None:
    # package.xml at a repository's root, meshes under share/NAME/ (a real layout): the
    # package found by its package.xml lacks meshes/m.obj, PyBullet finds share/pkg/meshes.
    repo = tmp_path / "pkg"
    repo.mkdir()
    (repo / "package.xml").write_text("<package><name>pkg</name></package>")
    (repo / "share" / "pkg" / "meshes").mkdir(parents=True)
    (repo / "share" / "pkg" / "meshes" / "m.obj").write_text(TETRA)
    path = _mesh_robot(repo / "share" / "pkg" / "robots" / "r", "package://pkg/meshes/m.obj")
    raw = _raw_mesh_file(path)
    assert raw == str((repo / "share" / "pkg" / "meshes" / "m.obj").resolve())
    for extra in ([], ["--package-path", str(repo)], ["--package", f"pkg={repo}"]):
        r = _cli("joints", str(path), *extra)
        assert r.returncode == 0, (extra, r.stderr)


def test_empty_visual_and_collision_names_are_no_names(tmp_path: Path) -> None:
    path = tmp_path / "named.urdf"
    path.write_text(f'<robot name="n"><link name="a">{INERTIAL}<visual name=""><geometry>'
                    '<box size="0.1 0.1 0.1"/></geometry></visual><collision name="">'
                    '<geometry><box size="0.1 0.1 0.1"/></geometry></collision></link></robot>')
    collision, visual = _raw_shapes(path)  # PyBullet loads it
    assert len(collision) == 1 and len(visual) == 1
    r = _cli("diff", str(path), str(path))
    assert r.returncode == 0, r.stderr
    xacro = tmp_path / "named.urdf.xacro"
    xacro.write_text(path.read_text())
    r = _cli("build", str(xacro), "-o", str(tmp_path / "out.urdf"))
    assert r.returncode == 0, r.stderr


@pytest.mark.parametrize("ignored", [
    '<sphere/>',                               # no radius
    '<sphere radius="-1"/>',                   # a negative size
    '<cylinder radius="nan" length="1"/>',     # not a number
    '<mesh filename="nowhere_at_all_k3.obj"/>',  # a mesh file that does not exist
    '<mesh/>',                                 # a mesh with no filename
])
def test_a_shape_after_the_first_is_never_read(tmp_path: Path, ignored: str) -> None:
    # Measured on 3.2.7: PyBullet builds <geometry> from its first element and never reads
    # the rest, so what is wrong with a second shape does not stop it loading.
    path = tmp_path / "second.urdf"
    shape = f'<geometry><box size="0.1 0.2 0.3"/>{ignored}</geometry>'
    path.write_text(f'<robot name="t"><link name="a">{INERTIAL}<visual>{shape}</visual>'
                    f'<collision>{shape}</collision></link></robot>')
    collision, visual = _raw_shapes(path)
    assert [(s[2], s[3]) for s in collision] == [(3, pytest.approx((0.1, 0.2, 0.3)))]
    assert [(s[2], s[3]) for s in visual] == [(3, pytest.approx((0.1, 0.2, 0.3)))]
    check = _cli("check", str(path), "--json")
    assert check.returncode == 0, check.stdout
    assert not [f for f in json.loads(check.stdout)["findings"] if f["level"] == "error"]
    for args in (["links", "--json"], ["collisions", "--samples", "2"],
                 ["render", "-o", str(tmp_path / "r.png"), "--size", "64x48"]):
        r = _cli(args[0], str(path), *args[1:])
        assert r.returncode == 0, (args, r.stderr)
        assert r.stderr.count("(U507)") == 2, (args, r.stderr)
    data = json.loads(_cli("links", str(path), "--json").stdout)["links"][0]
    assert data["local_inertia_diagonal"] == pytest.approx(_raw_inertia(path))


def test_render_frames_the_shape_pybullet_draws() -> None:
    import numpy as np
    from lxml import etree

    from urdfkit.draw.render import _half_extent

    geometry = etree.fromstring('<geometry><sphere radius="0.5"/><box size="4 4 4"/></geometry>')
    assert _half_extent(geometry, np.eye(3)) == pytest.approx([0.5, 0.5, 0.5])


def test_a_mesh_found_above_gives_the_shapes_raw_pybullet_gives(tmp_path: Path) -> None:
    # Twelve folders up (measured: no depth limit), scaled, in visual and collision: the shape
    # data of urdfkit's load equals raw p.loadURDF's, and every reading command takes it.
    deep = tmp_path.joinpath(*[f"d{k}" for k in range(12)])
    (tmp_path / "shapes").mkdir()
    (tmp_path / "shapes" / "t12.obj").write_text(TETRA)
    path = deep / "r.urdf"
    deep.mkdir(parents=True)
    shape = '<geometry><mesh filename="shapes/t12.obj" scale="2 3 4"/></geometry>'
    path.write_text(f'<robot name="r"><link name="l">{INERTIAL}<visual>{shape}</visual>'
                    f'<collision>{shape}</collision></link></robot>')
    raw_collision, raw_visual = _raw_shapes(path)
    assert raw_collision and raw_visual  # PyBullet loads it
    from urdfkit.engine.session import LoadOptions, Session
    from urdfkit.sources.resolve import open_input

    with open_input(str(path)) as res, Session() as s:
        body = s.load_urdf(res.load_path, LoadOptions(implicit_cylinder=False))
        ours_collision = list(s.p.getCollisionShapeData(body, -1, physicsClientId=s.client))
        ours_visual = list(s.p.getVisualShapeData(body, physicsClientId=s.client))

    def same(rows: list) -> list:  # file names compared as resolved paths
        return [tuple(str(Path(x.decode()).resolve()) if isinstance(x, bytes) and x else x
                      for x in row) for row in rows]

    assert same(ours_collision) == same(raw_collision)
    assert same(ours_visual) == same(raw_visual)
    for args in (["joints", "--no-guard"], ["info"], ["collisions", "--samples", "2"],
                 ["render", "-o", str(tmp_path / "r.png"), "--size", "64x48"],
                 ["diff", str(path)]):
        r = _cli(args[0], str(path), *args[1:])
        assert r.returncode == 0 and "U701" not in r.stderr, (args, r.stderr)
    fixed = _cli("fix", str(path), "--diff")
    assert fixed.returncode in (0, 1) and "U701" not in fixed.stdout + fixed.stderr, fixed


def test_a_nameless_material_in_a_gazebo_extension_is_ignored_as_pybullet_ignores_it(
        tmp_path: Path) -> None:
    path = tmp_path / "gz.urdf"  # Gazebo's own syntax, as linorobot2 writes it
    path.write_text(f'<robot name="g"><link name="base">{INERTIAL}<visual><geometry><box '
                    'size="0.2 0.2 0.2"/></geometry><material name="yellow"><color rgba="1 1 0 '
                    '1"/></material></visual></link><gazebo reference="base"><visual>'
                    '<material><ambient>1 1 0 1</ambient></material></visual></gazebo></robot>')
    collision, visual = _raw_shapes(path)  # PyBullet loads it, the link's yellow box
    assert [tuple(round(x, 3) for x in v[7]) for v in visual] == [(1.0, 1.0, 0.0, 1.0)]
    check = json.loads(_cli("check", str(path), "--json").stdout)
    assert not [f for f in check["findings"] if f["code"] == "U110"]
    for command in ("joints", "tree", "links"):
        assert _cli(command, str(path)).returncode == 0, command
    # A link's own <visual><material> without a name is still refused, as PyBullet refuses it.
    bad = tmp_path / "bad.urdf"
    bad.write_text(path.read_text().replace('<material name="yellow">', "<material>"))
    r = _cli("joints", str(bad))
    assert r.returncode == 2 and "U110" not in r.stdout and "no name attribute" in r.stderr
