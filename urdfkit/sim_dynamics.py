"""Dynamics models of a simulation's robots: copies of each robot in clients of their own.

PyBullet builds the model its calculateMassMatrix, calculateInverseDynamics and
calculateJacobian use once, at the first call, and never updates it: a mass changed later is
ignored (measured on 3.2.7). So :class:`~urdfkit.sim.Simulation`'s dynamics run on a copy of
the robot in a client of its own (a *shadow*), rebuilt after every ``set_mass``/``set_inertia``.
Split out of :mod:`urdfkit.sim`.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from typing import Any

from .session import Session


class Shadows:
    """One shadow client per robot, built at the first dynamics query, dropped when stale."""

    def __init__(self) -> None:
        self.models: dict[str, tuple[Session, int]] = {}

    def model(self, name: str, loaded: tuple[str, Any], gravity: Sequence[float],
              changes: Mapping[tuple[int, str], Any]) -> tuple[Any, int, int]:
        """``(p, client, body)`` of the robot's model: its URDF as loaded, its changes since."""
        if name not in self.models:
            s = Session()
            try:
                s.p.setGravity(*gravity, physicsClientId=s.client)
                body = s.load_urdf(loaded[0], loaded[1], display=name)
                for (link, key), value in changes.items():
                    s.p.changeDynamics(body, link, physicsClientId=s.client, **{key: value})
            except BaseException:
                s.close()
                raise
            self.models[name] = (s, body)
        s, body = self.models[name]
        return s.p, s.client, body

    def stale(self, name: str) -> None:
        """The robot's mass properties changed: close its model, rebuilt when next asked."""
        shadow = self.models.pop(name, None)
        if shadow is not None:
            shadow[0].close()

    def close(self) -> None:
        """Disconnect every shadow client (safe to call twice)."""
        for shadow in self.models.values():
            shadow[0].close()
        self.models.clear()
