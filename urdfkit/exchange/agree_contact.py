"""Collision geometry and contact parameters: PyBullet's shapes against MuJoCo's geoms.

PyBullet's side is what it loaded, through the engine seam (``collision_shapes``, PyBullet's
``getCollisionShapeData``: kind, dimensions, the shape's frame in the link's inertial frame;
``dynamics``, its ``getDynamicsInfo``: friction), not the file; MuJoCo's is the file's
collision geoms (:meth:`~urdfkit.engine.mujoco_file.MjcfFile.geoms`). Both sides
are placed in the world at the zero pose, base at the origin, and each PyBullet shape takes the
nearest unused MuJoCo collision geom (``contype`` or ``conaffinity`` set) of the same kind in
the body its link is welded to. A shape nothing matches is missing, a geom left over is extra,
and a matched pair is as far apart as the farthest of its sizes and corners. Meshes are
compared by the box around their vertices (MuJoCo keeps them in float32).

Contact parameters are compared per matched pair: friction (sliding, torsional, rolling), the
contact dimension that makes MuJoCo use the last two, that the geom meets MuJoCo's default
geoms (a ground), and that its priority makes MuJoCo take the robot's friction against a
ground, as PyBullet multiplies it by a ground's 1.0 (MuJoCo takes the larger of two equals).
:func:`collisions` writes the rows.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any

from urdfkit.exchange.agree_sides import Sides
from urdfkit.formats.fk import fused, link_frames

if TYPE_CHECKING:
    from urdfkit.engine.mujoco_file import Geom
    from urdfkit.engine.pybullet import PyBulletEngine

#: Sizes and places of primitives (m); measured 1.7e-16 at worst on r2d2, racecar, husky.
TOL_SHAPE = 1e-9
#: Mesh boxes, relative to the mesh's size (MuJoCo stores vertices in float32).
TOL_MESH = 1e-6
#: PyBullet's own collision vertices (getMeshData) against MuJoCo's, m (a mesh of 1 m or more:
#: relative to its size). Bullet's hull puts its points off the file's by up to 0.19 mm, most
#: by ~0.1 mm (bicycle's frame_scaled_left.stl; tiago 4.9e-5, kuka_iiwa 1.3e-5, r2d2 5.6e-6),
#: measured, cause not traced: a check of urdfkit's reading of a mesh against PyBullet's own,
#: which a misread file fails by far (jaxon's repeated COLLADA ids: 0.43).
TOL_BULLET_HULL = 1e-3
TOL_FRICTION = 1e-12


@dataclass
class Shape:
    """One collision shape in the world at the zero pose, in MuJoCo's terms."""

    link: str
    kind: str
    size: tuple[float, ...]      # MuJoCo's: half sizes; sphere (r,), cylinder (r, half)
    frame: Any                   # 4x4, world
    box: Any = None              # meshes: (min, max) of the vertices in the world
    group: str = ""


@dataclass
class Verdict:
    """What the comparison found, for the rows."""

    shape_error: tuple[float, str] | None    # None: no primitive on either side
    mesh_error: tuple[float, str] | None
    hull_error: tuple[float, str] | None     # PyBullet's own mesh data vs MuJoCo's
    missing: list[str]
    extra: list[str]
    skipped: list[str]
    contact: list[str]
    pairs: int
    links_compared: int


def _matrix(quat: Any) -> Any:
    import numpy as np

    from urdfkit.model.spec import quat_to_matrix

    n = math.sqrt(sum(c * c for c in quat)) or 1.0
    return np.array(quat_to_matrix([c / n for c in quat]))


def _transform(pos: Any, quat: Any) -> Any:
    import numpy as np

    t = np.eye(4)
    t[:3, :3] = _matrix(quat)
    t[:3, 3] = pos
    return t


_MESH_BOXES: dict[tuple[str, tuple[float, ...]], Any] = {}


def _mesh_points(path: str, scale: tuple[float, ...]) -> Any:
    """A mesh's vertices as PyBullet places them, scaled; None if none.

    Read as export reads it (:func:`urdfkit.formats.mjcf_mesh.mesh_asset`: the triangles
    MuJoCo can take), and only the vertices those triangles use: a COLLADA file's arrays may
    hold more (tiago's torso_lift_collision_*.dae hold the same 154, each file's triangles 16
    to 74), and PyBullet's hull leaves out an OBJ's stray vertex.
    """
    import numpy as np

    from urdfkit.formats.mjcf_mesh import mesh_asset

    key = (path, scale)
    if key not in _MESH_BOXES:
        asset = mesh_asset(Path(path))
        pts = None
        if not isinstance(asset, str) and len(asset.faces):
            used = np.unique(np.asarray(asset.faces))
            pts = np.asarray(asset.vertices, dtype=float)[used] * np.array(scale)
        _MESH_BOXES[key] = pts if pts is not None and len(pts) else None
    return _MESH_BOXES[key]


def _why_skipped(kind: str, size: tuple[float, ...], scale: tuple[float, ...],
                 static: bool) -> str:
    if kind == "plane" and not static:
        return "a plane on a moving link (MuJoCo allows planes on static bodies only)"
    if kind in ("sphere", "box", "cylinder", "capsule") and not all(
            s > 0 for s in size[:{"sphere": 1, "box": 3}.get(kind, 2)]):
        return "a zero-size shape (MuJoCo refuses it)"
    if kind == "mesh" and not all(s != 0 for s in scale):
        return "a mesh scaled by 0 (MuJoCo refuses it)"
    return ""


def pybullet_shapes(engine: PyBulletEngine, body: int, link_index: dict[str, int],
                    zero: dict[str, Any], group: dict[str, str], static: set[str]
                    ) -> tuple[list[Shape], list[str]]:
    """PyBullet's collision shapes at the zero pose, and those MuJoCo cannot hold (said)."""
    shapes: list[Shape] = []
    skipped: list[str] = []
    for link, i in link_index.items():
        if link not in zero:
            continue
        d = engine.dynamics(body, i)
        at = zero[link] @ _transform(d.inertial_position, d.inertial_orientation)
        for s in engine.collision_shapes(body, i):
            kind = s.kind
            dims = tuple(float(x) for x in s.dimensions)
            if kind == "other":
                skipped.append(f"{link}: a PyBullet geometry of no kind MuJoCo has")
                continue
            scale = dims if kind == "mesh" else (1.0, 1.0, 1.0)
            why = _why_skipped(kind, dims, scale, group[link] in static)
            if why:
                skipped.append(f"{link}: {why}")
                continue
            frame = at @ _transform(s.position, s.orientation)
            size: tuple[float, ...] = ()
            box = None
            if kind == "sphere":
                size = (dims[0],)
            elif kind == "box":
                size = (dims[0] / 2, dims[1] / 2, dims[2] / 2)
            elif kind in ("cylinder", "capsule"):
                size = (dims[1], dims[0] / 2)
            elif kind == "mesh":
                pts = _mesh_points(s.filename, scale)
                if pts is None:
                    skipped.append(f"{link}: a mesh urdfkit's readers find no vertices in")
                    continue
                world = pts @ frame[:3, :3].T + frame[:3, 3]
                box = (world.min(axis=0), world.max(axis=0))
            shapes.append(Shape(link, kind, size, frame, box, group[link]))
    return shapes, skipped


def pybullet_mesh_boxes(engine: PyBulletEngine, body: int, link_index: dict[str, int],
                        zero: dict[str, Any], shapes: list[Shape], skipped: list[str]
                        ) -> dict[str, Any]:
    """PyBullet's own vertices of each link whose collision shapes are all meshes, as a box.

    ``getMeshData(body, link, -1)`` (:meth:`~urdfkit.engine.pybullet.PyBulletEngine.\
collision_vertices`) gives every collision vertex PyBullet keeps for a link, in its inertial
    frame (measured: it matches the files' placed vertices exactly, and leaves out an OBJ's
    stray vertex): a check of urdfkit's mesh reading by PyBullet itself.
    """
    import numpy as np

    kinds: dict[str, set[str]] = {}
    for sh in shapes:
        kinds.setdefault(sh.link, set()).add(sh.kind)
    out = {}
    for link, k in kinds.items():
        if k != {"mesh"} or any(x.startswith(f"{link}: ") for x in skipped):
            continue
        vertices = engine.collision_vertices(body, link_index[link])
        if not vertices:
            continue
        d = engine.dynamics(body, link_index[link])
        at = zero[link] @ _transform(d.inertial_position, d.inertial_orientation)
        world = np.asarray(vertices, dtype=float) @ at[:3, :3].T + at[:3, 3]
        out[link] = (world.min(axis=0), world.max(axis=0))
    return out


def _union_errors(pairs: list[tuple[Shape, int, float]], geoms: list[tuple[int, Shape]],
                  boxes: dict[str, Any]) -> list[tuple[float, str]]:
    """Each link's PyBullet mesh box against the box of the MuJoCo geoms paired with it."""
    import numpy as np

    by_geom = dict(geoms)
    errors = []
    for link, (lo, hi) in boxes.items():
        mine = [by_geom[g].box for sh, g, _ in pairs if sh.link == link]
        if not mine:
            continue
        mlo = np.min([b[0] for b in mine], axis=0)
        mhi = np.max([b[1] for b in mine], axis=0)
        scale = max(1.0, float(np.abs(np.concatenate((lo, hi))).max()))
        errors.append((max(float(np.abs(mlo - lo).max()), float(np.abs(mhi - hi).max()))
                       / scale, link))
    return errors


def mujoco_geoms(geoms: list[Geom], keep_world: bool) -> list[tuple[int, Shape]]:
    """MuJoCo's collision geoms as shapes (``link`` empty): (geom id, shape).

    The world's own geoms (a ground) are left out unless ``keep_world`` (the URDF's root is
    ``world``).
    """
    return [(g.index, Shape("", g.kind, g.size, g.frame, g.box)) for g in geoms
            if g.body != 0 or keep_world]


def _corners(s: Shape) -> Any:
    import itertools

    import numpy as np

    signs = np.array(list(itertools.product((-1, 1), repeat=3)), dtype=float)
    return (signs * np.array(s.size)) @ s.frame[:3, :3].T + s.frame[:3, 3]


def distance(a: Shape, b: Shape) -> float:
    """How far apart two shapes of one kind are (m): sizes, places and axes."""
    import numpy as np

    centre = float(np.abs(a.frame[:3, 3] - b.frame[:3, 3]).max())
    if a.kind == "sphere":
        return max(abs(a.size[0] - b.size[0]), centre)
    if a.kind == "box":
        # the box's corners as sets: a box turned onto itself is the same box
        ca, cb = _corners(a), _corners(b)
        gap = np.abs(ca[:, None, :] - cb[None, :, :]).max(axis=2)
        return float(max(gap.min(axis=1).max(), gap.min(axis=0).max()))
    if a.kind in ("cylinder", "capsule"):
        za, zb = a.frame[:3, 2], b.frame[:3, 2]
        axis = min(float(np.abs(za - zb).max()), float(np.abs(za + zb).max()))
        return max(abs(a.size[0] - b.size[0]), abs(a.size[1] - b.size[1]), centre,
                   axis * max(a.size[1], a.size[0]))
    if a.kind == "mesh":
        return max(float(np.abs(a.box[0] - b.box[0]).max()),
                   float(np.abs(a.box[1] - b.box[1]).max()))
    if a.kind == "plane":  # the same normal, and b's point on a's plane
        return max(abs(float(a.frame[:3, 2] @ (b.frame[:3, 3] - a.frame[:3, 3]))),
                   float(np.abs(a.frame[:3, 2] - b.frame[:3, 2]).max()))
    return math.inf


def _extent(s: Shape) -> float:
    import numpy as np

    return max(1.0, float(np.abs(np.concatenate(s.box)).max())) if s.box is not None else 1.0


def compare(pb_shapes: list[Shape], geoms: list[tuple[int, Shape]], body_weld: Any,
            image: dict[str, int], names: dict[int, str], on_world: Any = None
            ) -> tuple[list[tuple[Shape, int, float]], list[str], list[str]]:
    """Pair each PyBullet shape with the nearest MuJoCo geom: (pairs, missing, extra).

    Nearest first over all candidate pairs (same kind, same welded body), so that a link with
    several meshes (tiago's torso_lift_link: three) does not give its first shape a
    neighbour's geom.
    """
    options = []
    for i, s in enumerate(pb_shapes):
        for g, t in geoms:
            if t.kind != s.kind:
                continue
            if s.group in image and int(body_weld(g)) != image[s.group]:
                continue
            options.append((distance(s, t), i, g))
    options.sort(key=lambda x: (x[0], x[1], x[2]))
    used: set[int] = set()
    paired: dict[int, tuple[int, float]] = {}
    for e, i, g in options:
        if i in paired or g in used:
            continue
        paired[i] = (g, e)
        used.add(g)
    pairs = [(s, paired[i][0], paired[i][1]) for i, s in enumerate(pb_shapes) if i in paired]
    missing = [f"{s.link} ({s.kind})" for i, s in enumerate(pb_shapes) if i not in paired]
    # the world's own geoms that no shape of the URDF's `world` link took: a ground, scenery
    extra = [f"{names.get(g, g)} ({t.kind})" for g, t in geoms
             if g not in used and not (on_world and on_world(g))]
    return pairs, missing, extra


def contact_errors(engine: PyBulletEngine, body: int, link_index: dict[str, int],
                   pairs: list[tuple[Shape, int, float]], geoms: dict[int, Geom]) -> list[str]:
    """Friction, contact dimension, what the geom meets, and priority: one line a link."""
    out: list[str] = []
    seen: set[str] = set()
    for s, g, _ in pairs:
        if s.link in seen:
            continue
        d = engine.dynamics(body, link_index[s.link])
        lateral = float(d.lateral_friction)
        rolling, spinning = float(d.rolling_friction), float(d.spinning_friction)
        geom = geoms[g]
        slide, torsion, roll = geom.friction
        condim = geom.condim
        said = []
        if not abs(slide - lateral) <= TOL_FRICTION:  # (a NaN fails too)
            said.append(f"friction {slide:g}, PyBullet's lateral {lateral:g}")
        got_spin = torsion if condim >= 4 else 0.0
        if not abs(got_spin - spinning) <= TOL_FRICTION:
            said.append(f"torsional friction {got_spin:g} (condim {condim}), PyBullet's "
                        f"spinning {spinning:g}")
        got_roll = roll if condim >= 6 else 0.0
        if not abs(got_roll - rolling) <= TOL_FRICTION:
            said.append(f"rolling friction {got_roll:g} (condim {condim}), PyBullet's "
                        f"{rolling:g}")
        if not (geom.contype & 1 or geom.conaffinity & 1):
            said.append("meets no default geom (contype and conaffinity without bit 1): it "
                        "falls through a ground")
        if geom.priority <= 0:
            said.append(f"priority {geom.priority}: against a ground MuJoCo takes the "
                        "larger friction, PyBullet the product")
        if said:
            seen.add(s.link)
            out.append(f"{s.link} ({geom.name}): " + "; ".join(said))
    return out


def collision_verdict(engine: PyBulletEngine, body: int, link_index: dict[str, int],
                      all_geoms: list[Geom], zero: dict[str, Any], group: dict[str, str],
                      image: dict[str, int], static: set[str], keep_world: bool) -> Verdict:
    """Collision geometry and contact parameters of both engines, compared.

    PyBullet's through ``engine`` (its load ``body``), MuJoCo's the file's collision geoms
    (:meth:`~urdfkit.engine.mujoco_file.MjcfFile.geoms`).
    """
    by_id = {g.index: g for g in all_geoms}
    names = {g.index: g.name for g in all_geoms}
    shapes, skipped = pybullet_shapes(engine, body, link_index, zero, group, static)
    geoms = mujoco_geoms(all_geoms, keep_world)
    pairs, missing, extra = compare(
        shapes, geoms, lambda g: by_id[g].weld, image, names, lambda g: by_id[g].body == 0)
    prim = [(e, f"{s.link} ({s.kind})") for s, _, e in pairs if s.kind != "mesh"]
    mesh = [(e / _extent(s), f"{s.link} ({s.kind})") for s, _, e in pairs if s.kind == "mesh"]
    hull = _union_errors(pairs, geoms, pybullet_mesh_boxes(engine, body, link_index, zero,
                                                           shapes, skipped))
    return Verdict(max(prim, key=lambda x: x[0]) if prim else None,
                   max(mesh, key=lambda x: x[0]) if mesh else None,
                   max(hull, key=lambda x: x[0]) if hull else None, missing, extra, skipped,
                   contact_errors(engine, body, link_index, pairs, by_id), len(pairs),
                   len({s.link for s in shapes}))


def collisions(s: Sides) -> None:
    """The contact rows: collision shapes, meshes, contact parameters, what MuJoCo cannot hold."""
    robot, res = s.robot, s.result
    where = fused(robot)
    group = {n: g for n, (g, _) in where.items()}
    static = {robot.root} if (s.options.fixed_base or robot.root == "world"
                              or robot.links[robot.root].inertial.mass == 0) else set()
    v = collision_verdict(s.pb.engine, s.pb.body, s.pb.link_index, s.mjcf.geoms(),
                          link_frames(robot, {}), group, s.weld_image(where, s.mjcf.tree.weld),
                          static, keep_world=robot.root == "world")
    lost = ([f"missing in the MJCF: {', '.join(v.missing[:3])}"
             f"{' ...' if len(v.missing) > 3 else ''}"] if v.missing else []) + \
        ([f"extra in the MJCF: {', '.join(v.extra[:3])}{' ...' if len(v.extra) > 3 else ''}"]
         if v.extra else [])
    if not v.pairs and not lost:
        res.add("contacts", "collision shapes", None, None, "",
                "no collision shapes on either side", status="info")
        return _said_skipped(s, v.skipped)
    if lost or v.shape_error is not None:
        worst, at = v.shape_error or (0.0, "")
        res.add("contacts", "collision shapes", math.inf if lost else worst, TOL_SHAPE, "m",
                "; ".join(x for x in [*lost, at] if x))
    if v.mesh_error is not None:
        res.add("contacts", "collision meshes", v.mesh_error[0], TOL_MESH, "relative",
                v.mesh_error[1])
    if v.hull_error is not None:
        res.add("contacts", "collision meshes vs PyBullet's own vertices",
                v.hull_error[0], TOL_BULLET_HULL, "relative", f"{v.hull_error[1]} "
                "(getMeshData: Bullet's hull points lie up to ~2e-4 off the file's, measured)")
    res.add("contacts", "contact parameters", float(len(v.contact)), 0.0, "links",
            "; ".join(v.contact[:2]) + (" ..." if len(v.contact) > 2 else "")
            or f"friction, condim, priority of {v.pairs} geoms")
    _said_skipped(s, v.skipped)


def _said_skipped(s: Sides, skipped: list[str]) -> None:
    if skipped:
        s.result.add(
            "contacts", "shapes MuJoCo cannot hold", float(len(skipped)), None, "known",
            "; ".join(skipped[:3]) + (" ..." if len(skipped) > 3 else "")
            + " (left out by export)", status="known")
