"""``urdfkit view``: the model against raw PyBullet, and the page in a real headless Chromium.

The server-side tests compare what the viewer shows with PyBullet DIRECT driven by hand and
with the physics of a uniform box. The browser tests drive Debian's Chromium through Playwright
(software WebGL via SwiftShader), as a person would: they look for robot pixels, move a slider
with the keyboard, click the collision toggle, and assert on PyBullet's state and the scene
afterwards, never on pixel-exact images.
"""

from __future__ import annotations

import math
import os
import signal
import subprocess
import sys
import time
import urllib.request
from collections.abc import Callable, Iterator
from pathlib import Path
from typing import Any

import pytest
from conftest import wait_until as _wait

#: One worker runs every page and server test (pytest-xdist --dist loadgroup): two Chromiums
#: drawing WebGL in software on 2 cores starve each other.
pytestmark = [pytest.mark.xdist_group("browser"), pytest.mark.usefixtures("plain_lighting")]

pytest.importorskip("viser", reason="urdfkit view needs viser (a core dependency)")

from urdfkit.draw import view_page  # noqa: E402
from urdfkit.draw.view import TINTS, TOUCHING_RGB, Viewer  # noqa: E402

DOCS = Path(__file__).parent.parent / "docs"

#: Green visuals, so robot pixels are told from the white page and grey grid.
ARM = """<?xml version="1.0"?>
<robot name="arm">
  <material name="green"><color rgba="0 0.9 0 1"/></material>
  <link name="base">
    <inertial><mass value="2"/>
      <inertia ixx="0.02" iyy="0.02" izz="0.02" ixy="0" ixz="0" iyz="0"/></inertial>
    <visual><geometry><box size="0.3 0.3 0.1"/></geometry><material name="green"/></visual>
    <collision><geometry><box size="0.3 0.3 0.1"/></geometry></collision>
  </link>
  <link name="upper">
    <inertial><origin xyz="0 0 0.25"/><mass value="1.5"/>
      <inertia ixx="0.02" iyy="0.03" izz="0.04" ixy="0" ixz="0" iyz="0"/></inertial>
    <visual><origin xyz="0 0 0.25"/><geometry><box size="0.08 0.08 0.5"/></geometry>
      <material name="green"/></visual>
    <collision><origin xyz="0 0 0.25"/><geometry><box size="0.08 0.08 0.5"/></geometry></collision>
  </link>
  <link name="finger">
    <inertial><mass value="0.1"/>
      <inertia ixx="0.001" iyy="0.001" izz="0.001" ixy="0" ixz="0" iyz="0"/></inertial>
    <visual><geometry><box size="0.02 0.02 0.1"/></geometry><material name="green"/></visual>
  </link>
  <link name="wheel">
    <inertial><mass value="0.1"/>
      <inertia ixx="0.001" iyy="0.001" izz="0.001" ixy="0" ixz="0" iyz="0"/></inertial>
    <visual><geometry><cylinder radius="0.05" length="0.06"/></geometry>
      <material name="green"/></visual>
    <collision><geometry><cylinder radius="0.05" length="0.06"/></geometry></collision>
  </link>
  <joint name="shoulder" type="revolute">
    <parent link="base"/><child link="upper"/><origin xyz="0 0 0.05"/><axis xyz="0 1 0"/>
    <limit lower="-1.5" upper="1.5" effort="10" velocity="1"/>
  </joint>
  <joint name="slide" type="prismatic">
    <parent link="upper"/><child link="finger"/><origin xyz="0 0 0.5"/><axis xyz="1 0 0"/>
    <limit lower="-0.1" upper="0.1" effort="10" velocity="1"/>
    <mimic joint="shoulder" multiplier="0.05" offset="0.01"/>
  </joint>
  <joint name="spin" type="continuous">
    <parent link="base"/><child link="wheel"/><origin xyz="0.2 0 0"/><axis xyz="0 0 1"/>
  </joint>
</robot>
"""


@pytest.fixture
def arm(tmp_path: Path) -> Path:
    """The test arm, in a folder of its own (edits in one test never reach another)."""
    path = tmp_path / "arm.urdf"
    path.write_text(ARM)
    return path


@pytest.fixture
def viewer_of(viewers: Callable[..., Viewer]) -> Callable[..., Viewer]:
    """Start viewers on free ports; every one is closed after the test (conftest's)."""
    return viewers


def _raw_link_state(path: Path, joints: dict[str, float], link: str,
                    **load: Any) -> tuple[tuple[float, ...], tuple[float, ...]]:
    """A link frame's world pose from PyBullet DIRECT, set up by hand."""
    import pybullet as p

    c = p.connect(p.DIRECT)
    try:
        body = p.loadURDF(str(path), physicsClientId=c,
                          flags=p.URDF_USE_IMPLICIT_CYLINDER, **load)
        index = {}
        for j in range(p.getNumJoints(body, physicsClientId=c)):
            info = p.getJointInfo(body, j, physicsClientId=c)
            index[info[1].decode()] = j
            index["link:" + info[12].decode()] = j
        for name, value in joints.items():
            p.resetJointState(body, index[name], value, physicsClientId=c)
        state = p.getLinkState(body, index["link:" + link], computeForwardKinematics=1,
                               physicsClientId=c)
        return tuple(state[4]), tuple(state[5])
    finally:
        p.disconnect(physicsClientId=c)


def _same_rotation(wxyz: tuple[float, ...], xyzw: tuple[float, ...]) -> bool:
    q = (xyzw[3], xyzw[0], xyzw[1], xyzw[2])
    return abs(abs(sum(a * b for a, b in zip(wxyz, q, strict=True))) - 1) < 1e-5


def _plain(markdown: str) -> str:
    """What a reader sees of the page's markdown: no HTML tags, no backslash escapes."""
    import re

    return re.sub(r"\\(.)", r"\1", re.sub(r"<[^>]+>", "", markdown))




# --------------------------------------------------------------------------- the server


def test_sliders_in_pybullet_order_within_limits(arm: Path, viewer_of: Any) -> None:
    import pybullet as p

    v = viewer_of(arm)
    c = p.connect(p.DIRECT)
    try:
        body = p.loadURDF(str(arm), physicsClientId=c)
        movable = [p.getJointInfo(body, j, physicsClientId=c)[1].decode()
                   for j in range(p.getNumJoints(body, physicsClientId=c))
                   if p.getJointInfo(body, j, physicsClientId=c)[2] in (p.JOINT_REVOLUTE,
                                                                         p.JOINT_PRISMATIC)]
    finally:
        p.disconnect(physicsClientId=c)
    assert list(v.sliders) == movable
    assert (v.sliders["shoulder"].min, v.sliders["shoulder"].max) == (-1.5, 1.5)
    assert (v.sliders["spin"].min, v.sliders["spin"].max) == (-math.pi, math.pi)  # continuous
    assert v.sliders["slide"].disabled  # a mimic joint follows, it has no slider of its own
    # From the start: shoulder 0 puts the mimic at its offset, in PyBullet and on its slider.
    assert v.model.positions()["slide"] == pytest.approx(0.01)
    assert v.sliders["slide"].value == pytest.approx(0.01)


def test_moving_a_joint_moves_pybullet_and_the_scene(arm: Path, viewer_of: Any) -> None:
    v = viewer_of(arm)
    before = v.link_pose("upper")
    now = v.set_joints({"shoulder": 0.7})
    assert now["shoulder"] == pytest.approx(0.7)
    assert now["slide"] == pytest.approx(0.7 * 0.05 + 0.01)  # the mimic follows its leader
    for link in ("upper", "finger"):
        pos, quat = _raw_link_state(arm, {"shoulder": 0.7, "slide": 0.045}, link)
        scene_pos, scene_wxyz = v.link_pose(link)
        assert scene_pos == pytest.approx(pos, abs=1e-6)
        assert _same_rotation(scene_wxyz, quat)
    assert v.link_pose("upper") != before
    assert v.vector_text.value == "[0.7, 0.045, 0.0]"
    assert v.joints_text.value == "--joints shoulder=0.7,slide=0.045,spin=0"
    v.reset()
    assert v.model.positions() == {"shoulder": 0.0, "slide": pytest.approx(0.01), "spin": 0.0}


def test_inertia_box_matches_the_principal_moments(arm: Path, viewer_of: Any) -> None:
    v = viewer_of(arm, inertia_from_file=True)
    # A uniform box of sides a, b, c and mass m: Ixx = m (b^2 + c^2) / 12, and so on.
    m, (ixx, iyy, izz) = 1.5, (0.02, 0.03, 0.04)
    want = [math.sqrt(6 * (iyy + izz - ixx) / m), math.sqrt(6 * (ixx + izz - iyy) / m),
            math.sqrt(6 * (ixx + iyy - izz) / m)]
    upper = next(lk for lk in v.model.links if lk.name == "upper")
    assert upper.inertia_box == pytest.approx(want)
    box = [h for h in v.nodes("inertia", "upper") if h.name.endswith("/box")]
    assert len(box) == 1 and tuple(box[0].dimensions) == pytest.approx(want)
    a, b, c = box[0].dimensions
    assert m * (b * b + c * c) / 12 == pytest.approx(ixx)


def test_inertia_box_without_the_file_is_pybullets(arm: Path, viewer_of: Any) -> None:
    # Without URDF_USE_INERTIA_FROM_FILE PyBullet computes inertia from the collision box's
    # bounds, so the equivalent box is the collision box itself.
    v = viewer_of(arm)
    upper = next(lk for lk in v.model.links if lk.name == "upper")
    assert upper.inertia_box == pytest.approx((0.08, 0.08, 0.5), abs=1e-6)


def _raw_touching(path: Path, joints: dict[str, float]) -> dict[tuple[str, str], float]:
    """Non-adjacent link pairs within 0 m, from PyBullet DIRECT with self-collision on."""
    import pybullet as p

    c = p.connect(p.DIRECT)
    try:
        body = p.loadURDF(str(path), useFixedBase=True, physicsClientId=c,
                          flags=p.URDF_USE_SELF_COLLISION | p.URDF_USE_IMPLICIT_CYLINDER)
        n = p.getNumJoints(body, physicsClientId=c)
        infos = [p.getJointInfo(body, j, physicsClientId=c) for j in range(n)]
        for info in infos:
            if info[1].decode() in joints:
                p.resetJointState(body, info[0], joints[info[1].decode()], physicsClientId=c)
        names = {-1: p.getBodyInfo(body, physicsClientId=c)[0].decode()}
        names.update({i[0]: i[12].decode() for i in infos})
        out = {}
        for a in range(-1, n):
            for b in range(a + 1, n):
                if infos[b][16] == a:
                    continue
                points = p.getClosestPoints(body, body, 0.0, a, b, physicsClientId=c)
                if points:
                    out[(names[a], names[b])] = min(pt[8] for pt in points)
        return out
    finally:
        p.disconnect(physicsClientId=c)


def test_touching_pairs_follow_the_sliders(arm: Path, viewer_of: Any) -> None:
    v = viewer_of(arm)
    v.show_touching.value = True  # off by default: the robot in its own colours
    assert v.touching == [] and _raw_touching(arm, {}) == {}
    v.set_joints({"shoulder": 1.5})  # the arm swings down onto the wheel
    raw = _raw_touching(arm, {"shoulder": 1.5, "slide": 0.085})
    assert list(raw) == [("upper", "wheel")]
    assert [(a, b) for a, b, _ in v.touching] == [("upper", "wheel")]
    assert v.touching[0][2] == pytest.approx(raw[("upper", "wheel")], abs=1e-6)
    assert [h.color for h in v.nodes("visual", "wheel")] == [TOUCHING_RGB]
    assert "touching: upper and wheel" in _plain(v.touching_text.content)
    v.reset()
    assert v.touching == [] and v.nodes("visual", "wheel")[0].color == (0, 229, 0)


def test_collision_layer_hidden_until_asked(arm: Path, viewer_of: Any) -> None:
    v = viewer_of(arm)
    assert v.visible("visual") and not v.visible("collision")
    v.show_collision.value = True
    v.apply_toggles()
    assert v.visible("collision")
    (shape,) = v.nodes("collision", "upper")
    assert shape.position == pytest.approx((0, 0, 0.25))  # in the link frame


U604 = ARM.replace('<inertia ixx="0.02" iyy="0.03" izz="0.04"',
                   '<inertia ixx="0.01" iyy="0.01" izz="0.5"')


def test_u604_error_tints_its_link_and_names_its_line(tmp_path: Path, viewer_of: Any) -> None:
    path = tmp_path / "bad.urdf"
    path.write_text(U604)
    line = next(i for i, text in enumerate(U604.splitlines(), 1) if 'izz="0.5"' in text)
    v = viewer_of(path, inertia_from_file=True)
    levels = {lk.name: lk.level for lk in v.model.links}
    assert levels["upper"] == "error" and levels["base"] is None
    # By default every link keeps PyBullet's colour; the tint is asked for.
    assert [h.color for h in v.nodes("visual", "upper")] == [(0, 229, 0)]
    v.tint_findings.value = True
    assert [h.color for h in v.nodes("visual", "upper")] == [TINTS["error"]]
    # The file's colour, as PyBullet keeps it (float32 0.9 of 255 = 229.49...).
    assert v.nodes("visual", "base")[0].color == (0, 229, 0)
    u604 = [f for f in v.model.findings if f.code == "U604"]
    assert [f.line for f in u604] == [line]
    # Listed once: by its button (it is on a link), whose link's panel gives file:line.
    assert f"{path}:{line}" not in _plain(view_page.findings(v.model))
    v.select("upper")
    assert f"{path}:{line}" in _plain(v.selected_text.content)


def test_edit_reloads_and_a_broken_file_keeps_the_last_robot(arm: Path, viewer_of: Any) -> None:
    v = viewer_of(arm)
    v.set_joints({"shoulder": 0.3})
    arm.write_text(ARM.replace('<origin xyz="0 0 0.05"/><axis xyz="0 1 0"/>',
                               '<origin xyz="0 0 0.15"/><axis xyz="0 1 0"/>'))
    assert _wait(lambda: v.reloads == 1, 5), "the edit was not picked up"
    assert v.model.positions()["shoulder"] == pytest.approx(0.3)  # kept by name
    pos, _ = _raw_link_state(arm, {"shoulder": 0.3}, "upper")
    assert v.link_pose("upper")[0] == pytest.approx(pos, abs=1e-6)
    assert pos[2] == pytest.approx(0.15)
    good = v.model
    arm.write_text(ARM.replace("</robot>", ""))
    assert _wait(lambda: v.error is not None, 5), "the broken file was not noticed"
    assert "arm.urdf" in v.error and v.model is good and v.reloads == 1
    assert "Reload failed" in v.status.content
    with urllib.request.urlopen(v.url, timeout=5) as r:  # the server is still up
        assert r.status == 200
    arm.write_text(ARM)
    assert _wait(lambda: v.reloads == 2 and v.error is None, 5)


def test_a_bad_file_refused_before_serving(tmp_path: Path) -> None:
    path = tmp_path / "bad.urdf"
    path.write_text("<robot name='x'><link name='a'>")
    with pytest.raises(Exception, match="bad.urdf") as e:
        Viewer(str(path))
    assert type(e.value).__name__ == "InputError"


def test_cli_prints_the_url_serves_and_exits_130(arm: Path) -> None:
    import select
    import threading

    proc = subprocess.Popen([sys.executable, "-m", "urdfkit", "view", str(arm)],
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    err_lines: list[str] = []
    # stderr is read as it comes, so the server can never block on a full pipe, and whatever
    # it said is in the message if no URL comes.
    reader = threading.Thread(target=lambda: err_lines.extend(iter(proc.stderr.readline, "")),
                              daemon=True)  # type: ignore[union-attr]
    reader.start()
    try:
        assert proc.stdout is not None
        # The URL within two minutes (seconds on a quiet machine; a loaded 2-core one has
        # taken 30): a server that never says where it is fails here, never hangs the suite.
        ready, _, _ = select.select([proc.stdout], [], [], 120)
        assert ready, (f"urdfkit view printed no URL within 120 s (exit {proc.poll()}); "
                       f"stderr: {''.join(err_lines)[-2000:]!r}")
        line = proc.stdout.readline()
        assert line.startswith("urdfkit view: http://localhost:"), (line, "".join(err_lines))
        url = line.split()[2]
        with urllib.request.urlopen(url, timeout=10) as r:
            assert r.status == 200 and b"<html" in r.read().lower()
        proc.send_signal(signal.SIGINT)
        proc.wait(timeout=20)
        out = proc.stdout.read()
        reader.join(10)
    finally:
        if proc.poll() is None:
            proc.kill()
            proc.wait()
        for pipe in (proc.stdout, proc.stderr):
            if pipe is not None:
                pipe.close()
    assert proc.returncode == 130
    assert "".join(err_lines).strip() == "urdfkit: interrupted" and out == ""


def test_cli_bad_file_is_one_line_exit_2(tmp_path: Path) -> None:
    r = subprocess.run([sys.executable, "-m", "urdfkit", "view", str(tmp_path / "none.urdf")],
                       capture_output=True, text=True, timeout=60)
    assert r.returncode == 2
    assert r.stderr.count("\n") == 1 and "none.urdf" in r.stderr and r.stdout == ""


@pytest.mark.parametrize("kind", ["fifo", "folder", "dangling"])
def test_cli_refuses_what_is_not_a_file_at_once(kind: str, tmp_path: Path) -> None:
    path = tmp_path / "robot.urdf"
    if kind == "fifo":
        os.mkfifo(path)
    elif kind == "folder":
        path.mkdir()
    else:
        path.symlink_to(tmp_path / "gone.urdf")
    t0 = time.monotonic()
    r = subprocess.run([sys.executable, "-m", "urdfkit", "view", str(path)],
                       capture_output=True, text=True, timeout=60)
    assert r.returncode == 2 and time.monotonic() - t0 < 30
    assert r.stderr.count("\n") == 1 and "robot.urdf" in r.stderr and r.stdout == ""


def test_xacro_with_args(tmp_path: Path, viewer_of: Any) -> None:
    path = tmp_path / "two.urdf.xacro"
    path.write_text(
        '<robot name="two" xmlns:xacro="http://www.ros.org/wiki/xacro">'
        '<xacro:arg name="reach" default="0.2"/>'
        '<link name="a"><visual><geometry><box size="0.1 0.1 0.1"/></geometry></visual></link>'
        '<link name="b"><visual><geometry><box size="0.1 0.1 0.1"/></geometry></visual></link>'
        '<joint name="j" type="prismatic"><parent link="a"/><child link="b"/>'
        '<limit lower="0" upper="$(arg reach)" effort="1" velocity="1"/></joint></robot>')
    v = viewer_of(path, xacro_args=["reach:=0.7"])
    assert (v.sliders["j"].min, v.sliders["j"].max) == (0.0, 0.7)
    v.set_joints({"j": 0.5})
    assert v.link_pose("b")[0] == pytest.approx((0.5, 0.0, 0.0), abs=1e-6)  # axis default x


# --------------------------------------------------------------------------- the page


@pytest.fixture
def page_of(module_chromium: Any) -> Iterator[Any]:
    """Open a viewer's page, connected; every page a test opens is closed after it.

    A page left open keeps drawing WebGL in software: a dozen of them starved the last
    tests of the module of CPU on a 2-core machine (their clicks timed out in CI).
    """
    opened: list[Any] = []

    def open_page(v: Viewer) -> Any:
        page = module_chromium.new_page(viewport={"width": 1000, "height": 700})
        opened.append(page)
        page.goto(v.url)
        page.get_by_text("Connected").wait_for(timeout=30000)
        return page

    yield open_page
    for page in opened:
        page.close()


def _pixels(page: Any, colour: str = "green", path: Path | None = None) -> int:
    """Pixels of the scene that are clearly green (visuals), red (error tint) or orange."""
    import io

    import numpy as np
    from PIL import Image

    png = page.screenshot(path=str(path) if path else None)
    # Where the camera looks: below the notice, above the axes gizmo (its y axis is green),
    # left of the control panel docked beside the canvas (its legend has red and amber).
    rgb = np.asarray(Image.open(io.BytesIO(png)).convert("RGB")).astype(int)[160:620, :600]
    r, g, b = rgb[..., 0], rgb[..., 1], rgb[..., 2]
    if colour == "green":
        return int(((g > r + 60) & (g > b + 60)).sum())
    if colour == "red":
        return int(((r > g + 90) & (r > b + 90) & (abs(g - b) < 40)).sum())
    return int(((r > g + 40) & (g > b + 40)).sum())


def test_page_connects_and_draws_the_robot(page_of: Any, arm: Path, viewer_of: Any,
                                           tmp_path: Path) -> None:
    v = viewer_of(arm)
    page = page_of(v)
    assert _wait(lambda: _pixels(page) > 2000, 30), "no robot pixels on the page"
    assert page.get_by_text("arm", exact=False).first.is_visible()


def test_slider_in_the_page_moves_pybullet_and_the_scene(page_of: Any, arm: Path,
                                                         viewer_of: Any) -> None:
    v = viewer_of(arm)
    page = page_of(v)
    thumb = page.locator("[role=slider][aria-valuemin='-1.5']")
    thumb.focus()
    page.keyboard.press("End")  # to the upper limit, as a keyboard user does
    assert _wait(lambda: v.model.positions()["shoulder"] == pytest.approx(1.5), 10)
    pos, quat = _raw_link_state(arm, {"shoulder": 1.5, "slide": 1.5 * 0.05 + 0.01}, "finger")
    scene_pos, scene_wxyz = v.link_pose("finger")
    assert scene_pos == pytest.approx(pos, abs=1e-6) and _same_rotation(scene_wxyz, quat)
    page.get_by_role("button", name="Reset to zero").click()
    assert _wait(lambda: v.model.positions()["shoulder"] == 0.0, 10)
    # The page redraws the slider after the server's update: software WebGL on a loaded
    # 2-core machine (the other test worker busy) has taken over 10 s here.
    assert _wait(lambda: thumb.get_attribute("aria-valuenow") == "0", 30), \
        thumb.get_attribute("aria-valuenow")


def test_collision_toggle_in_the_page(page_of: Any, arm: Path, viewer_of: Any) -> None:
    v = viewer_of(arm)
    page = page_of(v)
    page.get_by_label("Collision", exact=True).check()
    assert _wait(lambda: v.visible("collision"), 10)
    page.get_by_label("Visual").uncheck()
    assert _wait(lambda: not v.visible("visual"), 10)
    # Collision shapes only: the green visuals are gone from the picture, orange ones drawn.
    assert _wait(lambda: _pixels(page) < 20 and _pixels(page, "orange") > 2000, 10)


def test_finding_and_reload_error_shown_in_the_page(page_of: Any, tmp_path: Path,
                                                   viewer_of: Any) -> None:
    path = tmp_path / "bad.urdf"
    path.write_text(U604)
    line = next(i for i, text in enumerate(U604.splitlines(), 1) if 'izz="0.5"' in text)
    v = viewer_of(path, inertia_from_file=True)
    page = page_of(v)
    # The finding's button; clicked, its link's panel names the file and line.
    page.get_by_role("button", name=f"U604 line {line}: upper").click()
    page.get_by_text(f"{path}:{line}").wait_for(timeout=30000)
    # The robot's own colours first; red where the error is once the tint is asked for.
    assert _wait(lambda: _pixels(page) > 2000, 30) and _pixels(page, "red") < 20
    v.select(None)
    page.get_by_label("Tint findings").check()
    assert _wait(lambda: _pixels(page, "red") > 500, 20)
    if os.environ.get("URDFKIT_SHOTS"):  # docs/view.png: URDFKIT_SHOTS=1 pytest -k finding
        page.locator("button.mantine-Notification-closeButton").click()
        page.get_by_label("COM and inertia boxes").check()
        page.get_by_label("Frames and axes").check()
        time.sleep(2)
        page.screenshot(path=str(DOCS / "view.png"))
    path.write_text("<robot")
    page.get_by_text("Reload failed").wait_for(timeout=10000)
    assert page.get_by_text("Connected").is_visible()


# --------------------------------------------------------------------------- selection


def test_selecting_a_link_highlights_it_and_shows_its_joint_row(tmp_path: Path,
                                                                viewer_of: Any) -> None:
    from urdfkit.draw.view import NO_LINK, SELECTED_RGB

    path = tmp_path / "bad.urdf"
    path.write_text(U604)
    v = viewer_of(path, inertia_from_file=True)
    v.tint_findings.value = True
    v.select("upper")
    assert v.select_link.value == "upper"
    assert [h.color for h in v.nodes("visual", "upper")] == [SELECTED_RGB]
    assert v.nodes("visual", "base")[0].color == (0, 229, 0)  # the others keep theirs
    # Its joint's row, decoded as `urdfkit joints` decodes it, and the finding on it.
    row = next(j for j in v.model.table if j.link_name == "upper")
    assert f"joint {row.joint_index} **shoulder**" in _plain(v.selected_text.content)
    assert "U604" in v.selected_text.content
    v.select(None)
    assert v.select_link.value == NO_LINK
    assert [h.color for h in v.nodes("visual", "upper")] == [TINTS["error"]]  # tint again
    with pytest.raises(KeyError):
        v.select("no_such_link")


@pytest.mark.slow  # a long browser test (7-10 s): CI's slow step runs it
def test_clicking_a_finding_and_choosing_a_link_in_the_page_select_it(
        page_of: Any, tmp_path: Path, viewer_of: Any) -> None:
    path = tmp_path / "bad.urdf"
    path.write_text(U604)
    line = next(i for i, text in enumerate(U604.splitlines(), 1) if 'izz="0.5"' in text)
    v = viewer_of(path, inertia_from_file=True)
    page = page_of(v)
    # The finding's button in the page selects the link it is about, on the server.
    page.get_by_role("button", name=f"U604 line {line}: upper").click()
    assert _wait(lambda: v.selected == "upper", 10)
    page.get_by_text("child of joint").wait_for(timeout=30000)
    # Choosing another link in the Selection dropdown moves the selection to it.
    page.get_by_label("Link", exact=True).click()
    page.get_by_role("option", name="finger", exact=True).click()
    assert _wait(lambda: v.selected == "finger", 10)
    # Clicking the red (U604) link in the scene selects it: the middle of its red pixels.
    import io

    import numpy as np
    from PIL import Image

    page.get_by_label("Tint findings").check()
    assert _wait(lambda: _pixels(page, "red") > 500, 20)
    rgb = np.asarray(Image.open(io.BytesIO(page.screenshot())).convert("RGB")).astype(int)
    r, g, b = rgb[160:620, :600, 0], rgb[160:620, :600, 1], rgb[160:620, :600, 2]
    ys, xs = np.nonzero((r > g + 90) & (r > b + 90) & (abs(g - b) < 40))
    k = len(ys) // 2  # a red pixel in the middle of the list, not on the silhouette's edge
    page.mouse.click(int(xs[k]), int(ys[k]) + 160)
    assert _wait(lambda: v.selected == "upper", 10), v.selected


def test_a_joint_axis_is_drawn_in_the_link_frame_whatever_the_inertial_frame(
        tmp_path: Path, viewer_of: Any) -> None:
    # PyBullet reports the axis in the child's inertial frame; an <inertial><origin rpy> turns
    # that frame. The axis drawn in the link's node must still be the file's (0 1 0).
    import numpy as np

    path = tmp_path / "turned.urdf"
    text = ARM
    i = text.index('<link name="upper">')
    j = text.index("<inertial>", i) + len("<inertial>")
    path.write_text(text[:j] + '<origin rpy="0.9 0 0.6"/>' + text[j:])
    v = viewer_of(path)
    shoulder = next(jc for jc in v.model.joints if jc.name == "shoulder")
    assert abs(shoulder.axis[1]) < 0.6  # PyBullet's own, turned
    line = [h for h in v.nodes("frames", "upper") if h.name.endswith("/joint_axis")]
    assert len(line) == 1
    a, b = (np.asarray(pt, dtype=float) for pt in line[0].points[0])
    direction = (b - a) / np.linalg.norm(b - a)
    file_axis = [float(x) for x in ARM.split('<joint name="shoulder"')[1].split('xyz="')[2]
                 .split('"')[0].split()]
    assert direction == pytest.approx(np.asarray(file_axis) / np.linalg.norm(file_axis),
                                      abs=1e-6)


def _projected_share(camera: Any, lo: Any, hi: Any) -> tuple[float, float]:
    """The share of the canvas's width and height the box lo..hi spans, seen by the page's
    own camera (its position, look_at, up, vertical fov and aspect): a pinhole projection."""
    import itertools

    import numpy as np

    eye, target = np.asarray(camera.position, float), np.asarray(camera.look_at, float)
    forward = (target - eye) / np.linalg.norm(target - eye)
    right = np.cross(forward, np.asarray(camera.up_direction, float))
    right /= np.linalg.norm(right)
    up = np.cross(right, forward)
    tan_v = math.tan(camera.fov / 2)
    tan_h = tan_v * camera.aspect
    xs, ys = [], []
    for corner in itertools.product(*zip(lo, hi, strict=True)):
        rel = np.asarray(corner, float) - eye
        depth = rel @ forward
        assert depth > 0, "a corner behind the camera"
        xs.append(rel @ right / depth / tan_h)  # -1..1 across the canvas
        ys.append(rel @ up / depth / tan_v)
    assert max(map(abs, xs + ys)) <= 1.0, "the robot is not all inside the canvas"
    return (max(xs) - min(xs)) / 2, (max(ys) - min(ys)) / 2


@pytest.mark.slow  # a long browser test (7-10 s): CI's slow step runs it
@pytest.mark.environment_map  # the colours as users see them: viser's own lighting
def test_kuka_in_its_own_colours_with_a_legend_filling_the_view(page_of: Any,
                                                                viewer_of: Any) -> None:
    import io

    import numpy as np
    import pybullet as p
    import pybullet_data
    from PIL import Image

    path = Path(pybullet_data.getDataPath()) / "kuka_iiwa" / "model.urdf"
    v = viewer_of(path)
    # Every link has a U612 warning (its meshes are not closed) ...
    assert {lk.level for lk in v.model.links} == {"warning"}
    assert {f.code for f in v.model.findings if f.level == "warning"} >= {"U612"}
    # ... and still the links are drawn in PyBullet's own colours, as raw PyBullet has them.
    c = p.connect(p.DIRECT)
    try:
        body = p.loadURDF(str(path), physicsClientId=c)
        own = {tuple(int(round(x * 255)) for x in row[7][:3])
               for row in p.getVisualShapeData(body, physicsClientId=c)}
    finally:
        p.disconnect(physicsClientId=c)
    page = page_of(v)
    page.get_by_text("Colours: PyBullet's own").wait_for(timeout=10000)  # the legend
    assert page.get_by_text("a link with a warning (Tint findings)").is_visible()
    drawn = {tuple(h.color) for lk in v.model.links for h in v.nodes("visual", lk.name)}
    assert drawn <= own and TINTS["warning"] not in drawn
    # PyBullet's orange (1, 0.423529, 0.039215) is in the picture, and no amber tint.
    orange = next(c for c in own if c[0] > 200 and c[2] < 40)

    def near(rgb: Any, colour: tuple[int, ...], tol: int) -> int:
        return int((np.abs(rgb - np.asarray(colour)).max(axis=2) < tol).sum())

    def shot() -> Any:
        png = page.screenshot(timeout=120000)
        return np.asarray(Image.open(io.BytesIO(png)).convert("RGB")).astype(int)[160:620, :600]

    assert _wait(lambda: near(shot(), orange, 60) > 300, 30)
    # The camera fits the robot: seen through the page's own camera, its box spans at least
    # half the canvas's height or width, and lies wholly inside it.
    client = next(iter(v.server.get_clients().values()))
    assert _wait(lambda: client.camera.update_timestamp > 0, 10)
    lo, hi = v.model.bounds()
    wide, high = _projected_share(client.camera, lo, hi)
    assert max(wide, high) >= 0.5, (wide, high)


def test_the_robot_stands_on_the_grid_and_its_frames_scale_with_it(viewer_of: Any) -> None:
    import pybullet as p
    import pybullet_data

    path = Path(pybullet_data.getDataPath()) / "r2d2.urdf"
    v = viewer_of(path)
    c = p.connect(p.DIRECT)
    try:  # r2d2's lowest point, from PyBullet's own boxes: 0.47 m below its base frame
        body = p.loadURDF(str(path), flags=p.URDF_USE_IMPLICIT_CYLINDER, physicsClientId=c)
        low = min(p.getAABB(body, k, physicsClientId=c)[0][2]
                  for k in range(-1, p.getNumJoints(body, physicsClientId=c)))
    finally:
        p.disconnect(physicsClientId=c)
    assert v.grid.position[2] == pytest.approx(low, abs=1e-6) and low < -0.4
    # Link frames drawn at 15% of the robot's largest side (r2d2: ~1 m), not a fixed size.
    lo, hi = v.model.bounds()
    axes = v.nodes("frames", v.model.links[0].name)[0]
    assert axes.axes_length == pytest.approx(0.15 * max(b - a for a, b in zip(lo, hi,
                                                                          strict=True)))


def test_collision_shapes_are_drawn_just_outside_their_visuals(arm: Path, viewer_of: Any) -> None:
    # The arm's collision boxes are its visual boxes: drawn at the same size, both would
    # z-fight in the collision view. Drawn 0.5% larger about their middle, they do not.
    import numpy as np

    v = viewer_of(arm)
    (visual,) = v.nodes("visual", "upper")
    (collision,) = v.nodes("collision", "upper")
    span = np.ptp(np.asarray(visual.vertices), axis=0)
    assert span == pytest.approx((0.08, 0.08, 0.5), abs=1e-6)
    assert np.ptp(np.asarray(collision.vertices), axis=0) == pytest.approx(span * 1.005,
                                                                           rel=1e-6)
