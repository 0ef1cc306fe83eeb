"""PyBullet's dynamics behind the seam: a part of :class:`PyBulletEngine`.

:class:`Dynamics` holds the mass matrix, inverse dynamics and Jacobians
:class:`~urdfkit.engine.pybullet.PyBulletEngine` asks of PyBullet's inverse-dynamics model of
a body, which PyBullet builds at the first call (and may refuse); the engine is the class
that mixes it in.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import TYPE_CHECKING, Any

from urdfkit.core.errors import EngineError
from urdfkit.engine.api import Quat, Vec3

if TYPE_CHECKING:
    from urdfkit.engine.session import Session

_UNTRIED = "untried"

#: Why a body loaded after a ``removeBody`` gets no dynamics: PyBullet keeps each body's
#: inverse-dynamics model by the body's place in memory, and a new body can take a removed
#: one's place and its model (measured on 3.2.7: kuka_iiwa loaded after a removed pendulum
#: got the pendulum's model: a dimension error, and PyBullet's SystemError).
STALE_MODELS = ("PyBullet may give a body loaded after a removeBody the removed body's "
                "inverse-dynamics model (it keeps them by place in memory): its dynamics "
                "are not asked of this engine; load it into a fresh one")



class Dynamics:
    """A PyBullet engine's dynamics on each body's inverse-dynamics model (mixed in).

    Attributes:
        session: The engine's PyBullet session.
        error: ``pybullet.error``.
    """

    session: Session
    error: type[Exception]
    #: Per body, PyBullet's inverse-dynamics model: _UNTRIED, None (built: calls are
    #: bare) or why PyBullet refused to build it.
    _models: dict[int, str | None]

    def mass_matrix(self, body: int, positions: Sequence[float]) -> list[list[float]]:
        """``calculateMassMatrix``: a floating base's 6 coordinates first.

        Angular, then linear (measured on 3.2.7), with the base at PyBullet's default pose.
        """
        rows = self._dynamics("calculateMassMatrix", body, positions)
        return [list(row) for row in rows]

    def floating_mass_matrix(self, body: int, position: Vec3, orientation: Quat,
                             positions: Sequence[float]) -> list[list[float]]:
        """``calculateMassMatrix`` with ``flags=1``: the base's pose before the joints.

        PyBullet then gives 7 base rows and columns, linear then angular, and a 7th that is
        the identity's (the quaternion's 4th part); the 6 kept are the first three and the
        angular three. A root without ``<inertial>``, which PyBullet simulates at 1 kg, counts
        0 kg here (measured on 3.2.7: quadruped_like's linear diagonal reads 13.72 kg of the
        14.72 its links hold; with ``flags=0`` it reads 14.72).
        """
        full: list[list[float]] = self._dynamics(
            "calculateMassMatrix", body, [*position, *orientation, *positions], flags=1)
        return [row[:6] + row[7:] for k, row in enumerate(full) if k != 6]

    def inverse_dynamics(self, body: int, positions: Sequence[float],
                         velocities: Sequence[float],
                         accelerations: Sequence[float]) -> list[float]:
        """``calculateInverseDynamics`` (a fixed base only: PyBullet's limit)."""
        return list(self._dynamics("calculateInverseDynamics", body, positions, velocities,
                                   accelerations))

    def jacobian(self, body: int, link: int, point: Vec3, positions: Sequence[float]
                 ) -> tuple[list[list[float]], list[list[float]]]:
        """``calculateJacobian`` at rest.

        The velocities do not change PyBullet's Jacobian (bit for bit the same at any,
        measured on three robots, a floating one among them).
        """
        zero = [0.0] * len(positions)
        lin, ang = self._dynamics("calculateJacobian", body, link, list(point), positions,
                                  zero, zero)
        return lin, ang

    def _dynamics(self, fn: str, body: int, *args: Any, **kwargs: Any) -> Any:
        """One of the three dynamics calls on ``body``'s inverse-dynamics model.

        PyBullet builds that model at the first call and may refuse (and print): the first
        call runs quiet (:func:`dynamics_call`); after one worked, calls are bare; after a
        refusal, every call raises why.

        Raises:
            EngineError: with why as a clause.
        """
        state = self._models.get(body, _UNTRIED)
        if state is None:  # the motor's every-step path: the bare call
            b = self.session.bullet
            try:
                return getattr(b, fn)(body, *args, **kwargs)
            except (SystemError, self.error) as e:
                raise EngineError(f"PyBullet's {fn} failed "
                                  f"({e.__cause__ or e.__context__ or e})") from None
        if state is not _UNTRIED:
            raise EngineError(state)
        from urdfkit.engine.session import dynamics_call

        try:  # the call that builds PyBullet's model: it may print
            out = dynamics_call(self.session.bullet, fn, body, *args, **kwargs)
        except EngineError as e:
            self._models[body] = e.message
            raise EngineError(e.message) from None
        self._models[body] = None
        return out
