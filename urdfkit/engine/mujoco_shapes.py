"""A link's collision shapes and bounding box on the MuJoCo engine, as PyBullet gives them.

:func:`collision_shapes` is PyBullet's ``getCollisionShapeData``: each collision geom of a link
as a :class:`~urdfkit.engine.api.CollisionShape`, its frame in the link's inertial frame
(PyBullet's link frame), a box by its full sizes, a sphere by its radius (three times, as
PyBullet writes it), a cylinder or capsule by its length and radius, a mesh by its scale with
its vertices and the file it was read from. :func:`visual_shapes` is ``getVisualShapeData``:
the visual geoms the same way (a sphere by its radius once), each in its link's URDF frame,
with the colour the export wrote (MuJoCo's grey where it wrote none; PyBullet's is white, and
PyBullet lets a later ``<visual>`` reuse a material named in an earlier one, which the export
does not). A link without ``<visual>`` has none here; PyBullet lists its collision shapes as
what it draws. :func:`aabb` is ``getAABB``: the world box around the link's collision geoms
now.
"""

from __future__ import annotations

from typing import Any

from urdfkit.engine.api import CollisionShape, ShapeKind, Vec3, VisualShape
from urdfkit.engine.mujoco_world import World, vec3

#: PyBullet's AABB of a plane: all of space.
_FAR = 1e30


def collision_shapes(w: World, body: int, link: int) -> list[CollisionShape]:
    """A link's collision shapes (link -1: the root), in the export's order."""
    import numpy as np

    from urdfkit.model.spec import quat_to_matrix

    m, _ = w.compiled()
    r, _ = w.body(body)
    target = r.link(link)
    mj = w.mj
    # the link's inertial frame in its MuJoCo body
    dyn = target.dynamics
    frame = np.asarray(target.frame, dtype=float)
    rot = frame[:3, :3] @ np.array(quat_to_matrix(dyn.inertial_orientation))
    origin = frame[:3, 3] + frame[:3, :3] @ np.array(dyn.inertial_position)
    out = []
    for name, owner, _ in r.collisions:
        if owner != target.name:
            continue
        g = m.geom(f"{body}/{name}")
        at, turn = r.placed[name]
        shape_rot = rot.T @ np.array(quat_to_matrix(turn))
        position = vec3(rot.T @ (np.array(at) - origin))
        orientation = _quat(mj, np, shape_rot)
        shape, dims, filename = _kind(w, r, body, g)
        vertices: list[Vec3] | None = None
        if shape == "mesh":
            # MuJoCo's vertices are about the mesh's own centre, where its geom now sits
            geom_rot = np.array(quat_to_matrix((*g.quat[1:], g.quat[0])))
            local = hull(m, np, int(g.dataid[0])) @ geom_rot.T + g.pos
            vertices = [vec3(v) for v in (local - origin) @ rot]
        out.append(CollisionShape(shape, dims, position, orientation, vertices, filename))
    return out


def visual_shapes(w: World, body: int) -> list[VisualShape]:
    """A body's visual geoms, by link (the root first), each in its link's URDF frame."""
    import numpy as np

    from urdfkit.model.spec import quat_to_matrix

    m, _ = w.compiled()
    r, _ = w.body(body)
    index = {r.robot.root: -1} | {j.child: i for i, j in enumerate(r.robot.joints)}
    out = []
    for name, owner in r.visuals:
        link = index[owner]
        frame = np.asarray(r.link(link).frame, dtype=float)  # the link frame in its body
        at, turn = r.placed[name]
        g = m.geom(f"{body}/{name}")
        shape, dims, filename = _kind(w, r, body, g)
        if shape == "sphere":  # getVisualShapeData's: the radius, then zeros
            dims = (dims[0], 0.0, 0.0)
        rot = frame[:3, :3].T @ np.array(quat_to_matrix(turn))
        position = vec3(frame[:3, :3].T @ (np.array(at) - frame[:3, 3]))
        rgba = tuple(float(x) for x in g.rgba)
        out.append(VisualShape(link, shape, dims, filename, position, _quat(w.mj, np, rot),
                               (rgba[0], rgba[1], rgba[2], rgba[3])))
    out.sort(key=lambda v: v.link)  # stable: each link's in the export's order
    return out


def _kind(w: World, r: Any, body: int, g: Any) -> tuple[ShapeKind, tuple[float, ...], str]:
    """A compiled geom's kind, its dimensions as PyBullet writes them, a mesh's file."""
    m, types = w.m, w.mj.mjtGeom
    kind = int(g.type[0])
    size = [float(x) for x in g.size]
    if kind == types.mjGEOM_BOX:
        return "box", (2 * size[0], 2 * size[1], 2 * size[2]), ""
    if kind == types.mjGEOM_SPHERE:
        return "sphere", (size[0],) * 3, ""
    if kind in (types.mjGEOM_CYLINDER, types.mjGEOM_CAPSULE):
        return ("cylinder" if kind == types.mjGEOM_CYLINDER else "capsule",
                (2 * size[1], size[0], 0.0), "")
    if kind == types.mjGEOM_PLANE:
        return "plane", (0.0, 0.0, 1.0), ""
    if kind == types.mjGEOM_MESH:
        mesh = int(g.dataid[0])
        name = m.mesh(mesh).name.removeprefix(f"{body}/")
        return "mesh", tuple(float(x) for x in m.mesh_scale[mesh]), r.mesh_files.get(name, "")
    return "other", tuple(size), ""


def aabb(w: World, body: int, link: int) -> tuple[Vec3, Vec3]:
    """A link's axis-aligned bounding box now, world: the box of its collision geoms.

    Each geom's own: a box's corners, a sphere's, a cylinder's or capsule's rims, a mesh's
    convex hull (what MuJoCo collides with), so the box is tight (PyBullet's is the box, in
    world axes, of the link's box in its inertial frame: larger when either is turned). A
    link without collision geoms: its centre of mass, a box of no size (PyBullet's: 1 mm
    around it); a plane reaches everywhere (PyBullet's 1e30).
    """
    import numpy as np

    from urdfkit.engine.mujoco_bodies import link_pose

    m, d = w.compiled()
    r, _ = w.body(body)
    name = r.link(link).name
    w.fresh_kinematics()
    types = w.mj.mjtGeom
    lo, hi = np.full(3, np.inf), np.full(3, -np.inf)
    for geom, owner, _ in r.collisions:
        if owner != name:
            continue
        g = m.geom(f"{body}/{geom}").id
        kind, size = m.geom_type[g], m.geom_size[g]
        rot, centre = d.geom_xmat[g].reshape(3, 3), d.geom_xpos[g]
        if kind == types.mjGEOM_PLANE:
            return (-_FAR, -_FAR, -_FAR), (_FAR, _FAR, _FAR)
        if kind == types.mjGEOM_MESH:
            points = hull(m, np, int(m.geom_dataid[g])) @ rot.T + centre
            lo, hi = np.minimum(lo, points.min(axis=0)), np.maximum(hi, points.max(axis=0))
            continue
        if kind == types.mjGEOM_SPHERE:
            half = np.full(3, size[0])
        elif kind in (types.mjGEOM_CYLINDER, types.mjGEOM_CAPSULE):
            axis = np.abs(rot[:, 2])    # each world axis: the rims' reach, or the caps'
            rim = np.sqrt(np.clip(1.0 - axis * axis, 0.0, 1.0)) \
                if kind == types.mjGEOM_CYLINDER else np.ones(3)
            half = axis * size[1] + rim * size[0]
        else:   # a box, or any other by MuJoCo's box around it in its own frame
            box = m.geom_aabb[g]
            centre = centre + rot @ box[:3]
            half = np.abs(rot) @ box[3:]
        lo, hi = np.minimum(lo, centre - half), np.maximum(hi, centre + half)
    if not np.isfinite(lo).all():
        at = link_pose(w, body, link).inertial_position
        return at, at
    return vec3(lo), vec3(hi)


def hull(m: Any, np: Any, mesh: int) -> Any:
    """A mesh's convex hull's vertices (MuJoCo's, about the mesh's centre).

    All of its vertices where MuJoCo keeps no hull (it computes one only for geoms it
    collides by their types, not by explicit pairs as here).
    """
    start, count = int(m.mesh_vertadr[mesh]), int(m.mesh_vertnum[mesh])
    vertices = m.mesh_vert[start:start + count]
    at = int(m.mesh_graphadr[mesh])
    if at < 0:
        return vertices
    # MuJoCo's graph: numvert, numface, vert_edgeadr[numvert], vert_globalid[numvert], ...
    n = int(m.mesh_graph[at])
    return vertices[m.mesh_graph[at + 2 + n:at + 2 + 2 * n]]


def _quat(mj: Any, np: Any, rot: Any) -> tuple[float, float, float, float]:
    """A rotation matrix as a quaternion (x, y, z, w)."""
    q = np.zeros(4)
    mj.mju_mat2Quat(q, np.ascontiguousarray(rot).flatten())
    return float(q[1]), float(q[2]), float(q[3]), float(q[0])
