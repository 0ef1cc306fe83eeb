"""check's rules on joints that need the tree's dynamics (U310-U311).

Mimic joints PyBullet ignores, and joint damping PyBullet's explicit step cannot carry (judged
on the mass matrix at the zero pose).
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING, Any, cast

from lxml import etree

from urdfkit.checks.rules_mass import inertia_tensor, mass_of, principal_moments
from urdfkit.model.index import Doc, JointView, LinkView, first
from urdfkit.model.spec import (
    Matrix3,
    matmul,
    rotate,
    rpy_to_matrix,
    transpose,
)
from urdfkit.model.spec import attr_float as _num
from urdfkit.model.spec import attr_vec as _vec
from urdfkit.sources.guard import RuleReport
from urdfkit.sources.references import label

if TYPE_CHECKING:  # formats.fk is imported where a damped joint needs it
    from urdfkit.formats.fk import Frame


def rule_mimic(root: etree._Element, r: RuleReport) -> None:
    """U310: every ``<mimic>`` PyBullet ignores (its leader exists; U307 and U309 judge that).

    PyBullet 3.2.7 reads no ``<mimic>``: the follower is an ordinary joint that moves on its
    own, so a two-finger gripper whose second finger mimics the first opens one finger.
    """
    joints = {jv.name for jv in r.doc(root).joints}
    for jv in r.doc(root).joints:
        mimic = jv.mimic
        leader = mimic.get("joint") if mimic is not None else None
        if leader is None or leader not in joints or leader == jv.name:
            continue
        multiplier = _num(mimic, "multiplier", 1.0)
        offset = _num(mimic, "offset", 0.0)
        if multiplier is None or offset is None:
            continue  # U401 says why
        r.add("U310", "info", f"{label(jv.el)} mimics joint {leader!r} (position = "
              f"{leader} x {multiplier:g} + {offset:g}), and PyBullet ignores <mimic>: it moves "
              "on its own, free unless driven; drive it to that position each step"
              + (", or tie it with p.createConstraint(body, leader link, body, its link, "
                 f"p.JOINT_GEAR, ...) and gearRatio {-1 / multiplier:g} (measured: PyBullet's "
                 "gear holds leader + gearRatio x follower at 0; it keeps velocities, not the "
                 "offset)" if multiplier else ""), mimic)


#: PyBullet's default physics step (``setTimeStep``), which ``sim`` and ``drive`` keep.
DEFAULT_TIME_STEP = 1.0 / 240.0


def rule_damping(root: etree._Element, r: RuleReport) -> None:
    """U311: joint damping so large for what the joint moves that PyBullet's step is unstable.

    PyBullet applies ``<dynamics damping>`` explicitly: each step multiplies the joint speed by
    about ``1 - dt x damping / inertia``, which past 2 flips its sign and grows it to
    PyBullet's 100 rad/s joint-speed cap (measured: the Shadow hand, shadow-robot/sr_common,
    0.1 N m s/rad on ~5e-6 kg m^2 fingers, chatters at +-100 rad/s from the third step). The
    inertia is the joint-space one at the zero pose, ``M_ii``: everything below the joint about
    its axis (a prismatic joint: the mass below it), the file's inertia, 1 kg and unit inertia
    for a link without ``<inertial>``. The largest eigenvalue of ``M^-1 B`` is at least
    ``b_i / M_ii``, so a finding here is unstable for certain; joints coupled through the
    off-diagonal inertia can be unstable without one.
    """
    doc = r.doc(root)
    damped = []
    for jv in doc.joints:
        if jv.type not in ("revolute", "continuous", "prismatic"):
            continue
        dyn = first(jv.el, "dynamics")
        b = _num(dyn, "damping") if dyn is not None else None
        if b is not None and b > 0:
            damped.append((jv, b, dyn))
    if not damped:
        return
    links = {lv.name: lv for lv in doc.links if lv.name is not None}
    below: dict[str, list[Any]] = {}
    for jv in doc.joints:
        parent = jv.parent.get("link") if jv.parent is not None else None
        if parent is not None and jv.child is not None:
            below.setdefault(parent, []).append(jv)
    found: set[str] = set()
    for jv, b, dyn in damped:
        # Past dt x b / 2 the joint is stable: the sum may stop there.
        inertia = _joint_inertia(jv, links, below, DEFAULT_TIME_STEP * b / 2)
        if inertia is None or inertia <= 0:
            continue
        rate = DEFAULT_TIME_STEP * b / inertia
        if rate <= 2.0:
            continue
        found.add(jv.name or "")
        prismatic = jv.type == "prismatic"
        unit, what = ("N s/m", "kg") if prismatic else ("N m s/rad", "kg m^2")
        r.add("U311", "warning",
              f"{label(jv.el)} has damping {b:g} {unit} against the {inertia:.3g} {what} it "
              f"moves (at the zero pose, with the file's inertia): PyBullet applies joint "
              f"damping explicitly, so each step of its default 1/240 s multiplies the joint's "
              f"speed by 1 - {rate:.3g}, flipping its sign and growing it to PyBullet's "
              f"100 {'m/s' if prismatic else 'rad/s'} cap: the joint chatters instead of "
              f"settling; lower the damping under {2 * inertia / DEFAULT_TIME_STEP:.3g} or "
              f"step under {2 * inertia / b:.3g} s", dyn)
    _coupled_damping(doc, links, below, damped, found, r)


def _coupled_damping(doc: Doc, links: dict[str, LinkView], below: dict[str, list[Any]],
                     damped: list[tuple[Any, float, etree._Element]], found: set[str],
                     r: RuleReport) -> None:
    """U311 for damped joints unstable together though each alone is not.

    Toyota HSR's hand (hsr_description): ``hand_r_spring_proximal_joint`` and
    ``hand_r_mimic_distal_joint``, 1 N m s/rad each, move 0.033 and 0.030 kg m^2 alone (dt b /
    M_ii 0.13), but turned against each other the distal link keeps still and only the small
    link between moves: the largest eigenvalue of dt M^-1 B is 5.46, and raw PyBullet's speeds
    along that motion flip sign and grow 4.5x a step. Judged on the joint-space mass matrix of
    the whole tree at the zero pose, base fixed (a floating base only raises the eigenvalue).
    """
    got = _mass_matrix(doc, links, below)
    if got is None:
        return
    names, m = got
    index = {n: i for i, n in enumerate(names)}
    # Only the joints stable alone: the motions among them (the principal submatrix of
    # dt B^1/2 M^-1 B^1/2 over them, whose largest eigenvalue is at most the whole one's, so
    # each motion found is unstable in the whole too). A joint found alone is said already,
    # and over the rest the cheap bound below usually ends it (kuka_iiwa: no numpy).
    rows = [(index[jv.name], jv, b, dyn) for jv, b, dyn in damped
            if jv.name in index and jv.name not in found]
    low = _cholesky(m)
    if not rows or low is None:
        return
    # A = dt B^1/2 M^-1 B^1/2 over the damped joints: C = L^-1 B^1/2 e_k, A = dt C^T C
    cols = [_forward_solve(low, [math.sqrt(b) if i == k else 0.0 for i in range(len(names))])
            for k, _, b, _ in rows]
    a = [[DEFAULT_TIME_STEP * sum(x * y for x, y in zip(ci, cj, strict=True)) for cj in cols]
         for ci in cols]
    if max(sum(abs(x) for x in row) for row in a) <= 2.0:
        return  # Gershgorin: no eigenvalue past 2 (most files end here, without numpy)
    import numpy as np

    sym = np.array(a)
    root_b = np.sqrt(np.array([b for _, _, b, _ in rows]))
    values, vectors = np.linalg.eigh((sym + sym.T) / 2)
    said = set(found)
    for e in range(len(values) - 1, -1, -1):
        rate = float(values[e])
        if not rate > 2.0 or not math.isfinite(rate):
            break
        mode = vectors[:, e] / root_b  # the joint speeds of that motion
        mode = mode / np.abs(mode).max()
        part = [k for k in np.argsort(-np.abs(mode)) if abs(mode[k]) >= 0.2]
        if any(rows[k][1].name in said for k in part):
            continue  # said already, joint by joint or as a stiffer motion
        said.update(rows[k][1].name for k in part)
        lead = rows[part[0]]
        others = ", ".join(rows[k][1].name for k in part[1:4])
        motion = ", ".join(f"{rows[k][1].name} x {mode[k]:+.2f}" for k in part[:4])
        r.add("U311", "warning",
              f"{label(lead[1].el)}, moving with {others or 'no other damped joint'} "
              f"({motion}), is damped too hard for PyBullet's step, though each joint alone is "
              f"not: so moving they carry little inertia (at the zero pose, base fixed, the "
              f"file's inertia), and the largest eigenvalue of dt M^-1 B at its default "
              f"1/240 s is {rate:.3g}, past 2: each step multiplies that motion's speed by "
              f"1 - {rate:.3g}, flipping its sign and growing it to PyBullet's joint-speed "
              f"cap; scale those joints' damping under {2 / rate:.3g} of what it is or step "
              f"under {2 * DEFAULT_TIME_STEP / rate:.3g} s", lead[3])


Chain = list[tuple[int, tuple[float, ...], tuple[float, ...], bool]]


def _zero_pose_tree(doc: Doc, links: dict[str, LinkView], below: dict[str, list[Any]]
                    ) -> tuple[list[str], list[str], dict[str, Frame], dict[str, Chain]] | None:
    """The tree at the zero pose, or None when it does not read.

    Returns the moving joints' names, the links root first, each link's frame (rotation,
    origin: :func:`urdfkit.formats.fk.child_frame` composes it) and the moving joints above it
    (index, axis, a point on it, prismatic). It does not read with not one root, a loop, a
    missing link or a bad number.
    """
    from urdfkit.formats.fk import WORLD, child_frame

    children = {jv.child.get("link") for jv in doc.joints if jv.child is not None}
    roots = [n for n in links if n not in children]
    if len(roots) != 1:
        return None
    frame: dict[str, Frame] = {roots[0]: WORLD}
    chain: dict[str, Chain] = {roots[0]: []}
    names: list[str] = []
    order: list[str] = []
    stack = [roots[0]]
    while stack:
        name = stack.pop()
        order.append(name)
        here = frame[name]
        for jv in below.get(name, ()):
            child = jv.child.get("link") if jv.child is not None else None
            origin = _origin(jv)
            if child is None or child in frame or child not in links or origin is None:
                return None
            crot, cpos = frame[child] = child_frame(here, *origin)
            chain[child] = list(chain[name])
            if jv.type in ("revolute", "continuous", "prismatic"):
                axis = _unit_axis(jv)
                if axis is None or jv.name is None:
                    return None
                world = rotate(crot, axis)
                chain[child].append((len(names), world, cpos, jv.type == "prismatic"))
                names.append(jv.name)
            stack.append(child)
    return names, order, frame, chain


def _mass_matrix(doc: Doc, links: dict[str, LinkView], below: dict[str, list[Any]]
                 ) -> tuple[list[str], list[list[float]]] | None:
    """The joint-space mass matrix at the zero pose, base fixed, as PyBullet loads the file.

    With the file's inertia (1 kg and unit inertia for a link without ``<inertial>``),
    ``M_ij`` sums, over the links below both joints, ``m J_v,i . J_v,j + J_w,i^T I J_w,j``
    (each link's Jacobian columns at its centre of mass). Plain Python: the tree's depth, not
    its size, sets the cost. None when the tree does not read, has no moving joint, or is too
    big to be worth it.
    """
    tree = _zero_pose_tree(doc, links, below)
    if tree is None:
        return None
    names, order, frame, chain = tree
    n = len(names)
    if n == 0 or n > 200:
        return None
    m = [[0.0] * n for _ in range(n)]
    for name in order:
        above = chain[name]
        if not above:
            continue
        body = _link_inertia(links[name], *frame[name])
        if body is None:
            return None
        mass, com, turn, t = body
        # in the world frame (the unit inertia of a link without <inertial> is so everywhere)
        tensor = t if t is _IDENTITY else matmul(matmul(turn, t), transpose(turn))
        cols: list[tuple[int, tuple[float, ...], tuple[float, ...], tuple[float, ...]]] = []
        for i, a, at, prismatic in above:
            if prismatic:
                cols.append((i, a, (0.0, 0.0, 0.0), (0.0, 0.0, 0.0)))
                continue
            r_ = tuple(c - q for c, q in zip(com, at, strict=True))
            lin = (a[1] * r_[2] - a[2] * r_[1], a[2] * r_[0] - a[0] * r_[2],
                   a[0] * r_[1] - a[1] * r_[0])
            cols.append((i, lin, a, rotate(tensor, a)))
        for i, lin_i, _, iw_i in cols:
            row = m[i]
            for j, lin_j, w_j, _ in cols:  # the dot products written out: the rule's hot loop
                row[j] += mass * (lin_i[0] * lin_j[0] + lin_i[1] * lin_j[1]
                                  + lin_i[2] * lin_j[2]) \
                    + (iw_i[0] * w_j[0] + iw_i[1] * w_j[1] + iw_i[2] * w_j[2])
    return names, m


def _cholesky(m: list[list[float]]) -> list[list[float]] | None:
    """Lower-triangular L with L L^T = m, or None when m is not positive definite."""
    n = len(m)
    low = [[0.0] * n for _ in range(n)]
    for i in range(n):
        for j in range(i + 1):
            acc = m[i][j] - sum(low[i][k] * low[j][k] for k in range(j))
            if i == j:
                if not acc > 0.0:
                    return None
                low[i][i] = math.sqrt(acc)
            else:
                low[i][j] = acc / low[j][j]
    return low


def _forward_solve(low: list[list[float]], b: list[float]) -> list[float]:
    """The x with L x = b, L lower-triangular."""
    x: list[float] = []
    for i, row in enumerate(low):
        x.append((b[i] - sum(row[k] * x[k] for k in range(i))) / row[i])
    return x


_ZERO_TENSOR: Matrix3 = ((0.0, 0.0, 0.0), (0.0, 0.0, 0.0), (0.0, 0.0, 0.0))


def _loaded_tensor(inertia: etree._Element | None) -> Matrix3 | None:
    """The ``<inertia>`` tensor as PyBullet loads it with the file's inertia, or None.

    Zero where no rigid body has it (a negative principal moment, or one over the other
    two): PyBullet's importer says "Bad inertia tensor properties" and zeroes it (the Allegro
    hand's fingers in example-robot-data).
    """
    tensor = inertia_tensor(inertia) if inertia is not None else None
    if tensor is None or inertia is None:
        return None
    principal = principal_moments(inertia)
    if principal is not None and (principal[2] < 0 or principal[4] > principal[2] + principal[3]):
        return _ZERO_TENSOR
    return cast(Matrix3, tensor)


_IDENTITY: Matrix3 = ((1.0, 0.0, 0.0), (0.0, 1.0, 0.0), (0.0, 0.0, 1.0))


def _link_inertia(lv: LinkView, rot: Matrix3, pos: tuple[float, ...]
                  ) -> tuple[float, tuple[float, ...], Matrix3, Matrix3] | None:
    """(mass, centre of mass, the inertia's frame, its tensor there) of a link at (rot, pos).

    As PyBullet loads the file with its inertia: without ``<inertial>`` 1 kg (0 for
    ``world``) and :data:`_IDENTITY` at the link's frame. None where a number does not read.
    """
    mass = mass_of(lv)
    if mass is None:
        return None
    if lv.inertial is None:
        return mass, pos, rot, _IDENTITY
    origin = first(lv.inertial, "origin")
    xyz = _vec(origin, "xyz", 3, (0.0, 0.0, 0.0))
    rpy = _vec(origin, "rpy", 3, (0.0, 0.0, 0.0))
    tensor = _loaded_tensor(lv.inertia)
    if xyz is None or rpy is None or tensor is None:
        return None
    return (mass, tuple(p + o for p, o in zip(pos, rotate(rot, xyz), strict=True)),
            matmul(rot, rpy_to_matrix(rpy)), tensor)


def _origin(jv: Any) -> tuple[tuple[float, ...], tuple[float, ...]] | None:
    """Joint ``jv``'s ``<origin>`` (xyz, rpy), or None when a number does not read (U401)."""
    xyz = _vec(jv.origin, "xyz", 3, (0.0, 0.0, 0.0))
    rpy = _vec(jv.origin, "rpy", 3, (0.0, 0.0, 0.0))
    return None if xyz is None or rpy is None else (xyz, rpy)


def _unit_axis(jv: Any) -> tuple[float, ...] | None:
    """Joint ``jv``'s axis as a unit vector (x when absent); None when unreadable or zero."""
    axis = _vec(jv.axis, "xyz", 3, (1.0, 0.0, 0.0))  # None only when unreadable (U401)
    if axis is None:
        return None
    norm = math.sqrt(sum(x * x for x in axis))
    return None if norm == 0 else tuple(x / norm for x in axis)


def _joint_inertia(jv: JointView, links: dict[str, LinkView], below: dict[str, list[Any]],
                   enough: float = math.inf) -> float | None:
    """``M_ii`` of joint ``jv`` at the zero pose, as PyBullet loads the file with its inertia.

    None when a link below is missing or has no readable mass or inertia, or the tree loops.
    The sum stops once it passes ``enough`` while no link's term was negative (only an
    invalid tensor gives one): the caller only asks whether it stays under.
    """
    from urdfkit.formats.fk import WORLD, child_frame

    a = _unit_axis(jv)
    if a is None:
        return None
    prismatic = jv.type == "prismatic"
    # frames relative to the joint's own (its child link's frame at q = 0)
    todo: list[tuple[str | None, Frame]] = [
        (jv.child.get("link") if jv.child is not None else None, WORLD)]
    seen: set[str] = set()
    total = 0.0
    while todo:
        name, here = todo.pop()
        if name is None or name in seen or name not in links:
            return None
        seen.add(name)
        body = _link_inertia(links[name], *here)
        if body is None:
            return None
        mass, com, frame, tensor = body
        if prismatic:
            term = mass
        else:
            local = rotate(transpose(frame), a)  # the axis in the inertia's frame
            along = sum(c * x for c, x in zip(com, a, strict=True))
            term = sum(local[i] * tensor[i][j] * local[j] for i in range(3) for j in range(3)) \
                + mass * (sum(c * c for c in com) - along * along)
        total += term
        if term < 0:
            enough = math.inf
        elif total > enough:
            return total
        for child in below.get(name, ()):
            origin = _origin(child)
            if origin is None:
                return None
            todo.append((child.child.get("link") if child.child is not None else None,
                         child_frame(here, *origin)))
    return total
