"""The robot and its XML: :class:`Robot`, and a ``_parse_*``/``_write_*`` pair per tag.

:mod:`urdfkit.builder` is the public face and documents the model; it re-exports every name
in ``__all__`` here. This module lives on the model's floor so that the rooms below the top (the
templates in :mod:`urdfkit.model.catalog`, ``diff``) use the model without importing a
top-level module. The elements a robot is made of are in :mod:`urdfkit.model.builder_elements`.

Every tag has a ``_parse_*`` and a ``_write_*`` function side by side, and
``parse(write(robot)) == robot`` holds for everything the model holds.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from lxml import etree

from urdfkit.core.errors import ModelError
from urdfkit.core.output import atomic_write
from urdfkit.model.builder_elements import (
    SHAPE_CLASSES,
    Box,
    Calibration,
    Capsule,
    Cdf,
    Collision,
    Contact,
    Cylinder,
    Dynamics,
    Geometry,
    Inertia,
    Inertial,
    Limit,
    Link,
    Material,
    Mesh,
    Mimic,
    Origin,
    Plane,
    SafetyController,
    Sphere,
    Visual,
    _checked,
    _contact,
    _Element,
    _finite,
    _geometry,
    _inertial,
    _joint_type,
    _material,
    _name,
    _optional_name,
    _origin,
    as_written,
)
from urdfkit.model.builder_elements import Joint as Joint
from urdfkit.model.spec import (
    JOINT_TYPES,
    LIMITED_JOINT_TYPES,
    SHAPE_SIZES,
    SHAPES,
    depth_first,
    rpy_to_matrix,
)
from urdfkit.model.xmlio import fmt_float, fmt_vec, line_of, load_xml, parse_xml, to_bytes

#: The model API: every element class (defined in :mod:`urdfkit.model.builder_elements`), the robot,
#: and what spec lends it.
__all__ = ["JOINT_TYPES", "LIMITED_JOINT_TYPES", "SHAPE_CLASSES", "Box", "Calibration",
           "Capsule", "Cdf", "Collision", "Contact", "Cylinder", "Dynamics", "Geometry",
           "Inertia", "Inertial", "Joint", "Limit", "Link", "Material", "Mesh", "Mimic",
           "Origin", "Plane", "Robot", "SafetyController", "Sphere", "Visual", "as_written",
           "rpy_to_matrix"]


# --------------------------------------------------------------------------- the robot


@dataclass(eq=False)
class Robot(_Element):
    """A robot: links and joints in declaration order, plus top-level materials.

    ``extras`` keeps top-level elements the model does not know (``<gazebo>``,
    ``<transmission>``) so they survive a read-write round trip.
    """

    _tag = "robot"
    name: str = _checked(check=_name)
    links: list[Link] = field(default_factory=list)
    joints: list[Joint] = field(default_factory=list)
    materials: list[Material] = field(default_factory=list)
    extras: list[etree._Element] = field(default_factory=list)

    # ---- composing

    def add_link(self, link: Link) -> Link:
        """Append a link; its name must be new."""
        if any(x.name == link.name for x in self.links):
            raise ModelError(f"<robot name={self.name!r}> already has a link named {link.name!r}")
        self.links.append(link)
        return link

    def add_joint(self, joint: Joint) -> Joint:
        """Append a joint; its name must be new and its links must exist."""
        if any(x.name == joint.name for x in self.joints):
            raise ModelError(f"<robot name={self.name!r}> already has a joint named "
                             f"{joint.name!r}")
        names = {x.name for x in self.links}
        for role in ("parent", "child"):
            ref = getattr(joint, role)
            if ref not in names:
                raise ModelError(f"<joint name={joint.name!r}> {role} link {ref!r} does not "
                                 "exist; add the link first")
        if any(j.child == joint.child for j in self.joints):
            raise ModelError(f"<joint name={joint.name!r}>: link {joint.child!r} already has "
                             "a parent joint")
        self.joints.append(joint)
        return joint

    def add_material(self, material: Material) -> Material:
        """Define a top-level material that visuals can refer to by name."""
        if any(m.name == material.name for m in self.materials):
            raise ModelError(f"<robot name={self.name!r}> already has a material named "
                             f"{material.name!r}")
        self.materials.append(material)
        return material

    def link(self, name: str) -> Link:
        """The link called ``name``."""
        for x in self.links:
            if x.name == name:
                return x
        raise KeyError(name)

    def joint(self, name: str) -> Joint:
        """The joint called ``name``."""
        for x in self.joints:
            if x.name == name:
                return x
        raise KeyError(name)

    # ---- structure

    @property
    def root(self) -> str:
        """The root link: the one link that is no joint's child."""
        children = {j.child for j in self.joints}
        roots = [x.name for x in self.links if x.name not in children]
        if len(roots) != 1:
            raise ModelError(f"<robot name={self.name!r}> must have exactly one root link, "
                             f"found {len(roots)}: {', '.join(roots) or 'none (a cycle)'}")
        return roots[0]

    def pybullet_joint_order(self) -> list[Joint]:
        """Joints in PyBullet's index order: depth-first from the root, children in file order."""
        by_parent: dict[str, list[Joint]] = {}
        for j in self.joints:
            by_parent.setdefault(j.parent, []).append(j)
        return depth_first(self.root, by_parent, lambda j: j.child)

    def validate(self) -> None:
        """Check the tree: known links, unique names, one root, no cycle, single parents."""
        names = [x.name for x in self.links]
        dup = {n for n in names if names.count(n) > 1}
        if dup:
            raise ModelError(f"<robot name={self.name!r}> has duplicate link names: "
                             f"{', '.join(sorted(dup))}")
        jnames = [j.name for j in self.joints]
        dup = {n for n in jnames if jnames.count(n) > 1}
        if dup:
            raise ModelError(f"<robot name={self.name!r}> has duplicate joint names: "
                             f"{', '.join(sorted(dup))}")
        known = set(names)
        parents: dict[str, str] = {}
        for j in self.joints:
            for role in ("parent", "child"):
                if getattr(j, role) not in known:
                    raise ModelError(f"<joint name={j.name!r}> {role} link "
                                     f"{getattr(j, role)!r} does not exist")
            if j.child in parents:
                raise ModelError(f"link {j.child!r} has two parent joints: "
                                 f"{parents[j.child]!r} and {j.name!r}")
            parents[j.child] = j.name
        order = self.pybullet_joint_order()
        if len(order) != len(self.joints):
            raise ModelError(f"<robot name={self.name!r}> has a kinematic cycle: "
                             f"{len(self.joints) - len(order)} joint(s) unreachable from root "
                             f"{self.root!r}")

    def complete_inertia(self) -> None:
        """Fill in every inertial whose tensor is missing, from the link's collision shapes."""
        for link in self.links:
            link.inertial = link.resolved_inertial()

    # ---- XML

    def to_element(self) -> etree._Element:
        """The robot as an lxml element tree, in a stable order."""
        return _write_robot(self)

    def to_bytes(self) -> bytes:
        """Deterministic, pretty-printed URDF bytes."""
        return to_bytes(self.to_element())

    def write(self, path: str | Path, *, force: bool = False) -> Path:
        """Write atomically; an existing file is kept unless ``force``."""
        return atomic_write(path, self.to_bytes(), force=force)

    @classmethod
    def from_string(cls, text: str | bytes, file: str = "<string>", *,
                    strict: bool = True) -> Robot:
        """Parse URDF text into the model (``strict``: see :meth:`from_element`)."""
        data = text.encode("utf-8") if isinstance(text, str) else text
        return _parse_robot(parse_xml(data, file).getroot(), file, strict)

    @classmethod
    def from_file(cls, path: str | Path, *, strict: bool = True) -> Robot:
        """Parse a URDF file into the model (``strict``: see :meth:`from_element`)."""
        return _parse_robot(load_xml(path).getroot(), str(path), strict)

    @classmethod
    def from_element(cls, root: etree._Element, file: str, *, strict: bool = True) -> Robot:
        """Parse an already parsed ``<robot>`` element, such as a resolved (expanded) tree.

        Taking the element keeps its source lines for messages, which re-serialising it for
        :meth:`from_string` would lose.

        With ``strict`` False the robot is read to be compared, not built: a value the checks
        refuse (a zero axis, ``xyz="0.07, 0, -0.69"``, a sphere of radius 0, a lower limit
        above the upper, a missing ``velocity``) is kept :func:`as_written` instead of raising,
        and a ``<geometry>`` takes its first element as the shape, ignoring what follows, as
        PyBullet does. Names, joint types, shape tags, required elements and the tree (one
        root, known links, no cycle) are still checked. Such a model may hold values no URDF
        should; do not write or simulate it.
        """
        return _parse_robot(root, file, strict)


# --------------------------------------------------------------------------- parse / write
# One _parse_X / _write_X pair per tag; keep them side by side so none is forgotten.


class _Ctx:
    """Where we are in the file, for error messages, and whether values are checked.

    With ``strict`` False a value the model refuses is kept :func:`as_written` (a missing
    number as None), for comparing files rather than building from them. Names, joint types,
    the shape tag and the tree itself are checked either way: without them there is no robot
    to compare.
    """

    def __init__(self, file: str, strict: bool = True):
        self.file = file
        self.strict = strict

    def error(self, el: etree._Element, msg: str) -> ModelError:
        return ModelError(msg, file=self.file, line=line_of(el))

    def attr(self, el: etree._Element, name: str, required: bool = True) -> str | None:
        value = el.get(name)
        if value is None and required:
            raise self.error(el, f"<{el.tag!s}> is missing attribute '{name}'")
        return value

    def build(self, el: etree._Element, factory: Callable[..., Any], **kw: Any) -> Any:
        try:
            return factory(**kw)
        except ModelError as e:
            if self.strict or not isinstance(factory, type):
                raise self.error(el, e.message) from None
        try:
            return _unchecked(factory, kw)
        except ModelError as e:
            raise self.error(el, e.message) from None

    def num(self, el: etree._Element, name: str, required: bool = True) -> Any:
        raw = self.attr(el, name, required and self.strict)
        if raw is None:
            return None
        try:
            return _finite(raw)
        except ModelError as e:
            if not self.strict:
                return as_written(raw)
            raise self.error(el, f"<{el.tag!s} {name}>: {e.message}") from None


#: Checks of what identifies an element or holds the model together: never relaxed.
_STRUCTURAL_CHECKS: tuple[Callable[[Any], Any], ...] = (
    _name, _optional_name, _joint_type, _geometry, _origin, _material, _inertial, _contact)


def _unchecked(cls: type[_Element], kw: dict[str, Any]) -> Any:
    """An element whose refused values are kept :func:`as_written`: the lenient read.

    Fields are set one by one, each through its check, and a value the check refuses is kept
    as written; the cross-field checks of ``__post_init__`` (lower above upper, a limit a
    joint type needs) are skipped. A refused name, joint type or shape still raises.
    """
    obj = cls.__new__(cls)
    for f in dataclasses.fields(cls):  # type: ignore[arg-type]
        if f.name in kw:
            value = kw[f.name]
        elif f.default is not dataclasses.MISSING:
            value = f.default
        elif f.default_factory is not dataclasses.MISSING:
            value = f.default_factory()
        else:
            value = None
        check = f.metadata.get("check")
        if check is not None:
            try:
                value = check(value)
            except ModelError as e:
                if check in _STRUCTURAL_CHECKS:
                    raise ModelError(f"during assignment to attribute '{f.name}' of element "
                                     f"<{cls._tag}>: {e.message}") from None
                value = as_written(value)
        object.__setattr__(obj, f.name, value)
    return obj


def _set(el: etree._Element, name: str, value: float | None) -> None:
    if value is not None:
        el.set(name, fmt_float(value))


def _parse_origin(ctx: _Ctx, el: etree._Element | None) -> Origin:
    if el is None:
        return Origin()
    return ctx.build(el, Origin, xyz=el.get("xyz", "0 0 0"), rpy=el.get("rpy", "0 0 0"))


def _write_origin(parent: etree._Element, origin: Origin) -> None:
    if not origin.is_identity:
        el = etree.SubElement(parent, "origin")
        if any(origin.xyz):
            el.set("xyz", fmt_vec(origin.xyz))
        if any(origin.rpy):
            el.set("rpy", fmt_vec(origin.rpy))


def _parse_geometry(ctx: _Ctx, el: etree._Element | None, owner: etree._Element) -> Geometry:
    if el is None:
        raise ctx.error(owner, f"<{owner.tag!s}> has no <geometry>")
    elements = [c for c in el if isinstance(c.tag, str)]
    # PyBullet reads the first element as the shape and ignores what follows it (an <origin>
    # misplaced there, say); anything else is not one shape. Read leniently, the first
    # element is the shape and what follows it is ignored, as PyBullet does (racecar.urdf has
    # a <material> there).
    shapes = [c for c in elements if c.tag != "origin"]
    if not elements or (ctx.strict and (len(shapes) != 1 or elements[0] is not shapes[0])):
        raise ctx.error(el, f"<geometry> must hold exactly one shape, first, found "
                        f"{', '.join(f'<{c.tag!s}>' for c in elements) or 'nothing'}")
    s = elements[0]
    cls = SHAPE_CLASSES.get(str(s.tag))
    if cls is None:
        raise ctx.error(s, f"unknown shape <{s.tag!s}>; expected one of {', '.join(SHAPES)}")
    if s.tag in SHAPE_SIZES:
        sizes = {a: ctx.attr(s, a, ctx.strict) if a == "size" else ctx.num(s, a)
                 for a in SHAPE_SIZES[s.tag]}
        return ctx.build(s, cls, **sizes)
    if s.tag == "plane":
        return ctx.build(s, Plane, normal=s.get("normal", "0 0 1"))
    return ctx.build(s, cls, filename=ctx.attr(s, "filename"), scale=s.get("scale"))


def _write_geometry(parent: etree._Element, g: Geometry) -> None:
    geo = etree.SubElement(parent, "geometry")
    if isinstance(g, Box):
        etree.SubElement(geo, "box", size=fmt_vec(g.size))
    elif isinstance(g, Cylinder):
        etree.SubElement(geo, "cylinder", radius=fmt_float(g.radius), length=fmt_float(g.length))
    elif isinstance(g, Sphere):
        etree.SubElement(geo, "sphere", radius=fmt_float(g.radius))
    elif isinstance(g, Capsule):
        etree.SubElement(geo, "capsule", radius=fmt_float(g.radius), length=fmt_float(g.length))
    elif isinstance(g, Plane):
        etree.SubElement(geo, "plane", normal=fmt_vec(g.normal))
    else:
        m = etree.SubElement(geo, g._tag, filename=g.filename)
        if g.scale is not None:
            m.set("scale", fmt_vec(g.scale))


def _parse_material(ctx: _Ctx, el: etree._Element) -> Material:
    color = el.find("color")
    texture = el.find("texture")
    name = el.get("name")
    # The SolidWorks exporter writes <material name=""> with the colour inline; PyBullet takes
    # it. Read leniently it is kept, nameless: a material is compared by what it holds.
    unnamed = not ctx.strict and not (name or "").strip()
    material = ctx.build(
        el, Material, name="unnamed" if unnamed else ctx.attr(el, "name"),
        color=None if color is None else ctx.attr(color, "rgba"),
        texture=None if texture is None else ctx.attr(texture, "filename"),
    )
    if unnamed:
        object.__setattr__(material, "name", name or "")
    return material


def _write_material(parent: etree._Element, m: Material) -> None:
    el = etree.SubElement(parent, "material", name=m.name)
    if m.color is not None:
        etree.SubElement(el, "color", rgba=fmt_vec(m.color))
    if m.texture is not None:
        etree.SubElement(el, "texture", filename=m.texture)


def _parse_inertial(ctx: _Ctx, el: etree._Element) -> Inertial:
    mass_el = el.find("mass")
    if mass_el is None:
        raise ctx.error(el, "<inertial> has no <mass>")
    inertia_el = el.find("inertia")
    if inertia_el is None:  # PyBullet refuses the file; the model derives inertia only in code
        raise ctx.error(el, "<inertial> has no <inertia>")
    inertia = ctx.build(inertia_el, Inertia, **{
        k: ctx.num(inertia_el, k) for k in ("ixx", "ixy", "ixz", "iyy", "iyz", "izz")})
    return ctx.build(el, Inertial, mass=ctx.num(mass_el, "value"), inertia=inertia,
                     origin=_parse_origin(ctx, el.find("origin")))


def _write_inertial(parent: etree._Element, i: Inertial) -> None:
    el = etree.SubElement(parent, "inertial")
    _write_origin(el, i.origin)
    etree.SubElement(el, "mass", value=fmt_float(i.mass))
    if i.inertia is not None:
        t = i.inertia
        etree.SubElement(el, "inertia", ixx=fmt_float(t.ixx), ixy=fmt_float(t.ixy),
                         ixz=fmt_float(t.ixz), iyy=fmt_float(t.iyy), iyz=fmt_float(t.iyz),
                         izz=fmt_float(t.izz))


def _parse_visual(ctx: _Ctx, el: etree._Element) -> Visual:
    mat = el.find("material")
    return ctx.build(el, Visual, geometry=_parse_geometry(ctx, el.find("geometry"), el),
                     origin=_parse_origin(ctx, el.find("origin")),
                     material=None if mat is None else _parse_material(ctx, mat),
                     # name="" (exporters write it) names nothing, to PyBullet as here.
                     name=el.get("name") or None)


def _write_visual(parent: etree._Element, v: Visual) -> None:
    el = etree.SubElement(parent, "visual")
    if v.name is not None:
        el.set("name", v.name)
    _write_origin(el, v.origin)
    _write_geometry(el, v.geometry)
    if v.material is not None:
        _write_material(el, v.material)


def _parse_collision(ctx: _Ctx, el: etree._Element) -> Collision:
    return ctx.build(el, Collision, geometry=_parse_geometry(ctx, el.find("geometry"), el),
                     origin=_parse_origin(ctx, el.find("origin")), name=el.get("name") or None)


def _write_collision(parent: etree._Element, c: Collision) -> None:
    el = etree.SubElement(parent, "collision")
    if c.name is not None:
        el.set("name", c.name)
    _write_origin(el, c.origin)
    _write_geometry(el, c.geometry)


def _parse_contact(ctx: _Ctx, el: etree._Element) -> Contact:
    values: dict[str, Any] = {}
    for tag in Contact.VALUE_TAGS:
        child = el.find(tag)
        if child is not None:
            values[tag] = ctx.num(child, "value")
    values["friction_anchor"] = el.find("friction_anchor") is not None
    return ctx.build(el, Contact, **values)


def _write_contact(parent: etree._Element, c: Contact) -> None:
    el = etree.SubElement(parent, "contact")
    for tag in Contact.VALUE_TAGS:
        value = getattr(c, tag)
        if value is not None:
            etree.SubElement(el, tag, value=fmt_float(value))
    if c.friction_anchor:
        etree.SubElement(el, "friction_anchor")


def _parse_link(ctx: _Ctx, el: etree._Element) -> Link:
    inertial = el.find("inertial")
    contact = el.find("contact")
    return ctx.build(
        el, Link, name=ctx.attr(el, "name"),
        inertial=None if inertial is None else _parse_inertial(ctx, inertial),
        visuals=[_parse_visual(ctx, v) for v in el.findall("visual")],
        collisions=[_parse_collision(ctx, c) for c in el.findall("collision")],
        contact=None if contact is None else _parse_contact(ctx, contact),
    )


def _write_link(parent: etree._Element, link: Link) -> None:
    el = etree.SubElement(parent, "link", name=link.name)
    if link.contact is not None:
        _write_contact(el, link.contact)
    inertial = link.resolved_inertial()  # a written file always has a tensor
    if inertial is not None:
        _write_inertial(el, inertial)
    for v in link.visuals:
        _write_visual(el, v)
    for c in link.collisions:
        _write_collision(el, c)


def _parse_limit(ctx: _Ctx, el: etree._Element) -> Limit:
    return ctx.build(el, Limit, effort=ctx.num(el, "effort"), velocity=ctx.num(el, "velocity"),
                     lower=ctx.num(el, "lower", False), upper=ctx.num(el, "upper", False))


def _write_limit(parent: etree._Element, lim: Limit) -> None:
    el = etree.SubElement(parent, "limit")
    _set(el, "lower", lim.lower)
    _set(el, "upper", lim.upper)
    _set(el, "effort", lim.effort)
    _set(el, "velocity", lim.velocity)


def _parse_dynamics(ctx: _Ctx, el: etree._Element) -> Dynamics:
    return ctx.build(el, Dynamics, damping=ctx.num(el, "damping", False),
                     friction=ctx.num(el, "friction", False))


def _write_dynamics(parent: etree._Element, d: Dynamics) -> None:
    el = etree.SubElement(parent, "dynamics")
    _set(el, "damping", d.damping)
    _set(el, "friction", d.friction)


def _parse_mimic(ctx: _Ctx, el: etree._Element) -> Mimic:
    return ctx.build(el, Mimic, joint=ctx.attr(el, "joint"),
                     multiplier=ctx.num(el, "multiplier", False),
                     offset=ctx.num(el, "offset", False))


def _write_mimic(parent: etree._Element, m: Mimic) -> None:
    el = etree.SubElement(parent, "mimic", joint=m.joint)
    _set(el, "multiplier", m.multiplier)
    _set(el, "offset", m.offset)


def _parse_safety(ctx: _Ctx, el: etree._Element) -> SafetyController:
    return ctx.build(el, SafetyController, k_velocity=ctx.num(el, "k_velocity"),
                     soft_lower_limit=ctx.num(el, "soft_lower_limit", False),
                     soft_upper_limit=ctx.num(el, "soft_upper_limit", False),
                     k_position=ctx.num(el, "k_position", False))


def _write_safety(parent: etree._Element, s: SafetyController) -> None:
    el = etree.SubElement(parent, "safety_controller")
    _set(el, "soft_lower_limit", s.soft_lower_limit)
    _set(el, "soft_upper_limit", s.soft_upper_limit)
    _set(el, "k_position", s.k_position)
    _set(el, "k_velocity", s.k_velocity)


def _parse_calibration(ctx: _Ctx, el: etree._Element) -> Calibration:
    return ctx.build(el, Calibration, rising=ctx.num(el, "rising", False),
                     falling=ctx.num(el, "falling", False))


def _write_calibration(parent: etree._Element, c: Calibration) -> None:
    el = etree.SubElement(parent, "calibration")
    _set(el, "rising", c.rising)
    _set(el, "falling", c.falling)


_JOINT_CHILDREN: tuple[tuple[str, str, Callable[..., Any], Callable[..., None]], ...] = (
    ("limit", "limit", _parse_limit, _write_limit),
    ("dynamics", "dynamics", _parse_dynamics, _write_dynamics),
    ("mimic", "mimic", _parse_mimic, _write_mimic),
    ("safety_controller", "safety_controller", _parse_safety, _write_safety),
    ("calibration", "calibration", _parse_calibration, _write_calibration),
)


def _parse_joint(ctx: _Ctx, el: etree._Element) -> Joint:
    parent, child, axis = el.find("parent"), el.find("child"), el.find("axis")
    if parent is None or child is None:
        tag = "parent" if parent is None else "child"
        raise ctx.error(el, f"<joint name={el.get('name')!r}> has no <{tag} link=...>")
    kw: dict[str, Any] = {
        attr: None if (sub := el.find(tag)) is None else parse(ctx, sub)
        for tag, attr, parse, _ in _JOINT_CHILDREN
    }
    return ctx.build(
        el, Joint, name=ctx.attr(el, "name"), type=ctx.attr(el, "type"),
        parent=ctx.attr(parent, "link"), child=ctx.attr(child, "link"),
        origin=_parse_origin(ctx, el.find("origin")),
        axis=None if axis is None else axis.get("xyz", "1 0 0"), **kw,
    )


def _write_joint(parent: etree._Element, j: Joint) -> None:
    el = etree.SubElement(parent, "joint", name=j.name, type=j.type)
    etree.SubElement(el, "parent", link=j.parent)
    etree.SubElement(el, "child", link=j.child)
    _write_origin(el, j.origin)
    if j.axis is not None:
        etree.SubElement(el, "axis", xyz=fmt_vec(j.axis))
    for _, attr, _, write in _JOINT_CHILDREN:
        value = getattr(j, attr)
        if value is not None:
            write(el, value)


_KNOWN_TOP = ("link", "joint", "material")


def _parse_robot(el: etree._Element, file: str, strict: bool = True) -> Robot:
    ctx = _Ctx(file, strict)
    if el.tag != "robot":
        raise ctx.error(el, f"root element is <{el.tag!s}>, expected <robot>")
    robot = ctx.build(el, Robot, name=ctx.attr(el, "name"))
    for child in el:
        if not isinstance(child.tag, str):
            continue  # comments and processing instructions
        try:
            if child.tag == "link":
                robot.add_link(_parse_link(ctx, child))
            elif child.tag == "joint":
                joint = _parse_joint(ctx, child)
                if any(x.name == joint.name for x in robot.joints):
                    raise ModelError(f"duplicate joint name {joint.name!r}")
                robot.joints.append(joint)  # links may be declared after their joints
            elif child.tag == "material":
                robot.add_material(_parse_material(ctx, child))
            else:
                robot.extras.append(_copy(child))
        except ModelError as e:
            if e.line is None:
                raise ctx.error(child, e.message) from None
            raise
    try:
        robot.validate()
    except ModelError as e:
        raise ModelError(e.message, file=file) from None
    return robot


def _copy(el: etree._Element) -> etree._Element:
    import copy

    dup = copy.deepcopy(el)
    dup.tail = None
    return dup


def _write_robot(robot: Robot) -> etree._Element:
    el = etree.Element("robot", name=robot.name)
    for m in robot.materials:
        _write_material(el, m)
    for link in robot.links:
        _write_link(el, link)
    for joint in robot.joints:
        _write_joint(el, joint)
    for extra in robot.extras:
        el.append(_copy(extra))
    return el
