"""``urdfkit collisions``: which links of a robot touch each other, at rest and across poses.

A robot whose links interpenetrate at its start pose jitters or explodes the moment self-
collision is turned on (``URDF_USE_SELF_COLLISION``): the solver pushes the pair apart every
step. This module finds those pairs the way PyBullet sees them:

- The robot is loaded with a fixed base and nothing is simulated, on PyBullet through the
  engine seam (:mod:`urdfkit.engine.api`). Each pose is set with ``reset_joint``
  (``resetJointState``, which updates the link colliders at once), and every pair of links
  that both have collision shapes is measured with ``closest_points(body, body, margin,
  linkA, linkB)`` (``getClosestPoints``): the signed distance of the two links' collision
  shapes, negative when they interpenetrate. That query ignores collision filters, so it
  reports a pair whether or not a user later disables it.
- A link and its parent are never tested: PyBullet's multibody collider skips parent-child
  pairs (``btMultiBodyLinkCollider::checkCollideWithOverride``) unless a user loads with
  ``URDF_USE_SELF_COLLISION_INCLUDE_PARENT``. They are counted and said to be skipped.
- A concave mesh collides as its convex hull (one hull per OBJ object): a pair involving one
  may be "in contact" only across a hull's dips. Such pairs name the concave link.

Random poses are drawn from a seeded ``numpy`` generator within each joint's limits
(continuous and unlimited revolute joints over -pi..pi; unlimited prismatic joints stay at 0).
A ``<mimic>`` joint follows its leader (``multiplier * leader + offset``), as the real
mechanism does, so a gripper's mirrored fingers are never posed into each other by chance.
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from lxml import etree

from urdfkit.core.errors import InputError, ParameterError
from urdfkit.engine.api import JointInfo, LoadSettings, Simulator
from urdfkit.model.spec import atof, ignored_shape, numbers
from urdfkit.model.xmlio import children, line_of
from urdfkit.sources.resolve import Resolved

#: Most random poses one run may draw (each costs one distance query per link pair).
MAX_SAMPLES = 100_000


@dataclass
class Pair:
    """Two links whose collision shapes touch or interpenetrate in at least one pose.

    Attributes:
        link_a: The link with the lower PyBullet index (the base link is -1).
        link_b: The other link.
        index_a: PyBullet link index of ``link_a`` (-1 for the base).
        index_b: PyBullet link index of ``link_b``.
        distance: The smallest signed distance over all poses, m: negative is a penetration
            depth.
        poses_in_contact: In how many of the poses the pair touched (distance <= margin).
        hull: The links of the pair with a concave collision mesh: PyBullet collides with its
            convex hull, so the contact may be in the hull's dips, not on the surface.
    """

    link_a: str
    link_b: str
    index_a: int
    index_b: int
    distance: float
    poses_in_contact: int
    hull: list[str] = field(default_factory=list)

    def to_dict(self) -> dict[str, Any]:
        """The JSON form."""
        return {"link_a": self.link_a, "link_b": self.link_b, "link_index_a": self.index_a,
                "link_index_b": self.index_b, "distance": self.distance,
                "poses_in_contact": self.poses_in_contact, "convex_hull_of": self.hull}


@dataclass
class Collisions:
    """The self-collision pairs of one robot.

    Attributes:
        file: The file as the user named it.
        robot: The ``<robot name>``.
        poses: How many poses were tested: the start pose plus the samples.
        samples: How many of them were random.
        seed: The seed of the random poses.
        margin: The distance, m, at or below which a pair counts as in contact.
        joints: The joint positions pinned by the caller, in every pose.
        pairs: Pairs in contact in at least one pose, most often first, then deepest first.
        tested: How many link pairs were measured in each pose.
        skipped_adjacent: Parent-child pairs, not tested (PyBullet never tests them).
        without_shapes: Links with no collision shape (nothing to collide).
        warnings: What the caller should know (values beyond limits, unsampled joints).
    """

    file: str
    robot: str
    poses: int
    samples: int
    seed: int
    margin: float
    joints: dict[str, float]
    pairs: list[Pair]
    tested: int
    skipped_adjacent: list[tuple[str, str]]
    without_shapes: list[str]
    warnings: list[str] = field(default_factory=list)

    def always(self) -> list[Pair]:
        """Pairs in contact in every pose tested: the ones to filter out."""
        return [x for x in self.pairs if x.poses_in_contact == self.poses]

    def to_dict(self) -> dict[str, Any]:
        """The ``--json`` form (docs/collisions.md)."""
        return {"file": self.file, "robot": self.robot, "poses": self.poses,
                "samples": self.samples, "seed": self.seed, "margin": self.margin,
                "joints": self.joints, "pairs": [x.to_dict() for x in self.pairs],
                "pairs_tested": self.tested,
                "skipped_adjacent": [list(x) for x in self.skipped_adjacent],
                "links_without_collision": self.without_shapes, "warnings": self.warnings}

    def srdf(self) -> str:
        """A MoveIt SRDF document disabling the pairs always in contact, commented.

        One ``<disable_collisions>`` per pair, inside ``<robot name>`` with the robot's name;
        a comment says what was tested, and none is a document that says nothing matched.
        The reason is MoveIt Setup Assistant's: ``Default`` for a pair in contact at the one
        pose tested, ``Always`` for one in contact at every sampled pose too.
        """
        reason = "Always" if self.samples else "Default"
        always = self.always()
        tested = (f"{self.poses} poses tested (the start pose and {self.samples} random, seed "
                  f"{self.seed})" if self.samples else "the one pose tested (the start pose)")
        out = ['<?xml version="1.0"?>\n',
               f"<!-- urdfkit collisions {_comment(self.file)}: {len(always)} link pair(s) in "
               f"contact in {'all ' if self.samples else ''}{tested}, margin "
               f"{self.margin:g} m.{' Merge these entries into the robot SRDF.' if always else ''}"
               " -->\n",
               f'<robot name="{_attr(self.robot)}">\n']
        if not always:
            out.append("  <!-- no pair is in contact in every pose: nothing to disable -->\n")
        for x in always:
            if x.hull:  # MoveIt (FCL) collides the mesh itself: the pair may be clear there
                out.append(f"  <!-- {_comment(', '.join(x.hull))}: a concave mesh PyBullet "
                           "collides as its convex hull; MoveIt checks the mesh itself, so "
                           "check this pair there before disabling it -->\n")
            out.append(f'  <disable_collisions link1="{_attr(x.link_a)}" '
                       f'link2="{_attr(x.link_b)}" reason="{reason}"/>\n')
        out.append("</robot>\n")
        return "".join(out)

    def python(self) -> str:
        """``setCollisionFilterPair`` calls that disable the pairs always in contact."""
        lines = [f"# urdfkit collisions {self.file}: {len(self.always())} pairs in contact in "
                 f"all {self.poses} poses tested",
                 "# robot = p.loadURDF(..., flags=p.URDF_USE_SELF_COLLISION)"]
        lines += [f"p.setCollisionFilterPair(robot, robot, {x.index_a}, {x.index_b}, "
                  f"enableCollision=0)  # {x.link_a} / {x.link_b}"
                  + (f" (convex hull of {', '.join(x.hull)})" if x.hull else "")
                  for x in self.always()]
        return "\n".join(lines) + "\n"


def _attr(text: str) -> str:
    return text.replace("&", "&amp;").replace('"', "&quot;").replace("<", "&lt;")


def _comment(text: str) -> str:
    """``text`` safe inside an XML comment, which may hold no ``--`` (nor end in ``-``)."""
    while "--" in text:
        text = text.replace("--", "- -")
    return text + " " if text.endswith("-") else text


def self_collisions(resolved: Resolved, *, joints: Mapping[str, float] | None = None,
                    samples: int = 0, seed: int = 0, margin: float = 0.0,
                    packages: Mapping[str, Path] | None = None) -> Collisions:
    """Find the link pairs of a robot that touch, at its start pose and at random poses.

    Args:
        resolved: The file, resolved and guarded (:func:`urdfkit.sources.resolve.resolve`).
        joints: Joint positions (rad or m) by name: the start pose, and pinned in every
            sampled pose too (to test a gripper held closed, say).
        samples: Random poses to test besides the start pose.
        seed: Seed of the random poses; the same seed gives the same poses.
        margin: Count pairs closer than this (m) as in contact; 0 means touching or
            interpenetrating.
        packages: ``package://`` mappings, to find concave meshes.

    Raises:
        ParameterError: a bad ``samples``, ``margin`` or joint name.
        EngineError: PyBullet refused the file.
    """
    if isinstance(samples, bool) or not 0 <= samples <= MAX_SAMPLES:
        raise ParameterError(f"`samples` must be 0..{MAX_SAMPLES}, got {samples!r}",
                             param="samples")
    if not (math.isfinite(margin) and margin >= 0):
        raise ParameterError(f"`margin` must be a distance of 0 or more, got {margin!r}",
                             param="margin")
    import numpy as np

    pinned = dict(joints or {})
    read_as = _refuse_non_finite(resolved)
    _refuse_mimic_cycles(resolved)
    from urdfkit.engine.joints import pose_by_name
    from urdfkit.engine.registry import open_engine

    engine = open_engine("pybullet")
    try:
        # Without URDF_USE_SELF_COLLISION, getClosestPoints(body, body, 0, a, b) finds nothing
        # even for links 10 mm deep in each other (PyBullet 3.2.7).
        body = engine.load(str(resolved.load_path),
                           LoadSettings(fixed_base=True, self_collision=True),
                           display=resolved.name)
        engine.require_state_queries(body, resolved.name)
        table = engine.joints(body)
        names = engine.link_names(body)
        continuous = {el.get("name", "") for el in children(resolved.root, "joint")
                      if el.get("type") == "continuous"}
        warnings: list[str] = list(read_as)
        pose_by_name(engine, body, table, pinned, warnings, resolved.name,
                     unlimited=continuous)
        sampler = _Sampler(table, resolved.root, pinned, warnings, continuous)
        sampler.follow(engine, body, sampler.start())  # mimic joints follow at the start too
        shaped = [i for i in range(-1, len(table)) if engine.collision_shapes(body, i)]
        without = [names[i + 1] for i in range(-1, len(table)) if i not in set(shaped)]
        tested: list[tuple[int, int]] = []
        adjacent: list[tuple[str, str]] = []
        for k, a in enumerate(shaped):
            for b in shaped[k + 1:]:
                if table[b].parent == a:
                    adjacent.append((names[a + 1], names[b + 1]))
                else:
                    tested.append((a, b))
        rng = np.random.default_rng(seed)
        closest: dict[tuple[int, int], float] = {}
        hits: dict[tuple[int, int], int] = {}
        closest_points = engine.closest_points  # bound once, outside the loop
        for pose in range(samples + 1):
            if pose:
                sampler.pose(engine, body, rng)
            for a, b in tested:
                points = closest_points(body, body, margin, a, b)
                if not points:
                    continue
                d = min(x.distance for x in points)
                if d <= margin:
                    hits[(a, b)] = hits.get((a, b), 0) + 1
                    closest[(a, b)] = min(d, closest.get((a, b), math.inf))
    finally:
        engine.close()
    concave = _concave_links(resolved, packages)
    pairs = [Pair(names[a + 1], names[b + 1], a, b, closest[(a, b)], n,
                  [x for x in (names[a + 1], names[b + 1]) if x in concave])
             for (a, b), n in hits.items()]
    pairs.sort(key=lambda x: (-x.poses_in_contact, x.distance, x.index_a, x.index_b))
    return Collisions(resolved.name, resolved.robot_name, samples + 1, samples, seed, margin,
                      pinned, pairs, len(tested), adjacent, without, warnings)


#: The numbers that place and shape what collides: (element path under <robot>, attributes).
_PLACING = (("joint/origin", ("xyz", "rpy")), ("joint/axis", ("xyz",)),
            ("joint/mimic", ("multiplier", "offset")),
            ("link/collision/origin", ("xyz", "rpy")),
            ("link/collision/geometry/box", ("size",)),
            ("link/collision/geometry/sphere", ("radius",)),
            ("link/collision/geometry/cylinder", ("radius", "length")),
            ("link/collision/geometry/capsule", ("radius", "length")),
            ("link/collision/geometry/mesh", ("scale",)))

_VECTORS = frozenset({"xyz", "rpy", "size", "scale"})


def _refuse_non_finite(resolved: Resolved) -> list[str]:
    """Refuse NaN or infinite positions, sizes and mimic factors before anything runs.

    PyBullet takes them and answers nonsense: a NaN box collides with nothing, so the report
    would say "0 pairs in contact" of a robot whose finite twin collides. Text that is not
    numbers (xacro left in a .urdf: ``$(optenv X 0.5 0 0.3)``) PyBullet reads token by token
    as C's atof does, and loads; so does collisions, with a warning saying what it reads. A
    mimic factor must be numbers: urdfkit's sampler reads it, PyBullet does not.

    Returns:
        One warning per attribute that is not plain numbers.
    """
    warnings: list[str] = []
    for path, attrs in _PLACING:
        for el in resolved.root.iterfind(path):
            if ignored_shape(el):  # PyBullet never reads a shape after the first
                continue
            for attr in attrs:
                text = el.get(attr)
                if text is None:
                    continue
                values = [atof(x) for x in text.split()]
                shown = text if len(text) <= 60 else f"{text[:60]}... ({len(text)} characters)"
                if el.tag == "mimic":  # urdfkit's own sampler reads it, not PyBullet: numbers only
                    plain = numbers(text)
                    values = plain if plain is not None else [math.nan]
                if not all(map(math.isfinite, values)):
                    raise InputError(f"<{el.tag!s} {attr}={shown!r}> is not a finite number; "
                                     "collisions cannot place or size a shape with it",
                                     file=resolved.name, line=line_of(el))
                if numbers(text) is None:
                    # Vectors take the first three tokens (measured), a scalar the first.
                    used = values[:3] if attr in _VECTORS else values[:1]
                    read = " ".join(f"{v:g}" for v in used)
                    warnings.append(f"{resolved.name}:{line_of(el)}: <{el.tag!s} {attr}={shown!r}> "
                                    f"is not numbers (xacro left in a .urdf?): PyBullet reads "
                                    f"each token as a number or 0, so {read!r}")
    return warnings


def _refuse_mimic_cycles(resolved: Resolved) -> None:
    """A mimic joint that follows itself, or a ring of them, has no position to take."""
    els = {j.get("name"): j for j in children(resolved.root, "joint")}
    leader = {name: m.get("joint") for name, j in els.items()
              if (m := j.find("mimic")) is not None}
    for start in leader:
        seen, name = [start], leader[start]
        while name in leader and name not in seen:
            seen.append(name)
            name = leader[name]
        if name == start:
            ring = " -> ".join(str(x) for x in [*seen, start])
            raise InputError(f"mimic joints follow each other in a ring ({ring}): none has a "
                             "position to follow", file=resolved.name,
                             line=line_of(els[start]))


class _Sampler:
    """Draws joint positions within limits; pinned joints stay, mimic joints follow."""

    def __init__(self, table: Sequence[JointInfo], root: etree._Element,
                 pinned: Mapping[str, float], warnings: list[str], continuous: set[str]):
        self.free: list[tuple[int, float, float]] = []  # (index, low, high) of 1-DOF joints
        self.spherical: list[int] = []
        self.mimic: list[tuple[int, int, float, float]] = []  # (index, leader, mult, offset)
        index = {j.name: j.index for j in table}
        self.pinned = {index[name]: value for name, value in pinned.items() if name in index}
        types = {el.get("name"): el.get("type") for el in children(root, "joint")}
        leaders = {}
        for el in children(root, "joint"):
            m = el.find("mimic")
            if m is not None and m.get("joint") in index and el.get("name") in index:
                try:
                    leaders[el.get("name")] = (index[m.get("joint", "")],
                                               float(m.get("multiplier") or 1.0),
                                               float(m.get("offset") or 0.0))
                except ValueError:
                    continue
        for j in self._leaders_first(table, leaders):
            if j.name in pinned or j.kind == "fixed":
                continue
            limited = j.limited and j.name not in continuous
            if j.name in leaders:
                self.mimic.append((j.index, *leaders[j.name]))
            elif j.kind == "spherical":
                self.spherical.append(j.index)
            elif limited and math.isfinite(j.upper - j.lower):
                self.free.append((j.index, j.lower, j.upper))
            elif j.kind == "revolute":
                if limited:  # limits of 1e308 or inf: no range to draw from but a turn
                    warnings.append(f"joint {j.name}: limits {j.lower:g}..{j.upper:g} span "
                                    "more than any number can hold; sampled over one turn "
                                    "(-pi..pi)")
                self.free.append((j.index, -math.pi, math.pi))
            else:
                warnings.append(f"joint {j.name}: a {types.get(j.name) or j.kind} joint "
                                "without finite limits has no range to sample; held at 0")

    @staticmethod
    def _leaders_first(table: Sequence[JointInfo],
                       leaders: Mapping[Any, tuple[int, float, float]]) -> list[JointInfo]:
        """The joints with every mimic after the joint it follows (chains: A <- B <- C)."""
        by_index = {j.index: j for j in table}
        depth: dict[str, int] = {}
        for j in table:
            n, name = 0, j.name
            while name in leaders and n <= len(table):
                name, n = by_index[leaders[name][0]].name, n + 1
            depth[j.name] = n
        return sorted(table, key=lambda j: depth[j.name])

    def start(self) -> dict[int, float]:
        """Every leader's position at the start pose: pinned, else 0."""
        followers = {i for i, _, _, _ in self.mimic}
        return {leader: self.pinned.get(leader, 0.0) for _, leader, _, _ in self.mimic
                if leader not in followers}

    def follow(self, engine: Simulator, body: int, values: dict[int, float]) -> None:
        """Set each mimic joint from its leader's position in ``values``."""
        for i, leader, mult, offset in self.mimic:  # leaders first: a chain follows through
            if leader in values:
                values[i] = mult * values[leader] + offset
                engine.reset_joint(body, i, values[i])

    def pose(self, engine: Simulator, body: int, rng: Any) -> None:
        values: dict[int, float] = dict(self.pinned)
        for i, low, high in self.free:
            values[i] = float(rng.uniform(low, high))
            engine.reset_joint(body, i, values[i])
        for i in self.spherical:
            q = rng.normal(size=4)
            q = q / (float((q * q).sum()) ** 0.5 or 1.0)  # uniform over rotations
            engine.reset_spherical_joint(body, i, (float(q[0]), float(q[1]), float(q[2]),
                                                   float(q[3])))
        self.follow(engine, body, values)


def _concave_links(resolved: Resolved, packages: Mapping[str, Path] | None) -> set[str]:
    """Links with a collision mesh PyBullet replaces by its convex hull, concave or not."""
    from urdfkit.model.spec import attr_vec
    from urdfkit.sources.meshstore import CONCAVE_FRACTION, properties
    from urdfkit.sources.references import reference

    base = resolved.source.resolve().parent
    out = set()
    for link in children(resolved.root, "link"):
        for mesh in link.iterfind("collision/geometry/mesh"):
            if ignored_shape(mesh):
                continue
            fn = (mesh.get("filename") or "").strip()
            target = reference("mesh", fn, base, packages).load_path if fn else None
            if target is None:
                continue
            scale = attr_vec(mesh, "scale", 3, (1.0, 1.0, 1.0)) or (1.0, 1.0, 1.0)
            props = properties(Path(target), (scale[0], scale[1], scale[2]), concavity=True)
            if props is not None and props.concavity > CONCAVE_FRACTION * max(props.extent):
                out.add(link.get("name", ""))
    return out
