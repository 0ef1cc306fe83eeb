"""A semantic diff of two robots: what changed in meaning, not in text.

Two files that differ in whitespace, attribute order, comments or float spelling (``0.10``
and ``1e-1``) are the same robot. What counts:

- links and joints added, removed or renamed. Elements are matched by name first, then by
  structure: an unmatched joint whose type and origin match an unmatched joint of the other
  robot, and whose parent or child link is already matched, is the same joint renamed; a link
  at the same end of a matched joint, unmatched by name on both sides, is the same link
  renamed. Matching spreads from the root, so a robot renamed throughout (``left_`` prefixes)
  is matched whole.
- each field of a matched link or joint (limits, dynamics, mass, inertia, origins, axes,
  geometry, materials), naming the field with its old and new value;
- PyBullet joint indices that move. PyBullet numbers joints depth-first from the root, children
  in file order (:meth:`urdfkit.builder.Robot.pybullet_joint_order`), so inserting a joint
  early shifts every later index and breaks a script's ``wheel_indices = [1, 3, 4, 5]``;
- the total mass and degrees of freedom.

Values the URDF gives a default are compared with that default filled in (no ``<dynamics>``
is damping 0), an axis only where the joint type has one, and a continuous joint's lower and
upper not at all: each is what the robot *means*. Mesh and texture files are compared by
content when their paths differ, so a copied robot with its meshes beside it is the same.

Nothing here loads PyBullet: the files are resolved (xacro, ``package://``, the guard) and
parsed into the builder's model, leniently (``strict=False``): a diff compares what the files
say, so a value the model refuses to build from (a zero axis, a malformed vector, a sphere of
radius 0, a lower limit above the upper) is compared as written, as a number where it is one
and as its whitespace-normalised text where it is not (:func:`urdfkit.builder.as_written`).
What the guard refuses, and a file without a tree (a missing link, a cycle), is still bad input.
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Callable, Iterator
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Literal

from urdfkit.core.errors import ModelError, ParameterError
from urdfkit.model.robot import Joint, Link, Material, Robot
from urdfkit.model.spec import AXIS_JOINT_TYPES, URDF_JOINT_DOF

#: What a change is about: a link, a joint, or the robot itself (its name).
ChangeKind = Literal["link", "joint", "robot"]
#: What a robot has one of and another may not: a link or a joint.
ElementKind = Literal["link", "joint"]

#: Default float tolerance, absolute and relative: values this close are equal.
DEFAULT_TOLERANCE = 1e-9

#: Values the URDF specification defaults, by the last two parts of a field's path. A field
#: absent on one side equals its default on the other.
DEFAULTS: dict[str, Any] = {
    "origin.xyz": (0.0, 0.0, 0.0), "origin.rpy": (0.0, 0.0, 0.0),
    "limit.lower": 0.0, "limit.upper": 0.0,
    "dynamics.damping": 0.0, "dynamics.friction": 0.0,
    "mimic.multiplier": 1.0, "mimic.offset": 0.0,
    "safety_controller.soft_lower_limit": 0.0, "safety_controller.soft_upper_limit": 0.0,
    "safety_controller.k_position": 0.0,
    "geometry.scale": (1.0, 1.0, 1.0), "contact.friction_anchor": False,
}

#: Joint fields that hold link or joint names: compared through the rename maps.
_LINK_FIELDS = ("parent", "child")
_JOINT_NAME_FIELDS = ("mimic.joint",)


# --------------------------------------------------------------------------- results


@dataclass
class Change:
    """One field of a matched link or joint (or the robot) that differs.

    Attributes:
        kind: ``link``, ``joint`` or ``robot``.
        name: The element's name in the second robot.
        field: The field's path, as in the URDF: ``limit.effort``, ``origin.xyz``,
            ``visual[0].geometry.size``, ``inertial.inertia.ixx``.
        old: The first robot's value (None where it has none). Vectors are tuples (lists in
            JSON); a whole visual or collision that only one side has is a dict of its
            fields; a value the model refuses is as written (a number, numbers of any count,
            or text: :func:`urdfkit.builder.as_written`).
        new: The second robot's value.
    """

    kind: ChangeKind
    name: str
    field: str
    old: Any
    new: Any

    def to_dict(self) -> dict[str, Any]:
        """The JSON object of this change."""
        return {"kind": self.kind, "name": self.name, "field": self.field,
                "old": _jsonable(self.old), "new": _jsonable(self.new)}


@dataclass
class Rename:
    """A link or joint matched by structure under a new name."""

    kind: ElementKind
    old: str
    new: str

    def to_dict(self) -> dict[str, Any]:
        """The JSON object of this rename."""
        return {"old": self.old, "new": self.new}


@dataclass
class Element:
    """A link or joint only one robot has; ``index`` and ``type`` are for joints only.

    Attributes:
        kind: ``link`` or ``joint``.
        name: Its name.
        index: A joint's PyBullet index in its robot (None for links).
        type: A joint's type (None for links).
    """

    kind: ElementKind
    name: str
    index: int | None = None
    type: str | None = None

    def to_dict(self) -> dict[str, Any]:
        """The JSON object: ``name``, plus ``index`` and ``type`` for a joint."""
        if self.kind == "link":
            return {"name": self.name}
        return {"name": self.name, "index": self.index, "type": self.type}


@dataclass
class IndexShift:
    """A joint that PyBullet numbers differently: a script's hard-coded index now misses it.

    Attributes:
        joint: The joint's name in the second robot.
        old_name: Its name in the first robot (the same unless renamed).
        old: Its PyBullet joint index (also its child link's index) in the first robot.
        new: Its index in the second robot.
    """

    joint: str
    old_name: str
    old: int
    new: int

    def to_dict(self) -> dict[str, Any]:
        """The JSON object of this shift."""
        return {"joint": self.joint, "old_name": self.old_name, "old": self.old, "new": self.new}


@dataclass
class Total:
    """A whole-robot number before and after, with whether it changed beyond tolerance."""

    old: float
    new: float
    changed: bool

    def to_dict(self) -> dict[str, Any]:
        """The JSON object of this total."""
        return {"old": self.old, "new": self.new, "changed": self.changed}


@dataclass
class Side:
    """One of the two robots compared."""

    file: str
    robot: str
    links: int
    joints: int

    def to_dict(self) -> dict[str, Any]:
        """The JSON object of this side."""
        return {"file": self.file, "robot": self.robot, "links": self.links,
                "joints": self.joints}


@dataclass
class DiffResult:
    """Everything that differs between robot ``a`` (old) and robot ``b`` (new).

    Attributes:
        a: The first robot.
        b: The second robot.
        tolerance: The float tolerance used (absolute and relative).
        added: Links and joints only ``b`` has (links first, then joints in index order).
        removed: Links and joints only ``a`` has.
        renamed: Links and joints matched by structure under a new name.
        changes: Fields that differ, links first (``b``'s file order), then joints (``b``'s
            index order).
        index_shifts: Matched joints whose PyBullet index moved, in ``b``'s index order.
        mass: Total mass from the files' ``<inertial>`` (a link without one counts 0).
        dof: Degrees of freedom of the joints (:data:`urdfkit.model.spec.URDF_JOINT_DOF`).
        warnings: Refusals lifted by ``guard=False``, for the caller to show.
    """

    a: Side
    b: Side
    tolerance: float
    added: list[Element] = field(default_factory=list)
    removed: list[Element] = field(default_factory=list)
    renamed: list[Rename] = field(default_factory=list)
    changes: list[Change] = field(default_factory=list)
    index_shifts: list[IndexShift] = field(default_factory=list)
    mass: Total = field(default_factory=lambda: Total(0.0, 0.0, False))
    dof: Total = field(default_factory=lambda: Total(0, 0, False))
    warnings: list[str] = field(default_factory=list)

    @property
    def same(self) -> bool:
        """Whether the two robots mean the same thing (within the tolerance)."""
        return not (self.added or self.removed or self.renamed or self.changes
                    or self.index_shifts or self.mass.changed or self.dof.changed)

    @property
    def count(self) -> int:
        """How many differences there are, as listed (a shift or a total counts one)."""
        return (len(self.added) + len(self.removed) + len(self.renamed) + len(self.changes)
                + len(self.index_shifts) + self.mass.changed + self.dof.changed)

    def to_dict(self) -> dict[str, Any]:
        """The ``diff --json`` object (see docs/diff.md)."""

        def of(kind: ElementKind) -> dict[str, Any]:
            return {"added": [e.to_dict() for e in self.added if e.kind == kind],
                    "removed": [e.to_dict() for e in self.removed if e.kind == kind],
                    "renamed": [r.to_dict() for r in self.renamed if r.kind == kind]}

        return {"a": self.a.to_dict(), "b": self.b.to_dict(), "same": self.same,
                "tolerance": self.tolerance, "links": of("link"), "joints": of("joint"),
                "changes": [c.to_dict() for c in self.changes],
                "index_shifts": [s.to_dict() for s in self.index_shifts],
                "totals": {"mass": self.mass.to_dict(), "dof": self.dof.to_dict()}}


# --------------------------------------------------------------------------- entry points


def diff_files(a: str | Path, b: str | Path, *, tolerance: float = DEFAULT_TOLERANCE,
               packages: list[str] | None = None, xacro_args: list[str] | None = None,
               guard: bool = True, package_paths: list[str] | None = None) -> DiffResult:
    """Compare two robot files (URDF or xacro) in meaning.

    Each file goes the road every loader takes (:func:`urdfkit.sources.resolve.open_input`: locate,
    expand xacro, guard, resolve ``package://``), then into the builder's model; a file the
    lenient model still refuses (see :func:`load_robot`) is bad input naming the file.
    ``packages``, ``xacro_args`` and
    ``package_paths`` are the raw ``NAME=PATH``, ``name:=value`` and folder lists, applied to
    both files.
    """
    _check_tolerance(tolerance)
    robots, warnings = [], []
    for name in (a, b):
        robot, notes = load_robot(name, packages=packages, xacro_args=xacro_args, guard=guard,
                                  package_paths=package_paths)
        robots.append(robot)
        warnings += notes
    result = diff_robots(robots[0], robots[1], tolerance=tolerance, files=(str(a), str(b)))
    result.warnings = warnings
    return result


def load_robot(name: str | Path, *, packages: list[str] | None = None,
               xacro_args: list[str] | None = None, guard: bool = True,
               package_paths: list[str] | None = None) -> tuple[Robot, list[str]]:
    """A robot file resolved and read into the model, with the guard's lifted refusals.

    The model is read leniently (:meth:`urdfkit.builder.Robot.from_element` with ``strict``
    False): values it would refuse to build from are kept as written, so two versions of a
    robot that ``check`` has findings on can still be compared. A missing file, malformed
    XML, a guard refusal, or a file with no tree to compare (a joint naming a missing link, a
    cycle, an unknown joint type) still raises.
    """
    from urdfkit.sources.resolve import open_input

    with open_input(name, packages=packages, xacro_args=xacro_args, guard=guard,
                    package_paths=package_paths) as resolved:
        try:
            robot = Robot.from_element(resolved.root, resolved.name, strict=False)
        except ModelError as e:
            # The lines of expanded xacro are not the lines of the file the user wrote.
            line = None if resolved.source.suffix == ".xacro" else e.line
            raise ModelError(e.message, file=resolved.name, line=line) from None
        return robot, list(resolved.warnings)


def diff_robots(a: Robot, b: Robot, *, tolerance: float = DEFAULT_TOLERANCE,
                files: tuple[str, str] = ("a", "b")) -> DiffResult:
    """Compare two models in meaning; ``a`` is the old robot and ``b`` the new one."""
    _check_tolerance(tolerance)
    close = _closeness(tolerance)
    links, joints, renamed = _match(a, b, close)
    order_a = {j.name: i for i, j in enumerate(a.pybullet_joint_order())}
    order_b = {j.name: i for i, j in enumerate(b.pybullet_joint_order())}
    link_order = {x.name: i for i, x in enumerate(b.links)}
    renamed.sort(key=lambda r: (r.kind == "joint", order_b[r.new] if r.kind == "joint"
                                else link_order[r.new]))
    result = DiffResult(Side(files[0], a.name, len(a.links), len(a.joints)),
                        Side(files[1], b.name, len(b.links), len(b.joints)), tolerance,
                        renamed=renamed)
    matched_b_links = set(links.values())
    matched_b_joints = set(joints.values())
    joints_b = sorted(b.joints, key=lambda j: order_b[j.name])
    joints_a = sorted(a.joints, key=lambda j: order_a[j.name])
    result.added = (
        [Element("link", x.name) for x in b.links if x.name not in matched_b_links]
        + [Element("joint", j.name, order_b[j.name], j.type) for j in joints_b
           if j.name not in matched_b_joints])
    result.removed = (
        [Element("link", x.name) for x in a.links if x.name not in links]
        + [Element("joint", j.name, order_a[j.name], j.type) for j in joints_a
           if j.name not in joints])

    if a.name != b.name:
        result.changes.append(Change("robot", b.name, "name", a.name, b.name))
    link_a = {x.name: x for x in a.links}
    back_links = {new: old for old, new in links.items()}
    for lb in b.links:
        if lb.name in back_links:
            la = link_a[back_links[lb.name]]
            result.changes += _compare("link", lb.name, _link_fields(la, a),
                                       _link_fields(lb, b), close, _files_equal(close))
    joint_a = {j.name: j for j in a.joints}
    back_joints = {new: old for old, new in joints.items()}
    names = {**{f: links for f in _LINK_FIELDS}, **{f: joints for f in _JOINT_NAME_FIELDS}}
    for jb in joints_b:
        if jb.name not in back_joints:
            continue
        ja = joint_a[back_joints[jb.name]]
        result.changes += _compare("joint", jb.name, _joint_fields(ja), _joint_fields(jb),
                                   close, _files_equal(close), names)
        old, new = order_a[ja.name], order_b[jb.name]
        if old != new:
            result.index_shifts.append(IndexShift(jb.name, ja.name, old, new))

    mass_a, mass_b = _total_mass(a), _total_mass(b)
    result.mass = Total(mass_a, mass_b, not close(mass_a, mass_b))
    dof_a, dof_b = _dof(a), _dof(b)
    result.dof = Total(dof_a, dof_b, dof_a != dof_b)
    return result


def _check_tolerance(tolerance: float) -> None:
    if not (isinstance(tolerance, int | float) and math.isfinite(tolerance) and tolerance >= 0):
        raise ParameterError(f"`tolerance` must be a finite number >= 0, got {tolerance!r}",
                             param="tolerance")


def _dof(robot: Robot) -> int:
    return sum(URDF_JOINT_DOF[j.type] for j in robot.joints)


def _total_mass(robot: Robot) -> float:
    """The files' masses summed; one that is not a number (kept as written) counts 0."""
    masses = [x.inertial.mass for x in robot.links if x.inertial is not None
              and isinstance(x.inertial.mass, float | int)]
    try:
        return math.fsum(masses)
    except OverflowError:  # finite masses whose sum is not (two of 1e308): inf, as plain sum
        return sum(masses)


# --------------------------------------------------------------------------- matching


Close = Callable[[Any, Any], bool]


def _closeness(tolerance: float) -> Close:
    """Equality of leaf values: floats (and vectors of them) within ``tolerance``."""

    def close(x: Any, y: Any) -> bool:
        if isinstance(x, bool) or isinstance(y, bool):
            return x is y
        if isinstance(x, int | float) and isinstance(y, int | float):
            return math.isclose(x, y, rel_tol=tolerance, abs_tol=tolerance)
        if isinstance(x, tuple | list) and isinstance(y, tuple | list):
            return len(x) == len(y) and all(close(p, q) for p, q in zip(x, y, strict=True))
        return bool(x == y)

    return close


def _match(a: Robot, b: Robot, close: Close
           ) -> tuple[dict[str, str], dict[str, str], list[Rename]]:
    """Pair the links and joints of ``a`` with those of ``b``: by name, then by structure.

    Returns the link map and joint map (name in ``a`` -> name in ``b``) and the renames
    among them, in the order they were found.
    """
    b_links = {x.name for x in b.links}
    b_joints = {j.name: j for j in b.joints}
    links = {x.name: x.name for x in a.links if x.name in b_links}
    joints = {j.name: j.name for j in a.joints if j.name in b_joints}
    taken_links = set(links.values())
    taken_joints = set(joints.values())
    renamed: list[Rename] = []

    def pair_links(la: str, lb: str) -> bool:
        if la in links or lb in taken_links:
            return False
        links[la] = lb
        taken_links.add(lb)
        renamed.append(Rename("link", la, lb))
        return True

    def pair_ends(ja: Joint, jb: Joint) -> bool:
        return any([pair_links(ja.parent, jb.parent), pair_links(ja.child, jb.child)])

    joint_b_by_end: dict[tuple[str, str], list[Joint]] = {}
    for jb in b.joints:
        joint_b_by_end.setdefault(("parent", jb.parent), []).append(jb)
        joint_b_by_end.setdefault(("child", jb.child), []).append(jb)
    b_index = {j.name: i for i, j in enumerate(b.joints)}
    order_a = a.pybullet_joint_order()  # parents before children: one pass matches a chain
    progress = True
    while progress:
        progress = False
        for ja in a.joints:  # a joint kept by name carries its renamed links with it
            if ja.name in joints:
                progress |= pair_ends(ja, b_joints[joints[ja.name]])
        # The roots are the same link if nothing else claimed them: all hangs from them.
        progress |= pair_links(a.root, b.root)
        for ja in order_a:
            if ja.name in joints:
                continue
            candidates = _candidates(ja, links, taken_links, taken_joints, joint_b_by_end,
                                     close)
            if not candidates:
                continue
            jb = _most_alike(ja, sorted(candidates, key=lambda j: b_index[j.name]), close)
            joints[ja.name] = jb.name
            taken_joints.add(jb.name)
            renamed.append(Rename("joint", ja.name, jb.name))
            pair_ends(ja, jb)
            progress = True
    return links, joints, renamed


def _candidates(ja: Joint, links: dict[str, str], matched: set[str], taken: set[str],
                by_end: dict[tuple[str, str], list[Joint]], close: Close) -> list[Joint]:
    """Unmatched joints of ``b`` that ``ja`` may be, renamed: same type, origin and ends.

    One end must be matched already (evidence that this is the same place in the tree); the
    other must map to the candidate's end, or be unmatched on both sides (renamed with it).
    """
    found: dict[str, Joint] = {}
    for role in ("parent", "child"):
        end = getattr(ja, role)
        if end in links:
            for jb in by_end.get((role, links[end]), []):
                found.setdefault(jb.name, jb)
    out = []
    for jb in found.values():
        if jb.name in taken or jb.type != ja.type or not (
                close(ja.origin.xyz, jb.origin.xyz) and close(ja.origin.rpy, jb.origin.rpy)):
            continue
        ends = all(links[getattr(ja, r)] == getattr(jb, r) if getattr(ja, r) in links
                   else getattr(jb, r) not in matched for r in ("parent", "child"))
        if ends:
            out.append(jb)
    return out


def _most_alike(ja: Joint, candidates: list[Joint], close: Close) -> Joint:
    """The candidate sharing most fields with ``ja`` (the first of the best).

    One equal in every field ends the search, so a hub of many identical joints, all
    renamed, does not compare every field of every pair.
    """
    names = (*_LINK_FIELDS, *_JOINT_NAME_FIELDS)  # the ends are settled; names differ

    def fields(j: Joint) -> dict[str, Any]:
        return {k: v for k, v in _joint_fields(j).items() if k not in names}

    fa = fields(ja)
    best, score = candidates[0], -1
    for jb in candidates:
        fb = fields(jb)
        shared = sum(1 for k in fa.keys() & fb.keys() if close(fa[k], fb[k]))
        if shared == len(fa) == len(fb):
            return jb
        if shared > score:
            best, score = jb, shared
    return best


# --------------------------------------------------------------------------- fields


def _element_fields(el: Any, prefix: str) -> Iterator[tuple[str, Any]]:
    """The leaf values of a builder element, by dotted path (``limit.effort``)."""
    if el is None:
        return
    for f in dataclasses.fields(el):
        value = getattr(el, f.name)
        path = f"{prefix}{f.name}"
        if dataclasses.is_dataclass(value):
            yield from _element_fields(value, path + ".")
        else:
            yield path, value


def _shape_fields(geometry: Any, prefix: str) -> Iterator[tuple[str, Any]]:
    yield prefix, geometry._tag
    yield from _element_fields(geometry, prefix + ".")


def _material_fields(material: Material | None, robot: Robot, prefix: str
                     ) -> Iterator[tuple[str, Any]]:
    """What a visual looks like: a reference by name is looked up in the robot's materials.

    Material names are labels: two names for one colour are the same look.
    """
    if material is None:
        return
    if material.is_reference:
        defined = next((m for m in robot.materials if m.name == material.name), None)
        material = defined or material
    yield prefix + ".color", material.color
    yield prefix + ".texture", material.texture


def _link_fields(link: Link, robot: Robot) -> dict[str, Any]:
    """A link's comparable fields: inertial, contact, and each visual and collision."""
    out = dict(_element_fields(link.inertial, "inertial."))
    out.update(_element_fields(link.contact, "contact."))
    for i, visual in enumerate(link.visuals):
        out.update(_element_fields(visual.origin, f"visual[{i}].origin."))
        out.update(_shape_fields(visual.geometry, f"visual[{i}].geometry"))
        out.update(_material_fields(visual.material, robot, f"visual[{i}].material"))
    for i, collision in enumerate(link.collisions):
        out.update(_element_fields(collision.origin, f"collision[{i}].origin."))
        out.update(_shape_fields(collision.geometry, f"collision[{i}].geometry"))
    return out


def _joint_fields(joint: Joint) -> dict[str, Any]:
    """A joint's comparable fields, with what the URDF leaves meaningless left out."""
    out: dict[str, Any] = {"type": joint.type, "parent": joint.parent, "child": joint.child}
    out.update(_element_fields(joint.origin, "origin."))
    if joint.type in AXIS_JOINT_TYPES:  # a fixed joint's axis means nothing
        out["axis"] = joint.axis if joint.axis is not None else (1.0, 0.0, 0.0)
    for name in ("limit", "dynamics", "mimic", "safety_controller", "calibration"):
        out.update(_element_fields(getattr(joint, name), name + "."))
    if joint.type == "continuous":  # the URDF ignores a continuous joint's position limits
        out.pop("limit.lower", None)
        out.pop("limit.upper", None)
    return out


def _default(path: str) -> Any:
    return DEFAULTS.get(".".join(path.split(".")[-2:]))


def _files_equal(close: Close) -> Close:
    """Leaf equality where a mesh or texture path may differ yet name the same bytes."""

    def equal(x: Any, y: Any) -> bool:
        if close(x, y):
            return True
        if isinstance(x, str) and isinstance(y, str) and Path(x).is_absolute() \
                and Path(y).is_absolute():
            return _same_bytes(Path(x), Path(y))
        return False

    return equal


def _same_bytes(x: Path, y: Path) -> bool:
    try:
        if not (x.is_file() and y.is_file()) or x.stat().st_size != y.stat().st_size:
            return False
        return x.read_bytes() == y.read_bytes()
    except OSError:
        return False


def _compare(kind: ChangeKind, name: str, old: dict[str, Any], new: dict[str, Any], close: Close,
             equal: Close, names: dict[str, dict[str, str]] | None = None) -> list[Change]:
    """The changes between two elements' fields, in ``new``'s order then ``old``'s.

    A visual or collision only one side has is one change holding all its fields.
    """
    changes: list[Change] = []
    whole = _whole_items(old, new)
    for path in [*new, *(p for p in old if p not in new)]:
        item = _item(path)
        if item in whole:
            pair = whole[item]
            if item is not None and pair is not None:
                changes.append(Change(kind, name, item, *pair))
                whole[item] = None  # once per item
            continue
        was, now = old.get(path), new.get(path)
        mapped = was
        if names is not None and path in names and was is not None:
            mapped = names[path].get(was, was)  # a renamed link or joint is the same one
        x = _default(path) if mapped is None else mapped
        y = _default(path) if now is None else now
        if not _same_meaning(path, x, y, equal):
            changes.append(Change(kind, name, path, was, now))
    # A field only the old side has goes beside its group (visual[0], limit), not last.
    groups: dict[str, int] = {}
    for path in [*new, *old]:
        groups.setdefault(path.split(".", 1)[0], len(groups))
    changes.sort(key=lambda c: groups.get(c.field.split(".", 1)[0], 0))
    return changes


def _vector3(v: Any) -> bool:
    return isinstance(v, tuple | list) and len(v) == 3 and \
        all(isinstance(c, int | float) and not isinstance(c, bool) for c in v)


def _same_meaning(path: str, x: Any, y: Any, equal: Close) -> bool:
    """Equal values, or two spellings of one thing.

    An rpy is compared as the rotation it makes (yaw +pi is yaw -pi), an axis as its
    direction (PyBullet normalises ``0 0 2`` to ``0 0 1``; ``0 0 -1`` stays different).
    """
    if equal(x, y):
        return True
    if not (_vector3(x) and _vector3(y)):
        return False
    if path.endswith("rpy"):
        from urdfkit.model.spec import rpy_to_matrix

        return all(equal(p, q) for row_x, row_y in zip(rpy_to_matrix(x), rpy_to_matrix(y),
                                                       strict=True)
                   for p, q in zip(row_x, row_y, strict=True))
    if path == "axis":
        nx, ny = math.sqrt(sum(c * c for c in x)), math.sqrt(sum(c * c for c in y))
        return nx > 0 and ny > 0 and all(equal(p / nx, q / ny) for p, q in zip(x, y,
                                                                                strict=True))
    return False


def _item(path: str) -> str | None:
    """``visual[1]`` for ``visual[1].geometry.size``; None for a path of no list item."""
    head = path.split(".", 1)[0]
    return head if head.endswith("]") else None


def _whole_items(old: dict[str, Any], new: dict[str, Any]
                 ) -> dict[str | None, tuple[dict[str, Any] | None, dict[str, Any] | None] | None]:
    """Visuals and collisions that only one side has, each as (old fields, new fields)."""

    def items(fields: dict[str, Any]) -> dict[str, dict[str, Any]]:
        out: dict[str, dict[str, Any]] = {}
        for path, value in fields.items():
            head = _item(path)
            if head is not None:
                out.setdefault(head, {})[path[len(head) + 1:]] = value
        return out

    a, b = items(old), items(new)
    out: dict[str | None, tuple[dict[str, Any] | None, dict[str, Any] | None] | None] = {
        k: (a.get(k), b.get(k)) for k in [*b, *a] if (k in a) != (k in b)}
    return out


def _jsonable(value: Any) -> Any:
    if isinstance(value, tuple | list):
        return [_jsonable(v) for v in value]
    if isinstance(value, dict):
        return {k: _jsonable(v) for k, v in value.items()}
    return value
