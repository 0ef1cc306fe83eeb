"""check's rules on mass and inertia (U601-U611).

Each link's mass, its tensor, and the collision solid PyBullet would derive them from
(:func:`link_solid`, which ``fix`` writes).
"""

from __future__ import annotations

import math
import os
import sys
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any, cast

from lxml import etree

from urdfkit.model.index import Doc, LinkView, collision_parts
from urdfkit.model.massprops import combine
from urdfkit.model.spec import (
    SHAPES,
    SOLIDS,
    WORLD_LINK,
    Matrix3,
    atof,
    default_mass,
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
from urdfkit.sources.guard import RuleReport
from urdfkit.sources.meshstore import MeshProperties
from urdfkit.sources.meshstore import properties as mesh_properties
from urdfkit.sources.meshstore import stated as stated_properties
from urdfkit.sources.references import label

#: Drake's tolerance unit for inertia checks (DBL_EPSILON).
_DBL_EPSILON = sys.float_info.epsilon


def mass_of(link: LinkView) -> float | None:
    """The mass PyBullet gives a link: its <mass>, or without <inertial> 1 kg (0 for world)."""
    if link.inertial is None:
        return default_mass(link.name)
    return _num(link.mass, "value")


def _loaded_mass(link: LinkView) -> float | None:
    """:func:`mass_of`, with a malformed number read as PyBullet reads it (C's atof).

    ``"abc"`` is 0 kg to PyBullet, ``"nan"`` NaN: only a mass it reads as 0 makes U602 and
    U611 true (U401 says the number is malformed).
    """
    mass = mass_of(link)
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


def inertia_tensor(inertia: etree._Element) -> tuple[tuple[float, ...], ...] | None:
    """An ``<inertia>`` element's tensor as written, or None if a component does not read."""
    vals = [_num(inertia, a) for a in ("ixx", "ixy", "ixz", "iyy", "iyz", "izz")]
    if any(v is None for v in vals):
        return None
    ixx, ixy, ixz, iyy, iyz, izz = vals
    return ((ixx, ixy, ixz), (ixy, iyy, iyz), (ixz, iyz, izz))  # type: ignore[return-value]


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
        principal = principal_moments(inertia, doc.inertia_keys.get(inertia))
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


def principal_moments(inertia: etree._Element, key: tuple[Any, ...] | None = None
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
        tensor = inertia_tensor(inertia)
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
                moving = moving_of(r, link)
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
    if not parts:
        return None
    joined = combine([(volume, centre, tensor) for volume, centre, tensor, _ in parts])
    if not 0 < joined.mass < math.inf:
        return None
    if not all(map(math.isfinite, (*joined.tensor[0], *joined.tensor[1], *joined.tensor[2]))):
        return None
    return (joined.mass, joined.com, joined.tensor,
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
    props = mesh_properties_of(r, ref.load, scale, concavity, ref.stat)
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


def mesh_properties_of(r: RuleReport, path: str, scale: Sequence[float], concavity: bool = False,
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


def moving_links(doc: Doc) -> set[str]:
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


def moving_of(r: RuleReport, el: etree._Element) -> set[str]:
    """:func:`moving_links` of the document ``el`` belongs to, once per file."""
    moving: set[str] | None = r.memo.get("moving links")
    if moving is None:
        moving = r.memo["moving links"] = moving_links(r.doc(el.getroottree().getroot()))
    return moving
