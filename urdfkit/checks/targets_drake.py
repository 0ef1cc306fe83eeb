"""What Drake's URDF parser refuses, and what its MultibodyPlant holds that PyBullet's does not.

Read from Drake 1.51.1 (``multibody/parsing/detail_urdf_parser.cc``, ``detail_tinyxml.cc``,
``detail_common.cc``) and measured with ``Parser(plant).AddModels`` and
``plant.Finalize()``, the plant made with ``AddMultibodyPlantSceneGraph`` as a simulation
makes it (so ``<visual>`` and ``<collision>`` are read: a collision mesh must be OBJ, VTK or
glTF), its ``package_map`` holding the packages the file names that can be found
(tests/test_check_targets.py loads every rule's fixture in it).

Drake reads numbers with C++ streams: a vector must be exactly its count of whole numbers
(``$(optenv ...)``, ``0.07,`` and ``nan`` refuse), a single value must start with a number and
hold only one (``abc`` and ``1 2`` refuse), and what follows the number is dropped (``1,5`` is
1, ``-1.57.`` is -1.57: a warning).
"""

from __future__ import annotations

import functools
import math
import os

from lxml import etree

from urdfkit.checks.targets_ros import _DOUBLE, _children, _first, is_double
from urdfkit.sources.guard import RuleReport

El = etree._Element

JOINT_TYPES = frozenset({"revolute", "continuous", "prismatic", "fixed", "floating", "planar"})
MOVING = frozenset({"revolute", "continuous", "prismatic"})

CODES: dict[str, str] = {
    "T301": "drake: no top-level <robot>, or XML Drake's parser cannot read",
    "T303": "drake: <robot> without a name, or an empty one",
    "T305": "drake: a link without a name, or an empty one",
    "T307": "drake: two links, or two joints, with one name",
    "T309": "drake: a joint without a name or a type",
    "T311": "drake: a joint without <parent link> or <child link>",
    "T312": "drake: a joint naming a link that is not defined (nor world)",
    "T313": "drake: a joint type Drake does not know (spherical; ball in a plain <joint>)",
    "T315": "drake: a zero joint axis",
    "T316": "drake: an origin or axis that is not three numbers ($(optenv ...), 0.07,, nan)",
    "T317": "drake: a value that does not start with a number, or holds two",
    "T318": "drake: limit lower > upper, a negative velocity, or a negative damping",
    "T321": "drake: a joint whose parent is its child, or joints in a loop",
    "T324": "drake: a top-level material twice, without a name, or without a colour",
    "T328": "drake: a <mimic> without its joint, naming a missing joint or itself",
    "T329": "drake: a <transmission> without a type, naming a missing joint, or two "
            "SimpleTransmissions with one actuator name",
    "T331": "drake: a <visual> or <collision> without a <geometry> shape, or one without "
            "its size, radius, length or filename",
    "T334": "drake: a box size or cylinder radius <= 0, a sphere radius < 0, a mesh scale ~0",
    "T336": "drake: a mesh package Drake's package_map cannot be given, or a URI scheme it "
            "does not read (http://)",
    "T338": "drake: a mesh or texture file that does not exist where Drake looks",
    "T339": "drake: a collision mesh that is no OBJ, VTK or glTF (STL, COLLADA)",
    "T340": "drake: a visual <material> without a colour not defined before it, or "
            "defined again with another colour",
    "T353": "drake: a link without <inertial> has mass 0 (PyBullet: 1 kg) (warning)",
    "T355": "drake: mass 0 or less with an inertia: Drake puts a 1 kg sphere there (warning)",
    "T361": "drake: a number with text after it, read up to it (1,5 is 1) (warning)",
    "T362": "drake: <dynamics friction> dropped: the plant has no joint friction (warning)",
    "T363": "drake: a floating joint dropped: its child is a free body (warning)",
    "T370": "drake: a joint with an empty name, type or link is dropped, silently (warning)",
}


@functools.lru_cache(maxsize=4096)
def _scalar(text: str | None) -> tuple[bool, bool]:
    """(Drake reads it, it dropped text after the number)."""
    if text is None:
        return True, False
    s = text.lstrip(" \t\n\r\v\f")
    m = _DOUBLE.match(s)
    if m is None or not math.isfinite(float(m.group(0))):
        return False, False
    rest = s[m.end():].strip()
    if rest and _DOUBLE.match(rest) is not None:
        return False, False  # a second number: "1 2"
    return True, bool(rest)


@functools.lru_cache(maxsize=4096)
def _vector(text: str | None, count: int = 3) -> bool:
    if text is None:
        return True
    parts = text.split()
    return len(parts) == count and all(is_double(p) for p in parts)


def rule_drake(root: El, r: RuleReport) -> None:
    """T3xx: what Drake's parser refuses (errors) and reads otherwise (warnings)."""
    if root.tag != "robot":
        r.add("T301", "error", "Drake refuses the file: URDF does not contain a robot tag.",
              root)
        return
    if not root.get("name"):
        r.add("T303", "error", "Drake refuses the file: Your robot must have a name "
              "attribute" if root.get("name") is None else "Drake refuses the file: the "
              "robot's name is empty", root)
    _materials(root, r)
    links = _links(root, r)
    _geometry(root, r)
    joints = list(_children(root, "joint"))
    names: set[str] = set()
    kept = []
    for j in joints:
        if _dropped(j, r):
            continue
        kept.append(j)
        _joint(j, links, names, r)
    _tree(kept, r)
    _mimics(kept, r)
    actuators: set[str] = set()
    for t in _children(root, "transmission"):
        _transmission(t, {j.get("name"): j for j in kept}, actuators, r)


def _dropped(j: El, r: RuleReport) -> bool:
    """A joint Drake skips without a word: an empty name, type, parent or child link."""
    ends = [_first(j, tag) for tag in ("parent", "child")]
    empty = [what for what, value in (("name", j.get("name")), ("type", j.get("type")),
                                      ("parent link", ends[0].get("link")
                                       if ends[0] is not None else None),
                                      ("child link", ends[1].get("link")
                                       if ends[1] is not None else None))
             if value == ""]
    if empty:
        r.add("T370", "warning", f"joint {j.get('name')!r}: its {empty[0]} is empty: Drake "
              "drops the joint, silently, and its child link becomes a free body", j)
    return bool(empty)


def _materials(root: El, r: RuleReport) -> None:
    seen: set[str] = set()
    for m in _children(root, "material"):
        name = m.get("name")
        if name is None:
            r.add("T324", "error", "Drake refuses the file: Material tag is missing a "
                  "required name", m)
        elif name in seen:
            r.add("T324", "error", f"Drake refuses the file: Material '{name}' was "
                  "previously defined.", m)
        elif _first(m, "color") is None and _first(m, "texture") is None:
            r.add("T324", "error", f"Drake refuses the file: Material '{name}' not "
                  "previously defined, but has no color or texture information.", m)
        if name is not None:
            seen.add(name)
        _texture(m, r)


def _texture(material: El, r: RuleReport) -> None:
    """A material's ``<texture>`` file, which Drake resolves as it resolves meshes."""
    texture = _first(material, "texture")
    if texture is not None and texture.get("filename"):
        _file(texture.get("filename") or "", "texture", texture, r)


def _links(root: El, r: RuleReport) -> set[str]:
    names: set[str] = set()
    for link in _children(root, "link"):
        name = link.get("name")
        if not name:
            r.add("T305", "error", "Drake refuses the file: link tag is missing name "
                  "attribute." if name is None else "Drake refuses the file: a link's name "
                  "is empty (the RigidBody constructor requires one)", link)
            continue
        if name in names:
            r.add("T307", "error", f"Drake refuses the file: the model already contains a "
                  f"body named '{name}'. Body names must be unique within a given model.",
                  link)
        names.add(name)
        if name != "world":
            _inertial(link, name, r)
    return names


# --------------------------------------------------------------------------- geometry

#: The shapes Drake's URDF parser reads (and its own ``drake:`` ones).
SHAPES = ("box", "sphere", "cylinder", "capsule", "mesh", "{http://drake.mit.edu}capsule",
          "{http://drake.mit.edu}ellipsoid")
#: The collision mesh formats Drake's convex hull reads.
HULL_FORMATS = (".obj", ".vtk", ".gltf")


def _geometry(root: El, r: RuleReport) -> None:
    """Every ``<visual>`` and ``<collision>``: shapes, sizes, meshes, visual materials."""
    known: dict[str, str] = {}
    for m in _children(root, "material"):
        color = _first(m, "color")
        if m.get("name") is not None:
            known[m.get("name") or ""] = color.get("rgba", "") if color is not None else ""
    for link in _children(root, "link"):
        for part in link:
            if part.tag not in ("visual", "collision"):
                continue
            _part(part, str(part.tag), link.get("name") or "", r)
            if part.tag == "visual":
                for m in _children(part, "material"):
                    _visual_material(m, known, r)


def _part(part: El, tag: str, link: str, r: RuleReport) -> None:
    origin = _first(part, "origin")
    for attr in ("xyz", "rpy"):
        if origin is not None and not _vector(origin.get(attr)):
            r.add("T316", "error", f"Drake refuses the file: Expected 3 values for attribute "
                  f"{attr} got {origin.get(attr)}", origin)
            return
    geometry = _first(part, "geometry")
    shape = next((c for c in geometry if c.tag in SHAPES), None) \
        if geometry is not None else None
    if shape is None:
        what = "without geometry" if geometry is None else \
            "whose geometry has no shape it reads"
        r.add("T331", "error", f"Drake refuses the file: link {link!r} has a {tag} element "
              f"{what}", part)
        return
    kind = str(shape.tag).rpartition("}")[2]
    needs = {"box": ("size",), "sphere": ("radius",), "cylinder": ("radius", "length"),
             "capsule": ("radius", "length"), "mesh": ("filename",)}.get(kind, ())
    missing = [a for a in needs if shape.get(a) is None]
    if missing:
        r.add("T331", "error", f"Drake refuses the file: missing {kind} attribute: "
              f"{missing[0]}", shape)
        return
    for attr, count in (("size", 3), ("scale", 3)):
        if shape.get(attr) is not None and not _vector(shape.get(attr), count):
            r.add("T316", "error", f"Drake refuses the file: Expected {count} values for "
                  f"attribute {attr} got {shape.get(attr)}", shape)
            return
    for attr in ("radius", "length"):
        if shape.get(attr) is not None and _number(shape, attr, r) is None:
            return
    small = _small(shape, kind)
    if small:
        r.add("T334", "error", f"Drake refuses the file: {small}", shape)
        return
    if kind == "mesh":
        _file(shape.get("filename") or "", tag, shape, r)


def _small(shape: El, kind: str) -> str | None:
    def values(attr: str) -> list[float]:
        """The attribute as Drake reads it (its vectors whole, its scalars up to junk)."""
        text = shape.get(attr) or ""
        if attr in ("size", "scale"):
            return [float(p) for p in text.split()]
        m = _DOUBLE.match(text.lstrip(" \t\n\r\v\f"))
        return [float(m.group(0))] if m else []

    if kind == "box" and any(v <= 0 for v in values("size")):
        return f"a box's sizes must be positive (size {shape.get('size')!r})"
    for attr in ("radius", "length"):
        if kind in ("cylinder", "capsule") and any(not v > 0 for v in values(attr)):
            return f"a {kind}'s {attr} must be positive ({shape.get(attr)!r})"
    if kind == "sphere" and any(v < 0 for v in values("radius")):
        return f"a sphere's radius must not be negative ({shape.get('radius')!r})"
    if kind == "mesh" and shape.get("scale") is not None and any(
            abs(v) < 1e-8 for v in values("scale")):
        return f"Mesh |scale| cannot be < 1e-8 on any axis, given [{shape.get('scale')}]"
    return None


def drake_path(filename: str, folder: str | None,
               packages: dict[str, object] | None = None) -> str | None:
    """Where Drake's parser reads a mesh; None when it cannot.

    A ``package://`` mesh is in the package a ``package_map`` can hold: one named by
    ``--package``, or found by its folder's name or its package.xml above the file.
    """
    from pathlib import Path

    from urdfkit.sources.uris import find_package

    if folder is None:
        return None
    for scheme in ("package://", "model://"):
        if filename.startswith(scheme):
            name, _, rest = filename[len(scheme):].partition("/")
            root = (packages or {}).get(name) or (find_package(name, Path(folder))
                                                 if name else None)
            return None if root is None else os.path.join(str(root), rest)
    if filename.startswith("file://"):
        filename = filename[len("file://"):]
    return filename if os.path.isabs(filename) else os.path.join(folder, filename)


def _file(filename: str, tag: str, shape: El, r: RuleReport) -> None:
    """A mesh (of a ``tag``: visual, collision) or texture file, found as Drake finds it."""
    scheme = filename.partition("://")[0] if "://" in filename else ""
    if scheme not in ("", "file", "package", "model"):
        r.add("T336", "error", f"Drake refuses the file: URI {filename!r} specifies an "
              "unsupported scheme; supported schemes are 'file://', 'model://', and "
              "'package://'", shape)
        return
    if r.folder is None:
        return
    own = filename.partition("://")[2].partition("/")[0] if scheme in ("package", "model") \
        else None
    if own in ("drake", "drake_models"):
        r.add("T336", "error", f"Drake refuses the file: URI {filename!r} names Drake's own "
              f"package {own!r}, which Drake reads from its install (pip's drake ships none "
              "of these models), not from the file's folders", shape)
        return
    path = drake_path(filename, r.folder, dict(r.packages))
    if path is None:
        r.add("T336", "error", f"Drake refuses the file: URI {filename!r} refers to an unknown "
              "package (nor can one be found above the file: give it with --package, and "
              "Drake with parser.package_map().Add)", shape)
    elif not os.path.isfile(path):
        r.add("T338", "error", f"Drake refuses the file: URI {filename!r} resolved to "
              f"{path!r}, which does not exist", shape)
    elif tag == "collision" and not path.lower().endswith(HULL_FORMATS):
        r.add("T339", "error", f"Drake refuses the file: collision mesh {filename!r}: "
              "MakeConvexHull only applies to .obj, .vtk, and .gltf meshes (convert it, "
              "e.g. with trimesh, and point the <collision> at the .obj)", shape)
    elif tag == "collision" and path.lower().endswith(".obj"):
        from urdfkit.checks.rules_mass import mesh_properties_of

        props = mesh_properties_of(r, path, (1.0, 1.0, 1.0))
        if props is None or not max(props.extent) > 1e-12:
            r.add("T339", "error", f"Drake refuses the file: collision mesh {filename!r}: "
                  "MakeConvexHull finds no hull in it (no finite vertices apart)", shape)


def _visual_material(m: El, known: dict[str, str], r: RuleReport) -> None:
    _texture(m, r)
    name = m.get("name")
    if not name:
        return  # unnamed: Drake keeps it to this visual
    color = _first(m, "color")
    rgba = color.get("rgba") if color is not None else None
    if rgba is not None and not _vector(rgba, 4):
        r.add("T316", "error", f"Drake refuses the file: Expected 4 values for attribute rgba "
              f"got {rgba}", color)
        return
    if rgba is None and _first(m, "texture") is None:
        if name not in known:
            r.add("T340", "error", f"Drake refuses the file: Material '{name}' not previously "
                  "defined, but has no color or texture information.", m)
        return
    if name in known and known[name] and rgba is not None and not all(
            math.isclose(float(a), float(b), rel_tol=1e-9, abs_tol=1e-12)
            for a, b in zip(known[name].split(), rgba.split(), strict=False)):
        r.add("T340", "error", f"Drake refuses the file: Material '{name}' was previously "
              "defined (with another colour).", m)
    known.setdefault(name, rgba or "")


def _inertial(link: El, name: str, r: RuleReport) -> None:
    inertial = _first(link, "inertial")
    if inertial is None:
        r.add("T353", "warning", f"link {name!r} has no <inertial>: Drake gives it mass 0 and "
              "no inertia, silently (PyBullet: 1 kg); if it moves, Drake's first dynamics "
              "evaluation fails (a mass matrix that is not positive definite)", link)
        return
    origin = _first(inertial, "origin")
    if origin is not None:
        for attr in ("xyz", "rpy"):
            if not _vector(origin.get(attr)):
                r.add("T316", "error", f"Drake refuses the file: Expected 3 values for "
                      f"attribute {attr} got {origin.get(attr)}", origin)
    mass_el = _first(inertial, "mass")
    mass = _number(mass_el, "value", r)
    inertia = _first(inertial, "inertia")
    moments = [_number(inertia, a, r) for a in ("ixx", "iyy", "izz", "ixy", "ixz", "iyz")] \
        if inertia is not None else []
    if (mass is None or mass <= 0) and any(m for m in moments if m is not None):
        r.add("T355", "warning", f"link {name!r}: mass {mass if mass is not None else 'none'} "
              "with an inertia: Drake warns and puts a 1 kg solid sphere of water's density "
              "there (PyBullet keeps the file's)", mass_el if mass_el is not None else inertial)


def _number(el: El | None, attr: str, r: RuleReport) -> float | None:
    """An attribute read as Drake reads it; its findings said."""
    text = el.get(attr) if el is not None else None
    if text is None or el is None:
        return None
    ok, cut = _scalar(text)
    if not ok:
        r.add("T317", "error", f"Drake refuses the file: Expected single value for attribute "
              f"'{attr}' got '{text}'", el)
        return None
    value = float(_DOUBLE.match(text.lstrip(" \t\n\r\v\f")).group(0))  # type: ignore[union-attr]
    if cut:
        r.add("T361", "warning", f"{attr}={text!r}: Drake reads {value:g} and drops the rest, "
              "silently", el)
    return value


def _joint(j: El, links: set[str], names: set[str], r: RuleReport) -> None:
    name, kind = j.get("name"), j.get("type")
    if name is None or kind is None:
        r.add("T309", "error", f"Drake refuses the file: joint tag is missing "
              f"{'name' if name is None else 'type'} attribute", j)
        return
    if name in names:
        r.add("T307", "error", f"Drake refuses the file: the model already contains a frame "
              f"named '{name}_parent' (two joints named {name!r})", j)
    names.add(name)
    for tag in ("parent", "child"):
        el = _first(j, tag)
        link = el.get("link") if el is not None else None
        if el is None or link is None:
            r.add("T311", "error", f"Drake refuses the file: joint '{name}' doesn't have a "
                  f"{tag} node with a link attribute", j)
            return
        if link and link not in links and link != "world":
            r.add("T312", "error", f"Drake refuses the file: Could not find link named "
                  f"'{link}' for element '{name}'.", el)
    if kind not in JOINT_TYPES:
        r.add("T313", "error", f"Drake refuses the file: Joint '{name}' has unrecognized "
              f"type: '{kind}'", j)
        return
    origin = _first(j, "origin")
    for attr in ("xyz", "rpy"):
        if origin is not None and not _vector(origin.get(attr)):
            r.add("T316", "error", f"Drake refuses the file: Expected 3 values for attribute "
                  f"{attr} got {origin.get(attr)}", origin)
    if kind in ("fixed", "floating"):
        if kind == "floating":
            r.add("T363", "warning", f"joint {name!r} is floating: Drake drops it, warning "
                  "\"not supported by MultibodyPlant\", and leaves its child a free body "
                  "(PyBullet: a fixed joint)", j)
        return
    _axis(j, name, r)
    if kind in MOVING:
        _limits(j, name, r)


def _axis(j: El, name: str, r: RuleReport) -> None:
    axis = _first(j, "axis")
    if axis is None or axis.get("xyz") is None:
        return
    text = axis.get("xyz")
    if not _vector(text):
        r.add("T316", "error", f"Drake refuses the file: Expected 3 values for attribute xyz "
              f"got {text}", axis)
    elif math.hypot(*(float(p) for p in (text or "").split())) < 1e-8:
        r.add("T315", "error", f"Drake refuses the file: Joint '{name}' axis is zero.  Don't "
              "do that.", axis)


def _limits(j: El, name: str, r: RuleReport) -> None:
    limit, dyn = _first(j, "limit"), _first(j, "dynamics")
    values = {a: _number(limit, a, r) for a in ("lower", "upper", "effort", "velocity")}
    lower, upper, velocity = values["lower"], values["upper"], values["velocity"]
    if lower is not None and upper is not None and lower > upper:
        r.add("T318", "error", f"Drake refuses the file: joint {name!r} has lower {lower:g} > "
              f"upper {upper:g} (Drake stops: pos_lower_limits <= pos_upper_limits failed)",
              limit)
    if velocity is not None and velocity < 0:
        r.add("T318", "error", f"Drake refuses the file: joint {name!r} has a negative "
              "velocity limit (Drake stops: set_velocity_limits failed)", limit)
    damping = _number(dyn, "damping", r)
    friction = _number(dyn, "friction", r)
    if damping is not None and damping < 0:
        r.add("T318", "error", f"Drake refuses the file: joint {name!r}: joint damping must "
              "be nonnegative.", dyn)
    if friction:
        r.add("T362", "warning", f"joint {name!r}: Drake drops <dynamics friction> with a "
              "warning (MultibodyPlant has no joint friction); PyBullet reads it too but "
              "does not simulate it either", dyn)


def _tree(joints: list[El], r: RuleReport) -> None:
    """A joint from a link to itself, or joints closing a loop (Finalize refuses them)."""
    parent: dict[str, str] = {}

    def find(x: str) -> str:
        while parent.get(x, x) != x:
            x = parent[x]
        return x

    for j in joints:
        p, c = _first(j, "parent"), _first(j, "child")
        a = p.get("link") if p is not None else None
        b = c.get("link") if c is not None else None
        if not a or not b or not j.get("name") or j.get("type") not in JOINT_TYPES:
            continue
        if a == b:
            r.add("T321", "error", f"Drake refuses the file: joint {j.get('name')} would "
                  f"connect body {a} to itself.", j)
            return
        ra, rb = find(a), find(b)
        if ra == rb:
            r.add("T321", "error", "Drake refuses the file at Finalize(): the bodies and "
                  f"joints form a loop (joint {j.get('name')!r} closes it)", j)
            return
        parent[ra] = rb


def _mimics(joints: list[El], r: RuleReport) -> None:
    kinds = {j.get("name"): j.get("type") for j in joints}
    for j in joints:
        mimic = _first(j, "mimic")
        if mimic is None:
            continue
        name, other = j.get("name"), mimic.get("joint")
        why = "is missing the required 'joint' attribute" if other is None else \
            f"specifies joint '{other}' which does not exist" if other not in kinds else \
            f"specifies joint '{other}'. Joints cannot mimic themselves" if other == name \
            else None
        if why is None and (kinds[name] in MOVING) != (kinds[other] in MOVING):
            why = f"has {1 if kinds[name] in MOVING else 0} DOF, and cannot mimic joint " \
                  f"'{other}'"
        if why:
            r.add("T328", "error", f"Drake refuses the file: Joint '{name}' mimic element "
                  f"{why}.", mimic)
        for attr in ("multiplier", "offset"):
            _number(mimic, attr, r)


def _transmission(t: El, joints: dict[str | None, El], actuators: set[str],
                  r: RuleReport) -> None:
    kind = _first(t, "type")
    text = kind.text if kind is not None else t.get("type")
    if text is None:
        r.add("T329", "error", "Drake refuses the file: Transmission element is missing a "
              "type.", t)
        return
    joint = _first(t, "joint")
    if joint is None:
        return
    if joint.get("name") not in joints:
        r.add("T329", "error", f"Drake refuses the file: Transmission specifies joint "
              f"'{joint.get('name')}' which does not exist.", joint)
        return
    j = joints[joint.get("name")]
    limit = _first(j, "limit")
    effort = limit.get("effort") if limit is not None else None
    actuator = _first(t, "actuator")
    name = actuator.get("name") if actuator is not None else None
    # Drake makes an actuator of a SimpleTransmission on a moving joint with effort
    if "SimpleTransmission" not in text or j.get("type") == "fixed" or name is None or (
            effort is not None and is_double(effort) and float(effort) == 0):
        return
    if name in actuators:
        r.add("T329", "error", f"Drake refuses the file: the model already contains a joint "
              f"actuator named '{name}'. Joint actuator names must be unique within a given "
              "model.", actuator)
    actuators.add(name)
