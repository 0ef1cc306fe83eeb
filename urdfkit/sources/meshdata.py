"""A mesh's mass properties as records: what the readers make and the lookup keeps.

:class:`Integrals` is a mesh's volume integrals as read (what the cache and a run's pack
keep, unscaled); :class:`MeshProperties` the solid under a ``<mesh scale>``. Read by
:mod:`urdfkit.sources.meshes`, looked up by :mod:`urdfkit.sources.meshstore`.

Named tuples, not dataclasses: ``check`` imports this on every run, and a frozen dataclass
costs ~0.7 ms to make at import, a named tuple a sixth of that.
"""

from __future__ import annotations

import struct
from typing import NamedTuple

#: Largest mesh file read for checks; bigger ones are skipped (checks must stay fast).
MAX_MESH_BYTES = 16 * 1024 * 1024
#: A mesh whose surface dips more than this fraction of its size inside its hull is concave.
CONCAVE_FRACTION = 0.02


class MeshProperties(NamedTuple):
    """A closed triangle mesh as a solid of unit density (scaled).

    Attributes:
        volume: m^3 (positive for outward-facing triangles).
        com: Centre of mass in the mesh frame.
        inertia: 3x3 inertia tensor about ``com`` per kg/m^3 (multiply by mass / volume).
        extent: Size of the bounding box along x, y, z.
        closed: Every edge is shared by exactly two triangles.
        triangles: How many triangles.
        concavity: How far (m, about, under non-uniform scale) the surface lies inside the
            convex hull PyBullet collides with: the largest distance of a vertex in front of
            the plane of a triangle of its own piece. 0 for a convex mesh; NaN when it was not
            asked for (``properties(..., concavity=True)``).
        pieces: Convex hulls PyBullet makes of it (one per ``o``/``g`` object of an OBJ).
    """

    volume: float
    com: tuple[float, float, float]
    inertia: tuple[tuple[float, ...], ...]
    extent: tuple[float, float, float]
    closed: bool
    triangles: int
    concavity: float = 0.0
    pieces: int = 1

    def trace_for_mass(self, mass: float) -> float | None:
        """Trace of the inertia of this solid with ``mass``, or None without a volume."""
        if not self.closed or self.volume <= 0:
            return None
        t = self.inertia
        return (t[0][0] + t[1][1] + t[2][2]) * mass / self.volume


class Integrals(NamedTuple):
    """A mesh's volume integrals as read, unscaled and signed (what the cache keeps).

    Attributes:
        volume: Signed volume (negative when the triangles face inward).
        first: Integrals of x, y, z over the solid.
        second: Integrals of xx, yy, zz, xy, xz, yz over the solid.
        low, high: Corners of the bounding box of the vertices the triangles use.
        closed, triangles, concavity, pieces: As in :class:`MeshProperties` (concavity
            unscaled).
    """

    volume: float
    first: tuple[float, float, float]
    second: tuple[float, float, float, float, float, float]
    low: tuple[float, float, float]
    high: tuple[float, float, float]
    closed: bool
    triangles: int
    concavity: float = 0.0
    pieces: int = 1

    def pack(self) -> bytes:
        """The cache entry's bytes."""
        return _ENTRY + _FORMAT.pack(self.volume, *self.first, *self.second, *self.low,
                                     *self.high, self.concavity, self.closed, self.triangles,
                                     self.pieces)

    @classmethod
    def unpack(cls, data: bytes) -> Integrals:
        """Read a cache entry; ValueError if it is not one."""
        if len(data) != len(_ENTRY) + _FORMAT.size or not data.startswith(_ENTRY):
            raise ValueError("not a mesh cache entry")
        v = _FORMAT.unpack_from(data, len(_ENTRY))
        return cls(v[0], v[1:4], v[4:10], v[10:13], v[13:16], v[17], v[18], v[16], v[19])

    def scaled(self, scale: tuple[float, float, float]) -> MeshProperties | None:
        """The solid under ``<mesh scale>``: integrals scale as powers of each factor.

        Written out term by term (check asks once per mesh and file): the same arithmetic, in
        the same order, as the matrix form ``about = sign det S M S - volume com com^T``.
        """
        sx, sy, sz = scale
        det = sx * sy * sz
        if det == 0:
            return None
        volume = self.volume * det
        f0, f1, f2 = self.first
        f0, f1, f2 = f0 * sx * det, f1 * sy * det, f2 * sz * det
        xx, yy, zz, xy, xz, yz = self.second
        m00, m01, m02 = xx * sx * sx, xy * sx * sy, xz * sx * sz
        m11, m12, m22 = yy * sy * sy, yz * sy * sz, zz * sz * sz
        sign = -1.0 if volume < 0 else 1.0  # inward triangles: the same solid, inside out
        volume *= sign
        if volume:
            c0, c1, c2 = sign * f0 / volume, sign * f1 / volume, sign * f2 / volume
        else:
            c0 = c1 = c2 = 0.0
        k = sign * det
        a00 = k * m00 - volume * c0 * c0
        a01 = k * m01 - volume * c0 * c1
        a02 = k * m02 - volume * c0 * c2
        a10 = k * m01 - volume * c1 * c0
        a11 = k * m11 - volume * c1 * c1
        a12 = k * m12 - volume * c1 * c2
        a20 = k * m02 - volume * c2 * c0
        a21 = k * m12 - volume * c2 * c1
        a22 = k * m22 - volume * c2 * c2
        trace = a00 + a11 + a22
        tensor = ((trace - a00, 0.0 - a01, 0.0 - a02),
                  (0.0 - a10, trace - a11, 0.0 - a12),
                  (0.0 - a20, 0.0 - a21, trace - a22))
        (x0, y0, z0), (x1, y1, z1) = self.low, self.high
        extent = (abs(sx) * (x1 - x0), abs(sy) * (y1 - y0), abs(sz) * (z1 - z0))
        return MeshProperties(volume, (c0, c1, c2), tensor, extent, self.closed,
                              self.triangles, self.concavity * max(abs(sx), abs(sy), abs(sz)),
                              self.pieces)


#: Cache entries start with this; a new layout is a new prefix and a new folder.
_ENTRY = b"M5"
#: Integrals' cache entry layout, after the prefix.
_FORMAT = struct.Struct("<17d?II")
