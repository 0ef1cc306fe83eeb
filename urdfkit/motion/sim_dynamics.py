"""Dynamics: mass matrix, inverse and forward dynamics, Jacobians on shadow models.

Methods of :class:`urdfkit.sim.Simulation`, split out of :mod:`urdfkit.sim`: each function
takes the simulation as ``self`` and is bound as a method of ``Simulation`` (a class
attribute), so a call costs what a method defined in the class costs.

PyBullet builds the model its calculateMassMatrix, calculateInverseDynamics and
calculateJacobian use once, at the first call, and never updates it: a mass changed later is
ignored (measured on 3.2.7). So the dynamics run on a copy of the robot in a client of its
own (a *shadow*, :class:`Shadows`), rebuilt after every ``set_mass``/``set_inertia``.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from typing import Any

from urdfkit.core.errors import ParameterError
from urdfkit.engine.session import Session
from urdfkit.motion.sim_state import _FIXED, JointSpec, _Body


def dynamics_joints(self: Any, robot: str) -> list[str]:
    """The joints the dynamics quantities are ordered by (PyBullet's order).

    The movable joints; a floating base adds 6 base coordinates before them in
    :meth:`mass_matrix`.
    """
    return [j.name for j in self._dynamics_joints(self._body(robot))]


def _dynamics_joints(self: Any, b: _Body) -> list[JointSpec]:
    movable = [j for j in b.joints if j.type != _FIXED]
    odd = [j.name for j in movable if not j.active]
    if odd:
        raise ParameterError(f"{b.name}: the dynamics need 1-DOF joints; {odd[0]!r} is not",
                             param="robot")
    return movable


def _physical_state(self: Any, b: _Body) -> tuple[list[float], list[float]]:
    p, client = self.session.p, self.session.client
    states = p.getJointStates(b.body, [j.index for j in self._dynamics_joints(b)],
                              physicsClientId=client)
    return [float(st[0]) for st in states], [float(st[1]) for st in states]


def _fixed(self: Any, b: _Body, what: str) -> None:
    p, client = self.session.p, self.session.client
    moving_base = b.config.base != "fixed" and \
        p.getDynamicsInfo(b.body, -1, physicsClientId=client)[0] > 0
    if moving_base:
        raise ParameterError(f"{b.name}: {what} needs a fixed base (PyBullet's "
                             "calculateInverseDynamics does not take a floating one); "
                             "use base = \"fixed\"", param="robot")


def _model(self: Any, b: _Body) -> tuple[Any, int, int]:
    """``(p, client, body)`` of the robot's dynamics model, as the robot is now.

    PyBullet builds the model its calculateMassMatrix, calculateInverseDynamics and
    calculateJacobian use once, at the first call, and never updates it: a mass changed
    later is ignored (measured on 3.2.7). So the dynamics run on a copy of the robot in a
    client of their own, rebuilt after every ``set_mass``/``set_inertia``.
    """
    assert b.loaded is not None
    return self._shadows.model(b.name, b.loaded, self.config.physics.gravity, b.changes)


def _changed(self: Any, b: _Body, link: int, values: dict[str, Any]) -> None:
    """Remember a change to a robot's mass properties; its dynamics model is stale."""
    for key, value in values.items():
        b.changes[(link, key)] = value
    self._shadows.stale(b.name)


def mass_matrix(self: Any, robot: str) -> Any:
    """The joint-space mass matrix M(q) now (numpy, PyBullet's calculateMassMatrix).

    Physical joint coordinates, in :meth:`dynamics_joints` order; a floating base puts its
    6 coordinates first, as PyBullet does.
    """
    import numpy as np

    b = self._body(robot)
    q, _ = self._physical_state(b)
    p, client, body = self._model(b)
    return np.array(p.calculateMassMatrix(body, q, physicsClientId=client))


def coriolis_and_gravity(self: Any, robot: str) -> Any:
    """C(q, qd) qd + g(q) now: the torques that hold the current motion (numpy)."""
    import numpy as np

    b = self._body(robot)
    self._fixed(b, "coriolis_and_gravity")
    q, qd = self._physical_state(b)
    p, client, body = self._model(b)
    return np.array(p.calculateInverseDynamics(body, q, qd, [0.0] * len(q),
                                               physicsClientId=client))


def gravity_torques(self: Any, robot: str) -> Any:
    """g(q) now: the torques that hold the robot still against gravity (numpy)."""
    import numpy as np

    b = self._body(robot)
    self._fixed(b, "gravity_torques")
    q, _ = self._physical_state(b)
    p, client, body = self._model(b)
    zero = [0.0] * len(q)
    return np.array(p.calculateInverseDynamics(body, q, zero, zero,
                                               physicsClientId=client))


def forward_dynamics(self: Any, robot: str, tau: Sequence[float]) -> Any:
    """The joint accelerations ``tau`` would cause now, without contacts (numpy).

    qdd = M^-1 (tau - C qd - g).
    """
    import numpy as np

    b = self._body(robot)
    torque = np.asarray(tau, dtype=float)
    n = len(self._dynamics_joints(b))
    if torque.shape != (n,):
        raise ParameterError(f"`tau` needs {n} torques, one per dynamics joint of "
                             f"{robot}, got {torque.shape}", param="tau")
    return np.linalg.solve(self.mass_matrix(robot), torque - self.coriolis_and_gravity(robot))


def jacobian(self: Any, robot: str, link: str, point: Sequence[float] = (0.0, 0.0, 0.0)
             ) -> Any:
    """The 6 x n Jacobian (linear rows, then angular) of a point of a link now (numpy).

    ``point`` is in the link's URDF frame (the joint frame): PyBullet 3.2.7's
    calculateJacobian takes it so, whatever its docs say of the centre of mass (measured:
    the point (0, 0, 0) of a pendulum's bob link is on the hinge, J = 0).
    """
    import numpy as np

    b = self._body(robot)
    index = b.links.get(link)
    if index is None or index == -1:
        raise ParameterError(f"`link`: {robot} has no moving link named {link!r}",
                             param="link")
    q, qd = self._physical_state(b)
    p, client, body = self._model(b)
    lin, ang = p.calculateJacobian(body, index, list(point), q, qd, [0.0] * len(q),
                                   physicsClientId=client)
    return np.vstack([np.array(lin), np.array(ang)])


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
