"""A body's shape as drive sees it: points on its collision shapes, its lowest point, roundness.

Read from the engine's collision shapes and link frames, never from the AABB: PyBullet's AABB of
a base with inertia products turns with its inertial frame and grows (1.8 cm on a small robot).
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from typing import TYPE_CHECKING

from urdfkit.model.spec import quat_to_matrix, rotate

if TYPE_CHECKING:
    from urdfkit.engine.api import Simulator

Vec = tuple[float, float, float]

#: Sectors around a joint axis in which :func:`roundness` measures how far the shapes reach.
ROUND_SECTORS = 12


def shape_points(engine: Simulator, body: int, link: int) -> list[Vec]:
    """Points outlining a link's collision shapes, in world coordinates.

    Meshes (and cylinders PyBullet turned into meshes) give their vertices; implicit
    cylinders, capsules, spheres and boxes are outlined from their dimensions.
    """
    if link < 0:  # the base: its pose is its inertial (COM) frame
        pos_, orn_ = engine.base_pose(body)
        com_pos, com_rot = tuple(pos_), quat_to_matrix(orn_)
    else:
        st = engine.link_pose(body, link)
        com_pos, com_rot = st.inertial_position, quat_to_matrix(st.inertial_orientation)
    out: list[Vec] = []
    for shape in engine.collision_shapes(body, link):
        kind, dims, pos, orn = shape.kind, shape.dimensions, shape.position, shape.orientation
        local: list[Vec] = []
        if kind == "mesh":
            if shape.vertices:  # already in the link's inertial frame
                out += [vadd(com_pos, rotate(com_rot, v)) for v in shape.vertices]
            continue
        if kind == "sphere":
            r = dims[0]
            local = [(r * x, r * y, r * z) for x, y, z in _SPHERE_DIRECTIONS]
        elif kind in ("cylinder", "capsule"):
            length, r = dims[0], dims[1]
            local = [(r * math.cos(a), r * math.sin(a), z)
                     for a in (2 * math.pi * i / 24 for i in range(24))
                     for z in (-length / 2, length / 2)]
            if kind == "capsule":  # and its two half-spheres, beyond the cylinder's ends
                local += [(r * x, r * y, r * z + math.copysign(length / 2, z))
                          for x, y, z in _SPHERE_DIRECTIONS]
        elif kind == "box":
            hx, hy, hz = (d / 2 for d in dims)
            local = [(sx * hx, sy * hy, sz * hz) for sx in (-1, 1) for sy in (-1, 1)
                     for sz in (-1, 1)]
        shape_rot = quat_to_matrix(orn)
        for v in local:
            in_com = vadd(pos, rotate(shape_rot, v))
            out.append(vadd(com_pos, rotate(com_rot, in_com)))
    return out


def base_link_pose(engine: Simulator, body: int) -> tuple[Sequence[float], Sequence[float]]:
    """The base link frame's world pose (the engine's base pose is its inertial frame).

    With ``URDF_USE_INERTIA_FROM_FILE`` an ``<inertia>`` with products (ixy, ixz, iyz), or an
    ``<inertial><origin>``, puts the inertial frame elsewhere than the link frame: its pose is
    not the robot's.
    """
    return engine.link_frame(body, -1)


def set_base_link_pose(engine: Simulator, body: int, pos: Sequence[float],
                       orn: Sequence[float]) -> None:
    """Place the base link frame (the loader places it; a reset places the inertial frame)."""
    engine.reset_base_frame(body, (pos[0], pos[1], pos[2]), (orn[0], orn[1], orn[2], orn[3]))


def lowest_point(engine: Simulator, body: int,
                 points: dict[int, list[Vec]] | None = None) -> float:
    """The lowest z of the body's collision shapes, from the shapes themselves.

    Not from the AABB: a link whose ``<inertia>`` has products gets a rotated inertial
    frame, and its AABB grows with it (1.8 cm below a small car's real corners), which would
    lift the start and disqualify the wheels as "above the robot's lowest point". A link
    without collision shapes does not count; a body with none falls back to the AABB.
    ``points`` (link index to :func:`shape_points`) saves measuring them again.
    """
    n = len(engine.joints(body))
    if points is None:
        points = {link: shape_points(engine, body, link) for link in range(-1, n)}
    zs = [pt[2] for pts in points.values() for pt in pts]
    finite = [z for z in zs if math.isfinite(z)]
    if finite:
        return min(finite)
    return min(engine.aabb(body, link)[0][2] for link in range(-1, n))


def _fibonacci_sphere(n: int) -> list[Vec]:
    """``n`` unit vectors spread evenly over the sphere."""
    golden = math.pi * (3.0 - math.sqrt(5.0))
    out: list[Vec] = []
    for i in range(n):
        z = 1.0 - 2.0 * (i + 0.5) / n
        r = math.sqrt(1.0 - z * z)
        out.append((r * math.cos(golden * i), r * math.sin(golden * i), z))
    return out


#: Directions outlining a sphere. 100 spread evenly keep every one of the 12 sectors about
#: ANY axis through the centre at >= 0.97 of the radius (measured over random axes), so a
#: sphere wheel is round whichever way its joint turns; a few dozen on meridians are not.
_SPHERE_DIRECTIONS = _fibonacci_sphere(100)


def vadd(a: Sequence[float], b: Sequence[float]) -> Vec:
    """A + b."""
    return (a[0] + b[0], a[1] + b[1], a[2] + b[2])


def vsub(a: Sequence[float], b: Sequence[float]) -> Vec:
    """A - b."""
    return (a[0] - b[0], a[1] - b[1], a[2] - b[2])


def vdot(a: Sequence[float], b: Sequence[float]) -> float:
    """A . b."""
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]


def vunit(a: Sequence[float]) -> Vec:
    """A scaled to length 1 (a zero vector stays zero)."""
    n = math.sqrt(vdot(a, a)) or 1.0
    return (a[0] / n, a[1] / n, a[2] / n)


def roundness(points: list[Vec], origin: Vec, axis: Vec) -> tuple[float, float, Vec] | None:
    """``(radius, worst sector fraction, centre on the axis)`` of points about an axis.

    None for no points, or for points that are not all finite (a shape sized 1e309 is
    infinite): nothing round can be measured from them.
    """
    if not points or not all(math.isfinite(c) for pt in points for c in pt) or \
            not all(math.isfinite(c) for c in (*origin, *axis)):
        return None
    # Two directions perpendicular to the axis.
    helper = (1.0, 0.0, 0.0) if abs(axis[0]) < 0.9 else (0.0, 1.0, 0.0)
    u = vunit(vsub(helper, tuple(axis[i] * vdot(helper, axis) for i in range(3))))
    v = (axis[1] * u[2] - axis[2] * u[1], axis[2] * u[0] - axis[0] * u[2],
         axis[0] * u[1] - axis[1] * u[0])
    reach = [0.0] * ROUND_SECTORS
    along = 0.0
    for pt in points:
        d = vsub(pt, origin)
        along += vdot(d, axis)
        a, b = vdot(d, u), vdot(d, v)
        sector = int((math.atan2(b, a) + math.pi) / (2 * math.pi) * ROUND_SECTORS) \
            % ROUND_SECTORS
        reach[sector] = max(reach[sector], math.hypot(a, b))
    radius = max(reach)
    if radius <= 0:
        return None
    mean = along / len(points)
    return radius, min(reach) / radius, vadd(origin, tuple(axis[i] * mean for i in range(3)))
