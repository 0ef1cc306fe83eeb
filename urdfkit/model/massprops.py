"""Mass properties of rigidly joined parts: the one combination the builder, check and export use.

A part is its mass (or volume, for a solid of uniform density), its centre of mass and its
inertia tensor about that centre, both in the axes of one common frame. Joined, the masses add,
the centre of mass is their weighted mean, and each tensor is moved to that centre by the
parallel-axis theorem, ``I + m (|d|^2 E - d d^T)``, ``d`` from the common centre to the part's.

Plain Python, so that ``check`` (a link's collision solids, ``rules_mass``) stays free of numpy;
the builder (a link's shapes, :meth:`urdfkit.builder.Inertial.from_shapes`) and the MJCF writer
(the links fused into one body, :func:`urdfkit.formats.mjcf.combine`) place their parts in the
common axes first and call the same :func:`combine`.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import NamedTuple

from urdfkit.model.spec import Matrix3, Vec3

#: One part: (mass, centre of mass, inertia tensor about that centre), in the common axes.
Part = tuple[float, Sequence[float], Matrix3]


class MassProperties(NamedTuple):
    """Joined parts: total mass, centre of mass, and the (symmetric) tensor about it."""

    mass: float
    com: Vec3
    tensor: Matrix3


def combine(parts: Sequence[Part]) -> MassProperties:
    """The mass properties of ``parts`` joined rigidly (see the module).

    The centre of a total mass that is not positive is the first part's centre. Non-finite
    values are carried through, not refused: each caller says what it refuses.
    """
    total = sx = sy = sz = 0.0
    for m, c, _ in parts:
        total += m
        sx += m * c[0]
        sy += m * c[1]
        sz += m * c[2]
    if total > 0:
        cx, cy, cz = sx / total, sy / total, sz / total
    else:
        cx, cy, cz = parts[0][1][0], parts[0][1][1], parts[0][1][2]
    xx = xy = xz = yx = yy = yz = zx = zy = zz = 0.0
    for m, c, t in parts:
        dx, dy, dz = c[0] - cx, c[1] - cy, c[2] - cz
        d2 = dx * dx + dy * dy + dz * dz
        (t00, t01, t02), (t10, t11, t12), (t20, t21, t22) = t
        # each sum as (sum + tensor) + shift, the MJCF writer's order since the first export
        xx = xx + t00 + m * (d2 - dx * dx)
        xy = xy + t01 + m * (0.0 - dx * dy)
        xz = xz + t02 + m * (0.0 - dx * dz)
        yx = yx + t10 + m * (0.0 - dy * dx)
        yy = yy + t11 + m * (d2 - dy * dy)
        yz = yz + t12 + m * (0.0 - dy * dz)
        zx = zx + t20 + m * (0.0 - dz * dx)
        zy = zy + t21 + m * (0.0 - dz * dy)
        zz = zz + t22 + m * (d2 - dz * dz)
    # Exactly symmetric (a tensor rotated into the common axes can differ in the last bit):
    # (T + T^T) / 2, the diagonal included, which overflows past half the largest double.
    xx, yy, zz = (xx + xx) / 2, (yy + yy) / 2, (zz + zz) / 2
    xy = yx = (xy + yx) / 2
    xz = zx = (xz + zx) / 2
    yz = zy = (yz + zy) / 2
    return MassProperties(total, (cx, cy, cz), ((xx, xy, xz), (yx, yy, yz), (zx, zy, zz)))
