"""A URDF as Drake loads it (``Parser.AddModels``), base welded, in PyBullet's indices.

Drake parses the file into a continuous ``MultibodyPlant`` with no SceneGraph: the kinematics
and the dynamics, no geometry (``check --target drake`` judges the geometry a simulation
loads). The root link is welded to the world, as PyBullet's fixed load; each link is a body of
its own. What Drake says while parsing is kept (:attr:`DrakeModel.warnings`), not printed.
"""

from __future__ import annotations

import logging
from collections.abc import Sequence
from typing import Any

from urdfkit.core.errors import import_optional
from urdfkit.engine.api import JointInfo
from urdfkit.engine.welded import Coordinate, EngineJoint, WeldedModel, engine_refusal

#: Drake's joint types (``type_name()``) in the seam's words.
_KINDS = {"revolute": "revolute", "prismatic": "prismatic", "ball_rpy": "spherical",
          "planar": "planar", "weld": "fixed", "quaternion_floating": "floating",
          "rpy_floating": "floating"}


def import_drake() -> Any:
    """The ``pydrake.all`` module.

    Raises:
        MissingDependencyError: Drake is not installed (``urdfkit[engines]`` named).
    """
    return import_optional("pydrake.all", "Drake", "agree --engine drake", "engines")


class _Kept(logging.Handler):
    def __init__(self) -> None:
        super().__init__()
        self.said: list[str] = []

    def emit(self, record: logging.LogRecord) -> None:
        self.said.append(" ".join(record.getMessage().split()))


class DrakeModel(WeldedModel):
    """The URDF at ``path`` in Drake, base welded (a :class:`Model` of one body, 0).

    Raises:
        InputError: Drake refuses the file, with its reason.
        MissingDependencyError: Drake is not installed.
    """

    name = "drake"
    label = "Drake"

    def __init__(self, path: str, display: str, root: str,
                 layout: Sequence[JointInfo]) -> None:
        super().__init__(root, layout)
        d = self.drake = import_drake()
        log = logging.getLogger("drake")
        kept, was = _Kept(), log.propagate
        log.addHandler(kept)
        log.propagate = False
        try:
            plant = d.MultibodyPlant(0.0)
            d.Parser(plant).AddModels(str(path))
            if root != "world":  # Drake's world is a link named so
                plant.WeldFrames(plant.world_frame(), plant.GetBodyByName(root).body_frame())
            plant.Finalize()
        except Exception as e:  # noqa: BLE001 - Drake's C++ errors arrive as RuntimeError
            raise engine_refusal(self.label, e, display) from None
        finally:
            log.removeHandler(kept)
            log.propagate = was
        #: What Drake warned while parsing, each once.
        self.warnings = list(dict.fromkeys(kept.said))
        self.plant = plant
        self.context = plant.CreateDefaultContext()
        self._index(self._read_joints())

    def _read_joints(self) -> list[EngineJoint]:
        import math

        d, plant = self.drake, self.plant
        effort = {}
        for i in range(plant.num_actuators()):
            a = plant.get_joint_actuator(d.JointActuatorIndex(i))
            effort[a.joint().name()] = float(a.effort_limit())
        out = []
        for i in range(plant.num_joints()):
            j = plant.get_joint(d.JointIndex(i))
            kind = _KINDS.get(j.type_name(), j.type_name())
            c = Coordinate(j.name(), kind, j.type_name(),
                           int(j.position_start()), int(j.num_positions()),
                           int(j.velocity_start()), int(j.num_velocities()))
            lower, upper = -math.inf, math.inf
            velocity = None
            if j.num_positions() == 1:
                lower = float(j.position_lower_limits()[0])
                upper = float(j.position_upper_limits()[0])
                velocity = float(j.velocity_upper_limits()[0])
            axis = (0.0, 0.0, 0.0)
            if kind == "revolute":
                axis = tuple(float(x) for x in j.revolute_axis())  # type: ignore[assignment]
            elif kind == "prismatic":
                axis = tuple(float(x) for x in j.translation_axis())  # type: ignore[assignment]
            damping: Any = j.default_damping() if hasattr(j, "default_damping") and \
                j.num_velocities() else 0.0
            if hasattr(damping, "__len__"):  # a ball joint's: one per velocity
                damping = max(damping, default=0.0)
            out.append(EngineJoint(c, float(damping), 0.0, lower, upper,
                                   effort.get(j.name()), velocity, axis))
        return out

    def _body(self, link: str) -> Any:
        from urdfkit.core.errors import EngineError

        if link == "world":
            return self.plant.world_body()
        if not self.plant.HasBodyNamed(link):
            raise EngineError(f"link {link!r} has no body in Drake's plant")
        return self.plant.GetBodyByName(link)

    def _engine_inertial(self, link: str) -> tuple[float, Any, Any]:
        import numpy as np

        b = self._body(link)
        if link == "world":
            return 0.0, np.zeros(3), np.zeros((3, 3))
        mass = float(b.default_mass())
        inertia = b.default_spatial_inertia()
        com = np.array(inertia.get_com(), dtype=float)
        about_origin = np.array(inertia.CalcRotationalInertia().CopyToFullMatrix3())
        # about the centre of mass (parallel axes)
        tensor = about_origin - mass * (com @ com * np.eye(3) - np.outer(com, com))
        return mass, com, tensor

    def _engine_set(self, q: dict[str, float], v: dict[str, float]) -> None:
        import numpy as np

        plant, ctx = self.plant, self.context
        # the plant's defaults, not zeros: a floating joint's quaternion starts at 1 0 0 0
        qs = np.array(plant.GetDefaultPositions(), dtype=float)
        vs = np.zeros(plant.num_velocities())
        for name, value in q.items():
            c = self._joint[name].coordinate
            if c.nq == 1:
                qs[c.q] = value
        for name, value in v.items():
            c = self._joint[name].coordinate
            if c.nv == 1:
                vs[c.v] = value
        plant.SetPositions(ctx, qs)
        plant.SetVelocities(ctx, vs)

    def _engine_frame(self, link: str) -> Any:
        return self.plant.EvalBodyPoseInWorld(self.context, self._body(link)).GetAsMatrix4()

    def _engine_mass_matrix(self) -> Any:
        return self.plant.CalcMassMatrix(self.context)

    def _engine_inverse_dynamics(self, a: dict[str, float]) -> Any:
        import numpy as np

        d, plant = self.drake, self.plant
        acc = np.zeros(plant.num_velocities())
        for name, value in a.items():
            acc[self._joint[name].coordinate.v] = value
        # Drake's inverse dynamics leave gravity out (it is a force applied): added back
        forces = d.MultibodyForces_[float](plant)
        return plant.CalcInverseDynamics(self.context, acc, forces) \
            - plant.CalcGravityGeneralizedForces(self.context)

    def _engine_jacobian(self, link: str, point: Any) -> tuple[Any, Any]:
        d, plant = self.drake, self.plant
        frame, world = self._body(link).body_frame(), plant.world_frame()
        kv = d.JacobianWrtVariable.kV
        lin = plant.CalcJacobianTranslationalVelocity(self.context, kv, frame, point, world,
                                                      world)
        ang = plant.CalcJacobianAngularVelocity(self.context, kv, frame, world, world)
        return lin, ang
