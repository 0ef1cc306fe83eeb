"""One walk over a URDF document, feeding every rule: the check's single pass (issue 30).

``check`` runs some twenty rules on each file. Each used to find its own elements again
(``root.iter("material")``, ``link.find("inertial")``, a recursive walk for the element
rules, an XPath for the depth): fifteen walks of the same tree, and the same numbers parsed
by several rules. :class:`Doc` walks the tree once, in document order, and keeps what the
rules read:

- the top-level links, joints and materials, each link and joint with the children the
  rules look at (:class:`LinkView`, :class:`JointView`);
- every ``<material>``, ``<geometry>``, file reference (mesh, cdf, texture) and
  ``<transmission>`` anywhere, as ``root.iter(tag)`` would list them;
- the first element deeper than PyBullet's XML parser reads;
- the element rules' findings (U401-U402 numbers, U801-U802 unknown tags and attributes),
  made on the way, for ``rule_elements`` to report in its turn.

The element rules judge each distinct element (its tag and attributes) once for the whole
process (a bounded memo): real files repeat ``<origin rpy="0 0 0" xyz="0 0 0"/>`` thousands
of times.
"""

from __future__ import annotations

import math
from typing import Any

from urdfkit.model.spec import (
    FILE_TAGS,
    MAX_XML_DEPTH,
    NUMERIC,
    OPAQUE,
    SCHEMA,
    is_hex,
    numbers,
    used_shape,
)

El = Any  # an lxml element; this module never imports lxml


def collision_parts(col: El, shapes: tuple[str, ...]) -> tuple[El, El]:
    """(shape, origin) of a ``<collision>``, None for either when absent.

    The shape is the first child of its ``<geometry>`` children (in order) whose tag is in
    ``shapes``; the origin its first ``<origin>``. As ``col.iterfind("geometry/*")`` filtered
    and ``col.find("origin")``, in one look at the children.
    """
    shape = origin = None
    for c in col:
        tag = c.tag
        if tag == "geometry":
            if shape is None:
                for s in c:
                    if s.tag in shapes:
                        shape = s
                        break
        elif tag == "origin" and origin is None:
            origin = c
    return shape, origin


def first(el: El, tag: str) -> El:
    """``el.find(tag)`` for a tag name, without ``find``'s ElementPath (lxml's rules: "{ns}x").

    A plain name is a loop over the children: about half the cost of
    ``next(el.iterchildren(tag))``, whose tag matcher is built anew on each call (the rules
    ask ~12 times a file). A namespaced one ("{*}x" included) is lxml's.
    """
    if tag[0] == "{":
        return next(el.iterchildren(tag), None)
    for child in el:
        if child.tag == tag:
            return child
    return None


#: NUMERIC by tag: {tag: {attribute: how many numbers}}, one lookup per element.
NUMERIC_BY_TAG: dict[str, dict[str, int]] = {}
for (_tag, _attr), _n in NUMERIC.items():
    NUMERIC_BY_TAG.setdefault(_tag, {})[_attr] = _n



class LinkView:
    """A top-level ``<link>`` and the children the rules read (first of each, as lxml's find).

    Attributes:
        el: The element. name: Its ``name`` (None when absent).
        inertial, mass, inertia: The first ``<inertial>``, and its first ``<mass>`` and
            ``<inertia>`` (None when absent).
        parts: Its ``<visual>`` and ``<collision>`` children, in order.
        collisions: Its ``<collision>`` children, in order.
        gazebo: Whether a child's tag ends in ``gazebo`` (any namespace or prefix).
    """

    __slots__ = ("el", "name", "inertial", "mass", "inertia", "parts", "collisions", "gazebo")

    def __init__(self, el: El) -> None:
        self.el = el
        self.name: str | None = el.get("name")
        self.inertial: El
        self.mass: El
        self.inertia: El
        self.parts: list[El]
        self.collisions: list[El]
        self.gazebo: bool
        (self.inertial, self.mass, self.inertia, self.parts,
         self.collisions, self.gazebo) = _link_parts(el)


def _link_parts(el: El) -> tuple[El, El, El, list[El], list[El], bool]:
    """(inertial, mass, inertia, parts, collisions, gazebo) of a link, in one look."""
    inertial = mass = inertia = None
    parts: list[El] = []
    collisions: list[El] = []
    gazebo = False
    for c in el:
        tag = c.tag
        if tag == "visual" or tag == "collision":
            parts.append(c)
            if tag == "collision":
                collisions.append(c)
        elif tag == "inertial" and inertial is None:
            inertial = c
            for k in c:
                if k.tag == "mass" and mass is None:
                    mass = k
                elif k.tag == "inertia" and inertia is None:
                    inertia = k
        elif tag.__class__ is str and tag.endswith("gazebo"):
            gazebo = True
    return inertial, mass, inertia, parts, collisions, gazebo


class JointView:
    """A top-level ``<joint>`` and its children the rules read (the first of each).

    Attributes:
        el, name, type: The element and its attributes.
        parent, child: The first ``<parent>`` and ``<child>`` elements (None when absent).
        children: Every ``<child>`` element (a malformed joint may hold two).
        limit, axis, origin, mimic: The first of each, or None.
    """

    __slots__ = ("el", "name", "type", "parent", "child", "children", "limit", "axis",
                 "origin", "mimic")

    def __init__(self, el: El) -> None:
        self.el = el
        self.name: str | None = el.get("name")
        self.type: str | None = el.get("type")
        self.parent: El | None
        self.child: El | None
        self.children: list[El]
        self.limit: El | None
        self.axis: El | None
        self.origin: El | None
        self.mimic: El | None
        (self.parent, self.child, self.children, self.limit, self.axis, self.origin,
         self.mimic) = _joint_parts(el)


def _joint_parts(el: El) -> tuple[El, El, list[El], El, El, El, El]:
    """(parent, child, children, limit, axis, origin, mimic) of a joint, in one look."""
    first: dict[str, El] = {}
    children: list[El] = []
    for c in el:
        tag = c.tag
        if tag == "child":
            children.append(c)
        elif tag in _JOINT_SLOTS and tag not in first:
            first[tag] = c
    return (first.get("parent"), children[0] if children else None, children,
            first.get("limit"), first.get("axis"), first.get("origin"), first.get("mimic"))


_JOINT_SLOTS = frozenset({"parent", "limit", "axis", "origin", "mimic"})


def _gazebo_child(el: El) -> bool:
    """Whether a child of ``el`` has a tag ending in ``gazebo``."""
    for c in el:
        tag = c.tag
        if tag.__class__ is str and tag.endswith("gazebo"):
            return True
    return False


class Doc:
    """Everything the rules read from one document, collected in one walk.

    Attributes:
        root: The root element.
        links, joints: :class:`LinkView` and :class:`JointView` of the root's children.
        materials: The root's ``<material>`` children.
        deformables: How many ``<deformable>`` children the root has.
        gazebo: Whether a ``<gazebo>`` may stand where
            :func:`urdfkit.model.gazebo.gazebo_contacts` looks for one: a tag ending in
            ``gazebo`` (any namespace or prefix: a superset) among the root's children, or
            among the children of a root's child whose tag ends in ``link``.
        all_materials, geometries, files, transmissions: Every ``<material>``,
            ``<geometry>``, ``<mesh>``/``<cdf>``/``<texture>`` and ``<transmission>`` in
            the document, in document order (as ``root.iter(tag)``).
        unread: The elements of ``files`` that stand in a ``<geometry>`` after its first
            element, which PyBullet never reads (:func:`~urdfkit.model.spec.ignored_shape`).
        too_deep: The first element nested deeper than PyBullet reads, or None.
        element_findings: ``(code, level, message, element)`` of the element rules.
        inertia_keys: The memo key the walk made of each ``<inertia>`` it judged on its
            short road (its tag and attributes, as ``items()``), by element: what
            ``rule_inertia`` keys its own memo by, without reading the attributes again.
    """

    __slots__ = ("root", "links", "joints", "materials", "deformables", "gazebo", "all_materials",
                 "geometries", "files", "transmissions", "unread", "too_deep",
                 "element_findings", "inertia_keys",
                 "_buckets")

    def __init__(self, root: El) -> None:
        self.root = root
        self.links: list[LinkView] = []
        self.joints: list[JointView] = []
        self.materials: list[El] = []
        self.deformables = 0
        self.gazebo = False
        self.all_materials: list[El] = []
        self.geometries: list[El] = []
        self.files: list[El] = []
        self.transmissions: list[El] = []
        self.unread: set[El] = set()
        self.too_deep: El = None
        self.element_findings: list[tuple[str, str, str, El]] = []
        self.inertia_keys: dict[El, tuple[Any, ...]] = {}
        #: Where each collected tag's elements go.
        self._buckets = {"material": self.all_materials, "geometry": self.geometries,
                         "transmission": self.transmissions,
                         **{t: self.files for t in FILE_TAGS}}
        tag = root.tag
        if isinstance(tag, str):
            bucket = self._buckets.get(tag)
            if bucket is not None:
                bucket.append(root)
            for child in root:  # the root's own children are also the top-level lists
                ctag = child.tag
                if ctag == "link":
                    view = LinkView(child)
                    self.links.append(view)
                    self.gazebo = self.gazebo or view.gazebo
                elif ctag == "joint":
                    self.joints.append(JointView(child))
                elif ctag == "material":
                    self.materials.append(child)
                elif ctag == "deformable":
                    self.deformables += 1
                elif ctag.__class__ is str and not self.gazebo:
                    self.gazebo = ctag.endswith("gazebo") or (
                        ctag.endswith("link") and _gazebo_child(child))
            if tag[0] == "{" or tag in _OPAQUE:
                self._measure(root, 1)
            else:
                self._walk(root, tag, 1)

    def _walk(self, el: El, tag: str, depth: int) -> None:
        """Check ``el`` and its subtree, in document order.

        The element checks skip what ``rule_elements`` always skipped: comments, namespaced
        elements (xacro leftovers, extensions) and opaque subtrees (another tool's), and a
        shape after the first in a ``<geometry>`` (PyBullet never reads it); those subtrees
        are only measured for depth (:meth:`_measure`).
        """
        self._check(el, tag)
        self._children(el, tag, depth)

    def _children(self, el: El, tag: str, depth: int) -> None:
        """:meth:`_walk` below ``el``, which is checked already.

        Most children are known tags that no list collects (origin, mass, inertia, link,
        visual...): one lookup (:data:`_PLAIN`) gives such a child's memo key form, and it
        is judged here, as :meth:`_check` would, without a call. Any other child takes
        :meth:`_other`, the general road.
        """
        known = SCHEMA.get(tag)
        allowed = known[1] if known is not None else None
        first = used_shape(el) if tag == "geometry" else None
        if depth == MAX_XML_DEPTH and self.too_deep is None:
            self.too_deep = next((c for c in el if isinstance(c.tag, str)), None)
        depth += 1
        for child in el:
            ctag = child.tag
            form = _PLAIN.get(ctag)  # a comment's tag (a function) is no key: None
            if form is None:
                if ctag.__class__ is str:
                    self._other(child, ctag, tag, allowed, first, depth)
                continue
            if allowed is not None and ctag not in allowed:
                self.element_findings.append((
                    "U801", "warning", f"<{ctag}> is not known inside <{tag}>; PyBullet "
                    "ignores it", child))
            if first is not None and child is not first:  # never read (U507)
                if len(child):
                    self._measure(child, depth)
                continue
            if form is _NAMES:
                names = child.keys()
                key: tuple[Any, ...] | None = (ctag, *names) if names else None
            elif form is _VALUES:
                key = (ctag, *child.items())
            elif form is _INERTIA:  # as _VALUES, and kept for rule_inertia
                key = self.inertia_keys[child] = (ctag, *child.items())
            else:
                key = (ctag, *child.keys(), *map(child.get, form))
            if key is not None:
                found = _VERDICTS.get(key)
                if found is None:
                    found = _remember(key, ctag, child.items())
                if found:
                    self.element_findings.extend([(*f, child) for f in found])
            if len(child):
                self._children(child, ctag, depth)

    def _other(self, child: El, ctag: str, tag: str, allowed: frozenset[str] | None,
               first: El, depth: int) -> None:
        """:meth:`_walk`'s road for a child outside :data:`_PLAIN` (``depth``: the child's).

        Collected tags (material, geometry, mesh...), namespaced and opaque elements,
        unknown tags.
        """
        bucket = self._buckets.get(ctag)
        if bucket is not None:
            bucket.append(child)
            if bucket is self.files and first is not None and child is not first:
                self.unread.add(child)
        if ctag[0] == "{":
            if len(child):  # nothing to check, but maybe too deep
                self._measure(child, depth)
            return
        if allowed is not None and ctag not in allowed:
            self.element_findings.append((
                "U801", "warning", f"<{ctag}> is not known inside <{tag}>; PyBullet "
                "ignores it", child))
        # A shape after the first in a <geometry> is never read (U507).
        if ctag in _OPAQUE or (first is not None and child is not first):
            if len(child):
                self._measure(child, depth)
        elif len(child):
            self._walk(child, ctag, depth)
        else:  # a leaf: its attributes are all there is to check
            self._check(child, ctag)

    def _measure(self, el: El, depth: int) -> None:
        """Collect from an unchecked subtree, and find its first element too deep."""
        if depth == MAX_XML_DEPTH and self.too_deep is None:
            self.too_deep = next((c for c in el if isinstance(c.tag, str)), None)
        buckets = self._buckets
        for child in el:
            ctag = child.tag
            if ctag.__class__ is str:
                bucket = buckets.get(ctag)
                if bucket is not None:
                    bucket.append(child)
                    if bucket is self.files and el.tag == "geometry" and \
                            used_shape(el) is not child:
                        self.unread.add(child)
                if len(child):
                    self._measure(child, depth + 1)

    def _check(self, el: El, tag: str) -> None:
        """U401-U402 and U801-U802 of one element's attributes."""
        # The verdict depends on the attributes' names and on the values of the numeric
        # ones only: names and file names (unique to each file) stay out of the key, or
        # every link and mesh would miss. Decodable: the tag fixes the key's form.
        form = _KEY_FORMS.get(tag)
        if form is None:
            return  # an element no rule knows: nothing to say of its attributes
        if form is _NAMES:  # no values read: none is part of the verdict
            names = el.keys()
            if not names:
                return  # <geometry>, <inertial>, <contact>: nothing to judge
            key: tuple[Any, ...] = (tag, *names)
        elif form is _VALUES or form is _INERTIA:  # all known attributes numeric: all is key
            key = (tag, *el.items())
        else:  # names, then the numeric attributes' values (None when absent)
            key = (tag, *el.keys(), *map(el.get, form))
        found = _VERDICTS.get(key)
        if found is None:
            found = _remember(key, tag, el.items())
        if found:
            self.element_findings.extend([(*f, el) for f in found])


_OPAQUE = frozenset(OPAQUE)
#: The tags Doc collects from the whole document (no namespace: as ``root.iter(tag)``).
_COLLECTED = ("material", "geometry", "transmission", *FILE_TAGS)
#: How :meth:`Doc._check` keys its memo for each tag it judges: by the attributes' names
#: (_NAMES: no numeric attribute), by names and values (_VALUES: every known attribute is
#: numeric; an unknown one's value only makes the key longer), or by names and the values
#: of the numeric attributes named (a tuple: ``<mesh filename= scale=>``).
_NAMES: tuple[str, ...] = ("<names>",)
_VALUES: tuple[str, ...] = ("<values>",)
#: _VALUES for ``<inertia>``, whose keys the walk also keeps (Doc.inertia_keys).
_INERTIA: tuple[str, ...] = ("<inertia values>",)
_KEY_FORMS: dict[str, tuple[str, ...]] = {}
for _tag, (_attrs, _kids) in SCHEMA.items():
    _numeric = tuple(sorted(NUMERIC_BY_TAG.get(_tag, ())))
    _KEY_FORMS[_tag] = (_NAMES if not _numeric else _VALUES if set(_numeric) >= _attrs
                        else _numeric)
for _tag, _num in NUMERIC_BY_TAG.items():
    _KEY_FORMS.setdefault(_tag, tuple(sorted(_num)))
assert _KEY_FORMS["inertia"] is _VALUES
_KEY_FORMS["inertia"] = _INERTIA
#: The key forms of the tags :meth:`Doc._walk` handles on its short road: known, and neither
#: collected (:data:`_COLLECTED`) nor opaque.
_PLAIN: dict[object, tuple[str, ...]] = {
    t: form for t, form in _KEY_FORMS.items() if t not in _COLLECTED and t not in _OPAQUE}


#: The element rules' verdict on a tag with its attributes, for the whole process: real files
#: repeat ``<origin rpy="0 0 0" xyz="0 0 0"/>`` thousands of times. Emptied past _VERDICTS_MAX.
_VERDICTS: dict[tuple[str, ...], tuple[tuple[str, str, str], ...]] = {}
_VERDICTS_MAX = 65536


def _remember(key: tuple[Any, ...], tag: str, items: list[tuple[str, str]]
              ) -> tuple[tuple[str, str, str], ...]:
    """:func:`_verdict` of an element, kept in :data:`_VERDICTS` under ``key``."""
    found = _verdict(tag, items)
    if len(_VERDICTS) >= _VERDICTS_MAX:
        _VERDICTS.clear()
    _VERDICTS[key] = found
    return found


def _verdict(tag: str, items: list[tuple[str, str]]) -> tuple[tuple[str, str, str], ...]:
    """U401-U402 and U801-U802 findings of an element with ``tag`` and attributes ``items``."""
    known = SCHEMA.get(tag)
    numeric = NUMERIC_BY_TAG.get(tag)
    if known is None and numeric is None:
        return ()
    out = []
    for attr, text in items:
        n = numeric.get(attr) if numeric is not None else None
        if n is not None:
            vals = numbers(text)
            if vals is None or not all(map(math.isfinite, vals)):
                out.append(("U401", "error", f"<{tag} {attr}={text!r}>: expected "
                            f"{'a finite number' if n == 1 else f'{n} finite numbers'}"))
            elif is_hex(text):
                read = " ".join(f"{v:.17g}" for v in vals)
                out.append(("U401", "warning", f"<{tag} {attr}={text!r}>: C hexadecimal "
                            f"notation; PyBullet reads {read}, but urdfdom (ROS), Python and "
                            f"most URDF readers refuse it: write {read}"))
            elif len(vals) != n:
                out.append(("U402", "error", f"<{tag} {attr}={text!r}>: expected {n} numbers, "
                            f"got {len(vals)}"))
        if known is not None and attr not in known[0] and attr[0] != "{":
            out.append(("U802", "warning", f"<{tag}> has unknown attribute {attr!r}; PyBullet "
                        "ignores it"))
    return tuple(out)
