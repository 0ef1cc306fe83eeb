"""PyBullet's shapes and pictures behind the seam: a part of :class:`PyBulletEngine`.

:class:`Shapes` holds what :class:`~urdfkit.engine.pybullet.PyBulletEngine` answers of a
body's geometry (its collision and visual shapes, a link's box) and the pictures it draws
with the TinyRenderer; the engine is the class that mixes it in.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import TYPE_CHECKING

from urdfkit.engine.api import (
    Camera,
    CollisionShape,
    Light,
    Picture,
    ShapeKind,
    Vec3,
    VisualShape,
)

if TYPE_CHECKING:
    from urdfkit.engine.session import Session

#: ``getCollisionShapeData``'s geometry codes (``p.GEOM_*``) as the seam's shape kinds.
SHAPE_KINDS: dict[int, ShapeKind] = {2: "sphere", 3: "box", 4: "cylinder", 5: "mesh",
                                     6: "plane", 7: "capsule"}
MESH = 5


def text(raw: bytes) -> str:
    """A name PyBullet gives as bytes, as text (what is not UTF-8 replaced)."""
    return raw.decode("utf-8", "replace")



class Shapes:
    """A PyBullet engine's geometry and pictures (mixed into its class).

    Attributes:
        session: The engine's PyBullet session.
        error: ``pybullet.error``.
    """

    session: Session
    error: type[Exception]

    def collision_shapes(self, body: int, link: int) -> list[CollisionShape]:
        """``getCollisionShapeData``; a mesh's vertices from ``getMeshData``.

        A cylinder PyBullet turned into a mesh (no implicit cylinders) is a mesh here too.
        """
        b = self.session.bullet
        out: list[CollisionShape] = []
        for k, shape in enumerate(b.getCollisionShapeData(body, link)):
            kind = SHAPE_KINDS.get(shape[2], "other")
            vertices: Sequence[Vec3] | None = None
            if kind == "mesh":
                try:
                    count, verts = b.getMeshData(body, link, collisionShapeIndex=k)
                except self.error:
                    count, verts = 0, []
                vertices = verts if count else ()
            out.append(CollisionShape(kind, shape[3], shape[5], shape[6], vertices,
                                      text(shape[4]) if kind == "mesh" else ""))
        return out

    def collision_vertices(self, body: int, link: int) -> list[Vec3]:
        """``getMeshData(body, link, -1)``: every collision vertex PyBullet keeps for a link.

        In the link's inertial frame, all its collision shapes' at once (measured: the files'
        placed vertices exactly, an OBJ's stray vertex left out); empty where PyBullet gives
        none or refuses (it raises plain errors on a link without a mesh).
        """
        try:
            count, vertices = self.session.bullet.getMeshData(body, link, -1)
        except Exception:  # noqa: BLE001 - PyBullet raises plain errors; no data, no vertices
            return []
        return list(vertices) if count else []

    def visual_shapes(self, body: int) -> list[VisualShape]:
        """``getVisualShapeData``, quiet (what PyBullet prints goes to the diagnostics)."""
        from urdfkit.engine.session import quiet_stdout

        with quiet_stdout() as out:
            rows = self.session.bullet.getVisualShapeData(body)
        self.session.diagnostics.extend(out.lines)
        return [VisualShape(int(v[1]), SHAPE_KINDS.get(v[2], "other"), v[3],
                            text(v[4]) if v[2] == MESH else "", v[5], v[6], v[7])
                for v in rows]

    def aabb(self, body: int, link: int) -> tuple[Vec3, Vec3]:
        """``getAABB``."""
        lo, hi = self.session.bullet.getAABB(body, link)
        return lo, hi

    def camera_image(self, camera: Camera, width: int, height: int) -> bytes:
        """``getCameraImage`` with the TinyRenderer, its RGB without alpha."""
        import numpy as np

        b = self.session.bullet
        view = b.computeViewMatrix(camera.eye, camera.target, camera.up)
        proj = b.computeProjectionMatrixFOV(camera.fov, width / height, camera.near,
                                            camera.far)
        image = b.getCameraImage(width, height, view, proj,
                                 renderer=self.session.p.ER_TINY_RENDERER)[2]
        rgba = np.asarray(image, dtype=np.uint8).reshape(height, width, 4)
        return rgba[:, :, :3].tobytes()

    def picture(self, camera: Camera, width: int, height: int, light: Light | None = None
                ) -> Picture:
        """``getCameraImage`` with the TinyRenderer: RGB, segmentation mask, matrices.

        The matrices are ``computeViewMatrix``'s and ``computeProjectionMatrixFOV``'s. PyBullet
        computes the matrices in float32; they are handed out as it gives them, so
        that what is drawn over the picture meets what PyBullet drew.
        """
        import numpy as np

        b = self.session.bullet
        view = b.computeViewMatrix(camera.eye, camera.target, camera.up)
        proj = b.computeProjectionMatrixFOV(camera.fov, width / height, camera.near,
                                            camera.far)
        renderer = self.session.p.ER_TINY_RENDERER
        shoot = self.session.call  # quiet: a picture may go to stdout (render -o -)
        if light is None:
            shot = shoot("getCameraImage", width, height, view, proj, renderer=renderer)
        else:
            shot = shoot(
                "getCameraImage", width, height, view, proj, renderer=renderer,
                lightDirection=list(light.direction), shadow=int(light.shadows),
                lightAmbientCoeff=light.ambient, lightDiffuseCoeff=light.diffuse,
                lightSpecularCoeff=light.specular)
        from PIL import Image

        # Pillow drops the alpha in a third of the time numpy's strided copy takes (5 against
        # 16 ms at 1600x1200, render's supersampled 800x600)
        rgba = np.ascontiguousarray(shot[2], dtype=np.uint8)
        rgb = Image.frombuffer("RGBA", (width, height), rgba, "raw", "RGBA", 0, 1).convert("RGB")
        bodies = np.ascontiguousarray(shot[4], dtype="<i4").tobytes()
        return Picture(width, height, rgb.tobytes(), bodies, tuple(view), tuple(proj))
