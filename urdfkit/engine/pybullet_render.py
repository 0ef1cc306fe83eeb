"""What only PyBullet's TinyRenderer draws: a robot's collision shapes as its picture.

``urdfkit render --collision`` shows the shapes PyBullet collides with. TinyRenderer draws
visual shapes only; loading with ``URDF_IGNORE_VISUAL_SHAPES`` makes PyBullet build the
visual shapes from the ``<collision>`` elements instead (r2d2's base then draws with the
collision radius 0.17, not the visual 0.2), all white, so every link is recoloured
(``changeVisualShape``). PyBullet only: another engine is refused with one line.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from urdfkit.core.errors import ParameterError

if TYPE_CHECKING:
    from urdfkit.engine.api import LoadSettings, Simulator


def load_drawing_collisions(engine: Simulator, path: str, settings: LoadSettings,
                            display: str | None, rgba: tuple[float, float, float, float]
                            ) -> int:
    """Load a guarded URDF whose pictures draw its collision shapes, every link in ``rgba``.

    Raises:
        ParameterError: the engine is not PyBullet.
    """
    from urdfkit.engine.pybullet import PyBulletEngine

    if not isinstance(engine, PyBulletEngine):
        raise ParameterError(f"`collision`: drawing the collision shapes needs PyBullet's "
                             f"TinyRenderer, not {engine.label}", param="collision")
    session = engine.session
    body = engine.load(path, settings, display,
                       flags=session.p.URDF_IGNORE_VISUAL_SHAPES)
    for link in range(-1, session.bullet.getNumJoints(body)):
        session.call("changeVisualShape", body, link, rgbaColor=list(rgba))
    return body
