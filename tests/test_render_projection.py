"""render's pictures checked against geometry, not against a stored image (issue 27.11): the
corners of a known box, projected with PyBullet's own view and projection matrices from the
camera render reports, outline exactly the pixels the box covers."""

from __future__ import annotations

import itertools
from pathlib import Path

import numpy as np
import pybullet as p
import pytest
from matplotlib.path import Path as Polygon

from urdfkit.render import RenderOptions, render_file

BOX = """<robot name="box"><material name="red"><color rgba="0.9 0.1 0.1 1"/></material>
<link name="b"><visual><geometry><box size="0.4 0.2 0.1"/></geometry><material name="red"/>
</visual><collision><geometry><box size="0.4 0.2 0.1"/></geometry></collision></link></robot>"""


def _hull(points: np.ndarray) -> list[tuple[float, float]]:
    """Convex hull (Andrew's monotone chain), counter-clockwise."""
    pts = sorted(map(tuple, points))

    def cross(o: tuple, a: tuple, b: tuple) -> float:
        return (a[0] - o[0]) * (b[1] - o[1]) - (a[1] - o[1]) * (b[0] - o[0])

    lower: list[tuple[float, float]] = []
    for q in pts:
        while len(lower) >= 2 and cross(lower[-2], lower[-1], q) <= 0:
            lower.pop()
        lower.append(q)
    upper: list[tuple[float, float]] = []
    for q in reversed(pts):
        while len(upper) >= 2 and cross(upper[-2], upper[-1], q) <= 0:
            upper.pop()
        upper.append(q)
    return lower[:-1] + upper[:-1]


@pytest.mark.parametrize("view", ["iso", "top", "front", "side"])
def test_a_known_box_covers_exactly_its_projected_corners(tmp_path: Path, view: str) -> None:
    path = tmp_path / "box.urdf"
    path.write_text(BOX)
    r = render_file(path, RenderOptions(width=320, height=240, views=(view,)))
    cam = r.cameras[0]
    left, top, w, h = cam.panel
    # PyBullet's matrices (column-major) from the camera render reports: independent of how
    # render built its own.
    look = np.array(p.computeViewMatrix(cam.eye, cam.target, cam.up)).reshape(4, 4).T
    lens = np.array(p.computeProjectionMatrixFOV(cam.fov_deg, w / h, 0.01, 100.0)).reshape(4, 4).T
    corners = []
    for c in itertools.product((-0.2, 0.2), (-0.1, 0.1), (-0.05, 0.05)):
        # The box as placed: its half sizes about the middle of the bounding box render reports.
        mid = [(a + b) / 2 for a, b in zip(*r.aabb, strict=True)]
        clip = lens @ look @ np.array([*(m + x for m, x in zip(mid, c, strict=True)), 1.0])
        ndc = clip[:3] / clip[3]
        corners.append((left + (ndc[0] + 1) / 2 * w, top + (1 - ndc[1]) / 2 * h))
    hull = _hull(np.array(corners))
    yy, xx = np.mgrid[0:r.height, 0:r.width]
    inside = Polygon(hull).contains_points(
        np.c_[xx.ravel() + 0.5, yy.ravel() + 0.5]).reshape(r.height, r.width)
    img = r.image.astype(int)
    red = (img[:, :, 0] - img[:, :, 1] > 60) & (img[:, :, 0] - img[:, :, 2] > 60)
    # A box's silhouette is the hull of its corners. Only its edge pixels may go either way:
    # the anti-aliased and outlined perimeter, one pixel wide, so at most the perimeter.
    perimeter = sum(float(np.hypot(*np.subtract(a, b)))
                    for a, b in zip(hull, hull[1:] + hull[:1], strict=True))
    assert inside.sum() > 2000  # the box fills a real part of the frame
    assert (inside & ~red).sum() <= perimeter, view
    assert (red & ~inside).sum() <= perimeter, view
