"""Meshes made lighter for display: a convex hull without scipy, and vertex-clustering decimation.

For ``urdfkit view`` only: PyBullet keeps every triangle it loaded, and collides with a mesh's
convex hull; the page draws the hull, and a very large visual mesh with fewer triangles. Both
are plain numpy, so the viewer needs nothing beyond urdfkit's own dependencies.

- :func:`convex_hull`: quickhull (Barber, Dobkin and Huhdanpaa, 1996): start from a
  tetrahedron of extreme points, and repeatedly lift the face with points outside it to its
  farthest point, replacing every face that point sees by a fan over the horizon. Points
  within a relative tolerance of a face count as on it.
- :func:`decimate`: vertex clustering (Rossignac and Borrel, 1993): snap the vertices to a
  grid, merge those in one cell into their mean, drop the triangles that collapse. The shape
  keeps its outline to within one cell.
"""

from __future__ import annotations

from typing import Any

#: Points kept for a hull: more are thinned first by clustering on a grid (display only).
HULL_POINTS = 2000


def convex_hull(points: Any) -> tuple[Any, Any] | None:
    """``(vertices, faces)`` of the convex hull of 3-D ``points``, faces wound outward.

    None when the points span no volume (fewer than four, all on a plane or a line).
    """
    import numpy as np

    pts = np.unique(np.asarray(points, dtype=float).reshape(-1, 3), axis=0)
    if len(pts) > HULL_POINTS:
        pts = _cluster_points(pts, HULL_POINTS)
    if len(pts) < 4:
        return None
    scale = float(np.max(np.ptp(pts, axis=0))) or 1.0
    eps = 1e-9 * scale
    start = _tetrahedron(pts, eps)
    if start is None:
        return None
    inside = pts[list(start)].mean(axis=0)
    faces: dict[int, tuple[int, int, int]] = {}
    planes: dict[int, tuple[Any, float]] = {}
    outside: dict[int, Any] = {}
    edge_face: dict[tuple[int, int], int] = {}  # directed edge -> the face it bounds
    pending: list[int] = []  # faces that may have points outside
    counter = [0]

    def add_face(a: int, b: int, c: int, candidates: Any) -> None:
        normal = np.cross(pts[b] - pts[a], pts[c] - pts[a])
        norm = float(np.linalg.norm(normal))
        if norm == 0.0:
            return
        normal = normal / norm
        offset = float(normal @ pts[a])
        if normal @ inside - offset > 0:  # wind it outward
            b, c, normal, offset = c, b, -normal, -offset
        key = counter[0]
        counter[0] += 1
        faces[key] = (a, b, c)
        planes[key] = (normal, offset)
        for e in ((a, b), (b, c), (c, a)):
            edge_face[e] = key
        if len(candidates):
            d = pts[candidates] @ normal - offset
            outside[key] = candidates[d > eps]
        else:
            outside[key] = candidates
        if len(outside[key]):
            pending.append(key)

    everything = np.arange(len(pts))
    a, b, c, d = start
    for tri in ((a, b, c), (a, b, d), (a, c, d), (b, c, d)):
        add_face(*tri, everything)
    while pending:
        busy = pending.pop()
        if busy not in faces or not len(outside[busy]):
            continue
        normal, offset = planes[busy]
        cand = outside[busy]
        apex_point = pts[cand[np.argmax(pts[cand] @ normal - offset)]]
        apex = int(cand[np.argmax(pts[cand] @ normal - offset)])
        # The faces the apex sees form one patch around this one: walk it across edges.
        visible = {busy}
        stack = [busy]
        while stack:
            k = stack.pop()
            x, y, z = faces[k]
            for u, v in ((x, y), (y, z), (z, x)):
                other = edge_face.get((v, u))
                if other is None or other in visible:
                    continue
                n, o = planes[other]
                if float(n @ apex_point) - o > eps:
                    visible.add(other)
                    stack.append(other)
        horizon = []
        for k in visible:
            x, y, z = faces[k]
            for u, v in ((x, y), (y, z), (z, x)):
                if edge_face.get((v, u)) not in visible:
                    horizon.append((u, v))
        orphans = np.unique(np.concatenate([outside[k] for k in visible]))
        orphans = orphans[orphans != apex]
        for k in visible:
            x, y, z = faces[k]
            for e in ((x, y), (y, z), (z, x)):
                if edge_face.get(e) == k:
                    del edge_face[e]
            del faces[k], planes[k], outside[k]
        for u, v in horizon:
            add_face(u, v, apex, orphans)
    used = sorted({i for tri in faces.values() for i in tri})
    index = {old: new for new, old in enumerate(used)}
    tris = np.array([[index[i] for i in tri] for tri in faces.values()], dtype=np.int64)
    return pts[used], tris


def _tetrahedron(pts: Any, eps: float) -> tuple[int, int, int, int] | None:
    """Four points spanning a volume, from the extremes; None if there are none."""
    import numpy as np

    a = int(np.argmin(pts[:, 0]))
    b = int(np.argmax(np.linalg.norm(pts - pts[a], axis=1)))
    line = pts[b] - pts[a]
    if np.linalg.norm(line) <= eps:
        return None
    off_line = np.linalg.norm(np.cross(pts - pts[a], line), axis=1)
    c = int(np.argmax(off_line))
    if off_line[c] <= eps * np.linalg.norm(line):
        return None
    normal = np.cross(pts[b] - pts[a], pts[c] - pts[a])
    height = np.abs((pts - pts[a]) @ normal)
    d = int(np.argmax(height))
    if height[d] <= eps * np.linalg.norm(normal):
        return None
    return a, b, c, d


def _cluster_points(pts: Any, target: int) -> Any:
    """At most about ``target`` of ``pts``: the extreme point of each grid cell, per axis.

    Keeping real points (not cell means) keeps the hull of the subset inside the true hull
    and within one cell of it.
    """
    import numpy as np

    cells = _grid_cells(pts, target)
    keep: list[Any] = []
    for axis in range(3):
        for pick in (np.argmin, np.argmax):
            order = np.lexsort((pts[:, axis] if pick is np.argmin else -pts[:, axis],
                                cells))
            first = np.ones(len(order), dtype=bool)
            first[1:] = cells[order][1:] != cells[order][:-1]
            keep.append(order[first])
    return pts[np.unique(np.concatenate(keep))]


def _grid_cells(pts: Any, target: int) -> Any:
    """Each point's cell on a grid of about ``target`` occupied cells (one id per point)."""
    import numpy as np

    lo = pts.min(axis=0)
    size = np.maximum(np.ptp(pts, axis=0), 1e-12)
    # Occupied cells of a surface grow as the square of the divisions: aim for that.
    n = max(2, int(np.sqrt(target)))
    ijk = np.minimum(((pts - lo) / size * n).astype(np.int64), n - 1)
    return (ijk[:, 0] * (n + 1) + ijk[:, 1]) * (n + 1) + ijk[:, 2]


def decimate(vertices: Any, faces: Any, max_faces: int) -> tuple[Any, Any]:
    """Fewer than ``max_faces`` triangles by vertex clustering (see the module docstring).

    The grid is refined until the result fits: each try halves the cell size's count error.
    Returns the input when it already fits.
    """
    import numpy as np

    v = np.asarray(vertices, dtype=float)
    f = np.asarray(faces, dtype=np.int64)
    if len(f) <= max_faces:
        return v, f
    target = max_faces // 2  # a closed surface has about twice as many faces as vertices
    best: tuple[Any, Any] | None = None
    for _ in range(12):
        cells = _grid_cells(v, target)
        ids, inverse = np.unique(cells, return_inverse=True)
        counts = np.bincount(inverse, minlength=len(ids)).astype(float)
        merged = np.stack([np.bincount(inverse, weights=v[:, k], minlength=len(ids))
                           for k in range(3)], axis=1) / counts[:, None]
        tris = inverse[f]
        keep = (tris[:, 0] != tris[:, 1]) & (tris[:, 1] != tris[:, 2]) \
            & (tris[:, 0] != tris[:, 2])
        tris = np.unique(np.sort(tris[keep], axis=1), axis=0, return_index=True)[1]
        kept = inverse[f][keep][np.sort(tris)]
        best = (merged, kept)
        if len(kept) <= max_faces:
            return best
        target = int(target * 0.7)
    assert best is not None
    return best
