"""Convexity that holds on real meshes: slivers and mixed winding are not dips; holes hide none.

Each mesh is generated here, and scipy's ConvexHull (an independent library) says how much of
its hull it fills: a convex mesh 100%, the concave ones far less. check's U614 must agree.
"""

from __future__ import annotations

import json
import struct
from pathlib import Path

import numpy as np
import pytest
from typer.testing import CliRunner

from urdfkit.cli import app
from urdfkit.sources.meshes import read_integrals

scipy_spatial = pytest.importorskip("scipy.spatial")

CUBE_V = np.array([[x, y, z] for x in (0, 1) for y in (0, 1) for z in (0, 1)], dtype=float)
# Outward triangles of the unit cube (vertex index = 4x + 2y + z).
CUBE_F = np.array([
    [0, 1, 3], [0, 3, 2], [4, 6, 7], [4, 7, 5],  # x = 0, x = 1
    [0, 4, 5], [0, 5, 1], [2, 3, 7], [2, 7, 6],  # y = 0, y = 1
    [0, 2, 6], [0, 6, 4], [1, 5, 7], [1, 7, 3],  # z = 0, z = 1
])


def _stl(path: Path, vertices: np.ndarray, faces: np.ndarray) -> Path:
    """A binary STL (float32, as CAD exports write it)."""
    out = bytearray(80) + struct.pack("<I", len(faces))
    for f in faces:
        out += struct.pack("<3f", 0, 0, 0)
        for i in f:
            out += struct.pack("<3f", *vertices[i])
        out += b"\0\0"
    path.write_bytes(bytes(out))
    return path


def _volume(vertices: np.ndarray, faces: np.ndarray) -> float:
    a, b, c = vertices[faces.T]
    return abs(float(np.einsum("ij,ij->i", a, np.cross(b, c)).sum()) / 6)


def _filled(vertices: np.ndarray, faces: np.ndarray) -> float:
    """The mesh's volume over its convex hull's (scipy), faces wound outward."""
    return _volume(vertices, faces) / scipy_spatial.ConvexHull(vertices[np.unique(faces)]).volume


def _hull_depth(vertices: np.ndarray, faces: np.ndarray) -> float:
    """How deep inside its convex hull (scipy) the mesh's deepest vertex lies."""
    used = vertices[np.unique(faces)]
    eq = scipy_spatial.ConvexHull(used).equations  # n . x + d <= 0 inside
    return float((-(used @ eq[:, :3].T + eq[:, 3])).min(axis=1).max())


def _sliver_cube() -> tuple[np.ndarray, np.ndarray]:
    """A 0.3 m cube with a sliver triangle along a top edge, as CAD exports leave them.

    The side face y = 0 is re-made around a vertex m at the middle of the edge from (0,0,0.3)
    to (0.3,0,0.3), 1e-7 m inside the cube in y and z (a float rounding step); the gap between
    that edge and m is one sliver triangle, ~2e-8 m^2. Its plane runs at 45 degrees through
    the edge, so the cube's far top corners stand 0.21 m "in front" of it.
    """
    v = np.vstack([CUBE_V * 0.3, [[0.15, 1e-7, 0.3 - 1e-7]]])
    m = 8
    faces = [f for f in CUBE_F.tolist() if f != [0, 5, 1]]
    faces += [[0, 5, m], [0, m, 1], [5, 1, m]]
    return v, np.array(faces)


def _l_prism() -> tuple[np.ndarray, np.ndarray]:
    """A closed L-shaped prism (the L in x-y, 0.2 m tall), triangles wound outward."""
    outline = [(0, 0), (0.3, 0), (0.3, 0.1), (0.1, 0.1), (0.1, 0.3), (0, 0.3)]
    n = len(outline)
    v = np.array([[x, y, z] for z in (0.0, 0.2) for x, y in outline])
    faces = []
    for i in range(n):  # the sides
        j = (i + 1) % n
        faces += [[i, j, n + j], [i, n + j, n + i]]
    # bottom (outward -z) and top (+z): the L as two convex quads 0-1-2-3 and 0-3-4-5
    for quad in ([0, 1, 2, 3], [0, 3, 4, 5]):
        a, b, c, d = quad
        faces += [[a, c, b], [a, d, c]]
        faces += [[n + a, n + b, n + c], [n + a, n + c, n + d]]
    return v, np.array(faces)


def _robot(tmp_path: Path, mesh: Path) -> Path:
    """A two-link robot whose moving link collides with ``mesh``."""
    path = tmp_path / "robot.urdf"
    inertial = ('<inertial><mass value="1"/><inertia ixx="0.01" ixy="0" ixz="0" iyy="0.01" '
                'iyz="0" izz="0.01"/></inertial>')
    path.write_text(f"""<robot name="r">
  <link name="a">{inertial}</link>
  <link name="b">{inertial}
    <collision><geometry><mesh filename="{mesh.name}"/></geometry></collision></link>
  <joint name="j" type="revolute"><parent link="a"/><child link="b"/><origin xyz="0 0 0.5"/>
    <limit lower="-1" upper="1" effort="1" velocity="1"/></joint>
  <link name="c">{inertial}</link>
  <joint name="k" type="fixed"><parent link="a"/><child link="c"/><origin xyz="0.4 0 0"/></joint>
</robot>
""")
    return path


def _codes(path: Path) -> dict[str, str]:
    out = CliRunner().invoke(app, ["check", str(path), "--json", "--no-cache"]).stdout
    return {f["code"]: f["message"] for f in json.loads(out)["findings"]}


def test_convex_with_slivers_and_mixed_winding_is_convex(tmp_path: Path) -> None:
    v, f = _sliver_cube()
    assert _filled(v, f) == pytest.approx(1.0, abs=1e-6)  # scipy: it fills its hull
    assert _hull_depth(v, f) < 2e-7  # and its one dent is a rounding step deep
    mixed = f.copy()
    mixed[::3] = mixed[::3, ::-1]  # every third triangle wound backwards
    mesh = _stl(tmp_path / "cube.stl", v, mixed)
    props = read_integrals(mesh)
    assert props is not None and props.closed and props.concavity < 1e-6
    plain = read_integrals(_stl(tmp_path / "plain.stl", v, f))  # slivers alone, wound right
    assert plain is not None and plain.closed and plain.concavity < 1e-6
    assert "U614" not in _codes(_robot(tmp_path, mesh))


def test_closed_concave_mesh_is_concave(tmp_path: Path) -> None:
    v, f = _l_prism()
    filled = _filled(v, f)
    assert filled == pytest.approx(0.5 / 0.7, rel=1e-9)  # scipy: 71% of its hull (0.05/0.07)
    mixed = f.copy()
    mixed[1::4] = mixed[1::4, ::-1]
    mesh = _stl(tmp_path / "l.stl", v, mixed)
    props = read_integrals(mesh)
    assert props is not None and props.closed
    assert props.concavity == pytest.approx(0.2, rel=1e-5)  # the notch: 0.2 m deep
    assert "U614" in _codes(_robot(tmp_path, mesh))


def test_open_concave_mesh_gets_a_finding(tmp_path: Path) -> None:
    v, f = _l_prism()
    opened = f[2:]  # one side's two triangles gone: a hole
    assert _filled(v, f) < 0.72  # scipy: closed, the same L fills 71% of its hull
    mesh = _stl(tmp_path / "open_l.stl", v, opened)
    props = read_integrals(mesh)
    assert props is not None and not props.closed
    codes = _codes(_robot(tmp_path, mesh))
    assert "U614" in codes and "open" in codes["U614"]
    assert "U612" in codes  # its inertia cannot be derived: said too


def test_collisions_agrees(tmp_path: Path) -> None:
    """collisions names a concave link's hull only when check's U614 would."""
    from urdfkit.checks.collisions import _concave_links
    from urdfkit.sources.resolve import resolve

    v, f = _sliver_cube()
    convex = _robot(tmp_path, _stl(tmp_path / "cube.stl", v, f))
    with resolve(str(convex)) as resolved:
        assert _concave_links(resolved, None) == set()
    lv, lf = _l_prism()
    (tmp_path / "l").mkdir()
    concave = _robot(tmp_path / "l", _stl(tmp_path / "l" / "l.stl", lv, lf))
    with resolve(str(concave)) as resolved:
        assert _concave_links(resolved, None) == {"b"}


def test_a_shell_inside_a_convex_mesh_is_no_dip(tmp_path: Path) -> None:
    """A second closed shell inside the first (CAD exports leave inner parts in one STL, as
    UR10's shoulder.stl): its faces' planes put the outer corners "in front", but the hull
    (scipy: the outer cube's) is all filled, and PyBullet collides with that hull."""
    v = np.vstack([CUBE_V * 0.3, CUBE_V * 0.1 + 0.1])
    f = np.vstack([CUBE_F, CUBE_F + 8])
    assert scipy_spatial.ConvexHull(v).volume == pytest.approx(0.027)
    mesh = _stl(tmp_path / "nested.stl", v, f)
    props = read_integrals(mesh)
    assert props is not None and props.closed and props.concavity == 0.0
    assert "U614" not in _codes(_robot(tmp_path, mesh))
