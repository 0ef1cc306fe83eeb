"""``agree``'s two sides, matched: the URDF in PyBullet and the MJCF file in MuJoCo.

Both are :class:`~urdfkit.engine.api.Model` implementations in PyBullet's indices: PyBullet's
is :class:`~urdfkit.engine.pybullet.PyBulletEngine` itself (:class:`PyBulletSide` keeps its
loads and the names ``agree`` reads), MuJoCo's the file's
:class:`~urdfkit.engine.mujoco_file_model.MjcfModel`, built from the matching of
:mod:`urdfkit.exchange.agree_tree`. :class:`Sides` holds the two and the rows so far; the
structure, poses, contacts and swing modules each add their rows to it.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any, Protocol

from urdfkit.core.errors import EngineError
from urdfkit.engine.api import JointInfo, LinkDynamics, LoadSettings
from urdfkit.exchange.agree_report import Agreement, AgreeOptions
from urdfkit.exchange.agree_tree import Matching, match_models
from urdfkit.formats.robot import LoadedInertial, LoadedRobot

if TYPE_CHECKING:
    from urdfkit.engine.mujoco_file import MjcfFile
    from urdfkit.engine.mujoco_file_model import MjcfModel
    from urdfkit.engine.pybullet import PyBulletEngine


def _matrix(pos: Any, orn: Any) -> Any:
    """A pose as a 4 x 4 transform, its quaternion normalised first.

    PyBullet's quaternions are float32 products, up to ~4e-7 off unit length where a link's
    inertial frame is turned (youBot's casters): the unit formula would add 2x that to the
    matrix; normalised, as PyBullet's getMatrixFromQuaternion does.
    """
    import numpy as np

    from urdfkit.model.spec import quat_to_matrix

    t = np.eye(4)
    norm = math.sqrt(sum(c * c for c in orn))
    t[:3, :3] = quat_to_matrix([c / norm for c in orn])
    t[:3, 3] = pos
    return t


def loaded_inertial(d: LinkDynamics) -> LoadedInertial:
    """A link's mass properties as an engine reports them, as the file's: link frame axes."""
    import numpy as np

    from urdfkit.model.spec import quat_to_matrix

    r = np.array(quat_to_matrix(d.inertial_orientation))
    tensor = r @ np.diag(d.inertia) @ r.T
    return LoadedInertial(float(d.mass), d.inertial_position,
                          tuple(map(tuple, tensor)))  # type: ignore[arg-type]


class PyBulletSide:
    """The URDF in PyBullet: a floating load for masses, a fixed one for the rest.

    Attributes:
        engine: The engine both loads are in.
        flags: The load flags, by name.
        body: The fixed load.
        joints: Its joints (PyBullet's ``getJointInfo``).
        base: Its root link's name.
        link_index: Each link's index (the root -1).
        movable, names: The revolute, prismatic and spherical joints (planar ones export
            refuses): indices and names.
        one, one_names: The 1-dof joints, which the poses and the swing move (spherical ones
            stay at rest).
        spherical: The spherical joints' names.
    """

    def __init__(self, engine: PyBulletEngine, path: str, display: str,
                 options: AgreeOptions) -> None:
        from urdfkit.engine.pybullet import PyBulletEngine

        fixed = LoadSettings(fixed_base=True, inertia_from_file=options.inertia_from_file,
                             self_collision=options.self_collision)
        self.flags = PyBulletEngine.load_flags(fixed)
        self.engine = engine
        self.reload = (path, display, LoadSettings(
            inertia_from_file=options.inertia_from_file, self_collision=options.self_collision))
        free = engine.load(path, self.reload[2], display)
        self.body = engine.load(path, fixed, display)
        self.joints = engine.joints(self.body)
        self.base = engine.link_names(self.body)[0]
        self.link_index = {self.base: -1}
        for j in self.joints:
            self.link_index[j.link] = j.index
        self.movable = [j.index for j in self.joints
                        if j.kind in ("revolute", "prismatic", "spherical")]
        self.names = [self.joints[i].name for i in self.movable]
        self.one = [i for i in self.movable if self.joints[i].kind != "spherical"]
        self.one_names = [self.joints[i].name for i in self.one]
        self.spherical = [n for i, n in zip(self.movable, self.names, strict=True)
                          if self.joints[i].kind == "spherical"]
        # the floating copy's mass properties, read now: it must not fall onto the other
        self._inertials = {n: self._inertial(free, i) for n, i in self.link_index.items()}
        engine.remove_body(free)

    def _inertial(self, body: int, index: int) -> LoadedInertial:
        return loaded_inertial(self.engine.dynamics(body, index))

    def inertial(self, link: str) -> LoadedInertial:
        """A link's mass properties as PyBullet loaded them (floating load), link frame."""
        return self._inertials[link]

    def swinger(self, floating: bool, q0: dict[str, float], v0: dict[str, float],
                time_step: float) -> int:
        """The body to swing, set at ``q0`` (speeds ``v0``).

        The fixed load, or a floating one at rest at the origin; motors, link damping and
        contacts off, as MuJoCo is set.
        """
        e = self.engine
        body = self.body
        if floating:
            path, display, load = self.reload
            body = e.load(path, load, display)
        e.set_time_step(time_step)
        for i, n in zip(self.one, self.one_names, strict=True):
            e.reset_joint(body, i, q0.get(n, 0.0), v0.get(n, 0.0))
        e.motors(body, self.movable, "velocity", [0.0] * len(self.movable),
                 forces=[0.0] * len(self.movable))
        for i in range(-1, len(self.joints)):
            e.change_dynamics(body, i, linearDamping=0.0, angularDamping=0.0)
            # contacts off on this side too (URDF_USE_SELF_COLLISION would collide links)
            e.set_collision_filter(body, i, 0, 0)
        return int(body)

    def base_frame(self, body: int) -> Any:
        """The root link's frame (4x4, world): PyBullet reports the base's inertial frame."""
        import numpy as np

        d = self.engine.dynamics(body, -1)
        # in double precision: PyBullet's invertTransform and multiplyTransforms round to
        # float32 (bicycle's turned inertial frame: 1.9e-7 in the matrix)
        return _matrix(*self.engine.base_pose(body)) @ np.linalg.inv(
            _matrix(d.inertial_position, d.inertial_orientation))

    def pose(self, q: dict[str, float]) -> None:
        """The 1-dof joints at ``q`` (0 where not given), at rest."""
        for i, name in zip(self.one, self.one_names, strict=True):
            self.engine.reset_joint(self.body, i, q.get(name, 0.0), 0.0)

    def frames(self, links: list[str]) -> dict[str, Any]:
        """These links' frames now (4 x 4, world); none past PyBullet's state queries."""
        from urdfkit.exchange.bullet_state import unreadable_state

        if unreadable_state(self.joints):
            return {}  # none to compare (the row says why)
        return {n: _matrix(*self.engine.link_frame(self.body, self.link_index[n]))
                for n in links}

    def dynamics(self, q: list[float], qd: list[float], qdd: list[float],
                 turned_back: Any, gravity: tuple[float, float, float]
                 ) -> tuple[Any, Any] | str:
        """The mass matrix and inverse-dynamics torques at one state, or why PyBullet refuses.

        PyBullet's calculateInverseDynamics turns gravity by the base's inertial orientation
        (measured: bicycle/bike.urdf, base inertial rpy 1.57 0 0, 0.656 N m where MuJoCo and
        the swing say 0.0525): handed gravity turned back, it answers for the world's.
        """
        import numpy as np

        e = self.engine
        try:
            pm = np.array(e.mass_matrix(self.body, q))
        except EngineError as refusal:
            return f"calculateMassMatrix fails on this model ({refusal.message})"
        e.set_gravity(tuple(map(float, turned_back)))  # type: ignore[arg-type]
        try:
            tau = np.array(e.inverse_dynamics(self.body, q, qd, qdd))
        except EngineError as refusal:
            return f"calculateInverseDynamics fails on this model ({refusal.message})"
        finally:
            e.set_gravity(gravity)
        return pm, tau


class PoseSides(Protocol):
    """What the rows at seeded poses ask of a comparison.

    :class:`Sides` (an MJCF file) and :class:`~urdfkit.exchange.agree_engines.EngineSides`
    (``--engine``) both answer it.
    """

    robot: LoadedRobot
    options: AgreeOptions
    pb: PyBulletSide
    result: Agreement
    matched: list[str]
    repaired: list[str]
    geometry: bool
    inertia_slack: float

    @property
    def model(self) -> Any:
        """The other side, a :class:`~urdfkit.engine.api.Model` with ``link_matrices``."""
        ...

    @property
    def gravity(self) -> tuple[float, float, float]:
        """The gravity both sides are given."""
        ...

    def linked(self, link: str) -> bool:
        """Whether the other side has this link."""
        ...

    def snapped_sites(self, links: list[str]) -> dict[str, tuple[str, Any, float]]:
        """Links the other side computes at another frame: link -> (body, where, by)."""
        ...


@dataclass
class Sides:
    """Both sides of one comparison, matched, and the rows so far.

    Attributes:
        robot: The URDF as read.
        options: How to compare.
        pb: The URDF in PyBullet.
        mjcf: The MJCF file.
        model: The file's :class:`~urdfkit.engine.mujoco_file_model.MjcfModel`.
        match: Which body, site and joint is which link and joint.
        result: The rows so far.
        matched: PyBullet's movable joints that have a joint in the file, in its order.
        repaired: Links PyBullet zeroes whose body the MJCF gives another inertia (set by
            the masses' rows).
    """

    robot: LoadedRobot
    options: AgreeOptions
    pb: PyBulletSide
    mjcf: MjcfFile
    model: MjcfModel
    match: Matching
    result: Agreement
    matched: list[str]
    repaired: list[str] = field(default_factory=list)

    @property
    def jnt(self) -> dict[str, int]:
        """URDF joint name -> the welded copy's joint id."""
        return self.match.joints

    @property
    def body(self) -> dict[str, int]:
        """URDF link name -> MuJoCo body id."""
        return self.match.bodies

    @property
    def site(self) -> dict[str, int]:
        """URDF link name -> MuJoCo site id."""
        return self.match.sites

    def mj_joints(self) -> dict[str, JointInfo]:
        """The file's joint matched to each of PyBullet's movable joints, by name."""
        return {j.name: j for j in self.model.joints(0) if j.name in self.jnt}

    def weld_image(self, where: dict[str, tuple[str, Any]], weld: list[int]
                   ) -> dict[str, int]:
        """Each PyBullet body group -> the MuJoCo weld group its matched links are in.

        The groups are ``where``'s (:func:`urdfkit.formats.fk.fused`); the weld groups
        ``weld``'s (a :class:`~urdfkit.engine.mujoco_file.Tree`'s: body ids are the same in
        the model as written and its base-welded copy).
        """
        image: dict[str, int] = {}
        for link, (group, _) in where.items():
            if group in image:
                continue
            if link in self.body:
                image[group] = weld[self.body[link]]
            elif link in self.site:
                image[group] = weld[self.mjcf.tree.site_body[self.site[link]]]
        return image

    def root_free(self) -> int | None:
        """The free joint of the robot's root body in the MJCF as written (no other's)."""
        return self.mjcf.root_free(self.body.get(self.robot.root))

    def snapped_sites(self, links: list[str]) -> dict[str, tuple[str, Any, float]]:
        """Matched sites MuJoCo's compiler moved onto their body's frame.

        Link -> (body, where, by): ``body`` is the URDF link of the site's body (matched by
        name or by the tree's shape); ``where`` and ``by`` are
        :meth:`~urdfkit.engine.mujoco_file.MjcfFile.snapped_sites`'.
        """
        moved = self.mjcf.snapped_sites()
        frames = {j.child for j in self.robot.joints} | {self.robot.root}
        out: dict[str, tuple[str, Any, float]] = {}
        for n in links:
            if n in self.body or n not in self.site or self.site[n] not in moved:
                continue
            where, by = moved[self.site[n]]
            b = self.mjcf.tree.site_body[self.site[n]]
            body = next((link for link, i in self.body.items() if i == b), "")
            if body in frames:
                out[n] = (body, where, by)
        return out

    @property
    def gravity(self) -> tuple[float, float, float]:
        """The MJCF's gravity, which PyBullet is given too."""
        return self.mjcf.gravity

    #: The MJCF has collision geometry (self-contacts at the poses are compared).
    geometry = True
    #: No rounding of PyBullet's to allow for: export writes the inertia PyBullet loaded.
    inertia_slack = 0.0

    def linked(self, link: str) -> bool:
        """Whether a link has a body or site in the MJCF."""
        return link in self.body or link in self.site

    def pybullet_static(self) -> bool:
        """Whether PyBullet's root does not move: welded, ``world``, or of mass 0."""
        root = self.robot.links[self.robot.root]
        return self.options.fixed_base or self.robot.root == "world" or root.inertial.mass == 0


def sides(robot: LoadedRobot, mjcf: MjcfFile, engine: PyBulletEngine, load_path: str,
          model_path: str, options: AgreeOptions) -> Sides:
    """The URDF loaded in ``engine``, matched with ``mjcf``; no rows yet.

    Raises:
        ParameterError: A ``--map`` name the URDF or the MJCF does not have.
    """
    from urdfkit.engine.mujoco_file_model import MjcfModel

    pb = PyBulletSide(engine, load_path, robot.file, options)
    result = Agreement(robot.file, model_path, load_flags=pb.flags,
                       warnings=list(mjcf.warnings))
    #: URDF names -> MuJoCo ids: by name, by ``--map``, then by the tree's shape
    match = match_models(mjcf.tree, robot, pb.names, options.name_map)
    result.matched_by = [{"urdf": a, "mjcf": b, "how": how} for a, b, how in match.pairs]
    frames = {n: ("site", i) for n, i in match.sites.items()}
    frames.update({n: ("body", i) for n, i in match.bodies.items()})
    model = MjcfModel(mjcf, pb.base, pb.joints, frames, match.joints)
    # PyBullet's world has no gravity until set: MuJoCo's, for inverse dynamics and swing
    engine.set_gravity(mjcf.gravity)
    return Sides(robot, options, pb, mjcf, model, match, result,
                 [n for n in pb.names if n in match.joints])
