"""``agree``'s structure rows: base, joints, masses, the body tree, forces MuJoCo alone applies.

Joint names, order, kinds, limits, damping, armature and friction (1e-12); total and
per-body mass (1e-12 relative), centres of mass (1e-12 m) and inertia about the centre of
mass (1e-9 relative), bodies welded together (fixed links fused; MuJoCo's own welded bodies)
compared as one; the body tree by weld groups (:mod:`urdfkit.exchange.agree_tree`); and what
the MJCF would push the robot with that PyBullet has no counterpart of.
"""

from __future__ import annotations

import math
from typing import Any

from urdfkit.exchange.agree_report import TOL_COM, TOL_EXACT, TOL_INERTIA, worst
from urdfkit.exchange.agree_sides import Sides
from urdfkit.exchange.agree_tree import tree_errors
from urdfkit.formats.fk import fused, link_frames
from urdfkit.formats.mjcf import combine
from urdfkit.formats.robot import LoadedInertial, LoadedRobot

_ZERO3 = ((0.0, 0.0, 0.0), (0.0, 0.0, 0.0), (0.0, 0.0, 0.0))


def structure(s: Sides) -> None:
    """Every structure row."""
    robot, res = s.robot, s.result
    moving_root = not s.options.fixed_base and robot.links[robot.root].inertial.mass != 0 \
        and robot.root != "world"
    want = "free joint" if moving_root else "welded"
    # the root's own free joint: another free body (a loose box) is no robot base
    got = "free joint" if s.root_free() is not None else "welded"
    res.add("structure", "base", None, None, "", f"PyBullet: {want}; MJCF: {got}",
            "pass" if want == got else "fail")
    joint_rows(s)
    mimic = [f"{j.name} = {j.mimic[1]:g} x {j.mimic[0]} + {j.mimic[2]:g}"
             for j in robot.movable() if j.mimic is not None and j.name in s.jnt]
    if mimic:
        res.add("structure", "mimic joints", float(len(mimic)), None, "known",
                "PyBullet ignores <mimic>; an MJCF equality means it: " + "; ".join(mimic),
                status="known")
    masses(s)
    errors, groups = tree_errors(s.mjcf.written, s.mjcf.tree, robot, s.match)
    if groups:
        res.add("structure", "body tree", float(len(errors)), 0.0, "differ",
                "; ".join(errors[:3]) + (" ..." if len(errors) > 3 else "")
                or f"{groups} bodies, each under its PyBullet parent")
    else:
        res.add("structure", "body tree", None, None, "", "not compared: no link has a "
                "body or site in the MJCF")
    forces_of_mujoco_alone(s)


def forces_of_mujoco_alone(s: Sides) -> None:
    """What MuJoCo would push the robot with that PyBullet has no counterpart of.

    Joint springs (``stiffness``), gravity compensation (``gravcomp``), the medium's
    forces (``density``, ``viscosity``, ``wind``), and a gravity other than the
    0 0 -9.81 urdfkit's PyBullet commands set. Each would move MuJoCo's robot otherwise
    while the rows at poses (kinematics, mass matrix) still agreed.
    """
    import numpy as np

    f = s.mjcf.forces()
    said = [f"joint {name or k} stiffness {v:g}" for k, name, v in f.stiffness]
    said += [f"body {name or b} gravcomp {v:g}" for b, name, v in f.gravcomp]
    if not np.allclose(f.gravity, (0.0, 0.0, -9.81), rtol=0.0, atol=1e-12):
        said.append(f"gravity {' '.join(f'{g:g}' for g in f.gravity)} (PyBullet's "
                    "commands: 0 0 -9.81)")
    for what, value in (("density", f.density), ("viscosity", f.viscosity)):
        if value:
            said.append(f"{what} {value:g}")
    if any(f.wind):
        said.append(f"wind {' '.join(f'{w:g}' for w in f.wind)}")
    said += _equalities_of_mujoco_alone(s)
    s.result.add("structure", "forces MuJoCo alone applies", float(len(said)), 0.0, "found",
                 "; ".join(said[:3]) + (" ..." if len(said) > 3 else "")
                 or "no joint springs, gravity compensation or medium; gravity 0 0 -9.81")


def _equalities_of_mujoco_alone(s: Sides) -> list[str]:
    """Active MJCF equalities that are not the export's.

    The export's are a URDF ``<mimic>`` and a joint PyBullet locks (lower == upper). The
    swing turns equalities off, so a weld or a held joint the URDF has not would otherwise
    pass unseen.
    """
    mimic = {j.name: j.mimic[0] for j in s.robot.movable() if j.mimic is not None}
    locked = {j.name for j in s.robot.movable() if j.limited and j.lower == j.upper}
    names = s.mjcf.tree.joint_names
    out = []
    for e in s.mjcf.equalities():
        if e.kind == "joint":
            a, b = e.joint1, e.joint2
            urdf = next((n for n, k in s.jnt.items() if names[k] == a), a)
            lead = next((n for n, k in s.jnt.items() if names[k] == b), b)
            if (b and mimic.get(urdf) == lead) or (not b and urdf in locked):
                continue
            out.append(f"equality on joint {a or e.index}" + (f" and {b}" if b else ""))
        else:
            out.append(f"{e.kind} {e.name or e.index}")
    return out


def joint_rows(s: Sides) -> None:
    """Names, order, kinds, limits, damping, armature and friction of the matched joints."""
    pb, res, tree = s.pb, s.result, s.mjcf.tree
    mine = {k: n for n, k in s.jnt.items()}
    names = tree.joint_names
    res.unmatched_joints = [n for n in pb.names if n not in s.jnt]
    res.extra_joints = [names[k] or f"joint {k}" for k in range(len(names)) if k not in mine]
    missing = res.unmatched_joints + [f"+{n}" for n in res.extra_joints]
    res.add("structure", "joint names", float(len(missing)), 0.0, "unmatched",
            ", ".join(missing[:6]) + (" ..." if len(missing) > 6 else ""))
    if not s.matched:
        for what in ("joint order", "joint kinds", "joint limits", "joint damping"):
            res.add("structure", what, None, None, "",
                    "no movable joints" if not pb.names and not res.extra_joints else
                    "not compared: no joint matched", status="info"
                    if not pb.names and not res.extra_joints else None)
        return
    order = [mine[k] for k in range(len(names)) if k in mine]
    bad = next((a for a, b in zip(order, s.matched, strict=True) if a != b), "")
    res.add("structure", "joint order", 0.0 if not bad else 1.0, 0.0, "moved",
            f"first out of place: {bad}" if bad else f"{len(order)} joints")
    joints = {j.name: j for j in s.robot.joints}
    theirs = s.mj_joints()
    wrong, limits, damping, armature, friction = [], [], [], [], []
    known_friction = []
    for i, n in zip(pb.movable, pb.names, strict=True):
        if n not in s.jnt:
            continue
        ours, mj = pb.joints[i], theirs[n]
        if ours.kind != mj.kind:
            wrong.append(n)
        armature.append((abs(s.mjcf.armature(s.jnt[n])), n))
        loss = mj.friction
        if loss and loss == joints[n].friction:
            known_friction.append(f"{n} {loss:g}")
        else:
            friction.append((abs(loss), n))  # PyBullet 3.2.7 simulates none
        if ours.kind == "spherical":  # PyBullet's spherical joint has no limit
            limits.append((math.inf if mj.limited else 0.0, n))
            continue
        limits.append((limit_error(joints[n], ours.lower, ours.upper, mj.limited,
                                    mj.lower, mj.upper), n))
        if ours.kind == mj.kind:
            damping.append((abs(ours.damping - mj.damping), n))
    res.add("structure", "joint kinds", float(len(wrong)), 0.0, "differ", ", ".join(wrong))
    for what, items, unit in (("joint limits", limits, "rad|m"),
                              ("joint damping", damping, "N m s/rad")):
        v, d = worst(items)
        res.add("structure", what, v, TOL_EXACT, unit, d if items else
                "not compared: only ball joints matched", status=None if items else "info")
    v, d = worst(armature)
    res.add("structure", "joint armature", v, TOL_EXACT, "kg m^2",
            f"{d}: MuJoCo adds rotor inertia PyBullet does not have" if v > TOL_EXACT else d)
    v, d = worst(friction)
    res.add("structure", "joint frictionloss", v, TOL_EXACT, "N m",
            f"{d}: MuJoCo simulates a dry friction PyBullet 3.2.7 does not" if v > TOL_EXACT
            else d)
    if known_friction:
        res.add("structure", "joint friction of the URDF", float(len(known_friction)), None,
                "known", "PyBullet 3.2.7 does not simulate <dynamics friction>; the MJCF's "
                "frictionloss does: " + "; ".join(known_friction[:4]), status="known")


def limit_error(joint: Any, lower: float, upper: float, limited: bool, mj_lower: float,
                 mj_upper: float) -> float:
    """How far MuJoCo's range is from the limits PyBullet loaded (inf: one side only)."""
    # PyBullet limits a revolute or prismatic joint with lower <= upper, never a
    # continuous one (getJointInfo shows a continuous joint's <limit> all the same)
    if joint.limited and joint.lower == joint.upper and not limited:
        return 0.0  # locked: MuJoCo has no empty range (export holds it with an equality)
    if joint.limited != limited:
        return math.inf
    if not joint.limited:
        return 0.0
    return float(max(abs(lower - mj_lower), abs(upper - mj_upper)))


def masses(s: Sides) -> None:
    """Mass, centre of mass and inertia, welded groups compared at the zero pose."""
    import numpy as np

    res, robot = s.result, s.robot
    where = fused(robot)
    zero = link_frames(robot, {})
    # PyBullet: each body group (fixed links fused), in the world at the zero pose
    groups: dict[str, list[tuple[LoadedInertial, Any]]] = {}
    for link, (body, _) in where.items():
        if link in s.pb.link_index:
            groups.setdefault(body, []).append((s.pb.inertial(link), zero[link]))
    # MuJoCo: bodies grouped by the body they are welded to, at qpos0 = 0
    weld, snapped = _mujoco_weld_groups(s)
    image = s.weld_image(where, s.mjcf.written.weld)
    total_pb = sum(i.mass for parts in groups.values() for i, _ in parts)
    total_mj = s.mjcf.total_mass()
    res.add("structure", "total mass", abs(total_pb - total_mj) / max(total_pb, 1e-300),
            TOL_EXACT, "relative", f"PyBullet {total_pb!r} kg, MuJoCo {total_mj!r} kg"
            + defaults_said(s.robot, list(robot.links), abs(total_pb - total_mj)))
    mass: list[tuple[float, str]] = []
    com: list[tuple[float, str]] = []
    inertia: list[tuple[float, str]] = []
    missing: list[str] = []
    zeroed = zeroed_inertia(s)
    s.repaired = []
    for body, parts in groups.items():
        if body not in image:
            if not (body == robot.root == "world" and combine(parts).mass == 0):
                missing.append(body)  # (a massless `world` is MuJoCo's world body)
            continue
        nothing = [(LoadedInertial(0.0, (0, 0, 0), _ZERO3), np.eye(4))]
        ours, theirs = combine(parts), combine(weld.get(image[body], []) or nothing)
        mass.append((abs(ours.mass - theirs.mass) / max(ours.mass, theirs.mass, 1e-300), body))
        if ours.mass <= 0:
            continue
        com.append((float(np.abs(ours.com - theirs.com).max()), body))
        scale = max(float(np.abs(ours.tensor).max()), 1e-300)
        off = float(np.abs(ours.tensor - theirs.tensor).max()) / scale
        mine = [z for z in zeroed if where[z][0] == body]
        if mine and off > TOL_INERTIA:
            # PyBullet zeroed a link's tensor here and the MJCF holds another (export
            # writes the one `fix` would: MuJoCo refuses a moving body without one)
            s.repaired += mine
            continue
        inertia.append((off, body))
    taken = set(image.values())
    names = s.mjcf.written.body_names
    missing += [f"+{names[w] or f'body {w}'}" for w, parts in weld.items()
                if w and w not in taken and sum(i.mass for i, _ in parts) > 0]
    if missing:
        res.add("structure", "bodies", float(len(missing)), 0.0, "unmatched",
                ", ".join(missing[:6]) + (" ..." if len(missing) > 6 else ""))
    if not mass:
        res.add("structure", "body masses", None, None, "", "not compared: no link has a "
                "body or site in the MJCF")
    else:
        v, dd = worst(mass)
        members = [n for n, (g, _) in where.items() if g == dd]
        res.add("structure", "body masses", v, TOL_EXACT, "relative",
                dd + (defaults_said(s.robot, members, v) if v > TOL_EXACT else ""))
    for what, items, tol in (("centres of mass", com, TOL_COM),
                             ("inertia tensors", inertia, TOL_INERTIA)):
        if items:
            v, dd = worst(items)
            res.add("structure", what, v, tol, "m" if what[0] == "c" else "relative", dd)
    v, dd = worst(snapped)
    if v > 0:
        res.add("structure", "inertial frames MuJoCo puts on their body", v, None,
                "relative", f"{dd}: MuJoCo's compiler takes an inertial frame this close "
                "to its body's as the body's (body_sameframe) and simulates the tensor "
                "so turned; the inertia row compares the MJCF's own", status="known")
    if s.repaired:
        res.add("structure", "inertia MuJoCo cannot take", float(len(s.repaired)), None,
                "known", f"{', '.join(s.repaired[:4])}: PyBullet simulates a singular "
                "tensor here (zero where the file's breaks the triangle inequality) and "
                "MuJoCo refuses a moving body without one; "
                "their bodies' inertia tensors (not their masses or centres of mass), "
                "the dynamics and the swing are not compared",
                status="known")


def _mujoco_weld_groups(s: Sides) -> tuple[dict[int, list[tuple[LoadedInertial, Any]]],
                                           list[tuple[float, str]]]:
    """MuJoCo's bodies' mass properties by weld group (as written), placed at qpos 0.

    And the bodies whose inertial frame MuJoCo's compiler snapped onto the body's, with the
    relative change of their tensor.
    """
    import numpy as np

    weld: dict[int, list[tuple[LoadedInertial, Any]]] = {}
    snapped: list[tuple[float, str]] = []
    for b in s.mjcf.bodies():
        if b.snapped is not None:
            snapped.append((b.snapped, b.name))
        own = LoadedInertial(b.mass, (0.0, 0.0, 0.0),
                       tuple(map(tuple, np.diag(b.inertia))))  # type: ignore[arg-type]
        # grouped as written: a body with a free joint of its own that no link matches
        # (a second robot, a loose box) is a group of its own, said as extra
        weld.setdefault(b.weld, []).append((own, b.frame))
    return weld, snapped


def defaults_said(robot: LoadedRobot, links: list[str], off: float) -> str:
    """A mass difference's likely cause: links PyBullet gives its default 1 kg."""
    from urdfkit.model.spec import default_mass

    if off <= 0:
        return ""
    # (a link named `world` without one weighs 0 in PyBullet, not 1 kg)
    made = [n for n in links if not robot.links[n].inertial.given and default_mass(n) > 0]
    if not made:
        return ""
    return (f"; {len(made)} link(s) without <inertial> ({', '.join(made[:3])}"
            f"{' ...' if len(made) > 3 else ''}) weigh PyBullet's default 1 kg each")


def zeroed_inertia(s: Sides) -> list[str]:
    """Moving links PyBullet simulates with a singular tensor.

    A principal moment under MuJoCo's 1e-15: zeroed where the file's breaks the triangle
    inequality, or so in the file (laikago's chassis). MuJoCo refuses a moving body
    without inertia.
    """
    import numpy as np

    if not s.options.inertia_from_file:
        return []
    out = []
    robot = s.robot
    where = fused(robot)
    for n, link in robot.links.items():
        if not link.inertial.given or link.inertial.mass <= 0 or n not in s.pb.link_index:
            continue
        loaded = np.array(s.pb.inertial(n).tensor)
        if not np.isfinite(loaded).all() or np.linalg.eigvalsh(loaded)[0] > 1e-15:
            continue
        group = where[n][0]
        if group != robot.root or (not s.options.fixed_base
                                    and robot.links[group].inertial.mass != 0):
            out.append(n)
    return out
