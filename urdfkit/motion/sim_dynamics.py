"""Dynamics: mass matrix, inverse and forward dynamics, Jacobians on shadow models.

PyBullet builds the model its calculateMassMatrix, calculateInverseDynamics and
calculateJacobian use once, at the first call, and never updates it: a mass changed later is
ignored (measured on 3.2.7). So the dynamics run on a copy of the robot in a world of its own
in the same engine (a *shadow*, :class:`Shadows`), rebuilt after every
``set_mass``/``set_inertia``.

PyBullet can refuse to build that model for a robot it loads and simulates (KUKA KR210's
link_2 inertia; :func:`urdfkit.engine.session.dynamics_refusal` says why): the engine's
dynamics calls then raise :class:`EngineError` saying why, and every message here names the
robot before it.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING, TypeVar

from urdfkit.core.errors import EngineError, ParameterError
from urdfkit.engine.registry import open_engine
from urdfkit.motion.sim_state import JointSpec

if TYPE_CHECKING:
    import numpy as np

    from urdfkit.engine.api import LoadSettings, Simulator
    from urdfkit.motion.sim_robot import MassValue, SimRobot
    from urdfkit.motion.sim_world import World

T = TypeVar("T")

#: What each dynamics call computes, for messages.
MASS_MATRIX, INVERSE_DYNAMICS, JACOBIANS = "the mass matrix", "the inverse dynamics", "Jacobians"


class Dynamics:
    """The dynamics quantities of a world's robots, each on its robot's shadow model."""

    def __init__(self, world: World) -> None:
        self.world = world
        self.shadows = Shadows()

    def close(self) -> None:
        """Disconnect every shadow client (safe to call twice)."""
        self.shadows.close()

    def joints(self, robot: SimRobot) -> list[JointSpec]:
        """The joints the dynamics quantities are ordered by: the movable ones, 1-DOF."""
        movable = [j for j in robot.joints if j.kind != "fixed"]
        odd = [j.name for j in movable if not j.active]
        if odd:
            raise ParameterError(f"{robot.name}: the dynamics need 1-DOF joints; {odd[0]!r} "
                                 "is not", param="robot")
        return movable

    def physical_state(self, robot: SimRobot) -> tuple[list[float], list[float]]:
        """The joints' positions and velocities now, physical (no offsets or directions)."""
        states = self.world.engine.joint_rows(robot.body,
                                              [j.index for j in self.joints(robot)])
        return [float(st[0]) for st in states], [float(st[1]) for st in states]

    def _fixed(self, robot: SimRobot, what: str) -> None:
        moving_base = robot.config.base != "fixed" and \
            self.world.engine.dynamics(robot.body, -1).mass > 0
        if moving_base:
            raise ParameterError(f"{robot.name}: {what} needs a fixed base (PyBullet's "
                                 "calculateInverseDynamics does not take a floating one); "
                                 "use base = \"fixed\"", param="robot")

    def model(self, robot: SimRobot) -> tuple[Simulator, int]:
        """``(engine, body)`` of the robot's dynamics model, as the robot is now."""
        shadow = self._shadow(robot)
        return shadow.engine, shadow.body

    def _shadow(self, robot: SimRobot) -> Shadow:
        return self.shadows.model(robot.name, robot.loaded, self.world.config.physics.gravity,
                                  robot.changes, robot.mass_version, self.world.engine.name)

    def call(self, robot: SimRobot, what: str,
             compute: Callable[[Simulator, int], T]) -> T:
        """``compute(engine, body)`` on the robot's model; ``what`` it computes, for messages.

        Raises:
            EngineError: the engine cannot build its dynamics model of the robot, or the call
                failed; the message names the robot and says why.
        """
        shadow = self._shadow(robot)
        try:
            return compute(shadow.engine, shadow.body)
        except EngineError as e:
            raise EngineError(f"{shadow.engine.label} cannot compute {what} of robot "
                              f"{robot.name!r}: {e.message}") from None

    def mass_matrix(self, robot: SimRobot) -> np.ndarray:
        """The joint-space mass matrix M(q) now (PyBullet's calculateMassMatrix).

        Physical joint coordinates, in :meth:`joints` order; a floating base puts its 6
        coordinates first, as PyBullet does.
        """
        import numpy as np

        q, _ = self.physical_state(robot)
        return np.array(self.call(robot, MASS_MATRIX, lambda e, b: e.mass_matrix(b, q)))

    def coriolis_and_gravity(self, robot: SimRobot) -> np.ndarray:
        """C(q, qd) qd + g(q) now: the torques that hold the current motion."""
        import numpy as np

        self._fixed(robot, "coriolis_and_gravity")
        q, qd = self.physical_state(robot)
        zero = [0.0] * len(q)
        return np.array(self.call(robot, INVERSE_DYNAMICS,
                                  lambda e, b: e.inverse_dynamics(b, q, qd, zero)))

    def gravity_torques(self, robot: SimRobot) -> np.ndarray:
        """g(q) now: the torques that hold the robot still against gravity."""
        import numpy as np

        self._fixed(robot, "gravity_torques")
        q, _ = self.physical_state(robot)
        zero = [0.0] * len(q)
        return np.array(self.call(robot, INVERSE_DYNAMICS,
                                  lambda e, b: e.inverse_dynamics(b, q, zero, zero)))

    def forward_dynamics(self, robot: SimRobot, tau: Sequence[float]) -> np.ndarray:
        """The joint accelerations ``tau`` would cause now, without contacts.

        qdd = M^-1 (tau - C qd - g).
        """
        import numpy as np

        torque = np.asarray(tau, dtype=float)
        n = len(self.joints(robot))
        if torque.shape != (n,):
            raise ParameterError(f"`tau` needs {n} torques, one per dynamics joint of "
                                 f"{robot.name}, got {torque.shape}", param="tau")
        out: np.ndarray = np.linalg.solve(self.mass_matrix(robot),
                                          torque - self.coriolis_and_gravity(robot))
        return out

    def jacobian(self, robot: SimRobot, link: str, point: Sequence[float]) -> np.ndarray:
        """The 6 x n Jacobian (linear rows, then angular) of a point of a link now.

        ``point`` is from the link's URDF frame's origin (the joint), along the link's inertial
        frame's axes (the URDF frame's unless its ``<inertial>`` is turned): PyBullet 3.2.7's
        calculateJacobian takes it so, whatever its docs say of the centre of mass (measured:
        the point (0, 0, 0) of a pendulum's bob link is on the hinge, J = 0;
        tests/test_engine_contract.py turns the inertial frame).
        """
        import numpy as np

        index = robot.links.get(link)
        if index is None or index == -1:
            raise ParameterError(f"`link`: {robot.name} has no moving link named {link!r}",
                                 param="link")
        q, _ = self.physical_state(robot)
        at = (float(point[0]), float(point[1]), float(point[2]))
        lin, ang = self.call(robot, JACOBIANS, lambda e, b: e.jacobian(b, index, at, q))
        return np.vstack([np.array(lin), np.array(ang)])

    def times_mass_matrix(self, robot: SimRobot, vector: list[float]) -> list[float]:
        """``D M D v`` for the servo joints: M(q) at the true state, in the measured frame.

        With ``mass_matrix_angles = "measured"`` (simulation_and_control's servo): ``M v``
        with M from calculateMassMatrix given the measured angles ``(q - offset) * direction``
        as if they were joint angles, and no ``D``; the same as ``D M D v`` when every offset
        is 0 and every direction 1.
        """
        dyn = self.joints(robot)
        q, _ = self.physical_state(robot)
        motor = robot.config.motor
        measured = motor is not None and motor.mass_matrix_angles == "measured"
        if measured:
            q = [(x - robot.offsets.get(j.name, 0.0)) * robot.directions.get(j.name, 1.0)
                 for x, j in zip(q, dyn, strict=True)]
        matrix = self.call(robot, MASS_MATRIX, lambda e, b: e.mass_matrix(b, q))
        skip = len(matrix) - len(dyn)  # a floating base's 6 coordinates come first
        where = {j.name: skip + k for k, j in enumerate(dyn)}
        rows = [where[spec.name] for spec in robot.servo]
        if measured and rows == list(range(skip, skip + len(rows))):
            return self._as_numpy_does(robot, q, matrix, skip, len(rows), vector)
        signs = [1.0 if measured else robot.directions.get(spec.name, 1.0)
                 for spec in robot.servo]
        return [signs[i] * math.fsum(matrix[r][c] * signs[k] * vector[k]
                                     for k, c in enumerate(rows))
                for i, r in enumerate(rows)]

    def _as_numpy_does(self, robot: SimRobot, q: list[float], matrix: list[list[float]],
                       skip: int, n: int, vector: list[float]) -> list[float]:
        """``M v`` as simulation_and_control computes it, to the last bit.

        A floating base's matrix at the base's true pose (not at the engine's default base
        pose), and numpy's matrix product (whose rounding differs from an exact sum by an ulp
        or two).
        """
        import numpy as np

        if skip:
            pos, orn = self.world.engine.base_pose(robot.body)
            full = np.asarray(self.call(robot, MASS_MATRIX, lambda e, b: e.floating_mass_matrix(
                b, pos, orn, q)))
        else:
            full = np.asarray(matrix)
        block = full[skip:, skip:][:n, :n]
        return [float(x) for x in block @ np.asarray(vector, dtype=float)]


@dataclass
class Shadow:
    """One robot's dynamics model: its world, its body, the robot's version it is of.

    Attributes:
        engine: The shadow's own world, in the simulation's engine (which remembers whether
            it could build its dynamics model of the body).
        body: The robot's body id in it.
        version: The robot's mass-change count it was built at.
    """

    engine: Simulator
    body: int
    version: int


class Shadows:
    """One shadow world per robot, built at the first dynamics query, rebuilt when stale."""

    def __init__(self) -> None:
        self.models: dict[str, Shadow] = {}

    def model(self, name: str, loaded: tuple[str, LoadSettings], gravity: Sequence[float],
              changes: Mapping[tuple[int, str], MassValue], version: int,
              engine: str = "pybullet") -> Shadow:
        """The robot's model: its URDF as loaded, its changes since, in engine ``engine``.

        ``version`` counts the robot's mass changes: a model built at an older one is
        closed and built again.
        """
        shadow = self.models.get(name)
        if shadow is not None and shadow.version != version:
            self.stale(name)
            shadow = None
        if shadow is None:
            world = open_engine(engine)
            try:
                world.set_gravity((gravity[0], gravity[1], gravity[2]))
                body = world.load(loaded[0], loaded[1], display=name)
                for (link, key), value in changes.items():
                    world.change_dynamics(body, link, **{key: value})
            except BaseException:
                world.close()
                raise
            shadow = self.models[name] = Shadow(world, body, version)
        return shadow

    def stale(self, name: str) -> None:
        """Close a robot's model: it is built again when next asked."""
        shadow = self.models.pop(name, None)
        if shadow is not None:
            shadow.engine.close()

    def close(self) -> None:
        """Close every shadow world (safe to call twice)."""
        for shadow in self.models.values():
            shadow.engine.close()
        self.models.clear()
