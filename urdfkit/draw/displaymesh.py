"""Meshes made lighter for display: vertex-clustering decimation.

For ``urdfkit view``: PyBullet keeps every triangle it loaded; the page draws a very large visual
mesh with fewer triangles, and a colliding mesh as its hull (:mod:`urdfkit.sources.hull`). Plain
numpy, so the viewer needs nothing beyond urdfkit's own dependencies.

:func:`decimate` is vertex clustering (Rossignac and Borrel, 1993): snap the vertices to a grid,
merge those in one cell into their mean, drop the triangles that collapse. The shape keeps its
outline to within one cell.
"""

from __future__ import annotations

from typing import Any

from urdfkit.sources.hull import grid_cells


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
        cells = grid_cells(v, target)
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
