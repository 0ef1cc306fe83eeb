"""What the seam gives the rooms that draw: pictures, visual shapes, mesh files, a ball joint.

Each runs on both engines and is held to geometry (where a cube must appear in a picture,
which face a light lights, where a turned ball joint puts its child) and, on PyBullet, to the
raw calls ``render``, ``collisions`` and the viewer made before they spoke to the seam.
"""

from __future__ import annotations

import math
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import numpy as np
import pytest

from urdfkit.engine.api import Camera, Light, LoadSettings, Picture
from urdfkit.engine.registry import open_engine
from urdfkit.sources.resolve import open_input

ENGINES = ["pybullet", "mujoco"]
CUBE = """<robot name="cube"><link name="cube"><inertial><mass value="2"/>
<inertia ixx="0.01" ixy="0" ixz="0" iyy="0.01" iyz="0" izz="0.01"/></inertial>
<visual><geometry><box size="0.2 0.2 0.2"/></geometry>
<material name="red"><color rgba="0.8 0.2 0.2 1"/></material></visual>
<collision><geometry><box size="0.2 0.2 0.2"/></geometry></collision></link></robot>"""
SLAB = """<robot name="slab"><link name="slab"><visual><geometry><box size="2 2 0.02"/>
</geometry><material name="grey"><color rgba="0.9 0.9 0.9 1"/></material></visual></link>
</robot>"""
BALL = """<robot name="ball"><link name="base"><inertial><mass value="1"/>
<inertia ixx="0.01" ixy="0" ixz="0" iyy="0.01" iyz="0" izz="0.01"/></inertial></link>
<link name="arm"><inertial><origin xyz="0.2 0 0"/><mass value="1"/>
<inertia ixx="0.01" ixy="0" ixz="0" iyy="0.01" iyz="0" izz="0.01"/></inertial>
<collision><origin xyz="0.2 0 0"/><geometry><box size="0.4 0.05 0.05"/></geometry></collision>
</link><joint name="ball" type="spherical"><parent link="base"/><child link="arm"/>
<origin xyz="0 0 0.5"/></joint></robot>"""
W, H = 160, 120


@pytest.fixture(params=ENGINES)
def engine(request: pytest.FixtureRequest) -> Iterator[Any]:
    e = open_engine(request.param)
    try:
        yield e
    finally:
        e.close()


def _file(tmp_path: Path, name: str, text: str) -> str:
    path = tmp_path / name
    path.write_text(text)
    return str(path)


def _pixels(pic: Picture, points: Any) -> Any:
    """World points as (x, y) pixels, by the picture's own matrices."""
    m = np.array(pic.projection).reshape(4, 4).T @ np.array(pic.view).reshape(4, 4).T
    c = np.c_[np.asarray(points, dtype=float), np.ones(len(points))] @ m.T
    return np.c_[(c[:, 0] / c[:, 3] + 1) / 2 * pic.width, (1 - c[:, 1] / c[:, 3]) / 2 * pic.height]


def _arrays(pic: Picture) -> tuple[Any, Any]:
    rgb = np.frombuffer(pic.rgb, np.uint8).reshape(pic.height, pic.width, 3).astype(int)
    return rgb, np.frombuffer(pic.bodies, "<i4").reshape(pic.height, pic.width)


SLANT = Camera((1.5, -1.0, 1.0), (0.3, 0.1, 0.2), fov=40.0, near=0.5, far=5.0)
ABOVE = Camera((0.3, 0.1, 3.0), (0.3, 0.1, 0.2), up=(1.0, 0.0, 0.0), fov=30.0, near=0.5,
               far=5.0)


@pytest.mark.parametrize("camera", [SLANT, ABOVE], ids=["slant", "above"])
def test_a_picture_shows_the_cube_where_its_matrices_put_it(engine: Any, tmp_path: Path,
                                                          camera: Camera) -> None:
    """The pixels marked with the cube's body lie within a pixel of its eight corners'
    projection through the picture's matrices, and are red; no other body is marked."""
    cube = engine.load(_file(tmp_path, "cube.urdf", CUBE),
                       LoadSettings(fixed_base=True, position=(0.3, 0.1, 0.2)))
    pic = engine.picture(camera, W, H, Light((1.0, -0.5, 2.0)))
    rgb, bodies = _arrays(pic)
    assert (pic.width, pic.height, len(pic.view), len(pic.projection)) == (W, H, 16, 16)
    assert set(np.unique(bodies)) == {-1, cube}
    corners = [(0.3 + x, 0.1 + y, 0.2 + z) for x in (-0.1, 0.1) for y in (-0.1, 0.1)
               for z in (-0.1, 0.1)]
    px = _pixels(pic, corners)
    ys, xs = np.nonzero(bodies == cube)
    assert xs.min() == pytest.approx(px[:, 0].min(), abs=1.0)
    assert xs.max() + 1 == pytest.approx(px[:, 0].max(), abs=1.0)
    assert ys.min() == pytest.approx(px[:, 1].min(), abs=1.0)
    assert ys.max() + 1 == pytest.approx(px[:, 1].max(), abs=1.0)
    red = rgb[bodies == cube]
    assert np.all(red[:, 0] > red[:, 1] + 20) and np.all(red[:, 0] > red[:, 2] + 20)


def test_pybullets_picture_is_the_getcameraimage_render_made(tmp_path: Path) -> None:
    """The calls render made before the seam: computeViewMatrix, computeProjectionMatrixFOV,
    getCameraImage with the TinyRenderer and the light's four settings; the same bytes."""
    from urdfkit.engine.pybullet import PyBulletEngine

    e = PyBulletEngine()
    try:
        e.load(_file(tmp_path, "cube.urdf", CUBE), LoadSettings(fixed_base=True))
        b, p = e.bullet, e.session.p
        camera = Camera((1.2, -0.9, 0.7), (0.0, 0.0, 0.0), (0.0, 0.0, 1.0), 35.0, 0.3, 4.0)
        light = Light((0.4, -1.0, 0.8), 0.55, 0.5, 0.05, shadows=True)
        pic = e.picture(camera, W, H, light)
        view = b.computeViewMatrix([1.2, -0.9, 0.7], [0.0, 0.0, 0.0], [0.0, 0.0, 1.0])
        proj = b.computeProjectionMatrixFOV(35.0, W / H, 0.3, 4.0)
        raw = b.getCameraImage(W, H, list(view), list(proj), renderer=p.ER_TINY_RENDERER,
                               lightDirection=[0.4, -1.0, 0.8], shadow=1,
                               lightAmbientCoeff=0.55, lightDiffuseCoeff=0.5,
                               lightSpecularCoeff=0.05)
        assert (pic.view, pic.projection) == (tuple(view), tuple(proj))
        assert pic.rgb == np.asarray(raw[2], np.uint8).reshape(H, W, 4)[:, :, :3].tobytes()
        assert pic.bodies == np.asarray(raw[4], "<i4").tobytes()
        # without a light: PyBullet's own, as camera_image draws
        assert e.picture(camera, W, H).rgb == e.camera_image(camera, W, H)
    finally:
        e.close()


def test_the_light_lights_the_face_turned_to_it(engine: Any, tmp_path: Path) -> None:
    """The cube's +x face, seen from the slant, is brighter lit from +x than from -x."""
    engine.load(_file(tmp_path, "cube.urdf", CUBE),
                LoadSettings(fixed_base=True, position=(0.3, 0.1, 0.2)))
    seen = []
    for direction in ((1.0, 0.0, 0.3), (-1.0, 0.0, 0.3)):
        pic = engine.picture(SLANT, W, H, Light(direction, 0.4, 0.6, 0.0))
        rgb, _ = _arrays(pic)
        x, y = _pixels(pic, [(0.4, 0.1, 0.2)])[0]
        seen.append(int(rgb[int(y), int(x)].sum()))
    assert seen[0] > seen[1] + 100, seen


def test_shadows(engine: Any, tmp_path: Path) -> None:
    """A light from above with shadows: MuJoCo darkens the slab under the cube; PyBullet's
    TinyRenderer draws a different picture (its shadows are its own: the flag reaches it)."""
    engine.load(_file(tmp_path, "cube.urdf", CUBE),
                LoadSettings(fixed_base=True, position=(0.0, 0.0, 0.4)))
    slab = engine.load(_file(tmp_path, "slab.urdf", SLAB),
                       LoadSettings(fixed_base=True, position=(0.0, 0.0, -0.01)))
    camera = Camera((2.0, -2.0, 2.0), (0.0, 0.0, 0.2), fov=40.0, near=0.5, far=10.0)
    pictures = [engine.picture(camera, 200, 150, Light((0.3, 0.2, 1.0), 0.4, 0.6, 0.0,
                                                       shadows=on)) for on in (False, True)]
    assert pictures[0].rgb != pictures[1].rgb
    if engine.name == "mujoco":
        (lit, bodies), (shaded, _) = (_arrays(p) for p in pictures)
        x, y = _pixels(pictures[0], [(-0.12, -0.08, 0.0)])[0].astype(int)
        assert bodies[y, x] == slab
        assert shaded[y, x].sum() < lit[y, x].sum() - 100


def test_visual_shapes_are_pybullets_getvisualshapedata() -> None:
    from urdfkit.engine.pybullet import PyBulletEngine

    e = PyBulletEngine()
    try:
        with open_input("r2d2.urdf") as res:
            body = e.load(str(res.load_path), LoadSettings())
        raw = e.bullet.getVisualShapeData(body)
        shapes = e.visual_shapes(body)
        assert len(shapes) == len(raw) == 16
        for s, v in zip(shapes, raw, strict=True):
            assert (s.link, s.dimensions, s.position, s.orientation, s.rgba) == \
                (v[1], v[3], v[5], v[6], v[7])
            assert s.filename == (v[4].decode() if v[2] == e.session.p.GEOM_MESH else "")
    finally:
        e.close()


@pytest.mark.parametrize("name", ["kuka_iiwa/model.urdf", "r2d2.urdf"])
def test_visual_shapes_agree_between_the_engines(name: str) -> None:
    """Links, kinds, dimensions, mesh files and frames in the link frame (1e-7: PyBullet's
    are float32), and kuka's colours, which it names in each <visual> (r2d2 reuses a
    material named in an earlier <visual>, which PyBullet follows and the export does not)."""
    tables = []
    with open_input(name) as res:
        for engine in ENGINES:
            e = open_engine(engine)
            try:
                tables.append(e.visual_shapes(e.load(str(res.load_path), LoadSettings())))
            finally:
                e.close()
    bullet, mujoco = tables
    assert len(bullet) == len(mujoco) > 5
    for a, b in zip(bullet, mujoco, strict=True):
        assert (a.link, a.kind, a.filename) == (b.link, b.kind, b.filename)
        assert list(a.dimensions) == pytest.approx(list(b.dimensions), abs=1e-7)
        assert a.position == pytest.approx(b.position, abs=1e-7)
        dot = abs(sum(x * y for x, y in zip(a.orientation, b.orientation, strict=True)))
        assert dot == pytest.approx(1.0, abs=1e-7)
        if name.startswith("kuka"):
            assert a.rgba == pytest.approx(b.rgba, abs=1e-7)
    assert {s.kind for s in bullet} >= ({"mesh"} if name.startswith("kuka") else
                                         {"box", "cylinder", "sphere", "mesh"})


def test_collision_meshes_name_their_files(engine: Any) -> None:
    """kuka_iiwa's collision meshes: each is the file its <collision> names."""
    from lxml import etree

    with open_input("kuka_iiwa/model.urdf") as res:
        body = engine.load(str(res.load_path), LoadSettings(fixed_base=True))
        root = etree.parse(str(res.load_path)).getroot()
        written = {link.get("name"): [m.get("filename") for m in
                                      link.iterfind("collision/geometry/mesh")]
                   for link in root.iter("link")}
        names = engine.link_names(body)
        for k, name in enumerate(names):
            files = [s.filename for s in engine.collision_shapes(body, k - 1)]
            assert [Path(f).name for f in files] == [Path(f).name for f in written[name]]
            assert all(Path(f).is_file() for f in files)
    assert engine.collision_shapes(body, 0)[0].filename.endswith("meshes/link_1.stl")


def test_a_spherical_joint_turns_its_child(engine: Any, tmp_path: Path) -> None:
    """The ball joint turned 90 degrees about z, then about x: the arm's frame is turned
    so (1e-6: PyBullet's frames are float32)."""
    body = engine.load(_file(tmp_path, "ball.urdf", BALL), LoadSettings(fixed_base=True))
    s = math.sqrt(0.5)
    for q in ((0.0, 0.0, s, s), (s, 0.0, 0.0, s)):
        engine.reset_spherical_joint(body, 0, q)
        at, turn = engine.link_frame(body, 0)
        assert at == pytest.approx((0.0, 0.0, 0.5), abs=1e-6)
        dot = abs(sum(a * b for a, b in zip(turn, q, strict=True)))
        assert dot == pytest.approx(1.0, abs=1e-6)


def test_drawing_collision_shapes_is_pybullets_alone(tmp_path: Path) -> None:
    """render --collision's load: PyBullet draws the <collision> shapes in the colour given
    (the cube's red visual is not drawn); MuJoCo is refused, naming the option."""
    from urdfkit.core.errors import ParameterError
    from urdfkit.engine.pybullet_render import load_drawing_collisions

    path = _file(tmp_path, "cube.urdf", CUBE.replace(
        '<collision><geometry><box size="0.2 0.2 0.2"/>',
        '<collision><geometry><sphere radius="0.1"/>'))
    e = open_engine("pybullet")
    try:
        body = load_drawing_collisions(e, path, LoadSettings(fixed_base=True), "cube",
                                       (0.0, 0.0, 1.0, 1.0))
        assert [(s.kind, s.rgba) for s in e.visual_shapes(body)] == \
            [("sphere", (0.0, 0.0, 1.0, 1.0))]
        rgb, bodies = _arrays(e.picture(Camera((0.6, -0.6, 0.4), (0.0, 0.0, 0.0), fov=40.0,
                                               near=0.1, far=3.0), W, H))
        blue = rgb[bodies == body]
        assert len(blue) > 100 and np.all(blue[:, 2] > blue[:, 0] + 20)
    finally:
        e.close()
    m = open_engine("mujoco")
    try:
        with pytest.raises(ParameterError, match="`collision`: drawing the collision shapes "
                                                 "needs PyBullet's TinyRenderer, not MuJoCo"):
            load_drawing_collisions(m, path, LoadSettings(fixed_base=True), "cube",
                                    (0.0, 0.0, 1.0, 1.0))
    finally:
        m.close()
