"""``agree`` at seeded poses: link frames, the mass matrix, inverse dynamics, self-contacts.

Every matched link frame at each pose against PyBullet's ``getLinkState`` (float32 inside:
:func:`pybullet_frame_tolerances`) and against :mod:`urdfkit.formats.fk` (1e-12); the
joint-space mass matrix and inverse-dynamics torques (1e-9 relative), base fixed on both
sides, both asked of the two :class:`~urdfkit.engine.api.Model` implementations; and MuJoCo's
self-contacts, none unless self-collision was asked for.
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING, Any

from urdfkit.exchange.agree_report import TOL_DYNAMICS, TOL_FK, TOL_PYBULLET_FRAME, worst
from urdfkit.exchange.agree_sides import PoseSides, PyBulletSide
from urdfkit.formats.fk import link_frames
from urdfkit.formats.robot import LoadedRobot

if TYPE_CHECKING:
    from urdfkit.engine.api import Model

#: How far from the point of its range nearest zero a limited joint is sampled: a turn each
#: way (a revolute pose repeats past it), a metre along a prismatic one. Real ranges fit
#: whole (UR's +-2 pi); +-1e308 overflowed the sampler (exit 3), and poses that far out
#: would make every figure meaningless (float32 PyBullet, sines of 1e300).
SAMPLE_REACH = {"revolute": 2 * math.pi, "prismatic": 1.0}


def pybullet_frame_tolerances(robot: LoadedRobot) -> dict[str, float]:
    """Each link frame's tolerance against PyBullet's ``getLinkState``: float32 inside.

    A float32 rounding is 2^-24 relative; each transform on the way from the root rounds a
    few times (4 roundings a step, 2^-22), and a joint angle q is itself held to |q| 2^-24,
    which its sine and cosine carry. So a frame's error is bounded by
    2^-22 x sum over its chain of (1 + the joint's largest |q|), never below the issue's 1e-6
    (go2's FL_calf, whose joints reach 1.05, 3.49 and 2.72 rad, measured 1.0e-6, gets
    2.5e-6; kuka_iiwa's frames, measured 7.6e-7 at worst, mostly 1e-6).
    """
    acc = {robot.root: 0.0}
    for j in robot.joints:
        reach = 0.0
        if j.moves:
            reach = max(map(abs, sample_range(j))) if j.limited else \
                (1.0 if j.type == "prismatic" else math.pi)
        acc[j.child] = acc[j.parent] + 1.0 + reach
    return {n: max(TOL_PYBULLET_FRAME, 2.0 ** -22 * a) for n, a in acc.items()}


def sample_range(j: Any) -> tuple[float, float]:
    """The part of a limited joint's range poses and the swing start are drawn from."""
    reach = SAMPLE_REACH["prismatic" if j.type == "prismatic" else "revolute"]
    near = min(max(0.0, j.lower), j.upper)
    return max(j.lower, near - reach), min(j.upper, near + reach)


def sample_pose(robot: LoadedRobot, names: list[str], rng: Any) -> dict[str, float]:
    """A seeded value for each of these joints: within its limits, else a turn or a metre."""
    q = {}
    joints = {j.name: j for j in robot.joints}
    for n in names:
        j = joints[n]
        if j.limited:
            q[n] = float(rng.uniform(*sample_range(j)))
        elif j.type == "prismatic":
            q[n] = float(rng.uniform(-1.0, 1.0))
        else:
            q[n] = float(rng.uniform(-math.pi, math.pi))
    return q


def frame_error(a: Any, b: Any) -> tuple[float, float]:
    """Two frames' (4 x 4) largest position and rotation-matrix differences."""
    import numpy as np

    return float(np.abs(a[:3, 3] - b[:3, 3]).max()), float(np.abs(a[:3, :3] - b[:3, :3]).max())


def poses(s: PoseSides) -> None:
    """The rows at seeded poses: frames, mass matrix and inverse dynamics, self-contacts."""
    import numpy as np

    from urdfkit.model.spec import quat_to_matrix

    pb, res, robot, model = s.pb, s.result, s.robot, s.model
    links = [n for n in pb.link_index if s.linked(n)]
    res.unmatched_links = [n for n in pb.link_index if n not in links and n != "world"]
    index = [pb.link_index[n] for n in links]
    rng = np.random.default_rng(s.options.seed)
    pb_pos: list[tuple[float, str]] = []
    pb_rot: list[tuple[float, str]] = []
    fk_pos: list[tuple[float, str]] = []
    fk_rot: list[tuple[float, str]] = []
    mass_err: list[tuple[float, str]] = []
    id_err: list[tuple[float, str]] = []
    contacts: list[str] = []
    dyn = not res.unmatched_joints and not res.extra_joints and s.matched and not pb.spherical
    refused: str | None = None  # the PyBullet call that failed on this model
    if dyn and s.repaired:
        refused = f"model has a singular inertia on {', '.join(s.repaired[:3])} (see the " \
            "structure rows)"
    tol = pybullet_frame_tolerances(robot)
    base_inertial = np.array(quat_to_matrix(
        pb.engine.dynamics(pb.body, -1).inertial_orientation))
    turned_back = base_inertial.T @ np.array(s.gravity)
    snapped = s.snapped_sites(links)
    for _ in range(s.options.poses):
        q = sample_pose(robot, pb.one_names, rng)
        qd = sample_pose(robot, pb.one_names, rng)
        qdd = sample_pose(robot, pb.one_names, rng)
        # the matched joints at q; those PyBullet turns with a spherical joint (NaN) stay
        # at the file's reference
        model.set_joint_positions(0, [q.get(n, math.nan) for n in s.matched])
        theirs = dict(zip(links, model.link_matrices(0, index), strict=True))
        pb.pose(q)
        # none where PyBullet cannot report the body's state (_say_unreadable)
        pb_err = {n: frame_error(theirs[n], t) for n, t in pb.frames(links).items()}
        pb_pos += [(a / tol[n], n) for n, (a, _) in pb_err.items()]
        pb_rot += [(b / tol[n], n) for n, (_, b) in pb_err.items()]
        exact = link_frames(robot, q)
        for n in links:
            ref = exact[n] if n not in snapped else exact[snapped[n][0]] @ snapped[n][1]
            a, b = frame_error(theirs[n], ref)
            fk_pos.append((a, n))
            fk_rot.append((b, n))
        contacts += [f"{a}/{b}" for a, b in model.self_contacts(0)]
        if dyn and refused is None:
            got = dynamics_errors(pb, model, s.matched, (q, qd, qdd), turned_back,
                                  s.gravity, s.inertia_slack)
            if isinstance(got, str):
                refused = got  # PyBullet cannot answer for this model: not compared
            else:
                mass_err.append(got[0])
                id_err.append(got[1])
    if not links:
        res.add("kinematics", "link frames", None, None, "", "not compared: no link has "
                "a body or site of its name")
    _say_unreadable(s, links)
    for what, items, fixed in (("frames vs PyBullet: position", pb_pos, None),
                               ("frames vs PyBullet: rotation", pb_rot, None),
                               ("frames vs exact FK: position", fk_pos, TOL_FK),
                               ("frames vs exact FK: rotation", fk_rot, TOL_FK)):
        if not items:  # no link matched, or PyBullet cannot report the frames (said above)
            continue
        v, n = worst(items)
        limit = fixed if fixed is not None else tol[n]
        if fixed is None:
            v *= limit  # the worst error relative to its own frame's tolerance
        res.add("kinematics", what, v, limit, "m" if "position" in what else "matrix",
                f"{n} ({len(links)} frames x {s.options.poses} poses)")
    _say_snapped(s, snapped)
    _dynamics_rows(s, bool(dyn), refused, mass_err, id_err)
    if not s.geometry:
        return  # the engine's model has none (agree --engine pinocchio, drake)
    pairs = sorted(set(contacts))
    res.add("contacts", "self-contacts at the poses", float(len(contacts)), 0.0, "contacts",
            ", ".join(pairs[:4]) + (" ..." if len(pairs) > 4 else ""),
            status="info" if s.options.self_collision else None)


def dynamics_errors(pb: PyBulletSide, model: Model, matched: list[str],
                    state: tuple[dict[str, float], dict[str, float], dict[str, float]],
                    turned_back: Any, gravity: tuple[float, float, float],
                    slack: float = 0.0
                    ) -> tuple[tuple[float, str], tuple[float, str]] | str:
    """The worst relative mass-matrix and inverse-dynamics errors at one state (q, qd, qdd).

    Each with its joint; or, when PyBullet cannot build its inverse-dynamics model of this
    robot (:func:`urdfkit.engine.session.dynamics_call`), the call that failed and why.
    ``model`` answers over ``matched`` (every movable joint of PyBullet's: the caller compares
    only then) in PyBullet's order; PyBullet is given ``gravity``.

    ``slack`` (kg m^2) is the sum over links of how far PyBullet's rotational inertia may be
    from the other side's by PyBullet's own rounding (spectral norm): a mass-matrix entry
    takes at most ``slack`` of it (each joint's angular Jacobian column is a unit vector or
    zero), a torque at most ``slack (sum |qdd| + 2 (sum |qd|)^2)`` (a link's angular
    acceleration and squared speed are bounded so). That much is taken off each error first.
    """
    import numpy as np

    from urdfkit.exchange.bullet_state import unreliable_dynamics

    q, qd, qdd = state
    names = pb.names
    if unreliable_dynamics(len(names)):
        return unreliable_dynamics(len(names))
    got = pb.dynamics([q[n] for n in names], [qd[n] for n in names], [qdd[n] for n in names],
                      turned_back, gravity)
    if isinstance(got, str):
        return got
    pm, tau_pb = got
    mm = np.array(model.mass_matrix(0, [q[n] for n in matched]))
    scale = max(float(np.abs(pm).max()), 1e-300)
    e = np.maximum(np.abs(pm - mm) - slack, 0.0) / scale
    mass = (float(e.max()), names[int(np.unravel_index(e.argmax(), e.shape)[0])])
    tau_mj = np.array(model.inverse_dynamics(0, [q[n] for n in matched],
                                             [qd[n] for n in matched],
                                             [qdd[n] for n in matched]))
    scale = max(float(np.abs(tau_pb).max()), 1e-300)
    speeds = sum(abs(qd[n]) for n in names)
    allowed = slack * (sum(abs(qdd[n]) for n in names) + 2.0 * speeds * speeds)
    e = np.maximum(np.abs(tau_pb - tau_mj) - allowed, 0.0) / scale
    return mass, (float(e.max()), names[int(e.argmax())])


def _dynamics_rows(s: PoseSides, dyn: bool, refused: str | None,
                   mass_err: list[tuple[float, str]], id_err: list[tuple[float, str]]) -> None:
    res, pb = s.result, s.pb
    if dyn and refused is not None:
        res.add("dynamics", "mass matrix, inverse dynamics", None, None, "",
                f"not compared: raw PyBullet's {refused}", status="known")
    elif dyn:
        v, n = worst(mass_err)
        res.add("dynamics", "mass matrix", v, TOL_DYNAMICS, "relative", n)
        v, n = worst(id_err)
        res.add("dynamics", "inverse dynamics", v, TOL_DYNAMICS, "relative", n)
    elif not pb.names and not res.extra_joints:
        res.add("dynamics", "mass matrix, inverse dynamics", None, None, "",
                "no movable joints", status="info")
    elif pb.spherical and not res.unmatched_joints and not res.extra_joints:
        res.add("dynamics", "mass matrix, inverse dynamics", None, None, "",
                f"not compared: spherical joints ({', '.join(pb.spherical[:3])}); their "
                "frames are compared at rest", status="info")
    else:
        res.add("dynamics", "mass matrix, inverse dynamics", None, None, "",
                "not compared: the joints differ")


def _say_unreadable(s: PoseSides, links: list[str]) -> None:
    """Known rows saying why the frames are not compared with PyBullet's, if they are not."""
    from urdfkit.exchange.bullet_state import unreadable_state

    why = unreadable_state(s.pb.joints)
    if not links or not why:
        return
    for what in ("frames vs PyBullet: position", "frames vs PyBullet: rotation"):
        s.result.add("kinematics", what, None, None, "", f"not compared: {why}; the "
                     "exact-FK rows cover every frame", status="known")


def _say_snapped(s: PoseSides, snapped: dict[str, tuple[str, Any, float]]) -> None:
    """A known row naming the sites MuJoCo computes at their body's frame, if any."""
    if not snapped:
        return
    most = max(snapped, key=lambda n: snapped[n][2])
    more = f" and {len(snapped) - 1} more" if len(snapped) > 1 else ""
    s.result.add("kinematics", "sites MuJoCo puts on their body", snapped[most][2], None,
                 "m|rad", f"{most}{more}; MuJoCo's compiler places a site this close "
                 "to its body's frame at that frame (site_sameframe), so its frame is "
                 "compared there; the MJCF writes it where the file does", status="known")
