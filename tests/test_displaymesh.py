"""The viewer's own convex hull (urdfkit.sources.hull) and decimation (urdfkit.draw.displaymesh),
against qhull (scipy) and geometry: no scipy at run time, the same hull."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.spatial import ConvexHull

from urdfkit.draw.displaymesh import decimate
from urdfkit.sources.hull import HULL_POINTS, convex_hull


def _volume(v: np.ndarray, f: np.ndarray) -> float:
    a, b, c = v[f[:, 0]], v[f[:, 1]], v[f[:, 2]]
    return float(np.einsum("ij,ij->i", a, np.cross(b, c)).sum() / 6)


@pytest.mark.parametrize(("n", "seed"), [(4, 0), (10, 1), (200, 2), (1500, 3)])
def test_the_hull_is_qhulls(n: int, seed: int) -> None:
    pts = np.random.default_rng(seed).normal(size=(n, 3))
    hull = convex_hull(pts)
    assert hull is not None
    v, f = hull
    ref = ConvexHull(pts)
    assert _volume(v, f) == pytest.approx(ref.volume, rel=1e-12)  # wound outward: positive
    assert sorted(map(tuple, v)) == sorted(map(tuple, pts[ref.vertices]))
    # Every point is inside or on every face's plane.
    a, b, c = v[f[:, 0]], v[f[:, 1]], v[f[:, 2]]
    normals = np.cross(b - a, c - a)
    assert np.all(np.einsum("fj,pj->fp", normals, pts) - np.einsum("fj,fj->f", normals, a)[:, None]
                  <= 1e-9)


def test_points_all_on_the_hull_and_on_its_faces() -> None:
    rng = np.random.default_rng(4)
    sphere = rng.normal(size=(1000, 3))
    sphere /= np.linalg.norm(sphere, axis=1)[:, None]
    v, f = convex_hull(sphere)  # type: ignore[misc]
    assert _volume(v, f) == pytest.approx(ConvexHull(sphere).volume, rel=1e-12)
    grid = np.linspace(0.0, 1.0, 6)
    cube = np.array([[x, y, z] for x in grid for y in grid for z in grid])
    v, f = convex_hull(cube)  # type: ignore[misc]
    assert _volume(v, f) == pytest.approx(1.0) and len(v) == 8  # coplanar points dropped


def test_no_volume_no_hull() -> None:
    assert convex_hull(np.zeros((3, 3))) is None
    assert convex_hull(np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [1, 1, 0]])) is None
    assert convex_hull(np.array([[0, 0, 0], [1, 1, 1], [2, 2, 2], [3, 3, 3]])) is None


def test_a_thinned_hull_stays_inside_and_close() -> None:
    pts = np.random.default_rng(5).normal(size=(20 * HULL_POINTS, 3))
    v, f = convex_hull(pts)  # type: ignore[misc]
    ref = ConvexHull(pts).volume
    assert 0.97 * ref < _volume(v, f) <= ref * (1 + 1e-12)  # a subset's hull: never larger


def test_decimation_keeps_the_shape_in_fewer_triangles() -> None:
    import trimesh

    sphere = trimesh.creation.icosphere(subdivisions=6)  # 81,920 triangles
    v, f = decimate(sphere.vertices, sphere.faces, 8000)
    assert len(f) <= 8000
    assert np.ptp(v, axis=0) == pytest.approx(np.ptp(sphere.vertices, axis=0), rel=0.03)
    assert _volume(v, f) == pytest.approx(sphere.volume, rel=0.03)  # closed, wound outward
    same_v, same_f = decimate(sphere.vertices, sphere.faces, 10**6)
    assert len(same_f) == len(sphere.faces)  # small enough already: untouched
