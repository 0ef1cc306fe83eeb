"""Which joints of a loaded body are wheels and steering hinges, and how to drive them.

Detection works on the body PyBullet loaded (so it sees exactly the joint indices the motors
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
from typing import Any

from .errors import ParameterError
from .spec import quat_to_matrix, rotate

#: |axis . up| below this is "horizontal" (about 11 degrees of tilt allowed).
HORIZONTAL_TOLERANCE = 0.2
#: |axis . up| above this is "vertical".
VERTICAL_TOLERANCE = 0.98
#: A wheel is round: in every one of this many sectors around its axis, its shapes reach...
ROUND_SECTORS = 12
#: ...at least this fraction of its radius.
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

_REVOLUTE = 0  # p.JOINT_REVOLUTE
_PRISMATIC = 1  # p.JOINT_PRISMATIC
_SPHERE, _BOX, _CYLINDER, _MESH, _CAPSULE = 2, 3, 4, 5, 7  # p.GEOM_*

Vec = tuple[float, float, float]


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
            wheels): passive, and always free.
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
        """Mean distance from the rear axle to the hinge pivots (None without hinges)."""
        pivots = [self.pivot[h][0] for h in self.hinges if h in self.pivot]
        if not pivots:
            return None
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

    def to_dict(self) -> dict[str, Any]:
        """The JSON form: names keyed by joint index, and the geometry driving used."""
        def named(joints: list[int]) -> list[dict[str, Any]]:
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


def _is_continuous(info: tuple[Any, ...]) -> bool:
    lower, upper = info[8], info[9]
    return info[2] == _REVOLUTE and (lower > upper or upper - lower >= 2 * math.pi - 1e-6)


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
            from .suggest import hint

            known = ", ".join(names.values()) or "none"
            raise DrivetrainError(f"`{what}`: no joint named {key!r}"
                                  f"{hint(str(key), names.values())} (joints: {known})",
                                  param=what)
        if out[-1] not in movable:
            raise DrivetrainError(f"`{what}`: joint {names[out[-1]]!r} is fixed and cannot "
                                  "be driven", param=what)
    return out


def _shape_points(p: Any, body: int, link: int, client: int) -> list[Vec]:
    """Points outlining a link's collision shapes, in world coordinates.

    Meshes (and cylinders PyBullet turned into meshes) give their vertices; implicit
    cylinders, capsules, spheres and boxes are outlined from their dimensions.
    """
    if link < 0:  # the base: getBasePositionAndOrientation is its inertial (COM) frame
        pos_, orn_ = p.getBasePositionAndOrientation(body, physicsClientId=client)
        com_pos, com_rot = tuple(pos_), quat_to_matrix(orn_)
    else:
        st = p.getLinkState(body, link, computeForwardKinematics=True, physicsClientId=client)
        com_pos, com_rot = st[0], quat_to_matrix(st[1])
    out: list[Vec] = []
    for k, shape in enumerate(p.getCollisionShapeData(body, link, physicsClientId=client)):
        kind, dims, pos, orn = shape[2], shape[3], shape[5], shape[6]
        local: list[Vec] = []
        if kind == _MESH:
            try:
                count, verts = p.getMeshData(body, link, collisionShapeIndex=k,
                                             physicsClientId=client)
            except p.error:
                count, verts = 0, []
            if count:  # already in the link's inertial frame
                out += [_add(com_pos, rotate(com_rot, v)) for v in verts]
            continue
        if kind == _SPHERE:
            r = dims[0]
            local = [(r * x, r * y, r * z) for x, y, z in _SPHERE_DIRECTIONS]
        elif kind in (_CYLINDER, _CAPSULE):
            length, r = dims[0], dims[1]
            local = [(r * math.cos(a), r * math.sin(a), z)
                     for a in (2 * math.pi * i / 24 for i in range(24))
                     for z in (-length / 2, length / 2)]
            if kind == _CAPSULE:  # and its two half-spheres, beyond the cylinder's ends
                local += [(r * x, r * y, r * z + math.copysign(length / 2, z))
                          for x, y, z in _SPHERE_DIRECTIONS]
        elif kind == _BOX:
            hx, hy, hz = (d / 2 for d in dims)
            local = [(sx * hx, sy * hy, sz * hz) for sx in (-1, 1) for sy in (-1, 1)
                     for sz in (-1, 1)]
        shape_rot = quat_to_matrix(orn)
        for v in local:
            in_com = _add(pos, rotate(shape_rot, v))
            out.append(_add(com_pos, rotate(com_rot, in_com)))
    return out


def base_link_pose(p: Any, body: int, client: int) -> tuple[Any, Any]:
    """The base link frame's world pose (PyBullet reports the base's inertial frame).

    With ``URDF_USE_INERTIA_FROM_FILE`` an ``<inertia>`` with products (ixy, ixz, iyz), or an
    ``<inertial><origin>``, puts the inertial frame elsewhere than the link frame: its pose is
    not the robot's.
    """
    pos, orn = p.getBasePositionAndOrientation(body, physicsClientId=client)
    local = p.getDynamicsInfo(body, -1, physicsClientId=client)
    inv_pos, inv_orn = p.invertTransform(local[3], local[4])
    return p.multiplyTransforms(pos, orn, inv_pos, inv_orn)


def set_base_link_pose(p: Any, body: int, client: int, pos: Sequence[float],
                       orn: Sequence[float]) -> None:
    """Place the base link frame.

    ``resetBasePositionAndOrientation`` places the inertial frame; ``loadURDF`` the link frame.
    """
    local = p.getDynamicsInfo(body, -1, physicsClientId=client)
    com_pos, com_orn = p.multiplyTransforms(pos, orn, local[3], local[4])
    p.resetBasePositionAndOrientation(body, com_pos, com_orn, physicsClientId=client)


def lowest_point(p: Any, body: int, client: int,
                 points: dict[int, list[Vec]] | None = None) -> float:
    """The lowest z of the body's collision shapes, from the shapes themselves.

    Not from ``getAABB``: a link whose ``<inertia>`` has products gets a rotated inertial
    frame, and its AABB grows with it (1.8 cm below a small car's real corners), which would
    lift the start and disqualify the wheels as "above the robot's lowest point". A link
    without collision shapes does not count; a body with none falls back to the AABB.
    ``points`` (link index to :func:`_shape_points`) saves measuring them again.
    """
    n = p.getNumJoints(body, physicsClientId=client)
    if points is None:
        points = {link: _shape_points(p, body, link, client) for link in range(-1, n)}
    zs = [pt[2] for pts in points.values() for pt in pts]
    finite = [z for z in zs if math.isfinite(z)]
    if finite:
        return min(finite)
    return min(p.getAABB(body, link, physicsClientId=client)[0][2] for link in range(-1, n))


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


def _add(a: Sequence[float], b: Sequence[float]) -> Vec:
    return (a[0] + b[0], a[1] + b[1], a[2] + b[2])


def _sub(a: Sequence[float], b: Sequence[float]) -> Vec:
    return (a[0] - b[0], a[1] - b[1], a[2] - b[2])


def _dot(a: Sequence[float], b: Sequence[float]) -> float:
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]


def _unit(a: Sequence[float]) -> Vec:
    n = math.sqrt(_dot(a, a)) or 1.0
    return (a[0] / n, a[1] / n, a[2] / n)


def _roundness(points: list[Vec], origin: Vec, axis: Vec) -> tuple[float, float, Vec] | None:
    """``(radius, worst sector fraction, centre on the axis)`` of points about an axis.

    None for no points, or for points that are not all finite (a shape sized 1e309 is
    infinite): nothing round can be measured from them.
    """
    if not points or not all(math.isfinite(c) for pt in points for c in pt) or \
            not all(math.isfinite(c) for c in (*origin, *axis)):
        return None
    # Two directions perpendicular to the axis.
    helper = (1.0, 0.0, 0.0) if abs(axis[0]) < 0.9 else (0.0, 1.0, 0.0)
    u = _unit(_sub(helper, tuple(axis[i] * _dot(helper, axis) for i in range(3))))
    v = (axis[1] * u[2] - axis[2] * u[1], axis[2] * u[0] - axis[0] * u[2],
         axis[0] * u[1] - axis[1] * u[0])
    reach = [0.0] * ROUND_SECTORS
    along = 0.0
    for pt in points:
        d = _sub(pt, origin)
        along += _dot(d, axis)
        a, b = _dot(d, u), _dot(d, v)
        sector = int((math.atan2(b, a) + math.pi) / (2 * math.pi) * ROUND_SECTORS) \
            % ROUND_SECTORS
        reach[sector] = max(reach[sector], math.hypot(a, b))
    radius = max(reach)
    if radius <= 0:
        return None
    mean = along / len(points)
    return radius, min(reach) / radius, _add(origin, tuple(axis[i] * mean for i in range(3)))


def detect_drivetrain(p: Any, body: int, client: int,
                      wheels: Sequence[str | int] | None = None,
                      hinges: Sequence[str | int] | None = None,
                      mode: str = "differential") -> Drivetrain:
    """Find the wheels, steering hinges and passive joints of a body standing upright.

    Call it before the first ``stepSimulation``, with every joint at zero and the base in its
    upright orientation (the caller turns it to the spawn pose afterwards): "horizontal",
    "vertical" and "touches the ground" are judged in the base frame.

    Args:
        p: The pybullet module.
        body: The body id.
        client: The physics client id.
        wheels: Joint names or indices to drive instead of the detected wheels.
        hinges: Joint names or indices to steer instead of the detected hinges.
        mode: The drivetrain (see :data:`DRIVETRAINS`).

    Raises:
        DrivetrainError: no wheels were found (or given), or a name/index is unknown.
    """
    if mode not in DRIVETRAINS:
        raise DrivetrainError(f"`drivetrain` must be one of {', '.join(DRIVETRAINS)}, got "
                              f"{mode!r}", param="drivetrain")
    n = p.getNumJoints(body, physicsClientId=client)
    infos = [p.getJointInfo(body, j, physicsClientId=client) for j in range(n)]
    names = {j: info[1].decode("utf-8", "replace") for j, info in enumerate(infos)}
    movable = [j for j, info in enumerate(infos) if info[2] in (_REVOLUTE, _PRISMATIC)]
    states = {j: p.getLinkState(body, j, computeForwardKinematics=True, physicsClientId=client)
              for j in movable}
    origin = {j: tuple(states[j][4]) for j in movable}
    # getJointInfo's axis is in the child's inertial frame (measured: with inertia products
    # and URDF_USE_INERTIA_FROM_FILE a PR2 caster's vertical axis read 32 degrees off in the
    # link frame), so it turns with the link's centre-of-mass orientation, not its URDF frame.
    axes = {j: _unit(rotate(quat_to_matrix(states[j][1]), infos[j][13])) for j in movable}
    base_pos, base_orn = p.getBasePositionAndOrientation(body, physicsClientId=client)
    dyn = p.getDynamicsInfo(body, -1, physicsClientId=client)
    inv_pos, inv_orn = p.invertTransform(dyn[3], dyn[4])
    base_link, base_link_orn = p.multiplyTransforms(base_pos, base_orn, inv_pos, inv_orn)
    base_rot = quat_to_matrix(base_link_orn)
    base_x, base_y = rotate(base_rot, (1.0, 0.0, 0.0)), rotate(base_rot, (0.0, 1.0, 0.0))
    link_points = {link: _shape_points(p, body, link, client) for link in range(-1, n)}
    lowest = lowest_point(p, body, client, link_points)

    shapes: dict[int, tuple[float, float, Vec] | None] = {}

    def round_about(j: int) -> tuple[float, float, Vec] | None:
        if j not in shapes:
            shapes[j] = _roundness(link_points[j], origin[j], axes[j])
        return shapes[j]

    rejected: list[str] = []
    if wheels is not None:
        wheel_list = _pick(wheels, names, movable, "wheels")
    else:
        wheel_list = []
        for j in movable:
            if not _is_continuous(infos[j]):
                continue
            if abs(axes[j][2]) >= HORIZONTAL_TOLERANCE:
                rejected.append(f"{names[j]} (its axis is not horizontal)")
                continue
            shape = round_about(j)
            if shape is None:
                rejected.append(f"{names[j]} (its link has no collision shape to roll on)")
                continue
            size, fraction, centre = shape
            if fraction < ROUND_FRACTION:
                rejected.append(f"{names[j]} (its link is not round about the joint axis)")
                continue
            bottom = centre[2] - size * math.sqrt(max(0.0, 1 - axes[j][2] ** 2))
            if bottom - lowest > max(GROUND_FRACTION * size, 0.005):
                rejected.append(f"{names[j]} ({bottom - lowest:.2f} m above the robot's "
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
    wheel_set = set(wheel_list)

    def hinge_of(w: int, candidates: Sequence[int]) -> int | None:
        k = infos[w][16]
        while k >= 0:
            if k in candidates:
                return k
            k = infos[k][16]
        return None

    casters: list[int] = []
    if hinges is not None:
        hinge_list = _pick(hinges, names, movable, "hinges")
    else:
        verticals = [j for j in movable if j not in wheel_set and infos[j][2] == _REVOLUTE
                     and abs(axes[j][2]) > VERTICAL_TOLERANCE]
        carrying = [j for j in verticals if any(hinge_of(w, [j]) == j for w in wheel_list)]
        # A vertical joint that turns all the way round is a caster's swivel, not steering:
        # it and the wheels it carries roll free (unless the user named those wheels).
        swivels = [j for j in carrying if _is_continuous(infos[j])]
        hinge_list = [j for j in carrying if j not in swivels]
        if swivels:
            trailing = [w for w in wheel_list if hinge_of(w, swivels) is not None]
            casters = swivels + ([] if wheels is not None else trailing)
            if wheels is None:
                wheel_list = [w for w in wheel_list if w not in trailing]
                wheel_set = set(wheel_list)
                if not wheel_list:
                    raise DrivetrainError(
                        "no wheels found: every wheel hangs from a swivel that turns all the "
                        f"way round (casters: {', '.join(names[j] for j in casters)}); name "
                        "the wheels to drive with `wheels` and the joints that steer them with "
                        "`hinges`", param="wheels")
    overlap = wheel_set & set(hinge_list)
    if overlap:
        raise DrivetrainError(f"joint {names[min(overlap)]!r} cannot be both a wheel and a hinge",
                              param="hinges")

    forward = _forward([axes[w] for w in wheel_list], base_x, base_y)
    left = (-forward[1], forward[0], 0.0)

    def planar(pt: Sequence[float]) -> tuple[float, float]:
        d = _sub(pt, base_link)
        return (_dot(d, forward), _dot(d, left))

    radius: dict[int, float] = {}
    contact: dict[int, tuple[float, float]] = {}
    wheel_signs: dict[int, float] = {}
    for j in wheel_list:
        shape = round_about(j)
        if shape is not None:
            radius[j] = shape[0]
            contact[j] = planar(shape[2])
        else:  # a named wheel without collision shapes: its height above the ground
            radius[j] = max(origin[j][2] - lowest, 1e-3)
            contact[j] = planar(origin[j])
        a = axes[j]
        # A wheel spinning positively about axis a moves the car along a x up.
        along = a[1] * forward[0] - a[0] * forward[1]
        wheel_signs[j] = -1.0 if along < 0 else 1.0
    hinge_signs: dict[int, float] = {}
    hinge_limits: dict[int, tuple[float, float]] = {}
    pivot: dict[int, tuple[float, float]] = {}
    for j in hinge_list:
        sign = -1.0 if axes[j][2] < 0 else 1.0
        hinge_signs[j] = sign
        pivot[j] = planar(origin[j])
        lower, upper = infos[j][8], infos[j][9]
        if lower > upper:
            hinge_limits[j] = (-math.inf, math.inf)
        else:
            ends = sorted((lower * sign, upper * sign))
            hinge_limits[j] = (ends[0], ends[1])
    carried_by = {w: hinge_of(w, hinge_list) for w in wheel_list}
    driven = wheel_set | set(hinge_list)
    passive = [j for j in movable if j not in driven]
    in_base = (_dot(forward, base_x), _dot(forward, base_y))
    # Links resting on the ground beside the wheels: a fixed caster ball or skid. The links
    # the wheels and casters turn with are not among them, nor is the base itself.
    rolling = {j for j in wheel_list + casters}
    for j in range(n):
        if hinge_of(j, sorted(rolling)) is not None:
            rolling.add(j)
    caster_links = [k for k in range(n) if k not in rolling and link_points[k]
                    and min(pt[2] for pt in link_points[k]) - lowest <= 0.005]
    link_names = {k: infos[k][12].decode("utf-8", "replace") for k in range(n)}
    link_names[-1] = p.getBodyInfo(body, physicsClientId=client)[0].decode("utf-8", "replace")
    efforts = {j: float(infos[j][10]) for j in movable}
    return Drivetrain(wheel_list, hinge_list, passive, names, hinge_limits, wheel_signs,
                      hinge_signs, mode, radius, contact, carried_by, pivot, in_base,
                      [j for j in movable if j in set(casters)], caster_links, link_names,
                      efforts)


def _forward(wheel_axes: list[Vec], base_x: Vec, base_y: Vec) -> Vec:
    """The horizontal direction the wheels roll in that is closest to the base's +x.

    Wheels that roll along the base's y (r2d2's do) drive along +y: forward can only be a
    direction the wheels roll in.
    """
    flat_x = _unit((base_x[0], base_x[1], 0.0))
    ref = wheel_axes[0]
    total = [0.0, 0.0]
    for a in wheel_axes:
        s = 1.0 if a[0] * ref[0] + a[1] * ref[1] >= 0 else -1.0
        total[0] += s * a[0]
        total[1] += s * a[1]
    if math.hypot(*total) < 1e-9:
        return flat_x
    roll = _unit((-total[1], total[0], 0.0))  # up x axis: perpendicular in the ground plane
    along_x = _dot(roll, flat_x)
    if abs(along_x) >= 0.1:
        return roll if along_x > 0 else (-roll[0], -roll[1], 0.0)
    flat_y = (base_y[0], base_y[1], 0.0)
    return roll if _dot(roll, flat_y) > 0 else (-roll[0], -roll[1], 0.0)


def detect_upright(p: Any, body: int, client: int, upright: Sequence[float],
                   wheels: Sequence[str | int] | None = None,
                   hinges: Sequence[str | int] | None = None,
                   mode: str = "differential") -> Drivetrain:
    """:func:`detect_drivetrain` with the base link turned to ``upright`` (a quaternion).

    A body spawned tilted (or upside down) is stood up where it is for detection, so its
    wheels are judged in its own frame, then put back exactly as it was.
    """
    pos, orn = base_link_pose(p, body, client)  # the link frame is the one to stand up
    turned = any(abs(a - b) > 1e-12 for a, b in zip(orn, upright, strict=True))
    if turned:
        set_base_link_pose(p, body, client, pos, list(upright))
    try:
        return detect_drivetrain(p, body, client, wheels, hinges, mode)
    finally:
        if turned:
            set_base_link_pose(p, body, client, pos, orn)


def disable_default_motors(p: Any, body: int, client: int, joints: Sequence[int]) -> None:
    """Switch off PyBullet's default velocity motors on ``joints``.

    PyBullet gives every revolute and prismatic joint a velocity motor with target 0 at load
    time; left on, it brakes the joint. Force 0 frees it (and makes the first step of large
    bodies fast).
    """
    if not joints:
        return
    p.setJointMotorControlArray(body, list(joints), p.VELOCITY_CONTROL,
                                targetVelocities=[0.0] * len(joints),
                                forces=[0.0] * len(joints), physicsClientId=client)


def apply_drive(p: Any, body: int, client: int, train: Drivetrain, throttle: float,
                steer: float, max_force: float | None, steer_force: float = STEER_FORCE
                ) -> None:
    """Set the wheel and hinge motors once; PyBullet keeps them until they are changed.

    Args:
        p: The pybullet module.
        body: The body id.
        client: The physics client id.
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
        p.setJointMotorControlArray(
            body, driven, p.VELOCITY_CONTROL,
            targetVelocities=[speeds[w] * train.wheel_signs.get(w, 1.0) for w in driven],
            forces=[force] * len(driven), physicsClientId=client)
    disable_default_motors(p, body, client, train.free)
    if train.hinges:
        angles = train.hinge_angles(steer) if train.mode != "locked" else \
            dict.fromkeys(train.hinges, steer)
        p.setJointMotorControlArray(
            body, train.hinges, p.POSITION_CONTROL,
            targetPositions=[angles[h] * train.hinge_signs.get(h, 1.0) for h in train.hinges],
            forces=[steer_force] * len(train.hinges), physicsClientId=client)


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
