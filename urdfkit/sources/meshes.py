"""Mass properties of mesh files, for the mesh-aware physics checks (no trimesh needed).

About half of the links of real robots collide only through meshes. :func:`read_integrals`
reads an STL (binary or ASCII), OBJ or COLLADA (.dae) file, placed as PyBullet places it, and
integrates it by the signed-tetrahedron method (each triangle with the origin spans a
tetrahedron; summed with signs, they give the closed solid's integrals). It also says whether
the surface is closed (every edge shared by exactly two triangles), since a mesh with holes
has no meaningful volume.

Reading and integrating a mesh costs far more than checking the URDF that names it, so the
integrals are kept, unscaled, in urdfkit's cache (:mod:`urdfkit.sources.cache`), keyed by
the file's absolute path, size, modification time and inode: a second ``check`` of the same
robots reads no mesh. :func:`urdfkit.sources.meshstore.properties` is the lookup the rules
call (memory, the cache, the run's pack, and this module on a miss); any ``<mesh scale>`` is
applied to the integrals in closed form (:meth:`~urdfkit.sources.meshdata.Integrals.scaled`).
"""

from __future__ import annotations

import math
import os
import re
import struct
from pathlib import Path
from typing import Any

from urdfkit.core import deps
from urdfkit.core.errors import InputError
from urdfkit.model.spec import axis_angle_matrix
from urdfkit.sources.meshdata import MAX_MESH_BYTES, Integrals


def read_integrals(path: Path, suffix: str | None = None, *,
                   concavity: bool = True) -> Integrals | None:
    """Read a mesh and integrate it (no cache); None if unreadable, unsupported or empty.

    ``concavity`` False leaves the concavity depth NaN.
    """
    mesh = _read_mesh(path, suffix)
    if mesh is None:
        return None
    vertices, faces, starts = mesh
    return _solid(vertices, faces, starts, concavity=concavity)


def _read_mesh(path: Path, suffix: str | None = None) -> tuple[Any, Any, list[int]] | None:
    """A mesh's vertices, triangles and (OBJ) piece starts, as PyBullet places them.

    None if unreadable, unsupported, empty or out of range.
    """
    import numpy as np

    from urdfkit.model.xmlio import read_regular

    suffix = (suffix or path.suffix).lower()
    try:  # a FIFO or device named like a mesh must not hang or fill memory
        data = read_regular(path, limit=MAX_MESH_BYTES, kind="mesh")
    except InputError:
        return None
    parsed = parse_mesh(data, suffix, path)
    if parsed is None:
        return None
    vertices, faces, starts = parsed
    if (len(faces) == 0 or len(vertices) == 0 or faces.min() < 0
            or faces.max() >= len(vertices) or not np.isfinite(vertices).all()):
        return None
    return vertices, faces, starts


def parse_mesh(data: bytes, suffix: str, path: Path) -> tuple[Any, Any, list[int]] | None:
    """A mesh file's bytes as vertices, triangles and (OBJ) piece starts, unchecked.

    Placed as PyBullet places them, as :func:`read_triangles`, but as written: vertices may
    be non-finite and vertex indices out of range (``urdfkit export`` keeps the triangles
    that are sound). ``path`` names a COLLADA file's folder. None if unsupported or not
    parsable at all.
    """
    starts: list[int] = []
    try:
        if suffix == ".stl":
            vertices, faces = _stl(data)
        elif suffix == ".obj":
            vertices, faces, starts = _obj(data)
        elif suffix == ".dae":
            vertices, faces = _dae(data, path)
        else:
            return None
    except (ValueError, struct.error, IndexError, OverflowError, KeyError, InputError,
            AttributeError, StopIteration, TypeError):
        return None
    if vertices is None or faces is None:
        return None
    return vertices, faces, starts


#: A ``vn`` line of an OBJ, and the normal index of a face vertex (``v/vt/vn`` or ``v//vn``).
_OBJ_VN = re.compile(rb"\nvn[ \t]")
_OBJ_NORMAL_REF = re.compile(rb"[ \t]-?\d+/-?\d*/(-?\d+)")


def obj_normals_complete(data: bytes) -> bool:
    """Whether every face vertex of an OBJ that has ``vn`` lines names one of them.

    MuJoCo 4.0 refuses an OBJ with normals and a face vertex without one, or one out of
    range ("mesh_facenormal normal index out of bounds"; measured), which PyBullet and the
    OBJ format allow.
    """
    import numpy as np

    data = b"\n" + data
    count = len(_OBJ_VN.findall(data))
    if not count:
        return True
    flines = _OBJ_F.findall(data)
    text = b"".join(b" " + line + b" \n" for line in flines)
    refs = _OBJ_NORMAL_REF.findall(text)
    if len(refs) != int(_words_per_line(b"\n".join(flines), len(flines)).sum()):
        return False
    index = np.array(refs, dtype=np.int64)
    return bool((((index >= 1) & (index <= count)) | ((index < 0) & (index >= -count))).all())


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

    # Rows compared by their bits (+ 0.0 makes -0.0 the same vertex as 0.0), grouped by one
    # lexsort of three integer keys: 6x faster than np.unique(axis=0) on 28,000 vertices.
    c = np.ascontiguousarray(corners + 0.0)
    bits = c.view(np.uint64)
    order = np.lexsort((bits[:, 2], bits[:, 1], bits[:, 0]))
    ranked = bits[order]
    new = np.ones(len(ranked), dtype=bool)
    new[1:] = (ranked[1:] != ranked[:-1]).any(axis=1)
    index = np.empty(len(ranked), dtype=np.int64)
    index[order] = np.cumsum(new) - 1
    return c[order[new]], index.reshape(-1, 3)


#: "7/3/2" -> "7": texture and normal indices go.
_OBJ_INDEX_TAIL = re.compile(rb"/\S*")
#: The text after each keyword at a line's start (the data gets a leading newline, so every
#: pattern starts with a literal the regex engine searches for fast): vertex positions,
#: faces, object starts.
_OBJ_V = re.compile(rb"\nv[ \t]([^\r\n]*)")
_OBJ_F = re.compile(rb"\nf[ \t]([^\r\n]*)")
_OBJ_FACE = re.compile(rb"\nf[ \t]")
_OBJ_OBJECT = re.compile(rb"\n[og][ \t]")


def _numbers(lines: list[bytes], dtype: Any, per_line: int) -> Any:
    """The numbers of each line (the text after its keyword), ``per_line`` of them per line.

    The common case (every line holds exactly ``per_line`` words) is parsed in one C call;
    anything else raises ValueError, for the caller to read line by line. Lines are counted
    one by one (in numpy): "v 1 2" beside "v 3 4 5 6" is two bad lines, not two vertices.
    """
    import warnings

    import numpy as np

    text = b"\n".join(lines)
    if not (_words_per_line(text, len(lines)) == per_line).all():
        raise ValueError("irregular")
    if dtype is not float and b"/" in text:
        text = _OBJ_INDEX_TAIL.sub(b"", text)
    with warnings.catch_warnings():  # numpy warns when it stops early: counted below
        warnings.simplefilter("ignore", DeprecationWarning)
        values = np.fromstring(text, dtype=dtype, sep=" ")
    if values.size == per_line * len(lines):
        return values.reshape(-1, per_line)
    raise ValueError("irregular")


def _words_per_line(text: bytes, lines: int) -> Any:
    """How many words (as ``bytes.split`` finds them) each newline-separated line holds."""
    import numpy as np

    if not _SPACE:
        _SPACE.append(_space_table())
    chars = np.frombuffer(text, dtype=np.uint8)
    space = _SPACE[0][chars]
    word = ~space
    word[1:] &= space[:-1]  # a word starts after a space, or at the start
    line = np.searchsorted(np.flatnonzero(chars == 10), np.flatnonzero(word))
    return np.bincount(line, minlength=lines)


_SPACE: list[Any] = []  # the table below, made on first use (numpy loads lazily)


def _space_table() -> Any:
    import numpy as np

    table = np.zeros(256, dtype=bool)
    table[list(b" \t\n\r\x0b\x0c")] = True
    return table


def _obj(data: bytes) -> tuple[Any, Any, list[int]]:
    """Vertices, triangles, and the first triangle of each ``o``/``g`` object after the first.

    PyBullet collides with one convex hull per object of an OBJ (a V-HACD decomposition is
    many convex objects in one file), so the objects matter to the concavity test. Lines are
    found by regular expressions and their numbers parsed by numpy, so no Python runs per
    line in the common case (triangles); polygons are cut into fans with array arithmetic.
    """
    import numpy as np

    data = b"\n" + data
    vlines = _OBJ_V.findall(data)
    flines = _OBJ_F.findall(data)
    starts: list[int] = []  # f-line index where each object after the first begins
    objects = [m.start() for m in _OBJ_OBJECT.finditer(data)]
    first_face = _OBJ_FACE.search(data) if objects and flines else None
    if first_face is not None and objects[-1] > first_face.start():  # objects after faces
        face_at = np.array([m.start() for m in _OBJ_FACE.finditer(data)])
        for before in np.searchsorted(face_at, objects).tolist():
            if before and (not starts or starts[-1] != before):
                starts.append(before)
    try:
        vertices = _numbers(vlines, float, 3)
    except ValueError:  # "v x y z w" or "v x y z r g b": the first three are the position
        vertices = np.array([[float(x) for x in ln.split()[:3]] for ln in vlines],
                            dtype=float).reshape(-1, 3)
    count = len(vertices)
    try:
        tri = _numbers(flines, np.int64, 3)
    except ValueError:  # polygons: fans of triangles (object starts move to triangle counts)
        tri, first_triangle = _fans(flines)
        starts = [int(first_triangle[i]) for i in starts]
    # 1-based; negative counts from the end
    return vertices, np.where(tri > 0, tri - 1, count + tri), starts


def _fans(flines: list[bytes]) -> tuple[Any, Any]:
    """Polygons as fans of triangles ``(p0, pk, pk+1)``, and each line's first triangle."""
    import warnings

    import numpy as np

    text = b"\n".join(flines)
    sizes = _words_per_line(text, len(flines)).astype(np.int64)
    with warnings.catch_warnings():  # numpy warns when it stops early: counted below
        warnings.simplefilter("ignore", DeprecationWarning)
        flat = np.fromstring(_OBJ_INDEX_TAIL.sub(b"", text), dtype=np.int64, sep=" ")
    if len(flat) != int(sizes.sum()):
        raise ValueError("irregular")
    per_line = np.maximum(sizes - 2, 0)
    first_triangle = np.concatenate([[0], np.cumsum(per_line)])
    total = int(first_triangle[-1])
    line = np.repeat(np.arange(len(flines)), per_line)
    k = np.arange(total) - first_triangle[:-1][line] + 1
    at = (np.cumsum(sizes) - sizes)[line]
    tri = np.stack([flat[at], flat[at + k], flat[at + k + 1]], axis=1) if total else \
        np.zeros((0, 3), dtype=np.int64)
    return tri, first_triangle


def _dae(data: bytes, path: Path) -> tuple[Any, Any]:
    """Vertices and triangles of a COLLADA file, placed as PyBullet places them.

    As PyBullet 3.2.7 reads it for collision: every ``<instance_geometry>`` of the scene's
    visual scene, moved by its nodes' transforms (read PyBullet's way, see
    :meth:`_Collada.local`), then scaled by ``<unit meter>``; ``<up_axis>`` is not applied.
    Checked against PyBullet's getAABB of the same meshes in tests/test_meshes.py. Triangles,
    polylists and polygons are read (fans for polygons); a geometry in any other primitive
    (strips) makes the whole mesh unreadable rather than wrong. All one solid: PyBullet makes
    one hull.
    """
    import numpy as np

    doc = _Collada(data, path)
    scene_ref = doc.root.find("{*}scene/{*}instance_visual_scene")
    if scene_ref is not None:
        for node in doc.ref(scene_ref.get("url")).iterfind("{*}node"):
            doc.walk(node, np.eye(4), 0)
    unit = doc.root.find("{*}asset/{*}unit")
    world = np.eye(4) * float(unit.get("meter", "1") if unit is not None else 1.0)
    world[3, 3] = 1.0
    all_points, all_faces, count = [], [], 0
    for transform, geom in doc.placed:
        points, faces = doc.geometry(geom)
        m = world @ transform
        all_points.append(points @ m[:3, :3].T + m[:3, 3])
        all_faces.append(faces + count)
        count += len(points)
    if not all_points:
        raise ValueError("no geometry")
    return np.concatenate(all_points), np.concatenate(all_faces)


class _Collada:
    """One COLLADA document, read the way PyBullet reads it (see :func:`_dae`)."""

    def __init__(self, data: bytes, path: Path) -> None:
        from urdfkit.model.xmlio import parse_xml

        self.root = parse_xml(data, path).getroot()
        self.by_id = {el.get("id"): el for el in self.root.iter() if el.get("id")}
        #: (world transform, <geometry>) of every instance_geometry met by :meth:`walk`.
        self.placed: list[tuple[Any, Any]] = []

    def ref(self, url: str | None) -> Any:
        """The element a ``#id`` URL points at."""
        return self.by_id[(url or "").lstrip("#")]

    @staticmethod
    def numbers(el: Any, dtype: Any = float) -> Any:
        """An element's text as a flat array."""
        import numpy as np

        return np.array((el.text or "").split(), dtype=dtype)

    def geometry(self, geom: Any) -> tuple[Any, Any]:
        """A ``<geometry>``'s points and triangles (vertex indices)."""
        import numpy as np

        mesh = geom.find("{*}mesh")
        if mesh is None:
            raise ValueError("not a mesh")
        verts = mesh.find("{*}vertices")
        position = next(i for i in verts.iterfind("{*}input") if i.get("semantic") == "POSITION")
        # a source of this <mesh> first: files exported geometry by geometry repeat the same
        # ids in each (jaxon's LLEG_LINK3.dae: eight "geo0.positions"), and PyBullet reads each
        # geometry's own; the document's last one put every geometry on one part's points
        wanted = (position.get("source") or "").lstrip("#")
        source = next((el for el in mesh.iterfind("{*}source") if el.get("id") == wanted),
                      None)
        if source is None:
            source = self.ref(position.get("source"))
        accessor = source.find("{*}technique_common/{*}accessor")
        stride = int(accessor.get("stride", "3")) if accessor is not None else 3
        points = self.numbers(source.find("{*}float_array")).reshape(-1, stride)[:, :3]
        tris: list[Any] = []
        for prim in mesh:
            tag = etree_local(prim.tag)
            if tag in ("source", "vertices", "extra", "lines", "linestrips"):
                continue  # edges hold no faces (PyBullet skips them too)
            if tag not in ("triangles", "polylist", "polygons"):
                raise ValueError(f"COLLADA <{tag}> is not read")
            tris += self.triangles(prim, tag)
        faces = np.concatenate(tris).astype(np.int64) if tris else np.zeros((0, 3), np.int64)
        return points, faces

    def triangles(self, prim: Any, tag: str) -> list[Any]:
        """The triangles of one ``<triangles>``, ``<polylist>`` or ``<polygons>`` (fans)."""
        import numpy as np

        inputs = prim.findall("{*}input")
        width = max(int(i.get("offset", "0")) for i in inputs) + 1
        at = next(int(i.get("offset", "0")) for i in inputs if i.get("semantic") == "VERTEX")
        polys = [self.numbers(p_, np.int64).reshape(-1, width)[:, at]
                 for p_ in prim.iterfind("{*}p")]
        if tag == "triangles":
            return [np.concatenate(polys).reshape(-1, 3) if polys else np.zeros((0, 3))]
        if tag == "polylist":
            counts = self.numbers(prim.find("{*}vcount"), np.int64)
            polys = np.split(polys[0], np.cumsum(counts)[:-1]) if polys else []
        return [np.array([[poly[0], poly[k], poly[k + 1]]])
                for poly in polys for k in range(1, len(poly) - 1)]

    def local(self, node: Any) -> Any:
        """A node's own transform, as PyBullet reads it.

        PyBullet reads only the first <matrix>, <translate>, <scale> and <rotate> of a node
        (its loop steps to the node's sibling, not the element's), and composes them in that
        order whatever the file's order: a second <rotate> is ignored (measured).
        """
        import numpy as np

        m = np.eye(4)
        for kind in ("matrix", "translate", "scale", "rotate"):
            t = node.find("{*}" + kind)
            if t is None or not (t.text or "").strip():
                continue
            step = np.eye(4)
            if kind == "matrix":
                step = self.numbers(t).reshape(4, 4)
            elif kind == "translate":
                step[:3, 3] = self.numbers(t)[:3]
            elif kind == "scale":
                step = np.diag([*self.numbers(t)[:3], 1.0])
            else:
                x, y, z, deg = self.numbers(t)[:4]
                step[:3, :3] = axis_angle_matrix((x, y, z), math.radians(deg))
            m = m @ step
        return m

    def walk(self, node: Any, above: Any, depth: int) -> None:
        """Collect the node's geometry instances and its children's, with their transforms."""
        if depth > 64:
            raise ValueError("nodes nested too deep")
        here = above @ self.local(node)
        self.placed.extend((here, self.ref(g.get("url")))
                           for g in node.iterfind("{*}instance_geometry"))
        for child in node.iterfind("{*}node"):  # (<instance_node> is not read by PyBullet)
            self.walk(child, here, depth + 1)


def etree_local(tag: Any) -> str:
    """A tag without its namespace ("" for comments)."""
    return tag.rsplit("}", 1)[-1] if isinstance(tag, str) else ""


#: Vertex-by-plane tests per piece for the concavity depth; bigger pieces test a sample of
#: their triangles' planes (a concave mesh has many planes with vertices in front).
_CONCAVITY_BUDGET = 4_000_000
#: A triangle thinner than this fraction of its piece's size has no plane to judge by: its
#: corners' rounding tilts it, and the tilt grows over the piece. Measured: GP4's sliver
#: triangles (~2e-8 m^2 on 20-30 cm links) put convex meshes 0.023-0.18 m "in front".
SLIVER_FRACTION = 1e-3
#: Triangles beyond this many are not re-wound (a Python walk over their edges).
_WIND_TRIANGLES = 400_000


def _concavity(vertices: Any, faces: Any, starts: list[int], det: Any,
               closed: bool = True) -> float:
    """Largest distance of a vertex in front of a triangle's plane, within each piece.

    Robust to what CAD exports leave in convex meshes: sliver triangles (thinner than
    :data:`SLIVER_FRACTION` of the piece, whose planes are noise) test nothing, and when a
    piece still looks concave its triangles are re-wound consistently (:func:`_wound`) and
    the depth measured again, since one triangle wound backwards puts every vertex "in front"
    of it. ``det`` is each triangle's signed-volume term (6 x its tetrahedron with the
    origin), whose sum per piece says which side of its triangles is out.

    An open mesh (``closed`` False) has no inside to say which side is out: each plane is
    judged by the smaller of how far the piece reaches on its two sides, which is 0 for every
    plane exactly when the piece is convex, whatever the winding.
    """
    worst = 0.0
    bounds = [0, *starts, len(faces)]
    for lo, hi in zip(bounds, bounds[1:], strict=False):
        if hi - lo < 4:
            continue
        depth = _piece_depth(vertices, faces[lo:hi], det[lo:hi], closed)
        if closed and depth > 0 and hi - lo <= _WIND_TRIANGLES:
            wound = _wound(faces[lo:hi])
            piece = faces[lo:hi] if wound is None else wound
            a, b, c = vertices[piece.T]
            piece_det = _det(a, b, c)
            if wound is not None:
                depth = min(depth, _piece_depth(vertices, wound, piece_det))
            if depth > 0 and _fills_hull(vertices, piece, piece_det, CONVEX_FILL):
                depth = 0.0  # its faces' planes say dips, its volume says none to speak of
        worst = max(worst, depth)
    return worst


#: A closed piece filling at least this much of its convex hull is convex enough: the hull
#: adds under 5% (GP4's convex links fill 99.8-100%, its open link_2_l 63%).
CONVEX_FILL = 0.95
#: Sample points and hull directions for :func:`_fills_hull`.
_FILL_SAMPLES = 6_000
_FILL_DIRECTIONS = 1024


def _fills_hull(vertices: Any, faces: Any, det: Any, fill: float) -> bool:
    """Whether a closed piece fills at least ``fill`` of its convex hull (volume over hull).

    The hull is bounded by the piece's support planes along every triangle's normal, both
    ways (so winding does not matter) and along the axes: exactly the hull for a convex
    piece, a little more for a curved or concave one (so the fill errs low, never high for a
    concave piece). Its volume is counted on a fixed grid of sample points in the bounding
    box (deterministic; about 0.5% spread). Sliver normals do no harm: a support plane along
    any direction holds the whole hull.

    Each block of planes only drops points, so the fill it implies only grows: once it reaches
    ``fill`` the answer is yes, and the remaining blocks (most of the cost for a convex piece,
    whose inside points survive them all) are skipped. The verdict is the full count's.
    """
    import numpy as np

    used = vertices[np.flatnonzero(np.bincount(faces.ravel(), minlength=len(vertices)))]
    low, high = used.min(axis=0), used.max(axis=0)
    box = float(np.prod(high - low))
    volume = abs(float(det.sum())) / 6.0
    if not box > 0 or not volume > 0:
        return True
    a, b, c = vertices[faces.T]
    normal = np.cross(b - a, c - a)
    length = np.linalg.norm(normal, axis=1)
    order = np.argsort(-length)[:_FILL_DIRECTIONS]  # the largest triangles first
    normal = normal[order][length[order] > 0] / length[order][length[order] > 0, None]
    directions = np.vstack([normal, -normal, np.eye(3), -np.eye(3)])
    support = (used @ directions.T).max(axis=0)
    points = low + (high - low) * np.random.default_rng(0).random((_FILL_SAMPLES, 3))
    # Axes and the largest faces first: most points outside are dropped by the first blocks.
    directions = np.vstack([directions[-6:], directions[:-6]])
    support = np.concatenate([support[-6:], support[:-6]])
    for start in range(0, len(directions), 64):  # bounded temporaries, shrinking
        block = directions[start:start + 64]
        points = points[(points @ block.T <= support[start:start + 64]).all(axis=1)]
        if not len(points) or volume >= fill * box * len(points) / _FILL_SAMPLES:
            return True  # no point left: a hull of no counted volume, filled
    return volume >= fill * box * len(points) / _FILL_SAMPLES


def _det(a: Any, b: Any, c: Any) -> Any:
    """6 x the signed volume of each tetrahedron (origin, a, b, c)."""
    import numpy as np

    return np.einsum("ij,ij->i", a, np.cross(b, c))


def _piece_depth(vertices: Any, faces: Any, det: Any, sided: bool = True) -> float:
    """How far the piece's vertices stand in front of its (non-sliver) triangles' planes.

    ``sided`` False (an open piece): in front of or behind, whichever reaches less far.
    """
    import numpy as np

    a, b, c = vertices[faces.T]
    normal = np.cross(b - a, c - a)
    area2 = np.linalg.norm(normal, axis=1)  # twice each triangle's area
    points = vertices[np.flatnonzero(np.bincount(faces.ravel(), minlength=len(vertices)))]
    size = float((points.max(axis=0) - points.min(axis=0)).max())
    longest = np.sqrt(np.maximum(np.maximum(((b - a) ** 2).sum(1), ((c - b) ** 2).sum(1)),
                                 ((a - c) ** 2).sum(1)))
    # The triangle's smallest height (2 area / longest edge); slivers and degenerate ones out.
    keep = area2 > SLIVER_FRACTION * size * np.maximum(longest, 1e-300)
    if not keep.any():
        return 0.0
    inward = det.sum() < 0  # inward triangles: out is the other side
    normal = normal[keep] / area2[keep, None]
    offset = np.einsum("ij,ij->i", normal, a[keep])
    step = max(1, -(-len(normal) * len(points) // _CONCAVITY_BUDGET))
    height = points @ normal[::step].T  # one (points x planes) array, no temporaries:
    height -= offset[::step]  # in place, and the side picked by min or max
    if not sided:
        return max(0.0, float(np.minimum(height.max(axis=0), -height.min(axis=0)).max()))
    return max(0.0, -float(height.min()) if inward else float(height.max()))


def _wound(faces: Any) -> Any:
    """``faces`` with every triangle wound as its neighbours are, or None if they already are.

    Two triangles sharing an edge agree when they run along it in opposite directions. A
    walk over shared edges (each edge in exactly two triangles; others do not join) flips
    the triangles that disagree with the one they were reached from; each connected part
    then keeps the winding most of its triangles had.
    """
    import numpy as np

    n = len(faces)
    u = faces[:, [0, 1, 2]].ravel().astype(np.int64)
    v = faces[:, [1, 2, 0]].ravel().astype(np.int64)
    owner = np.repeat(np.arange(n), 3)
    big = int(max(u.max(), v.max())) + 1
    key = np.minimum(u, v) * big + np.maximum(u, v)
    order = np.argsort(key, kind="stable")
    k = key[order]
    first = np.flatnonzero((k[1:] == k[:-1])
                           & np.r_[True, k[1:-1] != k[:-2]]
                           & np.r_[k[2:] != k[1:-1], True])  # edges in exactly two triangles
    if len(first) == 0:
        return None
    i, j = order[first], order[first + 1]
    fa, fb = owner[i], owner[j]
    same = (u[i] < v[i]) == (u[j] < v[j])  # the same direction: the two disagree
    if not same.any():
        return None
    neighbours: list[list[tuple[int, bool]]] = [[] for _ in range(n)]
    for x, y, flip in zip(fa.tolist(), fb.tolist(), same.tolist(), strict=True):
        neighbours[x].append((y, flip))
        neighbours[y].append((x, flip))
    parity = [-1] * n
    flipped = np.zeros(n, dtype=bool)
    for seed in range(n):
        if parity[seed] >= 0:
            continue
        parity[seed] = 0
        part, stack = [seed], [seed]
        while stack:
            f = stack.pop()
            for g, flip in neighbours[f]:
                if parity[g] < 0:
                    parity[g] = parity[f] ^ flip
                    part.append(g)
                    stack.append(g)
        odd = [f for f in part if parity[f]]
        if 2 * len(odd) <= len(part):  # the majority's winding stays
            flipped[odd] = True
        else:
            flipped[[f for f in part if not parity[f]]] = True
    out = faces.copy()
    out[flipped] = out[flipped][:, ::-1]
    return out


#: Vertices closer than this fraction of a mesh's size are one point for the closed test: STL
#: stores float32 (7 digits), and CAD exports leave the two sides of a seam a rounding step
#: apart (fetch_description's laser_link.STL: two corners 9.3e-10 m apart on a 7.5 cm part).
CRACK_FRACTION = 1e-6
#: Open-edge vertices beyond this many are not compared (a mesh with real holes, not a seam).
_CRACK_VERTICES = 20000
#: How far along the sorted open-edge vertices a partner is looked for.
_CRACK_AHEAD = 16


def _closed(faces: Any) -> bool:
    """Every undirected edge in exactly two triangles.

    Sorted corners give each edge one int64 key; sorted keys must then come in equal pairs,
    each pair unlike the next.
    """
    import numpy as np

    e = np.sort(faces, axis=1).astype(np.int64)
    n = int(e[:, 2].max()) + 1
    keys = np.sort(np.concatenate([e[:, 0] * n + e[:, 1], e[:, 1] * n + e[:, 2],
                                   e[:, 0] * n + e[:, 2]]))
    return bool(len(keys) % 2 == 0 and (keys[0::2] == keys[1::2]).all()
                and (keys[2::2] != keys[1:-1:2]).all())


def _weld_cracks(vertices: Any, faces: Any, tolerance: float) -> Any:
    """``faces`` with the vertices of open edges that lie within ``tolerance`` made one.

    Only vertices on edges not shared by exactly two triangles are compared; triangles that
    the merge collapses are dropped. None when there
    are too many such vertices, or none within reach of another.
    """
    import numpy as np

    e = np.sort(faces, axis=1).astype(np.int64)
    n = int(e[:, 2].max()) + 1
    keys, counts = np.unique(np.concatenate([e[:, 0] * n + e[:, 1], e[:, 1] * n + e[:, 2],
                                             e[:, 0] * n + e[:, 2]]), return_counts=True)
    open_edges = keys[counts != 2]
    loose = np.unique(np.concatenate([open_edges // n, open_edges % n]))
    if len(loose) < 2 or len(loose) > _CRACK_VERTICES or not tolerance > 0:
        return None
    p = vertices[loose]
    # Pairs within reach, found in (x, y, z) order: a vertex's partner is among the next few
    # (less than ``tolerance`` further along x); each offset is one vectorised step, and at
    # most _CRACK_AHEAD of them are looked at (a pair further apart in that order stays open).
    order = np.lexsort((p[:, 2], p[:, 1], p[:, 0]))
    q = p[order]
    target = np.arange(len(q))  # each sorted vertex's partner, the first one within reach
    for k in range(1, min(len(q), _CRACK_AHEAD + 1)):
        ahead = q[k:, 0] - q[:-k, 0] <= tolerance
        if not ahead.any():
            break
        close = ahead & (((q[k:] - q[:-k]) ** 2).sum(axis=1) <= tolerance * tolerance)
        later = np.nonzero(close)[0] + k
        target[later] = np.minimum(target[later], target[later - k])
    if (target == np.arange(len(q))).all():
        return None
    mapping = np.arange(len(vertices))
    mapping[loose[order]] = loose[order[target]]
    welded = mapping[faces]
    keep = (welded[:, 0] != welded[:, 1]) & (welded[:, 1] != welded[:, 2]) & \
        (welded[:, 0] != welded[:, 2])
    return welded[keep] if keep.any() else None


def _solid(vertices: Any, faces: Any, starts: list[int] | None = None, *,
           concavity: bool = True) -> Integrals:
    import numpy as np

    p = vertices[faces.T]  # (corner, triangle, xyz)
    a, b, c = p
    det = np.einsum("ij,ij->i", a, np.cross(b, c))  # 6 x signed tetrahedron volumes
    s = a + b + c
    # Second moments of each tetrahedron (origin, a, b, c): (aa' + bb' + cc' + ss') det / 120.
    q = p.transpose(2, 0, 1).reshape(3, -1)
    second = ((q * np.tile(det, 3)) @ q.T + (s.T * det) @ s) / 120.0
    first = s.T @ det / 24.0
    used = np.zeros(len(vertices), dtype=bool)
    used[faces.ravel()] = True
    corners = vertices[used]
    low, high = corners.min(axis=0), corners.max(axis=0)
    closed = _closed(faces)
    if not closed:  # a crack narrower than the file's own rounding is no hole
        welded = _weld_cracks(vertices, faces, CRACK_FRACTION * float((high - low).max()))
        closed = welded is not None and _closed(welded)
    starts = starts or []
    return Integrals(float(det.sum()) / 6.0, (float(first[0]), float(first[1]), float(first[2])),
                     (float(second[0, 0]), float(second[1, 1]), float(second[2, 2]),
                      float(second[0, 1]), float(second[0, 2]), float(second[1, 2])),
                     (float(low[0]), float(low[1]), float(low[2])),
                     (float(high[0]), float(high[1]), float(high[2])), closed, len(faces),
                     _concavity(vertices, faces, starts, det, closed) if concavity
                     else math.nan,
                     len(starts) + 1)


def read_triangles(path: Path) -> tuple[Any, Any] | None:
    """A mesh's vertices and triangles (vertex indices), placed as PyBullet places them.

    For converting a mesh MuJoCo cannot read (COLLADA) to one it can (``urdfkit export``):
    the same readers as :func:`read_integrals`. None if unreadable, unsupported or empty.
    """
    mesh = _read_mesh(path)
    return None if mesh is None else (mesh[0], mesh[1])


def undrawn_visual(path: Path | str) -> str | None:
    """Why PyBullet draws nothing or only part of a visual mesh file, or None.

    An empty file, and a COLLADA file whose visual scene places its geometry through
    ``<instance_node>`` (PyBullet 3.2.7 follows only ``<node>`` and ``<instance_geometry>``:
    "cannot extract anything useful from mesh", and nothing is drawn; measured with the
    TinyRenderer). Cheap on the common case: a file without ``<instance_node>`` that holds an
    ``<instance_geometry>`` is not parsed.
    """
    try:  # one answer per file version: a tree's robots share their meshes
        st = os.stat(path)
    except OSError:
        return None  # missing or unreadable: U701, U704, said by the references
    key = (os.fspath(path), *deps.version(st))
    if key not in _UNDRAWN:
        if len(_UNDRAWN) > 4096:
            _UNDRAWN.clear()
        _UNDRAWN[key] = _undrawn(path)
    return _UNDRAWN[key]


#: :func:`undrawn_visual`'s answers, by path and stat.
_UNDRAWN: dict[tuple[str, int, int, int, int], str | None] = {}


def _undrawn(path: Path | str) -> str | None:
    from urdfkit.model.xmlio import read_regular

    try:
        data = read_regular(Path(path), limit=MAX_MESH_BYTES, kind="mesh")
    except InputError:
        return None  # not regular, too big: U704, said by the references
    if not data.strip():
        return "is empty: PyBullet draws nothing of it"
    if mesh_kind(str(path)) != ".dae" or (
            b"instance_node" not in data and b"instance_geometry" in data):
        return None
    try:
        doc = _Collada(data, Path(path))
        scene_ref = doc.root.find("{*}scene/{*}instance_visual_scene")
        scene = doc.ref(scene_ref.get("url")) if scene_ref is not None else None
        drawn = total = 0
        if scene is not None:
            drawn = sum(_instances(doc, n, follow=False, depth=0)
                        for n in scene.iterfind("{*}node"))
            total = sum(_instances(doc, n, follow=True, depth=0)
                        for n in scene.iterfind("{*}node"))
    except (InputError, KeyError, ValueError, AttributeError):
        return None  # not COLLADA PyBullet reads at all: not this finding's to say
    if drawn == total and total > 0:
        return None
    if total == 0:
        return "places no geometry in its visual scene: PyBullet draws nothing of it"
    through = "placed through <instance_node>, which PyBullet does not follow"
    if drawn == 0:
        return f"has {total} part(s), all {through}: PyBullet draws nothing of it"
    return f"has {total} part(s); PyBullet draws {drawn} (the rest are {through})"


def mesh_kind(name: str) -> str:
    """A mesh file's suffix, lower case."""
    return os.path.splitext(name)[1].lower()


def _instances(doc: _Collada, node: Any, *, follow: bool, depth: int) -> int:
    """``<instance_geometry>`` under a node (through ``<instance_node>`` when ``follow``)."""
    if depth > 64:
        raise ValueError("nodes nested too deep")
    n = sum(1 for _ in node.iterfind("{*}instance_geometry"))
    kids = list(node.iterfind("{*}node"))
    if follow:
        kids += [doc.ref(i.get("url")) for i in node.iterfind("{*}instance_node")]
    return n + sum(_instances(doc, k, follow=follow, depth=depth + 1) for k in kids)
