"""The guard every loader calls: what stands between a file and a PyBullet crash.

:func:`guard` runs the rules that stand between a file and a PyBullet segfault (two roots, a
child with two parents, cycles, duplicate names, ``%`` in names, ...) and what is not URDF at
all, and raises the first error as an :class:`~urdfkit.core.errors.InputError`. Every command that
loads a file calls it. The rest of ``check``'s rules live in :mod:`urdfkit.checks.validate`, which
builds on the :class:`RuleReport` and the runner here.
"""

from __future__ import annotations

import math
import os
import re
from collections.abc import Callable, Mapping, Sequence
from pathlib import Path
from typing import Any

from lxml import etree

from urdfkit.core.errors import InputError, Oversized
from urdfkit.core.finding import Finding
from urdfkit.model.index import Doc, LinkView
from urdfkit.model.spec import (
    CRASH_NAME_BYTES,
    CRASH_PERCENT_TAGS,
    JOINT_TYPES,
    LIMITED_JOINT_TYPES,
    MAX_LOADABLE_LINKS,
    MAX_NAME_BYTES,
    MAX_XML_DEPTH,
    SHAPE_SIZES,
    SHAPES,
    numbers,
    used_shape,
)
from urdfkit.model.spec import attr_float as _num
from urdfkit.model.spec import attr_vec as _vec
from urdfkit.model.xmlio import BIG_LINES, line_of
from urdfkit.sources.references import Reference, label, reference


class RuleReport:
    """Collects findings for one file.

    Attributes:
        file: The file, as the user named it.
        folder: The folder relative mesh paths start from (:attr:`base` as a Path); None
            skips the file-system rules.
        packages: ``--package NAME=PATH`` mappings for ``package://`` URIs.
    """

    def __init__(self, file: str, base: Path | str | None = None,
                 packages: Mapping[str, Path] | None = None,
                 origins: Mapping[etree._Element, str] | None = None):
        self.file = file
        self.folder = None if base is None else os.fspath(base)
        self.packages = dict(packages or {})
        self.origins = origins
        self.findings: list[Finding] = []
        #: The element each finding is about, in step with :attr:`findings` (``urdfkit fix``
        #: repairs elements, and lines cannot tell apart two elements on one line).
        self.elements: list[etree._Element | None] = []
        self._references: dict[tuple[str, str], Reference] = {}
        self._doc: Doc | None = None
        self._parts: tuple[Doc, list[Part]] | None = None
        #: Results rules share within this file (a mesh's properties at a scale).
        self.memo: dict[object, Any] = {}

    @property
    def base(self) -> Path | None:
        """The folder relative mesh paths start from, or None."""
        return None if self.folder is None else Path(self.folder)

    def doc(self, root: etree._Element) -> Doc:
        """The one walk over ``root`` every rule reads (:class:`~urdfkit.model.index.Doc`)."""
        doc = self._doc
        if doc is None or doc.root is not root:
            doc = self._doc = Doc(root)
        return doc

    def parts(self, root: etree._Element) -> list[Part]:
        """Every link's ``<visual>`` and ``<collision>``, in order, with what rules read of it.

        Each is (link view, the element, its first ``<geometry>``, the shape PyBullet builds
        it from: :func:`~urdfkit.model.spec.used_shape`), None where absent. Worked out once
        per file: the geometry and mesh rules all ask.
        """
        doc = self.doc(root)
        if self._parts is None or self._parts[0] is not doc:
            found: list[Part] = []
            for view in doc.links:
                for part in view.parts:
                    geometry = None
                    for c in part:  # first(part, "geometry"), without an iterator object
                        if c.tag == "geometry":
                            geometry = c
                            break
                    found.append((view, part, geometry, used_shape(geometry)))
            self._parts = (doc, found)
        return self._parts[1]

    def reference(self, tag: str, fn: str) -> Reference:
        """:func:`reference` from this file's folder, judged once per file (several rules ask)."""
        assert self.folder is not None
        key = (tag, fn)
        ref = self._references.get(key)
        if ref is None:
            ref = self._references[key] = reference(tag, fn, self.folder, self.packages)
        return ref

    def add(self, code: str, level: str, message: str, el: etree._Element | None = None,
            line: int | None = None) -> None:
        """Record a finding; its line comes from ``el`` unless given."""
        if line is None and el is not None:
            line = el.sourceline  # line_of(el), whose lookup only lines past 65,535 need
            if line is not None and line >= BIG_LINES:
                line = line_of(el)
        origin = self.origins.get(el) if self.origins is not None and el is not None else None
        self.findings.append(Finding(code, level, message, self.file, line, origin))
        self.elements.append(el)

    @property
    def errors(self) -> list[Finding]:
        """The error-level findings."""
        return [f for f in self.findings if f.level == "error"]


Rule = Callable[[etree._Element, RuleReport], None]
#: A ``<visual>`` or ``<collision>`` as :meth:`RuleReport.parts` gives it.
Part = tuple[LinkView, etree._Element, etree._Element | None, etree._Element | None]


#: Lifted by ``guard=False`` (``--no-guard``): refusals where the guard is stricter than
#: PyBullet 3.2.7, which loads such files. Everything else the guard refuses crashes PyBullet
#: or is not URDF at all, and stays refused.
LIFTABLE_CODES = frozenset({"U107", "U108"})


STRICTER = " (PyBullet 3.2.7 loads this, but the guard refuses it; `guard=False` lifts it)"


def rule_document(root: etree._Element, r: RuleReport) -> None:
    """U001-U003: root is <robot>, has a name, and has links."""
    if root.tag != "robot":
        r.add("U001", "error", f"root element is <{root.tag!s}>, expected <robot>", root)
        return
    if not root.get("name"):
        r.add("U002", "error", "<robot> has no name attribute; add name=\"...\"", root)
    doc = r.doc(root)
    deep = doc.too_deep
    if deep is not None:
        r.add("U005", "error", f"elements are nested more than {MAX_XML_DEPTH} deep; PyBullet's "
              "XML parser stops there and refuses the file", deep)
    if not doc.links:
        soft = doc.deformables > 0
        r.add("U003", "error", "<robot> has no <link>; a robot needs at least one link" +
              (" (this is a PyBullet soft body, <deformable>: load it with loadSoftBody)"
               if soft else ""), root)


def _check_name(el: etree._Element, r: RuleReport) -> str | None:
    name = el.get("name")
    if name is None or not name.strip():
        r.add("U101", "error", f"<{el.tag!s}> has no name; give it a unique name=\"...\"", el)
        return None
    _check_percent(el, name, r)
    _check_length(el, name, r)
    return name


def _check_percent(el: etree._Element, name: str, r: RuleReport) -> None:
    if "%" not in name:
        return
    # PyBullet passes some names into printf as the format string: "%s" reads garbage, "%n"
    # writes memory. Measured on 3.2.7: a link name crashes it; joint, material and robot
    # names load, but any diagnostic that quotes them is one format string away from a crash.
    if el.tag in CRASH_PERCENT_TAGS:
        r.add("U104", "error", f"{label(el)} contains '%', which crashes PyBullet "
              "(it uses names as printf formats); rename it", el)
    else:
        r.add("U107", "error", f"{label(el)} contains '%', which PyBullet may use as a "
              "printf format; rename it" + STRICTER, el)


def _check_length(el: etree._Element, name: str, r: RuleReport) -> None:
    if len(name) * 4 <= MAX_NAME_BYTES:
        return  # no character is more than 4 bytes of UTF-8
    size = len(name.encode("utf-8", "surrogatepass"))
    if size <= MAX_NAME_BYTES:
        return
    # PyBullet's buffers count UTF-8 bytes, not characters: 700 'é' are 1,400 bytes.
    crash = CRASH_NAME_BYTES.get(str(el.tag))
    what = f"<{el.tag!s}> name is {size} bytes long ({len(name)} characters)"
    if crash is not None and size >= crash:
        r.add("U106", "error", f"{what}; PyBullet crashes on {el.tag!s} names from {crash} bytes: "
              f"keep names under {MAX_NAME_BYTES} bytes", el)
    else:
        r.add("U108", "error", f"{what}; keep names under {MAX_NAME_BYTES} bytes, as PyBullet's "
              "fixed-size buffers are not much larger" + STRICTER, el)


def rule_names(root: etree._Element, r: RuleReport) -> None:
    """U101-U108: links, joints and materials are named, uniquely, without '%', not too long."""
    if root.tag != "robot":
        return
    robot_name = root.get("name")
    if robot_name:  # a missing robot name is U002
        _check_percent(root, robot_name, r)
        _check_length(root, robot_name, r)
    doc = r.doc(root)
    for views, code in ((doc.links, "U102"), (doc.joints, "U103")):
        seen: dict[str, etree._Element] = {}
        for view in views:
            el = view.el
            name = _check_name(el, r)
            if name is None:
                continue
            if name in seen:
                r.add(code, "error", f"duplicate {el.tag} name {name!r} (first on line "
                      f"{line_of(seen[name])}); names must be unique", el)
            else:
                seen[name] = el
    seen_mat: dict[str, etree._Element] = {}
    for el in doc.materials:
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
    for el in doc.all_materials:
        visual = el.getparent()
        if visual is root:
            continue
        # Only a link's visual: PyBullet ignores <gazebo> and what is in it (a Gazebo
        # <visual><material><ambient> has no name and loads; found on linorobot2).
        name = el.get("name")
        if name is None and visual is not None and visual.tag == "visual" and \
                visual.getparent() is not None and visual.getparent().tag == "link":
            # Measured: PyBullet refuses the whole file ("Could not parse visual element");
            # name="" loads.
            r.add("U110", "error", "<material> of a <visual> has no name attribute: PyBullet "
                  "refuses the file (\"Could not parse visual element\"); give it one "
                  "(name=\"\" is enough)", el)
        elif name and "%" in name:
            _check_name(el, r)


def rule_tree(root: etree._Element, r: RuleReport) -> None:
    """U201-U207: joints reference links; exactly one root; single parents; no cycles."""
    if root.tag != "robot":
        return
    doc = r.doc(root)
    links = {v.name: v.el for v in doc.links if v.name}
    parent_of: dict[str, tuple[str, etree._Element]] = {}
    children: dict[str, list[str]] = {}
    for view in doc.joints:
        j = view.el
        jname = view.name if view.name is not None else "?"
        ends: dict[str, str | None] = {}
        for role, sub in (("parent", view.parent), ("child", view.child)):
            if sub is None or not sub.get("link"):
                r.add("U201", "error", f"{label(j)} has no <{role} link=\"...\">", j)
                ends[role] = None
                continue
            link = sub.get("link")
            if link not in links:
                r.add("U202", "error", f"{label(j)} {role} link {link!r} does not exist; "
                      "declare it with <link name=...>", sub)
                ends[role] = None
            else:
                ends[role] = link
        parent, child = ends.get("parent"), ends.get("child")
        if parent is None or child is None:
            continue
        if parent == child:
            r.add("U203", "error", f"{label(j)} joins link {parent!r} to itself; parent and "
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
    if parent_of:  # with no parent anywhere, every link is a root and none is on a cycle
        _report_cycle(r, links, roots, parent_of, children)


def _report_cycle(r: RuleReport, links: dict[str, etree._Element], roots: list[str],
                  parent_of: dict[str, tuple[str, etree._Element]],
                  children: dict[str, list[str]]) -> None:
    """U207: links not reachable from a root sit on a cycle."""
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


def rule_joints(root: etree._Element, r: RuleReport) -> None:
    """U301-U307, U309: joint type, limits, axis; a mimic's leader exists and leads somewhere."""
    views = r.doc(root).joints
    joints = {v.name for v in views}
    leaders: dict[str | None, tuple[str | None, etree._Element]] = {}
    for view in views:
        j, jtype = view.el, view.type
        if jtype not in JOINT_TYPES:
            r.add("U301", "error", f"{label(j)} has type {jtype!r}; use one of "
                  f"{', '.join(JOINT_TYPES)}", j)
        limit = view.limit
        if jtype in LIMITED_JOINT_TYPES:
            if limit is None:
                r.add("U302", "error", f"{label(j)} is {jtype} but has no <limit>, which the "
                      "URDF spec requires and PyBullet refuses; add <limit lower=... upper=... "
                      "effort=... velocity=...>", j)
            else:
                missing = [a for a in ("effort", "velocity") if limit.get(a) is None]
                if missing:
                    r.add("U303", "error", f"<limit> of {label(j)} has no "
                          f"{' or '.join(missing)}; add {'='.join(missing[:1])}=\"...\"", limit)
        lower, upper = _num(limit, "lower"), _num(limit, "upper")
        if lower is not None and upper is not None and lower > upper:
            r.add("U304", "error", f"<limit> of {label(j)} has lower {lower:g} above upper "
                  f"{upper:g}; swap them (PyBullet reads lower > upper as 'no limit', other "
                  "tools refuse it)", limit)
        axis_el = view.axis
        axis = _vec(axis_el, "xyz", 3)
        if axis is not None and jtype != "fixed":
            norm = math.sqrt(sum(a * a for a in axis))
            if norm == 0:
                r.add("U305", "error", f"<axis> of {label(j)} is zero; give a direction such "
                      "as xyz=\"0 0 1\"", axis_el)
            elif abs(norm - 1) > 1e-4:
                r.add("U306", "warning", f"<axis> of {label(j)} has length {norm:.6g}, not 1; "
                      "PyBullet normalises it, other tools may not: write a unit vector",
                      axis_el)
        mimic = view.mimic
        if mimic is not None:
            target = mimic.get("joint")
            if target not in joints or target == view.name:
                r.add("U307", "error", f"<mimic> of {label(j)} follows joint {target!r}, which "
                      "does not exist (or is itself); name another joint", mimic)
            else:
                leaders[view.name] = (target, mimic)
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


def rule_geometry(root: etree._Element, r: RuleReport) -> None:
    """U501-U506: one shape per <geometry>, first; positive sizes; meshes have a filename."""
    for view, part, geometry, _ in r.parts(root):
        if geometry is None:
            r.add("U506", "error", f"<{part.tag!s}> of {label(view.el)} has no <geometry>, "
                  "which PyBullet refuses; add one or remove the element", part)
    for geom in r.doc(root).geometries:
        # The common case, one child and a shape, has nothing for _sole_shape to say.
        shape = geom[0] if len(geom) == 1 else None
        if shape is None or shape.tag not in SHAPES:
            shape = _sole_shape(geom, r)
            if shape is None:
                continue
        for attr in SHAPE_SIZES.get(str(shape.tag), ()):
            text = shape.get(attr)
            if text is None:
                r.add("U501", "error", f"<{shape.tag!s}> has no {attr}; add {attr}=\"...\"",
                      shape)
                continue
            vals = numbers(text)
            if vals and all(math.isfinite(v) for v in vals) and min(vals) <= 0:
                r.add("U501", "error", f"<{shape.tag!s} {attr}={text!r}>: sizes must be > 0",
                      shape)
        if shape.tag in ("mesh", "cdf") and not (shape.get("filename") or "").strip():
            r.add("U503", "error", f"<{shape.tag}> has no filename", shape)


def _sole_shape(geom: etree._Element, r: RuleReport) -> etree._Element | None:
    """U502, U504, U505, U507 of a ``<geometry>``; its first shape, None if it has none."""
    elements = [c for c in geom if isinstance(c.tag, str)]
    shapes = [c for c in elements if c.tag in SHAPES]
    if shapes and elements[0].tag not in SHAPES:
        r.add("U505", "error", f"<{elements[0].tag!s}> comes before the shape in <geometry>; "
              "PyBullet reads the first element as the shape and refuses the file",
              elements[0])
    for c in elements:
        if c.tag == "origin":
            r.add("U504", "warning", "<origin> inside <geometry> is ignored by PyBullet; put "
                  "it in the enclosing <visual> or <collision>", c)
    if len(shapes) != 1:
        owner = geom.getparent()
        holder = owner.getparent() if owner is not None else None
        what = f"<{owner.tag!s}> of {label(holder)}" if owner is not None \
            and holder is not None else "<geometry>"
        if not shapes:
            r.add("U502", "error", f"<geometry> in {what} holds no shape, which PyBullet "
                  f"refuses; it needs one of {', '.join(SHAPES[:4])}", geom)
            return None
        # Measured (PyBullet 3.2.7): the file loads, visual and collision alike built from
        # the first shape; the others are ignored.
        r.add("U507", "warning", f"<geometry> in {what} holds {len(shapes)} shapes "
              f"({', '.join(f'<{c.tag!s}>' for c in shapes)}); PyBullet uses the first, "
              f"<{shapes[0].tag!s}>, and ignores the rest: keep one", shapes[1])
    return shapes[0]  # PyBullet reads none after the first (measured)


def rule_inertial(root: etree._Element, r: RuleReport) -> None:
    """U609-U610: <inertial> has an <inertia> with all six components (PyBullet refuses less)."""
    for view in r.doc(root).links:
        link, inertial, inertia = view.el, view.inertial, view.inertia
        if inertial is None:
            continue
        if inertia is None:
            r.add("U609", "error", f"<inertial> of {label(link)} has no <inertia>, which "
                  "PyBullet refuses; add <inertia ixx=... iyy=... izz=... ixy ixz iyz>",
                  inertial)
            continue
        if _INERTIA_ATTRIBUTES.issubset(inertia.keys()):
            continue  # all six there (keys() names an attribute get() finds as get does)
        missing = [a for a in ("ixx", "ixy", "ixz", "iyy", "iyz", "izz") if inertia.get(a) is None]
        if missing:
            r.add("U610", "error", f"<inertia> of {label(link)} has no {', '.join(missing)}, "
                  "which PyBullet refuses; give all six components (0 for products of inertia "
                  "of a symmetric body)", inertia)


_INERTIA_ATTRIBUTES = frozenset(("ixx", "ixy", "ixz", "iyy", "iyz", "izz"))


def _too_many_links(n: int) -> str:
    return (f"{n} links: urdfkit refuses to load bodies with more than {MAX_LOADABLE_LINKS} "
            "links (PyBullet takes minutes on them and cannot query their state); split the "
            "model")


def rule_link_limit(root: etree._Element, r: RuleReport) -> None:
    """U209: refuse bodies so large that loading and stepping them takes minutes."""
    n = len(r.doc(root).links)
    if n > MAX_LOADABLE_LINKS:
        # Measured: `urdfkit joints` on a 5000-link chain ran for 2 minutes (a hang to a user).
        r.add("U209", "error", _too_many_links(n), root)


_LINK_TAG = re.compile(rb"<link[\s/>]")


def refuse_oversized(data: bytes, file: str) -> None:
    """Refuse a body of more than MAX_LOADABLE_LINKS links before it is parsed into a tree.

    A 280,000-link chain took 10 s and 720 MB to parse before :func:`rule_link_limit` could
    refuse it. Here one C-speed scan bounds the count from above (every ``<link`` tag, also in
    comments); only a file over the limit by that bound is counted exactly, streaming, with
    each top-level element freed as soon as it is read: linear time, constant memory.

    Raises:
        InputError: U209, the same refusal the guard gives.
    """
    if len(data) <= 5 * MAX_LOADABLE_LINKS or data.count(b"<link") <= MAX_LOADABLE_LINKS:
        return  # every <link tag is a "<link" (five bytes; a count at C speed)
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


def run_rules(root: etree._Element, file: str, rules: tuple[Rule, ...], *,
              base: Path | str | None = None,
              packages: Mapping[str, Path] | None = None,
              origins: Sequence[str | None] | None = None) -> list[Finding]:
    """Run ``rules`` over a document root and return the findings.

    ``base`` (the file's folder) and ``packages`` enable the rules that look at the file
    system (meshes exist); without ``base`` they are skipped. ``origins`` (xacro's, see
    :class:`urdfkit.sources.expand.Expanded`) give each finding the file and line its element was
    written on.
    """
    report = RuleReport(file, base, packages, origin_map(root, origins))
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
