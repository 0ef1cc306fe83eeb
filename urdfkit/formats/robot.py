"""A guarded URDF read as PyBullet loads it, into plain data the MJCF writer and agree share.

What PyBullet 3.2.7 does with a URDF, measured, is what this reads (the facts are in
docs/export.md): joints in its depth-first order, a link without ``<inertial>`` weighing 1 kg
with unit inertia (``URDF_USE_INERTIA_FROM_FILE``), the inertial ``rpy`` applied to the tensor,
``continuous`` unlimited (its ``<limit>`` reported, not enforced), a revolute or prismatic
joint limited only when lower <= upper, a ``floating`` joint loaded as fixed, ``<mimic>``
ignored (kept here: MuJoCo can mean it), lateral friction 0.5 unless ``<contact>`` says
otherwise, and the first shape of a ``<geometry>`` the one used.

Its records are named for that: :class:`LoadedRobot`, :class:`LoadedLink`, :class:`LoadedJoint`,
:class:`LoadedInertial`, :class:`LoadedShape` hold what PyBullet loads, its defaults filled in
and nothing to edit; ``Robot``, ``Link``, ``Joint`` and ``Inertial`` are the builder's
(:mod:`urdfkit.model.robot`), the file as written, checked where set and written back.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any

from urdfkit.core.errors import InputError
from urdfkit.model.spec import (
    atof,
    attr_float,
    attr_vec,
    c_number,
    depth_first,
    matmul,
    rpy_to_matrix,
    transpose,
    used_shape,
)
from urdfkit.model.xmlio import line_of

Matrix = tuple[tuple[float, float, float], tuple[float, float, float],
               tuple[float, float, float]]
Vec = tuple[float, float, float]

#: PyBullet's lateral friction of a link without ``<contact><lateral_friction>``.
DEFAULT_LATERAL_FRICTION = 0.5
#: What PyBullet gives a link without ``<inertial>`` under URDF_USE_INERTIA_FROM_FILE
#: (measured with getDynamicsInfo; BulletUrdfImporter.cpp says so in its warning).
DEFAULT_MASS = 1.0
DEFAULT_INERTIA = (1.0, 1.0, 1.0)


@dataclass
class LoadedInertial:
    """A link's mass properties in its own frame.

    Attributes:
        mass: kg.
        com: The centre of mass in the link frame.
        tensor: The inertia tensor about the centre of mass, in the link frame's axes (the
            inertial ``rpy`` applied: R I R^T).
        given: False when the link had no ``<inertial>`` (PyBullet's default used).
        line: The line of ``<inertial>`` (or of the link, for a default).
    """

    mass: float
    com: Vec
    tensor: Matrix
    given: bool = True
    line: int | None = None


@dataclass
class LoadedShape:
    """One ``<visual>`` or ``<collision>``: its shape, placed in the link frame."""

    kind: str                     # box, cylinder, sphere, capsule, mesh, plane
    size: tuple[float, ...]       # box: full sides; cylinder/capsule: radius, length; sphere: r
    xyz: Vec
    rpy: Vec
    filename: str | None = None   # meshes: the absolute path the resolver made
    scale: Vec = (1.0, 1.0, 1.0)
    rgba: tuple[float, float, float, float] | None = None
    material: str | None = None   # a named material without a colour (a texture) is noted
    texture: bool = False
    line: int | None = None


@dataclass
class LoadedLink:
    """A link: mass properties, shapes and contact parameters."""

    name: str
    inertial: LoadedInertial
    visuals: list[LoadedShape] = field(default_factory=list)
    collisions: list[LoadedShape] = field(default_factory=list)
    lateral_friction: float = DEFAULT_LATERAL_FRICTION
    rolling_friction: float = 0.0
    spinning_friction: float = 0.0
    contact_other: list[str] = field(default_factory=list)   # <contact> children not mapped
    line: int | None = None


@dataclass
class LoadedJoint:
    """A joint as PyBullet loads it (``type`` the URDF word; floating already made fixed)."""

    name: str
    type: str
    parent: str
    child: str
    xyz: Vec
    rpy: Vec
    axis: Vec
    limited: bool
    lower: float
    upper: float
    effort: float
    velocity: float
    damping: float
    friction: float
    mimic: tuple[str, float, float] | None = None   # (joint, multiplier, offset)
    declared_type: str = ""
    line: int | None = None
    #: a <limit> bound written as inf, nan or past a double (1e309): PyBullet reads it so
    odd_limit: str = ""

    @property
    def moves(self) -> bool:
        """Whether the joint has degrees of freedom in PyBullet."""
        return self.type != "fixed"


@dataclass
class LoadedRobot:
    """A URDF as PyBullet loads it.

    Attributes:
        name: The robot's name.
        root: The root link's name.
        links: Every link, by name.
        joints: Every joint, in PyBullet's depth-first order.
        file: The file as the user named it (for messages).
    """

    name: str
    root: str
    links: dict[str, LoadedLink]
    joints: list[LoadedJoint]
    file: str
    #: Attributes that were not plain numbers, and what PyBullet reads in them.
    warnings: list[str] = field(default_factory=list)

    def movable(self) -> list[LoadedJoint]:
        """The joints with degrees of freedom, in PyBullet's order."""
        return [j for j in self.joints if j.moves]

#: Vectors read PyBullet's way that were not plain numbers: (element, attribute, values).
_ODD: list[tuple[Any, str, tuple[float, ...]]] = []


def _scalar(el: Any, attr: str, default: float) -> float:
    """One number as PyBullet reads it: a plain one, else C's atof of the text.

    biped2d_pybullet's ``lower="-1.57."`` is -1.57 to PyBullet (its getJointInfo): read as
    the default 0 it exported a range of 0 to 1.57. A bound that is not finite stays the
    default here (:attr:`LoadedJoint.odd_limit` says it).
    """
    x = attr_float(el, attr, None)
    if x is not None:
        return x
    text = el.get(attr) if el is not None else None
    if text is None:
        return default
    value = atof(text.strip())
    if not math.isfinite(value):
        return default
    _ODD.append((el, attr, (value,)))
    return value


def _vec3(el: Any, attr: str, default: Vec = (0.0, 0.0, 0.0)) -> Vec:
    v = attr_vec(el, attr, 3)
    if v is not None:
        return (v[0], v[1], v[2])
    text = el.get(attr) if el is not None else None
    if text is None:
        return default
    values = [atof(x) for x in text.split()]
    if len(values) < 3:  # PyBullet: "Couldn't parse vector3", the default kept
        return default
    out = (values[0], values[1], values[2])
    if not all(map(math.isfinite, out)):
        raise InputError(f"<{el.tag} {attr}={text[:60]!r}> is not a finite vector; no frame "
                         "can be placed with it", line=line_of(el))
    _ODD.append((el, attr, out))
    return out


def _inertial(link: Any, name: str) -> LoadedInertial:
    el = link.find("inertial")
    if el is None:
        d = DEFAULT_INERTIA
        return LoadedInertial(DEFAULT_MASS, (0.0, 0.0, 0.0),
                              ((d[0], 0.0, 0.0), (0.0, d[1], 0.0), (0.0, 0.0, d[2])), given=False,
                              line=line_of(link))
    origin = el.find("origin")
    mass = attr_float(el.find("mass"), "value", 0.0) or 0.0
    i = el.find("inertia")
    ixx, iyy, izz, ixy, ixz, iyz = (attr_float(i, k, 0.0) or 0.0 for k in
                                    ("ixx", "iyy", "izz", "ixy", "ixz", "iyz"))
    local: Matrix = ((ixx, ixy, ixz), (ixy, iyy, iyz), (ixz, iyz, izz))
    rpy = _vec3(origin, "rpy")
    tensor = local
    if any(rpy):
        r = rpy_to_matrix(rpy)
        tensor = matmul(matmul(r, local), transpose(r))
        # exactly symmetric: the products above differ in the last bit
        tensor = tuple(tuple((tensor[a][b] + tensor[b][a]) / 2 for b in range(3))
                       for a in range(3))  # type: ignore[assignment]
    return LoadedInertial(mass, _vec3(origin, "xyz"), tensor, line=line_of(el))


def read_inertial(link: Any) -> LoadedInertial:
    """A ``<link>`` element's mass properties, as :func:`read_robot` reads them."""
    return _inertial(link, link.get("name", ""))


def _rgba(visual: Any, materials: dict[str, Any]) -> tuple[tuple[float, ...] | None, str | None,
                                                           bool]:
    mat = visual.find("material")
    if mat is None:
        return None, None, False
    name = mat.get("name")
    color = mat.find("color")
    texture = mat.find("texture") is not None
    if color is None and name in materials:
        color = materials[name].find("color")
        texture = texture or materials[name].find("texture") is not None
    rgba = attr_vec(color, "rgba", 4)
    return rgba, name, texture


def _shape(el: Any, materials: dict[str, Any]) -> LoadedShape | None:
    shape = used_shape(el.find("geometry"))
    if shape is None:
        return None
    origin = el.find("origin")
    kind = shape.tag
    if kind == "box":
        size: tuple[float, ...] = _vec3(shape, "size")
    elif kind in ("cylinder", "capsule"):
        size = (attr_float(shape, "radius", 0.0) or 0.0, attr_float(shape, "length", 0.0) or 0.0)
    elif kind == "sphere":
        size = (attr_float(shape, "radius", 0.0) or 0.0,)
    elif kind in ("mesh", "plane"):
        size = ()
    else:
        return None  # cdf: nothing MuJoCo reads
    out = LoadedShape(kind, size, _vec3(origin, "xyz"), _vec3(origin, "rpy"), line=line_of(el))
    if kind == "mesh":
        out.filename = shape.get("filename")
        out.scale = _vec3(shape, "scale", (1.0, 1.0, 1.0))
    if el.tag == "visual":
        rgba, out.material, out.texture = _rgba(el, materials)
        if rgba is not None:
            out.rgba = (rgba[0], rgba[1], rgba[2], rgba[3])
    return out


def _link(el: Any, materials: dict[str, Any]) -> LoadedLink:
    name = el.get("name", "")
    link = LoadedLink(name, _inertial(el, name), line=line_of(el))
    for tag, into in (("visual", link.visuals), ("collision", link.collisions)):
        for v in el.iterfind(tag):
            s = _shape(v, materials)
            if s is not None:
                into.append(s)
    contact = el.find("contact")
    if contact is not None:
        for child in contact:
            if not isinstance(child.tag, str):
                continue
            value = attr_float(child, "value")
            if child.tag == "lateral_friction" and value is not None:
                link.lateral_friction = value
            elif child.tag == "rolling_friction" and value is not None:
                link.rolling_friction = value
            elif child.tag == "spinning_friction" and value is not None:
                link.spinning_friction = value
            else:
                link.contact_other.append(child.tag)
    return link


def _joint(el: Any) -> LoadedJoint:
    declared = el.get("type", "")
    kind = "fixed" if declared == "floating" else declared
    origin = el.find("origin")
    axis = _vec3(el.find("axis"), "xyz", (1.0, 0.0, 0.0))
    limit = el.find("limit")
    # PyBullet's defaults when <limit> leaves them out: lower 0, upper -1 (unlimited; measured)
    lower = _scalar(limit, "lower", 0.0)
    upper = _scalar(limit, "upper", -1.0)
    # A continuous joint is never limited, but PyBullet reports the <limit> it was given
    # (racecar's right steering hinge: getJointInfo says -1, 1; it turns past them, measured)
    limited = kind in ("revolute", "prismatic") and lower <= upper
    dyn = el.find("dynamics")
    mimic_el = el.find("mimic")
    mimic = None
    if mimic_el is not None and mimic_el.get("joint"):
        mimic = (mimic_el.get("joint", ""), attr_float(mimic_el, "multiplier", 1.0) or 0.0,
                 attr_float(mimic_el, "offset", 0.0) or 0.0)
    odd = [f'{a}="{limit.get(a)}"' for a in ("lower", "upper")
           if limit is not None and _non_finite(limit.get(a))]
    return LoadedJoint(
        el.get("name", ""), kind, el.find("parent").get("link", ""),
        el.find("child").get("link", ""), _vec3(origin, "xyz"), _vec3(origin, "rpy"), axis,
        limited, lower, upper, _scalar(limit, "effort", 0.0), _scalar(limit, "velocity", 0.0),
        _scalar(dyn, "damping", 0.0), _scalar(dyn, "friction", 0.0), mimic, declared,
        line_of(el),
        " ".join(odd) if kind in ("revolute", "prismatic") else "")


def _non_finite(text: str | None) -> bool:
    """Whether an attribute is one number that is not finite (inf, nan, 1e309)."""
    x = c_number(text.strip()) if text is not None else None
    return x is not None and not math.isfinite(x)


def read_robot(root: Any, file: str, *, planar: bool = False) -> LoadedRobot:
    """The robot of a guarded ``<robot>`` element (:class:`urdfkit.sources.resolve.Resolved`).

    Args:
        root: The ``<robot>`` element.
        file: The file as the user named it (for messages).
        planar: Read planar joints (forward kinematics holds them at their origin, as every
            multi-dof joint), where the MJCF export must refuse them.

    Raises:
        InputError: A joint type MuJoCo has no counterpart for here (planar, unless
            ``planar``), a moving joint with a zero axis, a vector that is not finite; with
            its line.
    """
    _ODD.clear()
    try:
        robot = _read(root, file, planar)
    except InputError as e:
        if e.file is None:
            e.file = file
        raise
    robot.warnings = [f"<{el.tag} {attr}={el.get(attr)[:60]!r}> (line {line_of(el)}) is not "
                      "numbers (xacro left in a .urdf?): PyBullet reads each token as C's atof "
                      f"does, so {' '.join(repr(v) for v in vals)}; written so"
                      for el, attr, vals in _ODD]
    _ODD.clear()
    return robot


def _read(root: Any, file: str, planar: bool = False) -> LoadedRobot:
    materials = {m.get("name"): m for m in root.iterfind("material") if m.get("name")}
    links = {el.get("name", ""): _link(el, materials) for el in root.iterfind("link")}
    joints = [_joint(el) for el in root.iterfind("joint")]
    for j in joints:
        if j.type == "planar" and not planar:
            raise InputError(f"joint {j.name!r} is planar; export does not map planar joints "
                             "to MuJoCo yet (two slides and a hinge)", file=file, line=j.line)
        norm = math.sqrt(sum(a * a for a in j.axis))
        if j.moves and j.type != "spherical" and norm == 0:
            raise InputError(f"joint {j.name!r} has a zero axis", file=file, line=j.line)
    children = {j.child for j in joints}
    roots = [n for n in links if n not in children]
    if len(roots) != 1:  # the guard refuses these first; kept for --no-guard callers
        raise InputError(f"the robot has {len(roots)} root links, not one", file=file)
    below: dict[str, list[LoadedJoint]] = {}
    for j in joints:
        below.setdefault(j.parent, []).append(j)
    ordered = depth_first(roots[0], below, lambda j: j.child)
    return LoadedRobot(root.get("name", ""), roots[0], links, ordered, file)
