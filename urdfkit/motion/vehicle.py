"""Which joints of a loaded body are wheels and steering hinges, and how to drive them.

Detection works on the body the engine loaded (so it sees exactly the joint indices the motors
are addressed by), in the **base frame**: the caller stands the body upright for it (see
:func:`detect_drivetrain`), so a car spawned tilted is judged as the car it is.

- A **wheel** is a continuous joint (PyBullet reports those as ``JOINT_REVOLUTE`` with
  ``lower=0, upper=-1``; a revolute joint whose range covers a full turn counts too) about an
  axis roughly horizontal in the base frame, whose link is **round about that axis** (its
  collision shapes, cylinder, sphere or mesh, reach the same radius all the way round) and
  **touches the ground** (its lowest point is the robot's lowest point). An arm's wrist and a
  quadruped's knee are none of these.
- A **steering hinge** is a revolute joint with limits about an axis vertical in the base
  frame that carries a wheel. A vertical joint without limits (a full turn) that carries a
  wheel is a **caster's swivel**; it and its wheel roll free and are listed as a caster, as
  are the links that rest on the ground beside the wheels (a fixed ball or skid).
- Every other movable joint is **passive**. The drive holds passive joints at their start
  angle (an arm on a mobile base) unless asked to let them go limp; casters always roll free.

Driving (:class:`Drivetrain`) follows the kinematic bicycle model: with steer angle ``d`` the
car turns about the point on the rear axle's line at ``R = L / tan d`` (``L`` the wheelbase,
from the detected geometry). Each hinge gets its Ackermann angle for that point (equal angles
when the hinges share a pivot, as simplecar's do), and in the ``differential`` drivetrain each
wheel turns at the speed its own path needs (an ideal electronic differential). Without
hinges, wheels are driven as a skid-steered base: ``steer`` is then the yaw rate (rad/s), and
each side's speed differs by it times the track.

A base without hinges whose two driven wheels sit one each side is a **two-wheel differential**
robot (steering ``differential``); with more it is **skid steered** (``skid``). Both take
``steer`` as the yaw rate; the differential one's model radius is ``v / omega``.

Signs are part of detection. Positive throttle means "forward along the base's x axis" and
positive steer means "left, counter-clockwise seen from above", whatever way each joint's axis
points in the file: racecar.urdf's wheel axes point along -y, simplecar's along +y.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import TYPE_CHECKING

from urdfkit.core.errors import ParameterError
from urdfkit.model.spec import quat_to_matrix, rotate
from urdfkit.motion.vehicle_shapes import (
    Vec,
    base_link_pose,
    lowest_point,
    roundness,
    set_base_link_pose,
    shape_points,
    vdot,
    vsub,
    vunit,
)

if TYPE_CHECKING:
    from urdfkit.engine.api import JointInfo, Simulator

#: |axis . up| below this is "horizontal" (about 11 degrees of tilt allowed).
HORIZONTAL_TOLERANCE = 0.2
#: |axis . up| above this is "vertical".
VERTICAL_TOLERANCE = 0.98
#: A wheel is round: its shapes reach at least this fraction of its radius in every sector
#: around its axis (:data:`urdfkit.motion.vehicle_shapes.ROUND_SECTORS`).
ROUND_FRACTION = 0.9
#: A wheel's lowest point is within this fraction of its radius of the robot's lowest point.
GROUND_FRACTION = 0.25

#: Hinge motor force (N m): PyBullet's own default for POSITION_CONTROL, which the tutorial
#: relies on. With the wheel force (10) instead, one hinge of simplecar stalls at 0.02 rad of
#: a 0.2 rad target while the tyres scrub: steering would silently not happen.
STEER_FORCE = 100000.0
#: PyBullet's default motor force when ``setJointMotorControl2`` is not given one.
PYBULLET_DEFAULT_FORCE = 100000.0

#: How the wheels are driven (see docs/drive.md).
DRIVETRAINS = ("differential", "rear", "locked")



class DrivetrainError(ParameterError):
    """The model has no wheels, or ``wheels``/``hinges`` name joints it does not have."""


@dataclass
class Drivetrain:
    """The driven joints of a body, their geometry in the base frame, and how to drive them.

    Attributes:
        wheels: Wheel joints (VELOCITY_CONTROL).
        hinges: Steering joints (POSITION_CONTROL).
        passive: Other movable joints; their default motors are switched off.
        joint_names: Name of every joint index.
        hinge_limits: ``(lower, upper)`` of each hinge, in the steer convention (positive =
            left); ``(-inf, inf)`` when the joint has no limits.
        wheel_signs: ``+1`` or ``-1`` per wheel: the factor that turns "forward" into that
            joint's velocity.
        hinge_signs: ``+1`` or ``-1`` per hinge: the factor that turns "left" into that
            joint's position.
        mode: ``differential``, ``rear`` or ``locked`` (see :data:`DRIVETRAINS`).
        radius: Each wheel's rolling radius (m).
        contact: Each wheel's contact point (x forward, y left of :attr:`forward`) from the
            base link's origin, hinges at 0.
        carried_by: The hinge each wheel hangs from, if any.
        pivot: Each hinge's pivot (x, y) in the base frame.
        forward: The direction "forward" (x, y components in the base frame): the way the
            wheels roll that is closest to the base's +x (+y when they roll along y).
        casters: Caster joints (swivels without limits that carry a wheel, and those
            wheels; and the full-turn joints a caster link rolls on): passive, and always
            free.
        caster_links: Links other than the wheels that rest on the ground at the start (a
            fixed ball or skid under the base), by index.
        link_names: Name of every link index (-1 the base).
        efforts: Each joint's effort limit from the URDF (N m or N; 0 when not given).
    """

    wheels: list[int]
    hinges: list[int]
    passive: list[int]
    joint_names: dict[int, str]
    hinge_limits: dict[int, tuple[float, float]]
    wheel_signs: dict[int, float] = field(default_factory=dict)
    hinge_signs: dict[int, float] = field(default_factory=dict)
    mode: str = "differential"
    radius: dict[int, float] = field(default_factory=dict)
    contact: dict[int, tuple[float, float]] = field(default_factory=dict)
    carried_by: dict[int, int | None] = field(default_factory=dict)
    pivot: dict[int, tuple[float, float]] = field(default_factory=dict)
    forward: tuple[float, float] = (1.0, 0.0)
    casters: list[int] = field(default_factory=list)
    caster_links: list[int] = field(default_factory=list)
    link_names: dict[int, str] = field(default_factory=dict)
    efforts: dict[int, float] = field(default_factory=dict)

    # ---- geometry

    @property
    def steering(self) -> str:
        """How the base is steered.

        ``ackermann``: by hinges. Without hinges, by the speed difference of left and right
        (``steer`` is then a yaw rate): ``differential`` for two driven wheels, one each side
        (casters aside); ``skid`` for more, whose wheels must slip sideways to turn.
        """
        if self.hinges:
            return "ackermann"
        ys = [self.contact[w][1] for w in self.driven if w in self.contact]
        if len(ys) == 2 and ys[0] * ys[1] < 0:
            return "differential"
        return "skid"

    @property
    def yaw_steered(self) -> bool:
        """True when ``steer`` is a yaw rate (no hinges: differential or skid steering)."""
        return not self.hinges

    @property
    def rear_x(self) -> float:
        """The rear axle's x: the mean of the wheels no hinge carries (all, if none)."""
        fixed = [self.contact[w][0] for w in self.wheels
                 if self.carried_by.get(w) is None and w in self.contact]
        xs = fixed or [self.contact[w][0] for w in self.wheels if w in self.contact]
        return sum(xs) / len(xs) if xs else 0.0

    @property
    def wheelbase(self) -> float | None:
        """Mean distance from the rear axle to the hinge pivots (None without hinges).

        When every wheel hangs from a hinge (four-wheel steering: youBot's casters named as
        hinges), the "rear axle" is the wheels' mean x and the distance is to the hinges ahead
        of it; :meth:`hinge_angles` then turns those behind the other way. Taken over every
        pivot, front and rear cancel to 0 and every hinge turned the same way: the base
        crabbed sideways at the steer angle and never turned.
        """
        pivots = [self.pivot[h][0] for h in self.hinges if h in self.pivot]
        if not pivots:
            return None
        if all(self.carried_by.get(w) is not None for w in self.wheels):
            ahead = [x for x in pivots if x > self.rear_x]
            if ahead and len(ahead) < len(pivots):
                pivots = ahead
        return sum(pivots) / len(pivots) - self.rear_x

    @property
    def track(self) -> float:
        """Distance between the left-most and right-most wheel contacts."""
        ys = [self.contact[w][1] for w in self.wheels if w in self.contact]
        return max(ys) - min(ys) if ys else 0.0

    @property
    def reference_radius(self) -> float:
        """The radius of a wheel on the car's centre line: the driven wheels' mean."""
        rs = [self.radius[w] for w in self.driven if w in self.radius]
        return sum(rs) / len(rs) if rs else 1.0

    @property
    def driven(self) -> list[int]:
        """The wheels the drivetrain powers (``rear``: those no hinge carries)."""
        if self.mode == "rear" and self.hinges:
            return [w for w in self.wheels if self.carried_by.get(w) is None]
        return list(self.wheels)

    @property
    def free(self) -> list[int]:
        """Wheels that roll free (``rear``: the steered ones)."""
        driven = set(self.driven)
        return [w for w in self.wheels if w not in driven]

    def turn_center(self, steer: float) -> tuple[float, float] | None:
        """The instantaneous centre of rotation (x, y) in the base frame, None if straight."""
        if self.yaw_steered or steer == 0 or not self.wheelbase:
            return None
        return (self.rear_x, self.wheelbase / math.tan(steer))

    def expected_radius(self, throttle: float, steer: float) -> float | None:
        """The model's turning radius of the base link's origin (m), None without a model.

        Ackermann steering: the kinematic bicycle model, ``R = L / tan(steer)`` about the
        rear axle. Two-wheel differential: rolling without slip, the wheels' midpoint moves
        at ``v = throttle * radius`` and turns at ``omega = steer``, about the point ``v /
        omega`` to its left on the axle's line. Skid steering has no such model: its wheels
        must slip sideways to turn at all.
        """
        if self.mode == "locked":
            return None
        if self.steering == "ackermann":
            return self.bicycle_radius(steer)
        if self.steering != "differential" or steer == 0:
            return None
        v = throttle * self.reference_radius
        xs = [self.contact[w][0] for w in self.driven if w in self.contact]
        axle_x = sum(xs) / len(xs) if xs else 0.0
        return math.hypot(axle_x, v / steer)

    def bicycle_radius(self, steer: float) -> float | None:
        """The kinematic bicycle model's turning radius of the base link's origin (m)."""
        c = self.turn_center(steer)
        return None if c is None else math.hypot(c[0], c[1])

    def hinge_angles(self, steer: float) -> dict[int, float]:
        """Each hinge's angle for ``steer`` (the bicycle model's angle; positive = left)."""
        c = self.turn_center(steer)
        out: dict[int, float] = {}
        for h in self.hinges:
            if c is None or h not in self.pivot:
                out[h] = steer
                continue
            px, py = self.pivot[h]
            lateral = c[1] - py
            out[h] = math.atan((px - c[0]) / lateral) if lateral else math.copysign(
                math.pi / 2, steer)
        return out

    def wheel_speeds(self, throttle: float, steer: float) -> dict[int, float]:
        """Each driven wheel's angular speed (rad/s, positive = forward).

        ``throttle`` is the angular speed of a wheel of :attr:`reference_radius` on the car's
        centre line (at the rear axle); ``locked`` gives every wheel ``throttle``.
        """
        if self.mode == "locked":
            return {w: throttle for w in self.wheels}
        speed = throttle * self.reference_radius  # m/s of the rear axle's centre
        out: dict[int, float] = {}
        if self.yaw_steered:
            for w in self.driven:
                y = self.contact.get(w, (0.0, 0.0))[1]
                out[w] = (speed - steer * y) / self.radius.get(w, self.reference_radius)
            return out
        c = self.turn_center(steer)
        angles = self.hinge_angles(steer)
        for w in self.driven:
            r = self.radius.get(w, self.reference_radius)
            if c is None or w not in self.contact:
                out[w] = speed / r
                continue
            x, y = self.contact[w]
            h = self.carried_by.get(w)
            if h is not None and h in self.pivot:  # the wheel swings about its hinge
                px, py = self.pivot[h]
                a = angles[h]
                dx, dy = x - px, y - py
                x, y = px + dx * math.cos(a) - dy * math.sin(a), py + dx * math.sin(a) \
                    + dy * math.cos(a)
            out[w] = speed * math.hypot(x - c[0], y - c[1]) / abs(c[1]) / r
        return out

    def steer_range(self) -> tuple[float, float]:
        """The steer angles every hinge can reach (the intersection of their limits)."""
        lo, hi = -math.inf, math.inf
        for lower, upper in self.hinge_limits.values():
            lo, hi = max(lo, lower), min(hi, upper)
        return lo, hi

    def to_dict(self) -> dict[str, object]:
        """The JSON form: names keyed by joint index, and the geometry driving used."""
        def named(joints: list[int]) -> list[dict[str, object]]:
            return [{"index": j, "name": self.joint_names[j]} for j in joints]

        def r(x: float) -> float:
            return round(x, 6)

        return {
            "mode": self.mode, "steering": self.steering,
            "wheels": [{**named([w])[0], "radius": r(self.radius[w]) if w in self.radius
                        else None, "contact": [r(v) for v in self.contact[w]]
                        if w in self.contact else None, "driven": w in self.driven}
                       for w in self.wheels],
            "hinges": named(self.hinges), "passive": named(self.passive),
            "casters": named(self.casters),
            "caster_links": [self.link_names.get(k, str(k)) for k in self.caster_links],
            "forward": [r(v) for v in self.forward],
            "wheelbase": None if self.wheelbase is None else r(self.wheelbase),
            "track": r(self.track),
        }


def _is_continuous(info: JointInfo) -> bool:
    return info.kind == "revolute" and (not info.limited
                                        or info.upper - info.lower >= 2 * math.pi - 1e-6)


def _pick(spec: Sequence[str | int], names: dict[int, str], movable: list[int],
          what: str) -> list[int]:
    by_name = {n: j for j, n in names.items()}
    out: list[int] = []
    for item in spec:
        key = item.strip() if isinstance(item, str) else item
        if isinstance(key, str) and key.lstrip("-").isdigit():
            key = int(key)
        if isinstance(key, int):
            if key not in names:
                raise DrivetrainError(f"`{what}`: no joint with index {key} (the model has "
                                      f"joints 0..{len(names) - 1})", param=what)
            out.append(key)
        elif key in by_name:
            out.append(by_name[key])
        else:
            from urdfkit.core.suggest import hint

            known = ", ".join(names.values()) or "none"
            raise DrivetrainError(f"`{what}`: no joint named {key!r}"
                                  f"{hint(str(key), names.values())} (joints: {known})",
                                  param=what)
        if out[-1] not in movable:
            raise DrivetrainError(f"`{what}`: joint {names[out[-1]]!r} is fixed and cannot "
                                  "be driven", param=what)
    return out


def detect_drivetrain(engine: Simulator, body: int,
                      wheels: Sequence[str | int] | None = None,
                      hinges: Sequence[str | int] | None = None,
                      mode: str = "differential") -> Drivetrain:
    """Find the wheels, steering hinges and passive joints of a body standing upright.

    Call it before the first ``stepSimulation``, with every joint at zero and the base in its
    upright orientation (the caller turns it to the spawn pose afterwards): "horizontal",
    "vertical" and "touches the ground" are judged in the base frame.

    Args:
        engine: The world the body is in.
        body: The body id.
        wheels: Joint names or indices to drive instead of the detected wheels.
        hinges: Joint names or indices to steer instead of the detected hinges.
        mode: The drivetrain (see :data:`DRIVETRAINS`).

    Raises:
        DrivetrainError: no wheels were found (or given), or a name/index is unknown.
    """
    if mode not in DRIVETRAINS:
        raise DrivetrainError(f"`drivetrain` must be one of {', '.join(DRIVETRAINS)}, got "
                              f"{mode!r}", param="drivetrain")
    scan = _Scan(engine, body)
    names, movable, infos = scan.names, scan.movable, scan.infos
    wheel_list = _pick(wheels, names, movable, "wheels") if wheels is not None \
        else _find_wheels(scan)
    casters: list[int] = []
    if hinges is not None:
        hinge_list = _pick(hinges, names, movable, "hinges")
    else:
        wheel_list, hinge_list, casters = _find_hinges(scan, wheel_list, wheels is not None)
    overlap = set(wheel_list) & set(hinge_list)
    if overlap:
        raise DrivetrainError(f"joint {names[min(overlap)]!r} cannot be both a wheel and a hinge",
                              param="hinges")
    forward = _forward([scan.axes[w] for w in wheel_list], scan.base_x, scan.base_y)
    scan.face(forward)
    radius, contact, wheel_signs = _wheel_geometry(scan, wheel_list, forward)
    hinge_signs, hinge_limits, pivot = _hinge_geometry(scan, hinge_list)
    carried_by = {w: scan.hinge_of(w, hinge_list) for w in wheel_list}
    driven = set(wheel_list) | set(hinge_list)
    passive = [j for j in movable if j not in driven]
    in_base = (vdot(forward, scan.base_x), vdot(forward, scan.base_y))
    n = scan.n
    link_names = {k: infos[k].link for k in range(n)}
    link_names[-1] = engine.link_names(body)[0]
    efforts = {j: infos[j].effort for j in movable}
    caster_links = _caster_links(scan, wheel_list, casters)
    free = set(casters) | _caster_rollers(scan, caster_links, wheel_list, hinge_list)
    return Drivetrain(wheel_list, hinge_list, passive, names, hinge_limits, wheel_signs,
                      hinge_signs, mode, radius, contact, carried_by, pivot, in_base,
                      [j for j in movable if j in free], caster_links, link_names, efforts)


class _Scan:
    """What detection reads of a body once: joints, their world axes and origins, shapes."""

    def __init__(self, engine: Simulator, body: int) -> None:
        self.infos = infos = engine.joints(body)
        self.n = n = len(infos)
        self.names = {j: info.name for j, info in enumerate(infos)}
        self.movable = movable = [j for j, info in enumerate(infos)
                                  if info.kind in ("revolute", "prismatic")]
        states = {j: engine.link_pose(body, j) for j in movable}
        self.origin: dict[int, Vec] = {j: (states[j].position[0], states[j].position[1],
                                           states[j].position[2]) for j in movable}
        # getJointInfo's axis is in the child's inertial frame (measured: with inertia products
        # and URDF_USE_INERTIA_FROM_FILE a PR2 caster's vertical axis read 32 degrees off in the
        # link frame), so it turns with the link's centre-of-mass orientation, not its URDF
        # frame.
        self.axes = {j: vunit(rotate(quat_to_matrix(states[j].inertial_orientation),
                                     infos[j].axis))
                     for j in movable}
        base = engine.link_pose(body, -1)
        self.base_link, base_link_orn = base.position, base.orientation
        base_rot = quat_to_matrix(base_link_orn)
        self.base_x = rotate(base_rot, (1.0, 0.0, 0.0))
        self.base_y = rotate(base_rot, (0.0, 1.0, 0.0))
        self.link_points = {link: shape_points(engine, body, link) for link in range(-1, n)}
        self.lowest = lowest_point(engine, body, self.link_points)
        self._shapes: dict[int, tuple[float, float, Vec] | None] = {}
        self.forward: Vec = (1.0, 0.0, 0.0)
        self.left: Vec = (0.0, 1.0, 0.0)

    def round_about(self, j: int) -> tuple[float, float, Vec] | None:
        """How round joint ``j``'s link is about its axis (:func:`roundness`), once."""
        if j not in self._shapes:
            self._shapes[j] = roundness(self.link_points[j], self.origin[j], self.axes[j])
        return self._shapes[j]

    def hinge_of(self, w: int, candidates: Sequence[int]) -> int | None:
        """The nearest joint above ``w`` (``w`` excluded) that is among ``candidates``."""
        k = self.infos[w].parent
        while k >= 0:
            if k in candidates:
                return k
            k = self.infos[k].parent
        return None

    def face(self, forward: Vec) -> None:
        """Set the vehicle's forward direction (for :meth:`planar`)."""
        self.forward, self.left = forward, (-forward[1], forward[0], 0.0)

    def planar(self, pt: Sequence[float]) -> tuple[float, float]:
        """A world point in the vehicle's plane: (ahead of, left of) the base link."""
        d = vsub(pt, self.base_link)
        return (vdot(d, self.forward), vdot(d, self.left))


def _find_wheels(scan: _Scan) -> list[int]:
    """Continuous joints about a horizontal axis whose round link touches the ground."""
    rejected: list[str] = []
    wheel_list = []
    names, axes = scan.names, scan.axes
    for j in scan.movable:
        if not _is_continuous(scan.infos[j]):
            continue
        if abs(axes[j][2]) >= HORIZONTAL_TOLERANCE:
            rejected.append(f"{names[j]} (its axis is not horizontal)")
            continue
        shape = scan.round_about(j)
        if shape is None:
            rejected.append(f"{names[j]} (its link has no collision shape to roll on)")
            continue
        size, fraction, centre = shape
        if fraction < ROUND_FRACTION:
            rejected.append(f"{names[j]} (its link is not round about the joint axis)")
            continue
        bottom = centre[2] - size * math.sqrt(max(0.0, 1 - axes[j][2] ** 2))
        if bottom - scan.lowest > max(GROUND_FRACTION * size, 0.005):
            rejected.append(f"{names[j]} ({bottom - scan.lowest:.2f} m above the robot's "
                            "lowest point)")
            continue
        wheel_list.append(j)
    if not wheel_list:
        why = f"; turning joints that are not wheels: {', '.join(rejected[:4])}" \
            if rejected else ""
        raise DrivetrainError("no wheels found: a wheel is a continuous joint (or one with a "
                              "full turn of range) about a horizontal axis, whose link is "
                              f"round about it and touches the ground{why}. An arm or a "
                              "legged robot has none; name wheels with `wheels` (and "
                              "steering joints with `hinges`)", param="wheels")
    return wheel_list


def _find_hinges(scan: _Scan, wheel_list: list[int], named_wheels: bool
                 ) -> tuple[list[int], list[int], list[int]]:
    """Steering hinges above the wheels, and casters: (wheels, hinges, casters)."""
    infos, axes = scan.infos, scan.axes
    verticals = [j for j in scan.movable if j not in set(wheel_list)
                 and infos[j].kind == "revolute" and abs(axes[j][2]) > VERTICAL_TOLERANCE]
    carrying = [j for j in verticals if any(scan.hinge_of(w, [j]) == j for w in wheel_list)]
    # A vertical joint that turns all the way round is a caster's swivel, not steering:
    # it and the wheels it carries roll free (unless the user named those wheels).
    swivels = [j for j in carrying if _is_continuous(infos[j])]
    hinge_list = [j for j in carrying if j not in swivels]
    casters: list[int] = []
    if swivels:
        trailing = [w for w in wheel_list if scan.hinge_of(w, swivels) is not None]
        casters = swivels + ([] if named_wheels else trailing)
        if not named_wheels:
            wheel_list = [w for w in wheel_list if w not in trailing]
            if not wheel_list:
                raise DrivetrainError(
                    "no wheels found: every wheel hangs from a swivel that turns all the "
                    f"way round (swivels: {', '.join(scan.names[j] for j in swivels)}; the "
                    f"wheels on them: {', '.join(scan.names[j] for j in trailing)}), which "
                    "drive takes for casters; name the wheels to drive with `wheels` and the "
                    "joints that steer them with `hinges`", param="wheels")
    return wheel_list, hinge_list, casters


def _wheel_geometry(scan: _Scan, wheel_list: list[int], forward: Vec
                    ) -> tuple[dict[int, float], dict[int, tuple[float, float]],
                               dict[int, float]]:
    """Each wheel's radius, ground contact in the vehicle plane, and spin sign."""
    radius: dict[int, float] = {}
    contact: dict[int, tuple[float, float]] = {}
    wheel_signs: dict[int, float] = {}
    for j in wheel_list:
        shape = scan.round_about(j)
        if shape is not None:
            radius[j] = shape[0]
            contact[j] = scan.planar(shape[2])
        else:  # a named wheel without collision shapes: its height above the ground
            radius[j] = max(scan.origin[j][2] - scan.lowest, 1e-3)
            contact[j] = scan.planar(scan.origin[j])
        a = scan.axes[j]
        # A wheel spinning positively about axis a moves the car along a x up.
        along = a[1] * forward[0] - a[0] * forward[1]
        wheel_signs[j] = -1.0 if along < 0 else 1.0
    return radius, contact, wheel_signs


def _hinge_geometry(scan: _Scan, hinge_list: list[int]
                    ) -> tuple[dict[int, float], dict[int, tuple[float, float]],
                               dict[int, tuple[float, float]]]:
    """Each hinge's sign (its axis up or down), limits in that sense, and pivot."""
    hinge_signs: dict[int, float] = {}
    hinge_limits: dict[int, tuple[float, float]] = {}
    pivot: dict[int, tuple[float, float]] = {}
    for j in hinge_list:
        sign = -1.0 if scan.axes[j][2] < 0 else 1.0
        hinge_signs[j] = sign
        pivot[j] = scan.planar(scan.origin[j])
        lower, upper = scan.infos[j].lower, scan.infos[j].upper
        if not scan.infos[j].limited:
            hinge_limits[j] = (-math.inf, math.inf)
        else:
            ends = sorted((lower * sign, upper * sign))
            hinge_limits[j] = (ends[0], ends[1])
    return hinge_signs, hinge_limits, pivot


def _caster_links(scan: _Scan, wheel_list: list[int], casters: list[int]) -> list[int]:
    """Links resting on the ground beside the wheels: a fixed caster ball or skid.

    The links the wheels and casters turn with are not among them, nor is the base itself.
    """
    rolling = {j for j in wheel_list + casters}
    for j in range(scan.n):
        if scan.hinge_of(j, sorted(rolling)) is not None:
            rolling.add(j)
    return [k for k in range(scan.n) if k not in rolling and scan.link_points[k]
            and min(pt[2] for pt in scan.link_points[k]) - scan.lowest <= 0.005]


def _caster_rollers(scan: _Scan, caster_links: list[int], wheel_list: list[int],
                    hinge_list: list[int]) -> set[int]:
    """The full-turn joints a caster link rolls on: a ball caster modelled as joints.

    Toyota's HSR models each passive wheel as a frame rolling about x, one about y and the ball
    on a joint about z, each with an effort. Held at their start angles they lock the ball,
    which then drags on the ground (HSR went 0.461 m where raw PyBullet with them free goes
    0.792 m). Walking up from each caster link, every continuous joint is the caster's own,
    until a joint that is not continuous or that also carries a wheel (a turning drive unit).
    """
    carrying: set[int] = set()
    for w in wheel_list:
        k = scan.infos[w].parent
        while k >= 0:
            carrying.add(k)
            k = scan.infos[k].parent
    rollers: set[int] = set()
    for k in caster_links:
        j = k
        while j >= 0 and j not in carrying:
            if j in scan.movable:
                if not _is_continuous(scan.infos[j]) or j in wheel_list or j in hinge_list:
                    break
                rollers.add(j)
            j = scan.infos[j].parent
    return rollers


def _forward(wheel_axes: list[Vec], base_x: Vec, base_y: Vec) -> Vec:
    """The horizontal direction the wheels roll in that is closest to the base's +x.

    Wheels that roll along the base's y (r2d2's do) drive along +y: forward can only be a
    direction the wheels roll in.
    """
    flat_x = vunit((base_x[0], base_x[1], 0.0))
    ref = wheel_axes[0]
    total = [0.0, 0.0]
    for a in wheel_axes:
        s = 1.0 if a[0] * ref[0] + a[1] * ref[1] >= 0 else -1.0
        total[0] += s * a[0]
        total[1] += s * a[1]
    if math.hypot(*total) < 1e-9:
        return flat_x
    roll = vunit((-total[1], total[0], 0.0))  # up x axis: perpendicular in the ground plane
    along_x = vdot(roll, flat_x)
    if abs(along_x) >= 0.1:
        return roll if along_x > 0 else (-roll[0], -roll[1], 0.0)
    flat_y = (base_y[0], base_y[1], 0.0)
    return roll if vdot(roll, flat_y) > 0 else (-roll[0], -roll[1], 0.0)


def detect_upright(engine: Simulator, body: int, upright: Sequence[float],
                   wheels: Sequence[str | int] | None = None,
                   hinges: Sequence[str | int] | None = None,
                   mode: str = "differential") -> Drivetrain:
    """:func:`detect_drivetrain` with the base link turned to ``upright`` (a quaternion).

    A body spawned tilted (or upside down) is stood up where it is for detection, so its
    wheels are judged in its own frame, then put back exactly as it was.
    """
    pos, orn = base_link_pose(engine, body)  # the link frame is the one to stand up
    turned = any(abs(a - b) > 1e-12 for a, b in zip(orn, upright, strict=True))
    if turned:
        set_base_link_pose(engine, body, pos, list(upright))
    try:
        return detect_drivetrain(engine, body, wheels, hinges, mode)
    finally:
        if turned:
            set_base_link_pose(engine, body, pos, orn)


def disable_default_motors(engine: Simulator, body: int, joints: Sequence[int]) -> None:
    """Switch off PyBullet's default velocity motors on ``joints``.

    PyBullet gives every revolute and prismatic joint a velocity motor with target 0 at load
    time; left on, it brakes the joint. Force 0 frees it (and makes the first step of large
    bodies fast).
    """
    if not joints:
        return
    engine.motors(body, list(joints), "velocity", [0.0] * len(joints),
                  forces=[0.0] * len(joints))


def apply_drive(engine: Simulator, body: int, train: Drivetrain, throttle: float,
                steer: float, max_force: float | None, steer_force: float = STEER_FORCE
                ) -> None:
    """Set the wheel and hinge motors once; PyBullet keeps them until they are changed.

    Args:
        engine: The world the body is in.
        body: The body id.
        train: What :func:`detect_drivetrain` found.
        throttle: Wheel angular velocity, rad/s (positive = forward): see
            :meth:`Drivetrain.wheel_speeds`.
        steer: Steer angle, rad (positive = left), or the yaw rate (rad/s) of a skid-steered
            base. Callers clamp it to :meth:`Drivetrain.steer_range` first.
        max_force: Maximum torque (N m) of every wheel motor; None: PyBullet's default.
        steer_force: Maximum torque (N m) of every hinge motor.
    """
    speeds = train.wheel_speeds(throttle, steer)
    force = PYBULLET_DEFAULT_FORCE if max_force is None else max_force
    driven = [w for w in train.wheels if w in speeds]
    if driven:
        engine.motors(body, driven, "velocity",
                      [speeds[w] * train.wheel_signs.get(w, 1.0) for w in driven],
                      forces=[force] * len(driven))
    disable_default_motors(engine, body, train.free)
    if train.hinges:
        angles = train.hinge_angles(steer) if train.mode != "locked" else \
            dict.fromkeys(train.hinges, steer)
        engine.motors(body, train.hinges, "position",
                      [angles[h] * train.hinge_signs.get(h, 1.0) for h in train.hinges],
                      forces=[steer_force] * len(train.hinges))


def clamp_steer(train: Drivetrain, steer: float) -> tuple[float, str | None]:
    """The steer that keeps every hinge within its limits, and a warning if it changed."""
    if train.yaw_steered:
        return steer, None
    lo, hi = train.steer_range()
    clamped = min(max(steer, lo), hi)
    # Ackermann turns the inner hinge further than the bicycle angle: keep it in its limits.
    for _ in range(60):
        angles = train.hinge_angles(clamped)
        if all(train.hinge_limits[h][0] - 1e-9 <= a <= train.hinge_limits[h][1] + 1e-9
               for h, a in angles.items()):
            break
        clamped *= 0.98
    if clamped == steer:
        return steer, None
    return clamped, (f"steer {steer:g} rad is beyond what the hinges reach (limits "
                     f"[{lo:g}, {hi:g}]); clamped to {clamped:.4g}")
