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

from urdfkit.draw.render import Camera, RenderOptions, render_file

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


def _far(cam: Camera) -> float:
    """A far plane beyond the robot (the drawing views shoot from far away, with a long lens)."""
    return 2 * float(np.linalg.norm(np.subtract(cam.eye, cam.target))) + 100.0


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
    lens = np.array(p.computeProjectionMatrixFOV(cam.fov_deg, w / h, 0.01, _far(cam))
                    ).reshape(4, 4).T
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


def _ink_share(img: np.ndarray) -> np.ndarray:
    """Pixels that are neither the background nor the grid (test_render.py's measure)."""
    from urdfkit.draw import style

    far_bg = np.abs(img.astype(int) - np.array(style.rgb255(style.BACKGROUND))).sum(axis=2) > 30
    far_grid = np.abs(img.astype(int) - np.array(style.rgb255(style.GRID))).sum(axis=2) > 30
    return far_bg & far_grid


@pytest.mark.parametrize("robot", ["simplecar", "r2d2.urdf"])
@pytest.mark.parametrize("view", ["iso", "top", "front", "side"])
def test_the_robots_share_of_the_frame_is_what_pybullet_sees(tmp_path: Path, robot: str,
                                                             view: str) -> None:
    """The ink share, bounded by geometry rather than by a guessed 0.04..0.8 (issue 27.10).

    Below: raw PyBullet's own segmentation mask, shot with the same camera (view matrix from
    the eye, target and up render reports), counts the robot's pixels; render's picture may
    differ from it only on the anti-aliased silhouette edge, at most one pixel per pixel of
    the mask's outline (both ways for a coloured robot; for r2d2's white body only "no ink
    outside the robot"). Above: the robot lies in its bounding box, so its silhouette lies in
    the hull of the box's eight projected corners.
    """
    if robot == "simplecar":
        from urdfkit.model.catalog import build_template

        path = tmp_path / "simplecar.urdf"
        build_template("simplecar").write(path)
        load = str(path)
    else:
        import pybullet_data

        load = str(Path(pybullet_data.getDataPath()) / robot)
    r = render_file(load, RenderOptions(width=320, height=240, views=(view,), ground="none"))
    cam = r.cameras[0]
    w, h = r.width, r.height
    ink = _ink_share(r.image)
    c = p.connect(p.DIRECT)
    try:
        body = p.loadURDF(load, useFixedBase=True, physicsClientId=c)
        look = p.computeViewMatrix(cam.eye, cam.target, cam.up, physicsClientId=c)
        lens = p.computeProjectionMatrixFOV(cam.fov_deg, w / h, 0.01, _far(cam),
                                            physicsClientId=c)
        seg = np.reshape(np.asarray(p.getCameraImage(
            w, h, look, lens, renderer=p.ER_TINY_RENDERER, physicsClientId=c)[4]), (h, w))
        lo, hi = p.getAABB(body, -1, physicsClientId=c)
        for j in range(p.getNumJoints(body, physicsClientId=c)):
            a, b = p.getAABB(body, j, physicsClientId=c)
            lo, hi = np.minimum(lo, a), np.maximum(hi, b)
    finally:
        p.disconnect(physicsClientId=c)
    mask = seg == body
    # The mask's outline: pixels of the mask with a 4-neighbour outside it.
    edge = mask & ~(np.roll(mask, 1, 0) & np.roll(mask, -1, 0) & np.roll(mask, 1, 1)
                    & np.roll(mask, -1, 1))
    margin = int(edge.sum())
    assert mask.sum() > 1000, "the robot fills a real part of the frame"
    # Nothing is drawn where the robot is not...
    assert (ink & ~mask).sum() <= margin, view
    # ...and, for a robot of colours unlike the white background, all of it is drawn
    # (r2d2's body is white: its inside counts as background; only its outline is ink).
    if robot == "simplecar":
        assert (mask & ~ink).sum() <= margin, view
    look_m = np.array(look).reshape(4, 4).T
    lens_m = np.array(lens).reshape(4, 4).T
    corners = []
    for corner in itertools.product(*zip(lo, hi, strict=True)):
        clip = lens_m @ look_m @ np.array([*corner, 1.0])
        ndc = clip[:3] / clip[3]
        corners.append(((ndc[0] + 1) / 2 * w, (1 - ndc[1]) / 2 * h))
    hull = _hull(np.array(corners))
    yy, xx = np.mgrid[0:h, 0:w]
    inside = Polygon(hull).contains_points(np.c_[xx.ravel() + 0.5, yy.ravel() + 0.5]).reshape(h, w)
    perimeter = sum(float(np.hypot(*np.subtract(a, b)))
                    for a, b in zip(hull, hull[1:] + hull[:1], strict=True))
    assert (ink & ~inside).sum() <= perimeter, view


@pytest.mark.parametrize("view", ["iso", "front", "side", "top"])
def test_front_side_and_top_are_orthographic(tmp_path: Path, view: str) -> None:
    """Seen through the camera render reports (PyBullet's own matrices), a 10 cm segment at
    the back of the robot's box is drawn as long as one at its front in the three drawing
    views (to 0.5%), and visibly shorter in iso's perspective."""
    path = tmp_path / "box.urdf"
    path.write_text(BOX)
    r = render_file(path, RenderOptions(width=320, height=240, views=(view,)))
    cam = r.cameras[0]
    _, _, w, h = cam.panel
    look = np.array(p.computeViewMatrix(cam.eye, cam.target, cam.up)).reshape(4, 4).T
    lens = np.array(p.computeProjectionMatrixFOV(cam.fov_deg, w / h, 0.01, 1e9)).reshape(4, 4).T
    lo, hi = np.array(r.aabb[0]), np.array(r.aabb[1])
    toward = np.subtract(cam.eye, cam.target)
    toward /= np.linalg.norm(toward)
    across = np.cross(toward, cam.up)
    across /= np.linalg.norm(across)
    mid = (lo + hi) / 2
    depth = float(np.abs(toward) @ (hi - lo)) / 2

    def drawn(at: np.ndarray) -> float:
        a, b = (lens @ look @ np.array([*(at + s * 0.05 * across), 1.0]) for s in (-1, 1))
        return float(np.hypot(*(a[:2] / a[3] - b[:2] / b[3])) * h / 2)

    near, far = drawn(mid + toward * depth), drawn(mid - toward * depth)
    if view == "iso":
        assert far < 0.95 * near
    else:
        assert abs(far - near) <= 0.005 * near, (near, far)
