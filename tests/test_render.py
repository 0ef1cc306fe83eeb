"""urdfkit render: headless TinyRenderer pictures, checked on the pixels they contain."""

from __future__ import annotations

import io
import json
import math
import os
from pathlib import Path

import numpy as np
import pytest
from PIL import Image
from typer.testing import CliRunner

from urdfkit.cli import app
from urdfkit.core.errors import MissingDependencyError, OutputError, ParameterError
from urdfkit.draw import style
from urdfkit.draw.render import (
    ALL_VIEWS,
    Camera,
    RenderOptions,
    frame_view,
    parse_joint_positions,
    parse_size,
    render_file,
    write_png,
)

GOLDEN = Path(__file__).parent / "golden" / "render_simplecar_iso.png"
SMALL = {"width": 320, "height": 240}
WHITE = np.array(style.rgb255(style.BACKGROUND))

runner = CliRunner()


def _shot(path: str | Path, **kw: object) -> np.ndarray:
    opts = {**SMALL, **kw}
    return render_file(path, RenderOptions(**opts)).image  # type: ignore[arg-type]


def _ink(img: np.ndarray) -> np.ndarray:
    """Pixels that are neither background nor grid: the robot (and overlays)."""
    grid = np.array(style.rgb255(style.GRID))
    far_bg = np.abs(img.astype(int) - WHITE).sum(axis=2) > 30
    far_grid = np.abs(img.astype(int) - grid).sum(axis=2) > 30
    return far_bg & far_grid


def _diff(a: np.ndarray, b: np.ndarray) -> float:
    return float(np.abs(a.astype(float) - b.astype(float)).mean())


@pytest.fixture(scope="module")
def car_views(simplecar_urdf: Path) -> dict[str, np.ndarray]:
    return {v: _shot(simplecar_urdf, views=(v,)) for v in ALL_VIEWS}


@pytest.fixture(scope="module")
def r2d2_views() -> dict[str, np.ndarray]:
    return {v: _shot("r2d2.urdf", views=(v,)) for v in ("iso", "top")}


# --------------------------------------------------------------------------- pictures


@pytest.mark.parametrize("robot", ["car", "r2d2"])
def test_image_has_requested_size_and_real_content(robot: str, car_views: dict,
                                                   r2d2_views: dict) -> None:
    views = car_views if robot == "car" else r2d2_views
    for name, img in views.items():
        assert img.shape == (240, 320, 3), name
        assert img.dtype == np.uint8
        # Not blank: many distinct colours (shaded faces, smoothed edges, the grid), a real
        # contrast, and some ink. How much of the frame the robot covers is bounded by
        # geometry, not here: by PyBullet's own segmentation mask and the robot's projected
        # bounding box (test_render_projection.py).
        colours = len(np.unique(img.reshape(-1, 3), axis=0))
        assert colours > 10, (name, colours)
        assert img.std() > 20, (name, img.std())
        assert _ink(img).any(), name


def test_views_differ(car_views: dict, r2d2_views: dict) -> None:
    names = list(car_views)
    for i, a in enumerate(names):
        for b in names[i + 1:]:
            assert _diff(car_views[a], car_views[b]) > 3, (a, b)
    assert _diff(r2d2_views["iso"], r2d2_views["top"]) > 3


def test_robot_is_framed_with_margin(simplecar_urdf: Path) -> None:
    for name in ALL_VIEWS:
        img = _shot(simplecar_urdf, views=(name,), ground="none")
        ys, xs = np.nonzero(_ink(img))
        # The silhouette sits inside the frame, near the middle, not clipped by an edge.
        assert xs.min() > 2 and xs.max() < 317 and ys.min() > 2 and ys.max() < 237, name
        assert abs((xs.min() + xs.max()) / 2 - 160) < 40, name
        assert abs((ys.min() + ys.max()) / 2 - 120) < 40, name


def test_golden_image(simplecar_urdf: Path) -> None:
    img = _shot(simplecar_urdf, width=200, height=150)
    if os.environ.get("URDFKIT_UPDATE_GOLDEN"):
        Image.fromarray(img).save(GOLDEN, optimize=True)
    golden = np.asarray(Image.open(GOLDEN).convert("RGB"))
    assert golden.shape == img.shape
    delta = np.abs(img.astype(int) - golden.astype(int)).max(axis=2)
    # Tolerant of float noise along edges (a software rasteriser can move an edge pixel),
    # strict about anything a regression would change: framing, colours, shading.
    assert delta.mean() < 1.5, delta.mean()
    assert (delta > 48).mean() < 0.01, (delta > 48).mean()


def _project(cam: Camera, points: list[tuple[float, float, float]]
             ) -> tuple[np.ndarray, np.ndarray]:
    """Pixel x, y of world points, with a reported camera and PyBullet's own matrices."""
    from urdfkit.engine.session import import_pybullet

    p = import_pybullet()
    view = np.array(p.computeViewMatrix(cam.eye, cam.target, cam.up)).reshape(4, 4).T
    proj = np.array(p.computeProjectionMatrixFOV(cam.fov_deg, 320 / 240, 0.01, 100)
                    ).reshape(4, 4).T
    clip = np.array([[*pt, 1.0] for pt in points]) @ (proj @ view).T
    return (clip[:, 0] / clip[:, 3] + 1) / 2 * 320, (1 - clip[:, 1] / clip[:, 3]) / 2 * 240


def test_camera_metadata_reproduces_the_projection(tmp_path: Path) -> None:
    """A plain box seen from the top: its top face, projected with the reported camera,
    must coincide with the box's pixels (so --frames and the grid land where TinyRenderer
    draws)."""

    box = tmp_path / "box.urdf"
    box.write_text('<robot name="box"><link name="b"><visual><geometry><box size="0.4 0.2 0.1"/>'
                   '</geometry><material name="r"><color rgba="0.8 0.1 0.1 1"/></material>'
                   '</visual><collision><geometry><box size="0.4 0.2 0.1"/></geometry>'
                   '</collision></link></robot>')
    r = render_file(box, RenderOptions(views=("top",), ground="none", **SMALL))
    px, py = _project(r.cameras[0], [(x, y, 0.05) for x in (-0.2, 0.2) for y in (-0.1, 0.1)])
    ys, xs = np.nonzero(_ink(r.image))
    assert abs(xs.min() - px.min()) < 2.5 and abs(xs.max() + 1 - px.max()) < 2.5
    assert abs(ys.min() - py.min()) < 2.5 and abs(ys.max() + 1 - py.max()) < 2.5
    # The top view puts the robot's front (+x) up: the 0.4 m side is vertical.
    assert ys.max() - ys.min() > 1.5 * (xs.max() - xs.min())


def test_views_all_is_a_labelled_grid(simplecar_urdf: Path) -> None:
    r = render_file(simplecar_urdf, RenderOptions(views=ALL_VIEWS, width=400, height=300))
    assert r.image.shape == (300, 400, 3)
    assert [c.view for c in r.cameras] == list(ALL_VIEWS)
    assert [c.panel for c in r.cameras] == [(0, 0, 200, 150), (200, 0, 200, 150),
                                            (0, 150, 200, 150), (200, 150, 200, 150)]
    panels = [r.image[t:t + h, left:left + w] for left, t, w, h in (c.panel for c in r.cameras)]
    for i in range(4):
        assert _ink(panels[i]).mean() > 0.03
        for j in range(i + 1, 4):
            assert _diff(panels[i], panels[j]) > 3
    # Each panel carries its label top left, and only there.
    bare = render_file(simplecar_urdf, RenderOptions(views=ALL_VIEWS, width=400, height=300,
                                                     labels=False)).image
    changed = np.abs(r.image.astype(int) - bare).max(axis=2) > 60
    for left, top, w, h in (c.panel for c in r.cameras):
        assert changed[top:top + 30, left:left + 60].sum() > 10
        assert changed[top + 30:top + h, left:left + w].sum() == 0


def test_joints_pose_the_robot(simplecar_urdf: Path, car_views: dict) -> None:
    r = render_file(simplecar_urdf, RenderOptions(
        joints={"base_to_left_hinge": 0.5, "base_to_right_hinge": 0.5}, **SMALL))
    assert r.joints == {"base_to_left_hinge": 0.5, "base_to_right_hinge": 0.5}
    assert r.warnings == []
    assert _diff(r.image, car_views["iso"]) > 0.5


def test_joint_beyond_limits_warns(simplecar_urdf: Path) -> None:
    r = render_file(simplecar_urdf, RenderOptions(joints={"base_to_left_hinge": 2.0}, **SMALL))
    assert any("base_to_left_hinge" in w and "limits" in w for w in r.warnings)


def test_unknown_or_fixed_joint_is_refused(simplecar_urdf: Path) -> None:
    with pytest.raises(ParameterError, match="no joint named 'nope'.*base_to_left_hinge"):
        render_file(simplecar_urdf, RenderOptions(joints={"nope": 1.0}, **SMALL))
    with pytest.raises(ParameterError, match="fixed joint"):
        render_file("r2d2.urdf", RenderOptions(joints={"base_to_right_leg": 1.0}, **SMALL))


def test_collision_draws_collision_geometry() -> None:
    """r2d2's base is a visual cylinder of radius 0.2 but a collision cylinder of 0.17."""
    front = {"views": ("front",), "ground": "none"}
    visual = render_file("r2d2.urdf", RenderOptions(**front, **SMALL))  # type: ignore[arg-type]
    coll = render_file("r2d2.urdf", RenderOptions(collision=True, **front, **SMALL))  # type: ignore[arg-type]
    assert coll.collision and not visual.collision
    # Collision shapes are painted in the collision colour (orange: red > green > blue).
    ink = _ink(coll.image)
    mean = coll.image[ink].astype(float).mean(axis=0)
    assert mean[0] > mean[1] > mean[2], mean
    # r2d2's visual has blue and white; its collision picture has neither.
    blue = (visual.image[..., 2].astype(int) - visual.image[..., 0] > 100).sum()
    assert blue > 500
    assert (coll.image[..., 2].astype(int) - coll.image[..., 0] > 100).sum() == 0


def test_frames_draw_rgb_axes(simplecar_urdf: Path, car_views: dict) -> None:
    img = _shot(simplecar_urdf, frames=True)
    assert _diff(img, car_views["iso"]) > 0.3
    red = (img[..., 0] > 170) & (img[..., 1] < 90) & (img[..., 2] < 90)
    green = (img[..., 1] > 120) & (img[..., 0] < 110) & (img[..., 2] < 110)
    for mask in (red, green):
        assert mask.sum() > 15
    plain = car_views["iso"]
    assert ((plain[..., 0] > 170) & (plain[..., 1] < 90) & (plain[..., 2] < 90)).sum() == 0


def test_ground_options(simplecar_urdf: Path, car_views: dict) -> None:
    plane = _shot(simplecar_urdf, ground="plane")
    none = _shot(simplecar_urdf, ground="none")
    grid = car_views["iso"]
    assert _diff(plane, grid) > 3
    # Without ground everything that is not the robot is pure background.
    assert (np.abs(none.astype(int) - WHITE).sum(axis=2) == 0).mean() > 0.3
    grid_colour = np.array(style.rgb255(style.GRID))
    on_grid = (np.abs(grid.astype(int) - grid_colour).sum(axis=2) < 20).sum()
    on_none = (np.abs(none.astype(int) - grid_colour).sum(axis=2) < 20).sum()
    # Without ground, grid-grey pixels are only a few of the robot's (its darkened outline).
    assert on_grid > 200 and on_none < on_grid / 10, (on_grid, on_none)


def test_xacro_input_with_args(tmp_path: Path) -> None:
    xacro = Path(__file__).parents[1] / "templates" / "simplecar.urdf.xacro"
    r = render_file(xacro, RenderOptions(**SMALL), xacro_args=["wheel_radius:=0.2"])
    # Bigger wheels: the wheels (radius 0.2, axles at the body's height) now set the height,
    # 2 r, plus PyBullet's 1 mm collision margin above and below: 0.402 m, exactly.
    assert r.aabb[1][2] - r.aabb[0][2] == pytest.approx(2 * 0.2 + 2 * 0.001, abs=1e-9)


def test_frame_view_fits_every_corner() -> None:
    lo, hi = (-1.0, -0.2, 0.0), (1.0, 0.2, 0.3)
    for view in ALL_VIEWS:
        eye, target, up = frame_view(view, lo, hi, 4 / 3)
        forward = (target - eye) / np.linalg.norm(target - eye)
        right = np.cross(forward, up)
        half_v = math.tan(math.radians(15))
        for x in (lo[0], hi[0]):
            for y in (lo[1], hi[1]):
                for z in (lo[2], hi[2]):
                    rel = np.array([x, y, z]) - eye
                    depth = rel @ forward
                    assert depth > 0
                    assert abs(rel @ up) / depth <= half_v + 1e-9
                    assert abs(rel @ right) / depth <= half_v * 4 / 3 + 1e-9


# --------------------------------------------------------------------------- options


def test_parse_size_and_joints() -> None:
    assert parse_size("640x480") == (640, 480)
    assert parse_size("640X480") == (640, 480)
    for bad in ("640", "x480", "axb", ""):
        with pytest.raises(ParameterError, match="`size`"):
            parse_size(bad)
    assert parse_joint_positions(["a=1", "b=-0.5,c=2e-1"]) == {"a": 1.0, "b": -0.5, "c": 0.2}
    with pytest.raises(ParameterError, match="not a number"):
        parse_joint_positions(["a=fast"])
    with pytest.raises(ParameterError):
        parse_joint_positions(["a"])


@pytest.mark.parametrize("kw, match", [
    ({"views": ("diagonal",)}, "unknown view"),
    ({"views": ("iso", "top")}, "four"),
    ({"width": 8}, "16..8192"),
    ({"ground": "lava"}, "unknown `ground`"),
    ({"joints": {"a": math.nan}}, "finite"),
])
def test_bad_options(kw: dict, match: str) -> None:
    with pytest.raises(ParameterError, match=match):
        RenderOptions(**kw)


def test_missing_pillow_says_what_to_install(monkeypatch: pytest.MonkeyPatch,
                                            simplecar_urdf: Path) -> None:
    import sys

    monkeypatch.setitem(sys.modules, "PIL", None)  # makes `from PIL import ...` fail
    with pytest.raises(MissingDependencyError,
                           match=r"reinstall it: pip install --force-reinstall pillow"):
        render_file(simplecar_urdf, RenderOptions(**SMALL))


# --------------------------------------------------------------------------- writing


def test_write_png_atomic_and_refuses_overwrite(simplecar_urdf: Path, tmp_path: Path) -> None:
    r = render_file(simplecar_urdf, RenderOptions(**SMALL))
    out = write_png(r, tmp_path / "car.png")
    with Image.open(out) as im:
        assert im.format == "PNG" and im.size == (320, 240)
        assert np.array_equal(np.asarray(im.convert("RGB")), r.image)
    before = out.read_bytes()
    with pytest.raises(OutputError, match="`force=True`"):
        write_png(r, out)
    assert out.read_bytes() == before
    write_png(r, out, force=True)
    with pytest.raises(OutputError, match="PNG"):
        write_png(r, tmp_path / "car.jpg")
    assert sorted(p.name for p in tmp_path.iterdir()) == ["car.png"]  # no temp files left


# --------------------------------------------------------------------------- CLI


def test_cli_render_writes_png(simplecar_urdf: Path, tmp_path: Path) -> None:
    out = tmp_path / "car.png"
    res = runner.invoke(app, ["render", str(simplecar_urdf), "-o", str(out), "--size", "240x180",
                              "--views", "all", "--frames", "-j", "base_to_left_hinge=0.3"])
    assert res.exit_code == 0, res.output
    assert "wrote" in res.output
    with Image.open(out) as im:
        assert im.size == (240, 180)
    res = runner.invoke(app, ["render", str(simplecar_urdf), "-o", str(out)])
    assert res.exit_code == 2
    assert "exists; pass --force" in res.output and str(out) in res.output


def test_cli_render_json_and_stdout(simplecar_urdf: Path, tmp_path: Path) -> None:
    out = tmp_path / "car.png"
    res = runner.invoke(app, ["render", str(simplecar_urdf), "-o", str(out), "--size", "160x120",
                              "--json", "--view", "side"])
    assert res.exit_code == 0, res.output
    data = json.loads(res.stdout)
    assert data["output"] == str(out) and data["robot"] == "simplecar"
    assert (data["width"], data["height"]) == (160, 120)
    assert [v["view"] for v in data["views"]] == ["side"]
    assert data["aabb"]["min"][2] < 0 < data["aabb"]["max"][2]
    res = runner.invoke(app, ["render", str(simplecar_urdf), "-o", "-", "--size", "160x120"])
    assert res.exit_code == 0
    with Image.open(io.BytesIO(res.stdout_bytes)) as im:
        assert im.size == (160, 120)


def test_cli_render_pybullet_data_name_default_output(tmp_path: Path,
                                                      monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.chdir(tmp_path)
    res = runner.invoke(app, ["render", "r2d2.urdf", "--size", "160x120", "--collision"])
    assert res.exit_code == 0, res.output
    assert (tmp_path / "r2d2.png").is_file()


_TWO = ("<robot name='x'><link name='a'><visual><geometry><box size='.1 .1 .1'/></geometry>"
        "</visual></link><link name='b'/><joint name='j' type='revolute'><parent link='a'/>"
        "<child link='b'/>{}<limit lower='-1' upper='1' effort='1' velocity='1'/></joint>"
        "</robot>")


@pytest.mark.parametrize("content, expect", [
    (None, "no such file"),
    ("<robot name='x'><link name='a'>", "not well-formed XML"),
    ("<robot name='x'><link name='a'/><link name='b'/></robot>", "root links"),
    ("", "empty"),
    # PyBullet puts link b at NaN; the link frames cannot be drawn (check: U401, U305)
    (_TWO.format("<origin xyz='nan 0 0'/><axis xyz='0 0 1'/>"),
     "<origin xyz='nan 0 0'> is not a finite vector; no frame can be placed with it"),
    (_TWO.format("<axis xyz='0 0 0'/>"), "joint 'j' has a zero axis"),
])
def test_cli_render_bad_files(tmp_path: Path, content: str | None, expect: str) -> None:
    bad = tmp_path / "bad.urdf"
    if content is not None:
        bad.write_text(content)
    res = runner.invoke(app, ["render", str(bad), "-o", str(tmp_path / "out.png")])
    assert res.exit_code == 2
    assert expect in res.output and "bad.urdf" in res.output
    assert "Traceback" not in res.output
    assert not (tmp_path / "out.png").exists()


def test_cli_render_bad_options(simplecar_urdf: Path, tmp_path: Path) -> None:
    for args, expect in [
        (["--size", "big"], "--size"),
        (["--view", "diagonal"], "unknown view"),
        (["-j", "nope=1"], "no joint named 'nope'"),
        (["-o", str(tmp_path / "car.jpg")], "PNG"),
        (["--views", "iso,top"], "four"),
    ]:
        argv = ["render", str(simplecar_urdf), *args]
        if "-o" not in args:
            argv += ["-o", str(tmp_path / "x.png")]
        res = runner.invoke(app, argv)
        assert res.exit_code == 2, args
        assert expect in res.output, (args, res.output)
    assert not list(tmp_path.iterdir())


def test_visual_only_links_are_framed(tmp_path: Path) -> None:
    """getAABB knows collision shapes only; a visual-only robot must still be in the picture."""
    path = tmp_path / "visual_only.urdf"
    path.write_text('<robot name="v"><link name="a"><visual><origin xyz="1 0 0"/><geometry>'
                    '<box size="0.5 0.5 0.5"/></geometry></visual></link></robot>')
    r = render_file(path, RenderOptions(ground="none", **SMALL))
    assert r.warnings == []
    assert r.aabb[1][0] >= 1.25
    ys, xs = np.nonzero(_ink(r.image))
    assert len(xs) > 1000
    assert xs.min() > 2 and xs.max() < 317 and ys.min() > 2 and ys.max() < 237


def test_nothing_visible_warns(tmp_path: Path) -> None:
    path = tmp_path / "bare.urdf"
    path.write_text('<robot name="e"><link name="a"/></robot>')
    r = render_file(path, RenderOptions(**SMALL))
    assert any("no shape" in w for w in r.warnings)


def test_visual_bounds_match_pybullet_aabb(tmp_path: Path) -> None:
    """Our box around primitive visuals equals PyBullet's getAABB of identical collisions."""
    from lxml import etree

    from urdfkit.draw.render import _visual_bounds
    from urdfkit.engine.session import LoadOptions, Session
    from urdfkit.formats.fk import link_frames
    from urdfkit.formats.robot import read_robot

    shapes = ['<box size="0.4 0.1 0.2"/>', '<cylinder radius="0.1" length="0.5"/>',
              '<sphere radius="0.15"/>']
    links, joints = [], []
    for i, (shape, rpy) in enumerate(zip(shapes, ["0.3 0.7 -0.4", "1.1 -0.2 0.5", "0 0 0"],
                                         strict=True)):
        body = f'<origin xyz="0.1 -0.2 0.05" rpy="{rpy}"/><geometry>{shape}</geometry>'
        links.append(f'<link name="l{i}"><visual>{body}</visual><collision>{body}</collision>'
                     '</link>')
        if i:
            joints.append(f'<joint name="j{i}" type="revolute"><parent link="l{i - 1}"/>'
                          f'<child link="l{i}"/><origin xyz="0.5 0 0.3" rpy="0 0.4 0.9"/>'
                          '<axis xyz="0 1 0"/><limit lower="-1" upper="1" effort="1" '
                          'velocity="1"/></joint>')
    path = tmp_path / "shapes.urdf"
    path.write_text(f'<robot name="s">{"".join(links)}{"".join(joints)}</robot>')
    with Session() as s:
        body = s.load_urdf(path, LoadOptions(fixed_base=True))
        s.p.resetJointState(body, 1, 0.6, physicsClientId=s.client)
        root = etree.parse(str(path)).getroot()
        frames = link_frames(read_robot(root, str(path)), {"j2": 0.6})
        ours = [_visual_bounds(root, {f"l{i}": (frames[f"l{i}"][:3, 3], frames[f"l{i}"][:3, :3])})
                for i in range(3)]
        boxes = [s.p.getAABB(body, link, physicsClientId=s.client) for link in (-1, 0, 1)]
    # Bullet bounds a shape in a turned link by turning the shape's own box, so its AABB is
    # exact only where the link frame is not rotated (l0) and loose elsewhere; it also pads
    # every box with a collision margin of a few millimetres.
    assert np.allclose(ours[0][0], boxes[0][0], atol=0.006), (ours[0], boxes[0])
    assert np.allclose(ours[0][1], boxes[0][1], atol=0.006), (ours[0], boxes[0])
    for (lo, hi), (b_lo, b_hi) in zip(ours, boxes, strict=True):
        assert np.all(lo >= np.array(b_lo) - 1e-9) and np.all(hi <= np.array(b_hi) + 1e-9)
    # The sphere looks the same from every side: same centre, and exactly 2 r wide.
    lo, hi = ours[2]
    assert np.allclose((lo + hi) / 2, (np.array(boxes[2][0]) + boxes[2][1]) / 2, atol=1e-6)
    assert np.allclose(hi - lo, 0.3)


def test_up_axis_stands_a_y_up_model_upright(tmp_path: Path) -> None:
    # A tower modelled Y-up (as CAD and graphics exports are) lies down unless told.
    urdf = tmp_path / "tower.urdf"
    urdf.write_text('<robot name="tower"><link name="a"><inertial><mass value="1"/><inertia '
                    'ixx="0.1" ixy="0" ixz="0" iyy="0.1" iyz="0" izz="0.1"/></inertial>'
                    '<visual><geometry><box size="0.1 1 0.1"/></geometry></visual><collision>'
                    '<geometry><box size="0.1 1 0.1"/></geometry></collision></link></robot>')
    sizes = {}
    for up in ("z", "y", "x"):
        picture = render_file(urdf, RenderOptions(**{**SMALL, "up": up}))
        lo, hi = picture.aabb
        sizes[up] = [round(h - lo_, 3) for lo_, h in zip(lo, hi, strict=True)]
    assert sizes["z"] == [0.1, 1.0, 0.1]  # as written: along y, lying on the ground
    assert sizes["y"] == [0.1, 0.1, 1.0]  # stood up: its +y is the world's +z
    assert sizes["x"] == [0.1, 1.0, 0.1]  # its x is short: turning x up changes little here
    with pytest.raises(ParameterError, match="`up` must be one of z, y, x"):
        RenderOptions(up="w")


def test_a_white_robot_keeps_its_shape_on_the_white_background(tmp_path: Path) -> None:
    """A white box's lit top face is as white as the background; only the outline keeps it:
    the inked pixels must reach the top corner of the box, projected with the camera."""

    urdf = tmp_path / "white.urdf"
    urdf.write_text('<robot name="w"><material name="white"><color rgba="1 1 1 1"/></material>'
                    '<link name="a"><visual><geometry><box size="0.5 0.5 0.5"/></geometry>'
                    '<material name="white"/></visual><collision><geometry><box '
                    'size="0.5 0.5 0.5"/></geometry></collision></link></robot>')
    r = render_file(urdf, RenderOptions(ground="none", **SMALL))
    _, py = _project(r.cameras[0], [(x, y, 0.25) for x in (-0.25, 0.25) for y in (-0.25, 0.25)])
    highest = py.min()
    ys, _ = np.nonzero(np.abs(r.image.astype(int) - WHITE).sum(axis=2) > 60)
    assert abs(ys.min() - highest) < 3, (ys.min(), highest)


@pytest.mark.parametrize("name", ["kuka_iiwa/model.urdf", "r2d2.urdf", "humanoid/humanoid.urdf",
                                  "quadruped/minitaur.urdf", "franka_panda/panda.urdf",
                                  "bicycle/bike.urdf", "quadruped/microtaur/microtaur.urdf",
                                  "husky/husky.urdf"])
def test_link_frames_equal_getlinkstate(name: str) -> None:
    """Forward kinematics from the file, no state query (which fails from 128 links): every
    frame must equal getLinkState's URDF link frame, posed and turned (1e-6: PyBullet reports
    link states rounded to float32). bike, microtaur and husky hold attributes that are not
    plain numbers, read as PyBullet reads them (render's own kinematics, before it used
    formats/fk.py, read them as 0 and put microtaur's links 2 m off)."""
    from urdfkit.draw.render import link_frames
    from urdfkit.engine.api import LoadSettings
    from urdfkit.engine.pybullet import PyBulletEngine
    from urdfkit.model.spec import UP_AXES, quat_to_matrix
    from urdfkit.sources.resolve import open_input

    settings = LoadSettings(fixed_base=True, position=(0.3, -0.2, 0.1), orientation=UP_AXES["y"])
    rng = np.random.default_rng(3)
    e = PyBulletEngine()
    try:
        with open_input(name, guard=False) as res:
            body = e.load(str(res.load_path), settings)
            joints = e.joints(body)
            positions = {}
            for j in joints:
                if j.kind in ("revolute", "prismatic"):
                    positions[j.name] = float(rng.uniform(-1, 1))
                    e.bullet.resetJointState(body, j.index, positions[j.name])
            frames = link_frames(res, joints, settings, positions)
        assert len(frames) == len(joints) + 1
        for j, (pos, rot) in enumerate(frames[1:]):
            st = e.bullet.getLinkState(body, j, computeForwardKinematics=True)
            assert np.allclose(pos, st[4], atol=1e-6), (name, j)
            assert np.allclose(rot, np.array(quat_to_matrix(st[5])), atol=1e-6), (name, j)
    finally:
        e.close()


def test_a_planar_joint_is_drawn_where_pybullet_puts_its_child(tmp_path: Path) -> None:
    """A planar joint (which the MJCF export refuses) holds its child at its origin, as
    PyBullet does at rest; the revolute joint below it turns the link after it."""
    from urdfkit.draw.render import link_frames
    from urdfkit.engine.api import LoadSettings
    from urdfkit.engine.pybullet import PyBulletEngine
    from urdfkit.model.spec import quat_to_matrix
    from urdfkit.sources.resolve import open_input

    box = "<visual><geometry><box size='0.1 0.1 0.1'/></geometry></visual>"
    path = tmp_path / "planar.urdf"
    path.write_text(
        f"<robot name='p'><link name='a'>{box}</link><link name='b'>{box}</link>"
        f"<link name='c'>{box}</link><joint name='slide' type='planar'><parent link='a'/>"
        "<child link='b'/><origin xyz='0.1 0 0.2' rpy='0 0 0.3'/><axis xyz='0 0 1'/></joint>"
        "<joint name='turn' type='revolute'><parent link='b'/><child link='c'/>"
        "<origin xyz='0 0 0.15' rpy='0.2 0 0'/><axis xyz='0 0 1'/>"
        "<limit lower='-2' upper='2' effort='1' velocity='1'/></joint></robot>")
    settings = LoadSettings(fixed_base=True)
    e = PyBulletEngine()
    try:
        with open_input(str(path)) as res:
            body = e.load(str(res.load_path), settings)
            joints = e.joints(body)
            assert [j.kind for j in joints] == ["planar", "revolute"]
            e.reset_joint(body, 1, 0.8)
            frames = link_frames(res, joints, settings, {"turn": 0.8})
        for j, (pos, rot) in enumerate(frames[1:]):
            st = e.bullet.getLinkState(body, j, computeForwardKinematics=True)
            assert np.allclose(pos, st[4], atol=1e-6) and \
                np.allclose(rot, np.array(quat_to_matrix(st[5])), atol=1e-6), j
    finally:
        e.close()
    result = CliRunner().invoke(app, ["render", str(path), "--frames", "--joints", "turn=0.8",
                                      "-o", str(tmp_path / "p.png"), "--size", "160x120"])
    assert result.exit_code == 0, result.output


def test_render_draws_a_body_of_130_links(tmp_path: Path) -> None:
    # getLinkState fails from 128 links; render does not need it.
    links = ['<link name="l0"><visual><geometry><box size="0.1 0.1 0.1"/></geometry></visual>'
             '</link>']
    joints = []
    for i in range(1, 130):
        links.append(f'<link name="l{i}"><visual><geometry><box size="0.05 0.05 0.05"/>'
                     '</geometry></visual></link>')
        joints.append(f'<joint name="j{i}" type="revolute"><parent link="l{i - 1}"/>'
                      f'<child link="l{i}"/><origin xyz="0.06 0 0" rpy="0 0 0.05"/>'
                      '<axis xyz="0 0 1"/><limit lower="-1" upper="1" effort="1" velocity="1"/>'
                      '</joint>')
    path = tmp_path / "chain.urdf"
    path.write_text('<robot name="c">\n' + "\n".join(links + joints) + "\n</robot>\n")
    out = tmp_path / "chain.png"
    result = CliRunner().invoke(app, ["render", str(path), "-o", str(out), "--size", "320x240",
                                      "--joints", "j3=0.5"])
    assert result.exit_code == 0, result.stderr
    image = np.asarray(Image.open(out).convert("RGB"))
    assert (np.abs(image.astype(int) - WHITE).sum(axis=2) > 60).sum() > 200  # drawn, not blank
