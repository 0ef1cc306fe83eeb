"""What Pinocchio 4 refuses, and what its model holds that PyBullet's does not.

Pinocchio reads a URDF through urdfdom, then builds its own model (its
``src/parsers/urdf/model.hxx`` and ``model.cpp``), so it refuses all urdfdom refuses
(``T200``, urdfdom's reason given) and more. Measured with ``pinocchio.buildModelFromUrdf``
(tests/test_check_targets.py loads every rule's fixture in it).
"""

from __future__ import annotations

from lxml import etree

from urdfkit.checks.targets_ros import (
    _children,
    _first,
    is_double,
    read_by_urdfdom,
    vector_problem,
    version,
)
from urdfkit.model.spec import depth_first
from urdfkit.sources.guard import RuleReport

El = etree._Element

CODES: dict[str, str] = {
    "T200": "pinocchio: urdfdom, which Pinocchio reads through, refuses the file",
    "T201": "pinocchio: a negative <limit> effort or velocity, or <dynamics> friction",
    "T204": "pinocchio: a link that is the child of two joints, or its own parent",
    "T220": "pinocchio: fixed joints are frames, their links' inertia merged (info)",
    "T222": "pinocchio: a link without <inertial> has mass 0 (PyBullet: 1 kg) (warning)",
    "T223": "pinocchio: continuous joints have two coordinates (cos, sin) in q (info)",
    "T224": "pinocchio: a floating joint is a free flyer (PyBullet: a fixed joint) (warning)",
    "T225": "pinocchio: a planar joint moves in the XY plane whatever its axis (warning)",
    "T226": "pinocchio: a zero joint axis: forward kinematics gives no rotation (warning)",
    "T227": "pinocchio: joints in another order than PyBullet's (siblings by name) (info)",
}


def rule_pinocchio(root: El, r: RuleReport) -> None:
    """T2xx: what Pinocchio refuses (errors) and changes (warnings, info)."""
    refusals = read_by_urdfdom(root, r)
    for _code, reason, el in refusals:
        r.add("T200", "error", f"Pinocchio refuses the file: its urdfdom says: {reason}", el)
    if refusals:
        return
    v = version(root)
    assert v is not None
    joints = list(_children(root, "joint"))
    for j in joints:
        _limits(j, r)
    _tree(root, joints, r)
    for link in _children(root, "link"):
        if _first(link, "inertial") is None and link.get("name") != "world":
            r.add("T222", "warning", f"link {link.get('name')!r} has no <inertial>: mass 0 "
                  "and no inertia in Pinocchio, 1 kg and unit inertia in PyBullet; give it "
                  "its <inertial> (urdfkit fix writes one from its shapes)", link)
    moving = [j for j in joints if j.get("type") not in ("fixed", None)]
    fixed = [j for j in joints if j.get("type") == "fixed"]
    if fixed:
        r.add("T220", "info", f"{len(fixed)} fixed joint(s) ({_names(fixed)}) are frames in "
              "Pinocchio, not joints: their links' inertia is merged into the moving link "
              "above, and joint indices differ from PyBullet's, which counts them", fixed[0])
    continuous = [j for j in moving if j.get("type") == "continuous"]
    if continuous:
        r.add("T223", "info", f"continuous joint(s) {_names(continuous)}: two coordinates "
              "each in Pinocchio's q (cos, sin; nq = nv + 1 per joint), one in PyBullet's",
              continuous[0])
    for j in moving:
        _axis(j, r)
        if j.get("type") == "floating":
            r.add("T224", "warning", f"joint {j.get('name')!r} is floating: a free flyer in "
                  "Pinocchio (7 coordinates, 6 velocities), a fixed joint in PyBullet, which "
                  "does not simulate floating joints", j)
    _order(root, joints, r)


def _names(joints: list[El]) -> str:
    shown = ", ".join(repr(j.get("name")) for j in joints[:4])
    return shown + (", ..." if len(joints) > 4 else "")


def _limits(j: El, r: RuleReport) -> None:
    limit, dyn = _first(j, "limit"), _first(j, "dynamics")
    for el, attr, field in ((limit, "effort", "effort"), (limit, "velocity", "velocity"),
                            (dyn, "friction", "dry_friction")):
        text = el.get(attr) if el is not None else None
        if text is not None and is_double(text) and float(text) < 0 \
                and j.get("type") not in ("fixed", "floating", "planar"):
            r.add("T201", "error", f"Pinocchio refuses the file: joint {j.get('name')!r} "
                  f"{attr} {text} is negative (\"Some components of min_{field} are greater "
                  f"than max_{field}\")", el)
            return


def _tree(root: El, joints: list[El], r: RuleReport) -> None:
    seen: dict[str, El] = {}
    for j in joints:
        parent, child = _first(j, "parent"), _first(j, "child")
        p = parent.get("link") if parent is not None else None
        c = child.get("link") if child is not None else None
        if c is None:
            continue
        if c == p or c in seen:
            r.add("T204", "error", f"Pinocchio refuses the file: link {c!r} is "
                  f"{'its own parent' if c == p else 'the child of two joints'} (\"Model "
                  f"does not have any body named ...\")", j)
            return
        seen[c] = j


def _axis(j: El, r: RuleReport) -> None:
    axis = _first(j, "axis")
    kind = j.get("type")
    if axis is None:
        return
    text = axis.get("xyz")
    values = [0.0, 0.0, 0.0] if text is None else \
        [float(p) for p in text.split(" ") if p] if vector_problem(text) is None else None
    if values is None:
        return
    if kind == "planar":
        if any(abs(x) > 1e-12 for x in values[:2]):
            r.add("T225", "warning", f"planar joint {j.get('name')!r}: Pinocchio's moves in "
                  f"the XY plane (normal z) whatever its axis ({text}); PyBullet's in the "
                  "plane normal to the axis", axis)
        return
    if kind in ("revolute", "continuous", "prismatic") and not any(values):
        r.add("T226", "warning", f"joint {j.get('name')!r} has the zero axis: Pinocchio loads "
              "it and its forward kinematics gives matrices that are no rotations; give the "
              "joint its axis", axis)


def pybullet_order(root: El, joints: list[El]) -> list[str]:
    """PyBullet's order of the moving joints: depth first, children in file order."""
    return _depth_first(root, joints, sort=False)


def pinocchio_order(root: El, joints: list[El]) -> list[str]:
    """Pinocchio's: depth first, each link's child joints by name (urdfdom's std::map)."""
    return _depth_first(root, joints, sort=True)


def _depth_first(root: El, joints: list[El], *, sort: bool) -> list[str]:
    """The moving joints in a pre-order walk from the root (``model.spec.depth_first``).

    A link's child joints are taken in file order, or by name (``sort``).
    """
    below: dict[str, list[tuple[str, str, str]]] = {}
    children = set()
    for j in joints:
        parent, child = _first(j, "parent"), _first(j, "child")
        p = parent.get("link") if parent is not None else None
        c = child.get("link") if child is not None else None
        if p is None or c is None:
            continue
        below.setdefault(p, []).append((j.get("name") or "", c, j.get("type") or ""))
        children.add(c)
    roots = [name for link in _children(root, "link")
             if (name := link.get("name")) is not None and name not in children]
    if not roots:
        return []
    if sort:
        below = {link: sorted(edges) for link, edges in below.items()}
    return [name for name, _, kind in depth_first(roots[0], below, lambda e: e[1])
            if kind != "fixed"]


def _order(root: El, joints: list[El], r: RuleReport) -> None:
    ours, theirs = pybullet_order(root, joints), pinocchio_order(root, joints)
    if ours == theirs:
        return
    at = next(i for i, (a, b) in enumerate(zip(ours, theirs, strict=True)) if a != b)
    r.add("T227", "info", f"Pinocchio orders the moving joints otherwise than PyBullet: "
          f"from index {at} PyBullet has {', '.join(ours[at:at + 3])}, Pinocchio "
          f"{', '.join(theirs[at:at + 3])} (it takes a link's child joints by name); map "
          "q and v by joint name (urdfkit joints --json gives PyBullet's)", root)
