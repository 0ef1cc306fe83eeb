"""The view's cameras and lights (issue 49), judged by pixels in headless Chromium.

A robot's pixels are told from the rest by the page itself: two screenshots of the same
still view, the robot's visual shapes shown and hidden (the Show > Visual checkbox), differ
exactly where it is drawn. Its path is the orange of the line ``drive --view`` draws.
"""

from __future__ import annotations

import io
import math
import threading
import time
from pathlib import Path
from typing import Any

import pytest
from conftest import wait_until as _wait

#: One worker runs every page and server test (pytest-xdist --dist loadgroup): two Chromiums
#: drawing WebGL in software on 2 cores starve each other.
pytestmark = [pytest.mark.xdist_group("browser"), pytest.mark.usefixtures("plain_lighting")]

pytest.importorskip("viser", reason="urdfkit view needs viser (a core dependency)")

from urdfkit.draw.view import Viewer  # noqa: E402

#: A white arm: a box and a cylinder with no material (PyBullet draws them white), drawn
#: only (no ``<collision>``: :func:`_white` adds them).
WHITE = """<?xml version="1.0"?>
<robot name="white">
  <link name="base">
    <inertial><mass value="2"/>
      <inertia ixx="0.02" iyy="0.02" izz="0.02" ixy="0" ixz="0" iyz="0"/></inertial>
    <visual><geometry><box size="0.3 0.3 0.1"/></geometry></visual>
  </link>
  <link name="upper">
    <inertial><origin xyz="0 0 0.25"/><mass value="1"/>
      <inertia ixx="0.02" iyy="0.02" izz="0.02" ixy="0" ixz="0" iyz="0"/></inertial>
    <visual><origin xyz="0 0 LENGTH_HALF"/>
      <geometry><cylinder radius="0.06" length="LENGTH"/></geometry></visual>
  </link>
  <joint name="shoulder" type="revolute">
    <parent link="base"/><child link="upper"/><origin xyz="0 0 0.05"/><axis xyz="0 1 0"/>
    <limit lower="-1.5" upper="1.5" effort="10" velocity="1"/>
  </joint>
</robot>
"""


def _white(length: float, collide: bool = False) -> str:
    """The white arm, its cylinder ``length`` long; ``collide``: collision shapes as drawn."""
    import re

    text = WHITE.replace("LENGTH_HALF", f"{length / 2:g}").replace("LENGTH", f"{length:g}")
    if collide:
        text = re.sub(r"<visual>(.*?)</visual>", r"<visual>\1</visual><collision>\1</collision>",
                      text, flags=re.S)
    return text


def _shot(page: Any) -> Any:
    import numpy as np
    from PIL import Image

    png = page.screenshot(timeout=120000)  # software WebGL on a loaded machine: slow
    return np.asarray(Image.open(io.BytesIO(png)).convert("RGB")).astype(int)


def _still(page: Any, seconds: float = 60) -> Any:
    """A screenshot of the page once two in a row are the same (the page has drawn)."""
    import numpy as np

    end = time.monotonic() + seconds
    last = _shot(page)
    while time.monotonic() < end:
        time.sleep(0.3)
        now = _shot(page)
        if np.array_equal(now, last):
            return now
        last = now
    raise AssertionError("the page never stood still")


def _canvas(page: Any, rgb: Any) -> tuple[Any, Any]:
    """The canvas's pixels, and a mask of those not under the software-WebGL notice."""
    import numpy as np

    box = page.locator("canvas").first.bounding_box()
    x0, y0 = int(box["x"]), int(box["y"])
    x1, y1 = int(box["x"] + box["width"]), int(box["y"] + box["height"])
    free = np.ones(rgb.shape[:2], dtype=bool)
    notice = page.locator("#webgl-software-rendering")
    if notice.count():
        b = notice.first.bounding_box()
        if b is not None:
            free[int(b["y"]) - 4:int(b["y"] + b["height"]) + 4,
                 max(0, int(b["x"]) - 4):int(b["x"] + b["width"]) + 4] = False
    return rgb[y0:y1, x0:x1], free[y0:y1, x0:x1]


def _robot(page: Any, viewer: Viewer) -> tuple[Any, Any, Any]:
    """(canvas pixels with the robot, a mask of the robot's pixels, a mask of the usable canvas).

    Shown, hidden and shown again: a page that redrew anything else meanwhile (software
    WebGL lowers its resolution when frames are slow) is asked again.
    """
    import numpy as np

    def show(on: bool) -> Any:
        viewer.show_visual.value = on
        viewer.apply_toggles()
        return _still(page)

    for _ in range(10):  # a loaded machine's software WebGL can take several tries
        shown = _still(page)
        try:
            hidden = show(False)
        finally:
            again = show(True)
        if np.array_equal(shown, again):
            break
    else:
        raise AssertionError("the page kept redrawing")
    shown_c, free = _canvas(page, shown)
    hidden_c, _ = _canvas(page, hidden)
    return shown_c, (np.abs(shown_c - hidden_c).max(axis=2) > 24) & free, free


def _orange(rgb: Any, free: Any) -> int:
    """Pixels of the run's path (orange, (230, 97, 0)); the axes gizmo's red is not it."""
    r, g, b = rgb[..., 0], rgb[..., 1], rgb[..., 2]
    return int(((r > 170) & (g > 60) & (g < 150) & (b < 60) & free).sum())


def _margins(mask: Any) -> tuple[float, float, float, float]:
    """The robot's distance to the canvas's left, right, top and bottom edges (share of it)."""
    import numpy as np

    ys, xs = np.nonzero(mask)
    h, w = mask.shape
    return xs.min() / w, (w - 1 - xs.max()) / w, ys.min() / h, (h - 1 - ys.max()) / h


# --------------------------------------------------------------------------- following a run


@pytest.mark.slow  # a long browser test (10-30 s): CI's slow step runs it
def test_the_followed_car_is_whole_with_its_path_at_the_start_middle_and_end(
        module_chromium: Any) -> None:
    """drive --view's follow camera, on canvases that change shape under it.

    The page connects wide (1400 x 700); after the start the window narrows (800 x 700, the
    canvas then 0.6 as wide as high: what the panel docking beside it did to the first
    canvas a page reported), and after the run narrower still. At the start, the middle and
    the end of the run, and on a page opened after it, the car is whole inside the canvas,
    clear of every edge, with its orange path beside it. (Fitted once at connect for the wide
    canvas, the car ran off the narrow one's sides.)
    """
    from urdfkit.commands.driving import _run_view
    from urdfkit.motion.drive import DriveConfig, Scenario

    config = DriveConfig(throttle=10, steer=0.2, seconds=6)
    seen: dict[str, tuple[tuple[float, ...], int, int]] = {}

    def judge(name: str, page: Any, viewer: Viewer) -> None:
        rgb, car, free = _robot(page, viewer)
        seen[name] = (_margins(car), int(car.sum()), _orange(rgb, free & ~car))

    with Scenario(config) as sc:
        stream = _run_view(sc, config, None, None)
        viewer = stream.viewer
        stops = [1.0, 3.0]
        arrived, go = threading.Event(), threading.Event()
        failed: list[BaseException] = []

        def sink(row: Any) -> None:
            stream(row)
            if stops and float(row[0]) >= stops[0]:
                stops.pop(0)
                stream.push()  # the pose of this sample on the page, whatever the frame rate
                arrived.set()
                assert go.wait(300)
                go.clear()

        def run() -> None:
            try:
                sc.run(sink=sink)
                stream.finish("**Done**")
            except BaseException as e:  # noqa: BLE001 - reported by the test's thread
                failed.append(e)
            finally:
                arrived.set()

        page = module_chromium.new_page(viewport={"width": 1400, "height": 700})
        late = None
        try:
            page.goto(viewer.url)
            assert viewer.wait_for_page(60)
            runner = threading.Thread(target=run, daemon=True)
            runner.start()
            for name, width in (("start", 800), ("middle", None)):
                assert arrived.wait(300) and not failed, failed
                arrived.clear()
                judge(name, page, viewer)
                if width is not None:
                    page.set_viewport_size({"width": width, "height": 700})
                go.set()
            runner.join(300)
            assert not runner.is_alive() and not failed, failed
            page.set_viewport_size({"width": 700, "height": 800})
            judge("end", page, viewer)
            late = module_chromium.new_page(viewport={"width": 1000, "height": 700})
            late.goto(viewer.url)
            late.get_by_text("Done").first.wait_for(timeout=60000)
            judge("a page opened after the run", late, viewer)
        finally:
            go.set()
            page.close()
            if late is not None:
                late.close()
            viewer.close()
    for name, (margins, pixels, path) in seen.items():
        assert pixels > 1500, (name, pixels)  # the car is drawn, not a speck
        assert min(margins) > 0.05, (name, margins)  # whole, clear of every edge
        assert path > 40, (name, path)  # and its path beside it


# --------------------------------------------------------------------------- lights


def _look_from(viewer: Viewer, azimuth: float, elevation: float, at: tuple[float, ...],
               distance: float) -> None:
    """Put every page's camera at an azimuth and elevation (degrees) about a point."""
    a, e = math.radians(azimuth), math.radians(elevation)
    eye = (at[0] + distance * math.cos(e) * math.cos(a),
           at[1] + distance * math.cos(e) * math.sin(a), at[2] + distance * math.sin(e))
    for client in viewer.server.get_clients().values():
        with viewer.server.atomic():
            client.camera.up_direction = (0.0, 0.0, 1.0)
            client.camera.position = eye
            client.camera.look_at = at


def _brightness(page: Any, viewer: Viewer) -> tuple[float, float]:
    """The robot's pixels' 5th percentile and median brightness (0 black, 255 white)."""
    import numpy as np

    rgb, robot, _ = _robot(page, viewer)
    assert robot.sum() > 2000  # the arm is in view
    light = rgb.mean(axis=2)[robot]
    return float(np.percentile(light, 5)), float(np.median(light))


@pytest.mark.slow  # a long browser test (10-30 s): CI's slow step runs it
def test_a_white_robot_is_light_on_every_side_without_the_environment_map(
        module_chromium: Any, tmp_path: Path) -> None:
    """The default lighting (no environment map): every side of a white arm is light.

    viser's directional lights alone left the sides facing away from the main one black: a
    white cylinder seen from behind it had a median of 8 of 255 and its darkest 5% at 0.
    """
    path = tmp_path / "white.urdf"
    path.write_text(_white(0.5))
    viewer = Viewer(str(path))
    page = module_chromium.new_page(viewport={"width": 1000, "height": 700})
    try:
        assert viewer.lighting == "none"
        page.goto(viewer.url)
        page.get_by_text("Connected").wait_for(timeout=60000)
        found = {}
        for azimuth, elevation in ((0, 20), (90, 20), (180, 20), (270, 20), (225, -10),
                                   (45, 60)):
            _look_from(viewer, azimuth, elevation, (0.0, 0.0, 0.3), 1.6)
            found[azimuth, elevation] = _brightness(page, viewer)
    finally:
        page.close()
        viewer.close()
    for where, (dark, middle) in found.items():
        assert dark > 110 and middle > 160, (where, dark, middle)


@pytest.mark.slow  # a long browser test (10-30 s): CI's slow step runs it
@pytest.mark.environment_map
def test_a_white_robot_is_light_with_the_environment_map(module_chromium: Any,
                                                         tmp_path: Path) -> None:
    """viser's own environment map (``URDFKIT_VIEW_ENVIRONMENT=city``): the same white arm."""
    path = tmp_path / "white.urdf"
    path.write_text(_white(0.5))
    viewer = Viewer(str(path))
    page = module_chromium.new_page(viewport={"width": 1000, "height": 700})
    try:
        assert viewer.lighting == "city"
        page.goto(viewer.url)
        page.get_by_text("Connected").wait_for(timeout=60000)
        # Software WebGL prefilters the map for seconds, the canvas faded out meanwhile.
        end = time.monotonic() + 120
        while page.locator("canvas").nth(1).evaluate("c => c.style.opacity") not in ("", "1"):
            assert time.monotonic() < end, "the environment map never faded in"
            time.sleep(0.5)
        found = {}
        for azimuth, elevation in ((0, 20), (180, 20)):
            _look_from(viewer, azimuth, elevation, (0.0, 0.0, 0.3), 1.6)
            found[azimuth, elevation] = _brightness(page, viewer)
    finally:
        page.close()
        viewer.close()
    for where, (dark, middle) in found.items():
        assert dark > 110 and middle > 160, (where, dark, middle)


def test_a_bad_environment_name_is_refused(monkeypatch: pytest.MonkeyPatch,
                                           tmp_path: Path) -> None:
    import subprocess
    import sys

    path = tmp_path / "white.urdf"
    path.write_text(_white(0.5))
    monkeypatch.setenv("URDFKIT_VIEW_ENVIRONMENT", "moonlight")
    r = subprocess.run([sys.executable, "-m", "urdfkit", "view", str(path)], text=True,
                       capture_output=True, timeout=60, stdin=subprocess.DEVNULL)
    assert r.returncode == 2 and r.stderr.count("\n") == 1, r.stderr
    assert "URDFKIT_VIEW_ENVIRONMENT takes none or one of viser's maps" in r.stderr


# --------------------------------------------------------------------------- live reload


@pytest.mark.slow  # a long browser test (7-10 s): CI's slow step runs it
def test_a_robot_drawn_without_collision_shapes_is_framed_whole(module_chromium: Any,
                                                                 tmp_path: Path) -> None:
    """The white arm has visual shapes only: PyBullet's boxes (collision shapes) hold none of
    it, and the camera framed on them opened inside the arm."""
    path = tmp_path / "white.urdf"
    path.write_text(_white(0.5))
    viewer = Viewer(str(path))
    page = module_chromium.new_page(viewport={"width": 1000, "height": 700})
    try:
        page.goto(viewer.url)
        page.get_by_text("Connected").wait_for(timeout=60000)
        _, arm, _ = _robot(page, viewer)
    finally:
        page.close()
        viewer.close()
    assert arm.sum() > 2000 and min(_margins(arm)) > 0.05, _margins(arm)


@pytest.mark.slow  # a long browser test (10-30 s): CI's slow step runs it
def test_a_reloaded_robot_that_grew_is_framed_again_unless_the_camera_was_moved(
        module_chromium: Any, tmp_path: Path) -> None:
    """The arm rewritten three times as long is refitted on a page whose camera is urdfkit's:
    seen through the camera the page reports, the new arm is whole in the canvas, and its
    pixels clear the canvas's edges. A page whose user moved the camera keeps it."""
    import numpy as np

    path = tmp_path / "white.urdf"
    path.write_text(_white(0.5, collide=True))
    viewer = Viewer(str(path))
    page = module_chromium.new_page(viewport={"width": 1000, "height": 700})
    other = module_chromium.new_page(viewport={"width": 1000, "height": 700})
    try:
        for p in (page, other):
            p.goto(viewer.url)
            p.get_by_text("Connected").wait_for(timeout=60000)
        # viser counts a page as connected at its first camera report, which software
        # WebGL on a loaded machine can send well after the page shows "Connected"
        assert _wait(lambda: len(viewer.server.get_clients()) == 2, 60)
        clients = sorted(viewer.server.get_clients().values(), key=lambda c: c.client_id)
        mine, theirs = clients
        _, before, _ = _robot(page, viewer)
        assert min(_margins(before)) > 0.05  # the short arm is whole
        # The other page's user turns its camera (a drag on its canvas).
        box = other.locator("canvas").first.bounding_box()
        other.mouse.move(box["x"] + 200, box["y"] + 300)
        other.mouse.down()
        other.mouse.move(box["x"] + 320, box["y"] + 260, steps=8)
        other.mouse.up()
        assert _wait(lambda: viewer.cameras.moved(theirs), 30)
        turned = _settled(theirs.camera)  # (the drag's camera eases to a stop)
        assert not viewer.cameras.moved(mine)
        path.write_text(_white(1.5, collide=True))
        assert _wait(lambda: viewer.reloads == 1, 30)
        lo, hi = viewer.model.bounds()
        assert hi[2] - lo[2] > 1.5
        assert _wait(lambda: _inside(mine.camera, lo, hi), 30)
        _, after, _ = _robot(page, viewer)
        assert min(_margins(after)) > 0.03, _margins(after)
        time.sleep(1.0)
        assert np.asarray(theirs.camera.position, dtype=float) == pytest.approx(turned,
                                                                               abs=1e-6)
    finally:
        page.close()
        other.close()
        viewer.close()




def _settled(camera: Any, seconds: float = 60) -> Any:
    """A page's camera position once the page has reported the same for a second."""
    import numpy as np

    end = time.monotonic() + seconds
    last = np.asarray(camera.position, dtype=float)
    while time.monotonic() < end:
        time.sleep(1.0)
        now = np.asarray(camera.position, dtype=float)
        if np.array_equal(now, last):
            return now
        last = now
    raise AssertionError("the camera never settled")


def _inside(camera: Any, lo: Any, hi: Any) -> bool:
    """Whether every corner of lo..hi projects inside the camera's frame (a pinhole camera:
    its position, look_at, up, vertical fov and aspect, as the page reported them)."""
    import itertools

    import numpy as np

    eye, target = np.asarray(camera.position, float), np.asarray(camera.look_at, float)
    forward = (target - eye) / np.linalg.norm(target - eye)
    right = np.cross(forward, np.asarray(camera.up_direction, float))
    right /= np.linalg.norm(right)
    up = np.cross(right, forward)
    tan_v = math.tan(camera.fov / 2)
    tan_h = tan_v * camera.aspect
    for corner in itertools.product(*zip(lo, hi, strict=True)):
        rel = np.asarray(corner, float) - eye
        depth = rel @ forward
        if depth <= 0 or abs(rel @ right / depth) > tan_h or abs(rel @ up / depth) > tan_v:
            return False
    return True
