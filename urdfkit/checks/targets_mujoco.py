"""What MuJoCo's own URDF reader refuses, and what its model holds that PyBullet's does not.

MuJoCo 4.0 reads a URDF itself (``mujoco.MjModel.from_xml_path("robot.urdf")``; its
``src/xml/xml_urdf.cc``, then the compiler): not urdfkit's export (``urdfkit export mjcf``),
which carries PyBullet's reading over. Measured with MuJoCo 4.0.0 (tests/test_check_targets.py
loads every rule's fixture in it).

It reads numbers whole (``1,5``, ``-1.57.``, ``$(optenv ...)`` refuse; ``nan`` and ``inf``
load) and counts them (``T412``); it welds the root to the world and fuses fixed links into
their parents (``T450``), drops visuals (so nothing wrong in a visual refuses beyond the XML),
and compiles the rest: a moving body needs mass and inertia, every inertia its triangle
inequality, every collision shape a size and a mesh file it can open and decode.
"""

from __future__ import annotations

import math
import os
import re

from lxml import etree

from urdfkit.checks.rules_mass import principal_moments
from urdfkit.checks.targets_ros import _children, _first
from urdfkit.sources.guard import RuleReport

El = etree._Element

#: One number as MuJoCo's reader takes it (strtod over the whole token: nan and inf too).
_NUMBER = re.compile(r"[+-]?(?:(?:\d+\.?\d*|\.\d+)(?:[eE][+-]?\d+)?|inf(?:inity)?|nan"
                     r"|0x(?:[0-9a-f]+\.?[0-9a-f]*|\.[0-9a-f]+)(?:p[+-]?\d+)?)", re.IGNORECASE)


def number(text: str) -> float:
    """A token :data:`_NUMBER` matched, as strtod reads it (hexadecimal too: ``-0x1``)."""
    token = text.strip()
    if "x" in token.lower():
        return float.fromhex(token)
    return float(token)
JOINT_TYPES = frozenset({"revolute", "continuous", "prismatic", "fixed", "floating", "planar",
                         "spherical"})
MOVING = frozenset({"revolute", "continuous", "prismatic"})
#: MuJoCo's smallest mass and inertia of a moving body (mjMINVAL).
MINVAL = 1e-15
#: A binary STL's most faces MuJoCo's decoder reads.
STL_FACES = 200_000

CODES: dict[str, str] = {
    "T401": "mujoco: no top-level <robot>, or XML MuJoCo's parser cannot read",
    "T403": "mujoco: a required attribute missing (a name, a type, a link, a filename, an "
            "inertia component, a cylinder's length, a mimic's joint)",
    "T404": "mujoco: a required element missing (a joint's parent or child, a collision's "
            "geometry, an inertial's mass or inertia)",
    "T405": "mujoco: an <origin>, <limit>, <inertial> or <axis> given twice",
    "T406": "mujoco: two links with one name",
    "T407": "mujoco: a joint naming a link that is not defined (world included)",
    "T408": "mujoco: a link that is the child of two joints, its own parent, or in a loop",
    "T410": "mujoco: a joint type MuJoCo does not know",
    "T411": "mujoco: a number that does not read whole (1,5, -1.57., $(optenv ...))",
    "T412": "mujoco: more or fewer numbers than the attribute takes",
    "T414": "mujoco: a <geometry> without a shape (PyBullet's plane, a cdf), visual or not",
    "T420": "mujoco: a moving link without mass or inertia (MuJoCo's mjMINVAL)",
    "T421": "mujoco: an inertia breaking the triangle inequality, or with a moment <= 0",
    "T423": "mujoco: a zero joint axis",
    "T424": "mujoco: a collision box, sphere or cylinder of size <= 0",
    "T425": "mujoco: a floating joint under a moving link",
    "T426": "mujoco: a collision mesh MuJoCo cannot open or decode (package://, COLLADA, "
            "ASCII STL, over 200,000 faces)",
    "T450": "mujoco: the root welded to the world: a floating base is fixed (warning)",
    "T451": "mujoco: fixed joints fused away: their links are no bodies (info)",
    "T453": "mujoco: a link without <inertial> weighs what its collision shapes hold of "
            "water (PyBullet: 1 kg) (warning)",
    "T455": "mujoco: a limit MuJoCo drops: continuous, one-sided, or lower >= upper (warning)",
}

#: Attributes MuJoCo reads as numbers, by element: (attribute, how many).
_COUNTS: dict[str, tuple[tuple[str, int], ...]] = {
    "origin": (("xyz", 3), ("rpy", 3)), "axis": (("xyz", 3),), "box": (("size", 3),),
    "mesh": (("scale", 3),), "color": (("rgba", 4),), "mass": (("value", 1),),
    "inertia": tuple((a, 1) for a in ("ixx", "ixy", "ixz", "iyy", "iyz", "izz")),
    "limit": (("lower", 1), ("upper", 1), ("effort", 1), ("velocity", 1)),
    "dynamics": (("damping", 1), ("friction", 1)), "sphere": (("radius", 1),),
    "cylinder": (("radius", 1), ("length", 1)), "capsule": (("radius", 1), ("length", 1)),
    "mimic": (("multiplier", 1), ("offset", 1)),
}


def rule_mujoco(root: El, r: RuleReport) -> None:
    """T4xx: what MuJoCo's URDF reader refuses (errors) and reads otherwise (warnings, info)."""
    if root.tag != "robot":
        if root.tag != "mujoco":
            r.add("T401", "error", f"MuJoCo refuses the file: Unrecognized XML model type: "
                  f"{str(root.tag)!r}", root)
        return
    options = compiler_options(root)
    before = len(r.findings)
    _read(root, r, visuals=options.get("discardvisual") == "false")
    links = _links(root, r, visuals=options.get("discardvisual") == "false")
    joints = list(_children(root, "joint"))
    _joints(joints, links, r)
    if len(r.findings) > before:  # refused while reading: nothing is compiled
        return
    _compile(root, links, joints, options, r)


def compiler_options(root: El) -> dict[str, str]:
    """The file's ``<mujoco><compiler .../></mujoco>`` extension, which MuJoCo's reader obeys."""
    block = _first(root, "mujoco")
    compiler = _first(block, "compiler") if block is not None else None
    return dict(compiler.attrib) if compiler is not None else {}


#: Attributes MuJoCo must find where the element is: an empty value is a missing one.
_REQUIRED: dict[str, tuple[str, ...]] = {
    "axis": ("xyz",), "box": ("size",), "sphere": ("radius",), "cylinder": ("radius", "length"),
    "capsule": ("radius", "length"), "mesh": ("filename",), "mass": ("value",),
    "inertia": ("ixx", "ixy", "ixz", "iyy", "iyz", "izz"), "color": ("rgba",),
    "mimic": ("joint",), "parent": ("link",), "child": ("link",),
}


def _read(root: El, r: RuleReport, *, visuals: bool) -> None:
    """The elements MuJoCo's reader reads, their numbers and required attributes.

    It reads top-level materials, links' inertials and collisions (and visuals only with
    ``discardvisual="false"``; else just their materials) and joints' origin, axis, limit,
    dynamics and mimic.
    """
    read: list[El] = []
    for m in _children(root, "material"):
        read.extend(m.iter())
        _repeated(m, ("color", "texture"), r)
    for link in _children(root, "link"):
        for part in link:
            if part.tag in ("inertial", "collision") or (part.tag == "visual" and visuals):
                read.extend(part.iter())
            elif part.tag == "visual":
                for m in _children(part, "material"):
                    read.extend(m.iter())
                    _repeated(m, ("color", "texture"), r)
    for j in _children(root, "joint"):
        read.extend(c for c in j if c.tag in ("origin", "axis", "limit", "dynamics", "mimic",
                                              "parent", "child"))
    for el in read:
        tag = el.tag if isinstance(el.tag, str) else ""
        for attr in _REQUIRED.get(tag, ()):
            if not el.get(attr):
                r.add("T403", "error", f"MuJoCo refuses the file: required attribute "
                      f"missing: '{attr}' (<{tag}>)", el)
        for attr, count in _COUNTS.get(tag, ()):
            text = el.get(attr)
            if text:
                _count(el, attr, text, count, r)


def _count(el: El, attr: str, text: str, count: int, r: RuleReport) -> None:
    parts = text.split()
    bad = next((p for p in parts if _NUMBER.fullmatch(p) is None), None)
    if bad is None:
        bad = next((p for p in parts if p.lower().lstrip("+-") not in ("inf", "infinity")
                    and abs(number(p)) == float("inf")), None)
        if bad is not None:
            r.add("T411", "error", f"MuJoCo refuses the file: number is too large in "
                  f"attribute '{attr}' ({bad})", el)
            return
    if bad is not None:
        r.add("T411", "error", f"MuJoCo refuses the file: bad format in attribute "
              f"'{attr}' ({bad!r})", el)
    elif len(parts) != count:
        r.add("T412", "error", f"MuJoCo refuses the file: attribute '{attr}' has "
              f"{'too much' if len(parts) > count else 'not enough'} data "
              f"({len(parts)} numbers, {count} taken)", el)


def _links(root: El, r: RuleReport, *, visuals: bool) -> dict[str, El]:
    links: dict[str, El] = {}
    for link in _children(root, "link"):
        name = link.get("name")
        if name is None:
            r.add("T403", "error", "MuJoCo refuses the file: required attribute missing: "
                  "'name'", link)
            continue
        if name in links:
            r.add("T406", "error", f"MuJoCo refuses the file: repeated URDF name ({name!r})",
                  link)
        links[name] = link
        inertials = [c for c in link if c.tag == "inertial"]
        if len(inertials) > 1:
            r.add("T405", "error", "MuJoCo refuses the file: repeated element: 'inertial'",
                  inertials[1])
        for inertial in inertials[:1]:
            _repeated(inertial, ("origin", "mass", "inertia"), r)
            for tag in ("mass", "inertia"):
                if _first(inertial, tag) is None:
                    r.add("T404", "error", f"MuJoCo refuses the file: missing element: "
                          f"'{tag}'", inertial)
        for part in link:
            if part.tag == "collision" or (part.tag == "visual" and visuals):
                _part(part, r)
            elif part.tag == "visual":
                _repeated(part, ("material",), r)
    return links


def _repeated(el: El, tags: tuple[str, ...], r: RuleReport) -> None:
    for tag in tags:
        found = [c for c in el if c.tag == tag]
        if len(found) > 1:
            r.add("T405", "error", f"MuJoCo refuses the file: repeated element: '{tag}'",
                  found[1])


def _part(part: El, r: RuleReport) -> None:
    _repeated(part, ("origin", "geometry", "material"), r)
    geometry = _first(part, "geometry")
    if geometry is None:
        if part.tag == "collision":
            r.add("T404", "error", "MuJoCo refuses the file: missing element: 'geometry'",
                  part)
        return
    shapes = [c for c in geometry if c.tag in ("box", "cylinder", "sphere", "capsule", "mesh")]
    if not shapes:
        r.add("T414", "error", f"MuJoCo refuses the file: {str(part.tag)} geometry "
              "specification not found", geometry)
    _repeated(geometry, ("box", "cylinder", "sphere", "capsule", "mesh"), r)


def _joints(joints: list[El], links: dict[str, El], r: RuleReport) -> None:
    parents: dict[str, str] = {}
    for j in joints:
        for attr in ("name", "type"):
            if j.get(attr) is None:
                r.add("T403", "error", f"MuJoCo refuses the file: required attribute missing: "
                      f"'{attr}'", j)
        _repeated(j, ("origin", "limit", "axis", "dynamics", "mimic", "parent", "child"), r)
        kind = j.get("type")
        if kind is not None and kind not in JOINT_TYPES:
            r.add("T410", "error", "MuJoCo refuses the file: invalid joint type in URDF joint "
                  f"definition ({kind!r})", j)
        ends = []
        for tag in ("parent", "child"):
            el = _first(j, tag)
            if el is None:
                r.add("T404", "error", f"MuJoCo refuses the file: missing element: '{tag}'", j)
            elif not el.get("link"):
                continue  # said by _read
            elif el.get("link") not in links:
                r.add("T407", "error", f"MuJoCo refuses the file: URDF joint parent or child "
                      f"missing ({el.get('link')!r})", el)
            else:
                ends.append(el.get("link") or "")
        if len(ends) == 2:
            if ends[1] in parents:
                r.add("T408", "error", f"MuJoCo refuses the file: URDF body has multiple "
                      f"parents ({ends[1]!r})", j)
            parents[ends[1]] = ends[0]
    _reach(links, parents, r)


def _reach(links: dict[str, El], parents: dict[str, str], r: RuleReport) -> None:
    """Every link reached from a root: else a loop, or a link that is its own parent."""
    roots = [n for n in links if n not in parents]
    reached = set(roots)
    frontier = list(roots)
    while frontier:
        link = frontier.pop()
        for child, parent in parents.items():
            if parent == link and child not in reached:
                reached.add(child)
                frontier.append(child)
    lost = [n for n in links if n not in reached]
    if lost and not any(f.code == "T408" for f in r.findings):
        r.add("T408", "error", f"MuJoCo refuses the file: URDF body not found (link {lost[0]!r} "
              "is in a loop, or its own parent)", links[lost[0]])


# --------------------------------------------------------------------------- the compiler

def _compile(root: El, links: dict[str, El], joints: list[El], options: dict[str, str],
             r: RuleReport) -> None:
    kind_of = {}
    parent_of: dict[str, tuple[str, El]] = {}
    for j in joints:
        p, c = _first(j, "parent"), _first(j, "child")
        if p is not None and c is not None:
            parent_of[c.get("link") or ""] = (p.get("link") or "", j)
            kind_of[c.get("link") or ""] = j.get("type") or ""
    meshes = _MeshPlace(r.folder, options)
    for name, link in links.items():
        _inertia(name, link, options.get("balanceinertia") == "true", r)
        for part in link:
            if part.tag == "collision" or (part.tag == "visual"
                                           and options.get("discardvisual") == "false"):
                _collision(part, meshes, r)
    for j in joints:
        _axis_and_limits(j, r)
    _masses(links, parent_of, kind_of, r)
    for parent, j in parent_of.values():
        if j.get("type") == "floating" and _moving(parent, parent_of):
            r.add("T425", "error", "MuJoCo refuses the file: free joint can only be used on "
                  f"top level (joint {j.get('name')!r} under a moving link)", j)
    roots = [n for n in links if n not in parent_of and n != "world"]
    if roots:
        r.add("T450", "warning", f"MuJoCo's URDF reader welds the root link {roots[0]!r} to "
              "the world: the robot cannot move as a whole (PyBullet's base is free); "
              "`urdfkit export mjcf` writes a model with a free base", links[roots[0]])
    fixed = [j for j in joints if j.get("type") == "fixed"]
    if fixed and options.get("fusestatic") != "false":
        r.add("T451", "info", f"{len(fixed)} fixed joint(s) are fused away by MuJoCo's "
              "reader: their child links are no bodies of the model (their mass joins the "
              "parent's), and sites or sensors cannot name them", fixed[0])


def _moving(link: str, parent_of: dict[str, tuple[str, El]]) -> bool:
    """Whether ``link`` moves relative to the world (a moving joint on its way to the root)."""
    seen = set()
    while link in parent_of and link not in seen:
        seen.add(link)
        parent, j = parent_of[link]
        if j.get("type") != "fixed":
            return True
        link = parent
    return False


def _inertia(name: str, link: El, balance: bool, r: RuleReport) -> None:
    inertial = _first(link, "inertial")
    inertia = _first(inertial, "inertia") if inertial is not None else None
    if inertia is None:
        return
    found = principal_moments(inertia)
    if found is None:
        return
    _trace, _tol, a, b, c, text = found
    if a == b == c == 0:
        return
    if not all(map(math.isfinite, (a, b, c))) or a <= 0:
        r.add("T421", "error", f"MuJoCo refuses the file: link {name!r}: inertia must have "
              f"positive eigenvalues (principal moments {text})", inertia)
    elif a + b < c - MINVAL and not balance:
        r.add("T421", "error", f"MuJoCo refuses the file: link {name!r}: inertia must satisfy "
              f"A + B >= C (principal moments {text})", inertia)


class _MeshPlace:
    """Where MuJoCo's reader looks for a mesh.

    The file's folder joined with the extension's ``meshdir``; with ``strippath`` the mesh's
    name alone (so ``package://`` meshes are found there).
    """

    def __init__(self, folder: str | None, options: dict[str, str]) -> None:
        self.folder = folder
        self.meshdir = options.get("meshdir", "")
        self.strip = options.get("strippath") == "true"

    def path(self, filename: str) -> str | None:
        if self.strip:
            filename = filename.replace("\\", "/").rsplit("/", 1)[-1]
        if os.path.isabs(filename):
            return filename
        if self.folder is None:
            return None
        return os.path.join(self.folder, self.meshdir, filename)


def _collision(col: El, meshes: _MeshPlace, r: RuleReport) -> None:
    geometry = _first(col, "geometry")
    shape = next((c for c in geometry if isinstance(c.tag, str)), None) \
        if geometry is not None else None
    if shape is None:
        return
    sizes = {"box": ("size",), "sphere": ("radius",), "cylinder": ("radius", "length")}
    for attr in sizes.get(str(shape.tag), ()):
        values = [number(p) for p in (shape.get(attr) or "").split()]
        if any(v <= 0 for v in values):
            r.add("T424", "error", f"MuJoCo refuses the file: {attr} must be positive in "
                  f"geom ({str(shape.tag)} {attr}={shape.get(attr)!r})", shape)
            return
    if shape.tag == "mesh" and shape.get("filename"):
        why = _mesh_problem(shape.get("filename") or "", meshes)
        if why:
            r.add("T426", "error", f"MuJoCo refuses the file: {str(col.tag)} mesh "
                  f"{shape.get('filename')!r}: {why}", shape)


def _mesh_problem(filename: str, meshes: _MeshPlace) -> str | None:
    if "://" in filename and not meshes.strip:
        return "Error opening file (MuJoCo reads no package://, model:// or file:// URI)"
    path = meshes.path(filename)
    if path is None:
        return None
    if not os.path.isfile(path):
        return "Error opening file"
    if filename.lower().endswith(".stl"):
        try:
            size = os.path.getsize(path)
            with open(path, "rb") as f:
                head = f.read(84)
        except OSError:
            return "Error opening file"
        faces = int.from_bytes(head[80:84], "little") if len(head) == 84 else 0
        if not 1 <= faces <= STL_FACES or size < 84 + 50 * faces:
            return f"stl_decoder: number of faces should be between 1 and {STL_FACES} " \
                   "(an ASCII STL, or a larger one)"
    if filename.lower().endswith(".dae"):
        return "no decoder found for mesh file (MuJoCo reads no COLLADA)"
    return None


def _axis_and_limits(j: El, r: RuleReport) -> None:
    kind = j.get("type")
    axis = _first(j, "axis")
    if kind in MOVING and axis is not None and axis.get("xyz") is not None:
        values = [number(p) for p in (axis.get("xyz") or "").split()]
        if sum(v * v for v in values) < 1e-20:
            r.add("T423", "error", f"MuJoCo refuses the file: axis too small in joint "
                  f"{j.get('name')!r}", axis)
    limit = _first(j, "limit")
    if limit is None or kind not in MOVING:
        return
    lower, upper = limit.get("lower") or None, limit.get("upper") or None  # "" is absent
    why = None
    if kind == "continuous" and (lower is not None or upper is not None):
        why = "MuJoCo never limits a continuous joint (PyBullet reports the bounds)"
    elif kind != "continuous" and (lower is None) != (upper is None):
        why = "with only one of lower and upper MuJoCo leaves it unlimited"
    elif lower is not None and upper is not None and number(lower) >= number(upper):
        why = "with lower >= upper MuJoCo leaves it unlimited (PyBullet's 'no limit' too)" \
            if number(lower) > number(upper) else "equal lower and upper: MuJoCo ignores " \
            "the limit, with a warning"
    if why:
        r.add("T455", "warning", f"joint {j.get('name')!r}: {why}", limit)


def _masses(links: dict[str, El], parent_of: dict[str, tuple[str, El]],
            kind_of: dict[str, str], r: RuleReport) -> None:
    """Moving bodies need mass and inertia, their fixed descendants' included."""
    own: dict[str, tuple[float, bool]] = {}  # mass, whether it has an inertia (or shapes)
    for name, link in links.items():
        inertial = _first(link, "inertial")
        if inertial is None:
            shapes = any(True for _ in _children(link, "collision"))
            if shapes and name not in ("world",):
                r.add("T453", "warning", f"link {name!r} has no <inertial>: MuJoCo's reader "
                      "gives it the mass of its collision shapes filled with water "
                      "(1000 kg/m^3); PyBullet gives it 1 kg", link)
            own[name] = (1.0 if shapes else 0.0, shapes)
            continue
        mass_el, inertia = _first(inertial, "mass"), _first(inertial, "inertia")
        mass = number(mass_el.get("value") or "0") if mass_el is not None else 0.0
        found = principal_moments(inertia) if inertia is not None else None
        own[name] = (mass, found is not None and found[2] > MINVAL)
    body_of = {}
    for name in links:
        body = name
        while body in parent_of and kind_of.get(body) == "fixed":
            body = parent_of[body][0]
        body_of[name] = body
    total: dict[str, tuple[float, bool]] = {}
    for name, (mass, spread) in own.items():
        m, i = total.get(body_of[name], (0.0, False))
        total[body_of[name]] = (m + mass, i or spread)
    for body, (mass, spread) in total.items():
        if body in parent_of and kind_of.get(body) in MOVING | {"floating", "planar",
                                                             "spherical"}:
            if mass < MINVAL or not spread:
                r.add("T420", "error", f"MuJoCo refuses the file: mass and inertia of moving "
                      f"bodies must be larger than mjMINVAL (link {body!r}, with what is "
                      f"fixed to it: {mass:g} kg{'' if spread else ', no inertia'})",
                      links[body])
