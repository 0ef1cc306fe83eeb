"""PyBullet's GUI window as a control panel: sliders, and a camera that follows.

Sliders are read while a run steps (drive --gui); the camera follows the Gymnasium car in its
``human`` mode.

PyBullet only: its GUI client draws debug sliders (``addUserDebugParameter``) beside the
scene. Closing the window ends the run: every call then fails with ``pybullet.error``, which
:meth:`Sliders.read` turns into a plain answer (``None``) rather than an exception.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import TYPE_CHECKING

from urdfkit.core.errors import ParameterError

if TYPE_CHECKING:
    from urdfkit.engine.api import Simulator


class Sliders:
    """Named sliders in an engine's GUI window.

    Args:
        engine: A PyBullet world opened with ``gui=True``.
        sliders: ``(label, lowest, highest, start)`` for each slider, top to bottom.

    Raises:
        ParameterError: the engine is not PyBullet's GUI.
    """

    def __init__(self, engine: Simulator,
                 sliders: Sequence[tuple[str, float, float, float]]) -> None:
        from urdfkit.engine.pybullet import PyBulletEngine

        if not isinstance(engine, PyBulletEngine) or not engine.gui:
            raise ParameterError("`gui`: sliders need PyBullet's GUI window", param="gui")
        self._bullet = engine.bullet
        self._error = engine.session.p.error
        self._ids = [self._bullet.addUserDebugParameter(label, lo, hi, start)
                     for label, lo, hi, start in sliders]

    def read(self) -> tuple[float, ...] | None:
        """Every slider's value now, in the order given; None once the window is closed."""
        read = self._bullet.readUserDebugParameter
        try:
            return tuple(float(read(i)) for i in self._ids)
        except self._error:
            return None


def follow(engine: Simulator, distance: float, yaw: float, pitch: float,
           target: tuple[float, float, float]) -> None:
    """Point the GUI window's camera at ``target`` (``resetDebugVisualizerCamera``).

    Nothing on an engine without PyBullet's window.
    """
    from urdfkit.engine.pybullet import PyBulletEngine

    if isinstance(engine, PyBulletEngine) and engine.gui:
        engine.bullet.resetDebugVisualizerCamera(distance, yaw, pitch, list(target))
