"""Mass properties of mesh files, for the mesh-aware physics checks (no trimesh needed).

About half of the links of real robots collide only through meshes. :func:`properties` reads
an STL (binary or ASCII) or OBJ file, applies ``<mesh scale>``, and returns the solid's volume,
centre of mass and inertia per unit density by the signed-tetrahedron method (each triangle
with the origin spans a tetrahedron; summed with signs, they give the closed solid's
integrals). It also says whether the surface is closed (every edge shared by exactly two
triangles), since a mesh with holes has no meaningful volume. Results are cached by the
file's content hash: a tree of robots sharing meshes reads each mesh once per process.
COLLADA (.dae) is not read: checks skip those meshes.
"""

from __future__ import annotations

import hashlib
import re
import struct
from dataclasses import dataclass
from pathlib import Path
from typing import Any

#: Largest mesh file read for checks; bigger ones are skipped (checks must stay fast).
MAX_MESH_BYTES = 16 * 1024 * 1024


@dataclass(frozen=True)
class MeshProperties:
    """A closed triangle mesh as a solid of unit density (scaled).

    Attributes:
        volume: m^3 (positive for outward-facing triangles).
        com: Centre of mass in the mesh frame.
        inertia: 3x3 inertia tensor about ``com`` per kg/m^3 (multiply by mass / volume).
        extent: Size of the bounding box along x, y, z.
        closed: Every edge is shared by exactly two triangles.
        triangles: How many triangles.
    """

    volume: float
    com: tuple[float, float, float]
    inertia: tuple[tuple[float, ...], ...]
    extent: tuple[float, float, float]
    closed: bool
    triangles: int

    def trace_for_mass(self, mass: float) -> float | None:
        """Trace of the inertia of this solid with ``mass``, or None without a volume."""
        if not self.closed or self.volume <= 0:
            return None
        t = self.inertia
        return (t[0][0] + t[1][1] + t[2][2]) * mass / self.volume


_CACHE: dict[tuple[str, tuple[float, ...]], MeshProperties | None] = {}


def properties(path: Path, scale: tuple[float, float, float] = (1.0, 1.0, 1.0)
               ) -> MeshProperties | None:
    """Mass properties of an STL or OBJ mesh, or None if unreadable, unsupported or empty."""
    try:
        if path.stat().st_size > MAX_MESH_BYTES:
            return None
        data = path.read_bytes()
    except OSError:
        return None
    key = (hashlib.sha1(data).hexdigest(), tuple(scale))
    if key not in _CACHE:
        suffix = path.suffix.lower()
        try:
            vertices, faces = (_stl(data) if suffix == ".stl" else _obj(data) if suffix == ".obj"
                               else (None, None))
        except (ValueError, struct.error, IndexError):
            vertices, faces = None, None
        _CACHE[key] = (None if vertices is None or faces is None or len(faces) == 0
                       else _solid(vertices, faces, scale))
    return _CACHE[key]


def _stl(data: bytes) -> tuple[Any, Any]:
    import numpy as np

    if len(data) >= 84:
        count = struct.unpack_from("<I", data, 80)[0]
        if 84 + 50 * count == len(data):  # binary: 50 bytes per triangle
            rec = np.frombuffer(data, dtype=np.dtype([("n", "<f4", 3), ("v", "<f4", (3, 3)),
                                                      ("a", "<u2")]), count=count, offset=84)
            return _weld(rec["v"].reshape(-1, 3).astype(float))
    words = data.decode("ascii", "replace").split()
    coords = [float(words[i + 1]) for i in range(len(words)) if words[i] == "vertex"
              for i in (i, i + 1, i + 2)]
    return _weld(np.array(coords, dtype=float).reshape(-1, 3))


def _weld(corners: Any) -> tuple[Any, Any]:
    """Shared vertices from per-triangle corners (STL repeats them), for the closed test."""
    import numpy as np

    unique, index = np.unique(corners, axis=0, return_inverse=True)
    return unique, index.reshape(-1, 3)


_OBJ_VERTEX = re.compile(rb"^v[ \t]+(\S+)[ \t]+(\S+)[ \t]+(\S+)", re.M)
_OBJ_FACE = re.compile(rb"^f[ \t]+([^\r\n]+)", re.M)
_OBJ_TRIANGLE = re.compile(rb"^f[ \t]+(-?\d+)\S*[ \t]+(-?\d+)\S*[ \t]+(-?\d+)\S*[ \t]*\r?$",
                           re.M)


def _obj(data: bytes) -> tuple[Any, Any]:
    import numpy as np

    vertices = np.array(_OBJ_VERTEX.findall(data), dtype=float).reshape(-1, 3)
    count = len(vertices)
    lines = _OBJ_FACE.findall(data)
    triangles = _OBJ_TRIANGLE.findall(data)
    if len(triangles) == len(lines):  # the common case, all triangles: no Python loop
        tri = np.array(triangles, dtype=float).astype(int).reshape(-1, 3)
        return vertices, np.where(tri > 0, tri - 1, count + tri)
    faces: list[tuple[int, int, int]] = []
    for line in lines:
        idx = [int(p.split(b"/", 1)[0]) for p in line.split()]
        idx = [i - 1 if i > 0 else count + i for i in idx]
        faces += [(idx[0], idx[k], idx[k + 1]) for k in range(1, len(idx) - 1)]
    return vertices, np.array(faces, dtype=int).reshape(-1, 3)


def _solid(vertices: Any, faces: Any, scale: tuple[float, float, float]) -> MeshProperties:
    import numpy as np

    v = vertices * np.asarray(scale, dtype=float)
    a, b, c = v[faces[:, 0]], v[faces[:, 1]], v[faces[:, 2]]
    det = np.einsum("ij,ij->i", a, np.cross(b, c))  # 6 x signed tetrahedron volumes
    volume = det.sum() / 6.0
    if volume < 0:  # inward-facing triangles: the same solid, turned inside out
        det, volume = -det, -volume
    com = ((a + b + c) * det[:, None]).sum(axis=0) / (24.0 * volume) if volume else np.zeros(3)
    # Second moments of each tetrahedron (origin, a, b, c) about the origin.
    s = a + b + c
    second = (np.einsum("ij,ik->ijk", a, a) + np.einsum("ij,ik->ijk", b, b)
              + np.einsum("ij,ik->ijk", c, c) + np.einsum("ij,ik->ijk", s, s))
    moments = (second * det[:, None, None]).sum(axis=0) / 120.0  # integral of x_i x_j
    about_com = moments - volume * np.outer(com, com)
    tensor = np.trace(about_com) * np.eye(3) - about_com
    # Closed: every undirected edge in exactly two triangles (one int64 key per edge: a 1-D
    # sort, not a row-wise unique, which is ten times slower).
    ends = np.concatenate([faces[:, [0, 1]], faces[:, [1, 2]], faces[:, [2, 0]]]).astype(np.int64)
    keys = ends.min(axis=1) * (int(faces.max()) + 1) + ends.max(axis=1)
    _, counts = np.unique(keys, return_counts=True)
    used = v[np.unique(faces)]
    extent = used.max(axis=0) - used.min(axis=0)
    return MeshProperties(float(volume), tuple(float(x) for x in com),  # type: ignore[arg-type]
                          tuple(tuple(float(x) for x in row) for row in tensor),
                          tuple(float(x) for x in extent),  # type: ignore[arg-type]
                          bool((counts == 2).all()), int(len(faces)))
