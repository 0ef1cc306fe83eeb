"""Pictures of a MuJoCo world: :meth:`~urdfkit.engine.api.Simulator.camera_image`.

MuJoCo draws with OpenGL. Headless (no ``DISPLAY``) :func:`urdfkit.engine.mujoco.import_mujoco`
picks EGL (``MUJOCO_GL=egl``, Mesa's software renderer where there is no GPU) unless the user
set ``MUJOCO_GL`` already; where no OpenGL can be had, the picture is refused with one line
saying so. MuJoCo's free camera keeps +Z up: a :class:`~urdfkit.engine.api.Camera`'s ``up`` is
not used.
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING, Any

from urdfkit.core.errors import EngineError

if TYPE_CHECKING:
    from urdfkit.engine.api import Camera
    from urdfkit.engine.mujoco_world import World


def camera_image(w: World, renderers: dict[tuple[int, int, int], Any], camera: Camera,
                 width: int, height: int) -> bytes:
    """``height`` rows of ``width`` RGB pixels, top row first, seen from ``camera``.

    ``renderers`` keeps one renderer per model and frame size (a recompile makes a new model).
    """
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
    image: Any = renderer.render()
    return bytes(image.tobytes())
