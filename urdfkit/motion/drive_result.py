"""What a drive run measured: its statistics while it runs, the circle it turned, its result.

:class:`DriveResult` is what :func:`urdfkit.motion.drive.drive` returns (and ``drive --json``
prints);
:class:`Stats` and :class:`Monitor` watch the samples as they come (memory stays flat however
long the run), and :func:`fit_circle` finds the turning circle of the settled part.
"""

from __future__ import annotations

import csv
import io
import json
import math
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from urdfkit.core.errors import ParameterError
from urdfkit.motion.vehicle import Drivetrain

#: The settled part of a turn, for the circle fit: samples after this fraction of the run.
SETTLED_FRACTION = 0.5


#: A circle is only fitted when the car turned at least this much (rad) while settled.
MIN_TURN = 0.5


#: A fitted circle counts only if the path stays this close to it (RMS, fraction of radius).
CIRCLE_TOLERANCE = 0.02


#: Settled samples kept for the circle fit; more are thinned evenly (memory stays flat).
FIT_SAMPLES = 2048



@dataclass
class Circle:
    """A circle fitted to a path: centre and radius (m), and the RMS distance off it."""

    center: tuple[float, float]
    radius: float
    rms: float


def fit_circle(xs: list[float], ys: list[float]) -> Circle | None:
    """Least-squares circle through points (Kasa's algebraic fit), or None if degenerate.

    Solves ``x^2 + y^2 + D x + E y + F = 0`` in the least-squares sense; coordinates are
    centred first so the 3x3 normal equations stay well conditioned. Pure Python: numpy is
    not worth importing for a 3x3 system.
    """
    n = len(xs)
    if n < 5:
        return None
    mx, my = sum(xs) / n, sum(ys) / n
    u = [x - mx for x in xs]
    v = [y - my for y in ys]
    w = [a * a + b * b for a, b in zip(u, v, strict=False)]
    suu = sum(a * a for a in u)
    svv = sum(b * b for b in v)
    suv = sum(a * b for a, b in zip(u, v, strict=False))
    suw = sum(a * c for a, c in zip(u, w, strict=False))
    svw = sum(b * c for b, c in zip(v, w, strict=False))
    # With centred data, sum(u) = sum(v) = 0, and the system for (D, E) decouples from F.
    det = suu * svv - suv * suv
    if abs(det) < 1e-12 * max(1.0, suu * svv):
        return None
    d = (-suw * svv + svw * suv) / det
    e = (-svw * suu + suw * suv) / det
    f = -sum(w) / n
    r2 = (d * d + e * e) / 4 - f
    if r2 <= 0:
        return None
    cu, cv = -d / 2, -e / 2
    radius = math.sqrt(r2)
    rms = math.sqrt(sum((math.hypot(a - cu, b - cv) - radius) ** 2
                        for a, b in zip(u, v, strict=False)) / n)
    return Circle((cu + mx, cv + my), radius, rms)


@dataclass
class DriveResult:
    """What a drive measured. Distances in m, angles in rad, times in s.

    Attributes:
        model: The car, as named on the command line (or ``simplecar``).
        final_position: Base position at the end.
        final_yaw: Base yaw at the end, in (-pi, pi].
        heading_change: Total yaw turned (unwrapped; positive = left).
        distance: Length of the base's path in the x-y plane (from the samples).
        mean_speed: ``distance / sim_time``.
        turning_radius: Radius of the circle fitted to the settled half of the path, when the
            car turned at least :data:`MIN_TURN` rad there and the path stays within
            :data:`CIRCLE_TOLERANCE` of the circle; else None, and ``radius_note`` says why.
        turn_center: That circle's centre.
        expected_radius: The model's radius for the base link's origin: the kinematic
            bicycle model for steered cars, ``v / omega`` for two-wheel differential robots;
            None for skid steering (see :meth:`Drivetrain.expected_radius`).
        radius_note: Why there is no turning radius (None when there is one).
        sim_time: Simulated time.
        steps: Physics steps taken.
        time_step: The physics time step.
        wall_time: Wall-clock time of the stepping loop.
        real_time_factor: ``sim_time / wall_time``.
        throttle: The throttle applied (rad/s).
        steer: The steer applied, after clamping (rad, or rad/s of yaw without hinges).
        interrupted: Ctrl-C stopped the run early.
        drivetrain: The wheels and hinges driven, and how.
        simulated: What was simulated: load flags, forces, time step, damping, the start.
        samples: How many samples were taken.
        trajectory: The samples (None unless the run kept them).
        warnings: Things the user should know (a clamped steer, ...), problems included.
        problems: What makes the run physically suspect: left the ground, fell, flipped,
            stuck, wheels slipping, static base, started inside the ground.
        yaw_rate: Mean yaw rate over the settled half (rad/s).
    """

    model: str
    final_position: tuple[float, float, float]
    final_yaw: float
    heading_change: float
    distance: float
    mean_speed: float
    turning_radius: float | None
    turn_center: tuple[float, float] | None
    sim_time: float
    steps: int
    time_step: float
    wall_time: float
    real_time_factor: float
    throttle: float
    steer: float
    interrupted: bool
    drivetrain: Drivetrain
    trajectory: Trajectory | None
    warnings: list[str] = field(default_factory=list)
    expected_radius: float | None = None
    radius_note: str | None = None
    simulated: dict[str, object] = field(default_factory=dict)
    samples: int = 0
    problems: list[str] = field(default_factory=list)
    yaw_rate: float | None = None

    def to_dict(self) -> dict[str, Any]:  # the JSON document
        """The JSON form (the trajectory goes to its own file, not here)."""
        def r(x: float | None) -> float | None:
            return None if x is None else round(x, 6)

        return {
            "model": self.model,
            "final_position": [r(v) for v in self.final_position],
            "final_yaw": r(self.final_yaw),
            "heading_change": r(self.heading_change),
            "yaw_rate": r(self.yaw_rate),
            "distance": r(self.distance),
            "mean_speed": r(self.mean_speed),
            "turning_radius": r(self.turning_radius),
            "turn_center": None if self.turn_center is None else [r(v) for v in self.turn_center],
            "expected_radius": r(self.expected_radius),
            "radius_note": self.radius_note,
            "sim_time": r(self.sim_time),
            "steps": self.steps,
            "time_step": self.time_step,
            "wall_time": r(self.wall_time),
            "real_time_factor": r(self.real_time_factor),
            "throttle": self.throttle,
            "steer": self.steer,
            "interrupted": self.interrupted,
            "samples": self.samples,
            "drivetrain": self.drivetrain.to_dict(),
            "simulated": self.simulated,
            "warnings": self.warnings,
            "problems": self.problems,
        }


class Stats:
    """Running statistics of a drive, in memory that does not grow with the run."""

    def __init__(self, settle_at: float):
        self.settle_at = settle_at
        self.distance = 0.0
        self.first_yaw: float | None = None
        self.yaw = 0.0  # unwrapped
        self.settled_yaw: float | None = None
        self.settled_t = 0.0
        self.fit: list[tuple[float, float]] = []
        self.stride = 1  # keep every stride-th settled sample
        self.seen = 0
        self.last: tuple[float, ...] | None = None
        self.count = 0

    def add(self, row: tuple[float, ...]) -> None:
        """Take one sample: distance, heading and (once settled) the points to fit."""
        t, x, y, yaw = row[0], row[1], row[2], row[6]
        if self.last is None:
            self.first_yaw = self.yaw = yaw
        else:
            self.distance += math.hypot(x - self.last[1], y - self.last[2])
            d = yaw - self.last[6]
            self.yaw += (d + math.pi) % (2 * math.pi) - math.pi
        if t >= self.settle_at:
            if self.settled_yaw is None:
                self.settled_yaw, self.settled_t = self.yaw, t
            if self.seen % self.stride == 0:
                self.fit.append((x, y))
                if len(self.fit) >= FIT_SAMPLES:  # thin evenly: every other one goes
                    self.fit = self.fit[::2]
                    self.stride *= 2
            self.seen += 1
        self.last = row
        self.count += 1

    def yaw_rate(self) -> float | None:
        """Mean yaw rate over the settled half (rad/s), None before it."""
        if self.settled_yaw is None or self.last is None or self.last[0] <= self.settled_t:
            return None
        return (self.yaw - self.settled_yaw) / (self.last[0] - self.settled_t)

    def circle(self) -> tuple[Circle | None, str | None]:
        """The settled path's circle, or None and why not."""
        if self.settled_yaw is None or len(self.fit) < 5:
            return None, "too few settled samples for a circle"
        turned = abs(self.yaw - self.settled_yaw)
        if turned < MIN_TURN:
            return None, (f"straight: turned {turned:.2f} rad in the settled half (a circle "
                          f"needs {MIN_TURN:g})")
        c = fit_circle([p[0] for p in self.fit], [p[1] for p in self.fit])
        if c is None:
            return None, "the settled path fits no circle"
        if c.rms > CIRCLE_TOLERANCE * c.radius:
            return None, (f"not a circle: the settled path strays {c.rms:.3g} m RMS "
                          f"({c.rms / c.radius:.0%}) from the best circle (r = "
                          f"{c.radius:.3g} m)")
        return c, None


class Monitor:
    """Watches a run's samples for what makes it physically suspect (first time each).

    Args:
        train: The drivetrain driven.
        columns: The run's sample columns.
        bounds: The ground's extent, (x0, y0, x1, y1), or None.
        top: The ground's height, or None.
        static_base: The base cannot move (said once already; its wheels spin in the air).
        duration: The run's simulated length (s).
    """

    def __init__(self, train: Drivetrain, columns: list[str],
                 bounds: tuple[float, float, float, float] | None, top: float | None,
                 static_base: bool, duration: float) -> None:
        self.problems: list[str] = []
        self.seen: set[str] = set()
        self.bounds = bounds
        self.top = top
        self.wheel_cols = [(columns.index(f"{train.joint_names[w]}_speed"),
                           train.radius.get(w, train.reference_radius)) for w in train.driven]
        self.stuck_since: float | None = None
        if static_base:  # said once already; its wheels spin in the air by design
            self.wheel_cols = []
        self.slip_sum = self.tread_sum = 0.0
        self.settle_at = duration * SETTLED_FRACTION

    def _once(self, key: str, message: str) -> None:
        if key not in self.seen:
            self.seen.add(key)
            self.problems.append(message)

    def add(self, row: tuple[float, ...]) -> None:
        """Take one sample: off the ground, flipped, stuck or slipping, said once each."""
        t, x, y, z, roll, pitch = row[0], row[1], row[2], row[3], row[4], row[5]
        if self.bounds is not None:
            x0, x1, y0, y1 = self.bounds
            if not (x0 <= x <= x1 and y0 <= y <= y1):
                self._once("left", f"left the ground at t = {t:.2f} s, at ({x:.2f}, {y:.2f}) "
                           f"m (the ground spans x {x0:g}..{x1:g}, y {y0:g}..{y1:g})")
        if self.top is not None and z < self.top - 1.0:
            self._once("fell", f"fell: z = {z:.2f} m at t = {t:.2f} s, more than 1 m below "
                       "the ground's top")
        if math.cos(roll) * math.cos(pitch) < 0:
            self._once("flipped", f"flipped over at t = {t:.2f} s")
        if not self.wheel_cols or self.seen & {"left", "fell"}:
            return  # off the ground, wheel and body speeds say nothing about traction
        tread = sum(abs(row[i]) * r for i, r in self.wheel_cols) / len(self.wheel_cols)
        body = math.hypot(row[7], row[8])
        if tread > 0.1 and body < 0.05 * tread:
            if self.stuck_since is None:
                self.stuck_since = t
            elif t - self.stuck_since >= 1.0:
                self._once("stuck", f"stuck from t = {self.stuck_since:.2f} s: the wheels "
                           f"turn ({tread:.2f} m/s at the tread) but the body does not move")
        else:
            self.stuck_since = None
        if t >= self.settle_at:
            self.slip_sum += abs(tread - body)
            self.tread_sum += tread

    def finish(self) -> list[str]:
        """Every problem seen, and slip over the settled half."""
        if self.tread_sum > 0 and "stuck" not in self.seen \
                and self.slip_sum / self.tread_sum > 0.3:
            self._once("slip", f"wheels slipping: over the settled half the treads and the "
                       f"body differ by {self.slip_sum / self.tread_sum:.0%} of the tread speed")
        return self.problems


#: Trajectory formats by file suffix.
TRAJECTORY_FORMATS = (".csv", ".jsonl")


@dataclass
class Trajectory:
    """Samples of the car's state: one row per sample, in :attr:`columns` order."""

    columns: list[str]
    rows: list[tuple[float, ...]] = field(default_factory=list)

    def column(self, name: str) -> list[float]:
        """All values of one column."""
        i = self.columns.index(name)
        return [r[i] for r in self.rows]

    def to_bytes(self, fmt: str) -> bytes:
        """The trajectory as ``.csv`` or ``.jsonl`` bytes (deterministic: fixed precision)."""
        return self.header_bytes(fmt) + self.rows_bytes(self.rows, fmt)

    def header_bytes(self, fmt: str) -> bytes:
        """What comes before the rows: the CSV header line; nothing for JSON lines."""
        check_format(fmt)
        if fmt != ".csv":
            return b""
        buf = io.StringIO()
        csv.writer(buf, lineterminator="\n").writerow(self.columns)
        return buf.getvalue().encode("utf-8")

    def rows_bytes(self, rows: list[tuple[float, ...]], fmt: str) -> bytes:
        """Rows as CSV lines or JSON lines (non-finite values as empty / null)."""
        from urdfkit.model.xmlio import fmt_float

        check_format(fmt)
        cells = [[fmt_float(v) if math.isfinite(v) else "" for v in row] for row in rows]
        if fmt == ".csv":
            buf = io.StringIO()
            csv.writer(buf, lineterminator="\n").writerows(cells)
            return buf.getvalue().encode("utf-8")
        lines = ("{" + ", ".join(f"{json.dumps(k)}: {v or 'null'}"
                                 for k, v in zip(self.columns, row, strict=False))
                 + "}\n" for row in cells)
        return "".join(lines).encode("utf-8")


def check_format(fmt: str) -> None:
    """Refuse a trajectory format other than :data:`TRAJECTORY_FORMATS`."""
    if fmt not in TRAJECTORY_FORMATS:
        raise ParameterError(f"trajectory format must be one of {', '.join(TRAJECTORY_FORMATS)}"
                             f", got {fmt or 'no suffix'!r}", param="trajectory")


def trajectory_format(path: str | Path) -> str:
    """The format a trajectory path asks for, checked before the run starts."""
    suffix = Path(path).suffix.lower()
    if suffix not in TRAJECTORY_FORMATS:
        raise ParameterError(f"`trajectory` must end in {' or '.join(TRAJECTORY_FORMATS)}",
                             param="trajectory")
    return suffix
