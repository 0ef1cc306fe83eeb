"""What PyBullet computes for a URDF that the MJCF writer mirrors, and what fix writes instead.

PyBullet's recomputed inertia (:func:`loaded_inertials`), and, for a tensor PyBullet zeroes,
the one ``urdfkit fix`` writes (:func:`zeroed_repairs`).
"""

from __future__ import annotations

import copy
from typing import Any

from urdfkit.formats.robot import LoadedInertial, LoadedRobot, read_inertial


def loaded_inertials(resolved: Any, *, inertia_from_file: bool) -> dict[str, LoadedInertial]:
    """Each link's mass properties as PyBullet loads them, in the link frame.

    Without ``inertia_from_file`` PyBullet discards the file's ``<inertia>`` and computes one
    from the collision shapes' bounding boxes (a link without collision shapes gets a tiny
    sphere's, 6.7e-7 for 1 kg): ``export --inertia-from-shapes`` writes these.
    """
    from urdfkit.engine.inertials import link_tensor, loaded_dynamics

    loaded = loaded_dynamics(resolved.load_path, inertia_from_file=inertia_from_file,
                             display=resolved.name)
    return {name: LoadedInertial(d.mass, d.inertial_position, link_tensor(d))
            for name, d in loaded.items()}


def zeroed_repairs(resolved: Any, robot: LoadedRobot, inertials: dict[str, LoadedInertial]
                   ) -> dict[str, tuple[LoadedInertial, str, str, str]]:
    """The links PyBullet simulates with a singular tensor, each with what ``fix`` writes.

    PyBullet sets a tensor that breaks the triangle inequality to zero ("Bad inertia tensor
    properties"): the file gave one, PyBullet loaded none; and a file may give a singular one
    itself (laikago's chassis: 0 0 0; biped2d's y_prismatic: a moment of 5e-18), which
    PyBullet loads as it is. MuJoCo refuses either on a moving body. For each such link: its
    mass properties as read from the link fix would write (mass and centre kept, the
    ``<inertia>`` of :func:`urdfkit.checks.fix.triangle_repair`), that ``<inertia>`` element,
    and how it was made. Where fix has nothing to write (no collision solid, and a tensor
    that cannot be balanced: reachy's ``r_antenna``, romeo's thighs), the tensor PyBullet
    itself computes from the collision shapes' box without URDF_USE_INERTIA_FROM_FILE.
    """
    import numpy as np

    zeroed = {}
    for name, link in robot.links.items():
        if name not in inertials or not link.inertial.given or not link.inertial.mass > 0:
            continue
        loaded = np.array(inertials[name].tensor)
        if not np.isfinite(loaded).all() or np.linalg.eigvalsh(loaded)[0] > 1e-15:
            continue  # mjMINVAL: MuJoCo's floor for a moving body's principal moments
        if not loaded.any() and any(link.inertial.tensor[k][k] for k in range(3)):
            zeroed[name] = "a zero tensor: the file's breaks the triangle inequality, and " \
                "PyBullet zeroes it"
        else:
            moments = ", ".join(f"{x:.3g}" for x in np.linalg.eigvalsh(loaded))
            zeroed[name] = f"the file's singular tensor (principal moments {moments})"
    if not zeroed:
        return {}
    from lxml import etree

    from urdfkit.checks.fix import triangle_repair
    from urdfkit.sources.guard import RuleReport

    report = RuleReport(resolved.name, resolved.source.absolute().parent)
    elements = {el.get("name", ""): el for el in resolved.root.iterchildren("link")}
    out: dict[str, tuple[LoadedInertial, str, str, str]] = {}
    boxes: dict[str, LoadedInertial] = {}
    for name in zeroed:
        given = robot.links[name].inertial
        if name not in elements:
            continue
        found = triangle_repair(elements[name], report, given.mass)
        if found is None:  # PyBullet's own inertia without the file's, from the shapes' box
            boxes = boxes or loaded_inertials(resolved, inertia_from_file=False)
            found = triangle_repair(elements[name], report, given.mass,
                                    boxes[name].tensor if name in boxes else None)
        if found is None:
            continue
        fixed = copy.deepcopy(elements[name])
        inertial = fixed.find("inertial")
        inertial.replace(inertial.find("inertia"), etree.fromstring(found[0]))
        repaired = read_inertial(fixed)
        repaired.line = given.line
        out[name] = (repaired, found[0], found[1], zeroed[name])
    return out
