"""What ``agree`` reports: its options, its rows, and the tolerance beside each figure.

Each comparison is one :class:`Row` with its worst figure, its tolerance and what the figure is
about; :class:`Agreement` holds them with what could not be matched. docs/export.md explains
each tolerance.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

#: Tolerances (docs/export.md explains each).
TOL_EXACT = 1e-12          # joint limits, damping (absolute); masses (relative)
TOL_COM = 1e-12            # centres of mass, m
TOL_INERTIA = 1e-9         # inertia tensors, relative to the largest moment
TOL_PYBULLET_FRAME = 1e-6  # getLinkState: float32 inside
TOL_FK = 1e-12             # against double-precision forward kinematics
TOL_DYNAMICS = 1e-9        # mass matrix, inverse dynamics, relative
TOL_SWING = 1e-9           # rad over the free swing
TOL_FLOATING_BASE = 1e-9   # m, and in the rotation matrix, over the floating swing
LIMIT_MARGIN = 0.01        # rad: the swing is compared until a joint comes this close


@dataclass
class Row:
    """One comparison: its worst figure, the tolerance, and what the figure is about."""

    group: str
    what: str
    value: float | None
    tolerance: float | None
    unit: str
    status: str          # pass, fail, info, known
    detail: str = ""

    @property
    def ok(self) -> bool:
        """Whether the row holds (info and known differences do not fail)."""
        return self.status != "fail"


@dataclass
class AgreeOptions:
    """How to compare.

    Attributes:
        fixed_base: The export welded the base (``useFixedBase``).
        inertia_from_file: PyBullet loads with URDF_USE_INERTIA_FROM_FILE (export's default).
        self_collision: Self-collision was asked for (contacts at the poses are allowed).
        poses: How many seeded poses.
        seed: The poses' seed.
        seconds: The free swing's length.
        time_step: Its step.
        name_map: URDF link or joint name -> MJCF body, site or joint name, for pairs whose
            names differ (``--map``); the rest match by name, then by the tree's shape.
    """

    fixed_base: bool = False
    inertia_from_file: bool = True
    self_collision: bool = False
    poses: int = 100
    seed: int = 0
    seconds: float = 1.0
    time_step: float = 1e-3
    name_map: dict[str, str] = field(default_factory=dict)


@dataclass
class Agreement:
    """Every row, and what could not be matched."""

    file: str
    model: str
    rows: list[Row] = field(default_factory=list)
    unmatched_links: list[str] = field(default_factory=list)
    unmatched_joints: list[str] = field(default_factory=list)
    extra_joints: list[str] = field(default_factory=list)
    #: pairs not matched by name: {"urdf", "mjcf", "how": "map" | "structure"}
    matched_by: list[dict[str, str]] = field(default_factory=list)
    load_flags: list[str] = field(default_factory=list)
    #: What the other engine said while loading the model (MuJoCo's decoders', Drake's).
    warnings: list[str] = field(default_factory=list)
    #: The other engine, as messages name it.
    engine: str = "MuJoCo"
    #: ``--engine``: each joint's indices in PyBullet and in the other engine, side by side
    #: ({"joint", "pybullet": {"index", "q", "u"}, "engine": {"kind", "q", "nq", "v", "nv"}}).
    indices: list[dict[str, object]] = field(default_factory=list)

    @property
    def ok(self) -> bool:
        """Whether every row holds."""
        return all(r.ok for r in self.rows)

    def add(self, group: str, what: str, value: float | None, tolerance: float | None,
            unit: str, detail: str = "", status: str | None = None) -> None:
        """A row; its status from the figure and the tolerance unless given."""
        if status is None:  # (a NaN figure fails: NaN <= tolerance is False)
            status = "pass" if value is not None and tolerance is not None and \
                value <= tolerance else "fail"
        self.rows.append(Row(group, what, value, tolerance, unit, status, detail))


def worst(items: list[tuple[float, str]]) -> tuple[float, str]:
    """The largest figure, a NaN above all (a NaN in the MJCF must not pass as 0)."""
    return max(items, key=lambda x: math.inf if x[0] != x[0] else x[0]) if items else (0.0, "")
