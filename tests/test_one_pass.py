"""check's one walk (urdfkit.model.index.Doc) against lxml's own walks and a plain oracle.

The rules used to find their elements with ``root.iter(tag)``, ``root.iterchildren(tag)``,
``find`` and an XPath for the depth; the Doc must list exactly what those list, in the same
order, on real files and on random trees. The element findings (U401-U402, U801-U802) are
compared with the rule as it was written before the walk was shared: a recursion that says
what it skips (comments, namespaced elements, opaque subtrees, shapes after the first).
"""

from __future__ import annotations

import math
import re
from pathlib import Path

import pybullet_data
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from lxml import etree

from urdfkit.model.index import Doc
from urdfkit.model.spec import (
    FILE_TAGS,
    MAX_XML_DEPTH,
    NUMERIC,
    OPAQUE,
    SCHEMA,
    ignored_shape,
    used_shape,
)
from urdfkit.model.xmlio import parse_xml, read_bytes

DATA = Path(pybullet_data.getDataPath())
FIXTURES = Path(__file__).parent / "fixtures"


#: A whole token as C's strtod reads one (PyBullet reads numbers with atof): decimal, inf, nan;
#: Python's float() also takes "1_0" and other scripts' digits, which C reads otherwise.
_DEC = re.compile(r"[+-]?(?:(?:[0-9]+\.?[0-9]*|\.[0-9]+)(?:[eE][+-]?[0-9]+)?|inf|infinity|nan)",
                  re.IGNORECASE)
_HEX = re.compile(r"[+-]?0[xX](?:[0-9a-fA-F]+\.?[0-9a-fA-F]*|\.[0-9a-fA-F]+)(?:[pP][+-]?[0-9]+)?")


def _c_float(token: str) -> float:
    if _DEC.fullmatch(token):
        return float(token)
    if _HEX.fullmatch(token):
        return float.fromhex(token)
    raise ValueError(token)


def oracle_findings(root: etree._Element) -> list[tuple[str, str, etree._Element]]:
    """U401/U402/U801/U802 as (code, message, element), by the plain recursive rule."""
    out: list[tuple[str, str, etree._Element]] = []

    def below(el: etree._Element, tag: str) -> None:
        known = SCHEMA.get(tag)
        for attr, text in el.items():
            n = NUMERIC.get((tag, attr))
            if n is not None:
                try:
                    vals = [_c_float(x) for x in text.split()]
                except ValueError:
                    vals = None
                if vals is None or not all(math.isfinite(v) for v in vals):
                    out.append(("U401", f"<{tag} {attr}={text!r}>: expected "
                                f"{'a finite number' if n == 1 else f'{n} finite numbers'}", el))
                elif any(_HEX.fullmatch(x) for x in text.split()):
                    read = " ".join(f"{v:.17g}" for v in vals)
                    out.append(("U401", f"<{tag} {attr}={text!r}>: C hexadecimal notation; "
                                f"PyBullet reads {read}, but urdfdom (ROS), Python and most URDF "
                                f"readers refuse it: write {read}", el))
                elif len(vals) != n:
                    out.append(("U402", f"<{tag} {attr}={text!r}>: expected {n} numbers, "
                                f"got {len(vals)}", el))
            if known is not None and attr not in known[0] and not attr.startswith("{"):
                out.append(("U802", f"<{tag}> has unknown attribute {attr!r}; PyBullet "
                            "ignores it", el))
        for child in el:
            ctag = child.tag
            if not isinstance(ctag, str) or ctag.startswith("{"):
                continue
            if known is not None and ctag not in known[1]:
                out.append(("U801", f"<{ctag}> is not known inside <{tag}>; PyBullet "
                            "ignores it", child))
            skipped = tag == "geometry" and used_shape(el) is not child
            if ctag not in OPAQUE and not skipped:
                below(child, ctag)

    tag = root.tag
    if isinstance(tag, str) and not tag.startswith("{") and tag not in OPAQUE:
        below(root, tag)
    return out


def assert_same_as_lxml(root: etree._Element) -> None:
    doc = Doc(root)
    assert [v.el for v in doc.links] == list(root.iterchildren("link"))
    assert [v.el for v in doc.joints] == list(root.iterchildren("joint"))
    assert doc.materials == list(root.iterchildren("material"))
    assert doc.deformables == len(list(root.iterchildren("deformable")))
    assert doc.all_materials == list(root.iter("material"))
    assert doc.geometries == list(root.iter("geometry"))
    assert doc.files == list(root.iter(*FILE_TAGS))
    assert doc.transmissions == list(root.iter("transmission"))
    assert doc.unread == {el for el in doc.files if ignored_shape(el)}
    deep = etree.XPath("/*" * (MAX_XML_DEPTH + 1))(root)
    assert doc.too_deep is (deep[0] if deep else None)
    for view in doc.links:
        inertial = view.el.find("inertial")
        assert view.inertial is inertial
        assert view.mass is (inertial.find("mass") if inertial is not None else None)
        assert view.inertia is (inertial.find("inertia") if inertial is not None else None)
        assert view.parts == [p for p in view.el if p.tag in ("visual", "collision")]
    for jv in doc.joints:
        for tag in ("parent", "child", "limit", "axis", "origin", "mimic"):
            assert getattr(jv, tag) is jv.el.find(tag), tag
        assert jv.children == jv.el.findall("child")
    got = [(code, message, el) for code, _, message, el in doc.element_findings]
    assert got == oracle_findings(root)
    assert doc.gazebo is may_hold_gazebo(root)


def may_hold_gazebo(root: etree._Element) -> bool:
    """Where gazebo_contacts looks: a tag ending in gazebo among the root's children, or among
    the children of a root's child whose tag ends in link (as rule_gazebo_contacts' own look
    was written before the walk gave it)."""
    def ends(el: etree._Element, suffix: str) -> bool:
        return isinstance(el.tag, str) and el.tag.endswith(suffix)

    return any(ends(child, "gazebo") or (ends(child, "link") and any(ends(g, "gazebo")
                                                                     for g in child))
               for child in root)


REAL = sorted(p for p in DATA.rglob("*.urdf") if "random_urdfs" not in p.parts) + \
    sorted(DATA.glob("random_urdfs/00*/*.urdf")) + sorted(FIXTURES.rglob("*.urdf"))


@pytest.mark.parametrize("path", REAL, ids=lambda p: str(p.relative_to(p.parents[1])))
def test_the_walk_lists_what_lxml_lists_on_real_files(path: Path) -> None:
    assert_same_as_lxml(parse_xml(read_bytes(path), path).getroot())


TAGS = [*SCHEMA, *OPAQUE, "sensor", "{urn:x}thing", "plugin", "{urn:x}gazebo", "{urn:x}link"]
ATTRS = sorted({a for attrs, _ in SCHEMA.values() for a in attrs} | {"bogus", "{urn:x}a"})
VALUES = ["0", "1", "0 0 0", " 1  2\t3 ", "1 2", "nan", "-inf", "1e999", "x", "", "1_0",
          "0.5 0.5 0.5 1", "base"]


@st.composite
def trees(draw: st.DrawFn, depth: int = 0) -> etree._Element:
    tag = draw(st.sampled_from(TAGS if depth else ["robot", "robot", "link", "gazebo"]))
    el = etree.Element(tag)
    for attr in draw(st.lists(st.sampled_from(ATTRS), max_size=3, unique=True)):
        el.set(attr, draw(st.sampled_from(VALUES)))
    if depth < 5:
        for _ in range(draw(st.integers(0, 4 if depth < 3 else 2))):
            kind = draw(st.integers(0, 19))
            if kind == 0:
                el.append(etree.Comment("c"))
            elif kind == 1:
                el.append(etree.ProcessingInstruction("pi", "x"))
            else:
                el.append(draw(trees(depth + 1)))
    return el


@pytest.mark.slow  # 300 drawn trees: the suite's longest property test (CI runs it)
@settings(max_examples=300, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(root=trees())
def test_the_walk_lists_what_lxml_lists_on_random_trees(root: etree._Element) -> None:
    assert_same_as_lxml(root)


def test_the_depth_limit_is_found_where_the_xpath_finds_it() -> None:
    for extra in (0, 1, 2):
        root = etree.Element("robot")
        el = root
        for _ in range(MAX_XML_DEPTH - 1 + extra):
            el = etree.SubElement(el, "link")
        etree.SubElement(root, "link")
        assert_same_as_lxml(root)
        assert (Doc(root).too_deep is not None) == (extra > 0)


@settings(max_examples=200, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(trees(), st.sampled_from([*TAGS, "color", "texture", "nothing"]))
def test_first_finds_what_iterchildren_finds(root: etree._Element, tag: str) -> None:
    from urdfkit.model.index import first

    for el in root.iter(etree.Element):
        assert first(el, tag) is next(el.iterchildren(tag), None)


def test_first_keeps_lxml_namespace_rules() -> None:
    from urdfkit.model.index import first

    root = etree.fromstring(b'<r xmlns:a="urn:a"><a:color/><color/><a:thing/></r>')
    assert first(root, "color") is root[1]  # a plain name is no namespace's
    assert first(root, "{urn:a}color") is root[0]
    assert first(root, "{*}thing") is root[2]
    assert first(etree.fromstring(b'<r xmlns="urn:d"><color/></r>'), "color") is None


def _views(root: etree._Element) -> list[tuple[object, ...]]:
    from urdfkit.model.index import JointView, LinkView, collision_parts
    from urdfkit.model.spec import SHAPES

    out: list[tuple[object, ...]] = []
    for el in root.iter("link", "joint", "collision"):
        if el.tag == "link":
            v = LinkView(el)
            out.append((v.inertial, v.mass, v.inertia, *v.parts, None, *v.collisions))
        elif el.tag == "joint":
            j = JointView(el)
            out.append((j.parent, j.child, *j.children, None, j.limit, j.axis, j.origin,
                        j.mimic))
        else:
            out.append(collision_parts(el, SHAPES))
    return out


PART_TAGS = ["visual", "collision", "inertial", "mass", "inertia", "geometry", "origin", "box",
             "mesh", "sphere", "plane", "parent", "child", "limit", "axis", "mimic",
             "{urn:x}collision", "{urn:x}box", "{urn:x}origin", "#comment"]


@st.composite
def part_trees(draw: st.DrawFn, tag: str = "robot", depth: int = 0) -> etree._Element:
    """Links and joints whose children, grandchildren and great-grandchildren are drawn
    from the names the views read, namespaced twins and comments among them."""
    el = etree.Element(tag)
    names = ["link", "joint", "collision"] if depth == 0 else PART_TAGS
    for _ in range(draw(st.integers(0, 6 if depth < 2 else 3))):
        name = draw(st.sampled_from(names))
        if name == "#comment":
            el.append(etree.Comment("c"))
        elif depth < 3:
            el.append(draw(part_trees(name, depth + 1)))
        else:
            etree.SubElement(el, name)
    return el


def _lxml_views(root: etree._Element) -> list[tuple[object, ...]]:
    """What :func:`_views` lists, found by lxml's own ``find``, ``findall`` and ``iterfind``."""
    from urdfkit.model.spec import SHAPES

    out: list[tuple[object, ...]] = []
    for el in root.iter("link", "joint", "collision"):
        if el.tag == "link":
            inertial = el.find("inertial")
            inner = (None, None) if inertial is None else \
                (inertial.find("mass"), inertial.find("inertia"))
            parts = [c for c in el if c.tag in ("visual", "collision")]
            out.append((inertial, *inner, *parts, None, *el.findall("collision")))
        elif el.tag == "joint":
            out.append((el.find("parent"), el.find("child"), *el.findall("child"), None,
                        el.find("limit"), el.find("axis"), el.find("origin"), el.find("mimic")))
        else:
            shape = next((s for s in el.iterfind("geometry/*") if s.tag in SHAPES), None)
            out.append((shape, el.find("origin")))
    return out


@settings(max_examples=300, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(root=st.one_of(trees(), part_trees()))
def test_the_views_read_what_lxml_finds(root: etree._Element) -> None:
    # LinkView, JointView and collision_parts read each element's children in one look: the
    # same elements (the very proxies) as lxml's find, findall and iterfind.
    views, found = _views(root), _lxml_views(root)
    assert len(views) == len(found)
    for a, b in zip(views, found, strict=True):
        assert len(a) == len(b) and all(x is y for x, y in zip(a, b, strict=True)), (a, b)


@pytest.mark.parametrize("text, held", [
    (b"<robot><link name='a'><gazebo/></link></robot>", True),
    (b"<robot><link name='a'><visual/></link><x:gazebo xmlns:x='urn:x'/></robot>", True),
    (b"<robot><x:link xmlns:x='urn:x'><x:gazebo/></x:link></robot>", True),
    (b"<robot><link name='a'><visual><gazebo/></visual></link></robot>", False),
    (b"<robot><joint name='j'><gazebo/></joint><!-- gazebo --></robot>", False),
])
def test_the_walk_says_where_a_gazebo_block_may_stand(text: bytes, held: bool) -> None:
    # rule_gazebo_contacts reads <gazebo> only where gazebo_contacts looks: the root's
    # children and its links' children (a <gazebo> deeper is never read).
    root = etree.fromstring(text)
    assert may_hold_gazebo(root) is held
    assert_same_as_lxml(root)


@pytest.mark.parametrize("text, unread", [
    (b"<robot><link name='a'><visual><geometry><box size='1 1 1'/><mesh filename='m.stl'/>"
     b"</geometry></visual></link></robot>", 1),
    (b"<robot><link name='a'><visual><geometry><mesh filename='m.stl'/><box/></geometry>"
     b"</visual></link></robot>", 0),
    (b"<robot><gazebo><geometry><box/><mesh filename='m.stl'/></geometry></gazebo></robot>", 1),
    (b"<robot><gazebo><geometry><mesh filename='m.stl'/></geometry></gazebo></robot>", 0),
    (b"<robot><x:a xmlns:x='urn:x'><geometry><!-- c --><cdf filename='c'/><mesh "
     b"filename='m.stl'/></geometry></x:a></robot>", 1),
])
def test_the_walk_knows_which_files_pybullet_never_reads(text: bytes, unread: int) -> None:
    # A mesh after the first element of a <geometry> is never opened (rule_meshes skips
    # it), in the walked tree and in the subtrees the walk only measures alike.
    root = etree.fromstring(text)
    assert len(Doc(root).unread) == unread
    assert_same_as_lxml(root)
