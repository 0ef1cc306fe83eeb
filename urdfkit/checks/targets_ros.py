"""What urdfdom (ROS: robot_state_publisher, RViz, MoveIt) refuses, and what it drops.

Read from urdfdom 6.0.0 (the URDF 1.2 release that ``pip install pin`` brings; its
``urdf_parser/src/{model,joint,link,pose}.cpp``) and measured with its ``check_urdf``
(tests/test_check_targets.py loads every rule's fixture in it). What urdfdom reads depends on
``<robot version>``: absent is 1.0; 1.2 adds checks on limits and sizes.

- :func:`urdfdom_refusals`: each reason ``parseURDF`` returns no model (``check_urdf`` exits
  255). Pinocchio reads through the same urdfdom, so its target repeats them (``T200``).
- :func:`rule_ros`: those as ``T1xx`` errors, and the warnings: a link part urdfdom cannot read
  is dropped with what follows it (the link itself is kept, half read: ``T150``), a
  ``<limit>`` without ``lower``/``upper`` pins the joint at 0 (``T163``), an ``<axis/>``
  without ``xyz`` is the zero axis (``T169``).
"""

from __future__ import annotations

import functools
import re
from collections.abc import Iterator

from lxml import etree

from urdfkit.sources.guard import RuleReport

El = etree._Element

#: One C++ ``istream >> double`` that must use the whole token (urdfdom's ``strToDouble``,
#: classic locale): no ``nan``, ``inf``, hex or ``1.0.0``.
_DOUBLE = re.compile(r"[+-]?(?:\d+\.?\d*|\.\d+)(?:[eE][+-]?\d+)?")
#: Leading white space ``>>`` skips (trailing white space is refused: "1 " is no float).
_SPACE = " \t\n\r\v\f"
JOINT_TYPES = frozenset({"revolute", "continuous", "prismatic", "fixed", "floating", "planar"})
SHAPES = frozenset({"box", "cylinder", "sphere", "mesh", "capsule"})

CODES: dict[str, str] = {
    "T101": "ros: XML urdfdom's parser (tinyxml2) cannot read, or nested over 498 levels",
    "T102": "ros: no top-level <robot> (urdfdom refuses the file)",
    "T103": "ros: <robot> without a name",
    "T104": "ros: <robot version> not 1.0, 1.1 or 1.2",
    "T105": "ros: no <link>",
    "T106": "ros: two links with one name",
    "T107": "ros: two joints with one name",
    "T108": "ros: two top-level materials with one name",
    "T109": "ros: joint without a name",
    "T110": "ros: joint without a type",
    "T111": "ros: joint type urdfdom does not know (spherical, a capitalised type)",
    "T112": "ros: revolute or prismatic joint without <limit>",
    "T114": "ros: <limit> without effort or velocity (on any joint type)",
    "T116": "ros: a <limit> value that is not a number",
    "T117": "ros: URDF 1.2 limit without lower and upper, upper < lower, or a negative effort, "
            "velocity or acceleration",
    "T120": "ros: joint <origin> xyz or rpy not three numbers ($(optenv ...), 1,0,0, nan)",
    "T121": "ros: <origin> with both rpy and quat_xyzw (URDF 1.1 and later)",
    "T122": "ros: joint <axis> xyz not three numbers",
    "T123": "ros: <dynamics> without damping and friction, or one not a number",
    "T124": "ros: <safety_controller> without k_velocity, or a value not a number",
    "T125": "ros: <calibration> rising or falling not a number",
    "T126": "ros: <mimic> without a joint, or multiplier or offset not a number",
    "T127": "ros: joint without <parent link> or <child link>",
    "T128": "ros: joint naming a link that is not defined",
    "T130": "ros: more than one root link",
    "T131": "ros: no root link (every link has a parent)",
    "T150": "ros: a link part urdfdom cannot read: it and what follows are dropped "
            "(warning; the link loads half read)",
    "T163": "ros: <limit> without lower or upper: urdfdom pins the joint at 0 (warning)",
    "T169": "ros: <axis/> without xyz: the zero axis, not (1, 0, 0) (warning)",
}


@functools.lru_cache(maxsize=4096)  # files repeat their numbers ("0", "0 0 0"): ~4x faster
def is_double(text: str | None) -> bool:
    """Whether urdfdom reads ``text`` as one number (finite, the whole of it)."""
    if text is None:
        return False
    token = text.lstrip(_SPACE)
    if _DOUBLE.fullmatch(token) is None:
        return False
    return abs(float(token)) != float("inf")


@functools.lru_cache(maxsize=4096)
def vector_problem(text: str | None, count: int = 3) -> str | None:
    """Why urdfdom cannot read ``text`` as ``count`` numbers (split on spaces), or None."""
    parts = [p for p in (text or "").split(" ") if p]
    for p in parts:
        if not is_double(p):
            return f"Unable to parse component [{p}] to a double"
    if len(parts) != count:
        return f"Parser found {len(parts)} elements but {count} expected while parsing " \
               f"vector [{text}]"
    return None


def version(root: El) -> tuple[int, int] | None:
    """The file's URDF version (1.0 when absent); None when urdfdom refuses it."""
    text = root.get("version")
    if text is None:
        return (1, 0)
    m = re.fullmatch(r"(\d+)\.(\d+)", text)
    if m is None:
        return None
    v = (int(m.group(1)), int(m.group(2)))
    return v if (1, 0) <= v <= (1, 2) else None


def _first(el: El, tag: str) -> El | None:
    for c in el:
        if c.tag == tag:
            return c
    return None


def _children(el: El, tag: str) -> Iterator[El]:
    return (c for c in el if c.tag == tag)


# --------------------------------------------------------------------------- refusals

Refusal = tuple[str, str, El]  # code, urdfdom's reason, the element


def read_by_urdfdom(root: El, r: RuleReport) -> list[Refusal]:
    """:func:`urdfdom_refusals`, worked out once per file (ros and pinocchio both ask)."""
    found = r.memo.get("urdfdom")
    if found is None:
        found = r.memo["urdfdom"] = urdfdom_refusals(root)
    return list(found)


def urdfdom_refusals(root: El) -> list[Refusal]:
    """Every reason urdfdom 6.0.0 returns no model for this document (empty: it loads)."""
    if root.tag != "robot":
        return [("T102", "Could not find the 'robot' element in the xml file", root)]
    found: list[Refusal] = []
    if root.get("name") is None:
        found.append(("T103", "No name given for the robot.", root))
    v = version(root)
    if v is None:
        found.append(("T104", f"version {root.get('version')!r}: versions from 1.0 upto 1.2 "
                      "are currently supported, in the form 'x.y'", root))
        return found  # nothing after the version is read
    names: set[str] = set()
    for m in _children(root, "material"):
        name = m.get("name")
        if name is not None and name in names:
            found.append(("T108", f"material '{name}' is not unique.", m))
        if name is not None:
            names.add(name)
    links: dict[str, El] = {}
    for link in _children(root, "link"):
        name = link.get("name") or ""
        if name in links:
            found.append(("T106", f"link '{name}' is not unique.", link))
        links[name] = link
    if not links:
        found.append(("T105", "No link elements found in urdf file", root))
        return found
    for j in _children(root, "joint"):
        found.extend(_joint(j, v))
    found.extend(_tree(root, links))
    return found


def _tree(root: El, links: dict[str, El]) -> list[Refusal]:
    """``initTree`` and ``initRoot``: unique joint names, defined links, one root."""
    found: list[Refusal] = []
    joints: set[str] = set()
    tree_ok = True
    children: dict[str, str] = {}
    for j in _children(root, "joint"):
        name = j.get("name")
        if name is not None:
            if name in joints:
                found.append(("T107", f"joint '{name}' is not unique.", j))
            joints.add(name)
        parent, child = _first(j, "parent"), _first(j, "child")
        plink = parent.get("link") if parent is not None else None
        clink = child.get("link") if child is not None else None
        if plink is None or clink is None:
            found.append(("T127", f"Failed to build tree: Joint [{name}] is missing a parent "
                          "and/or child link specification.", j))
            tree_ok = False
            continue
        for role, link_name in (("child", clink), ("parent", plink)):
            if link_name not in links:
                found.append(("T128", f"Failed to build tree: {role} link [{link_name}] of "
                              f"joint [{name}] not found", j))
                tree_ok = False
        children[clink] = plink
    if tree_ok:
        roots = [n for n in links if n not in children]
        if len(roots) > 1:
            found.append(("T130", f"Failed to find root link: Two root links found: "
                          f"[{roots[0]}] and [{roots[1]}]", links[roots[1]]))
        elif not roots:
            found.append(("T131", "Failed to find root link: No root link found. The robot "
                          "xml is not a valid tree.", root))
    return found


def _joint(j: El, v: tuple[int, int]) -> list[Refusal]:
    """Why urdfdom cannot read this joint (``parseJoint``), in its order."""
    name = j.get("name")
    if name is None:
        return [("T109", "unnamed joint found", j)]
    found: list[Refusal] = []
    origin = _first(j, "origin")
    if origin is not None:
        for attr in ("xyz", "rpy"):
            problem = vector_problem(origin.get(attr)) if origin.get(attr) is not None \
                else None
            if problem:
                found.append(("T120", f"{problem}; Malformed parent origin element for joint "
                              f"[{name}]", origin))
                break
        else:
            if v >= (1, 1) and origin.get("rpy") is not None and \
                    origin.get("quat_xyzw") is not None:
                found.append(("T121", "Both rpy and quat_xyzw orientations are defined. Use "
                              "either one or the other.", origin))
    kind = j.get("type")
    if kind is None:
        return [*found, ("T110", f"joint [{name}] has no type, check to see if it's a "
                         "reference.", j)]
    if kind not in JOINT_TYPES:
        return [*found, ("T111", f"Joint [{name}] has no known type [{kind}]", j)]
    axis = _first(j, "axis")
    if axis is not None and kind not in ("floating", "fixed") and axis.get("xyz") is not None:
        problem = vector_problem(axis.get("xyz"))
        if problem:
            found.append(("T122", f"Malformed axis element for joint [{name}]: {problem}",
                          axis))
    limit = _first(j, "limit")
    if limit is not None:
        found.extend(_limit(limit, name, kind, v))
    elif kind in ("revolute", "prismatic"):
        found.append(("T112", f"Joint [{name}] is of type {kind.upper()} but it does not "
                      "specify limits", j))
    found.extend(_extras(j, name))
    return found


def _limit(limit: El, name: str, kind: str, v: tuple[int, int]) -> list[Refusal]:
    values: dict[str, float] = {}
    for attr in ("lower", "upper", "effort", "velocity", "acceleration"):
        text = limit.get(attr)
        if text is None:
            continue
        if attr == "acceleration" and v < (1, 2):
            continue  # "Ignoring acceleration attribute" before 1.2
        if not is_double(text):
            return [("T116", f"joint [{name}]: {attr} value ({text}) is not a valid float",
                     limit)]
        values[attr] = float(text.lstrip(_SPACE))
    for attr in ("effort", "velocity"):
        if attr not in values:
            return [("T114", f"joint [{name}]: limit has no {attr}; Could not parse limit "
                     f"element for joint [{name}]", limit)]
    if v >= (1, 2):
        if kind in ("revolute", "prismatic") and ("lower" not in values
                                                  or "upper" not in values):
            return [("T117", f"joint [{name}]: revolute and prismatic joints must have both "
                     "lower and upper position limits specified in URDF version 1.2 or "
                     "later", limit)]
        if values.get("upper", 0.0) < values.get("lower", 0.0):
            return [("T117", f"joint [{name}]: upper position limit cannot be smaller than "
                     "lower position limit", limit)]
        for attr in ("effort", "velocity", "acceleration"):
            if values.get(attr, 0.0) < 0:
                return [("T117", f"joint [{name}]: {attr} value ({values[attr]:g}) is "
                         "negative", limit)]
    return []


def _extras(j: El, name: str) -> list[Refusal]:
    """``<dynamics>``, ``<safety_controller>``, ``<calibration>``, ``<mimic>``."""
    found: list[Refusal] = []
    dyn = _first(j, "dynamics")
    if dyn is not None:
        given = [a for a in ("damping", "friction") if dyn.get(a) is not None]
        if not given:
            found.append(("T123", "joint dynamics element specified with no damping and no "
                          f"friction; Could not parse joint_dynamics element for joint "
                          f"[{name}]", dyn))
        for a in given:
            if not is_double(dyn.get(a)):
                found.append(("T123", f"{a} value ({dyn.get(a)}) is not a valid float", dyn))
                break
    safety = _first(j, "safety_controller")
    if safety is not None:
        if safety.get("k_velocity") is None:
            found.append(("T124", f"joint safety: no k_velocity; Could not parse safety "
                          f"element for joint [{name}]", safety))
        else:
            bad = [a for a in ("soft_lower_limit", "soft_upper_limit", "k_position",
                               "k_velocity")
                   if safety.get(a) is not None and not is_double(safety.get(a))]
            if bad:
                found.append(("T124", f"{bad[0]} value ({safety.get(bad[0])}) is not a valid "
                              "float", safety))
    cal = _first(j, "calibration")
    if cal is not None:
        bad = [a for a in ("rising", "falling")
               if cal.get(a) is not None and not is_double(cal.get(a))]
        if bad:
            found.append(("T125", f"{bad[0]} value ({cal.get(bad[0])}) is not a valid float",
                          cal))
    mimic = _first(j, "mimic")
    if mimic is not None:
        if mimic.get("joint") is None:
            found.append(("T126", "joint mimic: no mimic joint specified", mimic))
        else:
            bad = [a for a in ("multiplier", "offset")
                   if mimic.get(a) is not None and not is_double(mimic.get(a))]
            if bad:
                found.append(("T126", f"{bad[0]} value ({mimic.get(bad[0])}) is not a valid "
                              "float", mimic))
    return found


# --------------------------------------------------------------------------- what it drops

def link_part_problems(link: El, v: tuple[int, int]) -> Iterator[tuple[str, El]]:
    """Why urdfdom cannot read a part of this link (it keeps the link, half read).

    ``parseLink`` reads the inertial, then every visual, then every collision, and stops at
    the first it cannot read: what follows is not read either.
    """
    inertial = _first(link, "inertial")
    if inertial is not None:
        problem = _inertial_problem(inertial)
        if problem:
            yield f"{problem}: urdfdom drops its inertial (mass 0), its visuals and its " \
                  "collisions", inertial
            return
    for tag in ("visual", "collision"):
        for part in _children(link, tag):
            problem = _part_problem(part, tag, v)
            if problem:
                what = "this visual, those after it and every collision" if tag == "visual" \
                    else "this collision and those after it"
                yield f"{problem}: urdfdom drops {what}", part
                return


def _origin_problem(el: El, tag: str) -> str | None:
    """Why urdfdom cannot read the ``<origin>`` of ``el`` (a ``tag``), or None."""
    origin = _first(el, "origin")
    for attr in ("xyz", "rpy"):
        if origin is not None and origin.get(attr) is not None:
            problem = vector_problem(origin.get(attr))
            if problem:
                return f"<{tag}><origin {attr}>: {problem}"
    return None


def _inertial_problem(inertial: El) -> str | None:
    problem = _origin_problem(inertial, "inertial")
    if problem:
        return problem
    mass = _first(inertial, "mass")
    if mass is None:
        return "Inertial element must have a mass element"
    if mass.get("value") is None:
        return "Inertial: mass element must have value attribute"
    if not is_double(mass.get("value")):
        return f"Inertial: mass [{mass.get('value')}] is not a float"
    inertia = _first(inertial, "inertia")
    if inertia is None:
        return "Inertial element must have inertia element"
    for attr in ("ixx", "ixy", "ixz", "iyy", "iyz", "izz"):
        text = inertia.get(attr)
        if text is None:
            return f"Inertial: inertia element missing {attr} attribute"
        if not is_double(text):
            return f"Inertial: inertia element {attr} is not a valid double"
    return None


def _part_problem(part: El, tag: str, v: tuple[int, int]) -> str | None:
    problem = _origin_problem(part, tag)
    if problem:
        return problem
    geometry = _first(part, "geometry")
    if geometry is None:
        return f"<{tag}> without <geometry>"
    shape = next((c for c in geometry if isinstance(c.tag, str)), None)
    if shape is None:
        return "Geometry tag contains no child element."
    problem = _shape_problem(shape, v)
    if problem:
        return problem
    if tag == "visual":
        material = _first(part, "material")
        if material is not None and material.get("name") is None:
            return "Visual material must contain a name attribute"
    return None


def _shape_problem(shape: El, v: tuple[int, int]) -> str | None:
    kind = str(shape.tag)
    if kind not in SHAPES or (kind == "capsule" and v < (1, 1)):
        return f"Unknown geometry type '{kind}'" if kind != "capsule" else \
            "capsule needs URDF version 1.1 or later"
    sizes: dict[str, tuple[str, ...]] = {"sphere": ("radius",), "cylinder": ("length", "radius"),
                                         "capsule": ("length", "radius")}
    if kind == "box":
        if shape.get("size") is None:
            return "Box shape has no size attribute"
        problem = vector_problem(shape.get("size"))
        if problem:
            return problem
        values = [float(p) for p in (shape.get("size") or "").split(" ") if p]
        if v >= (1, 2) and not all(x > 0 for x in values):
            return "Box size must be positive finite values"
    elif kind in sizes:
        for attr in sizes[kind]:
            text = shape.get(attr)
            if text is None:
                return f"{kind.capitalize()} shape must have {' and '.join(sizes[kind])} " \
                       "attribute(s)"
            if not is_double(text):
                return f"{attr} [{text}] is not a valid float"
            if v >= (1, 2) and not float(text.lstrip(_SPACE)) > 0:
                return f"{kind.capitalize()} sizes must be positive finite values"
    elif kind == "mesh":
        if shape.get("filename") is None:
            return "Mesh must contain a filename attribute"
        if shape.get("scale") is not None:
            problem = vector_problem(shape.get("scale"))
            if problem:
                return f"Mesh scale was specified, but could not be parsed: {problem}"
    return None


def rule_ros(root: El, r: RuleReport) -> None:
    """T1xx: what urdfdom refuses (errors) and what it reads otherwise (warnings)."""
    refusals = read_by_urdfdom(root, r)
    for code, reason, el in refusals:
        r.add(code, "error", f"urdfdom refuses the file: {reason}", el)
    v = version(root)
    if refusals or v is None:
        return  # refused: what it would have dropped does not matter
    for link in _children(root, "link"):
        for reason, el in link_part_problems(link, v):
            r.add("T150", "warning", f"link {link.get('name')!r}: {reason}, and loads the "
                  "link without them (ROS tools show and plan with it so)", el)
    for j in _children(root, "joint"):
        kind = j.get("type")
        limit = _first(j, "limit")
        if kind in ("revolute", "prismatic") and limit is not None and v < (1, 2) and (
                limit.get("lower") is None or limit.get("upper") is None):
            r.add("T163", "warning", f"joint {j.get('name')!r}: <limit> without lower or "
                  "upper: urdfdom reads the missing one as 0, so ROS tools (MoveIt, "
                  "joint_state_publisher) hold the joint near 0; PyBullet reads it unlimited",
                  limit)
        axis = _first(j, "axis")
        if axis is not None and axis.get("xyz") is None and kind not in ("fixed", "floating"):
            r.add("T169", "warning", f"joint {j.get('name')!r}: <axis/> without xyz is the "
                  "axis (0, 0, 0) in urdfdom (its default (1, 0, 0) is only for no <axis> "
                  "at all); give xyz", axis)
