"""The convex hull of a point set, in plain numpy (no scipy at run time).

PyBullet collides with a mesh's convex hull, and MuJoCo builds one for every colliding mesh: the
viewer draws it (``urdfkit view``, with :mod:`urdfkit.draw.displaymesh`), and ``urdfkit export``
asks :func:`spans_volume` whether MuJoCo can build it.

:func:`convex_hull` is quickhull (Barber, Dobkin and Huhdanpaa, 1996): start from a tetrahedron
of extreme points, and repeatedly lift the face with points outside it to its farthest point,
replacing every face that point sees by a fan over the horizon. Points within a relative
tolerance of a face count as on it.
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
    hull = _Quickhull(pts, eps, pts[list(start)].mean(axis=0))
    everything = np.arange(len(pts))
    a, b, c, d = start
    for tri in ((a, b, c), (a, b, d), (a, c, d), (b, c, d)):
        hull.add_face(*tri, everything)
    while hull.pending:
        busy = hull.pending.pop()
        if busy in hull.faces and len(hull.outside[busy]):
            hull.lift(busy)
    used = sorted({i for tri in hull.faces.values() for i in tri})
    index = {old: new for new, old in enumerate(used)}
    tris = np.array([[index[i] for i in tri] for tri in hull.faces.values()], dtype=np.int64)
    return pts[used], tris


def spans_volume(points: Any) -> bool:
    """Whether 3-D ``points`` span a volume, so that a convex hull of them exists.

    Four of them are off one plane by more than :func:`convex_hull`'s tolerance, 1e-9 of
    their extent.
    """
    import numpy as np

    pts = np.asarray(points, dtype=float).reshape(-1, 3)
    if len(pts) < 4 or not np.isfinite(pts).all():
        return False
    scale = float(np.max(np.ptp(pts, axis=0))) or 1.0
    return _tetrahedron(pts, 1e-9 * scale) is not None


class _Quickhull:
    """The faces of a hull being built, with the points still outside each (see the module)."""

    def __init__(self, pts: Any, eps: float, inside: Any) -> None:
        self.pts, self.eps, self.inside = pts, eps, inside
        self.faces: dict[int, tuple[int, int, int]] = {}
        self.planes: dict[int, tuple[Any, float]] = {}
        self.outside: dict[int, Any] = {}
        self.edge_face: dict[tuple[int, int], int] = {}  # directed edge -> the face it bounds
        self.pending: list[int] = []  # faces that may have points outside
        self.counter = 0

    def add_face(self, a: int, b: int, c: int, candidates: Any) -> None:
        """Add the face (a, b, c), wound outward, keeping the candidates outside it."""
        import numpy as np

        pts = self.pts
        normal = np.cross(pts[b] - pts[a], pts[c] - pts[a])
        norm = float(np.linalg.norm(normal))
        if norm == 0.0:
            return
        normal = normal / norm
        offset = float(normal @ pts[a])
        if normal @ self.inside - offset > 0:  # wind it outward
            b, c, normal, offset = c, b, -normal, -offset
        key = self.counter
        self.counter += 1
        self.faces[key] = (a, b, c)
        self.planes[key] = (normal, offset)
        for e in ((a, b), (b, c), (c, a)):
            self.edge_face[e] = key
        if len(candidates):
            d = pts[candidates] @ normal - offset
            self.outside[key] = candidates[d > self.eps]
        else:
            self.outside[key] = candidates
        if len(self.outside[key]):
            self.pending.append(key)

    def lift(self, busy: int) -> None:
        """Replace the faces the farthest point outside ``busy`` sees by a fan from it."""
        import numpy as np

        normal, offset = self.planes[busy]
        cand = self.outside[busy]
        apex = int(cand[np.argmax(self.pts[cand] @ normal - offset)])
        visible = self._visible(busy, self.pts[apex])
        horizon = []
        for k in visible:
            x, y, z = self.faces[k]
            for u, v in ((x, y), (y, z), (z, x)):
                if self.edge_face.get((v, u)) not in visible:
                    horizon.append((u, v))
        orphans = np.unique(np.concatenate([self.outside[k] for k in visible]))
        orphans = orphans[orphans != apex]
        for k in visible:
            x, y, z = self.faces[k]
            for e in ((x, y), (y, z), (z, x)):
                if self.edge_face.get(e) == k:
                    del self.edge_face[e]
            del self.faces[k], self.planes[k], self.outside[k]
        for u, v in horizon:
            self.add_face(u, v, apex, orphans)

    def _visible(self, busy: int, apex_point: Any) -> set[int]:
        """The faces the apex sees: one patch around ``busy``, walked across edges."""
        visible = {busy}
        stack = [busy]
        while stack:
            x, y, z = self.faces[stack.pop()]
            for u, v in ((x, y), (y, z), (z, x)):
                other = self.edge_face.get((v, u))
                if other is None or other in visible:
                    continue
                n, o = self.planes[other]
                if float(n @ apex_point) - o > self.eps:
                    visible.add(other)
                    stack.append(other)
        return visible


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

    cells = grid_cells(pts, target)
    keep: list[Any] = []
    for axis in range(3):
        for pick in (np.argmin, np.argmax):
            order = np.lexsort((pts[:, axis] if pick is np.argmin else -pts[:, axis],
                                cells))
            first = np.ones(len(order), dtype=bool)
            first[1:] = cells[order][1:] != cells[order][:-1]
            keep.append(order[first])
    return pts[np.unique(np.concatenate(keep))]


def grid_cells(pts: Any, target: int) -> Any:
    """Each point's cell on a grid of about ``target`` occupied cells (one id per point)."""
    import numpy as np

    lo = pts.min(axis=0)
    size = np.maximum(np.ptp(pts, axis=0), 1e-12)
    # Occupied cells of a surface grow as the square of the divisions: aim for that.
    n = max(2, int(np.sqrt(target)))
    ijk = np.minimum(((pts - lo) / size * n).astype(np.int64), n - 1)
    return (ijk[:, 0] * (n + 1) + ijk[:, 1]) * (n + 1) + ijk[:, 2]
