"""check's rules on contact parameters (U803-U804).

Gazebo's, which PyBullet ignores, and ``<contact>`` values that are no contact.
"""

from __future__ import annotations

import math

from lxml import etree

from urdfkit.model.index import first
from urdfkit.model.spec import attr_float as _num
from urdfkit.sources.guard import RuleReport
from urdfkit.sources.references import label


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
