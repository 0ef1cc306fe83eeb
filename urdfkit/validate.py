"""Validation of URDF documents: the rules, and the guard every loader calls.

Rules work on the lxml tree (not on a parsed model) so that every finding can carry the line
it comes from, and so that broken files are described rather than refused at the first error.

:func:`guard` runs the rules that stand between a file and a PyBullet segfault (two roots, a
child with two parents, cycles, duplicate names, ``%`` in names, ...) and raises the first
error as an :class:`~urdfkit.errors.InputError`. Every command that loads a file calls it.
"""

from __future__ import annotations

import math
import re
import sys
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path

from lxml import etree

from .errors import InputError
from .finding import LEVELS, Finding  # noqa: F401 - re-exported: rules and callers use both
from .spec import (
    CRASH_NAME_BYTES,
    CRASH_PERCENT_TAGS,
    FILE_TAGS,
    JOINT_TYPES,
    LIMITED_JOINT_TYPES,
    MAX_LOADABLE_LINKS,
    MAX_NAME_BYTES,
    MAX_STATE_LINKS,
    MAX_XML_DEPTH,
    MESH_FORMATS,
    NUMERIC,
    OPAQUE,
    SCHEMA,
    SHAPE_SIZES,
    SHAPES,
    SOLIDS,
    Matrix3,
    extension_note,
    ignored_shape,
    matmul,
    numbers,
    rotate,
    rpy_to_matrix,
    solid_inertia,
    solid_volume,
    sym_eigenvalues,
    transpose,
    used_shape,
)
from .spec import attr_float as _num
from .spec import attr_vec as _vec
from .uris import not_a_file, pybullet_data_path, resolve_uri
from .xmlio import children, line_of


class Report:
    """Collects findings for one file.

    Attributes:
        file: The file, as the user named it.
        base: The folder relative mesh paths start from; None skips the file-system rules.
        packages: ``--package NAME=PATH`` mappings for ``package://`` URIs.
    """

    def __init__(self, file: str, base: Path | None = None,
                 packages: Mapping[str, Path] | None = None,
                 origins: Mapping[etree._Element, str] | None = None):
        self.file = file
        self.base = base
        self.packages = dict(packages or {})
        self.origins = origins
        self.findings: list[Finding] = []
        #: The element each finding is about, in step with :attr:`findings` (``urdfkit fix``
        #: repairs elements, and lines cannot tell apart two elements on one line).
        self.elements: list[etree._Element | None] = []
        self._references: dict[tuple[str, str], Reference] = {}

    def reference(self, tag: str, fn: str) -> Reference:
        """:func:`reference` from this file's folder, judged once per file (several rules ask)."""
        assert self.base is not None
        key = (tag, fn)
        ref = self._references.get(key)
        if ref is None:
            ref = self._references[key] = reference(tag, fn, self.base, self.packages)
        return ref

    def add(self, code: str, level: str, message: str, el: etree._Element | None = None,
            line: int | None = None) -> None:
        """Record a finding; its line comes from ``el`` unless given."""
        if line is None and el is not None:
            line = line_of(el)
        origin = self.origins.get(el) if self.origins is not None and el is not None else None
        self.findings.append(Finding(code, level, message, self.file, line, origin))
        self.elements.append(el)

    @property
    def errors(self) -> list[Finding]:
        """The error-level findings."""
        return [f for f in self.findings if f.level == "error"]


Rule = Callable[[etree._Element, Report], None]


_elements = children


def _label(el: etree._Element) -> str:
    name = el.get("name")
    if name is None:
        return f"<{el.tag}>"
    if len(name) > 60:  # a 3,000-character name would drown the message
        return f"<{el.tag} name={name[:40]!r}... ({len(name)} characters)>"
    return f"<{el.tag} name={name!r}>"


#: Lifted by ``guard=False`` (``--no-guard``): refusals where the guard is stricter than
#: PyBullet 3.2.7, which loads such files. Everything else the guard refuses crashes PyBullet
#: or is not URDF at all, and stays refused.
LIFTABLE_CODES = frozenset({"U107", "U108"})
STRICTER = " (PyBullet 3.2.7 loads this, but the guard refuses it; `guard=False` lifts it)"


# --------------------------------------------------------------------------- structural rules
# These are the rules PyBullet crashes on when they are broken; the guard runs exactly these.


#: An XPath that finds the elements one level below what PyBullet's XML parser reads: a path
#: step per level, evaluated in C, pruned at every leaf (linear, and ~free on real files).
_TOO_DEEP = etree.XPath("/*" * (MAX_XML_DEPTH + 1))


def _too_deep(root: etree._Element) -> etree._Element | None:
    """The first element nested deeper than PyBullet reads, or None."""
    found = _TOO_DEEP(root)
    return found[0] if isinstance(found, list) and found else None


def rule_document(root: etree._Element, r: Report) -> None:
    """U001-U003: root is <robot>, has a name, and has links."""
    if root.tag != "robot":
        r.add("U001", "error", f"root element is <{root.tag}>, expected <robot>", root)
        return
    if not root.get("name"):
        r.add("U002", "error", "<robot> has no name attribute; add name=\"...\"", root)
    deep = _too_deep(root)
    if deep is not None:
        r.add("U005", "error", f"elements are nested more than {MAX_XML_DEPTH} deep; PyBullet's "
              "XML parser stops there and refuses the file", deep)
    if next(_elements(root, "link"), None) is None:
        soft = next(_elements(root, "deformable"), None) is not None
        r.add("U003", "error", "<robot> has no <link>; a robot needs at least one link" +
              (" (this is a PyBullet soft body, <deformable>: load it with loadSoftBody)"
               if soft else ""), root)


def _check_name(el: etree._Element, r: Report) -> str | None:
    name = el.get("name")
    if name is None or not name.strip():
        r.add("U101", "error", f"<{el.tag}> has no name; give it a unique name=\"...\"", el)
        return None
    _check_percent(el, name, r)
    _check_length(el, name, r)
    return name


def _check_percent(el: etree._Element, name: str, r: Report) -> None:
    if "%" not in name:
        return
    # PyBullet passes some names into printf as the format string: "%s" reads garbage, "%n"
    # writes memory. Measured on 3.2.7: a link name crashes it; joint, material and robot
    # names load, but any diagnostic that quotes them is one format string away from a crash.
    if el.tag in CRASH_PERCENT_TAGS:
        r.add("U104", "error", f"{_label(el)} contains '%', which crashes PyBullet "
              "(it uses names as printf formats); rename it", el)
    else:
        r.add("U107", "error", f"{_label(el)} contains '%', which PyBullet may use as a "
              "printf format; rename it" + STRICTER, el)


def _check_length(el: etree._Element, name: str, r: Report) -> None:
    size = len(name.encode("utf-8", "surrogatepass"))
    if size <= MAX_NAME_BYTES:
        return
    # PyBullet's buffers count UTF-8 bytes, not characters: 700 'é' are 1,400 bytes.
    crash = CRASH_NAME_BYTES.get(el.tag)
    what = f"<{el.tag}> name is {size} bytes long ({len(name)} characters)"
    if crash is not None and size >= crash:
        r.add("U106", "error", f"{what}; PyBullet crashes on {el.tag} names from {crash} bytes: "
              f"keep names under {MAX_NAME_BYTES} bytes", el)
    else:
        r.add("U108", "error", f"{what}; keep names under {MAX_NAME_BYTES} bytes, as PyBullet's "
              "fixed-size buffers are not much larger" + STRICTER, el)


def rule_names(root: etree._Element, r: Report) -> None:
    """U101-U108: links, joints and materials are named, uniquely, without '%', not too long."""
    if root.tag != "robot":
        return
    robot_name = root.get("name")
    if robot_name:  # a missing robot name is U002
        _check_percent(root, robot_name, r)
        _check_length(root, robot_name, r)
    for tag, code in (("link", "U102"), ("joint", "U103")):
        seen: dict[str, etree._Element] = {}
        for el in _elements(root, tag):
            name = _check_name(el, r)
            if name is None:
                continue
            if name in seen:
                r.add(code, "error", f"duplicate {tag} name {name!r} (first on line "
                      f"{line_of(seen[name])}); names must be unique", el)
            else:
                seen[name] = el
    seen_mat: dict[str, etree._Element] = {}
    for el in _elements(root, "material"):
        if el.get("name") is None or not el.get("name", "").strip():
            # PyBullet warns ("Material must contain a name attribute") and loads the file;
            # nothing can refer to a nameless material, so its colour is never drawn.
            r.add("U109", "warning", "<material> at the top level has no name: PyBullet "
                  "skips it with a warning, and no <visual> can use it; give it a name", el)
            continue
        name = _check_name(el, r)
        if name is None:
            continue
        if name in seen_mat:
            r.add("U105", "error", f"duplicate material name {name!r} (first on line "
                  f"{line_of(seen_mat[name])})", el)
        seen_mat[name] = el
    for el in root.iter("material"):
        if el.getparent() is root:
            continue
        visual = el.getparent()
        # Only a link's visual: PyBullet ignores <gazebo> and what is in it (a Gazebo
        # <visual><material><ambient> has no name and loads; found on linorobot2).
        if el.get("name") is None and visual is not None and visual.tag == "visual" and \
                visual.getparent() is not None and visual.getparent().tag == "link":
            # Measured: PyBullet refuses the whole file ("Could not parse visual element");
            # name="" loads.
            r.add("U110", "error", "<material> of a <visual> has no name attribute: PyBullet "
                  "refuses the file (\"Could not parse visual element\"); give it one "
                  "(name=\"\" is enough)", el)
        elif el.get("name") and "%" in el.get("name", ""):
            _check_name(el, r)


def rule_tree(root: etree._Element, r: Report) -> None:
    """U201-U207: joints reference links; exactly one root; single parents; no cycles."""
    if root.tag != "robot":
        return
    links = {el.get("name"): el for el in _elements(root, "link") if el.get("name")}
    parent_of: dict[str, tuple[str, etree._Element]] = {}
    children: dict[str, list[str]] = {}
    for j in _elements(root, "joint"):
        jname = j.get("name", "?")
        ends: dict[str, str | None] = {}
        for role in ("parent", "child"):
            sub = j.find(role)
            if sub is None or not sub.get("link"):
                r.add("U201", "error", f"{_label(j)} has no <{role} link=\"...\">", j)
                ends[role] = None
                continue
            link = sub.get("link")
            if link not in links:
                r.add("U202", "error", f"{_label(j)} {role} link {link!r} does not exist; "
                      "declare it with <link name=...>", sub)
                ends[role] = None
            else:
                ends[role] = link
        parent, child = ends.get("parent"), ends.get("child")
        if parent is None or child is None:
            continue
        if parent == child:
            r.add("U203", "error", f"{_label(j)} joins link {parent!r} to itself; parent and "
                  "child must differ", j)
            continue
        if child in parent_of:
            first, first_el = parent_of[child]
            r.add("U204", "error", f"link {child!r} has two parents: joint {first!r} (line "
                  f"{line_of(first_el)}) and {jname!r}; a link may be the child of one "
                  "joint only", j)
            continue
        parent_of[child] = (jname, j)
        children.setdefault(parent, []).append(child)
    if not links:
        return
    roots = [n for n in links if n not in parent_of]
    if len(roots) > 1:
        r.add("U205", "error", f"{len(roots)} root links ({', '.join(map(repr, roots[:5]))}"
              f"{', ...' if len(roots) > 5 else ''}); connect them with joints so exactly one "
              "link has no parent", links[roots[1]])
    elif not roots:
        r.add("U206", "error", "no root link: every link is some joint's child, so the joints "
              "form a cycle", root)
    # Anything not reachable from a root sits on a cycle.
    reachable: set[str] = set()
    stack = list(roots)
    while stack:
        n = stack.pop()
        if n in reachable:
            continue
        reachable.add(n)
        stack.extend(children.get(n, []))
    cyclic = [n for n in links if n not in reachable]
    if cyclic and roots:
        j = parent_of[cyclic[0]][1]
        r.add("U207", "error", f"kinematic cycle through link(s) "
              f"{', '.join(map(repr, cyclic[:5]))}; joints must form a tree", j)


def rule_link_count(root: etree._Element, r: Report) -> None:
    """U208: 128 links or more break PyBullet's state queries."""
    n = sum(1 for _ in _elements(root, "link"))
    if n >= MAX_STATE_LINKS:
        r.add("U208", "error", f"{n} links: PyBullet's getJointState/getLinkState fail on "
              f"bodies with {MAX_STATE_LINKS} links or more (MAX_DEGREE_OF_FREEDOM); split "
              "the model", root)


# --------------------------------------------------------------------------- values and physics
# Numbers are parsed once per attribute by _num/_vec, which never report: rule_numbers reports
# every malformed number once, and the other rules simply skip what does not parse.

#: Drake's tolerance unit for inertia checks (DBL_EPSILON).
_DBL_EPSILON = sys.float_info.epsilon


def rule_elements(root: etree._Element, r: Report) -> None:
    """U401-U402 and U801-U802, in one pass over the tree.

    Numbers parse, are finite and have the right length; tags and attributes are known
    (typos, or extensions PyBullet ignores). Comments, namespaced elements (xacro leftovers,
    extensions) and opaque subtrees (another tool's: gazebo, transmission, ...) are skipped
    whole. Each parent checks its own children's tags, so no element asks for its parent.
    """
    tag = root.tag
    if isinstance(tag, str) and tag[0] != "{" and tag not in OPAQUE:
        _elements_below(root, tag, r)


def _elements_below(el: etree._Element, tag: str, r: Report) -> None:
    known = SCHEMA.get(tag)
    numeric = _NUMERIC_BY_TAG.get(tag)
    if known is not None or numeric is not None:
        for attr, text in el.items():
            n = numeric.get(attr) if numeric is not None else None
            if n is not None:
                try:
                    vals = [float(x) for x in text.split()]
                except ValueError:
                    vals = None
                if vals is None or not all(map(math.isfinite, vals)):
                    r.add("U401", "error", f"<{tag} {attr}={text!r}>: expected "
                          f"{'a finite number' if n == 1 else f'{n} finite numbers'}", el)
                elif len(vals) != n:
                    r.add("U402", "error", f"<{tag} {attr}={text!r}>: expected {n} numbers, "
                          f"got {len(vals)}", el)
            if known is not None and attr not in known[0] and attr[0] != "{":
                r.add("U802", "warning", f"<{tag}> has unknown attribute {attr!r}; PyBullet "
                      "ignores it", el)
    allowed = known[1] if known is not None else None
    for child in el:
        ctag = child.tag
        if not isinstance(ctag, str) or ctag[0] == "{":
            continue  # comments, processing instructions, namespaced elements
        if allowed is not None and ctag not in allowed:
            r.add("U801", "warning", f"<{ctag}> is not known inside <{tag}>; PyBullet "
                  "ignores it", child)
        if ctag not in OPAQUE and not (tag == "geometry" and ignored_shape(child)):
            _elements_below(child, ctag, r)  # a shape after the first is never read (U507)


#: NUMERIC by tag: {tag: {attribute: how many numbers}}, for one lookup per element.
_NUMERIC_BY_TAG: dict[str, dict[str, int]] = {}
for (_tag, _attr), _n in NUMERIC.items():
    _NUMERIC_BY_TAG.setdefault(_tag, {})[_attr] = _n


def rule_joints(root: etree._Element, r: Report) -> None:
    """U301-U307, U309: joint type, limits, axis; a mimic's leader exists and leads somewhere."""
    joints = {j.get("name") for j in _elements(root, "joint")}
    leaders: dict[str | None, tuple[str | None, etree._Element]] = {}
    for j in _elements(root, "joint"):
        jtype = j.get("type")
        if jtype not in JOINT_TYPES:
            r.add("U301", "error", f"{_label(j)} has type {jtype!r}; use one of "
                  f"{', '.join(JOINT_TYPES)}", j)
        limit = j.find("limit")
        if jtype in LIMITED_JOINT_TYPES:
            if limit is None:
                r.add("U302", "error", f"{_label(j)} is {jtype} but has no <limit>, which the "
                      "URDF spec requires and PyBullet refuses; add <limit lower=... upper=... "
                      "effort=... velocity=...>", j)
            else:
                missing = [a for a in ("effort", "velocity") if limit.get(a) is None]
                if missing:
                    r.add("U303", "error", f"<limit> of {_label(j)} has no "
                          f"{' or '.join(missing)}; add {'='.join(missing[:1])}=\"...\"", limit)
        lower, upper = _num(limit, "lower"), _num(limit, "upper")
        if lower is not None and upper is not None and lower > upper:
            r.add("U304", "error", f"<limit> of {_label(j)} has lower {lower:g} above upper "
                  f"{upper:g}; swap them (PyBullet reads lower > upper as 'no limit', other "
                  "tools refuse it)", limit)
        axis_el = j.find("axis")
        axis = _vec(axis_el, "xyz", 3)
        if axis is not None and jtype != "fixed":
            norm = math.sqrt(sum(a * a for a in axis))
            if norm == 0:
                r.add("U305", "error", f"<axis> of {_label(j)} is zero; give a direction such "
                      "as xyz=\"0 0 1\"", axis_el)
            elif abs(norm - 1) > 1e-4:
                r.add("U306", "warning", f"<axis> of {_label(j)} has length {norm:.6g}, not 1; "
                      "PyBullet normalises it, other tools may not: write a unit vector",
                      axis_el)
        mimic = j.find("mimic")
        if mimic is not None:
            target = mimic.get("joint")
            if target not in joints or target == j.get("name"):
                r.add("U307", "error", f"<mimic> of {_label(j)} follows joint {target!r}, which "
                      "does not exist (or is itself); name another joint", mimic)
            else:
                leaders[j.get("name")] = (target, mimic)
    reported: set[str | None] = set()
    for start in leaders:
        ring, name = [start], leaders[start][0]
        while name in leaders and name not in ring:
            ring.append(name)
            name = leaders[name][0]
        if name == start and start not in reported:
            reported.update(ring)
            r.add("U309", "error", "mimic joints follow each other in a ring ("
                  + " -> ".join(repr(n) for n in [*ring, start]) + "): none has a leader to "
                  "take its position from; make one of them an ordinary joint",
                  leaders[start][1])


def rule_geometry(root: etree._Element, r: Report) -> None:
    """U501-U506: one shape per <geometry>, first; positive sizes; meshes have a filename."""
    for link in _elements(root, "link"):
        for part in link:
            if part.tag in ("visual", "collision") and part.find("geometry") is None:
                r.add("U506", "error", f"<{part.tag}> of {_label(link)} has no <geometry>, "
                      "which PyBullet refuses; add one or remove the element", part)
    for geom in root.iter("geometry"):
        elements = [c for c in geom if isinstance(c.tag, str)]
        if elements and elements[0].tag not in SHAPES and any(c.tag in SHAPES for c in elements):
            r.add("U505", "error", f"<{elements[0].tag}> comes before the shape in <geometry>; "
                  "PyBullet reads the first element as the shape and refuses the file",
                  elements[0])
        for c in elements:
            if c.tag == "origin":
                r.add("U504", "warning", "<origin> inside <geometry> is ignored by PyBullet; put "
                      "it in the enclosing <visual> or <collision>", c)
        shapes = [c for c in geom if isinstance(c.tag, str) and c.tag in SHAPES]
        owner = geom.getparent()
        what = f"<{owner.tag}> of {_label(owner.getparent())}" if owner is not None \
            and owner.getparent() is not None else "<geometry>"
        if not shapes:
            r.add("U502", "error", f"<geometry> in {what} holds no shape, which PyBullet "
                  f"refuses; it needs one of {', '.join(SHAPES[:4])}", geom)
        elif len(shapes) > 1:
            # Measured (PyBullet 3.2.7): the file loads, visual and collision alike built from
            # the first shape; the others are ignored.
            r.add("U507", "warning", f"<geometry> in {what} holds {len(shapes)} shapes "
                  f"({', '.join(f'<{c.tag}>' for c in shapes)}); PyBullet uses the first, "
                  f"<{shapes[0].tag}>, and ignores the rest: keep one", shapes[1])
        for shape in shapes[:1]:  # PyBullet reads none after the first (measured)
            for attr in SHAPE_SIZES.get(shape.tag, ()):
                vals = numbers(shape.get(attr))
                if shape.get(attr) is None:
                    r.add("U501", "error", f"<{shape.tag}> has no {attr}; add {attr}=\"...\"",
                          shape)
                elif vals and all(math.isfinite(v) for v in vals) and min(vals) <= 0:
                    r.add("U501", "error", f"<{shape.tag} {attr}={shape.get(attr)!r}>: sizes must "
                          "be > 0", shape)
            if shape.tag in ("mesh", "cdf") and not (shape.get("filename") or "").strip():
                r.add("U503", "error", f"<{shape.tag}> has no filename", shape)


def _mass_of(link: etree._Element) -> float | None:
    """The mass PyBullet gives a link: its <mass>, or 1 kg if there is no <inertial>."""
    inertial = link.find("inertial")
    if inertial is None:
        return 1.0
    return _num(inertial.find("mass"), "value")


def rule_mass(root: etree._Element, r: Report) -> None:
    """U601-U602, U606: mass >= 0, > 0 on links that move; warn on missing <inertial>."""
    links = {el.get("name"): el for el in _elements(root, "link") if el.get("name")}
    fixed_children: dict[str, list[str]] = {}
    moving: list[tuple[str, etree._Element]] = []
    for j in _elements(root, "joint"):
        parent, child = j.find("parent"), j.find("child")
        if parent is None or child is None:
            continue
        if j.get("type") == "fixed":
            fixed_children.setdefault(parent.get("link", ""), []).append(child.get("link", ""))
        else:
            moving.append((child.get("link", ""), j))
    child_names = {c.get("link") for j in _elements(root, "joint") for c in j.findall("child")}
    for link in links.values():
        inertial = link.find("inertial")
        if inertial is None:
            # Never "mass 0" for the root: PyBullet fixes a mass-0 base in place (U611).
            advice = ("add <inertial> with its real mass (mass 0 would fix the robot in place)"
                      if link.get("name") not in child_names else
                      "add <inertial> (mass 0 for a frame)")
            r.add("U606", "warning", f"{_label(link)} has no <inertial>; PyBullet silently gives "
                  f"it 1 kg and unit inertia: {advice}", link)
            continue
        mass_el = inertial.find("mass")
        mass = _num(mass_el, "value")
        if mass_el is None or mass_el.get("value") is None:
            r.add("U601", "error", f"<inertial> of {_label(link)} has no <mass value=...>",
                  inertial)
        elif mass is not None and mass < 0:
            r.add("U601", "error", f"{_label(link)} has negative mass {mass:g}; mass must be "
                  ">= 0", mass_el)
    def rigid_mass(name: str) -> float:
        # A link moves with everything fixed to it: it is massless only if all of them are.
        total, stack, seen = 0.0, [name], set()
        while stack:
            n = stack.pop()
            if n in seen or n not in links:
                continue
            seen.add(n)
            total += max(0.0, _mass_of(links[n]) or 0.0)
            stack.extend(fixed_children.get(n, []))
        return total

    for name, j in moving:
        if name in links and rigid_mass(name) == 0:
            r.add("U602", "error", f"{_label(links[name])} moves (joint {j.get('name')!r} is "
                  f"{j.get('type')}) but has mass 0; give it a mass > 0", links[name])
    roots = [link for name, link in links.items() if name not in child_names]
    # PyBullet judges the root link's own mass: 0 fixes the base in place, whatever its fixed
    # children weigh (a mass-0 base_footprint over a 28 kg base_link hangs in the air). A
    # root with no <inertial> gets 1 kg, so it moves (U606 says so).
    own = _mass_of(roots[0]) if len(roots) == 1 and roots[0].find("inertial") is not None \
        else None
    if own is not None and own == 0:
        base, static = roots[0], not moving
        carried = rigid_mass(base.get("name", ""))
        held = (f"; its fixed links weigh {carried:g} kg, and PyBullet ignores that: it looks "
                "at the root's own mass" if carried > 0 else "")
        r.add("U611", "info" if static and not carried else "warning",
              f"root {_label(base)} has mass 0: PyBullet makes the base static, fixed where it "
              "is loaded" + (" (right for a static object such as ground)"
                             if static and not carried else
                             "; right for an arm bolted to the world, wrong for a robot "
                             "that should fall or drive: give the root link a mass, or make "
                             "the massive link the root") + held, base)


def _inertia_tensor(inertia: etree._Element) -> tuple[tuple[float, ...], ...] | None:
    vals = [_num(inertia, a) for a in ("ixx", "ixy", "ixz", "iyy", "iyz", "izz")]
    if any(v is None for v in vals):
        return None
    ixx, ixy, ixz, iyy, iyz, izz = vals
    return ((ixx, ixy, ixz), (ixy, iyy, iyz), (ixz, iyz, izz))  # type: ignore[return-value]


def rule_material_colours(root: etree._Element, r: Report) -> None:
    """U710: one material name given several colours; PyBullet draws them all in one.

    Measured on PyBullet 3.2.7: every visual whose material has that name (``""`` included,
    at the top level or inline) is drawn in the colour written last in the file.
    """
    colours: dict[str, list[tuple[str, etree._Element]]] = {}
    for m in root.iter("material"):
        name, color = m.get("name"), m.find("color")
        if name is None or color is None or color.get("rgba") is None:
            continue
        colours.setdefault(name, []).append((" ".join(color.get("rgba", "").split()), color))
    for name, found in colours.items():
        distinct = list(dict.fromkeys(c for c, _ in found))
        if len(distinct) < 2:
            continue
        shown = ", ".join(distinct[:4]) + (f" and {len(distinct) - 4} more"
                                           if len(distinct) > 4 else "")
        r.add("U710", "warning", f"material name {name!r} is given {len(distinct)} colours "
              f"({shown}): PyBullet draws every visual named so in the last one written, "
              f"rgba {found[-1][0]}; give each colour its own name", found[1][1])


def rule_references(root: etree._Element, r: Report) -> None:
    """U308, U706-U708: references that lead nowhere, and limits PyBullet reads differently.

    A ``<material name>`` used but never defined, a ``<transmission>`` naming a missing joint,
    an empty ``<texture/>``, ``package:///`` without a package name, and a revolute or
    prismatic ``<limit>`` without lower/upper (PyBullet: unlimited; the URDF spec: 0..0).
    """
    defined = {m.get("name") for m in root.iter("material")
               if m.find("color") is not None or m.find("texture") is not None}
    for m in root.iter("material"):
        parent = m.getparent()
        if (parent is not None and parent.tag == "visual" and m.get("name")
                and m.find("color") is None and m.find("texture") is None
                and m.get("name") not in defined):
            r.add("U706", "warning", f"<material name={m.get('name')!r}> is used but never "
                  "defined with a <color> or <texture>; PyBullet draws the default colour", m)
    for t in root.iter("texture"):
        if not (t.get("filename") or "").strip():
            r.add("U707", "warning", "<texture> without a filename; remove it or name the "
                  "image", t)
    for el in root.iter(*FILE_TAGS):
        if (el.get("filename") or "").strip().startswith("package:///"):
            r.add("U708", "info", f"<{el.tag} filename={el.get('filename')!r}>: package:/// "
                  "has no package name; PyBullet and urdfkit look the path up beside the file "
                  "and in every folder above, ROS tools refuse it", el)
    joints = {j.get("name") for j in _elements(root, "joint")}
    for t in root.iter("transmission"):
        for j in t.iter("joint"):
            if j.get("name") and j.get("name") not in joints:
                r.add("U709", "warning", f"<transmission name={t.get('name')!r}> names joint "
                      f"{j.get('name')!r}, which does not exist", j)
    for j in _elements(root, "joint"):
        limit = j.find("limit")
        if (j.get("type") in LIMITED_JOINT_TYPES and limit is not None
                and (limit.get("lower") is None or limit.get("upper") is None)):
            missing = " and ".join(a for a in ("lower", "upper") if limit.get(a) is None)
            r.add("U308", "warning", f"<limit> of {_label(j)} has no {missing}: PyBullet reads "
                  "it as unlimited, the URDF spec (and ROS) as 0; give both", limit)


def rule_inertial(root: etree._Element, r: Report) -> None:
    """U609-U610: <inertial> has an <inertia> with all six components (PyBullet refuses less)."""
    for link in _elements(root, "link"):
        inertial = link.find("inertial")
        if inertial is None:
            continue
        inertia = inertial.find("inertia")
        if inertia is None:
            r.add("U609", "error", f"<inertial> of {_label(link)} has no <inertia>, which "
                  "PyBullet refuses; add <inertia ixx=... iyy=... izz=... ixy ixz iyz>",
                  inertial)
            continue
        missing = [a for a in ("ixx", "ixy", "ixz", "iyy", "iyz", "izz") if inertia.get(a) is None]
        if missing:
            r.add("U610", "error", f"<inertia> of {_label(link)} has no {', '.join(missing)}, "
                  "which PyBullet refuses; give all six components (0 for products of inertia "
                  "of a symmetric body)", inertia)


def rule_inertia(root: etree._Element, r: Report) -> None:
    """U603-U605, U607: inertia positive definite, triangle inequality, plausible for shapes.

    Tolerance as in Drake's ``RotationalInertia::CouldBePhysicallyValid``:
    ``eps = 10 * DBL_EPSILON * max(1, trace / 2)``, on the principal moments.
    """
    noted = False
    for link in _elements(root, "link"):
        inertial = link.find("inertial")
        inertia = inertial.find("inertia") if inertial is not None else None
        if inertia is None:
            continue
        if not noted:
            r.add("U607", "info", "PyBullet ignores <inertia> from the file and recomputes it "
                  "from the collision shapes unless loaded with URDF_USE_INERTIA_FROM_FILE "
                  "(urdfkit: --inertia-from-file)", inertia)
            noted = True
        tensor = _inertia_tensor(inertia)
        mass = _num(inertial.find("mass"), "value")
        if tensor is None:
            continue
        trace = tensor[0][0] + tensor[1][1] + tensor[2][2]
        eps = 10 * _DBL_EPSILON * max(1.0, trace / 2)
        a, b, c = sym_eigenvalues(tensor)
        moments = _moments((a, b, c), max(abs(a), abs(b), abs(c)))
        shapes = _shape_trace(link, mass, r)
        fix = (f"; its collision shapes and mass imply a trace of {shapes[0]:.4g}, e.g. "
               f"ixx=iyy=izz={shapes[0] / 3:.4g} with products 0"
               if shapes and shapes[1] >= STUB_SIZE else "")
        if a < -eps:
            r.add("U603", "error", f"inertia of {_label(link)} is not positive definite "
                  f"(principal moments {moments}); every principal moment must be > 0{fix}",
                  inertia)
            continue
        if mass is not None and mass > 0 and a <= eps:
            r.add("U608", "warning", f"inertia of {_label(link)} is singular (principal moments "
                  f"{moments}): a point or a thin rod, not a solid; with "
                  f"URDF_USE_INERTIA_FROM_FILE the solver may blow up{fix}", inertia)
        if a + b < c - eps:
            r.add("U604", "error", f"inertia of {_label(link)} violates the triangle inequality: "
                  f"principal moments {moments} (the two smaller sum to less than the largest); "
                  f"no rigid body has it: lower the largest to at most {a + b:.4g}{fix}",
                  inertia)
            continue
        if shapes and shapes[0] > 0 and trace > 0 and not 0.1 <= trace / shapes[0] <= 10:
            ratio = f"inertia of {_label(link)} is {trace / shapes[0]:.3g} times what its " \
                    f"collision shapes and mass {mass:g} kg imply"
            if shapes[1] < STUB_SIZE:
                r.add("U605", "warning", f"{ratio}, but those shapes are stubs (largest size "
                      f"{shapes[1]:.3g} m): PyBullet recomputes inertia from them unless loaded "
                      "with URDF_USE_INERTIA_FROM_FILE; give real collision shapes", inertia)
            else:
                r.add("U605", "warning", f"{ratio}; check the units and the mass", inertia)


#: Collision shapes smaller than this (m, largest size) are placeholders, not the body.
STUB_SIZE = 0.01


def _moments(values: Sequence[float], scale: float) -> str:
    """Principal moments for a message: round-off (-4.2e-22 beside 0.1) printed as 0."""
    return ", ".join("0" if abs(v) <= 1e-9 * scale else f"{v:.4g}" for v in values)


@dataclass(frozen=True)
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


def link_solid(link: etree._Element, r: Report | None = None) -> Solid | None:
    """The solid the link's collision shapes make: what ``U605`` and ``urdfkit fix`` use.

    Primitive shapes use spec's closed forms; STL, OBJ and COLLADA meshes (with ``scale``)
    are integrated by :mod:`urdfkit.meshes` when ``r`` knows the file's folder. Each part's
    tensor is rotated into the link frame and moved to the common centre of mass (parallel
    axes). None if unknown: no collision, a capsule, plane or SDF, a mesh that cannot be read
    or is not closed, a bad size.
    """
    parts: list[tuple[float, tuple[float, ...], Matrix3, float]] = []
    for col in link.findall("collision"):
        shape = next((c for c in col.iterfind("geometry/*") if c.tag in SHAPES), None)
        origin = col.find("origin")
        xyz = _vec(origin, "xyz", 3, (0.0, 0.0, 0.0))
        rpy = _vec(origin, "rpy", 3, (0.0, 0.0, 0.0))
        if shape is None or xyz is None or rpy is None:
            return None
        rot = rpy_to_matrix(rpy)
        if shape.tag == "mesh":
            part = _mesh_part(shape, xyz, rot, r)
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
        parts.append((volume, tuple(xyz), matmul(matmul(rot, diag), transpose(rot)), size))
    total = sum(p[0] for p in parts)
    if not parts or not 0 < total < math.inf:
        return None
    com = tuple(sum(v * c[i] for v, c, _, _ in parts) / total for i in range(3))
    acc = [[0.0] * 3 for _ in range(3)]
    for volume, centre, tensor, _ in parts:
        dv = [centre[i] - com[i] for i in range(3)]
        d2 = sum(x * x for x in dv)
        for i in range(3):
            for j in range(3):
                acc[i][j] += tensor[i][j] + volume * ((d2 if i == j else 0.0) - dv[i] * dv[j])
    out = tuple((row[0], row[1], row[2]) for row in acc)
    if not all(math.isfinite(x) for row in out for x in row):
        return None
    return Solid(total, (com[0], com[1], com[2]), out, max(p[3] for p in parts))


def _shape_trace(link: etree._Element, mass: float | None,
                 r: Report | None = None) -> tuple[float, float] | None:
    """Trace of the inertia of the link's collision solids for ``mass``, and their size."""
    if mass is None or mass <= 0:
        return None
    solid = link_solid(link, r)
    if solid is None:
        return None
    trace = solid.trace(mass)
    return (trace, solid.size) if math.isfinite(trace) else None


def _mesh_part(shape: etree._Element, xyz: Sequence[float], rot: Matrix3,
               r: Report | None) -> tuple[float, tuple[float, ...], Matrix3, float] | None:
    """A collision mesh as (volume, centre in the link, tensor per unit density, size)."""
    fn = (shape.get("filename") or "").strip()
    if r is None or r.base is None or not fn:
        return None
    ref = r.reference("mesh", fn)
    scale = _vec(shape, "scale", 3, (1.0, 1.0, 1.0))
    if ref.load_path is None or scale is None:
        return None
    from .meshes import properties

    props = properties(ref.load_path, (scale[0], scale[1], scale[2]))
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
    centre = rotate(rot, props.com)
    t = props.inertia
    own = ((t[0][0], t[0][1], t[0][2]), (t[1][0], t[1][1], t[1][2]), (t[2][0], t[2][1], t[2][2]))
    return (props.volume, tuple(xyz[i] + centre[i] for i in range(3)),
            matmul(matmul(rot, own), transpose(rot)), max(props.extent))


@dataclass(frozen=True)
class Reference:
    """What a ``filename`` attribute points at, and what is wrong with it, if anything.

    Attributes:
        path: The file it means (for loading: ``load_path`` is what PyBullet must be given).
        code, level, message: The finding, or ``code`` None when the file is fine.
    """

    path: Path | None
    load_path: Path | None
    code: str | None = None
    level: str = "error"
    message: str = ""


def reference(tag: str, fn: str, base: Path, packages: Mapping[str, Path] | None) -> Reference:
    """Resolve and judge one file reference: the one rule check and the loaders share.

    U702 unknown package, U704 not a regular file (folder, FIFO, device, unreadable), U701
    missing, U703 found only in pybullet_data (which ``p.loadURDF`` searches once a user adds
    it to the search path, so loaders point PyBullet there), U705 a mesh format PyBullet does
    not read.
    """
    label = f"<{tag} filename={fn!r}>"
    target = resolve_uri(fn, base, packages)
    if target.path is None:
        return Reference(None, None, "U702", "error", f"{label}: {target.problem}")
    path = target.path
    why = not_a_file(path)
    if why == "missing":
        data = pybullet_data_path()
        if target.package is None and data is not None and not_a_file(data / fn) is None:
            return Reference(path, data / fn, "U703", "warning", f"{label}: not beside the "
                             "file, found only in pybullet_data's search path; make the path "
                             "relative to the file")
        return Reference(path, None, "U701", "error", f"{label}: file not found ({path}); "
                         "PyBullet refuses a URDF whose mesh is missing")
    if why is not None:
        return Reference(path, None, "U704", "error", f"{label}: {path} is {why}; PyBullet "
                         "hangs, aborts or fails on it")
    if tag == "mesh" and path.suffix.lower() not in MESH_FORMATS:
        return Reference(path, None, "U705", "error", f"{label}: PyBullet reads "
                         f"{', '.join(MESH_FORMATS)} meshes, not {path.suffix or 'this file'}")
    return Reference(path, path)


def rule_meshes(root: etree._Element, r: Report) -> None:
    """U701-U705: mesh and texture files exist, are files, in formats PyBullet reads."""
    if r.base is None:
        return
    for el in root.iter(*FILE_TAGS):
        fn = (el.get("filename") or "").strip()
        if fn and not ignored_shape(el):  # a mesh after the first shape is never opened
            ref = r.reference(el.tag, fn)
            if ref.code is not None:
                r.add(ref.code, ref.level, ref.message, el)


#: A mesh this many times larger (or smaller) than the robot's typical joint spacing is in
#: the wrong units (millimetres read as metres gives 1000x).
UNITS_RATIO = 200.0


def rule_mesh_shapes(root: etree._Element, r: Report) -> None:
    """U613-U614: meshes in the wrong units; concave collision meshes on links that move.

    Units are judged against the robot's own scale: the median distance between joint
    frames (a model with fewer than two offset joints has no scale, and is not judged).
    PyBullet collides with the convex hull of a mesh (one per OBJ object), so a concave
    collision mesh on a moving link touches where it has a dip; the root's rigid group is not
    judged (a static or bolted base may use ``<collision concave="yes">`` instead).
    """
    if r.base is None:
        return
    from .meshes import CONCAVE_FRACTION, properties

    offsets = sorted(math.sqrt(sum(x * x for x in xyz)) for j in _elements(root, "joint")
                     if (xyz := _vec(j.find("origin"), "xyz", 3)) is not None and any(xyz))
    spacing = offsets[len(offsets) // 2] if len(offsets) >= 2 else None
    moving = _moving_links(root)
    for link in _elements(root, "link"):
        for part in link:
            if part.tag not in ("visual", "collision"):
                continue
            mesh = used_shape(part.find("geometry"))
            fn = (mesh.get("filename") or "").strip() if mesh is not None and \
                mesh.tag == "mesh" else ""
            if not fn or (ref := r.reference("mesh", fn)).load_path is None:
                continue
            scale = _vec(mesh, "scale", 3, (1.0, 1.0, 1.0))
            props = properties(ref.load_path, (scale[0], scale[1], scale[2])) if scale else None
            if props is None:
                continue
            size = max(props.extent)
            if spacing and size > 0 and not 1 / UNITS_RATIO <= size / spacing <= UNITS_RATIO:
                ratio = size / spacing
                fix = ("probably in millimetres: add scale=\"0.001 0.001 0.001\"" if ratio > 1
                       else "probably scaled twice, or in metres where millimetres were meant: "
                       "check its scale")
                r.add("U613", "warning", f"mesh {fn!r} of {_label(link)} is {size:.3g} m across, "
                      f"{ratio:.3g} times the robot's typical joint spacing ({spacing:.3g} m): "
                      f"{fix}", mesh)
            if (part.tag == "collision" and link.get("name") in moving and props.closed
                    and props.concavity > CONCAVE_FRACTION * size):
                r.add("U614", "warning", f"collision mesh {fn!r} of moving {_label(link)} is "
                      f"concave (it is {size:.3g} m across, and parts of it stand up to "
                      f"{props.concavity:.3g} m in front of its own faces' planes): PyBullet "
                      "collides with its convex hull, so contacts happen in mid-air over the "
                      "dips; split it into convex parts (p.vhacd, or one OBJ object per part) "
                      "or use primitives", mesh)


def _moving_links(root: etree._Element) -> set[str]:
    """Links outside the root's rigid group: each moves through a joint that is not fixed."""
    below: dict[str, list[tuple[str, bool]]] = {}
    children = set()
    for j in _elements(root, "joint"):
        parent, child = j.find("parent"), j.find("child")
        if parent is None or child is None:
            continue
        below.setdefault(parent.get("link", ""), []).append(
            (child.get("link", ""), j.get("type") == "fixed"))
        children.add(child.get("link", ""))
    names = [link.get("name", "") for link in _elements(root, "link")]
    roots = [n for n in names if n not in children]
    still, stack = set(), roots[:1]
    while stack:
        n = stack.pop()
        if n not in still:
            still.add(n)
            stack.extend(c for c, fixed in below.get(n, ()) if fixed)
    return set(names) - still


def _too_many_links(n: int) -> str:
    return (f"{n} links: urdfkit refuses to load bodies with more than {MAX_LOADABLE_LINKS} "
            "links (PyBullet takes minutes on them and cannot query their state); split the "
            "model")


def rule_link_limit(root: etree._Element, r: Report) -> None:
    """U209: refuse bodies so large that loading and stepping them takes minutes."""
    n = sum(1 for _ in _elements(root, "link"))
    if n > MAX_LOADABLE_LINKS:
        # Measured: `urdfkit joints` on a 5000-link chain ran for 2 minutes (a hang to a user).
        r.add("U209", "error", _too_many_links(n), root)


_LINK_TAG = re.compile(rb"<link[\s/>]")


class Oversized(InputError):
    """A body over MAX_LOADABLE_LINKS links, refused before parsing (finding U209)."""

    code = "U209"


def refuse_oversized(data: bytes, file: str) -> None:
    """Refuse a body of more than MAX_LOADABLE_LINKS links before it is parsed into a tree.

    A 280,000-link chain took 10 s and 720 MB to parse before :func:`rule_link_limit` could
    refuse it. Here one C-speed scan bounds the count from above (every ``<link`` tag, also in
    comments); only a file over the limit by that bound is counted exactly, streaming, with
    each top-level element freed as soon as it is read: linear time, constant memory.

    Raises:
        InputError: U209, the same refusal the guard gives.
    """
    bound = 0
    for _ in _LINK_TAG.finditer(data):
        bound += 1
        if bound > MAX_LOADABLE_LINKS:
            break
    else:
        return
    import io

    n = 0
    try:
        for _, el in etree.iterparse(io.BytesIO(data), events=("end",), resolve_entities=False,
                                     no_network=True, huge_tree=False, load_dtd=False):
            parent = el.getparent()
            if parent is None or parent.getparent() is not None:
                continue  # only the root's children count, and only they are freed
            if el.tag == "link":
                n += 1
            el.clear()
            while el.getprevious() is not None:
                del parent[0]
    except etree.XMLSyntaxError:
        return  # the full parse reports it, with its line
    if n > MAX_LOADABLE_LINKS:
        raise Oversized(_too_many_links(n), file=file, line=1)


def rule_portability(root: etree._Element, r: Report) -> None:
    """U901: PyBullet-only joint types and shapes, which other URDF tools refuse (info)."""
    for j in _elements(root, "joint"):
        note = extension_note("joint", j.get("type", ""))
        if note:
            r.add("U901", "info", f"{_label(j)}: {note}", j)
    for geom in root.iter("geometry"):
        for shape in geom:
            note = extension_note("shape", shape.tag) if isinstance(shape.tag, str) else None
            if note:
                r.add("U901", "info", note, shape)


#: Rules that stand between a file and a PyBullet crash (or hang), in order.
#: The guard also runs rule_joints and rule_geometry, but refuses only what is not URDF by
#: the one spec (see GUARD_CODES); their value findings are for ``check``.
GUARD_RULES: tuple[Rule, ...] = (rule_document, rule_names, rule_tree, rule_link_limit,
                                 rule_joints, rule_geometry, rule_inertial)

#: The error codes every command refuses: what crashes PyBullet, and what is not URDF at all
#: (an unknown joint type or shape, a <geometry> without a shape, a revolute or
#: prismatic joint without <limit>), which PyBullet refuses or silently misreads. Errors in
#: values (limits, sizes, masses, inertia) are ``check`` findings: PyBullet loads such files,
#: and pybullet_data ships some, so the loading commands still load them.
GUARD_CODES = frozenset({"U001", "U002", "U003", "U005", "U101", "U102", "U103", "U104", "U105",
                         "U106", "U107", "U108", "U110", "U201", "U202", "U203", "U204", "U205",
                         "U206", "U207", "U209", "U301", "U302", "U502", "U505", "U506",
                         "U609", "U610"})

#: Every rule ``urdfkit check`` runs, in order.
ALL_RULES: tuple[Rule, ...] = (*GUARD_RULES, rule_link_count, rule_elements, rule_mass,
                               rule_inertia, rule_meshes, rule_mesh_shapes, rule_references,
                               rule_material_colours, rule_portability)

#: Every finding code with a one-line summary (for ``--select``/``--ignore`` and the docs).
CODES: dict[str, str] = {
    "U000": "file unreadable or not well-formed XML",
    "U004": "XML quirk PyBullet tolerates but other parsers refuse",
    "U005": "elements nested deeper than PyBullet's XML parser reads (98 levels)",
    "U006": "xacro not expanded: executing it is disabled (--no-exec, URDFKIT_NO_EXEC)",
    "U007": "xacro macro library (no links of its own): checked through its includers",
    "U008": "line longer than 8191 bytes: PyBullet breaks it and may misread the file",
    "U009": "a file not named .xacro that holds xacro: read literally ('${prefix}base')",
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
    "U702": "package:// package not found",
    "U703": "mesh found only through pybullet_data's search path",
    "U704": "mesh or texture is a directory, FIFO, device or unreadable",
    "U705": "mesh in a format PyBullet does not read (it reads .stl, .obj, .dae)",
    "U706": "material used but never defined",
    "U707": "<texture> without a filename",
    "U708": "package:/// without a package name",
    "U709": "transmission names a missing joint",
    "U710": "one material name given several colours (PyBullet draws them all in the last)",
    "U801": "unknown tag",
    "U802": "unknown attribute",
    "U901": "PyBullet extension (spherical joint, capsule, plane, cdf): not portable",
    "U950": "links in contact at the zero pose (check --physics: self-collision jitters)",
    "U951": "PyBullet cannot load the file (check --physics)",
}


def run_rules(root: etree._Element, file: str, rules: tuple[Rule, ...], *,
              base: Path | None = None,
              packages: Mapping[str, Path] | None = None,
              origins: Sequence[str | None] | None = None) -> list[Finding]:
    """Run ``rules`` over a document root and return the findings.

    ``base`` (the file's folder) and ``packages`` enable the rules that look at the file
    system (meshes exist); without ``base`` they are skipped. ``origins`` (xacro's, see
    :class:`urdfkit.expand.Expanded`) give each finding the file and line its element was
    written on.
    """
    report = Report(file, base, packages, origin_map(root, origins))
    for rule in rules:
        rule(root, report)
    return report.findings


def origin_map(root: etree._Element, origins: Sequence[str | None] | None
               ) -> dict[etree._Element, str] | None:
    """Elements (document order) paired with their origins; None if they do not line up."""
    if not origins:
        return None
    elements = list(root.iter(etree.Element))
    if len(elements) != len(origins):
        return None
    return {el: at for el, at in zip(elements, origins, strict=True) if at}


#: Warnings every loading command shows (the file loads, but not as written): PyBullet builds
#: a <geometry> with two shapes from the first alone.
GUARD_WARNINGS = frozenset({"U507"})


def guard_findings(root: etree._Element, file: str,
                   origins: Sequence[str | None] | None = None) -> list[Finding]:
    """The findings every command refuses a document for, or warns of.

    Codes in GUARD_CODES (refused) and GUARD_WARNINGS (shown as warnings).
    """
    return [f for f in run_rules(root, file, GUARD_RULES, origins=origins)
            if f.code in GUARD_CODES or f.code in GUARD_WARNINGS]


def guard(tree: etree._ElementTree | etree._Element, file: str, *,
          strict: bool = True, origins: Sequence[str | None] | None = None) -> list[Finding]:
    """Raise :class:`InputError` for the first finding every command refuses.

    With ``strict=False`` (``--no-guard``), the refusals in :data:`LIFTABLE_CODES`, where the
    guard is stricter than PyBullet, are returned instead, for the caller to show as warnings;
    everything that crashes PyBullet is still refused. Nothing is skipped silently. The
    :data:`GUARD_WARNINGS` are returned either way.
    ``origins`` (xacro's) name where a refused element was written.
    """
    root = tree.getroot() if isinstance(tree, etree._ElementTree) else tree
    lifted = []
    for f in guard_findings(root, file, origins):
        if f.code in GUARD_WARNINGS or (not strict and f.code in LIFTABLE_CODES):
            lifted.append(f)
            continue
        raise InputError(f.text, file=f.file, line=f.line,
                         param="guard" if f.code in LIFTABLE_CODES else None)
    return lifted
