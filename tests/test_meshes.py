"""Mesh mass properties (sources/meshes.py): against closed forms, trimesh, the cache's rules."""

from __future__ import annotations

import math
import os
from pathlib import Path

import numpy as np
import pybullet_data
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from urdfkit.model.spec import solid_inertia, solid_volume
from urdfkit.sources import meshes, meshstore

DATA = Path(pybullet_data.getDataPath())
FIXTURES = Path(__file__).parent / "fixtures" / "meshes"

#: A box's 8 corners and 6 outward quads (1-based, counter-clockwise seen from outside).
CORNERS = [(x, y, z) for x in (0.0, 1.0) for y in (0.0, 1.0) for z in (0.0, 1.0)]
QUADS = [(1, 2, 4, 3), (5, 7, 8, 6), (1, 5, 6, 2), (3, 4, 8, 7), (1, 3, 7, 5), (2, 6, 8, 4)]


def box_obj(size: tuple[float, float, float] = (1.0, 1.0, 1.0), *, quads: bool = True,
            style: str = "plain", newline: str = "\n", flip: bool = False) -> str:
    """An OBJ of a box with one corner at the origin, in the styles real exporters write."""
    lines = ["# exported", "o box", "mtllib box.mtl"]
    for x, y, z in CORNERS:
        v = f"v {x * size[0]} {y * size[1]} {z * size[2]}"
        lines.append(v + (" 0.5 0.5 0.5" if style == "colours" else ""))
    lines += ["vt 0 0", "vn 0 0 1", "usemtl m", "s off"]
    for quad in QUADS:
        q = quad[::-1] if flip else quad
        faces = [q] if quads else [(q[0], q[1], q[2]), (q[0], q[2], q[3])]
        for face in faces:
            idx = [str(i) for i in face]
            if style == "slashes":
                idx = [f"{i}/1/1" for i in idx]
            elif style == "negative":
                idx = [str(int(i) - 9) for i in idx]  # -8 is the first vertex
            lines.append("f " + " ".join(idx))
    return newline.join(lines) + newline


def check_box(props: meshstore.MeshProperties | None, size: tuple[float, float, float],
              centred: bool = False) -> None:
    assert props is not None and props.closed
    volume = solid_volume("box", list(size))
    assert props.volume == pytest.approx(volume)
    assert props.com == pytest.approx((0.0, 0.0, 0.0) if centred else tuple(s / 2 for s in size))
    ixx, iyy, izz = solid_inertia("box", list(size), volume)  # per unit density
    assert [props.inertia[i][i] for i in range(3)] == pytest.approx([ixx, iyy, izz])
    assert props.inertia[0][1] == pytest.approx(0.0, abs=1e-12)
    assert props.extent == pytest.approx(tuple(abs(s) for s in size))


@pytest.fixture(autouse=True)
def fresh_memory(monkeypatch: pytest.MonkeyPatch, tmp_path: Path) -> None:
    monkeypatch.setattr(meshstore, "_MEMORY", {})
    monkeypatch.setenv("URDFKIT_CACHE_DIR", str(tmp_path / "cache"))


@pytest.mark.parametrize(("quads", "style", "newline", "flip"), [
    (True, "plain", "\n", False), (False, "plain", "\n", False), (True, "slashes", "\r\n", False),
    (False, "colours", "\n", False), (False, "negative", "\n", False),
    (False, "plain", "\n", True),  # inward-facing triangles: the same solid
])
def test_obj_box_matches_the_closed_form(tmp_path: Path, quads: bool, style: str,
                                         newline: str, flip: bool) -> None:
    path = tmp_path / "box.obj"
    path.write_text(box_obj((0.2, 0.5, 1.5), quads=quads, style=style, newline=newline,
                            flip=flip))
    check_box(meshstore.properties(path), (0.2, 0.5, 1.5))


@pytest.mark.parametrize("scale", [(2.0, 0.5, 3.0), (-1.0, 1.0, 1.0), (0.001, 0.001, 0.001),
                                   (0.1, -0.2, 0.3)])
def test_scale_applied_in_closed_form_equals_a_scaled_file(tmp_path: Path,
                                                           scale: tuple[float, float, float]
                                                           ) -> None:
    unit, scaled = tmp_path / "unit.obj", tmp_path / "scaled.obj"
    unit.write_text(box_obj(quads=False))
    scaled.write_text(box_obj(scale, quads=False))
    a, b = meshstore.properties(unit, scale), meshstore.properties(scaled)
    assert a is not None and b is not None
    assert a.volume == pytest.approx(b.volume) == pytest.approx(abs(math.prod(scale)))
    assert a.com == pytest.approx(b.com)
    for row_a, row_b in zip(a.inertia, b.inertia, strict=True):
        assert row_a == pytest.approx(row_b, abs=1e-15)
    assert a.extent == pytest.approx(b.extent)


def test_binary_stl_cube_and_open_surface() -> None:
    check_box(meshstore.properties(FIXTURES / "unit_cube.stl"), (1.0, 1.0, 1.0), centred=True)
    props = meshstore.properties(FIXTURES / "open_triangle.stl")
    assert props is not None and not props.closed and props.trace_for_mass(1.0) is None


def test_real_meshes_agree_with_trimesh() -> None:
    trimesh = pytest.importorskip("trimesh")
    for name in ("duck_vhacd.obj", "random_urdfs/000/000.obj", "sphere_smooth.obj"):
        ours = meshstore.properties(DATA / name)
        theirs = trimesh.load(DATA / name, force="mesh", process=False)
        assert ours is not None and ours.closed, name
        assert ours.volume == pytest.approx(theirs.volume, rel=1e-9), name
        assert ours.com == pytest.approx(tuple(theirs.center_mass), rel=1e-6, abs=1e-9), name
        # trimesh's moment_inertia is for density 1 about the centre of mass, like ours.
        for row_a, row_b in zip(ours.inertia, theirs.moment_inertia, strict=True):
            assert row_a == pytest.approx(tuple(row_b), rel=1e-6, abs=1e-9 * ours.volume), name


@pytest.mark.parametrize("text", [
    "v nan nan nan\nv 1 0 0\nv 0 1 0\nf 1 2 3\n",      # pybullet_data ships one (random_urdfs/168)
    "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 9\n",            # an index past the last vertex
    "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 x\n",            # junk
    "v 0 0 0\nv 1 zero 0\nv 0 1 0\nf 1 2 3\n",
    "v 0 0 0\nv 1 0 0\nf 1 2\n",                       # a face of two corners
    "",                                                 # empty
    "v 1e999 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n",        # overflow
    # Two and four numbers make six, as two vertices would: lines are counted one by one.
    "v 0 0\nv 0 0 1 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\nf 2 3 4\nf 1 2 4\nf 1 3 4\n",
])
def test_broken_meshes_are_unreadable_not_a_crash(tmp_path: Path, text: str) -> None:
    path = tmp_path / "bad.obj"
    path.write_text(text)
    assert meshstore.properties(path) is None


def test_a_mesh_changed_just_now_is_not_kept_on_disk(tmp_path: Path) -> None:
    # Within the clock's grain an edit can keep a file's stat, ctime included: an answer
    # about a mesh changed under two seconds ago stays in memory only.
    path = tmp_path / "box.obj"
    path.write_text(box_obj((1.0, 2.0, 3.0)))
    check_box(meshstore.properties(path), (1.0, 2.0, 3.0))
    assert not (tmp_path / "cache" / meshstore._FOLDER).exists()


def test_cache_serves_the_second_read_and_follows_edits(tmp_path: Path, settled: None,
                                                        monkeypatch: pytest.MonkeyPatch) -> None:
    path = tmp_path / "box.obj"
    path.write_text(box_obj((1.0, 2.0, 3.0)))
    check_box(meshstore.properties(path), (1.0, 2.0, 3.0))
    entries = list((tmp_path / "cache" / meshstore._FOLDER).iterdir())
    assert len(entries) == 1
    # A new process (empty memory) reads the entry, not the mesh.
    monkeypatch.setattr(meshstore, "_MEMORY", {})

    def refuse(*_: object) -> None:
        raise AssertionError("the mesh was read again")

    read = meshes.read_integrals
    monkeypatch.setattr(meshes, "read_integrals", refuse)
    check_box(meshstore.properties(path, (2.0, 2.0, 2.0)), (2.0, 4.0, 6.0))
    monkeypatch.setattr(meshes, "read_integrals", read)
    monkeypatch.setattr(meshstore, "_MEMORY", {})
    # An edit (new size and time) is a new key: the new box, never the old one's values.
    path.write_text(box_obj((3.0, 2.0, 1.0)))
    os.utime(path, ns=(1, 1))
    check_box(meshstore.properties(path), (3.0, 2.0, 1.0))
    # A damaged entry is read past and rewritten.
    for entry in (tmp_path / "cache" / meshstore._FOLDER).iterdir():
        entry.write_bytes(b"garbage")
    monkeypatch.setattr(meshstore, "_MEMORY", {})
    check_box(meshstore.properties(path), (3.0, 2.0, 1.0))
    good = [e for e in (tmp_path / "cache" / meshstore._FOLDER).iterdir()
            if e.read_bytes().startswith(b"M5")]
    assert len(good) == 1  # the current key's, rewritten (the first box's stays unused)


def test_empty_cache_dir_turns_the_cache_off(tmp_path: Path,
                                              monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setenv("URDFKIT_CACHE_DIR", "")
    path = tmp_path / "box.obj"
    path.write_text(box_obj())
    check_box(meshstore.properties(path), (1.0, 1.0, 1.0))
    assert not (tmp_path / "cache").exists()


def test_unwritable_cache_is_skipped(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    blocker = tmp_path / "not-a-folder"
    blocker.write_text("")
    monkeypatch.setenv("URDFKIT_CACHE_DIR", str(blocker))
    path = tmp_path / "box.obj"
    path.write_text(box_obj())
    check_box(meshstore.properties(path), (1.0, 1.0, 1.0))


def box_dae(*, unit: float = 0.001, up: str = "Y_UP", node: str = "") -> str:
    """A 100 x 200 x 300 box in COLLADA (quads in a polylist), in ``unit`` metres per unit."""
    size = (100.0, 200.0, 300.0)
    corners = " ".join(f"{x * size[0]} {y * size[1]} {z * size[2]}" for x, y, z in CORNERS)
    quads = " ".join(str(i - 1) for quad in QUADS for i in quad)
    return f"""<?xml version="1.0"?>
<COLLADA xmlns="http://www.collada.org/2005/11/COLLADASchema" version="1.4.1">
  <asset><unit meter="{unit}" name="u"/><up_axis>{up}</up_axis></asset>
  <library_geometries><geometry id="box"><mesh>
    <source id="box-pos"><float_array id="box-pos-a" count="24">{corners}</float_array>
      <technique_common><accessor source="#box-pos-a" count="8" stride="3"/></technique_common>
    </source>
    <vertices id="box-v"><input semantic="POSITION" source="#box-pos"/></vertices>
    <polylist count="6"><input semantic="VERTEX" source="#box-v" offset="0"/>
      <vcount>4 4 4 4 4 4</vcount><p>{quads}</p></polylist>
    <lines count="1"><input semantic="VERTEX" source="#box-v" offset="0"/><p>0 1</p></lines>
  </mesh></geometry></library_geometries>
  <library_visual_scenes><visual_scene id="scene">
    <node id="n">{node}<instance_geometry url="#box"/></node>
  </visual_scene></library_visual_scenes>
  <scene><instance_visual_scene url="#scene"/></scene>
</COLLADA>
"""


def pybullet_aabb(p, client: int, mesh: Path, workdir: Path) -> tuple:  # type: ignore[no-untyped-def]
    urdf = workdir / f"{mesh.stem}-probe.urdf"
    urdf.write_text('<robot name="r"><link name="a"><inertial><mass value="1"/><inertia ixx="1" '
                    'ixy="0" ixz="0" iyy="1" iyz="0" izz="1"/></inertial><collision><geometry>'
                    f'<mesh filename="{mesh}"/></geometry></collision></link></robot>')
    body = p.loadURDF(str(urdf), physicsClientId=client)
    return p.getAABB(body, -1, physicsClientId=client)


@pytest.mark.parametrize("node", [
    "",
    '<translate>1000 0 0</translate>',
    # PyBullet reads only the first <rotate> of a node: the second is ignored, as here.
    '<translate>0 0 500</translate><rotate>0 0 1 90</rotate><rotate>1 0 0 90</rotate>',
    '<matrix>1 0 0 0  0 0 -1 0  0 1 0 0  0 0 0 1</matrix>',
])
def test_dae_is_placed_as_pybullet_places_it(tmp_path: Path, node: str, pb) -> None:
    path = tmp_path / "box.dae"
    path.write_text(box_dae(node=node))
    props = meshstore.properties(path)
    assert props is not None and props.closed
    assert props.volume == pytest.approx(0.1 * 0.2 * 0.3)  # <unit meter="0.001">
    assert sorted(props.extent) == pytest.approx([0.1, 0.2, 0.3])
    p, client = pb
    lo, hi = (np.array(v) for v in pybullet_aabb(p, client, path, tmp_path))
    # PyBullet pads a hull with a collision margin (here 2 mm on each side).
    centre = np.array(props.com)
    assert (lo + hi) / 2 == pytest.approx(centre, abs=1e-6)
    assert hi - lo - 0.004 == pytest.approx(props.extent, abs=1e-6)


def test_real_dae_meshes_are_placed_as_pybullet_places_them(tmp_path: Path, pb) -> None:
    # pybullet_data's racecar: Y_UP files (not turned), an inch-unit cone, a scene of nodes.
    p, client = pb
    for mesh in sorted((DATA / "racecar" / "meshes").glob("*.dae")):
        vertices, faces = meshes._dae(mesh.read_bytes(), mesh)
        used = vertices[np.unique(faces)]
        lo, hi = (np.array(v) for v in pybullet_aabb(p, client, mesh, tmp_path))
        assert used.min(axis=0) == pytest.approx(lo + 0.002, abs=1e-4), mesh.name
        assert used.max(axis=0) == pytest.approx(hi - 0.002, abs=1e-4), mesh.name


def _new_process(monkeypatch: pytest.MonkeyPatch) -> None:
    """What a new process starts with: no entries in memory, none used, no pack read."""
    monkeypatch.setattr(meshstore, "_MEMORY", {})
    monkeypatch.setattr(meshstore, "USED", {})
    monkeypatch.setattr(meshstore, "_PACKED", set())


def _robot_with_box(folder: Path, size: tuple[float, float, float]) -> Path:
    folder.mkdir(exist_ok=True)
    (folder / "box.obj").write_text(box_obj(size))
    urdf = folder / "r.urdf"
    urdf.write_text('<robot name="r"><link name="a"><inertial><mass value="1"/>'
                    '<inertia ixx="1" ixy="0" ixz="0" iyy="1" iyz="0" izz="1"/></inertial>'
                    '<collision><geometry><mesh filename="box.obj"/></geometry></collision>'
                    '</link></robot>')
    return urdf


def test_a_run_s_pack_serves_the_next_run_and_follows_edits(
        tmp_path: Path, settled: None, monkeypatch: pytest.MonkeyPatch) -> None:
    from urdfkit.checks.check import check_paths

    folder = tmp_path / "robot"
    _robot_with_box(folder, (1.0, 2.0, 3.0))
    _new_process(monkeypatch)
    check_paths([folder], jobs=1, cache=False)
    packs = list((tmp_path / "cache" / meshstore._PACKS).iterdir())
    assert len(packs) == 1
    # The next run reads the pack alone: no entry file, no mesh.
    for entry in (tmp_path / "cache" / meshstore._FOLDER).iterdir():
        entry.unlink()
    _new_process(monkeypatch)

    def refuse(*_: object) -> None:
        raise AssertionError("the mesh was read again")

    monkeypatch.setattr(meshes, "read_integrals", refuse)
    assert meshstore.load_pack([str(folder)]) == 1
    check_box(meshstore.properties(folder / "box.obj"), (1.0, 2.0, 3.0))
    monkeypatch.undo()
    monkeypatch.setenv("URDFKIT_CACHE_DIR", str(tmp_path / "cache"))
    # An edited mesh misses the pack: its new values, never the packed ones.
    (folder / "box.obj").write_text(box_obj((3.0, 2.0, 1.0)))
    os.utime(folder / "box.obj", ns=(1, 1))
    _new_process(monkeypatch)
    meshstore.load_pack([str(folder)])
    check_box(meshstore.properties(folder / "box.obj"), (3.0, 2.0, 1.0))


def test_a_damaged_pack_is_ignored_whole(tmp_path: Path, settled: None,
                                         monkeypatch: pytest.MonkeyPatch) -> None:
    from urdfkit.checks.check import check_paths

    folder = tmp_path / "robot"
    _robot_with_box(folder, (1.0, 2.0, 3.0))
    _new_process(monkeypatch)
    check_paths([folder], jobs=1, cache=False)
    (pack,) = (tmp_path / "cache" / meshstore._PACKS).iterdir()
    good = pack.read_bytes()
    for damaged in (good[:-1], good[:20] + bytes([good[20] ^ 1]) + good[21:], b"MP1\n",
                    b"garbage"):
        pack.write_bytes(damaged)
        _new_process(monkeypatch)
        assert meshstore.load_pack([str(folder)]) == 0
        assert meshstore._MEMORY == {}


def test_packs_are_capped(tmp_path: Path, settled: None, monkeypatch: pytest.MonkeyPatch) -> None:
    folder = tmp_path / "robot"
    _robot_with_box(folder, (1.0, 1.0, 1.0))
    monkeypatch.setattr(meshstore, "MAX_PACKS", 3)
    for n in range(6):
        _new_process(monkeypatch)
        meshstore.properties(folder / "box.obj")
        assert meshstore.save_pack([str(folder), f"run{n}"])
    assert len(list((tmp_path / "cache" / meshstore._PACKS).iterdir())) == 3
    _new_process(monkeypatch)
    meshstore.properties(folder / "box.obj")
    assert meshstore.load_pack([str(folder), "run5"]) == 1
    assert not meshstore.save_pack([str(folder), "run5"])  # the same entries: not rewritten


def test_workers_hand_their_entries_to_the_run_s_pack(
        tmp_path: Path, settled: None, monkeypatch: pytest.MonkeyPatch) -> None:
    from urdfkit.checks.check import check_paths

    (tmp_path / "robots").mkdir()
    for n in range(16):  # enough files for a pool of two
        _robot_with_box(tmp_path / "robots" / f"r{n}", (1.0 + n, 1.0, 1.0))
    _new_process(monkeypatch)
    check_paths([tmp_path / "robots"], jobs=2, cache=False)
    _new_process(monkeypatch)
    assert meshstore.load_pack([str(tmp_path / "robots")]) == 16


@settings(max_examples=200, deadline=None)
@given(st.lists(st.lists(st.integers(1, 9), min_size=1, max_size=7), min_size=1, max_size=12),
       st.lists(st.integers(0, 11), max_size=3), st.sampled_from(["", "/1", "/1/2", "//3"]),
       st.sampled_from([" ", "\t", "  "]))
def test_obj_polygons_become_the_fans_pybullet_makes(
        polygons: list[list[int]], objects: list[int], tail: str, gap: str) -> None:
    """Any mix of polygons, index styles and object starts: triangles (p0, pk, pk+1), as a
    plain loop over the lines makes them, and each object's first triangle."""
    lines = [f"v {i} {i * i} {i % 3}" for i in range(1, 10)]
    oracle: list[tuple[int, int, int]] = []
    first_of_object: list[int] = []  # triangles before each object's first face line
    last_line = -1
    for n, poly in enumerate(polygons):
        if n in objects and n > 0 and n != last_line:
            first_of_object.append(len(oracle))
            last_line = n
        if n in objects:
            lines.append(f"o part{n}")
        lines.append("f" + gap + gap.join(f"{i}{tail}" for i in poly))
        oracle += [(poly[0] - 1, poly[k] - 1, poly[k + 1] - 1) for k in range(1, len(poly) - 1)]
    vertices, faces, starts = meshes._obj(("\n".join(lines) + "\n").encode())
    assert len(vertices) == 9
    assert [tuple(f) for f in faces.tolist()] == oracle
    assert starts == first_of_object


@settings(max_examples=100, deadline=None)
@given(st.lists(st.tuples(*[st.sampled_from([0.0, -0.0, 1.0, 0.5, -2.25, 3e-9])] * 3),
                min_size=3, max_size=60).filter(lambda c: len(c) % 3 == 0))
def test_welding_stl_corners_groups_equal_points_as_numpy_unique_does(
        corners: list[tuple[float, float, float]]) -> None:
    array = np.array(corners, dtype=float)
    unique, index = meshes._weld(array)
    expected = np.unique(array, axis=0)  # compares floats: -0.0 is 0.0
    assert len(unique) == len(expected)
    assert np.array_equal(unique[index.ravel()], array)  # every corner is its own point


def _stl_box(path: Path, size: float, crack: float = 0.0, drop: int | None = None) -> Path:
    """A binary STL box (float32, as STL stores it): one corner of its first triangle moved by
    ``crack`` along x (a seam that CAD export left a rounding step open), or triangle
    ``drop`` left out (a real hole)."""
    corners = np.array(CORNERS) * size
    tris = [t for quad in QUADS for t in ((quad[0], quad[1], quad[2]), (quad[0], quad[2], quad[3]))]
    data = np.array([[corners[i - 1] for i in t] for t in tris], dtype=np.float64)
    data[0, 0, 0] += crack
    if drop is not None:
        data = np.delete(data, drop, axis=0)
    rows = np.zeros(len(data), dtype=[("n", "<f4", 3), ("v", "<f4", (3, 3)), ("a", "<u2")])
    rows["v"] = data.astype(np.float32)
    path.write_bytes(b"\0" * 80 + np.uint32(len(data)).tobytes() + rows.tobytes())
    return path


def test_a_seam_open_by_a_rounding_step_is_closed(tmp_path: Path) -> None:
    """fetch_description's laser_link.STL: two corners of one seam a float32 step apart (9.3e-10
    m on a 7.5 cm part). That is no hole: the box keeps the closed form's volume and inertia."""
    size = 0.075
    step = float(np.spacing(np.float32(size)))  # one float32 step at the box's far corner
    path = _stl_box(tmp_path / "cracked.stl", size, crack=step)
    raw = np.frombuffer(path.read_bytes()[84:], dtype=[("n", "<f4", 3), ("v", "<f4", (3, 3)),
                                                       ("a", "<u2")])["v"].reshape(-1, 3)
    assert len(np.unique(raw, axis=0)) == 9  # the crack is really in the file: 9 points, not 8
    check_box(meshstore.properties(path), (size, size, size))


@pytest.mark.parametrize("how", ["wide crack", "missing triangle"])
def test_a_real_gap_stays_open(tmp_path: Path, how: str) -> None:
    size = 0.075
    path = _stl_box(tmp_path / "open.stl", size, crack=size * 1e-3) if how == "wide crack" \
        else _stl_box(tmp_path / "open.stl", size, drop=3)
    props = meshstore.properties(path)
    assert props is not None and not props.closed


def test_dae_geometries_that_repeat_their_ids_keep_their_own_points(tmp_path: Path,
                                                                      pb) -> None:
    """Files exported geometry by geometry repeat the same source ids in each (jaxon's
    LLEG_LINK3.dae: eight "geo0.positions"): PyBullet reads each geometry's own points; the
    document-wide id put both boxes here on the second's points (its box was 1 x 1 x 1 m)."""
    one = box_dae(unit=0.001)
    # a second geometry with the same source ids, 1 m along x, in a second node
    geo = one[one.index("<geometry id=\"box\">"):one.index("</geometry>") + len("</geometry>")]
    far = geo.replace('id="box"', 'id="box2"')
    corners = far[far.index('count="24">') + 11:far.index("</float_array>")]
    moved = " ".join(str(float(v) + (1000.0 if k % 3 == 0 else 0.0))
                     for k, v in enumerate(corners.split()))
    far = far.replace(corners, moved)
    text = one.replace("</library_geometries>", far + "</library_geometries>").replace(
        '<node id="n"><instance_geometry url="#box"/></node>',
        '<node id="n"><instance_geometry url="#box"/></node>'
        '<node id="m"><instance_geometry url="#box2"/></node>')
    path = tmp_path / "two.dae"
    path.write_text(text)
    vertices, faces = meshes._dae(path.read_bytes(), path)
    used = vertices[np.unique(faces)]
    p, client = pb
    lo, hi = (np.array(v) for v in pybullet_aabb(p, client, path, tmp_path))
    assert used.min(axis=0) == pytest.approx(lo + 0.002, abs=1e-6)
    assert used.max(axis=0) == pytest.approx(hi - 0.002, abs=1e-6)
    assert hi[0] - lo[0] == pytest.approx(1.1 + 0.004, abs=1e-6)  # both boxes, 1 m apart
