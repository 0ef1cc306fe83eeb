"""``agree --engine``: the URDF as another engine loads it, compared with PyBullet row by row.

The same file goes to PyBullet (the fixed load ``agree`` always makes, and a floating one for
the masses: :class:`~urdfkit.exchange.agree_sides.PyBulletSide`) and to the other engine's own
URDF reader:

- ``pinocchio``, ``drake``: a :class:`~urdfkit.engine.welded.WeldedModel` (Pinocchio's
  ``buildModelFromUrdf``, Drake's ``Parser`` into a ``MultibodyPlant``), base welded, the
  kinematics and dynamics alone;
- ``mujoco-loader``: MuJoCo's own URDF reader, which the MJCF comparison
  (:func:`urdfkit.exchange.agree.agree`) takes as it takes an MJCF file;
- ``mujoco``: an MJCF file the user gives (``agree FILE MODEL.xml``).

The rows (:class:`EngineSides`) are those of the MJCF comparison where they ask the same
question, through the same functions: joints (names, kinds, order, limits, damping, effort and
velocity limits) by name, each joint's position and velocity index in both engines side by side
(:attr:`~urdfkit.exchange.agree_report.Agreement.indices`), masses, centres of mass and
inertia of each body (welded links fused, as :func:`urdfkit.formats.fk.fused` groups them),
naming the links PyBullet gives its default 1 kg, and the rows at seeded poses
(:func:`urdfkit.exchange.agree_poses.poses`): every link frame, the mass matrix and
inverse-dynamics torques. A joint order that differs is a known difference (a user maps
actions by name), not a failure.
"""

from __future__ import annotations

import importlib
import math
from dataclasses import dataclass, field
from typing import Any

from urdfkit.exchange.agree_report import (
    TOL_COM,
    TOL_EXACT,
    TOL_INERTIA,
    Agreement,
    AgreeOptions,
    worst,
)
from urdfkit.exchange.agree_sides import PyBulletSide, loaded_inertial
from urdfkit.formats.robot import LoadedRobot

#: ``agree --engine``'s choices: the MJCF file given, or the URDF in an engine's own reader.
AGREE_ENGINES = ("mujoco", "mujoco-loader", "pinocchio", "drake")
#: The engines loaded as a :class:`~urdfkit.engine.welded.WeldedModel`: ``module:class``.
_MODELS = {"pinocchio": "urdfkit.engine.pinocchio_model:PinocchioModel",
           "drake": "urdfkit.engine.drake_model:DrakeModel"}
#: Both engines' gravity (Pinocchio's and Drake's default), which PyBullet is given too.
GRAVITY = (0.0, 0.0, -9.81)
#: PyBullet diagonalises an ``<inertia>`` with products (``btMatrix3x3::diagonalize``,
#: threshold 1e-6, 30 sweeps): it stops once every off-diagonal term is at most 1e-6 x the
#: trace and drops what is left, so its tensor is off the file's by at most twice that (the
#: spectral norm of three such pairs). Measured on 114 robots: 1.3e-6 of the largest moment.
DIAGONALISE = 2e-6


@dataclass
class EngineSides:
    """Both sides of ``agree --engine pinocchio|drake`` and the rows so far.

    Attributes:
        robot: The URDF as read.
        options: How to compare.
        pb: The URDF in PyBullet.
        model: The URDF in the other engine, in PyBullet's indices.
        result: The rows so far.
        matched: PyBullet's movable joints the engine has, in PyBullet's order.
    """

    robot: LoadedRobot
    options: AgreeOptions
    pb: PyBulletSide
    model: Any
    result: Agreement
    matched: list[str]
    repaired: list[str] = field(default_factory=list)
    gravity: tuple[float, float, float] = GRAVITY
    #: kg m^2: PyBullet's rounding of the links' rotational inertia, summed (:func:`masses`).
    inertia_slack: float = 0.0
    #: The engine's model has no geometry (no self-contacts to compare).
    geometry = False

    def linked(self, link: str) -> bool:
        """Whether the engine has this link (each engine loads every link of the file)."""
        return link in self._links

    def snapped_sites(self, links: list[str]) -> dict[str, tuple[str, Any, float]]:
        """None: no engine here moves a link frame (MuJoCo's sites only)."""
        return {}

    @property
    def _links(self) -> set[str]:
        return set(self.model.link_names(0))


def agree_engine(resolved: Any, engine: str, options: AgreeOptions | None = None
                 ) -> Agreement:
    """Compare the resolved URDF in ``engine`` (:data:`AGREE_ENGINES` but ``mujoco``) with PyBullet.

    Raises:
        InputError: The engine refuses the file (its reason, one line).
        MissingDependencyError: The engine is not installed.
    """
    import numpy as np

    from urdfkit.engine.pybullet import PyBulletEngine
    from urdfkit.exchange.agree_poses import poses
    from urdfkit.formats.robot import read_robot

    o = options or AgreeOptions()
    if engine == "mujoco-loader":
        return _mujoco_loader(resolved, o)
    module, cls = _MODELS[engine].split(":")
    kind = getattr(importlib.import_module(module), cls)
    robot = read_robot(resolved.root, resolved.name)
    load = str(resolved.load_path)
    with np.errstate(all="ignore"):
        bullet = PyBulletEngine()
        try:
            pb = PyBulletSide(bullet, load, robot.file, o)
            model = kind(load, robot.file, pb.base, pb.joints)
            result = Agreement(robot.file, robot.file, load_flags=pb.flags,
                               warnings=list(getattr(model, "warnings", [])),
                               engine=model.label)
            bullet.set_gravity(GRAVITY)
            s = EngineSides(robot, o, pb, model, result,
                            [n for n in pb.names if model.engine_joint(n) is not None])
            result.add("structure", "base", None, None, "", "welded on both sides for "
                       "the comparison (a free base is the caller's root joint in "
                       f"{model.label})", status="info")
            joint_rows(s)
            masses(s)
            poses(s)
        finally:
            bullet.close()
    return result


def _mujoco_loader(resolved: Any, o: AgreeOptions) -> Agreement:
    """The URDF through MuJoCo's own reader, compared as an MJCF file is.

    MuJoCo reads the file where it is (its meshes from its folder, as its reader looks for
    them); a xacro, or a file whose references were rewritten, through its expanded copy.
    """
    from urdfkit.exchange.agree import agree

    source = resolved.source
    result = agree(resolved, source if source.suffix == ".urdf" else resolved.load_path, o)
    result.model = str(resolved.name)
    result.engine = "MuJoCo's URDF reader"
    return result


# ---- joints


def joint_rows(s: EngineSides) -> None:
    """Names, indices, order, kinds, limits, damping, effort and velocity limits."""
    from urdfkit.exchange.agree_structure import limit_error

    pb, res, model = s.pb, s.result, s.model
    label = model.label
    moving = [c for c in model.coordinates if c.kind != "fixed"]
    res.unmatched_joints = [n for n in pb.names if n not in s.matched]
    res.extra_joints = [c.name for c in moving if c.name not in pb.names]
    missing = res.unmatched_joints + [f"+{n}" for n in res.extra_joints]
    res.add("structure", "joint names", float(len(missing)), 0.0, "unmatched",
            ", ".join(missing[:6]) + (" ..." if len(missing) > 6 else ""))
    res.indices = _indices(s, moving)
    if not s.matched:
        res.add("structure", "joints", None, None, "", "no movable joints" if not pb.names
                else "not compared: no joint matched", status="info")
        return
    theirs = sorted(s.matched, key=lambda n: model.engine_joint(n).coordinate.v)
    bad = next(((a, b) for a, b in zip(s.matched, theirs, strict=True) if a != b), None)
    res.add("structure", "joint order", 0.0 if bad is None else 1.0, None, "moved",
            f"{len(theirs)} joints in PyBullet's order" if bad is None else
            f"{label} numbers {bad[1]} where PyBullet has {bad[0]}: map actions by name "
            "(the index table)", status="pass" if bad is None else "known")
    urdf = {j.name: j for j in s.robot.joints}
    ours = {pb.joints[i].name: pb.joints[i] for i in pb.movable}
    kinds: list[str] = []
    twice: list[str] = []
    one_sided: list[str] = []
    limits: list[tuple[float, str]] = []
    damping: list[tuple[float, str]] = []
    effort: list[tuple[float, str]] = []
    speed: list[tuple[float, str]] = []
    for n in s.matched:
        mine, e = ours[n], model.engine_joint(n)
        c = e.coordinate
        if mine.kind != c.kind:
            kinds.append(f"{n} ({mine.kind} in PyBullet, {c.detail} in {label})")
            continue
        if c.kind == "revolute" and c.nq != c.nv:
            twice.append(n)
        if c.kind != "spherical":
            held = math.isfinite(e.lower) and math.isfinite(e.upper)
            limits.append((limit_error(urdf[n], mine.lower, mine.upper, held, e.lower,
                                       e.upper), _limits_said(urdf[n], e, label)))
        damping.append((abs(mine.damping - e.damping), n))
        for items, a, b in ((effort, mine.effort, e.effort), (speed, mine.velocity,
                                                              e.velocity)):
            given = a > 0  # PyBullet's 0: none given
            held = b is not None and math.isfinite(b) and b > 0
            if given and held:
                items.append((abs(a - b) / max(a, b), n))
            elif given != held:
                one_sided.append(f"{n} {'effort' if items is effort else 'velocity'}")
    res.add("structure", "joint kinds", float(len(kinds)), 0.0, "differ",
            "; ".join(kinds[:3]) + (" ..." if len(kinds) > 3 else ""))
    if twice:
        res.add("structure", "continuous joints' positions", float(len(twice)), None, "known",
                f"{', '.join(twice[:4])}{' ...' if len(twice) > 4 else ''}: {label} holds "
                "cos and sin (2 positions, 1 velocity), PyBullet the angle", status="known")
    for what, items, unit in (("joint limits", limits, "rad|m"),
                              ("joint damping", damping, "N m s/rad")):
        v, d = worst(items)
        res.add("structure", what, v, TOL_EXACT, unit, d if items else
                "not compared: only ball joints matched", status=None if items else "info")
    for what, items in (("joint effort limits", effort), ("joint velocity limits", speed)):
        word = what.split()[1]
        alone = [x.split()[0] for x in one_sided if x.endswith(word)]
        said = (f"; {label} holds none for {', '.join(alone[:3])}"
                f"{' ...' if len(alone) > 3 else ''}" if alone else "")
        if items:
            v, d = worst(items)
            res.add("structure", what, v, TOL_EXACT, "relative", d + said)
        elif alone:
            res.add("structure", what, None, None, "", f"not compared{said}" + (
                " (Drake holds an effort limit only on a <transmission>'s actuator)"
                if word == "effort" and model.name == "drake" else ""), status="known")


def _limits_said(joint: Any, e: Any, label: str) -> str:
    """Both sides' limits: PyBullet's those it holds (a continuous joint's <limit>: none)."""
    def span(limited: bool, lo: float, hi: float) -> str:
        return f"{lo:g} .. {hi:g}" if limited else "none"

    held = math.isfinite(e.lower) and math.isfinite(e.upper)
    kind = f" ({joint.declared_type or joint.type} in the file)" if not joint.limited and held \
        else ""
    return (f"{joint.name}{kind}: PyBullet holds {span(joint.limited, joint.lower, joint.upper)}"
            f", {label} {span(held, e.lower, e.upper)}")


def _indices(s: EngineSides, moving: list[Any]) -> list[dict[str, object]]:
    """Each movable joint's indices in PyBullet and in the engine, PyBullet's order first."""
    pb, model = s.pb, s.model
    out: list[dict[str, object]] = []
    for action, i in enumerate(pb.movable):
        j = pb.joints[i]
        e = model.engine_joint(j.name)
        c = e.coordinate if e is not None else None
        out.append({"joint": j.name, "pybullet": {"index": j.index, "action": action,
                                                  "q": j.q_index, "u": j.v_index},
                    "engine": None if c is None else {
                        "kind": c.detail, "q": c.q, "nq": c.nq, "v": c.v, "nv": c.nv}})
    for c in moving:
        if c.name not in pb.names:
            out.append({"joint": c.name, "pybullet": None, "engine": {
                "kind": c.detail, "q": c.q, "nq": c.nq, "v": c.v, "nv": c.nv}})
    return out


# ---- masses


def masses(s: EngineSides) -> None:
    """Total mass, and each body's (welded links fused) mass, centre of mass and inertia."""
    import numpy as np

    from urdfkit.core.errors import EngineError
    from urdfkit.exchange.agree_structure import defaults_said
    from urdfkit.formats.fk import fused, link_frames
    from urdfkit.formats.mjcf import combine

    res, robot, pb, label = s.result, s.robot, s.pb, s.model.label
    where = fused(robot)
    zero = link_frames(robot, {})
    ours: dict[str, list[Any]] = {}
    theirs: dict[str, list[Any]] = {}
    try:
        for link, (group, _) in where.items():
            if link not in pb.link_index:
                continue
            ours.setdefault(group, []).append((pb.inertial(link), zero[link]))
            theirs.setdefault(group, []).append(
                (loaded_inertial(s.model.dynamics(0, pb.link_index[link])), zero[link]))
    except EngineError as e:
        res.add("structure", "body masses", None, None, "", f"not compared: {e.message}")
        return
    total_pb = sum(i.mass for parts in ours.values() for i, _ in parts)
    total_e = sum(i.mass for parts in theirs.values() for i, _ in parts)
    off = abs(total_pb - total_e)
    res.add("structure", "total mass", off / max(total_pb, total_e, 1e-300), TOL_EXACT,
            "relative", f"PyBullet {total_pb!r} kg, {label} {total_e!r} kg"
            + defaults_said(robot, list(robot.links), off))
    names = {g: [n for n, (h, _) in where.items() if h == g and n in pb.link_index]
             for g in ours}
    slack = _rounding(ours, names, robot)
    s.inertia_slack = sum(slack.values())
    mass, com, inertia = [], [], []
    for group, parts in ours.items():
        a, b = combine(parts), combine(theirs[group])
        mass.append((abs(a.mass - b.mass) / max(a.mass, b.mass, 1e-300), group))
        if a.mass <= 0 or b.mass <= 0:
            continue
        com.append((float(np.abs(a.com - b.com).max()), group))
        scale = max(float(np.abs(a.tensor).max()), float(np.abs(b.tensor).max()), 1e-300)
        off = float(np.abs(a.tensor - b.tensor).max()) - slack.get(group, 0.0)
        said = group
        # Bullet keeps the mass of a link whose tensor it zeroes (a `world` it weighs 0)
        zeroed = [n for n, (i, _) in zip(names[group], parts, strict=True)
                  if i.mass > 0 and not np.any(i.tensor)
                  and np.any(robot.links[n].inertial.tensor)]
        if zeroed:
            said += f": PyBullet holds a zero tensor on {', '.join(zeroed[:3])} (the " \
                "file's breaks the triangle inequality: Bullet zeroes it)"
        inertia.append((max(off, 0.0) / scale, said))
    v, d = worst(mass)
    members = [n for n, (g, _) in where.items() if g == d]
    res.add("structure", "body masses", v, TOL_EXACT, "relative",
            d + (defaults_said(robot, members, v) if v > TOL_EXACT else ""))
    for what, items, tol in (("centres of mass", com, TOL_COM),
                             ("inertia tensors", inertia, TOL_INERTIA)):
        if items:
            v, d = worst(items)
            if what[0] == "i" and s.inertia_slack:
                d += f" (PyBullet's diagonalisation allowed for: {s.inertia_slack:.2g} kg m^2 " \
                    "over the links with products of inertia)"
            res.add("structure", what, v, tol, "m" if what[0] == "c" else "relative", d)


def _rounding(ours: dict[str, list[Any]], names: dict[str, list[str]], robot: LoadedRobot
              ) -> dict[str, float]:
    """Each body's allowance for PyBullet's diagonalisation (:data:`DIAGONALISE`), kg m^2.

    The sum over its links whose tensor in the file has products of inertia and which
    PyBullet loaded off the file's by no more than Bullet's stopping rule explains (measured
    against the file, not the other engine, which may hold a fused body's inertia on one of
    its links); a link off by more gets none (the row shows it whole).
    """
    import numpy as np

    out: dict[str, float] = {}
    for group, parts in ours.items():
        total = 0.0
        for name, (mine, _) in zip(names[group], parts, strict=True):
            t = np.array(mine.tensor, dtype=float)
            u = np.array(robot.links[name].inertial.tensor, dtype=float)
            if not np.isfinite(t).all() or not np.isfinite(u).all():
                continue
            if not np.any(u - np.diag(np.diag(u))):
                continue  # no products: PyBullet takes the moments as they are
            bound = DIAGONALISE * abs(float(np.trace(u)))
            if float(np.linalg.norm(t - u, 2)) <= bound:
                total += bound
        if total:
            out[group] = total
    return out
