"""Validation of URDF documents: ``check``'s rules beyond the guard.

Rules work on the lxml tree (not on a parsed model) so that every finding can carry the line
it comes from, and so that broken files are described rather than refused at the first error.
The rules every loader runs, and the :class:`~urdfkit.sources.guard.RuleReport` they all write
to, are in :mod:`urdfkit.sources.guard`; :data:`ALL_RULES` is the guard's rules followed by
these.
"""

from __future__ import annotations

import math
import os
import sys
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any, cast

from lxml import etree

from urdfkit.model.index import Doc, JointView, LinkView, collision_parts, first
from urdfkit.model.spec import (
    EXTENSIONS,
    LIMITED_JOINT_TYPES,
    MAX_STATE_LINKS,
    SHAPES,
    SOLIDS,
    WORLD_LINK,
    Matrix3,
    atof,
    default_mass,
    extension_note,
    matmul,
    rotate,
    rpy_to_matrix,
    solid_inertia,
    solid_volume,
    sym_eigenvalues,
    transpose,
)
from urdfkit.model.spec import attr_float as _num
from urdfkit.model.spec import attr_vec as _vec
from urdfkit.sources.guard import GUARD_RULES, Rule, RuleReport, label, mesh_crash
from urdfkit.sources.meshstore import CONCAVE_FRACTION, MeshProperties
from urdfkit.sources.meshstore import properties as mesh_properties
from urdfkit.sources.meshstore import stated as stated_properties

# --------------------------------------------------------------------------- structural rules
# These are the rules PyBullet crashes on when they are broken; the guard runs exactly these.


def rule_link_count(root: etree._Element, r: RuleReport) -> None:
    """U208: 128 links or more break PyBullet's state queries."""
    n = len(r.doc(root).links)
    if n >= MAX_STATE_LINKS:
        r.add("U208", "error", f"{n} links: PyBullet's getJointState/getLinkState fail on "
              f"bodies with {MAX_STATE_LINKS} links or more (MAX_DEGREE_OF_FREEDOM); split "
              "the model", root)


# --------------------------------------------------------------------------- values and physics
# Numbers are parsed once per attribute by _num/_vec, which never report: rule_numbers reports
# every malformed number once, and the other rules simply skip what does not parse.

#: Drake's tolerance unit for inertia checks (DBL_EPSILON).
_DBL_EPSILON = sys.float_info.epsilon


def rule_elements(root: etree._Element, r: RuleReport) -> None:
    """U401-U402 and U801-U802: numbers and names of tags and attributes.

    Numbers parse, are finite and have the right length; tags and attributes are known
    (typos, or extensions PyBullet ignores). Judged on the document's one walk
    (:class:`~urdfkit.model.index.Doc`), which skips comments, namespaced elements (xacro
    leftovers, extensions), opaque subtrees (another tool's: gazebo, transmission, ...) and
    shapes after the first in a ``<geometry>``.
    """
    found = r.doc(root).element_findings
    if not found:
        return  # most files (and no import statement run for them)
    from urdfkit.model.spec import did_you_mean, nearest_attributes, nearest_tags

    for code, level, message, el in found:
        if code == "U801" and el.tag == "gazebo":
            continue  # another tool's block, PyBullet ignores it: U803 judges its contacts
        # The verdicts are shared between elements; the nearest name is added per finding.
        if code == "U801":
            parent = el.getparent()
            if parent is not None:
                message += did_you_mean(nearest_tags(el.tag, parent.tag))
        elif code == "U802":
            for attr in el.keys():
                if f"unknown attribute {attr!r};" in message:
                    message += did_you_mean(nearest_attributes(attr, el.tag), tags=False)
                    break
        r.add(code, level, message, el)


def _mass_of(link: LinkView) -> float | None:
    """The mass PyBullet gives a link: its <mass>, or without <inertial> 1 kg (0 for world)."""
    if link.inertial is None:
        return default_mass(link.name)
    return _num(link.mass, "value")


def _loaded_mass(link: LinkView) -> float | None:
    """:func:`_mass_of`, with a malformed number read as PyBullet reads it (C's atof).

    ``"abc"`` is 0 kg to PyBullet, ``"nan"`` NaN: only a mass it reads as 0 makes U602 and
    U611 true (U401 says the number is malformed).
    """
    mass = _mass_of(link)
    if mass is None and link.mass is not None and (text := link.mass.get("value")) is not None:
        return atof(text.strip())
    return mass


def rule_mass(root: etree._Element, r: RuleReport) -> None:
    """U601-U602, U606: mass >= 0, > 0 on links that move; warn on missing <inertial>."""
    doc = r.doc(root)
    views = {v.name: v for v in doc.links if v.name}
    fixed_children: dict[str, list[str]] = {}
    moving: list[tuple[str, etree._Element]] = []
    for jv in doc.joints:
        parent, child = jv.parent, jv.child
        if parent is None or child is None:
            continue
        if jv.type == "fixed":
            fixed_children.setdefault(parent.get("link", ""), []).append(child.get("link", ""))
        else:
            moving.append((child.get("link", ""), jv.el))
    child_names = {c.get("link") for jv in doc.joints for c in jv.children}
    for view in views.values():
        link, inertial = view.el, view.inertial
        if inertial is None and view.name == WORLD_LINK:
            continue  # PyBullet gives it mass 0, not 1 kg: U611 (a root) or U602 (moving) say so
        if inertial is None:
            # Never "mass 0" for the root: PyBullet fixes a mass-0 base in place (U611).
            advice = ("add <inertial> with its real mass (mass 0 would fix the robot in place)"
                      if link.get("name") not in child_names else
                      "add <inertial> (mass 0 for a frame)")
            r.add("U606", "warning", f"{label(link)} has no <inertial>; PyBullet silently gives "
                  f"it 1 kg and unit inertia: {advice}", link)
            continue
        mass_el = view.mass
        mass = _num(mass_el, "value")
        if mass_el is None or mass_el.get("value") is None:
            r.add("U601", "error", f"<inertial> of {label(link)} has no <mass value=...>",
                  inertial)
        elif mass is not None and mass < 0:
            r.add("U601", "error", f"{label(link)} has negative mass {mass:g}; mass must be "
                  ">= 0", mass_el)
    for name, j in moving:
        if name in views and _rigid_mass(name, views, fixed_children) == 0:
            r.add("U602", "error", f"{label(views[name].el)} moves (joint {j.get('name')!r} is "
                  f"{j.get('type')}) but has mass 0"
                  + (" (it has no <inertial> and is named world, which PyBullet gives mass 0, "
                     "not 1 kg)" if name == WORLD_LINK and views[name].inertial is None else "")
                  + "; give it a mass > 0", views[name].el)
    roots = [view for name, view in views.items() if name not in child_names]
    # PyBullet judges the root link's own mass: 0 fixes the base in place, whatever its fixed
    # children weigh (a mass-0 base_footprint over a 28 kg base_link hangs in the air). A
    # root with no <inertial> gets 1 kg, so it moves (U606 says so).
    # A root named world without <inertial> gets mass 0 from PyBullet (measured), so it too.
    own = _loaded_mass(roots[0]) if len(roots) == 1 and (
        roots[0].inertial is not None or roots[0].name == WORLD_LINK) else None
    if own is not None and own == 0:
        base, static = roots[0].el, not moving
        carried = _rigid_mass(base.get("name", ""), views, fixed_children)
        held = (f"; its fixed links weigh {carried:g} kg, and PyBullet ignores that: it looks "
                "at the root's own mass" if carried > 0 else "")
        why = ("has no <inertial> and is named world, which PyBullet gives mass 0 (not 1 kg)"
               if roots[0].inertial is None else "has mass 0")
        # A root named world is the ROS convention for "bolted to the world": as meant.
        bolted = roots[0].inertial is None
        r.add("U611", "info" if bolted or (static and not carried) else "warning",
              f"root {label(base)} {why}: PyBullet makes the base static, fixed where it "
              "is loaded" + (" (right for a static object such as ground)"
                             if static and not carried else
                             "; right for an arm bolted to the world, wrong for a robot "
                             "that should fall or drive: give the root link a mass, or make "
                             "the massive link the root") + (held if not bolted else ""),
              base)


def _rigid_mass(name: str, views: dict[str, LinkView],
                fixed_children: dict[str, list[str]]) -> float:
    """The mass of link ``name`` with everything fixed to it: massless only if all of them are.

    A module function, not one nested in rule_mass: a closure over the rule's locals once
    kept each file's whole document alive in a reference cycle until the collector ran
    (tests/test_check_memory.py fails on per-file cycles).
    """
    total, stack, seen = 0.0, [name], set()
    while stack:
        n = stack.pop()
        if n in seen or n not in views:
            continue
        seen.add(n)
        mass = _loaded_mass(views[n]) or 0.0
        total += 0.0 if mass < 0 else mass  # NaN stays NaN: not a mass of 0
        stack.extend(fixed_children.get(n, []))
    return total


def _inertia_tensor(inertia: etree._Element) -> tuple[tuple[float, ...], ...] | None:
    vals = [_num(inertia, a) for a in ("ixx", "ixy", "ixz", "iyy", "iyz", "izz")]
    if any(v is None for v in vals):
        return None
    ixx, ixy, ixz, iyy, iyz, izz = vals
    return ((ixx, ixy, ixz), (ixy, iyy, iyz), (ixz, iyz, izz))  # type: ignore[return-value]


def rule_material_colours(root: etree._Element, r: RuleReport) -> None:
    """U710: one material name given several colours; PyBullet draws them all in one.

    Measured on PyBullet 3.2.7: every visual whose material has that name (``""`` included,
    at the top level or inline) is drawn in the colour written last in the file.
    """
    materials = r.doc(root).all_materials
    if len(materials) < 2:
        return  # no name can be given two colours
    colours: dict[str, list[tuple[str, etree._Element]]] = {}
    for m in materials:
        name = m.get("name")
        if name is None:
            continue
        color = _child(m, "color")
        if color is None or color.get("rgba") is None:
            continue
        colours.setdefault(name, []).append((" ".join(color.get("rgba", "").split()), color))
    for name, found in colours.items():
        if len(found) < 2:
            continue  # one colour given
        distinct = list(dict.fromkeys(c for c, _ in found))
        if len(distinct) < 2:
            continue
        shown = ", ".join(distinct[:4]) + (f" and {len(distinct) - 4} more"
                                           if len(distinct) > 4 else "")
        r.add("U710", "warning", f"material name {name!r} is given {len(distinct)} colours "
              f"({shown}): PyBullet draws every visual named so in the last one written, "
              f"rgba {found[-1][0]}; give each colour its own name", found[1][1])


def rule_references(root: etree._Element, r: RuleReport) -> None:
    """U308, U706-U708: references that lead nowhere, and limits PyBullet reads differently.

    A ``<material name>`` used but never defined, a ``<transmission>`` naming a missing joint,
    an empty ``<texture/>``, ``package:///`` without a package name, and a revolute or
    prismatic ``<limit>`` without lower/upper (PyBullet: unlimited; the URDF spec: 0..0).
    """
    doc = r.doc(root)
    # (material, whether it has a <color> or <texture> child), each looked at once
    given = [(m, _defines_colour(m)) for m in doc.all_materials]
    defined = {m.get("name") for m, has in given if has}
    for m, has in given:
        if has:
            continue
        parent = m.getparent()
        if (parent is not None and parent.tag == "visual" and m.get("name")
                and m.get("name") not in defined):
            r.add("U706", "warning", f"<material name={m.get('name')!r}> is used but never "
                  "defined with a <color> or <texture>; PyBullet draws the default colour", m)
    # One look at each filename; all U707 first, then all U708, as two passes gave them.
    empty, rooted = [], []
    for el in doc.files:
        fn = (el.get("filename") or "").strip()
        if not fn:
            if el.tag == "texture":
                empty.append(el)
        elif fn.startswith("package:///"):
            rooted.append(el)
    for t in empty:
        r.add("U707", "warning", "<texture> without a filename; remove it or name the "
              "image", t)
    for el in rooted:
        r.add("U708", "info", f"<{el.tag} filename={el.get('filename')!r}>: package:/// "
              "has no package name; PyBullet and urdfkit look the path up beside the file "
              "and in every folder above, ROS tools refuse it", el)
    joints = {jv.name for jv in doc.joints} if doc.transmissions else set()
    for t in doc.transmissions:
        for j in t.iter("joint"):
            if j.get("name") and j.get("name") not in joints:
                r.add("U709", "warning", f"<transmission name={t.get('name')!r}> names joint "
                      f"{j.get('name')!r}, which does not exist", j)
    for jv in doc.joints:
        j, limit = jv.el, jv.limit
        if (jv.type in LIMITED_JOINT_TYPES and limit is not None
                and (limit.get("lower") is None or limit.get("upper") is None)):
            missing = " and ".join(a for a in ("lower", "upper") if limit.get(a) is None)
            r.add("U308", "warning", f"<limit> of {label(j)} has no {missing}: PyBullet reads "
                  "it as unlimited, the URDF spec (and ROS) as 0; give both", limit)


def _defines_colour(material: etree._Element) -> bool:
    """Whether a ``<material>`` has a ``<color>`` or ``<texture>`` child."""
    for c in material:  # first(m, "color") or first(m, "texture"), in one look
        if c.tag == "color" or c.tag == "texture":
            return True
    return False


def _child(el: etree._Element, tag: str) -> etree._Element | None:
    """``first(el, tag)``: the first child named ``tag``, by a loop (no iterator object)."""
    for c in el:
        if c.tag == tag:
            return c
    return None


def rule_inertia(root: etree._Element, r: RuleReport) -> None:
    """U603-U605, U607: inertia positive definite, triangle inequality, plausible for shapes.

    Tolerance as in Drake's ``RotationalInertia::CouldBePhysicallyValid``:
    ``eps = 10 * DBL_EPSILON * max(1, trace / 2)``, on the principal moments.
    """
    noted = False
    doc = r.doc(root)
    for view in doc.links:
        link, inertial, inertia = view.el, view.inertial, view.inertia
        if inertial is None or inertia is None:
            continue
        if not noted:
            r.add("U607", "info", "PyBullet ignores <inertia> from the file and recomputes it "
                  "from the collision shapes unless loaded with URDF_USE_INERTIA_FROM_FILE "
                  "(urdfkit: --inertia-from-file)", inertia)
            noted = True
        principal = _principal(inertia, doc.inertia_keys.get(inertia))
        if principal is None:
            continue
        trace, eps, a, b, c, moments = principal
        mass = _num(view.mass, "value")
        shapes = _shape_trace(link, mass, r, view.collisions)
        if a < -eps:
            r.add("U603", "error", f"inertia of {label(link)} is not positive definite "
                  f"(principal moments {moments}); every principal moment must be "
                  f"> 0{_shapes_fix(shapes)}", inertia)
            continue
        if mass is not None and mass > 0 and a <= eps:
            r.add("U608", "warning", f"inertia of {label(link)} is singular (principal moments "
                  f"{moments}): a point or a thin rod, not a solid; with "
                  f"URDF_USE_INERTIA_FROM_FILE the solver may blow up{_shapes_fix(shapes)}",
                  inertia)
        if a + b < c - eps:
            r.add("U604", "error", f"inertia of {label(link)} violates the triangle inequality: "
                  f"principal moments {moments} (the two smaller sum to less than "
                  f"the largest); no rigid body has it: lower the largest to at most "
                  f"{a + b:.4g}{_shapes_fix(shapes)}", inertia)
            continue
        if shapes and shapes[0] > 0 and trace > 0 and not 0.1 <= trace / shapes[0] <= 10:
            ratio = f"inertia of {label(link)} is {trace / shapes[0]:.3g} times what its " \
                    f"collision shapes and mass {mass:g} kg imply"
            if shapes[1] < STUB_SIZE:
                r.add("U605", "warning", f"{ratio}, but those shapes are stubs (largest size "
                      f"{shapes[1]:.3g} m): PyBullet recomputes inertia from them unless loaded "
                      "with URDF_USE_INERTIA_FROM_FILE; give real collision shapes", inertia)
            else:
                r.add("U605", "warning", f"{ratio}; check the units and the mass", inertia)


#: Collision shapes smaller than this (m, largest size) are placeholders, not the body.
STUB_SIZE = 0.01


def _principal(inertia: etree._Element, key: tuple[Any, ...] | None = None
               ) -> tuple[float, float, float, float, float, str] | None:
    """(trace, tolerance, principal moments a <= b <= c, the moments as a message writes them).

    None if a component is missing or malformed. Kept per process by the element's
    attributes, which are all it depends on (bounded): files repeat their inertia values
    (pybullet_data's thousand random objects all have ``ixx="1" ... izz="0"``). ``key``:
    the element's tag and attributes as the document's walk keyed them
    (:attr:`~urdfkit.model.index.Doc.inertia_keys`), when it has them.
    """
    if key is None:
        key = (inertia.tag, *inertia.items())
    found: Any = _PRINCIPAL.get(key, _UNSEEN)
    if found is _UNSEEN:
        tensor = _inertia_tensor(inertia)
        if tensor is None:
            found = None
        else:
            trace = tensor[0][0] + tensor[1][1] + tensor[2][2]
            a, b, c = sym_eigenvalues(tensor)
            found = (trace, 10 * _DBL_EPSILON * max(1.0, trace / 2), a, b, c,
                     _moments((a, b, c)))
        if len(_PRINCIPAL) >= _PRINCIPAL_MAX:
            _PRINCIPAL.clear()
        _PRINCIPAL[key] = found
    return found


_PRINCIPAL: dict[tuple[Any, ...],
                 tuple[float, float, float, float, float, str] | None] = {}
_PRINCIPAL_MAX = 4096


def _moments(values: Sequence[float]) -> str:
    """Principal moments for a message: round-off (-4.2e-22 beside 0.1) printed as 0."""
    scale = max(abs(v) for v in values)
    return ", ".join("0" if abs(v) <= 1e-9 * scale else f"{v:.4g}" for v in values)


def _shapes_fix(shapes: tuple[float, float] | None) -> str:
    """The inertia the collision shapes imply, as a message's advice ("" for stubs or none).

    Written only into a finding: most links have none, and formatting is not free.
    """
    if not shapes or shapes[1] < STUB_SIZE:
        return ""
    return (f"; its collision shapes and mass imply a trace of {shapes[0]:.4g}, e.g. "
            f"ixx=iyy=izz={shapes[0] / 3:.4g} with products 0")


@dataclass(frozen=True, slots=True)
class Solid:
    """A link's collision shapes as one solid of uniform density.

    Attributes:
        volume: m^3.
        com: Centre of mass in the link frame.
        tensor: Inertia about ``com``, in link axes, per unit density (multiply by
            mass / volume for a mass).
        size: The largest size of any part, m (stub shapes are tiny).
    """

    volume: float
    com: tuple[float, float, float]
    tensor: tuple[tuple[float, float, float], ...]
    size: float

    def inertia(self, mass: float) -> tuple[tuple[float, float, float], ...]:
        """The inertia tensor about ``com`` for a total ``mass``."""
        k = mass / self.volume
        return tuple((row[0] * k, row[1] * k, row[2] * k) for row in self.tensor)

    def trace(self, mass: float) -> float:
        """Trace of :meth:`inertia`."""
        return sum(self.tensor[i][i] for i in range(3)) * mass / self.volume


def link_solid(link: etree._Element, r: RuleReport | None = None,
               collisions: list[etree._Element] | None = None) -> Solid | None:
    """The solid the link's collision shapes make: what ``U605`` and ``urdfkit fix`` use.

    Primitive shapes use spec's closed forms; STL, OBJ and COLLADA meshes (with ``scale``)
    are integrated by :mod:`urdfkit.sources.meshes` when ``r`` knows the file's folder. Each part's
    tensor is rotated into the link frame and moved to the common centre of mass (parallel
    axes). None if unknown: no collision, a capsule, plane or SDF, a mesh that cannot be read
    or is not closed, a bad size. ``collisions``: the link's ``<collision>`` children, when
    the caller has them (:class:`~urdfkit.model.index.LinkView`).
    """
    found = _solid(link, r, collisions)
    return None if found is None else Solid(*found)


_ZERO3: tuple[float, ...] = (0.0, 0.0, 0.0)


def _solid(link: etree._Element, r: RuleReport | None,
           collisions: list[etree._Element] | None
           ) -> tuple[float, tuple[float, float, float], Matrix3, float] | None:
    """:func:`link_solid`'s fields (volume, com, tensor, size), without making the record."""
    parts: list[tuple[float, tuple[float, ...], Matrix3, float]] = []
    moving: set[str] | None = None
    if collisions is None:
        collisions = [c for c in link if c.tag == "collision"]
    for col in collisions:
        shape, origin = collision_parts(col, SHAPES)
        if shape is None:
            return None
        xyz: tuple[float, ...] | None
        rpy: tuple[float, ...] | None
        if origin is None:
            xyz = rpy = _ZERO3
        else:
            xyz = _vec(origin, "xyz", 3, _ZERO3)
            rpy = _vec(origin, "rpy", 3, _ZERO3)
            if xyz is None or rpy is None:
                return None
        rot = None if rpy == _ZERO3 else rpy_to_matrix(rpy)  # None: no rotation
        if shape.tag == "mesh":
            # The mesh-shape rule will want a moving link's concavity: read it in one go.
            if r is not None and moving is None:
                moving = _moving(r, link)
            concave = moving is not None and link.get("name") in moving
            part = _mesh_part(shape, xyz, rot, r, concave)
            if part is None:
                return None
            parts.append(part)
            continue
        if shape.tag not in SOLIDS or shape.tag == "capsule":
            return None  # planes, SDFs: no volume
        raw: Sequence[float | None] | None = (
            _vec(shape, "size", 3) if shape.tag == "box"
            else [_num(shape, attr) for attr in SOLIDS[shape.tag]])
        dims = [d for d in raw or () if d is not None and math.isfinite(d) and d > 0]
        if raw is None or len(dims) != len(raw):
            return None  # U401/U501 say why
        volume = solid_volume(shape.tag, dims)
        size = max(dims) if shape.tag == "box" else max([2 * dims[0], *dims[1:]])
        d = solid_inertia(shape.tag, dims, volume)
        diag = ((d[0], 0.0, 0.0), (0.0, d[1], 0.0), (0.0, 0.0, d[2]))
        parts.append((volume, xyz, diag if rot is None else
                      matmul(matmul(rot, diag), transpose(rot)), size))
    return _combine(parts)


def _combine(parts: list[tuple[float, tuple[float, ...], Matrix3, float]]
             ) -> tuple[float, tuple[float, float, float], Matrix3, float] | None:
    """Parts (volume, centre, tensor per unit density, size) as one solid's fields."""
    if len(parts) == 1:  # the common case: sum() of one term is 0.0 plus the term
        volume, centre, _, _ = parts[0]
        total = 0.0 + volume
        if not 0 < total < math.inf:
            return None
        cx = (0.0 + volume * centre[0]) / total
        cy = (0.0 + volume * centre[1]) / total
        cz = (0.0 + volume * centre[2]) / total
    else:
        total = sum(p[0] for p in parts)
        if not parts or not 0 < total < math.inf:
            return None
        cx = sum(v * c[0] for v, c, _, _ in parts) / total
        cy = sum(v * c[1] for v, c, _, _ in parts) / total
        cz = sum(v * c[2] for v, c, _, _ in parts) / total
    # Parallel axes: each part's tensor moved from its centre to the common one.
    xx = xy = xz = yx = yy = yz = zx = zy = zz = 0.0
    for volume, centre, t, _ in parts:
        dx, dy, dz = centre[0] - cx, centre[1] - cy, centre[2] - cz
        d2 = dx * dx + dy * dy + dz * dz
        (t00, t01, t02), (t10, t11, t12), (t20, t21, t22) = t
        xx += t00 + volume * (d2 - dx * dx)
        xy += t01 + volume * (0.0 - dx * dy)
        xz += t02 + volume * (0.0 - dx * dz)
        yx += t10 + volume * (0.0 - dy * dx)
        yy += t11 + volume * (d2 - dy * dy)
        yz += t12 + volume * (0.0 - dy * dz)
        zx += t20 + volume * (0.0 - dz * dx)
        zy += t21 + volume * (0.0 - dz * dy)
        zz += t22 + volume * (d2 - dz * dz)
    if not all(map(math.isfinite, (xx, xy, xz, yx, yy, yz, zx, zy, zz))):
        return None
    return (total, (cx, cy, cz), ((xx, xy, xz), (yx, yy, yz), (zx, zy, zz)),
            parts[0][3] if len(parts) == 1 else max(p[3] for p in parts))


def _shape_trace(link: etree._Element, mass: float | None, r: RuleReport | None = None,
                 collisions: list[etree._Element] | None = None
                 ) -> tuple[float, float] | None:
    """Trace of the inertia of the link's collision solids for ``mass``, and their size."""
    if mass is None or mass <= 0:
        return None
    solid = _solid(link, r, collisions)
    if solid is None:
        return None
    volume, _, tensor, size = solid
    trace = sum((tensor[0][0], tensor[1][1], tensor[2][2])) * mass / volume  # Solid.trace
    return (trace, size) if math.isfinite(trace) else None


def _mesh_part(shape: etree._Element, xyz: Sequence[float], rot: Matrix3 | None,
               r: RuleReport | None, concavity: bool = False
               ) -> tuple[float, tuple[float, ...], Matrix3, float] | None:
    """A collision mesh as (volume, centre in the link, tensor per unit density, size).

    ``rot``: the collision's rotation, None for none.
    """
    fn = (shape.get("filename") or "").strip()
    if r is None or r.folder is None or not fn:
        return None
    ref = r.reference("mesh", fn)
    scale = _vec(shape, "scale", 3, (1.0, 1.0, 1.0))
    if ref.load is None or scale is None:
        return None
    props = _properties(r, ref.load, scale, concavity, ref.stat)
    if props is None:
        return None
    if not props.closed:
        r.add("U612", "warning", f"collision mesh {fn!r} is not closed (some edges do not "
              "join two triangles): it has no volume, so its inertia cannot be derived and "
              "PyBullet's recomputed inertia is unreliable; close it or give <inertia> and load "
              "with URDF_USE_INERTIA_FROM_FILE", shape)
        return None
    if props.volume <= 0:
        return None
    # MeshProperties.scaled makes the tensor as three rows of three: no copy needed.
    own = cast(Matrix3, props.inertia)
    com = props.com
    if rot is None:
        return (props.volume, (xyz[0] + com[0], xyz[1] + com[1], xyz[2] + com[2]), own,
                max(props.extent))
    centre = rotate(rot, com)
    return (props.volume, (xyz[0] + centre[0], xyz[1] + centre[1], xyz[2] + centre[2]),
            matmul(matmul(rot, own), transpose(rot)), max(props.extent))


def _properties(r: RuleReport, path: str, scale: Sequence[float], concavity: bool = False,
                st: os.stat_result | None = None) -> MeshProperties | None:
    """:func:`urdfkit.sources.meshstore.properties`, once per mesh and scale per file.

    The inertia and mesh-shape rules both ask. ``concavity``: the concavity depth is needed
    (a collision mesh of a moving link); it is worked out only then. ``st``: the path's
    ``os.stat``, when the reference already took it.
    """
    key = ("mesh", path, scale[0], scale[1], scale[2])
    memo = r.memo
    found: Any = memo.get(key, _UNSEEN)  # Any: the marker is not a MeshProperties
    if found is _UNSEEN or (concavity and found is not None and math.isnan(found.concavity)):
        # A reference carries a stat only from guard.reference's plain-path branch, which has
        # noted ``path`` to deps and, for a "mesh" reference (the only kind asked here),
        # found a mesh suffix on it: meshstore.stated skips those two steps.
        three = (scale[0], scale[1], scale[2])
        props = memo[key] = (mesh_properties(path, three, concavity=concavity) if st is None
                             else stated_properties(path, st, three, concavity=concavity))
        return props
    return found


_UNSEEN: Any = object()


def _moving(r: RuleReport, el: etree._Element) -> set[str]:
    """:func:`_moving_links` of the document ``el`` belongs to, once per file."""
    moving: set[str] | None = r.memo.get("moving links")
    if moving is None:
        moving = r.memo["moving links"] = _moving_links(r.doc(el.getroottree().getroot()))
    return moving


def rule_meshes(root: etree._Element, r: RuleReport) -> None:
    """U701-U705: mesh and texture files exist, are files, in formats PyBullet reads."""
    if r.folder is None:
        return
    doc = r.doc(root)
    for el in doc.files:
        fn = (el.get("filename") or "").strip()
        if fn and el not in doc.unread:  # a mesh after the first shape is never opened
            ref = r.reference(el.tag, fn)
            if ref.code is not None:
                r.add(ref.code, ref.level, ref.message, el)


def rule_mesh_crashes(root: etree._Element, r: RuleReport) -> None:
    """U712-U713: mesh files PyBullet crashes or hangs on, which every loader refuses.

    The guard's own rule (:func:`urdfkit.sources.guard.mesh_crash`), said as a finding: COLLADA
    PyBullet's reader crashes on, NaN vertices in a collision mesh it builds a hull of.
    """
    if r.folder is None:
        return
    for _, _, _, mesh in r.parts(root):
        if mesh is None or mesh.tag != "mesh":
            continue
        fn = (mesh.get("filename") or "").strip()
        if not fn or (ref := r.reference("mesh", fn)).load is None or (
                ref.code is not None and ref.level == "error"):
            continue
        crash = mesh_crash(mesh, ref)
        if crash is not None:
            r.add(crash[0], "error", crash[1], mesh)


def rule_visual_meshes(root: etree._Element, r: RuleReport) -> None:
    """U715: a visual mesh PyBullet draws nothing or only part of.

    An empty file, or COLLADA placing its parts through ``<instance_node>`` (robots exported
    from some CAD tools): PyBullet loads the robot and draws nothing of that link, without a
    word on stdout. Only ``.dae`` files are read (a substring search first); an empty file is
    known from its stat.
    """
    if r.folder is None:
        return
    for view, part, _, mesh in r.parts(root):
        if part.tag != "visual" or mesh is None or mesh.tag != "mesh":
            continue
        fn = (mesh.get("filename") or "").strip()
        if not fn or (ref := r.reference("mesh", fn)).load is None:
            continue
        empty = ref.stat is not None and ref.stat.st_size == 0
        # meshes.mesh_kind(ref.load), without importing the mesh readers for every check run
        # (and without splitting names that cannot end in .dae)
        if not empty and (ref.load[-4:].lower() != ".dae"
                          or os.path.splitext(ref.load)[1].lower() != ".dae"):
            continue
        from urdfkit.sources.meshes import undrawn_visual

        why = undrawn_visual(ref.load)
        if why is not None:
            r.add("U715", "warning", f"visual mesh {fn!r} of {label(view.el)} {why}; "
                  "the robot looks incomplete in render, view and the GUI (export it "
                  "with its nodes flattened, or as .obj/.stl)", mesh)


#: A mesh this many times larger (or smaller) than the robot's typical joint spacing is in
#: the wrong units (millimetres read as metres gives 1000x).
UNITS_RATIO = 200.0


def rule_mesh_shapes(root: etree._Element, r: RuleReport) -> None:
    """U613-U614: meshes in the wrong units; concave collision meshes on links that move.

    Units are judged against the robot's own scale: the median distance between joint
    frames (a model with fewer than two offset joints has no scale, and is not judged).
    PyBullet collides with the convex hull of a mesh (one per OBJ object), so a concave
    collision mesh on a moving link touches where it has a dip; the root's rigid group is not
    judged (a static or bolted base may use ``<collision concave="yes">`` instead).
    """
    if r.folder is None:
        return
    doc = r.doc(root)
    offsets = sorted(math.sqrt(sum(x * x for x in xyz)) for jv in doc.joints
                     if (xyz := _vec(jv.origin, "xyz", 3)) is not None and any(xyz))
    spacing = offsets[len(offsets) // 2] if len(offsets) >= 2 else None
    moving = _moving(r, root)
    if not spacing and not moving:
        return  # neither finding can be made of any mesh
    for view, part, _, mesh in r.parts(root):
        link = view.el
        concave_matters = part.tag == "collision" and view.name in moving
        if not spacing and not concave_matters:
            continue  # neither finding can be made of this mesh
        fn = (mesh.get("filename") or "").strip() if mesh is not None and \
            mesh.tag == "mesh" else ""
        if not fn or (ref := r.reference("mesh", fn)).load is None:
            continue
        scale = _vec(mesh, "scale", 3, (1.0, 1.0, 1.0))
        props = _properties(r, ref.load, scale, concave_matters, ref.stat) \
            if scale else None
        if props is None:
            continue
        size = max(props.extent)
        if spacing and size > 0 and not 1 / UNITS_RATIO <= size / spacing <= UNITS_RATIO:
            ratio = size / spacing
            fix = ("probably in millimetres: add scale=\"0.001 0.001 0.001\"" if ratio > 1
                   else "probably scaled twice, or in metres where millimetres were meant: "
                   "check its scale")
            r.add("U613", "warning", f"mesh {fn!r} of {label(link)} is {size:.3g} m across, "
                  f"{ratio:.3g} times the robot's typical joint spacing ({spacing:.3g} m): "
                  f"{fix}", mesh)
        if concave_matters and props.concavity > CONCAVE_FRACTION * size:
            r.add("U614", "warning", f"collision mesh {fn!r} of moving {label(link)} is "
                  f"concave (it is {size:.3g} m across, and parts of it stand up to "
                  f"{props.concavity:.3g} m in front of its own faces' planes"
                  + ("" if props.closed else "; it is also open, so the depth is "
                     "judged on the faces it has") + "): PyBullet "
                  "collides with its convex hull, so contacts happen in mid-air over the "
                  "dips; split it into convex parts (p.vhacd, or one OBJ object per part) "
                  "or use primitives", mesh)


def _moving_links(doc: Doc) -> set[str]:
    """Links outside the root's rigid group: each moves through a joint that is not fixed."""
    below: dict[str, list[tuple[str, bool]]] = {}
    children = set()
    for jv in doc.joints:
        parent, child = jv.parent, jv.child
        if parent is None or child is None:
            continue
        below.setdefault(parent.get("link", ""), []).append(
            (child.get("link", ""), jv.type == "fixed"))
        children.add(child.get("link", ""))
    names = [view.name if view.name is not None else "" for view in doc.links]
    if not below:  # no joint: only the first link stays with the root
        return set(names) - set(names[:1])
    roots = [n for n in names if n not in children]
    still, stack = set(), roots[:1]
    while stack:
        n = stack.pop()
        if n not in still:
            still.add(n)
            stack.extend(c for c, fixed in below.get(n, ()) if fixed)
    return set(names) - still


def rule_mimic(root: etree._Element, r: RuleReport) -> None:
    """U310: every ``<mimic>`` PyBullet ignores (its leader exists; U307 and U309 judge that).

    PyBullet 3.2.7 reads no ``<mimic>``: the follower is an ordinary joint that moves on its
    own, so a two-finger gripper whose second finger mimics the first opens one finger.
    """
    joints = {jv.name for jv in r.doc(root).joints}
    for jv in r.doc(root).joints:
        mimic = jv.mimic
        leader = mimic.get("joint") if mimic is not None else None
        if leader is None or leader not in joints or leader == jv.name:
            continue
        multiplier = _num(mimic, "multiplier", 1.0)
        offset = _num(mimic, "offset", 0.0)
        if multiplier is None or offset is None:
            continue  # U401 says why
        r.add("U310", "info", f"{label(jv.el)} mimics joint {leader!r} (position = "
              f"{leader} x {multiplier:g} + {offset:g}), and PyBullet ignores <mimic>: it moves "
              "on its own, free unless driven; drive it to that position each step"
              + (", or tie it with p.createConstraint(body, leader link, body, its link, "
                 f"p.JOINT_GEAR, ...) and gearRatio {-1 / multiplier:g} (measured: PyBullet's "
                 "gear holds leader + gearRatio x follower at 0; it keeps velocities, not the "
                 "offset)" if multiplier else ""), mimic)


#: PyBullet's default physics step (``setTimeStep``), which ``sim`` and ``drive`` keep.
DEFAULT_TIME_STEP = 1.0 / 240.0


def rule_damping(root: etree._Element, r: RuleReport) -> None:
    """U311: joint damping so large for what the joint moves that PyBullet's step is unstable.

    PyBullet applies ``<dynamics damping>`` explicitly: each step multiplies the joint speed by
    about ``1 - dt x damping / inertia``, which past 2 flips its sign and grows it to
    PyBullet's 100 rad/s joint-speed cap (measured: the Shadow hand, shadow-robot/sr_common,
    0.1 N m s/rad on ~5e-6 kg m^2 fingers, chatters at +-100 rad/s from the third step). The
    inertia is the joint-space one at the zero pose, ``M_ii``: everything below the joint about
    its axis (a prismatic joint: the mass below it), the file's inertia, 1 kg and unit inertia
    for a link without ``<inertial>``. The largest eigenvalue of ``M^-1 B`` is at least
    ``b_i / M_ii``, so a finding here is unstable for certain; joints coupled through the
    off-diagonal inertia can be unstable without one.
    """
    doc = r.doc(root)
    damped = []
    for jv in doc.joints:
        if jv.type not in ("revolute", "continuous", "prismatic"):
            continue
        dyn = first(jv.el, "dynamics")
        b = _num(dyn, "damping") if dyn is not None else None
        if b is not None and b > 0:
            damped.append((jv, b, dyn))
    if not damped:
        return
    links = {lv.name: lv for lv in doc.links if lv.name is not None}
    below: dict[str, list[Any]] = {}
    for jv in doc.joints:
        parent = jv.parent.get("link") if jv.parent is not None else None
        if parent is not None and jv.child is not None:
            below.setdefault(parent, []).append(jv)
    found: set[str] = set()
    for jv, b, dyn in damped:
        # Past dt x b / 2 the joint is stable: the sum may stop there.
        inertia = _joint_inertia(jv, links, below, DEFAULT_TIME_STEP * b / 2)
        if inertia is None or inertia <= 0:
            continue
        rate = DEFAULT_TIME_STEP * b / inertia
        if rate <= 2.0:
            continue
        found.add(jv.name or "")
        prismatic = jv.type == "prismatic"
        unit, what = ("N s/m", "kg") if prismatic else ("N m s/rad", "kg m^2")
        r.add("U311", "warning",
              f"{label(jv.el)} has damping {b:g} {unit} against the {inertia:.3g} {what} it "
              f"moves (at the zero pose, with the file's inertia): PyBullet applies joint "
              f"damping explicitly, so each step of its default 1/240 s multiplies the joint's "
              f"speed by 1 - {rate:.3g}, flipping its sign and growing it to PyBullet's "
              f"100 {'m/s' if prismatic else 'rad/s'} cap: the joint chatters instead of "
              f"settling; lower the damping under {2 * inertia / DEFAULT_TIME_STEP:.3g} or "
              f"step under {2 * inertia / b:.3g} s", dyn)
    _coupled_damping(doc, links, below, damped, found, r)


def _coupled_damping(doc: Doc, links: dict[str, LinkView], below: dict[str, list[Any]],
                     damped: list[tuple[Any, float, etree._Element]], found: set[str],
                     r: RuleReport) -> None:
    """U311 for damped joints unstable together though each alone is not.

    Toyota HSR's hand (hsr_description): ``hand_r_spring_proximal_joint`` and
    ``hand_r_mimic_distal_joint``, 1 N m s/rad each, move 0.033 and 0.030 kg m^2 alone (dt b /
    M_ii 0.13), but turned against each other the distal link keeps still and only the small
    link between moves: the largest eigenvalue of dt M^-1 B is 5.46, and raw PyBullet's speeds
    along that motion flip sign and grow 4.5x a step. Judged on the joint-space mass matrix of
    the whole tree at the zero pose, base fixed (a floating base only raises the eigenvalue).
    """
    got = _mass_matrix(doc, links, below)
    if got is None:
        return
    names, m = got
    index = {n: i for i, n in enumerate(names)}
    # Only the joints stable alone: the motions among them (the principal submatrix of
    # dt B^1/2 M^-1 B^1/2 over them, whose largest eigenvalue is at most the whole one's, so
    # each motion found is unstable in the whole too). A joint found alone is said already,
    # and over the rest the cheap bound below usually ends it (kuka_iiwa: no numpy).
    rows = [(index[jv.name], jv, b, dyn) for jv, b, dyn in damped
            if jv.name in index and jv.name not in found]
    low = _cholesky(m)
    if not rows or low is None:
        return
    # A = dt B^1/2 M^-1 B^1/2 over the damped joints: C = L^-1 B^1/2 e_k, A = dt C^T C
    cols = [_forward_solve(low, [math.sqrt(b) if i == k else 0.0 for i in range(len(names))])
            for k, _, b, _ in rows]
    a = [[DEFAULT_TIME_STEP * sum(x * y for x, y in zip(ci, cj, strict=True)) for cj in cols]
         for ci in cols]
    if max(sum(abs(x) for x in row) for row in a) <= 2.0:
        return  # Gershgorin: no eigenvalue past 2 (most files end here, without numpy)
    import numpy as np

    sym = np.array(a)
    root_b = np.sqrt(np.array([b for _, _, b, _ in rows]))
    values, vectors = np.linalg.eigh((sym + sym.T) / 2)
    said = set(found)
    for e in range(len(values) - 1, -1, -1):
        rate = float(values[e])
        if not rate > 2.0 or not math.isfinite(rate):
            break
        mode = vectors[:, e] / root_b  # the joint speeds of that motion
        mode = mode / np.abs(mode).max()
        part = [k for k in np.argsort(-np.abs(mode)) if abs(mode[k]) >= 0.2]
        if any(rows[k][1].name in said for k in part):
            continue  # said already, joint by joint or as a stiffer motion
        said.update(rows[k][1].name for k in part)
        lead = rows[part[0]]
        others = ", ".join(rows[k][1].name for k in part[1:4])
        motion = ", ".join(f"{rows[k][1].name} x {mode[k]:+.2f}" for k in part[:4])
        r.add("U311", "warning",
              f"{label(lead[1].el)}, moving with {others or 'no other damped joint'} "
              f"({motion}), is damped too hard for PyBullet's step, though each joint alone is "
              f"not: so moving they carry little inertia (at the zero pose, base fixed, the "
              f"file's inertia), and the largest eigenvalue of dt M^-1 B at its default "
              f"1/240 s is {rate:.3g}, past 2: each step multiplies that motion's speed by "
              f"1 - {rate:.3g}, flipping its sign and growing it to PyBullet's joint-speed "
              f"cap; scale those joints' damping under {2 / rate:.3g} of what it is or step "
              f"under {2 * DEFAULT_TIME_STEP / rate:.3g} s", lead[3])


Chain = list[tuple[int, tuple[float, ...], tuple[float, ...], bool]]


def _zero_pose_tree(doc: Doc, links: dict[str, LinkView], below: dict[str, list[Any]]
                    ) -> tuple[list[str], list[str], dict[str, Any], dict[str, Chain]] | None:
    """The tree at the zero pose, or None when it does not read.

    Returns the moving joints' names, the links root first, each link's frame (rotation,
    origin) and the moving joints above it (index, axis, a point on it, prismatic). It does not
    read with not one root, a loop, a missing link or a bad number.
    """
    children = {jv.child.get("link") for jv in doc.joints if jv.child is not None}
    roots = [n for n in links if n not in children]
    if len(roots) != 1:
        return None
    frame: dict[str, Any] = {roots[0]: (_IDENTITY, (0.0, 0.0, 0.0))}
    chain: dict[str, Chain] = {roots[0]: []}
    names: list[str] = []
    order: list[str] = []
    stack = [roots[0]]
    while stack:
        name = stack.pop()
        order.append(name)
        rot, pos = frame[name]
        for jv in below.get(name, ()):
            child = jv.child.get("link") if jv.child is not None else None
            placed = _child_frame(jv, rot, pos)
            if child is None or child in frame or child not in links or placed is None:
                return None
            crot, cpos = frame[child] = placed
            chain[child] = list(chain[name])
            if jv.type in ("revolute", "continuous", "prismatic"):
                axis = _unit_axis(jv)
                if axis is None or jv.name is None:
                    return None
                world = rotate(crot, axis)
                chain[child].append((len(names), world, cpos, jv.type == "prismatic"))
                names.append(jv.name)
            stack.append(child)
    return names, order, frame, chain


def _mass_matrix(doc: Doc, links: dict[str, LinkView], below: dict[str, list[Any]]
                 ) -> tuple[list[str], list[list[float]]] | None:
    """The joint-space mass matrix at the zero pose, base fixed, as PyBullet loads the file.

    With the file's inertia (1 kg and unit inertia for a link without ``<inertial>``),
    ``M_ij`` sums, over the links below both joints, ``m J_v,i . J_v,j + J_w,i^T I J_w,j``
    (each link's Jacobian columns at its centre of mass). Plain Python: the tree's depth, not
    its size, sets the cost. None when the tree does not read, has no moving joint, or is too
    big to be worth it.
    """
    tree = _zero_pose_tree(doc, links, below)
    if tree is None:
        return None
    names, order, frame, chain = tree
    n = len(names)
    if n == 0 or n > 200:
        return None
    m = [[0.0] * n for _ in range(n)]
    for name in order:
        above = chain[name]
        if not above:
            continue
        body = _link_inertia(links[name], *frame[name])
        if body is None:
            return None
        mass, com, turn, t = body
        # in the world frame (the unit inertia of a link without <inertial> is so everywhere)
        tensor = t if t is _IDENTITY else matmul(matmul(turn, t), transpose(turn))
        cols: list[tuple[int, tuple[float, ...], tuple[float, ...], tuple[float, ...]]] = []
        for i, a, at, prismatic in above:
            if prismatic:
                cols.append((i, a, (0.0, 0.0, 0.0), (0.0, 0.0, 0.0)))
                continue
            r_ = tuple(c - q for c, q in zip(com, at, strict=True))
            lin = (a[1] * r_[2] - a[2] * r_[1], a[2] * r_[0] - a[0] * r_[2],
                   a[0] * r_[1] - a[1] * r_[0])
            cols.append((i, lin, a, rotate(tensor, a)))
        for i, lin_i, _, iw_i in cols:
            row = m[i]
            for j, lin_j, w_j, _ in cols:  # the dot products written out: the rule's hot loop
                row[j] += mass * (lin_i[0] * lin_j[0] + lin_i[1] * lin_j[1]
                                  + lin_i[2] * lin_j[2]) \
                    + (iw_i[0] * w_j[0] + iw_i[1] * w_j[1] + iw_i[2] * w_j[2])
    return names, m


def _cholesky(m: list[list[float]]) -> list[list[float]] | None:
    """Lower-triangular L with L L^T = m, or None when m is not positive definite."""
    n = len(m)
    low = [[0.0] * n for _ in range(n)]
    for i in range(n):
        for j in range(i + 1):
            acc = m[i][j] - sum(low[i][k] * low[j][k] for k in range(j))
            if i == j:
                if not acc > 0.0:
                    return None
                low[i][i] = math.sqrt(acc)
            else:
                low[i][j] = acc / low[j][j]
    return low


def _forward_solve(low: list[list[float]], b: list[float]) -> list[float]:
    """The x with L x = b, L lower-triangular."""
    x: list[float] = []
    for i, row in enumerate(low):
        x.append((b[i] - sum(row[k] * x[k] for k in range(i))) / row[i])
    return x


_ZERO_TENSOR: Matrix3 = ((0.0, 0.0, 0.0), (0.0, 0.0, 0.0), (0.0, 0.0, 0.0))


def _loaded_tensor(inertia: etree._Element | None) -> Matrix3 | None:
    """The ``<inertia>`` tensor as PyBullet loads it with the file's inertia, or None.

    Zero where no rigid body has it (a negative principal moment, or one over the other
    two): PyBullet's importer says "Bad inertia tensor properties" and zeroes it (the Allegro
    hand's fingers in example-robot-data).
    """
    tensor = _inertia_tensor(inertia) if inertia is not None else None
    if tensor is None or inertia is None:
        return None
    principal = _principal(inertia)
    if principal is not None and (principal[2] < 0 or principal[4] > principal[2] + principal[3]):
        return _ZERO_TENSOR
    return cast(Matrix3, tensor)


_IDENTITY: Matrix3 = ((1.0, 0.0, 0.0), (0.0, 1.0, 0.0), (0.0, 0.0, 1.0))


def _link_inertia(lv: LinkView, rot: Matrix3, pos: tuple[float, ...]
                  ) -> tuple[float, tuple[float, ...], Matrix3, Matrix3] | None:
    """(mass, centre of mass, the inertia's frame, its tensor there) of a link at (rot, pos).

    As PyBullet loads the file with its inertia: without ``<inertial>`` 1 kg (0 for
    ``world``) and :data:`_IDENTITY` at the link's frame. None where a number does not read.
    """
    mass = _mass_of(lv)
    if mass is None:
        return None
    if lv.inertial is None:
        return mass, pos, rot, _IDENTITY
    origin = first(lv.inertial, "origin")
    xyz = _vec(origin, "xyz", 3, (0.0, 0.0, 0.0))
    rpy = _vec(origin, "rpy", 3, (0.0, 0.0, 0.0))
    tensor = _loaded_tensor(lv.inertia)
    if xyz is None or rpy is None or tensor is None:
        return None
    return (mass, tuple(p + o for p, o in zip(pos, rotate(rot, xyz), strict=True)),
            matmul(rot, rpy_to_matrix(rpy)), tensor)


def _child_frame(jv: Any, rot: Matrix3, pos: tuple[float, ...]
                 ) -> tuple[Matrix3, tuple[float, ...]] | None:
    """The frame of joint ``jv``'s child link at q = 0, its parent's being (rot, pos)."""
    xyz = _vec(jv.origin, "xyz", 3, (0.0, 0.0, 0.0))
    rpy = _vec(jv.origin, "rpy", 3, (0.0, 0.0, 0.0))
    if xyz is None or rpy is None:
        return None
    return (matmul(rot, rpy_to_matrix(rpy)),
            tuple(p + o for p, o in zip(pos, rotate(rot, xyz), strict=True)))


def _unit_axis(jv: Any) -> tuple[float, ...] | None:
    """Joint ``jv``'s axis as a unit vector (x when absent); None when unreadable or zero."""
    axis = _vec(jv.axis, "xyz", 3, (1.0, 0.0, 0.0))  # None only when unreadable (U401)
    if axis is None:
        return None
    norm = math.sqrt(sum(x * x for x in axis))
    return None if norm == 0 else tuple(x / norm for x in axis)


def _joint_inertia(jv: JointView, links: dict[str, LinkView], below: dict[str, list[Any]],
                   enough: float = math.inf) -> float | None:
    """``M_ii`` of joint ``jv`` at the zero pose, as PyBullet loads the file with its inertia.

    None when a link below is missing or has no readable mass or inertia, or the tree loops.
    The sum stops once it passes ``enough`` while no link's term was negative (only an
    invalid tensor gives one): the caller only asks whether it stays under.
    """
    a = _unit_axis(jv)
    if a is None:
        return None
    prismatic = jv.type == "prismatic"
    # frames relative to the joint's own (its child link's frame at q = 0)
    todo: list[tuple[str | None, Matrix3, tuple[float, ...]]] = [
        (jv.child.get("link") if jv.child is not None else None, _IDENTITY, (0.0, 0.0, 0.0))]
    seen: set[str] = set()
    total = 0.0
    while todo:
        name, rot, pos = todo.pop()
        if name is None or name in seen or name not in links:
            return None
        seen.add(name)
        body = _link_inertia(links[name], rot, pos)
        if body is None:
            return None
        mass, com, frame, tensor = body
        if prismatic:
            term = mass
        else:
            local = rotate(transpose(frame), a)  # the axis in the inertia's frame
            along = sum(c * x for c, x in zip(com, a, strict=True))
            term = sum(local[i] * tensor[i][j] * local[j] for i in range(3) for j in range(3)) \
                + mass * (sum(c * c for c in com) - along * along)
        total += term
        if term < 0:
            enough = math.inf
        elif total > enough:
            return total
        for child in below.get(name, ()):
            placed = _child_frame(child, rot, pos)
            if placed is None:
                return None
            todo.append((child.child.get("link") if child.child is not None else None,
                         *placed))
    return total


def rule_gazebo_contacts(root: etree._Element, r: RuleReport) -> None:
    """U803: Gazebo contact parameters (mu1, mu2, kp, kd) PyBullet ignores, per link.

    Read by :func:`urdfkit.model.gazebo.gazebo_contacts`; judged against what PyBullet loads
    for the link (its ``<contact>``, else lateral friction 0.5 and a rigid contact). A link
    whose ``<contact>`` already carries the values gets nothing.
    """
    if not r.doc(root).gazebo:
        return  # most files: nothing to read, and no Gazebo reader to load
    from urdfkit.model.gazebo import NOT_CARRIED, PYBULLET_LATERAL_FRICTION, gazebo_contacts

    contacts = gazebo_contacts(root)
    if not contacts:
        return
    # A link without <collision> touches nothing: its contact parameters do nothing in either
    # engine (Unitree's imu_link carries mu1 0.2 from a macro that gives every link one).
    links = {v.name: v.el for v in r.doc(root).links if v.name and v.collisions}
    for name, gz in contacts.items():
        link = links.get(name)
        if link is None:
            continue  # a joint, a missing link, or one without shapes: nothing to carry
        have = _contact_values(link)
        want = gz.pybullet()
        differ = {k: v for k, v in want.items()
                  if not math.isclose(have.get(k, math.nan), v, rel_tol=1e-9)}
        given = ", ".join(f"{k} {v:g}" for k, v in gz.given().items())
        refused = "; ".join(f"{k} {gz.given()[k]:g} is {why}" for k, why in gz.refused.items())
        if not differ:
            if refused:
                r.add("U803", "warning", f"<gazebo reference={name!r}> gives {label(link)} "
                      f"{given}, which PyBullet ignores, and `urdfkit fix --gazebo-contacts` "
                      f"does not carry: {refused}", gz.element)
            continue
        parts = []
        if "lateral_friction" in differ:
            now = have.get("lateral_friction", PYBULLET_LATERAL_FRICTION)
            parts.append(f"lateral friction {now:g} where Gazebo's is "
                         f"{differ['lateral_friction']:g}")
        if "stiffness" in differ:
            parts.append("a rigid contact where Gazebo's is a spring of "
                         f"{differ['stiffness']:g} N/m and {differ['damping']:g} N s/m"
                         if "stiffness" not in have else
                         f"contact stiffness {have['stiffness']:g} and damping "
                         f"{have.get('damping', math.nan):g} where Gazebo's are "
                         f"{differ['stiffness']:g} and {differ['damping']:g}")
        notes = []
        if gz.grip_only_one_way:
            notes.append(f"mu1 and mu2 differ and one is 0 (grip one way, none across): "
                         f"PyBullet has one coefficient in every direction, and 0 would leave "
                         f"the link no grip at all, so fix writes the larger, "
                         f"{gz.lateral_friction:g}, which grips across too")
        elif gz.mu1 is not None and gz.mu2 is not None and gz.mu1 != gz.mu2:
            notes.append(f"mu1 and mu2 differ: PyBullet has one coefficient in every direction, "
                         f"and fix writes the smaller, {gz.lateral_friction:g}")
        if (gz.kp is None) != (gz.kd is None):
            notes.append(f"{'kp' if gz.kd is None else 'kd'} is not given, so stiffness and "
                         "damping (a pair in PyBullet) are not carried")
        if gz.not_carried:
            notes.append("not carried: " + "; ".join(f"{k} ({NOT_CARRIED[k]})"
                                                     for k in gz.not_carried))
        if refused:
            notes.append(f"not carried: {refused}")
        written = ", ".join(f"{k} {v:g}" for k, v in differ.items())
        r.add("U803", "warning", f"<gazebo reference={name!r}> gives {label(link)} {given}, "
              f"which PyBullet ignores: it loads {' and '.join(parts)}; `urdfkit fix "
              f"--gazebo-contacts` writes the link a <contact> with {written} (PyBullet "
              "multiplies the two bodies' friction: on a ground of lateral friction 1, such "
              "as plane.urdf, the contact has the link's)" + "".join(f"; {n}" for n in notes),
              gz.element)


def rule_contact_values(root: etree._Element, r: RuleReport) -> None:
    """U804: ``<contact>`` values that are no contact (:func:`urdfkit.model.gazebo.unusable`).

    A stiffness of 0, negative or subnormal (PyBullet loads 2.2e-16 N/m and the link sinks
    through the ground), negative damping or friction.
    """
    from urdfkit.model.gazebo import unusable

    for view in r.doc(root).links:
        contact = first(view.el, "contact")
        if contact is None:
            continue
        for child in contact:
            if not isinstance(child.tag, str):
                continue
            value = _num(child, "value")
            why = unusable(child.tag, value) if value is not None else None
            if why is not None:
                r.add("U804", "warning", f"<contact><{child.tag} value={child.get('value')!r}> "
                      f"of {label(view.el)}: {why}", child)


def _contact_values(link: etree._Element) -> dict[str, float]:
    """The link's ``<contact>`` values PyBullet reads: {lateral_friction, stiffness, ...}."""
    contact = first(link, "contact")
    out: dict[str, float] = {}
    if contact is None:
        return out
    for child in contact:
        value = _num(child, "value") if isinstance(child.tag, str) else None
        if value is not None and child.tag not in out:
            out[child.tag] = value
    return out


def rule_portability(root: etree._Element, r: RuleReport) -> None:
    """U901: PyBullet-only joint types and shapes, which other URDF tools refuse (info)."""
    doc = r.doc(root)
    for jv in doc.joints:
        note = extension_note("joint", jv.type if jv.type is not None else "")
        if note:
            r.add("U901", "info", f"{label(jv.el)}: {note}", jv.el)
    for geom in doc.geometries:
        for shape in geom:
            note = _SHAPE_NOTES.get(shape.tag)  # a comment's tag is a function: no note
            if note:
                r.add("U901", "info", note, shape)


#: extension_note("shape", tag) by tag, one lookup a shape.
_SHAPE_NOTES = {key.partition(":")[2]: note for key, note in EXTENSIONS.items()
                if key.startswith("shape:")}


#: Every rule ``urdfkit check`` runs, in order.
ALL_RULES: tuple[Rule, ...] = (*GUARD_RULES, rule_link_count, rule_elements, rule_mass,
                               rule_inertia, rule_meshes, rule_mesh_crashes, rule_mesh_shapes,
                               rule_visual_meshes, rule_references, rule_material_colours,
                               rule_mimic, rule_damping, rule_gazebo_contacts, rule_contact_values,
                               rule_portability)

#: Every finding code with a one-line summary (for ``--select``/``--ignore`` and the docs).
CODES: dict[str, str] = {
    "U000": "file unreadable or not well-formed XML",
    "U004": "XML quirk PyBullet tolerates but other parsers refuse",
    "U005": "elements nested deeper than PyBullet's XML parser reads (98 levels)",
    "U006": "xacro not expanded: executing it is disabled (--no-exec, URDFKIT_NO_EXEC)",
    "U007": "xacro macro library (no links of its own): checked through its includers",
    "U008": "line longer than 8191 bytes: PyBullet breaks it and may misread the file",
    "U009": "a file not named .xacro that holds xacro: read literally ('${prefix}base')",
    "U010": "a fragment another checked file includes (no robot alone): checked through it",
    "U001": "root element is not <robot>",
    "U002": "<robot> has no name",
    "U003": "no <link>",
    "U101": "link, joint or material without a name",
    "U102": "duplicate link name",
    "U103": "duplicate joint name",
    "U104": "'%' in a link name (crashes PyBullet)",
    "U105": "duplicate material name",
    "U106": "name near PyBullet's crash length (joint 1200, link 2200, robot 1024 bytes)",
    "U107": "'%' in a joint, material or robot name (refused; --no-guard lifts it)",
    "U108": "name over 1000 bytes (refused; --no-guard lifts it)",
    "U109": "top-level <material> without a name (PyBullet skips it; warning)",
    "U110": "<material> of a <visual> without a name attribute (PyBullet refuses the file)",
    "U201": "joint without <parent> or <child>",
    "U202": "joint refers to a missing link",
    "U203": "joint joins a link to itself",
    "U204": "link with two parents",
    "U205": "more than one root link",
    "U206": "no root link (cycle)",
    "U207": "kinematic cycle",
    "U208": "128 links or more",
    "U209": "more than 1000 links (refused before loading)",
    "U301": "unknown joint type",
    "U302": "revolute/prismatic joint without <limit>",
    "U303": "<limit> without effort or velocity",
    "U304": "limit lower > upper",
    "U305": "zero joint axis",
    "U306": "joint axis not unit length",
    "U307": "mimic refers to a missing joint",
    "U309": "mimic joints follow each other in a ring",
    "U310": "<mimic> that PyBullet ignores (the joint moves on its own; info)",
    "U311": "joint damping too large for what the joint moves: PyBullet's 1/240 s step is unstable",
    "U308": "revolute/prismatic <limit> without lower or upper (PyBullet: unlimited)",
    "U401": "number does not parse or is not finite",
    "U402": "vector of the wrong length",
    "U501": "missing or non-positive shape size",
    "U502": "<geometry> without a shape",
    "U503": "mesh without filename",
    "U504": "<origin> inside <geometry> (ignored by PyBullet)",
    "U505": "<geometry> whose first element is not the shape",
    "U506": "<visual> or <collision> without <geometry>",
    "U507": "<geometry> with more than one shape (PyBullet uses the first)",
    "U601": "negative or missing mass",
    "U602": "moving link with mass 0",
    "U603": "inertia not positive definite",
    "U604": "inertia violates the triangle inequality",
    "U605": "inertia far from what shapes and mass imply",
    "U606": "link without <inertial>",
    "U607": "file inertia ignored without URDF_USE_INERTIA_FROM_FILE",
    "U608": "singular inertia (a zero principal moment) with positive mass",
    "U609": "<inertial> without <inertia>",
    "U610": "<inertia> missing a component",
    "U611": "mass-0 root link: PyBullet makes the base static",
    "U612": "collision mesh not closed: no volume, inertia cannot be derived",
    "U613": "mesh in the wrong units (200x larger or smaller than the joint spacing)",
    "U614": "concave collision mesh on a moving link (PyBullet collides with its hull)",
    "U701": "mesh or texture file not found",
    "U702": "package:// package not found, or a path climbing out of its package",
    "U703": "mesh found only through pybullet_data's search path",
    "U704": "mesh or texture is a directory, FIFO, device or unreadable",
    "U705": "mesh in a format PyBullet does not read (it reads .stl, .obj, .dae)",
    "U706": "material used but never defined",
    "U707": "<texture> without a filename",
    "U708": "package:/// without a package name",
    "U709": "transmission names a missing joint",
    "U710": "one material name given several colours (PyBullet draws them all in the last)",
    "U711": "package:// found only through a package.xml, which raw PyBullet does not read",
    "U712": "COLLADA mesh PyBullet's reader crashes on (no <asset> or <library_geometries>, ...)",
    "U713": "collision mesh with NaN beside numbers on an axis: PyBullet's hull crashes or hangs",
    "U715": "visual mesh PyBullet draws nothing or only part of (empty, COLLADA <instance_node>)",
    "U801": "unknown tag",
    "U802": "unknown attribute",
    "U803": "Gazebo contact parameters (mu1, mu2, kp, kd) PyBullet ignores (fix --gazebo-contacts)",
    "U804": "<contact> that is no contact: stiffness not positive (the link sinks), negative "
            "damping or friction",
    "U901": "PyBullet extension (spherical joint, capsule, plane, cdf): not portable",
    "U950": "links in contact at the zero pose (check --physics: self-collision jitters)",
    "U951": "PyBullet cannot load the file (check --physics)",
}


