"""Mesh mass properties (urdfkit.meshes): against closed forms, trimesh, and the cache's rules."""

from __future__ import annotations

import math
import os
from pathlib import Path

import pybullet_data
import pytest

from urdfkit import meshes
from urdfkit.spec import solid_inertia, solid_volume

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


def check_box(props: meshes.MeshProperties | None, size: tuple[float, float, float],
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
    monkeypatch.setattr(meshes, "_MEMORY", {})
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
    check_box(meshes.properties(path), (0.2, 0.5, 1.5))


@pytest.mark.parametrize("scale", [(2.0, 0.5, 3.0), (-1.0, 1.0, 1.0), (0.001, 0.001, 0.001),
                                   (0.1, -0.2, 0.3)])
def test_scale_applied_in_closed_form_equals_a_scaled_file(tmp_path: Path,
                                                           scale: tuple[float, float, float]
                                                           ) -> None:
    unit, scaled = tmp_path / "unit.obj", tmp_path / "scaled.obj"
    unit.write_text(box_obj(quads=False))
    scaled.write_text(box_obj(scale, quads=False))
    a, b = meshes.properties(unit, scale), meshes.properties(scaled)
    assert a is not None and b is not None
    assert a.volume == pytest.approx(b.volume) == pytest.approx(abs(math.prod(scale)))
    assert a.com == pytest.approx(b.com)
    for row_a, row_b in zip(a.inertia, b.inertia, strict=True):
        assert row_a == pytest.approx(row_b, abs=1e-15)
    assert a.extent == pytest.approx(b.extent)


def test_binary_stl_cube_and_open_surface() -> None:
    check_box(meshes.properties(FIXTURES / "unit_cube.stl"), (1.0, 1.0, 1.0), centred=True)
    props = meshes.properties(FIXTURES / "open_triangle.stl")
    assert props is not None and not props.closed and props.trace_for_mass(1.0) is None


def test_real_meshes_agree_with_trimesh() -> None:
    trimesh = pytest.importorskip("trimesh")
    for name in ("duck_vhacd.obj", "random_urdfs/000/000.obj", "sphere_smooth.obj"):
        ours = meshes.properties(DATA / name)
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
])
def test_broken_meshes_are_unreadable_not_a_crash(tmp_path: Path, text: str) -> None:
    path = tmp_path / "bad.obj"
    path.write_text(text)
    assert meshes.properties(path) is None


def test_cache_serves_the_second_read_and_follows_edits(tmp_path: Path,
                                                        monkeypatch: pytest.MonkeyPatch) -> None:
    path = tmp_path / "box.obj"
    path.write_text(box_obj((1.0, 2.0, 3.0)))
    check_box(meshes.properties(path), (1.0, 2.0, 3.0))
    entries = list((tmp_path / "cache" / "meshes-2").iterdir())
    assert len(entries) == 1
    # A new process (empty memory) reads the entry, not the mesh.
    monkeypatch.setattr(meshes, "_MEMORY", {})

    def refuse(*_: object) -> None:
        raise AssertionError("the mesh was read again")

    monkeypatch.setattr(meshes, "read_integrals", refuse)
    check_box(meshes.properties(path, (2.0, 2.0, 2.0)), (2.0, 4.0, 6.0))
    monkeypatch.undo()
    monkeypatch.setenv("URDFKIT_CACHE_DIR", str(tmp_path / "cache"))
    monkeypatch.setattr(meshes, "_MEMORY", {})
    # An edit (new size and time) is a new key: the new box, never the old one's values.
    path.write_text(box_obj((3.0, 2.0, 1.0)))
    os.utime(path, ns=(1, 1))
    check_box(meshes.properties(path), (3.0, 2.0, 1.0))
    # A damaged entry is read past and rewritten.
    for entry in (tmp_path / "cache" / "meshes-2").iterdir():
        entry.write_bytes(b"garbage")
    monkeypatch.setattr(meshes, "_MEMORY", {})
    check_box(meshes.properties(path), (3.0, 2.0, 1.0))
    good = [e for e in (tmp_path / "cache" / "meshes-2").iterdir()
            if e.read_bytes().startswith(b"M2")]
    assert len(good) == 1  # the current key's, rewritten (the first box's stays unused)


def test_empty_cache_dir_turns_the_cache_off(tmp_path: Path,
                                              monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setenv("URDFKIT_CACHE_DIR", "")
    path = tmp_path / "box.obj"
    path.write_text(box_obj())
    check_box(meshes.properties(path), (1.0, 1.0, 1.0))
    assert not (tmp_path / "cache").exists()


def test_unwritable_cache_is_skipped(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    blocker = tmp_path / "not-a-folder"
    blocker.write_text("")
    monkeypatch.setenv("URDFKIT_CACHE_DIR", str(blocker))
    path = tmp_path / "box.obj"
    path.write_text(box_obj())
    check_box(meshes.properties(path), (1.0, 1.0, 1.0))
