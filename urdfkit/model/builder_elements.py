"""The model's elements: one class per URDF tag, each value checked where it is set.

:mod:`urdfkit.builder` is the public face (it re-exports every class here);
:mod:`urdfkit.model.robot` holds :class:`~urdfkit.builder.Robot` with the XML reading and
writing; this module holds what a robot is made of: :class:`Link`, :class:`Joint`,
:class:`Inertial`, the shapes, and the checks on their values.
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Callable, Iterable
from dataclasses import dataclass, field
from typing import Any, ClassVar

from lxml import etree

from urdfkit.core.errors import ModelError
from urdfkit.model.massprops import combine
from urdfkit.model.spec import (
    JOINT_TYPES,
    LIMITED_JOINT_TYPES,
    SHAPES,
    Matrix3,
    Vec3,
    finite,
    matmul,
    rpy_to_matrix,
    solid_inertia,
    solid_volume,
    sym_eigenvalues,
    transpose,
)
from urdfkit.model.xmlio import fmt_float, fmt_vec

_REL_TOL = 1e-9


_ABS_TOL = 1e-12


def _fail(msg: str) -> ModelError:
    return ModelError(msg)


def _finite(value: Any) -> float:
    try:
        return finite(value)
    except ValueError as e:
        raise _fail(str(e)) from None


def _optional(check: Callable[[Any], Any]) -> Callable[[Any], Any]:
    return lambda v: None if v is None else check(v)


def _positive(value: Any) -> float:
    x = _finite(value)
    if x <= 0:
        raise _fail(f"must be > 0, got {fmt_float(x)}")
    return x


def _non_negative(value: Any) -> float:
    x = _finite(value)
    if x < 0:
        raise _fail(f"must be >= 0, got {fmt_float(x)}")
    return x


def _vector(n: int, elem: Callable[[Any], float] = _finite) -> Callable[[Any], tuple[float, ...]]:
    def check(value: Any) -> tuple[float, ...]:
        if isinstance(value, str):
            value = value.split()
        try:
            items = list(value)
        except TypeError:
            raise _fail(f"expected {n} numbers, got {value!r}") from None
        if len(items) != n:
            raise _fail(f"expected {n} numbers, got {len(items)}")
        return tuple(elem(v) for v in items)

    return check


def _rgba(value: Any) -> tuple[float, ...]:
    rgba = _vector(4)(value)
    if any(c < 0 or c > 1 for c in rgba):
        raise _fail(f"colour components must lie in 0..1, got {fmt_vec(rgba)}")
    return rgba


def _name(value: Any) -> str:
    if not isinstance(value, str) or not value:
        raise _fail(f"expected a non-empty name, got {value!r}")
    return value


def _optional_name(value: Any) -> str | None:
    return None if value is None else _name(value)


def _joint_type(value: Any) -> str:
    if value not in JOINT_TYPES:
        raise _fail(f"unknown joint type {value!r}; expected one of {', '.join(JOINT_TYPES)}")
    return str(value)


def _checked(default: Any = dataclasses.MISSING, check: Callable[[Any], Any] | None = None,
             **kw: Any) -> Any:
    md = {"check": check} if check else {}
    if default is dataclasses.MISSING:
        return field(metadata=md, **kw)
    return field(default=default, metadata=md, **kw)


def _close(a: Any, b: Any) -> bool:
    if isinstance(a, float) or isinstance(b, float):
        if not isinstance(a, int | float) or not isinstance(b, int | float):
            return False
        return math.isclose(a, b, rel_tol=_REL_TOL, abs_tol=_ABS_TOL)
    if isinstance(a, tuple | list) and isinstance(b, tuple | list):
        return len(a) == len(b) and all(_close(x, y) for x, y in zip(a, b, strict=True))
    if isinstance(a, etree._Element) and isinstance(b, etree._Element):
        return bool(etree.tostring(a) == etree.tostring(b))
    return bool(a == b)


class _Element:
    """Base of the model classes: checks on assignment, float-tolerant equality."""

    _tag: ClassVar[str] = ""

    def __setattr__(self, name: str, value: Any) -> None:
        f = self.__dataclass_fields__.get(name)  # type: ignore[attr-defined]
        check = f.metadata.get("check") if f is not None else None
        if check is not None:
            try:
                value = check(value)
            except ModelError as e:
                raise ModelError(
                    f"during assignment to attribute '{name}' of element <{self._tag}>: "
                    f"{e.message}"
                ) from None
        object.__setattr__(self, name, value)

    def __eq__(self, other: object) -> bool:
        if type(self) is not type(other):
            return NotImplemented
        return all(
            _close(getattr(self, f.name), getattr(other, f.name))
            for f in dataclasses.fields(self)  # type: ignore[arg-type]
        )

    __hash__ = None  # type: ignore[assignment]


def as_written(value: Any) -> Any:
    """A value the checks refuse, kept for comparison: numbers where it has them, else text.

    A number stays a float (a sphere's radius 0, a lower limit above the upper); a vector of
    numbers, of whatever length, a tuple of floats (``scale="1 1 1 1"``); anything else, a
    non-finite number included, its text with whitespace normalised (``"0.07, 0, -0.69"``,
    ``"inf"``), so that two spellings of one broken value still compare equal.
    """
    if value is None or isinstance(value, bool):
        return value
    if isinstance(value, int | float):
        x = float(value)
        return x if math.isfinite(x) else str(x)
    if isinstance(value, tuple | list):
        items = [as_written(v) for v in value]
        return tuple(items) if all(isinstance(v, float) for v in items) else \
            " ".join(str(v) for v in items)
    if not isinstance(value, str):
        return value
    tokens = value.split()
    if not tokens:
        return ""
    numbers = []
    for token in tokens:
        try:
            numbers.append(float(token))
        except ValueError:
            return " ".join(tokens)
    if not all(math.isfinite(x) for x in numbers):
        return " ".join(str(x) if not math.isfinite(x) else token
                        for x, token in zip(numbers, tokens, strict=True))
    return numbers[0] if len(numbers) == 1 else tuple(numbers)


@dataclass(eq=False)
class Origin(_Element):
    """A pose: ``xyz`` in metres and ``rpy`` (fixed-axis roll, pitch, yaw) in radians."""

    _tag = "origin"
    xyz: Vec3 = _checked((0.0, 0.0, 0.0), _vector(3))
    rpy: Vec3 = _checked((0.0, 0.0, 0.0), _vector(3))

    @property
    def is_identity(self) -> bool:
        """Whether this origin is the identity (and can be left out of the XML)."""
        return all(v == 0 for v in self.xyz + self.rpy)

    @property
    def rotation(self) -> Matrix3:
        """The rotation matrix of ``rpy``."""
        return rpy_to_matrix(self.rpy)


@dataclass(eq=False)
class Inertia(_Element):
    """The six independent entries of a symmetric inertia tensor, in kg m^2."""

    _tag = "inertia"
    ixx: float = _checked(0.0, _finite)
    ixy: float = _checked(0.0, _finite)
    ixz: float = _checked(0.0, _finite)
    iyy: float = _checked(0.0, _finite)
    iyz: float = _checked(0.0, _finite)
    izz: float = _checked(0.0, _finite)

    @property
    def matrix(self) -> Matrix3:
        """The full 3x3 tensor."""
        return (
            (self.ixx, self.ixy, self.ixz),
            (self.ixy, self.iyy, self.iyz),
            (self.ixz, self.iyz, self.izz),
        )

    @classmethod
    def from_matrix(cls, m: Matrix3) -> Inertia:
        """Build from a 3x3 tensor, symmetrising it and rounding away float noise."""

        def clean(x: float) -> float:
            return 0.0 if abs(x) < 1e-15 else x

        return cls(
            ixx=clean(m[0][0]), ixy=clean((m[0][1] + m[1][0]) / 2),
            ixz=clean((m[0][2] + m[2][0]) / 2),
            iyy=clean(m[1][1]), iyz=clean((m[1][2] + m[2][1]) / 2), izz=clean(m[2][2]),
        )

    def rotated(self, rotation: Matrix3) -> Inertia:
        """The tensor expressed in a frame rotated by ``rotation``: ``R I R^T``."""
        return Inertia.from_matrix(matmul(matmul(rotation, self.matrix), transpose(rotation)))

    @property
    def principal_moments(self) -> tuple[float, float, float]:
        """Eigenvalues of the tensor, ascending (closed form for symmetric 3x3)."""
        return sym_eigenvalues(self.matrix)


class _Solid(_Element):
    """A shape with a closed-form volume and solid inertia (spec.solid_*), by its tag."""

    def _dims(self) -> tuple[float, ...]:
        raise NotImplementedError

    @property
    def volume(self) -> float:
        """Volume in m^3."""
        return solid_volume(self._tag, self._dims())

    def inertia(self, mass: float) -> Inertia:
        """Solid inertia about the centre, in the shape's own frame (axis z)."""
        ixx, iyy, izz = solid_inertia(self._tag, self._dims(), mass)
        return Inertia(ixx=ixx, iyy=iyy, izz=izz)


@dataclass(eq=False)
class Box(_Solid):
    """A box centred on its origin; ``size`` is the full extent along x, y, z."""

    _tag = "box"
    size: Vec3 = _checked(check=_vector(3, _positive))

    def _dims(self) -> tuple[float, ...]:
        return tuple(self.size)


@dataclass(eq=False)
class Cylinder(_Solid):
    """A cylinder centred on its origin, its axis along the local z axis."""

    _tag = "cylinder"
    radius: float = _checked(check=_positive)
    length: float = _checked(check=_positive)

    def _dims(self) -> tuple[float, ...]:
        return (self.radius, self.length)


@dataclass(eq=False)
class Sphere(_Solid):
    """A sphere centred on its origin."""

    _tag = "sphere"
    radius: float = _checked(check=_positive)

    def _dims(self) -> tuple[float, ...]:
        return (self.radius,)


@dataclass(eq=False)
class Capsule(_Solid):
    """A capsule (PyBullet extension): a cylinder of ``length`` capped by two hemispheres.

    Its axis is the local z axis and ``length`` excludes the caps, as in PyBullet.
    """

    _tag = "capsule"
    radius: float = _checked(check=_positive)
    length: float = _checked(check=_positive)

    def _dims(self) -> tuple[float, ...]:
        return (self.radius, self.length)


@dataclass(eq=False)
class Plane(_Element):
    """An infinite plane (PyBullet extension) through the origin, with normal ``normal``."""

    _tag = "plane"
    normal: Vec3 = _checked((0.0, 0.0, 1.0), _vector(3))

    @property
    def volume(self) -> float:
        """A plane has no finite volume; raises :class:`ModelError`."""
        raise ModelError(_PLANE_INERTIA)

    def inertia(self, mass: float) -> Inertia:
        """Not defined for an infinite plane; raises :class:`ModelError`."""
        raise ModelError(_PLANE_INERTIA)


_PLANE_INERTIA = ("cannot derive inertia from an infinite <plane>; give <inertia> explicitly "
                  "(or mass 0 for static ground)")


@dataclass(eq=False)
class Mesh(_Element):
    """A mesh file (STL, OBJ, DAE), optionally scaled per axis."""

    _tag = "mesh"
    filename: str = _checked(check=_name)
    scale: Vec3 | None = _checked(None, _optional(_vector(3)))

    @property
    def volume(self) -> float:
        """Meshes have no volume urdfkit can know without loading them."""
        raise ModelError(f"cannot derive inertia from mesh {self.filename!r}; give <inertia> "
                         "explicitly")

    def inertia(self, mass: float) -> Inertia:
        """Not derivable without the mesh; raises :class:`ModelError`."""
        raise ModelError(f"cannot derive inertia from mesh {self.filename!r}; give <inertia> "
                         "explicitly")


@dataclass(eq=False)
class Cdf(Mesh):
    """A signed-distance-field file (PyBullet extension), read like a mesh."""

    _tag = "cdf"


Geometry = Box | Cylinder | Sphere | Capsule | Plane | Mesh


#: The model class of each shape tag in :data:`urdfkit.model.spec.SHAPES`.
SHAPE_CLASSES: dict[str, type[_Element]] = {
    "box": Box, "cylinder": Cylinder, "sphere": Sphere, "mesh": Mesh, "capsule": Capsule,
    "plane": Plane, "cdf": Cdf,
}
assert set(SHAPE_CLASSES) == set(SHAPES), "builder shapes out of step with urdfkit.model.spec"


def _geometry(value: Any) -> Geometry:
    if not isinstance(value, tuple(SHAPE_CLASSES.values())):
        raise _fail(f"expected one of {', '.join(c.__name__ for c in SHAPE_CLASSES.values())}, "
                    f"got {type(value).__name__}")
    return value  # type: ignore[return-value]


def _origin(value: Any) -> Origin:
    if value is None:
        return Origin()
    if not isinstance(value, Origin):
        raise _fail(f"expected Origin, got {type(value).__name__}")
    return value


@dataclass(eq=False)
class Inertial(_Element):
    """Mass, centre of mass and inertia of a link.

    Leave ``inertia`` as None to have it derived from the link's collision shapes (solid, of
    uniform density) when the robot is written or :meth:`Robot.complete_inertia` runs; a
    written file always has a tensor.
    """

    _tag = "inertial"
    mass: float = _checked(check=_non_negative)
    inertia: Inertia | None = None
    origin: Origin = _checked(None, _origin)

    @classmethod
    def from_shapes(cls, mass: float, shapes: Iterable[tuple[Geometry, Origin]]) -> Inertial:
        """The inertial of a solid made of ``shapes`` with total ``mass``, uniform density.

        Mass is shared by volume, the centre of mass is the volume-weighted centre, and the
        tensor is each shape's rotated tensor moved to that centre by the parallel-axis theorem.
        """
        shapes = list(shapes)
        if not shapes:
            raise ModelError("cannot derive inertia: the link has no shapes")
        # the solid at unit density (volumes as masses), then scaled to ``mass``
        solid = combine([(geom.volume, origin.xyz, matmul(matmul(
            origin.rotation, geom.inertia(geom.volume).matrix), transpose(origin.rotation)))
            for geom, origin in shapes])
        scale = mass / solid.mass
        (a, b, c), (d, e, f), (g, h, i) = solid.tensor
        tensor = ((a * scale, b * scale, c * scale), (d * scale, e * scale, f * scale),
                  (g * scale, h * scale, i * scale))
        return cls(mass=mass, inertia=Inertia.from_matrix(tensor),
                   origin=Origin(xyz=solid.com))


@dataclass(eq=False)
class Material(_Element):
    """A named material; with neither colour nor texture it is a reference by name."""

    _tag = "material"
    name: str = _checked(check=_name)
    color: tuple[float, float, float, float] | None = _checked(None, _optional(_rgba))
    texture: str | None = None

    @property
    def is_reference(self) -> bool:
        """Whether this only names a material defined elsewhere."""
        return self.color is None and self.texture is None


def _material(value: Any) -> Material | None:
    if value is None or isinstance(value, Material):
        return value
    if isinstance(value, str):
        return Material(name=value)
    raise _fail(f"expected Material or a material name, got {type(value).__name__}")


@dataclass(eq=False)
class Visual(_Element):
    """What a link looks like."""

    _tag = "visual"
    geometry: Geometry = _checked(check=_geometry)
    origin: Origin = _checked(None, _origin)
    material: Material | None = _checked(None, _material)
    name: str | None = _checked(None, _optional_name)


@dataclass(eq=False)
class Collision(_Element):
    """The shape a link collides with (and, by default in PyBullet, its inertia comes from)."""

    _tag = "collision"
    geometry: Geometry = _checked(check=_geometry)
    origin: Origin = _checked(None, _origin)
    name: str | None = _checked(None, _optional_name)


@dataclass(eq=False)
class Contact(_Element):
    """PyBullet's ``<contact>`` extension: per-link friction and contact coefficients.

    ``stiffness`` and ``damping`` only take effect together, as in PyBullet.
    """

    _tag = "contact"
    lateral_friction: float | None = _checked(None, _optional(_non_negative))
    rolling_friction: float | None = _checked(None, _optional(_non_negative))
    spinning_friction: float | None = _checked(None, _optional(_non_negative))
    restitution: float | None = _checked(None, _optional(_non_negative))
    stiffness: float | None = _checked(None, _optional(_non_negative))
    damping: float | None = _checked(None, _optional(_non_negative))
    contact_cfm: float | None = _checked(None, _optional(_non_negative))
    contact_erp: float | None = _checked(None, _optional(_non_negative))
    inertia_scaling: float | None = _checked(None, _optional(_non_negative))
    friction_anchor: bool = False

    #: Value-carrying children, in the order they are written.
    VALUE_TAGS: ClassVar[tuple[str, ...]] = (
        "lateral_friction", "rolling_friction", "spinning_friction", "restitution",
        "stiffness", "damping", "contact_cfm", "contact_erp", "inertia_scaling",
    )


def _inertial(value: Any) -> Inertial | None:
    if value is not None and not isinstance(value, Inertial):
        raise _fail(f"expected Inertial, got {type(value).__name__}")
    return value


def _contact(value: Any) -> Contact | None:
    if value is not None and not isinstance(value, Contact):
        raise _fail(f"expected Contact, got {type(value).__name__}")
    return value


@dataclass(eq=False)
class Link(_Element):
    """A rigid body: inertial, visuals, collisions and PyBullet contact coefficients."""

    _tag = "link"
    name: str = _checked(check=_name)
    inertial: Inertial | None = _checked(None, _inertial)
    visuals: list[Visual] = field(default_factory=list)
    collisions: list[Collision] = field(default_factory=list)
    contact: Contact | None = _checked(None, _contact)

    def resolved_inertial(self) -> Inertial | None:
        """The inertial with its tensor filled in from the shapes when none was given.

        Collision shapes are used (they are what PyBullet derives inertia from); a link with
        none falls back to its visuals.
        """
        if self.inertial is None or self.inertial.inertia is not None:
            return self.inertial
        shapes = [(c.geometry, c.origin) for c in self.collisions] or \
                 [(v.geometry, v.origin) for v in self.visuals]
        if not shapes:
            raise ModelError(f"<link name={self.name!r}> has a mass but no shapes to derive "
                             "its inertia from; give <inertia> explicitly")
        try:
            return Inertial.from_shapes(self.inertial.mass, shapes)
        except ModelError as e:
            raise ModelError(f"<link name={self.name!r}>: {e.message}") from None


@dataclass(eq=False)
class Limit(_Element):
    """Joint limits: position (rad or m), effort (N m or N), velocity (rad/s or m/s)."""

    _tag = "limit"
    effort: float = _checked(check=_non_negative)
    velocity: float = _checked(check=_non_negative)
    lower: float | None = _checked(None, _optional(_finite))
    upper: float | None = _checked(None, _optional(_finite))

    def __post_init__(self) -> None:
        if self.lower is not None and self.upper is not None and self.lower > self.upper:
            raise ModelError(f"<limit> lower {fmt_float(self.lower)} is above upper "
                             f"{fmt_float(self.upper)}")


@dataclass(eq=False)
class Dynamics(_Element):
    """Joint damping and static friction."""

    _tag = "dynamics"
    damping: float | None = _checked(None, _optional(_non_negative))
    friction: float | None = _checked(None, _optional(_non_negative))


@dataclass(eq=False)
class Mimic(_Element):
    """This joint follows ``joint``: ``q = multiplier * q_joint + offset``."""

    _tag = "mimic"
    joint: str = _checked(check=_name)
    multiplier: float | None = _checked(None, _optional(_finite))
    offset: float | None = _checked(None, _optional(_finite))


@dataclass(eq=False)
class SafetyController(_Element):
    """Soft limits for a real robot's controller."""

    _tag = "safety_controller"
    k_velocity: float = _checked(check=_finite)
    soft_lower_limit: float | None = _checked(None, _optional(_finite))
    soft_upper_limit: float | None = _checked(None, _optional(_finite))
    k_position: float | None = _checked(None, _optional(_finite))


@dataclass(eq=False)
class Calibration(_Element):
    """Reference positions of the joint's calibration edges."""

    _tag = "calibration"
    rising: float | None = _checked(None, _optional(_finite))
    falling: float | None = _checked(None, _optional(_finite))


def _axis(value: Any) -> Vec3 | None:
    if value is None:
        return None
    axis = _vector(3)(value)
    if all(a == 0 for a in axis):
        raise _fail("axis must not be zero")
    return axis  # type: ignore[return-value]


@dataclass(eq=False)
class Joint(_Element):
    """A joint from ``parent`` to ``child``; the child's frame is ``origin`` in the parent's."""

    _tag = "joint"
    name: str = _checked(check=_name)
    type: str = _checked(check=_joint_type)
    parent: str = _checked(check=_name)
    child: str = _checked(check=_name)
    origin: Origin = _checked(None, _origin)
    axis: Vec3 | None = _checked(None, _axis)
    limit: Limit | None = None
    dynamics: Dynamics | None = None
    mimic: Mimic | None = None
    safety_controller: SafetyController | None = None
    calibration: Calibration | None = None

    def __post_init__(self) -> None:
        if self.type in LIMITED_JOINT_TYPES and self.limit is None:
            raise ModelError(f"<joint name={self.name!r}> of type {self.type} needs "
                             "<limit effort=... velocity=...>")
        if self.parent == self.child:
            raise ModelError(f"<joint name={self.name!r}> joins link {self.parent!r} to itself")

    @property
    def movable(self) -> bool:
        """Whether the joint has a degree of freedom."""
        return self.type != "fixed"
