"""check's rules on mesh files (U613-U614, U701-U705, U712-U715).

Files that exist and are read, units, concavity, and the meshes PyBullet crashes on or draws
nothing of.
"""

from __future__ import annotations

import math
import os

from lxml import etree

from urdfkit.checks.rules_mass import mesh_properties_of, moving_of
from urdfkit.model.spec import attr_vec as _vec
from urdfkit.sources.guard import RuleReport
from urdfkit.sources.meshstore import CONCAVE_FRACTION
from urdfkit.sources.references import label, mesh_crash


def rule_meshes(root: etree._Element, r: RuleReport) -> None:
    """U701-U705: mesh and texture files exist, are files, in formats PyBullet reads."""
    if r.folder is None:
        return
    doc = r.doc(root)
    for el in doc.files:
        fn = (el.get("filename") or "").strip()
        if fn and el not in doc.unread:  # a mesh after the first shape is never opened
            ref = r.reference(el.tag, fn)
            if ref.code is not None:
                r.add(ref.code, ref.level, ref.message, el)


def rule_mesh_crashes(root: etree._Element, r: RuleReport) -> None:
    """U712-U713: mesh files PyBullet crashes or hangs on, which every loader refuses.

    The guard's own rule (:func:`urdfkit.sources.guard.mesh_crash`), said as a finding: COLLADA
    PyBullet's reader crashes on, NaN vertices in a collision mesh it builds a hull of.
    """
    if r.folder is None:
        return
    for _, _, _, mesh in r.parts(root):
        if mesh is None or mesh.tag != "mesh":
            continue
        fn = (mesh.get("filename") or "").strip()
        if not fn or (ref := r.reference("mesh", fn)).load is None or (
                ref.code is not None and ref.level == "error"):
            continue
        crash = mesh_crash(mesh, ref)
        if crash is not None:
            r.add(crash[0], "error", crash[1], mesh)


def rule_visual_meshes(root: etree._Element, r: RuleReport) -> None:
    """U715: a visual mesh PyBullet draws nothing or only part of.

    An empty file, or COLLADA placing its parts through ``<instance_node>`` (robots exported
    from some CAD tools): PyBullet loads the robot and draws nothing of that link, without a
    word on stdout. Only ``.dae`` files are read (a substring search first); an empty file is
    known from its stat.
    """
    if r.folder is None:
        return
    for view, part, _, mesh in r.parts(root):
        if part.tag != "visual" or mesh is None or mesh.tag != "mesh":
            continue
        fn = (mesh.get("filename") or "").strip()
        if not fn or (ref := r.reference("mesh", fn)).load is None:
            continue
        empty = ref.stat is not None and ref.stat.st_size == 0
        # meshes.mesh_kind(ref.load), without importing the mesh readers for every check run
        # (and without splitting names that cannot end in .dae)
        if not empty and (ref.load[-4:].lower() != ".dae"
                          or os.path.splitext(ref.load)[1].lower() != ".dae"):
            continue
        from urdfkit.sources.meshes import undrawn_visual

        why = undrawn_visual(ref.load)
        if why is not None:
            r.add("U715", "warning", f"visual mesh {fn!r} of {label(view.el)} {why}; "
                  "the robot looks incomplete in render, view and the GUI (export it "
                  "with its nodes flattened, or as .obj/.stl)", mesh)


#: A mesh this many times larger (or smaller) than the robot's typical joint spacing is in
#: the wrong units (millimetres read as metres gives 1000x).
UNITS_RATIO = 200.0


def rule_mesh_shapes(root: etree._Element, r: RuleReport) -> None:
    """U613-U614: meshes in the wrong units; concave collision meshes on links that move.

    Units are judged against the robot's own scale: the median distance between joint
    frames (a model with fewer than two offset joints has no scale, and is not judged).
    PyBullet collides with the convex hull of a mesh (one per OBJ object), so a concave
    collision mesh on a moving link touches where it has a dip; the root's rigid group is not
    judged (a static or bolted base may use ``<collision concave="yes">`` instead).
    """
    if r.folder is None:
        return
    doc = r.doc(root)
    offsets = sorted(math.sqrt(sum(x * x for x in xyz)) for jv in doc.joints
                     if (xyz := _vec(jv.origin, "xyz", 3)) is not None and any(xyz))
    spacing = offsets[len(offsets) // 2] if len(offsets) >= 2 else None
    moving = moving_of(r, root)
    if not spacing and not moving:
        return  # neither finding can be made of any mesh
    for view, part, _, mesh in r.parts(root):
        link = view.el
        concave_matters = part.tag == "collision" and view.name in moving
        if not spacing and not concave_matters:
            continue  # neither finding can be made of this mesh
        fn = (mesh.get("filename") or "").strip() if mesh is not None and \
            mesh.tag == "mesh" else ""
        if not fn or (ref := r.reference("mesh", fn)).load is None:
            continue
        scale = _vec(mesh, "scale", 3, (1.0, 1.0, 1.0))
        props = mesh_properties_of(r, ref.load, scale, concave_matters, ref.stat) \
            if scale else None
        if props is None:
            continue
        size = max(props.extent)
        if spacing and size > 0 and not 1 / UNITS_RATIO <= size / spacing <= UNITS_RATIO:
            ratio = size / spacing
            fix = ("probably in millimetres: add scale=\"0.001 0.001 0.001\"" if ratio > 1
                   else "probably scaled twice, or in metres where millimetres were meant: "
                   "check its scale")
            r.add("U613", "warning", f"mesh {fn!r} of {label(link)} is {size:.3g} m across, "
                  f"{ratio:.3g} times the robot's typical joint spacing ({spacing:.3g} m): "
                  f"{fix}", mesh)
        if concave_matters and props.concavity > CONCAVE_FRACTION * size:
            r.add("U614", "warning", f"collision mesh {fn!r} of moving {label(link)} is "
                  f"concave (it is {size:.3g} m across, and parts of it stand up to "
                  f"{props.concavity:.3g} m in front of its own faces' planes"
                  + ("" if props.closed else "; it is also open, so the depth is "
                     "judged on the faces it has") + "): PyBullet "
                  "collides with its convex hull, so contacts happen in mid-air over the "
                  "dips; split it into convex parts (p.vhacd, or one OBJ object per part) "
                  "or use primitives", mesh)
