"""Pictures of a MuJoCo world: ``camera_image`` and ``picture`` of the seam.

MuJoCo draws with OpenGL. Headless (no ``DISPLAY``) :func:`urdfkit.engine.mujoco.import_mujoco`
picks EGL (``MUJOCO_GL=egl``, Mesa's software renderer where there is no GPU) unless the user
set ``MUJOCO_GL`` already; where no OpenGL can be had, the picture is refused with one line
saying so. MuJoCo's free camera keeps +Z up: a :class:`~urdfkit.engine.api.Camera`'s ``up`` is
not used (looking straight down, the picture's up is +X). The visual geoms are drawn (the
export's group 2), not the collision ones.
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING, Any

from urdfkit.core.errors import EngineError

if TYPE_CHECKING:
    from urdfkit.engine.api import Camera, Light, Picture
    from urdfkit.engine.mujoco_world import World


def camera_image(w: World, renderers: dict[tuple[int, int, int], Any], camera: Camera,
                 width: int, height: int) -> bytes:
    """``height`` rows of ``width`` RGB pixels, top row first, seen from ``camera``.

    ``renderers`` keeps one renderer per model and frame size (a recompile makes a new model).
    """
    renderer = _scene(w, renderers, camera, width, height)
    image: Any = renderer.render()
    return bytes(image.tobytes())


def picture(w: World, renderers: dict[tuple[int, int, int], Any], camera: Camera,
            width: int, height: int, light: Light | None) -> Picture:
    """:func:`camera_image`, lit by ``light``, with each pixel's body and the matrices used.

    The camera's ``near`` and ``far`` are MuJoCo's clipping planes for this picture. Each
    pixel's body is from MuJoCo's segmentation pass (a second drawing). The matrices are
    what MuJoCo's ``mjr_render`` sets from the scene's camera (its two eyes averaged,
    ``glFrustum`` over the picture's aspect, ``mjr_lookAt``).
    """
    import numpy as np

    from urdfkit.engine.api import Picture

    m, _ = w.compiled()
    extent = float(m.stat.extent) or 1.0
    clip = float(m.vis.map.znear), float(m.vis.map.zfar)
    m.vis.map.znear, m.vis.map.zfar = camera.near / extent, camera.far / extent
    try:
        renderer = _scene(w, renderers, camera, width, height)
    finally:  # camera_image keeps MuJoCo's own clipping planes
        m.vis.map.znear, m.vis.map.zfar = clip
    scene = renderer.scene
    if light is not None:
        _light(w, scene, camera, light)
    rgb: Any = renderer.render()
    renderer.enable_segmentation_rendering()
    try:
        ids: Any = renderer.render()
    finally:
        renderer.disable_segmentation_rendering()
    geom = int(w.mj.mjtObj.mjOBJ_GEOM)
    owner = np.full(int(m.ngeom) + 1, -1, dtype=np.int64)
    for g, (robot, _) in w.geom_owner.items():
        owner[g] = robot
    hit = (ids[:, :, 1] == geom) & (ids[:, :, 0] >= 0)
    bodies = np.where(hit, owner[np.where(hit, ids[:, :, 0], -1)], -1).astype("<i4")
    view, projection = _matrices(scene, width, height)
    return Picture(width, height, bytes(rgb.tobytes()), bodies.tobytes(), view, projection)


def _matrices(scene: Any, width: int, height: int) -> tuple[tuple[float, ...],
                                                             tuple[float, ...]]:
    """The view and projection matrices ``mjr_render`` draws a mono picture with."""
    import numpy as np

    a, b = scene.camera[0], scene.camera[1]
    eye = (np.asarray(a.pos, dtype=float) + np.asarray(b.pos, dtype=float)) / 2
    forward = (np.asarray(a.forward, dtype=float) + np.asarray(b.forward, dtype=float)) / 2
    up = (np.asarray(a.up, dtype=float) + np.asarray(b.up, dtype=float)) / 2
    f = forward / np.linalg.norm(forward)
    s = np.cross(f, up)
    s = s / np.linalg.norm(s)
    u = np.cross(s, f)
    view = np.eye(4)
    view[0, :3], view[1, :3], view[2, :3] = s, u, -f
    view[:3, 3] = -view[:3, :3] @ eye
    bottom, top = float(a.frustum_bottom), float(a.frustum_top)
    near, far, centre = float(a.frustum_near), float(a.frustum_far), float(a.frustum_center)
    half = 0.5 * width / height * (top - bottom)
    left, right = centre - half, centre + half
    proj = np.zeros((4, 4))
    proj[0, 0], proj[0, 2] = 2 * near / (right - left), (right + left) / (right - left)
    proj[1, 1], proj[1, 2] = 2 * near / (top - bottom), (top + bottom) / (top - bottom)
    proj[2, 2], proj[2, 3] = -(far + near) / (far - near), -2 * far * near / (far - near)
    proj[3, 2] = -1.0
    # column-major, as OpenGL (and PyBullet) lay a matrix out
    return tuple(float(x) for x in view.T.reshape(-1)), \
        tuple(float(x) for x in proj.T.reshape(-1))


def _light(w: World, scene: Any, camera: Camera, light: Light) -> None:
    """The scene's lights replaced by ``light``: directional, from ``direction``.

    A directional light casts its shadows from where it stands: two model extents from the
    camera's target, so that the world lies within the shadow map's depth, which ends at the
    far clipping plane the renderer was made with (a light 12.8 m away, beyond the 10 m of
    its renderer, cast no shadow).
    """
    to_light = [float(x) for x in light.direction]
    norm = math.sqrt(sum(x * x for x in to_light)) or 1.0
    to_light = [x / norm for x in to_light]
    reach = 2 * float(w.m.stat.extent)
    scene.nlight = 1
    lamp = scene.lights[0]
    lamp.type = w.mj.mjtLightType.mjLIGHT_DIRECTIONAL
    lamp.headlight = 0
    lamp.dir[:] = [-x for x in to_light]
    lamp.pos[:] = [t + reach * x for t, x in zip(camera.target, to_light, strict=True)]
    lamp.ambient[:] = (light.ambient,) * 3
    lamp.diffuse[:] = (light.diffuse,) * 3
    lamp.specular[:] = (light.specular,) * 3
    lamp.castshadow = int(light.shadows)


def _scene(w: World, renderers: dict[tuple[int, int, int], Any], camera: Camera, width: int,
           height: int) -> Any:
    """The renderer of this size, its scene updated to what ``camera`` sees now."""
    mj = w.mj
    m, d = w.compiled()
    w.fresh_kinematics()
    key = (id(m), width, height)
    renderer = renderers.get(key)
    if renderer is None:
        for k in [k for k in renderers if k[0] != id(m)]:
            renderers.pop(k).close()
        m.vis.global_.offwidth = max(m.vis.global_.offwidth, width)
        m.vis.global_.offheight = max(m.vis.global_.offheight, height)
        try:
            renderer = mj.Renderer(m, height, width)
        except Exception as e:  # noqa: BLE001 - whatever the GL backend raises, said once
            raise EngineError(f"MuJoCo cannot draw here: no OpenGL ({type(e).__name__}: "
                              f"{str(e).splitlines()[0] if str(e) else 'no context'}); "
                              "headless, set MUJOCO_GL=egl (Mesa's libEGL) or osmesa before "
                              "mujoco is first imported") from None
        renderers[key] = renderer
    eye, target = camera.eye, camera.target
    ahead = [t - e for t, e in zip(target, eye, strict=True)]
    distance = math.sqrt(sum(a * a for a in ahead)) or 1e-9
    view = mj.MjvCamera()
    view.type = mj.mjtCamera.mjCAMERA_FREE
    view.lookat[:] = target
    view.distance = distance
    view.azimuth = math.degrees(math.atan2(ahead[1], ahead[0]))
    view.elevation = math.degrees(math.asin(max(-1.0, min(1.0, ahead[2] / distance))))
    m.vis.global_.fovy = camera.fov
    # the export has no lights: MuJoCo's headlight alone, brighter than its default (0.1
    # ambient, 0.4 diffuse), lights faces turned from the camera too
    m.vis.headlight.ambient[:] = (0.4, 0.4, 0.4)
    m.vis.headlight.diffuse[:] = (0.6, 0.6, 0.6)
    renderer.update_scene(d, camera=view)
    return renderer
