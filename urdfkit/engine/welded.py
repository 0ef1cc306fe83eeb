"""A URDF as another engine loads it, base welded, as a :class:`~urdfkit.engine.api.Model`.

``agree --engine pinocchio|drake`` loads the URDF in PyBullet (its fixed load) and in the other
engine, and asks both the same questions through the same interface. :class:`WeldedModel` is
the other engine's side, in PyBullet's indices, as
:class:`~urdfkit.engine.mujoco_file_model.MjcfModel` is an MJCF file's: its link ``i`` is
PyBullet's link ``i`` (-1 the root), its joint ``i`` the engine's joint of PyBullet's joint
``i``'s name (a joint the engine does not move is a fixed one here), and its positions, mass
matrix and torques are over the matched movable joints in PyBullet's order. Each engine is one
subclass (:mod:`~urdfkit.engine.pinocchio_model`, :mod:`~urdfkit.engine.drake_model`) that
answers in its own indices; this class maps them.

What the engine itself numbers is kept in :attr:`WeldedModel.coordinates`: every joint in the
engine's order with its own position and velocity indices, so that a user can map actions
between engines.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

from urdfkit.core.errors import EngineError, ParameterError
from urdfkit.engine.api import JointInfo, JointKind, LinkDynamics, Quat, Vec3

#: The joint kinds the seam has words for.
SEAM_KINDS = ("revolute", "prismatic", "spherical", "planar", "fixed")


@dataclass(frozen=True)
class Coordinate:
    """One joint as the engine numbers it.

    Attributes:
        name: The joint's name in the engine (the URDF's).
        kind: Its kind in the seam's words (``floating`` and the engine's own name for what
            the seam has no word for); ``detail`` the engine's own (``JointModelRUBZ``).
        q, nq, v, nv: Its first position and velocity index and how many of each.
    """

    name: str
    kind: str
    detail: str
    q: int
    nq: int
    v: int
    nv: int


@dataclass(frozen=True)
class EngineJoint:
    """What an engine holds for one joint (limits as loaded; ``None``: it holds none)."""

    coordinate: Coordinate
    damping: float
    friction: float
    lower: float
    upper: float
    effort: float | None
    velocity: float | None
    axis: Vec3


class WeldedModel:
    """A URDF in another engine, base welded, in PyBullet's indices (one body, 0).

    A subclass loads the file and implements the ``_engine_*`` methods in its own indices.

    Args:
        root: PyBullet's root link's name (link -1).
        layout: PyBullet's joints (its :meth:`~urdfkit.engine.api.Model.joints`).
    """

    name = ""
    label = ""

    def __init__(self, root: str, layout: Sequence[JointInfo]) -> None:
        self._layout = list(layout)
        self._links = [root] + [j.link for j in layout]
        self.coordinates: list[Coordinate] = []
        self._joint: dict[str, EngineJoint] = {}

    def _index(self, joints: list[EngineJoint]) -> None:
        """Keep the engine's joints (its order) and map PyBullet's movable ones onto them."""
        self.coordinates = [j.coordinate for j in joints]
        self._joint = {j.coordinate.name: j for j in joints if j.coordinate.kind != "fixed"}
        #: the matched movable joints, in PyBullet's order: what positions are over
        self._movable = [self._joint[j.name] for j in self._layout
                         if j.kind != "fixed" and j.name in self._joint]

    def _check(self, body: int) -> None:
        if body != 0:
            raise ParameterError(f"the {self.label} model is body 0, not {body}", param="body")

    # ---- the tables

    def joints(self, body: int) -> list[JointInfo]:
        """PyBullet's joints as the engine has them; one the engine does not move is fixed.

        The indices are the engine's own; ``effort`` and ``velocity`` are 0 where it holds
        none.
        """
        self._check(body)
        out = []
        for j in self._layout:
            e = self._joint.get(j.name) if j.kind != "fixed" else None
            if e is None:
                out.append(JointInfo(j.index, j.name, "fixed", -1, -1, 0.0, 0.0, 0.0, -1.0,
                                     False, 0.0, 0.0, j.link, (0.0, 0.0, 0.0), j.parent))
                continue
            c = e.coordinate
            limited = math.isfinite(e.lower) and math.isfinite(e.upper)
            kind: JointKind = c.kind if c.kind in SEAM_KINDS else "fixed"  # type: ignore[assignment]
            out.append(JointInfo(j.index, j.name, kind, c.q, c.v, e.damping, e.friction,
                                 e.lower if limited else 0.0, e.upper if limited else -1.0,
                                 limited, e.effort or 0.0, e.velocity or 0.0, j.link, e.axis,
                                 j.parent))
        return out

    def engine_joint(self, name: str) -> EngineJoint | None:
        """What the engine holds for the movable joint of this name, if it has one."""
        return self._joint.get(name)

    def link_names(self, body: int) -> list[str]:
        """PyBullet's link names, the root first."""
        self._check(body)
        return list(self._links)

    def dynamics(self, body: int, link: int) -> LinkDynamics:
        """A link's mass properties as the engine holds them, in the link frame.

        An engine that fuses welded links into one body (Pinocchio) gives the body's on its
        first link and 0 kg on the others. No contact parameters: 0 friction.
        """
        import numpy as np

        from urdfkit.formats.mjcf_text import mat_to_quat

        self._check(body)
        mass, com, tensor = self._engine_inertial(self._links[link + 1])
        # principal axes (the seam's form): the tensor about the centre of mass turned
        moments, axes = np.linalg.eigh(np.array(tensor, dtype=float))
        if np.linalg.det(axes) < 0:
            axes[:, 0] = -axes[:, 0]
        w, x, y, z = mat_to_quat(axes)
        return LinkDynamics(float(mass), (float(moments[0]), float(moments[1]),
                                          float(moments[2])),
                            (float(com[0]), float(com[1]), float(com[2])), (x, y, z, w),
                            0.0, 0.0, 0.0, 0.0, -1.0, -1.0)

    # ---- a pose

    def _values(self, values: Sequence[float]) -> dict[str, float]:
        if len(values) != len(self._movable):
            raise ParameterError(f"{len(values)} values for {len(self._movable)} joints",
                                 param="positions")
        return {e.coordinate.name: float(v) for e, v in zip(self._movable, values,
                                                               strict=True)}

    def set_joint_positions(self, body: int, positions: Sequence[float],
                            velocities: Sequence[float] | None = None) -> None:
        """The matched joints at these values (PyBullet's order), the rest at the engine's zero.

        A NaN leaves its joint at zero; a spherical joint stays at rest (``agree`` compares
        a ball joint at rest, as its MJCF side).
        """
        self._check(body)
        q = {n: v for n, v in self._values(positions).items() if v == v}
        self._engine_set(q, self._values(velocities) if velocities is not None else {})

    def link_matrices(self, body: int, links: Sequence[int]) -> list[Any]:
        """These links' frames at the pose set, world, as the engine computes them (4 x 4)."""
        self._check(body)
        return [self._engine_frame(self._links[i + 1]) for i in links]

    def link_frames(self, body: int) -> list[tuple[Vec3, Quat]]:
        """Every link frame at the pose set, world, the root first."""
        from urdfkit.formats.mjcf_text import mat_to_quat

        out: list[tuple[Vec3, Quat]] = []
        for t in self.link_matrices(body, range(-1, len(self._layout))):
            w, x, y, z = mat_to_quat(t[:3, :3])
            out.append(((float(t[0, 3]), float(t[1, 3]), float(t[2, 3])), (x, y, z, w)))
        return out

    def self_contacts(self, body: int) -> list[tuple[str, str]]:
        """None: the engine's model is loaded without geometry (dynamics alone)."""
        self._check(body)
        return []

    # ---- dynamics

    def _columns(self) -> list[int]:
        out = []
        for e in self._movable:
            if e.coordinate.nv != 1:
                raise EngineError(f"joint {e.coordinate.name!r} has {e.coordinate.nv} "
                                  f"velocities in {self.label}: the seam gives each joint one")
            out.append(e.coordinate.v)
        return out

    def mass_matrix(self, body: int, positions: Sequence[float]) -> list[list[float]]:
        """The engine's joint-space mass matrix over the matched joints, PyBullet's order."""
        import numpy as np

        self.set_joint_positions(body, positions)
        cols = self._columns()
        full = np.array(self._engine_mass_matrix(), dtype=float)
        return [[float(x) for x in row] for row in full[np.ix_(cols, cols)]]

    def inverse_dynamics(self, body: int, positions: Sequence[float],
                         velocities: Sequence[float],
                         accelerations: Sequence[float]) -> list[float]:
        """The engine's rigid-body torques, gravity (0 0 -9.81) included, PyBullet's order."""
        self.set_joint_positions(body, positions, velocities)
        cols = self._columns()
        a = self._values(accelerations)
        tau = self._engine_inverse_dynamics(a)
        return [float(tau[c]) for c in cols]

    def floating_mass_matrix(self, body: int, position: Vec3, orientation: Quat,
                             positions: Sequence[float]) -> list[list[float]]:
        """None here: the base is welded.

        Raises:
            ParameterError: always.
        """
        self._check(body)
        raise ParameterError(f"the {self.label} model's base is welded: floating_mass_matrix "
                             "is the mass matrix of a floating base", param="body")

    def jacobian(self, body: int, link: int, point: Vec3, positions: Sequence[float]
                 ) -> tuple[list[list[float]], list[list[float]]]:
        """A point's Jacobians, columns the matched joints in PyBullet's order.

        ``point`` is from the link frame's origin along the link frame's axes and the rows
        are in the world (the welded root's frame), as the MJCF side's.
        """
        import numpy as np

        self.set_joint_positions(body, positions)
        cols = self._columns()
        lin, ang = self._engine_jacobian(self._links[link + 1], np.array(point, dtype=float))
        lin, ang = np.asarray(lin), np.asarray(ang)
        return lin[:, cols].tolist(), ang[:, cols].tolist()

    def close(self) -> None:
        """Nothing to release (the engine's model is a Python object)."""

    # ---- what a subclass implements, in the engine's own indices

    def _engine_inertial(self, link: str) -> tuple[float, Any, Any]:
        raise NotImplementedError

    def _engine_set(self, q: dict[str, float], v: dict[str, float]) -> None:
        raise NotImplementedError

    def _engine_frame(self, link: str) -> Any:
        raise NotImplementedError

    def _engine_mass_matrix(self) -> Any:
        raise NotImplementedError

    def _engine_inverse_dynamics(self, a: dict[str, float]) -> Any:
        raise NotImplementedError

    def _engine_jacobian(self, link: str, point: Any) -> tuple[Any, Any]:
        raise NotImplementedError


def engine_refusal(label: str, error: BaseException, file: str, why: str = "") -> Exception:
    """The engine's refusal as an :class:`~urdfkit.core.errors.InputError`: one bounded line.

    ``why`` is the engine's first reason where its exception says less (urdfdom's line).
    """
    from urdfkit.core.errors import InputError

    text = " ".join(str(error).split()) or type(error).__name__
    if why:
        text = f"{why} ({text})"
    if len(text) > 300:
        text = text[:297] + "..."
    return InputError(f"{label} cannot load it: {text}", file=file)


if TYPE_CHECKING:
    from urdfkit.engine.api import Model

    def _is_a_model(model: WeldedModel) -> Model:
        """Never called: mypy checks here that the class keeps the whole protocol."""
        return model
