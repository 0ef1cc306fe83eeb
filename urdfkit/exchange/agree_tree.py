"""Which MuJoCo body, site and joint is which URDF link and joint, and is the tree the same?

``agree`` compares what it can match. Matching goes by name first; ``--map URDF=MJCF``
names pairs by hand; what is still apart is matched by the tree's shape: a URDF joint whose
parent link is matched takes the one body below that link's MuJoCo body whose frame at the
zero pose is the link's (within :data:`FRAME_TOL`), carrying a joint of the same kind about
the same axis. Menagerie's h1 drops the URDF's ``_joint`` suffixes; its panda shares no name
with example-robot-data's: both match so, and each pair says how it was matched.

The body tree is then compared through welded groups, so that a model which keeps a fixed
link as a body of its own compares the same as one that fuses it: PyBullet's links grouped
as the export fuses them, MuJoCo's bodies by ``body_weldid``. Each group must be one MuJoCo
group, no two groups one, and each group's parent the image of its PyBullet parent: a wheel
detached from the chassis and welded to the world fails here, naming the wheel.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any

from urdfkit.core.errors import ParameterError
from urdfkit.formats.fk import fused, link_frames, unit
from urdfkit.formats.robot import LoadedRobot

if TYPE_CHECKING:
    from urdfkit.engine.mujoco_file import Tree

#: How far (m, and in the rotation matrix) a body's zero-pose frame may be from a link's for
#: the two to be matched by the tree's shape (files written with 6 significant digits match).
FRAME_TOL = 1e-4
#: MuJoCo's joint kinds for PyBullet's 1-dof joint types.
_KINDS = {"revolute": "hinge", "continuous": "hinge", "prismatic": "slide", "spherical": "ball"}


@dataclass
class Matching:
    """URDF names -> MuJoCo ids, and how each pair that is not a name was matched."""

    joints: dict[str, int] = field(default_factory=dict)
    bodies: dict[str, int] = field(default_factory=dict)
    sites: dict[str, int] = field(default_factory=dict)
    #: (URDF name, MJCF name, "map" or "structure"): every pair not matched by name
    pairs: list[tuple[str, str, str]] = field(default_factory=list)


def parse_map(items: list[str] | None) -> dict[str, str]:
    """``--map URDF=MJCF`` pairs.

    Raises:
        ParameterError: An item without ``=``.
    """
    out: dict[str, str] = {}
    for item in items or []:
        urdf, sep, mjcf = item.partition("=")
        if not sep or not urdf or not mjcf:
            raise ParameterError(f"a name pair is URDF=MJCF, got {item!r}", param="name_map")
        out[urdf] = mjcf
    return out


class _Model:
    """A compiled model's tree (:class:`~urdfkit.engine.mujoco_file.Tree`), walked."""

    def __init__(self, tree: Tree) -> None:
        self.t = tree
        self.joint, self.body, self.site = tree.joints, tree.bodies, tree.sites
        self.xpos, self.xmat, self.xaxis = tree.xpos, tree.xmat, tree.xaxis

    def children(self, b: int) -> list[int]:
        return [i for i in range(1, len(self.t.parent)) if self.t.parent[i] == b]

    def below(self, b: int) -> list[int]:
        """Bodies under ``b``: its children, and theirs through bodies that do not move."""
        out, todo = [], self.children(b)
        while todo:
            c = todo.pop(0)
            out.append(c)
            if not self.t.body_joints[c]:
                todo.extend(self.children(c))
        return out

    def joints_of(self, b: int) -> list[int]:
        return self.t.body_joints[b]


def _close(a: Any, b: Any) -> float:
    import numpy as np

    return float(max(np.abs(a[:3, 3] - b[:3, 3]).max(), np.abs(a[:3, :3] - b[:3, :3]).max()))


def match_models(fixed: Tree, robot: LoadedRobot, movable: list[str],
                 name_map: dict[str, str]) -> Matching:
    """Match the URDF's links and movable joints to the (base-welded) MuJoCo model's.

    Raises:
        ParameterError: A ``name_map`` name the URDF or the MJCF does not have.
    """
    model = _Model(fixed)
    out = Matching()
    links = set(robot.links)
    movable_set = set(movable)
    name_map_targets_seen: set[str] = set()
    for urdf, mjcf in name_map.items():
        if urdf not in links and urdf not in movable_set:
            raise ParameterError(f"--map: the URDF has no link or movable joint {urdf!r}",
                                 param="name_map")
        if mjcf in name_map_targets_seen:
            raise ParameterError(f"--map: {mjcf!r} is named for two URDF names",
                                 param="name_map")
        name_map_targets_seen.add(mjcf)
        if urdf in movable_set and mjcf in model.joint:
            out.joints[urdf] = model.joint[mjcf]
        elif urdf in links and mjcf in model.body:
            out.bodies[urdf] = model.body[mjcf]
        elif urdf in links and mjcf in model.site:
            out.sites[urdf] = model.site[mjcf]
        else:
            what = "joint" if urdf in movable_set else "body or site"
            raise ParameterError(f"--map: the MJCF has no {what} {mjcf!r}", param="name_map")
        out.pairs.append((urdf, mjcf, "map"))
    taken_j = set(out.joints.values())
    taken_b = set(out.bodies.values())
    for n in movable:
        if n not in out.joints and n in model.joint and model.joint[n] not in taken_j:
            out.joints[n] = model.joint[n]
    for n in robot.links:
        if n in out.bodies or n in out.sites:
            continue
        if n in model.body and model.body[n] not in taken_b:
            out.bodies[n] = model.body[n]
        elif n in model.site:
            out.sites[n] = model.site[n]
    _match_by_shape(model, robot, movable_set, out)
    return out


def _root_body(model: _Model) -> int | None:
    """The body the robot hangs from.

    The only child of the world that has children or a joint (a ground is not a robot).
    """
    top = [b for b in model.children(0) if model.children(b) or model.joints_of(b)]
    return top[0] if len(top) == 1 else None


def _mj_body_of(out: Matching, model: _Model, link: str) -> int | None:
    if link in out.bodies:
        return out.bodies[link]
    if link in out.sites:
        return model.t.site_body[out.sites[link]]
    return None


def _match_by_shape(model: _Model, robot: LoadedRobot, movable: set[str], out: Matching) -> None:
    """Match what names did not by the tree's shape and the zero-pose frames."""
    import numpy as np

    zero = link_frames(robot, {})
    group = {link: body for link, (body, _) in fused(robot).items()}
    if robot.root not in out.bodies and robot.root not in out.sites and robot.root != "world":
        root = _root_body(model)
        if root is not None and root not in out.bodies.values():
            out.bodies[robot.root] = root
            out.pairs.append((robot.root, _body_name(model, root), "structure"))
    taken_j = set(out.joints.values())
    taken_b = set(out.bodies.values())
    for j in robot.joints:
        if not j.moves:
            continue
        want = zero[j.child]
        axis = want[:3, :3] @ np.array(unit(j.axis)) if j.type != "spherical" else None
        if j.child in out.bodies or j.child in out.sites or j.name in out.joints:
            _match_one_side(model, j, axis, movable, out, taken_j, taken_b)
            continue
        parent = _mj_body_of(out, model, j.parent)
        if parent is None:  # a fixed link fused into its group's body, with no site of its own
            parent = _mj_body_of(out, model, group[j.parent])
        if parent is None:
            continue
        found = []
        for b in model.below(parent):
            if b in taken_b:
                continue
            t = np.eye(4)
            t[:3, :3], t[:3, 3] = model.xmat[b], model.xpos[b]
            if _close(t, want) > FRAME_TOL:
                continue
            found += [(b, k) for k in _joints_like(model, b, j.type, axis) if k not in taken_j]
        if len(found) != 1:
            continue  # none, or ambiguous: left unmatched (and said)
        b, k = found[0]
        out.bodies[j.child] = b
        taken_b.add(b)
        out.pairs.append((j.child, _body_name(model, b), "structure"))
        if j.name in movable and j.name not in out.joints:
            out.joints[j.name] = k
            taken_j.add(k)
            out.pairs.append((j.name, _joint_name(model, k), "structure"))


def _match_one_side(model: _Model, j: Any, axis: Any, movable: set[str], out: Matching,
                    taken_j: set[int], taken_b: set[int]) -> None:
    """A joint whose body is matched (by name) or a body whose joint is: the other half."""
    if j.child in out.bodies or j.child in out.sites:
        # the body is matched: its joint may still be named otherwise (h1's `_joint`)
        b = _mj_body_of(out, model, j.child)
        if j.name in out.joints or j.name not in movable or b is None:
            return
        ks = [k for k in _joints_like(model, b, j.type, axis) if k not in taken_j]
        if len(ks) == 1:
            out.joints[j.name] = ks[0]
            taken_j.add(ks[0])
            out.pairs.append((j.name, _joint_name(model, ks[0]), "structure"))
        return
    b = model.t.joint_body[out.joints[j.name]]  # the joint is matched: its body is
    if b not in taken_b:
        out.bodies[j.child] = b
        taken_b.add(b)
        out.pairs.append((j.child, _body_name(model, b), "structure"))


def _joints_like(model: _Model, b: int, kind: str, axis: Any) -> list[int]:
    """The joints of body ``b`` of PyBullet's ``kind`` about ``axis`` (world, zero pose)."""
    import numpy as np

    out = []
    for k in model.joints_of(b):
        if model.t.joint_kind[k] != _KINDS[kind]:
            continue
        if axis is not None and float(np.abs(model.xaxis[k] - axis).max()) > FRAME_TOL:
            continue
        out.append(k)
    return out


def _body_name(model: _Model, b: int) -> str:
    return next((n for n, i in model.body.items() if i == b), f"body {b}")


def _joint_name(model: _Model, k: int) -> str:
    return next((n for n, i in model.joint.items() if i == k), f"joint {k}")


def tree_errors(written: Tree, fixed: Tree, robot: LoadedRobot, match: Matching
                ) -> tuple[list[str], int]:
    """What differs in the body tree (one line each, naming the body), and groups compared.

    ``written`` is the model as written (a free joint keeps its root a group of its own);
    ``fixed`` the same with its free joints removed, whose joint ids ``match`` holds (the
    bodies' ids are the same in both).
    """
    model = _Model(written)
    weld, up = written.weld, written.parent
    where = fused(robot)
    group = {link: body for link, (body, _) in where.items()}
    parent: dict[str, str | None] = {robot.root: None}
    for j in robot.joints:
        if group[j.child] == j.child:
            parent[j.child] = group[j.parent]
    weld_of: dict[str, set[int]] = {}
    for link in robot.links:
        b = _mj_body_of(match, model, link)
        if b is None and link == robot.root == "world":
            b = 0  # MuJoCo's world body
        if b is not None:
            weld_of.setdefault(group[link], set()).add(weld[b])
    errors: list[str] = []
    image: dict[str, int] = {}
    for g, welds in weld_of.items():
        if len(welds) > 1:
            errors.append(f"{g}: its links move as one in PyBullet but lie in {len(welds)} "
                          "bodies MuJoCo moves apart")
        image[g] = min(welds)
    seen: dict[int, str] = {}
    for g in sorted(image, key=list(robot.links).index):
        w = image[g]
        if w in seen:
            errors.append(f"{g}: moves apart from {seen[w]} in PyBullet but is welded to it "
                          "in MuJoCo")
        seen.setdefault(w, g)
    for g, w in image.items():
        p = parent.get(g)
        if p is None or p not in image:
            continue
        got = weld[up[w]] if w else 0
        if w and got != image[p]:
            errors.append(f"{g}: hangs from {_weld_name(model, got)} in MuJoCo, from {p} in "
                          "PyBullet")
    for name, k in match.joints.items():
        j = next(j for j in robot.joints if j.name == name)
        b = fixed.joint_body[k]
        if group[j.child] in image and weld[b] != image[group[j.child]]:
            errors.append(f"joint {name}: moves {_body_name(model, b)} in MuJoCo, "
                          f"{j.child} in PyBullet")
    return errors, len(image)


def _weld_name(model: _Model, w: int) -> str:
    return "the world" if w == 0 else _body_name(model, w)
