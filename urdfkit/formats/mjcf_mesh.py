"""Mesh files MuJoCo 4.0 loads: every mesh read with urdfkit's readers before it is written.

The MJCF writer (:mod:`urdfkit.formats.mjcf`) never hands MuJoCo a file unread. Each mesh is
parsed by :func:`urdfkit.sources.meshes.parse_mesh` (placed as PyBullet places it), and what
MuJoCo 4.0.0 refuses was measured, file by file:

- no triangles (an empty or garbage OBJ: "at least 4 vertices required"; a binary STL of 0
  faces), fewer than 4 vertices, a vertex that is not finite as a float ("vertex coordinate 0
  is not finite"; an OBJ coordinate of 1e300 is infinite once MuJoCo reads it as a float);
- a vertex index out of range ("vertex index 98 does not exist"); an OBJ whose faces do not
  all name one of its ``vn`` normals ("normal index out of bounds");
- a binary STL of more than 200,000 faces ("number of faces should be between 1 and
  200000"); MuJoCo's OBJ reader has no such limit (2,402,496 faces loaded);
- a surface area under 1e-15 m^2 at the geom's scale (a unit cube scaled 1e-8 is refused,
  1e-7 loads), and, for a geom that collides, vertices that span no volume (MuJoCo builds the
  convex hull it collides with: "coplanar vertices, cannot compute convex hull").

A mesh MuJoCo reads as it is, is copied byte for byte. One it cannot, whose sound triangles
can be kept, is converted: triangles with a non-finite vertex or an index out of range
removed, and the rest written as binary STL (as OBJ past 200,000 faces: every face kept). A
mesh with nothing sound left is dropped. The use checks (area at a scale, volume for a
collision) are per geom: :func:`unusable`.
"""

from __future__ import annotations

import hashlib
import struct
from dataclasses import dataclass
from pathlib import Path
from typing import Any

#: MuJoCo 4.0's STL reader takes at most this many faces; its OBJ reader takes more.
STL_MAX_FACES = 200_000
#: MuJoCo refuses a mesh whose surface is under mjMINVAL, 1e-15 m^2; ten times that keeps
#: float32 rounding on the safe side.
MIN_AREA = 1e-14
#: The largest mesh file export reads (a binary STL this large is far past MuJoCo's limit).
MAX_EXPORT_MESH_BYTES = 512 * 1024 * 1024
#: The largest float32: MuJoCo reads vertices as floats, so a larger coordinate is infinite.
FLOAT32_MAX = 3.4028234663852886e38


@dataclass
class MeshAsset:
    """One mesh file as it will be written into the assets folder.

    Attributes:
        data: The source file to copy byte for byte, or the bytes of a converted file.
        suffix: ``.stl`` or ``.obj``: what MuJoCo will read it as.
        digest: The SHA-256 of the bytes written (hex).
        vertices, faces: What MuJoCo will read (unscaled), for the checks of each use.
        converted: What was done to it, for the note ("" for a copy).
    """

    data: bytes | Path
    suffix: str
    digest: str
    vertices: Any
    faces: Any
    converted: str = ""


def mesh_asset(path: Path) -> MeshAsset | str:
    """The file to write for the mesh at ``path``, or why MuJoCo can have none of it."""
    import numpy as np

    from urdfkit.core.errors import InputError
    from urdfkit.model.xmlio import read_regular
    from urdfkit.sources.meshes import obj_normals_complete, parse_mesh

    try:
        data = read_regular(path, limit=MAX_EXPORT_MESH_BYTES, kind="mesh")
    except InputError as e:
        return f"urdfkit cannot read it ({e.message})"
    suffix = path.suffix.lower()
    parsed = parse_mesh(data, suffix, path)
    if parsed is None or len(parsed[1]) == 0:
        return "urdfkit's readers found no triangles in it"
    vertices, faces = np.asarray(parsed[0], dtype=float), np.asarray(parsed[1])
    sound = _sound(vertices, faces)
    if not sound.any():
        return (f"none of its {len(faces)} triangle(s) has finite vertices (as MuJoCo's floats) "
                "and vertex indices in range")
    binary = suffix == ".stl" and 84 + 50 * _stl_count(data) == len(data)
    # vertices no triangle uses: PyBullet's collision hull leaves them out, MuJoCo's takes
    # them (an OBJ cube with one stray vertex at 5 5 5: PyBullet's box 0.5, MuJoCo's 5)
    stray = len(vertices) - len(np.unique(faces[sound]))
    copy = bool(sound.all()) and not stray and (
        (binary and len(faces) <= STL_MAX_FACES)
        or (suffix == ".obj" and obj_normals_complete(data)))
    if copy:
        return MeshAsset(path, suffix, hashlib.sha256(data).hexdigest(), vertices, faces)
    why = _why_converted(suffix, binary, len(faces), int(sound.sum()), data, stray)
    used = faces[sound]
    keep = np.unique(used)
    vertices, faces = vertices[keep], np.searchsorted(keep, used)
    out, out_suffix = ((_binary_stl(vertices, faces), ".stl") if len(faces) <= STL_MAX_FACES
                       else (_obj(vertices, faces), ".obj"))
    return MeshAsset(out, out_suffix, hashlib.sha256(out).hexdigest(), vertices, faces,
                     f"{why}; written as {'binary STL' if out_suffix == '.stl' else 'OBJ'}"
                     + (f" ({len(faces)} faces: MuJoCo reads at most {STL_MAX_FACES} from an "
                        "STL, any number from an OBJ)" if out_suffix == ".obj" else ""))


def _stl_count(data: bytes) -> int:
    return struct.unpack_from("<I", data, 80)[0] if len(data) >= 84 else -1


def _sound(vertices: Any, faces: Any) -> Any:
    """Per triangle: every index in range, every vertex finite as a float."""
    import numpy as np

    finite = (np.abs(vertices) <= FLOAT32_MAX).all(axis=1)  # NaN compares False
    inside = ((faces >= 0) & (faces < len(vertices))).all(axis=1)
    ok = inside.copy()
    ok[inside] = finite[faces[inside]].all(axis=1)
    return ok


def _why_converted(suffix: str, binary: bool, faces: int, sound: int, data: bytes,
                   stray: int = 0) -> str:
    """Why a mesh is not copied as it is (the start of its note)."""
    from urdfkit.sources.meshes import obj_normals_complete

    reasons = []
    if suffix == ".stl" and not binary:
        reasons.append("ASCII STL, which MuJoCo does not read")
    elif suffix == ".dae":
        reasons.append("COLLADA, which MuJoCo does not read (materials and UVs dropped)")
    if sound < faces:
        reasons.append(f"{faces - sound} of its {faces} triangles have a vertex that is not "
                       "finite (as MuJoCo's floats) or an index out of range; removed")
    if suffix == ".obj" and sound == faces and not obj_normals_complete(data):
        reasons.append("an OBJ whose faces do not all name one of its normals, which MuJoCo "
                       "refuses; normals and UVs dropped (MuJoCo computes its own normals)")
    if stray and suffix != ".dae":
        reasons.append(f"{stray} vertices no triangle uses, which MuJoCo's collision hull "
                       "would take and PyBullet's does not; left out")
    if binary and faces > STL_MAX_FACES:
        reasons.append(f"a binary STL of {faces} faces, over the {STL_MAX_FACES} MuJoCo reads "
                       "from one")
    return "; ".join(reasons) or "converted"


def _binary_stl(vertices: Any, faces: Any) -> bytes:
    """Triangles as binary STL (float32, the facet normals computed)."""
    import numpy as np

    tri = vertices[faces]
    normals = np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0])
    lengths = np.linalg.norm(normals, axis=1)
    normals = normals / np.where(lengths > 0, lengths, 1.0)[:, None]
    rec = np.zeros(len(tri), dtype=np.dtype([("n", "<f4", 3), ("v", "<f4", (3, 3)),
                                              ("a", "<u2")]))
    rec["n"] = normals
    rec["v"] = tri
    header = b"urdfkit export: converted mesh".ljust(80, b" ")
    return header + struct.pack("<I", len(rec)) + rec.tobytes()


def _obj(vertices: Any, faces: Any) -> bytes:
    """Triangles as OBJ text, every coordinate as the double it is (``%.17g``)."""
    import io

    import numpy as np

    out = io.BytesIO()
    out.write(b"# urdfkit export: converted mesh\n")
    np.savetxt(out, vertices, fmt="v %.17g %.17g %.17g")
    np.savetxt(out, faces + 1, fmt="f %d %d %d")
    return out.getvalue()


def unusable(asset: MeshAsset, scale: tuple[float, float, float], collides: bool) -> str | None:
    """Why MuJoCo refuses the mesh in a geom at ``scale`` (colliding or not), or None."""
    import numpy as np

    if len(asset.vertices) < 4:  # as MuJoCo counts them: an OBJ's v lines, an STL's corners
        return "it has fewer than 4 vertices (MuJoCo: \"at least 4 vertices required\")"
    points = asset.vertices * np.asarray(scale, dtype=float)
    tri = points[asset.faces]
    area = 0.5 * float(np.linalg.norm(np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0]),
                                      axis=1).sum())
    if not area >= MIN_AREA:
        return (f"its surface is {area:.3g} m^2 at scale {' '.join(map(repr, scale))} (MuJoCo "
                "refuses under 1e-15: \"mesh surface area is too small\")")
    if collides:
        from urdfkit.sources.hull import spans_volume

        if not spans_volume(points):
            return ("its vertices span no volume (flat), so MuJoCo cannot build the convex hull "
                    "it collides with")
    return None
