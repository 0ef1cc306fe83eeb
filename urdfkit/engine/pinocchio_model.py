"""A URDF as Pinocchio loads it (``buildModelFromUrdf``), base welded, in PyBullet's indices.

Pinocchio reads the file with urdfdom, without a root joint (the base welded at the universe,
as PyBullet's fixed load), and fuses every link welded to a joint's body into that body: a
body's mass properties are on its first link, the others hold 0 kg here. A continuous joint is
Pinocchio's unbounded revolute, two positions (cos, sin) and one velocity; the seam's position
is its angle. Nothing of the geometry is loaded: Pinocchio's model is the kinematics and the
dynamics.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from typing import Any

from urdfkit.core.errors import import_optional
from urdfkit.engine.api import JointInfo
from urdfkit.engine.welded import Coordinate, EngineJoint, WeldedModel, engine_refusal

#: Pinocchio's joint models (``shortname()`` less ``JointModel``) in the seam's words.
_KINDS = {"RX": "revolute", "RY": "revolute", "RZ": "revolute",
          "RevoluteUnaligned": "revolute", "RUBX": "revolute", "RUBY": "revolute",
          "RUBZ": "revolute", "RevoluteUnboundedUnaligned": "revolute",
          "PX": "prismatic", "PY": "prismatic", "PZ": "prismatic",
          "PrismaticUnaligned": "prismatic", "Spherical": "spherical",
          "SphericalZYX": "spherical", "Planar": "planar", "FreeFlyer": "floating"}


def import_pinocchio() -> Any:
    """The ``pinocchio`` package.

    Raises:
        MissingDependencyError: It is not installed (``urdfkit[engines]`` named).
    """
    return import_optional("pinocchio", "Pinocchio", "agree --engine pinocchio", "engines")


class PinocchioModel(WeldedModel):
    """The URDF at ``path`` in Pinocchio, base welded (a :class:`Model` of one body, 0).

    Raises:
        InputError: Pinocchio (urdfdom) refuses the file, with its reason.
        MissingDependencyError: Pinocchio is not installed.
    """

    name = "pinocchio"
    label = "Pinocchio"

    def __init__(self, path: str, display: str, root: str,
                 layout: Sequence[JointInfo]) -> None:
        super().__init__(root, layout)
        from urdfkit.engine.session import quiet_stderr

        pin = self.pin = import_pinocchio()
        with quiet_stderr() as said:  # urdfdom prints its reasons on fd 2
            try:
                self.model = pin.buildModelFromUrdf(str(path))
            except Exception as e:  # noqa: BLE001 - its C++ exceptions: invalid_argument ...
                failed: Exception | None = e
            else:
                failed = None
        #: What urdfdom said while parsing (its "Error:" and warning lines), each once.
        self.warnings = list(dict.fromkeys(
            ln.removeprefix("Error:").strip() for ln in said.lines if not ln.startswith("at ")))
        if failed is not None:
            first = self.warnings[0] if self.warnings else ""
            raise engine_refusal(self.label, failed, display, first) from None
        self.data = self.model.createData()
        self._q = pin.neutral(self.model)
        self._v: Any = None
        self._placed = False
        self._index(self._read_joints())

    def _read_joints(self) -> list[EngineJoint]:
        import numpy as np

        pin, m = self.pin, self.model
        d = m.createData()
        q0 = pin.neutral(m)
        pin.computeJointJacobians(m, d, q0)
        out = []
        for i in range(1, m.njoints):
            j = m.joints[i]
            short = j.shortname().removeprefix("JointModel")
            kind = _KINDS.get(short, short.lower())
            c = Coordinate(str(m.names[i]), kind, j.shortname(),
                           int(j.idx_q), int(j.nq), int(j.idx_v), int(j.nv))
            lower = upper = math.nan
            if kind in ("revolute", "prismatic") and j.nq == 1:
                lower = float(m.lowerPositionLimit[j.idx_q])
                upper = float(m.upperPositionLimit[j.idx_q])
            else:  # unbounded, spherical, planar: no position limit held
                lower, upper = -math.inf, math.inf
            axis = (0.0, 0.0, 0.0)
            if j.nv == 1:  # the joint's motion in its own (the child link's) frame
                # (eigenpy gives a one-column matrix as a vector: shaped back)
                s = np.reshape(pin.getJointJacobian(m, d, i, pin.ReferenceFrame.LOCAL),
                               (6, m.nv))[:, j.idx_v]
                a = s[3:] if kind == "revolute" else s[:3]
                axis = (float(a[0]), float(a[1]), float(a[2]))
            v = int(j.idx_v)
            out.append(EngineJoint(
                c, float(m.damping[v]) if j.nv else 0.0,
                float(m.friction[v]) if j.nv else 0.0, lower, upper,
                float(np.min(m.effortLimit[v:v + j.nv])) if j.nv else None,
                float(np.min(m.velocityLimit[v:v + j.nv])) if j.nv else None, axis))
        return out

    def _frame_id(self, link: str) -> int:
        from urdfkit.core.errors import EngineError

        f = int(self.model.getFrameId(link, self.pin.FrameType.BODY))
        if f >= self.model.nframes:
            raise EngineError(f"link {link!r} has no frame in Pinocchio's model")
        return f

    def _engine_inertial(self, link: str) -> tuple[float, Any, Any]:
        """The body's mass properties on its first link (the joint's child or the root)."""
        import numpy as np

        m = self.model
        f = m.frames[self._frame_id(link)]
        first = link == self._links[0] or m.frames[f.parentFrame].type == \
            self.pin.FrameType.JOINT
        if not first:
            return 0.0, np.zeros(3), np.zeros((3, 3))
        inertia = m.inertias[f.parentJoint]
        # the joint's frame is its child link's, and the universe's the welded root's:
        # the body's inertia is in this link's frame (the frame's placement is identity)
        place = f.placement
        com = place.rotation.T @ (np.array(inertia.lever) - place.translation)
        tensor = place.rotation.T @ np.array(inertia.inertia) @ place.rotation
        return float(inertia.mass), com, tensor

    def _engine_set(self, q: dict[str, float], v: dict[str, float]) -> None:
        import numpy as np

        pin, m = self.pin, self.model
        self._q = pin.neutral(m)
        self._v = np.zeros(m.nv)
        for name, value in q.items():
            c = self._joint[name].coordinate
            if c.kind == "spherical":
                continue
            if c.nq == 2 and c.nv == 1:  # unbounded revolute: cos, sin
                self._q[c.q], self._q[c.q + 1] = math.cos(value), math.sin(value)
            elif c.nq == 1:
                self._q[c.q] = value
        for name, value in v.items():
            c = self._joint[name].coordinate
            self._v[c.v] = value
        self._placed = False

    def _engine_frame(self, link: str) -> Any:
        if not self._placed:
            self.pin.forwardKinematics(self.model, self.data, self._q)
            self.pin.updateFramePlacements(self.model, self.data)
            self._placed = True
        return self.data.oMf[self._frame_id(link)].homogeneous.copy()

    def _engine_mass_matrix(self) -> Any:
        import numpy as np

        nv = self.model.nv
        full = np.reshape(self.pin.crba(self.model, self.data, self._q), (nv, nv))
        self._placed = False
        return np.triu(full) + np.triu(full, 1).T  # crba fills the upper triangle

    def _engine_inverse_dynamics(self, a: dict[str, float]) -> Any:
        import numpy as np

        acc = np.zeros(self.model.nv)
        for name, value in a.items():
            acc[self._joint[name].coordinate.v] = value
        v = self._v if self._v is not None else np.zeros(self.model.nv)
        self._placed = False
        return np.array(self.pin.rnea(self.model, self.data, self._q, v, acc))

    def _engine_jacobian(self, link: str, point: Any) -> tuple[Any, Any]:
        import numpy as np

        pin, m, d = self.pin, self.model, self.data
        pin.computeJointJacobians(m, d, self._q)
        pin.updateFramePlacements(m, d)
        self._placed = True
        f = self._frame_id(link)
        j = np.reshape(pin.getFrameJacobian(m, d, f, pin.ReferenceFrame.LOCAL_WORLD_ALIGNED),
                       (6, m.nv))
        r = d.oMf[f].rotation @ point
        skew = np.array([[0.0, -r[2], r[1]], [r[2], 0.0, -r[0]], [-r[1], r[0], 0.0]])
        return j[:3] - skew @ j[3:], j[3:]
