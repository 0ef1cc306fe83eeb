"""Validation of URDF documents: ``check``'s rules beyond the guard.

Rules work on the lxml tree (not on a parsed model) so that every finding can carry the line
it comes from, and so that broken files are described rather than refused at the first error.
The rules every loader runs, and the :class:`~urdfkit.sources.guard.RuleReport` they all write
to, are in :mod:`urdfkit.sources.guard`; :data:`ALL_RULES` is the guard's rules followed by
these.
"""

from __future__ import annotations

from lxml import etree

from urdfkit.checks.rules_contacts import rule_contact_values, rule_gazebo_contacts
from urdfkit.checks.rules_joints import rule_damping, rule_mimic
from urdfkit.checks.rules_mass import rule_inertia, rule_mass
from urdfkit.checks.rules_meshes import (
    rule_mesh_crashes,
    rule_mesh_shapes,
    rule_meshes,
    rule_visual_meshes,
)
from urdfkit.checks.targets import TARGET_CODES
from urdfkit.model.spec import (
    EXTENSIONS,
    LIMITED_JOINT_TYPES,
    MAX_STATE_LINKS,
    extension_note,
)
from urdfkit.sources.guard import GUARD_RULES, Rule, RuleReport
from urdfkit.sources.references import label

# --------------------------------------------------------------------------- structural rules
# These are the rules PyBullet crashes on when they are broken; the guard runs exactly these.


def rule_link_count(root: etree._Element, r: RuleReport) -> None:
    """U208: 128 links or more break PyBullet's state queries."""
    n = len(r.doc(root).links)
    if n >= MAX_STATE_LINKS:
        r.add("U208", "error", f"{n} links: PyBullet's getJointState/getLinkState fail on "
              f"bodies with {MAX_STATE_LINKS} links or more (MAX_DEGREE_OF_FREEDOM); split "
              "the model", root)


# --------------------------------------------------------------------------- values and physics
# Numbers are parsed once per attribute by _num/_vec, which never report: rule_numbers reports
# every malformed number once, and the other rules simply skip what does not parse.

def rule_elements(root: etree._Element, r: RuleReport) -> None:
    """U401-U402 and U801-U802: numbers and names of tags and attributes.

    Numbers parse, are finite and have the right length; tags and attributes are known
    (typos, or extensions PyBullet ignores). Judged on the document's one walk
    (:class:`~urdfkit.model.index.Doc`), which skips comments, namespaced elements (xacro
    leftovers, extensions), opaque subtrees (another tool's: gazebo, transmission, ...) and
    shapes after the first in a ``<geometry>``.
    """
    found = r.doc(root).element_findings
    if not found:
        return  # most files (and no import statement run for them)
    from urdfkit.model.spec import did_you_mean, nearest_attributes, nearest_tags

    for code, level, message, el in found:
        if code == "U801" and el.tag == "gazebo":
            continue  # another tool's block, PyBullet ignores it: U803 judges its contacts
        # The verdicts are shared between elements; the nearest name is added per finding.
        if code == "U801":
            parent = el.getparent()
            if parent is not None:
                message += did_you_mean(nearest_tags(el.tag, parent.tag))
        elif code == "U802":
            for attr in el.keys():
                if f"unknown attribute {attr!r};" in message:
                    message += did_you_mean(nearest_attributes(attr, el.tag), tags=False)
                    break
        r.add(code, level, message, el)


def rule_material_colours(root: etree._Element, r: RuleReport) -> None:
    """U710: one material name given several colours; PyBullet draws them all in one.

    Measured on PyBullet 3.2.7: every visual whose material has that name (``""`` included,
    at the top level or inline) is drawn in the colour written last in the file.
    """
    materials = r.doc(root).all_materials
    if len(materials) < 2:
        return  # no name can be given two colours
    colours: dict[str, list[tuple[str, etree._Element]]] = {}
    for m in materials:
        name = m.get("name")
        if name is None:
            continue
        color = _child(m, "color")
        if color is None or color.get("rgba") is None:
            continue
        colours.setdefault(name, []).append((" ".join(color.get("rgba", "").split()), color))
    for name, found in colours.items():
        if len(found) < 2:
            continue  # one colour given
        distinct = list(dict.fromkeys(c for c, _ in found))
        if len(distinct) < 2:
            continue
        shown = ", ".join(distinct[:4]) + (f" and {len(distinct) - 4} more"
                                           if len(distinct) > 4 else "")
        r.add("U710", "warning", f"material name {name!r} is given {len(distinct)} colours "
              f"({shown}): PyBullet draws every visual named so in the last one written, "
              f"rgba {found[-1][0]}; give each colour its own name", found[1][1])


def rule_references(root: etree._Element, r: RuleReport) -> None:
    """U308, U706-U708: references that lead nowhere, and limits PyBullet reads differently.

    A ``<material name>`` used but never defined, a ``<transmission>`` naming a missing joint,
    an empty ``<texture/>``, ``package:///`` without a package name, and a revolute or
    prismatic ``<limit>`` without lower/upper (PyBullet: unlimited; the URDF spec: 0..0).
    """
    doc = r.doc(root)
    # (material, whether it has a <color> or <texture> child), each looked at once
    given = [(m, _defines_colour(m)) for m in doc.all_materials]
    defined = {m.get("name") for m, has in given if has}
    for m, has in given:
        if has:
            continue
        parent = m.getparent()
        if (parent is not None and parent.tag == "visual" and m.get("name")
                and m.get("name") not in defined):
            r.add("U706", "warning", f"<material name={m.get('name')!r}> is used but never "
                  "defined with a <color> or <texture>; PyBullet draws the default colour", m)
    # One look at each filename; all U707 first, then all U708, as two passes gave them.
    empty, rooted = [], []
    for el in doc.files:
        fn = (el.get("filename") or "").strip()
        if not fn:
            if el.tag == "texture":
                empty.append(el)
        elif fn.startswith("package:///"):
            rooted.append(el)
    for t in empty:
        r.add("U707", "warning", "<texture> without a filename; remove it or name the "
              "image", t)
    for el in rooted:
        r.add("U708", "info", f"<{el.tag} filename={el.get('filename')!r}>: package:/// "
              "has no package name; PyBullet and urdfkit look the path up beside the file "
              "and in every folder above, ROS tools refuse it", el)
    joints = {jv.name for jv in doc.joints} if doc.transmissions else set()
    for t in doc.transmissions:
        for j in t.iter("joint"):
            if j.get("name") and j.get("name") not in joints:
                r.add("U709", "warning", f"<transmission name={t.get('name')!r}> names joint "
                      f"{j.get('name')!r}, which does not exist", j)
    for jv in doc.joints:
        j, limit = jv.el, jv.limit
        if (jv.type in LIMITED_JOINT_TYPES and limit is not None
                and (limit.get("lower") is None or limit.get("upper") is None)):
            missing = " and ".join(a for a in ("lower", "upper") if limit.get(a) is None)
            r.add("U308", "warning", f"<limit> of {label(j)} has no {missing}: PyBullet reads "
                  "it as unlimited, the URDF spec (and ROS) as 0; give both", limit)


def _defines_colour(material: etree._Element) -> bool:
    """Whether a ``<material>`` has a ``<color>`` or ``<texture>`` child."""
    for c in material:  # first(m, "color") or first(m, "texture"), in one look
        if c.tag == "color" or c.tag == "texture":
            return True
    return False


def _child(el: etree._Element, tag: str) -> etree._Element | None:
    """``first(el, tag)``: the first child named ``tag``, by a loop (no iterator object)."""
    for c in el:
        if c.tag == tag:
            return c
    return None


def rule_portability(root: etree._Element, r: RuleReport) -> None:
    """U901: PyBullet-only joint types and shapes, which other URDF tools refuse (info)."""
    doc = r.doc(root)
    for jv in doc.joints:
        note = extension_note("joint", jv.type if jv.type is not None else "")
        if note:
            r.add("U901", "info", f"{label(jv.el)}: {note}", jv.el)
    for geom in doc.geometries:
        for shape in geom:
            note = _SHAPE_NOTES.get(shape.tag)  # a comment's tag is a function: no note
            if note:
                r.add("U901", "info", note, shape)


#: extension_note("shape", tag) by tag, one lookup a shape.
_SHAPE_NOTES = {key.partition(":")[2]: note for key, note in EXTENSIONS.items()
                if key.startswith("shape:")}


#: Every rule ``urdfkit check`` runs, in order.
ALL_RULES: tuple[Rule, ...] = (*GUARD_RULES, rule_link_count, rule_elements, rule_mass,
                               rule_inertia, rule_meshes, rule_mesh_crashes, rule_mesh_shapes,
                               rule_visual_meshes, rule_references, rule_material_colours,
                               rule_mimic, rule_damping, rule_gazebo_contacts, rule_contact_values,
                               rule_portability)

#: Every finding code with a one-line summary (for ``--select``/``--ignore`` and the docs).
CODES: dict[str, str] = {
    "U000": "file unreadable or not well-formed XML",
    "U004": "XML quirk PyBullet tolerates but other parsers refuse",
    "U005": "elements nested deeper than PyBullet's XML parser reads (98 levels)",
    "U006": "xacro not expanded: executing it is disabled (--no-exec, URDFKIT_NO_EXEC)",
    "U007": "xacro macro library (no links of its own): checked through its includers",
    "U008": "line longer than 8191 bytes: PyBullet breaks it and may misread the file",
    "U009": "a file not named .xacro that holds xacro: read literally ('${prefix}base')",
    "U010": "a fragment another checked file includes (no robot alone): checked through it",
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
    "U310": "<mimic> that PyBullet ignores (the joint moves on its own; info)",
    "U311": "joint damping too large for what the joint moves: PyBullet's 1/240 s step is unstable",
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
    "U702": "package:// package not found, or a path climbing out of its package",
    "U703": "mesh found only through pybullet_data's search path",
    "U704": "mesh or texture is a directory, FIFO, device or unreadable",
    "U705": "mesh in a format PyBullet does not read (it reads .stl, .obj, .dae)",
    "U706": "material used but never defined",
    "U707": "<texture> without a filename",
    "U708": "package:/// without a package name",
    "U709": "transmission names a missing joint",
    "U710": "one material name given several colours (PyBullet draws them all in the last)",
    "U711": "package:// found only through a package.xml, which raw PyBullet does not read",
    "U712": "COLLADA mesh PyBullet's reader crashes on (no <asset> or <library_geometries>, ...)",
    "U713": "collision mesh with NaN beside numbers on an axis: PyBullet's hull crashes or hangs",
    "U715": "visual mesh PyBullet draws nothing or only part of (empty, COLLADA <instance_node>)",
    "U801": "unknown tag",
    "U802": "unknown attribute",
    "U803": "Gazebo contact parameters (mu1, mu2, kp, kd) PyBullet ignores (fix --gazebo-contacts)",
    "U804": "<contact> that is no contact: stiffness not positive (the link sinks), negative "
            "damping or friction",
    "U901": "PyBullet extension (spherical joint, capsule, plane, cdf): not portable",
    "U950": "links in contact at the zero pose (check --physics: self-collision jitters)",
    "U951": "PyBullet cannot load the file (check --physics)",
    **TARGET_CODES,
}
