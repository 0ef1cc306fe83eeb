"""``urdfkit render``: draw a robot headless to a PNG with PyBullet's TinyRenderer.

The robot is loaded in PyBullet (DIRECT) through the engine seam (:mod:`urdfkit.engine.api`)
and drawn with its ``picture``: ``getCameraImage(renderer=ER_TINY_RENDERER)``, PyBullet's CPU
rasteriser: no GPU, no display, no OpenGL context, so it works the same on a laptop and on a
CI machine.

What TinyRenderer does and does not do, measured on PyBullet 3.2.7, decides the design:

- It draws *visual* shapes only. Loading with ``URDF_IGNORE_VISUAL_SHAPES`` makes PyBullet
  build the visual shapes from the ``<collision>`` elements instead (r2d2's base then draws
  with the collision radius 0.17, not the visual 0.2), all white. That is the honest way to
  show collision geometry, so ``collision=True`` loads that way and recolours every shape
  (PyBullet's alone: :func:`urdfkit.engine.pybullet_render.load_drawing_collisions`).
- It ignores ``addUserDebugLine`` (those are GUI-only; the image does not change by a single
  pixel). Ground grid, link frames and joint axes are therefore projected here with the view
  and projection matrices the picture was drawn with and drawn with Pillow; the link frames
  are the file's forward kinematics (:func:`urdfkit.formats.fk.link_frames`), which needs no
  state query (those fail from 128 links).
- It does not antialias. We render at :data:`SUPERSAMPLE` times the size and average each
  block of pixels down, which costs about 0.25 s at 800x600 and makes edges and lines smooth.
- The segmentation mask tells robot pixels from background exactly, so the drawn grid can go
  *behind* the robot: it is painted only where the mask says background (or ground plane).

Camera framing is computed in closed form from the robot's axis-aligned bounding box, after
posing: the union of ``getAABB`` over all links (collision shapes only) and of the primitive
visuals' world boxes. The distance is the smallest at which all eight corners fit the frustum
with a margin, then the target is shifted to centre them.
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Literal

from urdfkit.core.errors import EngineError, InputError, MissingDependencyError, ParameterError
from urdfkit.draw import style
from urdfkit.engine.api import Camera as EngineCamera
from urdfkit.engine.api import JointInfo, Light, LoadSettings, Simulator
from urdfkit.model.spec import UP_AXES, UpAxis, attr_vec, rpy_to_matrix, vector

#: The views, as (direction from target to camera, camera up vector). URDF: x forward, z up.
#: ``front`` looks at the robot's face (+x), ``side`` at its right flank (-y), so the robot
#: drives to the right of the image; ``top`` looks down with the front pointing up.
#: A camera direction: ``--view``.
View = Literal["iso", "front", "side", "top"]
#: What the robot stands on in the picture: ``--ground``.
Ground = Literal["grid", "plane", "none"]
VIEWS: dict[View, tuple[tuple[float, float, float], tuple[float, float, float]]] = {
    "iso": ((math.cos(math.radians(30)) * math.cos(math.radians(-40)),
             math.cos(math.radians(30)) * math.sin(math.radians(-40)),
             math.sin(math.radians(30))), (0.0, 0.0, 1.0)),
    "front": ((1.0, 0.0, 0.0), (0.0, 0.0, 1.0)),
    "side": ((0.0, -1.0, 0.0), (0.0, 0.0, 1.0)),
    "top": ((0.0, 0.0, 1.0), (1.0, 0.0, 0.0)),
}
#: Order of the panels of ``--views all``: a 2x2 grid.
ALL_VIEWS: tuple[View, ...] = ("iso", "front", "side", "top")
#: Views drawn as an engineering drawing: parallel edges stay parallel, a length reads the same
#: at the front and the back of the robot (perspective only in ``iso``).
ORTHO_VIEWS: tuple[View, ...] = ("front", "side", "top")
GROUNDS: tuple[Ground, ...] = ("grid", "plane", "none")
#: The largest robot (bounding-box side, m) render frames: beyond, camera distances and grid
#: steps overflow or lose all precision (a 1e308 m box once ended in an OverflowError).
MAX_EXTENT = 1e5
#: Render this many times larger, then downsample: TinyRenderer has no antialiasing.
SUPERSAMPLE = 2
#: Vertical field of view in degrees; narrow enough that perspective does not distort.
FOV_DEG = 30.0
#: The field of view of :data:`ORTHO_VIEWS`: a telephoto lens from far away (573 frame
#: heights), so the robot's back is drawn smaller than its front by its depth over 573 frame
#: heights: 0.35% for a robot twice as deep as the frame is high. PyBullet has no orthographic lens,
#: and TinyRenderer draws nothing through a glOrtho matrix (measured: 0 pixels of a cube it
#: draws 121 of in perspective).
ORTHO_FOV_DEG = 0.1
#: Fraction of the frame the robot's bounding box may fill.
FILL = 0.82
#: Colour of collision shapes (``collision=True``): the secondary accent, unlike any visual.
COLLISION_COLOR = style.SECONDARY
#: Joint-axis arrows (``frames=True``).
JOINT_AXIS_COLOR = style.END


@dataclass(frozen=True)
class RenderOptions:
    """What to draw and how.

    Attributes:
        views: View names from :data:`VIEWS`; four views make a labelled 2x2 grid.
        width: Image width in pixels.
        height: Image height in pixels.
        ground: ``grid`` (drawn lines behind the robot), ``plane`` (a shaded ground slab in
            the scene, with the robot's shadow) or ``none``.
        joints: Joint name to position (rad or m), set with ``resetJointState`` before the shot.
        collision: Draw the collision shapes instead of the visuals.
        frames: Mark link frames (RGB = xyz) and joint axes.
        labels: Write the view name into each panel (default: only for several views).
        up: The model's up axis (``z``, ``y`` or ``x``); it is turned onto the world's +Z.
    """

    views: tuple[View, ...] = ("iso",)
    width: int = 800
    height: int = 600
    ground: Ground = "grid"
    joints: Mapping[str, float] = field(default_factory=dict)
    collision: bool = False
    frames: bool = False
    labels: bool | None = None
    up: UpAxis = "z"

    def __post_init__(self) -> None:
        if self.up not in UP_AXES:
            raise ParameterError(f"`up` must be one of {', '.join(UP_AXES)}, got {self.up!r}",
                                 param="up")
        if not self.views:
            raise ParameterError("no view given")
        for v in self.views:
            if v not in VIEWS:
                from urdfkit.core.suggest import hint

                raise ParameterError(f"unknown view {v!r}{hint(v, VIEWS)} (choose from "
                                     f"{', '.join(VIEWS)})", param="views")
        if len(self.views) not in (1, 4):
            raise ParameterError("give one view, or four for a 2x2 grid (`views`)",
                                 param="views")
        if not (16 <= self.width <= 8192 and 16 <= self.height <= 8192):
            raise ParameterError(f"`size` {self.width}x{self.height}: each side must be "
                                 "16..8192 pixels", param="size")
        if self.ground not in GROUNDS:
            raise ParameterError(f"unknown `ground` {self.ground!r}; choose from "
                                 f"{', '.join(GROUNDS)}")
        for name, value in self.joints.items():
            if not math.isfinite(value):
                raise ParameterError(f"`joints` {name}: position must be a finite number",
                                     param="joints")


@dataclass
class Camera:
    """Where one view's camera stands (for the metadata, and to reproduce a shot)."""

    view: View
    eye: tuple[float, float, float]
    target: tuple[float, float, float]
    up: tuple[float, float, float]
    fov_deg: float
    #: The panel in the final image: (left, top, width, height) in pixels.
    panel: tuple[int, int, int, int]


@dataclass
class Rendering:
    """A rendered picture and what it shows.

    Attributes:
        image: ``height x width x 3`` uint8 RGB array.
        robot: The robot's name attribute.
        source: The file as the user named it.
        cameras: One per view.
        aabb: The robot's bounding box (min xyz, max xyz) as posed, in metres.
        joints: The joint positions that were set.
        collision: Whether collision shapes were drawn.
        warnings: Things the user should know (joint beyond its limits, nothing visible...).
    """

    image: Any
    robot: str
    source: str
    cameras: list[Camera]
    aabb: tuple[tuple[float, float, float], tuple[float, float, float]]
    joints: dict[str, float] = field(default_factory=dict)
    collision: bool = False
    warnings: list[str] = field(default_factory=list)

    @property
    def width(self) -> int:
        """Image width in pixels."""
        return int(self.image.shape[1])

    @property
    def height(self) -> int:
        """Image height in pixels."""
        return int(self.image.shape[0])

    def to_dict(self) -> dict[str, Any]:
        """The JSON form (without the pixels)."""
        return {
            "robot": self.robot, "source": self.source, "width": self.width,
            "height": self.height, "collision": self.collision,
            "aabb": {"min": list(self.aabb[0]), "max": list(self.aabb[1])},
            "joints": self.joints,
            "views": [{"view": c.view, "eye": list(c.eye), "target": list(c.target),
                       "up": list(c.up), "fov_deg": c.fov_deg, "panel": list(c.panel)}
                      for c in self.cameras],
            "warnings": self.warnings,
        }

    def png_bytes(self) -> bytes:
        """The image encoded as PNG (deterministic: Pillow writes no timestamp)."""
        Image = _pillow()
        import io

        buf = io.BytesIO()
        Image.fromarray(self.image, "RGB").save(buf, format="PNG")
        return buf.getvalue()


def _pillow() -> Any:
    try:
        from PIL import Image
    except ImportError as e:
        raise MissingDependencyError(
            "rendering needs Pillow, which urdfkit installs; reinstall it: "
            "pip install --force-reinstall pillow") from e
    return Image


def parse_size(text: str) -> tuple[int, int]:
    """Parse ``WxH`` (e.g. ``800x600``)."""
    w, sep, h = text.lower().partition("x")
    try:
        if not sep:
            raise ValueError
        return int(w), int(h)
    except ValueError:
        raise ParameterError(f"`size` expects WIDTHxHEIGHT such as 800x600, got {text!r}",
                             param="size") from None


def parse_joint_positions(items: Sequence[str] | None) -> dict[str, float]:
    """Parse repeated ``--joints name=value`` (value in rad or m); ``a=1,b=2`` works too."""
    from urdfkit.model.catalog import parse_assignments

    flat = [part for item in items or [] for part in item.split(",") if part.strip()]
    out: dict[str, float] = {}
    for name, value in parse_assignments(flat, "joints").items():
        try:
            out[name] = float(value)
        except ValueError:
            raise ParameterError(f"`joints` {name}: {value!r} is not a number",
                                 param="joints") from None
    return out


# --------------------------------------------------------------------------- geometry


def _basis(view: View) -> tuple[Any, Any, Any]:
    """(towards camera, right, up) unit vectors of a view."""
    from urdfkit.draw.framing import basis

    return basis(*VIEWS[view])


def frame_view(view: View, lo: Sequence[float], hi: Sequence[float], aspect: float,
               fov_deg: float = FOV_DEG, fill: float = FILL) -> tuple[Any, Any, Any]:
    """Place a camera so the box ``lo..hi`` fills the frame; return (eye, target, up).

    :func:`urdfkit.draw.framing.fit_box` from the view's direction (the page's camera fits
    the same way).
    """
    from urdfkit.draw.framing import fit_box

    return fit_box(_basis(view), lo, hi, aspect, fov_deg, fill)


def view_fov(view: str) -> float:
    """The vertical field of view a view is shot with (see :data:`ORTHO_FOV_DEG`)."""
    return ORTHO_FOV_DEG if view in ORTHO_VIEWS else FOV_DEG


class Projector:
    """Project world points to pixels exactly as TinyRenderer does (column-major matrices)."""

    def __init__(self, view: Sequence[float], proj: Sequence[float], width: int, height: int,
                 near: float):
        import numpy as np

        self.m = np.array(proj, dtype=float).reshape(4, 4).T @ \
            np.array(view, dtype=float).reshape(4, 4).T
        self.width = width
        self.height = height
        self.near = near

    def clip(self, pts: Any) -> Any:
        """Homogeneous clip coordinates of world points (N x 3 -> N x 4)."""
        import numpy as np

        pts = np.atleast_2d(np.asarray(pts, dtype=float))
        return np.c_[pts, np.ones(len(pts))] @ self.m.T

    def pixels(self, clip: Any) -> Any:
        """Clip coordinates to pixel (x, y), y down."""
        import numpy as np

        ndc = clip[:, :2] / clip[:, 3:4]
        return np.c_[(ndc[:, 0] + 1) / 2 * self.width, (1 - ndc[:, 1]) / 2 * self.height]

    def segment(self, a: Sequence[float], b: Sequence[float]) -> tuple[float, ...] | None:
        """A 3D segment as pixel endpoints, clipped to in front of the camera (or None)."""
        import numpy as np

        ca, cb = self.clip([a, b])
        # w is the distance along the view axis; cut the part behind the near plane, where
        # the perspective divide would flip it across the image.
        wa, wb = ca[3], cb[3]
        if wa < self.near and wb < self.near:
            return None
        if wa < self.near:
            ca = ca + (cb - ca) * (self.near - wa) / (wb - wa)
        elif wb < self.near:
            cb = cb + (ca - cb) * (self.near - wb) / (wa - wb)
        (x0, y0), (x1, y1) = self.pixels(np.array([ca, cb]))
        return float(x0), float(y0), float(x1), float(y1)


def _nice_step(span: float, lines: int = 10) -> float:
    """A round grid spacing (1, 2 or 5 x 10^k) giving about ``lines`` lines over ``span``."""
    raw = max(span, 1e-6) / lines
    k = 10 ** math.floor(math.log10(raw))
    for m in (1, 2, 5, 10):
        if raw <= m * k:
            return m * k
    return 10 * k  # pragma: no cover - the loop always returns


# --------------------------------------------------------------------------- the engine


@dataclass
class _Scene:
    """A loaded, posed robot and what the drawing needs to know about it."""

    engine: Simulator
    body: int
    lo: Any
    hi: Any
    frames: list[tuple[Any, Any]]  # (position, 3x3 rotation) of every link frame
    axes: list[tuple[Any, Any]]  # (position, world axis) of every movable joint
    plane: int | None = None


def _load(resolved: Any, engine: Simulator, o: RenderOptions, warnings: list[str]) -> _Scene:
    import numpy as np

    from urdfkit.engine.joints import pose_by_name
    from urdfkit.model.spec import quat_to_matrix

    # Fixed base: nothing is simulated, and the robot must stay exactly where it is posed.
    settings = LoadSettings(fixed_base=True, orientation=UP_AXES[o.up])
    if o.collision:
        # Make TinyRenderer draw the collision shapes (see the module docstring).
        from urdfkit.engine.pybullet_render import load_drawing_collisions

        body = load_drawing_collisions(engine, str(resolved.load_path), settings,
                                       resolved.name, (*COLLISION_COLOR, 1.0))
    else:
        body = engine.load(str(resolved.load_path), settings, display=resolved.name)
    try:
        joints = engine.joints(body)
        positions = pose_by_name(engine, body, joints, o.joints, warnings, resolved.name)
        lo = np.full(3, np.inf)
        hi = np.full(3, -np.inf)
        for link in range(-1, len(joints)):
            box = engine.aabb(body, link)
            a, b = np.array(box[0]), np.array(box[1])
            # A link without collision shapes reports an empty or inverted box; skip it.
            if np.all(np.isfinite(a)) and np.all(np.isfinite(b)) and np.all(b >= a):
                lo, hi = np.minimum(lo, a), np.maximum(hi, b)
        frames = link_frames(resolved, joints, settings, positions)
        for pos, _ in frames:
            lo, hi = np.minimum(lo, pos), np.maximum(hi, pos)
        if not o.collision:
            # getAABB only knows collision shapes; a link with visuals only (common in
            # hand-written files) would fall outside the frame. Bound its visuals too.
            names = engine.link_names(body)
            v_lo, v_hi = _visual_bounds(resolved.root, dict(zip(names, frames, strict=True)))
            lo, hi = np.minimum(lo, v_lo), np.maximum(hi, v_hi)
        axes = []
        for j in joints:
            if j.kind not in ("revolute", "prismatic"):
                continue
            pos, rot = frames[j.index + 1]
            # The engine's axis is in the child's inertial frame: turn it into the link frame.
            local = engine.dynamics(body, j.index).inertial_orientation
            inertial = np.array(quat_to_matrix(local), dtype=float)
            axes.append((pos, rot @ inertial @ np.array(j.axis, dtype=float)))
    except engine.error as e:
        raise EngineError(f"{engine.label} cannot report this body's state ({e})",
                          file=resolved.name) from None
    extent = float(np.max(hi - lo)) if np.all(np.isfinite(lo)) and np.all(np.isfinite(hi)) \
        else math.inf
    if not extent <= MAX_EXTENT:  # also catches NaN
        raise InputError(f"the robot spans {extent:.3g} m as loaded, too large to frame and "
                         f"draw (at most {MAX_EXTENT:g} m); check its sizes and origins "
                         "(urdfkit check)", file=resolved.name)
    return _Scene(engine, body, lo, hi, frames, axes)


def _visual_bounds(root: Any, frames: Mapping[str, tuple[Any, Any]]) -> tuple[Any, Any]:
    """The world box around every primitive ``<visual>``, from the file and the posed frames.

    Exact for boxes, cylinders and spheres. Meshes are skipped: their size is only known after
    loading them, and nearly all mesh links have collision shapes that getAABB covers.
    """
    import numpy as np

    lo, hi = np.full(3, np.inf), np.full(3, -np.inf)
    for link in root.iter("link"):
        frame = frames.get(link.get("name", ""))
        if frame is None:
            continue
        for visual in link.iter("visual"):
            origin = visual.find("origin")
            xyz = attr_vec(origin, "xyz", 3, (0, 0, 0))
            rpy = attr_vec(origin, "rpy", 3, (0, 0, 0))
            rot = frame[1] @ np.array(rpy_to_matrix(rpy))  # type: ignore[arg-type]
            half = _half_extent(visual.find("geometry"), rot)
            if half is None:
                continue
            centre = frame[0] + frame[1] @ np.array(xyz)
            lo, hi = np.minimum(lo, centre - half), np.maximum(hi, centre + half)
    return lo, hi


def _half_extent(geometry: Any, rot: Any) -> Any:
    """Half the world-axis extent of a primitive shape turned by ``rot`` (None: unknown)."""
    import numpy as np

    if geometry is None:
        return None
    from urdfkit.model.spec import used_shape

    shape = used_shape(geometry)  # what PyBullet draws: the first element
    box, cyl, sphere = (shape if shape is not None and shape.tag == tag else None
                        for tag in ("box", "cylinder", "sphere"))
    if box is not None:
        size = vector(box.get("size"), 3)
        return np.abs(rot) @ (np.abs(size) / 2) if size else None
    if cyl is not None:
        r, length = vector(cyl.get("radius"), 1), vector(cyl.get("length"), 1)
        if not (r and length):
            return None
        # A disc of radius r around the axis a reaches r * sqrt(1 - a_i^2) along world axis i;
        # the axis adds half the length times |a_i|.
        a = rot[:, 2]
        return abs(r[0]) * np.sqrt(np.clip(1 - a * a, 0, 1)) + abs(length[0]) / 2 * np.abs(a)
    if sphere is not None:
        r = vector(sphere.get("radius"), 1)
        return np.full(3, abs(r[0])) if r else None
    return None


def link_frames(resolved: Any, joints: Sequence[JointInfo], settings: LoadSettings,
                positions: Mapping[str, float]) -> list[tuple[Any, Any]]:
    """World pose (position, 3x3 rotation) of every link frame, root first, in ``joints``' order.

    :func:`urdfkit.formats.fk.link_frames` of the file, with no state query, so it works on
    bodies of 128 links or more, where getLinkState fails: the root's link frame where the body
    was loaded (``settings``), each joint at its position in ``positions`` (others 0), link
    ``j`` the child of ``joints[j]``. Equal to getLinkState's worldLinkFrame
    (tests/test_render.py).
    """
    import numpy as np

    from urdfkit.formats.fk import link_frames as forward
    from urdfkit.formats.robot import read_robot
    from urdfkit.model.spec import quat_to_matrix

    robot = read_robot(resolved.root, resolved.name, planar=True)
    base = np.eye(4)
    base[:3, :3] = quat_to_matrix(settings.orientation)
    base[:3, 3] = settings.position
    frames = forward(robot, positions, base)
    return [(frames[name][:3, 3], frames[name][:3, :3])
            for name in [robot.root] + [j.link for j in joints]]


def _add_plane(scene: _Scene) -> int:
    """A ground slab under the robot in the style's ground colour, to catch its shadow.

    A box that is seen and does not collide, written as a URDF and loaded as scenery (the
    picture is PyBullet's createVisualShape and createMultiBody of it to the pixel, measured
    on r2d2, kuka_iiwa and racecar in four views).
    """
    import tempfile

    import numpy as np

    size = float(np.max(scene.hi - scene.lo))
    half = float(max(scene.hi[0] - scene.lo[0], scene.hi[1] - scene.lo[1])) * 1.5 + size
    thick = size * 0.01
    centre = (scene.lo + scene.hi) / 2
    rgba = " ".join(repr(float(x)) for x in (*style.GROUND, 1.0))
    urdf = (f'<robot name="ground"><link name="ground"><visual><geometry><box size="'
            f'{2 * half!r} {2 * half!r} {2 * thick!r}"/></geometry><material name="ground">'
            f'<color rgba="{rgba}"/></material></visual></link></robot>')
    with tempfile.TemporaryDirectory(prefix="urdfkit-ground-") as folder:
        path = Path(folder) / "ground.urdf"
        path.write_text(urdf, "utf-8")
        return scene.engine.load(str(path), LoadSettings(
            fixed_base=True, scenery=True, position=(float(centre[0]), float(centre[1]),
                                                     float(scene.lo[2]) - thick)))


def _shoot(scene: _Scene, view: View, width: int, height: int, o: RenderOptions,
           scale: int) -> tuple[Any, Camera, bool]:
    """Render one view at ``width x height`` (already supersampled) with its overlays."""
    import numpy as np

    Image = _pillow()
    from PIL import ImageDraw

    aspect = width / height
    fov = view_fov(view)
    eye, target, up = frame_view(view, scene.lo, scene.hi, aspect, fov_deg=fov)
    dist = float(np.linalg.norm(eye - target))
    radius = float(np.linalg.norm(scene.hi - scene.lo)) / 2
    near = max(dist - 3 * radius, dist * 0.02)
    far = dist + 8 * radius + 1.0
    back, right, _ = _basis(view)
    # Light from over the viewer's left shoulder, so faces turned to the camera are lit.
    light = back + up * 0.9 - right * 0.6
    shot = scene.engine.picture(
        EngineCamera(_floats(eye), _floats(target), _floats(up), fov, near, far), width, height,
        Light(_floats(light), ambient=0.55, diffuse=0.5, specular=0.05,
              shadows=scene.plane is not None))
    rgb = np.frombuffer(shot.rgb, dtype=np.uint8).reshape(height, width, 3)
    seg = np.frombuffer(shot.bodies, dtype="<i4").reshape(height, width)
    robot = seg == scene.body
    proj = Projector(shot.view, shot.projection, width, height, near)

    canvas = Image.new("RGB", (width, height), style.rgb255(style.BACKGROUND))
    if scene.plane is not None:
        canvas = Image.fromarray(np.where((seg >= 0)[..., None], rgb,
                                          np.array(style.rgb255(style.BACKGROUND),
                                                   dtype=np.uint8)).astype(np.uint8), "RGB")
    if o.ground != "none":
        grid = canvas.copy()
        _draw_grid(ImageDraw.Draw(grid), proj, scene, scale)
        # Paint the grid only where the robot is not: it lies under the robot, which stands
        # on the ground, so the robot always hides it and never the other way round.
        behind = ~robot if scene.plane is None else seg == scene.plane
        canvas = Image.composite(grid, canvas, Image.fromarray((behind * 255).astype(np.uint8)))
    canvas.paste(Image.fromarray(_outlined(rgb, robot, scale), "RGB"), mask=Image.fromarray(
        (robot * 255).astype(np.uint8)))
    if o.frames:
        _draw_frames(ImageDraw.Draw(canvas), proj, scene, scale)
    camera = Camera(view, tuple(float(x) for x in eye),  # type: ignore[arg-type]
                    tuple(float(x) for x in target), tuple(float(x) for x in up),  # type: ignore[arg-type]
                    fov, (0, 0, 0, 0))
    return canvas, camera, bool(robot.any())


def _floats(v: Any) -> tuple[float, float, float]:
    return float(v[0]), float(v[1]), float(v[2])


def _outlined(rgb: Any, robot: Any, scale: int) -> Any:
    """The robot's pixels with its silhouette drawn darker, ``scale`` pixels wide.

    A white or light robot's lit faces match a white background (a white box loses its top
    face); the outline, in the robot's own colour darkened, keeps any robot's shape readable
    on any background, and costs a few array shifts.
    """
    import numpy as np

    inside = robot.copy()
    for _ in range(max(1, scale)):  # erode: a pixel stays inside if its 4 neighbours do
        shrunk = inside.copy()
        shrunk[1:, :] &= inside[:-1, :]
        shrunk[:-1, :] &= inside[1:, :]
        shrunk[:, 1:] &= inside[:, :-1]
        shrunk[:, :-1] &= inside[:, 1:]
        inside = shrunk
    edge = robot & ~inside
    out = rgb.copy()
    out[edge] = (rgb[edge].astype(np.uint16) * 11 // 20).astype(np.uint8)
    return out


def _draw_grid(draw: Any, proj: Projector, scene: _Scene, scale: int) -> None:
    extent = scene.hi - scene.lo
    size = float(max(extent[0], extent[1], extent[2] * 0.5, 1e-3))
    centre = (scene.lo + scene.hi) / 2
    half = size * 1.25
    step = _nice_step(2 * half)
    z = float(scene.lo[2])
    x0 = math.floor((centre[0] - half) / step) * step
    y0 = math.floor((centre[1] - half) / step) * step
    nx = int(math.ceil(2 * half / step)) + 1
    ny = int(math.ceil(2 * half / step)) + 1
    x1, y1 = x0 + (nx - 1) * step, y0 + (ny - 1) * step
    color = style.rgb255(style.GRID)
    width = max(1, scale)
    for i in range(nx):
        x = x0 + i * step
        seg = proj.segment((x, y0, z), (x, y1, z))
        if seg:
            draw.line(seg, fill=color, width=width)
    for i in range(ny):
        y = y0 + i * step
        seg = proj.segment((x0, y, z), (x1, y, z))
        if seg:
            draw.line(seg, fill=color, width=width)


def _draw_frames(draw: Any, proj: Projector, scene: _Scene, scale: int) -> None:
    import numpy as np

    size = float(np.max(scene.hi - scene.lo))
    length = size * 0.12
    # About 2 px at 800x600 (in final pixels), thicker for big pictures.
    width = scale * max(1, round(max(proj.width, proj.height) / scale / 400))
    for pos, axis in scene.axes:
        seg = proj.segment(pos, pos + axis * length * 1.6)
        if seg:
            draw.line(seg, fill=style.rgb255(JOINT_AXIS_COLOR), width=width + scale)
            r = width + scale
            draw.ellipse((seg[2] - r, seg[3] - r, seg[2] + r, seg[3] + r),
                         fill=style.rgb255(JOINT_AXIS_COLOR))
    for pos, rot in scene.frames:
        for k, color in enumerate((style.AXIS_X, style.AXIS_Y, style.AXIS_Z)):
            seg = proj.segment(pos, pos + rot[:, k] * length)
            if seg:
                draw.line(seg, fill=style.rgb255(color), width=width)


def _font(size: int) -> Any:
    from PIL import ImageFont

    # The style's family (DejaVu Sans) as a file Pillow can find in the system font folders;
    # Pillow's own scalable default font when it is not installed.
    name = style.FONT_FAMILY.replace(" ", "") + ".ttf"
    try:
        return ImageFont.truetype(name, size)
    except OSError:
        return ImageFont.load_default(size)


def render(resolved: Any, options: RenderOptions | None = None) -> Rendering:
    """Render a resolved (guarded) URDF; see :class:`RenderOptions`.

    Args:
        resolved: A :class:`urdfkit.sources.resolve.Resolved` from
        :func:`urdfkit.sources.resolve.open_input`.
        options: What to draw; the default is one iso view at 800x600 with a ground grid.
    """
    import numpy as np

    from urdfkit.engine.registry import open_engine

    o = options or RenderOptions()
    Image = _pillow()
    from PIL import ImageDraw

    warnings: list[str] = []
    tiled = len(o.views) == 4
    cols, rows = (2, 2) if tiled else (1, 1)
    panel_w, panel_h = o.width // cols, o.height // rows
    ss = SUPERSAMPLE
    out = Image.new("RGB", (o.width * ss, o.height * ss), style.rgb255(style.BACKGROUND))
    cameras: list[Camera] = []
    visible = False
    engine = open_engine("pybullet")
    try:
        scene = _load(resolved, engine, o, warnings)
        if not np.all(np.isfinite(scene.lo)):
            raise EngineError("nothing to draw: no link has a shape", file=resolved.name)
        if o.ground == "plane":
            scene.plane = _add_plane(scene)
        for k, view in enumerate(o.views):
            col, row = k % cols, k // cols
            img, cam, seen = _shoot(scene, view, panel_w * ss, panel_h * ss, o, ss)
            visible = visible or seen
            left, top = col * panel_w, row * panel_h
            out.paste(img, (left * ss, top * ss))
            cam.panel = (left, top, panel_w, panel_h)
            cameras.append(cam)
    finally:
        engine.close()
    if not visible:
        warnings.append("no shape of the robot is visible in the picture"
                        + ("" if o.collision else "; try --collision"))
    draw = ImageDraw.Draw(out)
    labels = tiled if o.labels is None else o.labels
    if labels:
        font = _font(max(10, round(min(panel_w, panel_h) / 22)) * ss)
        for cam in cameras:
            left, top, _, _ = cam.panel
            draw.text(((left + 10) * ss, (top + 8) * ss), cam.view, fill=style.rgb255(style.TEXT),
                      font=font)
    if tiled:
        line = style.rgb255(style.GRID)
        draw.line((panel_w * ss, 0, panel_w * ss, o.height * ss), fill=line, width=ss)
        draw.line((0, panel_h * ss, o.width * ss, panel_h * ss), fill=line, width=ss)
    # A box filter over each ss x ss block: plain supersampling, and 10x cheaper than Lanczos.
    final = out.reduce(ss)
    lo, hi = scene.lo, scene.hi
    return Rendering(
        image=np.asarray(final, dtype=np.uint8).copy(), robot=resolved.robot_name,
        source=resolved.name, cameras=cameras,
        aabb=(tuple(float(x) for x in lo), tuple(float(x) for x in hi)),  # type: ignore[arg-type]
        joints=dict(o.joints), collision=o.collision, warnings=warnings)


def render_file(name: str | Path, options: RenderOptions | None = None, *,
                packages: list[str] | None = None,
                xacro_args: list[str] | None = None, guard: bool = True,
                package_paths: list[str] | None = None) -> Rendering:
    """Resolve (xacro, package://, pybullet_data, guard) and render a robot file.

    ``guard=False`` lifts the guard's stricter-than-PyBullet refusals; they come back as
    warnings of the rendering.
    """
    from urdfkit.sources.resolve import open_input

    _pillow()  # fail before expanding xacro when Pillow is missing
    with open_input(name, packages=packages, xacro_args=xacro_args, guard=guard,
                    package_paths=package_paths) as resolved:
        picture = render(resolved, options)
        picture.warnings[:0] = resolved.warnings
        if options is None or not options.collision:
            from urdfkit.sources.resolve import undrawn_note

            note = undrawn_note(resolved)
            if note is not None:
                picture.warnings.append(note)
        return picture


def check_picture_path(path: str | Path, *, force: bool = False) -> Path:
    """Refuse an output path early: not ``*.png``, or an existing file without ``force``.

    The CLI calls this before rendering, so a refused path costs nothing.
    """
    from urdfkit.core.output import check_output as check

    return check(path, force=force, suffixes=(".png",), what="the picture (urdfkit render "
                 "writes PNG)")


def write_png(rendering: Rendering, path: str | Path, *, force: bool = False) -> Path:
    """Write the picture atomically; refuses to replace a file unless ``force``."""
    path = check_picture_path(path, force=force)
    from urdfkit.core.output import atomic_write

    return atomic_write(path, rendering.png_bytes(), force=force)
