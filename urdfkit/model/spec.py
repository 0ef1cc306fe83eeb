"""The one URDF spec: what URDF allows, what PyBullet adds, and what PyBullet cannot do.

Every other module reads its lists from here: the builder (what it accepts), the rules and the
guard (what they refuse), inspect and tree (how they name and count joints), render, vehicle
detection and sim. Four copies of these lists once disagreed, and ``build`` refused what
``check`` accepted; there is now one.

It also holds the small pieces of geometry every step needs, once: number parsing from XML
attributes, roll-pitch-yaw and quaternion rotations, and PyBullet's depth-first joint order.

Nothing here imports lxml or PyBullet: elements are read through their ``get`` method.
"""

from __future__ import annotations

import math
import os
import re
from collections.abc import Callable, Hashable, Mapping, Sequence
from typing import Any, Literal, Protocol, TypeVar

# --------------------------------------------------------------------------- joints

#: Joint types of the URDF specification.
URDF_JOINT_TYPES = ("revolute", "continuous", "prismatic", "fixed", "floating", "planar")
#: Joint types PyBullet adds to URDF (other URDF tools refuse them).
PYBULLET_JOINT_TYPES = ("spherical",)
#: Every joint type urdfkit accepts: the URDF ones plus PyBullet's.
JOINT_TYPES = URDF_JOINT_TYPES + PYBULLET_JOINT_TYPES
#: Joint types that need ``<limit>`` with effort and velocity (and whose lower/upper count).
LIMITED_JOINT_TYPES = ("revolute", "prismatic")
#: Joint types whose ``<axis>`` means something (default (1, 0, 0) when absent).
AXIS_JOINT_TYPES = ("revolute", "continuous", "prismatic", "planar")

#: ``getJointInfo``'s jointType codes (``p.JOINT_REVOLUTE == 0``, ...), as PyBullet names them.
PYBULLET_JOINT_CODES = {0: "REVOLUTE", 1: "PRISMATIC", 2: "SPHERICAL", 3: "PLANAR", 4: "FIXED",
                        5: "POINT2POINT", 6: "GEAR"}
#: Velocity degrees of freedom of each PyBullet joint type (a planar joint is x, y and yaw).
JOINT_DOF = {"REVOLUTE": 1, "PRISMATIC": 1, "SPHERICAL": 3, "PLANAR": 3, "FIXED": 0,
             "POINT2POINT": 0, "GEAR": 0}
#: Degrees of freedom of each URDF joint type, as the URDF means it (``diff`` counts these).
#: A planar joint is x, y and yaw, as in PyBullet and MoveIt; a floating joint is 6, though
#: PyBullet loads it as a fixed joint (and JOINT_DOF then counts 0).
URDF_JOINT_DOF = {"revolute": 1, "continuous": 1, "prismatic": 1, "fixed": 0, "floating": 6,
                  "planar": 3, "spherical": 3}
assert set(URDF_JOINT_DOF) == set(JOINT_TYPES)
#: What ``joints --type`` accepts: the URDF types and PyBullet's, lower case.
#: (PyBullet's own type names, lower-cased, are all among them.)
JOINT_TYPE_FILTERS = JOINT_TYPES


def pybullet_joint_type(code: int) -> str:
    """PyBullet's name for a ``getJointInfo`` jointType code (the code itself if unknown)."""
    return PYBULLET_JOINT_CODES.get(int(code), str(code))


# --------------------------------------------------------------------------- shapes

#: Shapes of the URDF specification.
URDF_SHAPES = ("box", "cylinder", "sphere", "mesh")
#: Shapes PyBullet adds (other URDF tools refuse them).
PYBULLET_SHAPES = ("capsule", "plane", "cdf")
#: Every shape a ``<geometry>`` may hold.
SHAPES = URDF_SHAPES + PYBULLET_SHAPES
#: Size attributes of each primitive shape: all required, all > 0.
SHAPE_SIZES: dict[str, tuple[str, ...]] = {
    "box": ("size",), "cylinder": ("radius", "length"), "capsule": ("radius", "length"),
    "sphere": ("radius",),
}
#: Shapes that name a file.
FILE_SHAPES = ("mesh", "cdf")
#: Elements whose ``filename`` attribute names a file to load.
FILE_TAGS = ("mesh", "cdf", "texture")


def used_shape(geometry: Any) -> Any:
    """The element PyBullet 3.2.7 builds a ``<geometry>`` from: its first child element.

    Measured: tinyxml2's ``FirstChildElement`` is the shape (comments skipped); a second
    shape, even one with no size, a negative size or a missing mesh file, is never read, and
    an unknown first element makes loadURDF fail. None if ``geometry`` has no child element.
    """
    if geometry is None:
        return None
    for c in geometry:  # a loop, not next() over a generator: check asks per shape of a file
        if isinstance(c.tag, str):
            return c
    return None


def ignored_shape(el: Any) -> bool:
    """Whether ``el`` sits in a ``<geometry>`` after its first element (PyBullet skips it)."""
    parent = el.getparent()
    return parent is not None and parent.tag == "geometry" and used_shape(parent) is not el


#: Mesh formats PyBullet 3.2.7's URDF importer reads (any case); with any other suffix, or a
#: missing mesh file, loadURDF fails ("Cannot load URDF file").
MESH_FORMATS = (".stl", ".obj", ".dae")


def mesh_suffix(name: str) -> str:
    """``os.path.splitext(name)[1].lower()`` when it is one of :data:`MESH_FORMATS`, else "".

    Without splitting (the mesh rules ask once per mesh of every file): every format is a
    dot and three letters, and splitext gives a suffix only where something other than dots
    stands before it in the file's name (".obj" alone has none).
    """
    suffix = name[-4:].lower()
    if suffix not in MESH_FORMATS:
        return ""
    stem = name[:-4]
    for sep in SEPARATORS:
        stem = stem.rpartition(sep)[2]
    return suffix if stem.strip(".") else ""


#: What separates a path's parts here (and ends a folder's name).
SEPARATORS = (os.sep, os.altsep) if os.altsep else (os.sep,)

#: PyBullet's extensions to URDF, with what to tell a user who needs portable files.
EXTENSIONS: dict[str, str] = {
    "joint:spherical": "a spherical joint is a PyBullet extension; ROS, Drake and MuJoCo's "
                       "URDF importers refuse it (chain three revolute joints to be portable)",
    "shape:capsule": "<capsule> is a PyBullet extension; other URDF tools refuse it (use a "
                     "cylinder and two spheres to be portable)",
    "shape:plane": "<plane> is a PyBullet extension; other URDF tools refuse it (use a thin "
                   "box to be portable)",
    "shape:cdf": "<cdf> is a PyBullet extension (signed-distance fields); other URDF tools "
                 "refuse it",
}


def extension_note(kind: str, name: str) -> str | None:
    """The portability note for a PyBullet-only joint type or shape, else None.

    Args:
        kind: ``"joint"`` or ``"shape"``.
        name: The joint type or the shape's tag.
    """
    return EXTENSIONS.get(f"{kind}:{name}")


# --------------------------------------------------------------------------- the document

#: Subtrees urdfkit does not look into: ROS/Gazebo extensions and PyBullet's soft bodies.
OPAQUE = ("gazebo", "transmission", "deformable", "ros2_control")
#: PyBullet's ``<contact>`` children, each with a ``value``.
CONTACT_VALUES = ("lateral_friction", "rolling_friction", "spinning_friction", "restitution",
                  "stiffness", "damping", "contact_cfm", "contact_erp", "inertia_scaling",
                  "friction_anchor")

#: Numeric attributes: (tag, attribute) -> how many numbers it holds.
NUMERIC: dict[tuple[str, str], int] = {
    ("origin", "xyz"): 3, ("origin", "rpy"): 3, ("axis", "xyz"): 3,
    ("box", "size"): 3, ("cylinder", "radius"): 1, ("cylinder", "length"): 1,
    ("capsule", "radius"): 1, ("capsule", "length"): 1, ("sphere", "radius"): 1,
    ("mesh", "scale"): 3, ("cdf", "scale"): 3, ("plane", "normal"): 3,
    ("color", "rgba"): 4, ("specular", "rgb"): 3, ("mass", "value"): 1,
    **{("inertia", a): 1 for a in ("ixx", "ixy", "ixz", "iyy", "iyz", "izz")},
    **{("limit", a): 1 for a in ("lower", "upper", "effort", "velocity")},
    ("dynamics", "damping"): 1, ("dynamics", "friction"): 1,
    ("mimic", "multiplier"): 1, ("mimic", "offset"): 1,
    **{("safety_controller", a): 1
       for a in ("soft_lower_limit", "soft_upper_limit", "k_position", "k_velocity")},
    ("calibration", "rising"): 1, ("calibration", "falling"): 1,
    **{(t, "value"): 1 for t in CONTACT_VALUES if t != "friction_anchor"},
}

#: Known attributes and children per tag, PyBullet's extensions included (``<contact>``,
#: ``<collision group= mask= concave=>``, ``<specular>``, capsule/plane/cdf shapes).
SCHEMA: dict[str, tuple[frozenset[str], frozenset[str]]] = {
    tag: (frozenset(attrs.split()), frozenset(kids.split()))
    for tag, attrs, kids in (
        ("robot", "name version", "link joint material " + " ".join(OPAQUE)),
        ("link", "name type", "inertial visual collision contact"),
        ("inertial", "", "origin mass inertia"),
        ("origin", "xyz rpy", ""),
        ("mass", "value", ""),
        ("inertia", "ixx ixy ixz iyy iyz izz", ""),
        ("visual", "name", "origin geometry material"),
        ("collision", "name group mask concave", "origin geometry"),
        ("geometry", "", " ".join(SHAPES)),
        ("box", "size", ""), ("cylinder", "radius length", ""), ("sphere", "radius", ""),
        ("capsule", "radius length", ""), ("mesh", "filename scale", ""),
        ("plane", "normal", ""), ("cdf", "filename scale", ""),
        ("material", "name", "color texture specular"),
        ("color", "rgba", ""), ("texture", "filename", ""), ("specular", "rgb", ""),
        ("contact", "", " ".join(CONTACT_VALUES)),
        *((t, "value", "") for t in CONTACT_VALUES),
        ("joint", "name type", "origin parent child axis calibration dynamics limit mimic "
                               "safety_controller"),
        ("parent", "link", ""), ("child", "link", ""), ("axis", "xyz", ""),
        ("calibration", "rising falling reference_position", ""),
        ("dynamics", "damping friction", ""),
        ("limit", "lower upper effort velocity", ""),
        ("mimic", "joint multiplier offset", ""),
        ("safety_controller", "soft_lower_limit soft_upper_limit k_position k_velocity", ""),
    )
}

#: Children PyBullet builds from, by parent: a misspelt one of these changes the robot (a
#: joint it never sees, a collision it drops), so the loaders warn of it, not check alone.
BUILT_CHILDREN: dict[str, frozenset[str]] = {
    "robot": frozenset(("link", "joint")),
    "link": frozenset(("inertial", "visual", "collision")),
    "joint": frozenset(("origin", "parent", "child", "axis", "limit", "dynamics")),
    "inertial": frozenset(("origin", "mass", "inertia")),
    "visual": frozenset(("origin", "geometry")), "collision": frozenset(("origin", "geometry")),
}


#: :func:`nearest_tags` and :func:`nearest_attributes`' answers: a tree repeats its unknown
#: names (pybullet_data: 325 unknown tags, a few dozen distinct), and each match costs ~0.4 ms.
_NEAREST: dict[tuple[bool, str, str], list[str]] = {}


def nearest_tags(tag: str, parent: str) -> list[str]:
    """The known children of ``<parent>`` nearest a misspelt ``<tag>`` (none when none is near)."""
    if not isinstance(tag, str):
        return []
    return _nearest(True, tag, parent)


def nearest_attributes(attr: str, tag: str) -> list[str]:
    """The known attributes of ``<tag>`` nearest a misspelt ``attr``."""
    return _nearest(False, attr, tag)


def _nearest(children: bool, name: str, owner: str) -> list[str]:
    key = (children, name, owner)
    hit = _NEAREST.get(key)
    if hit is None:
        from urdfkit.core.suggest import close

        known = SCHEMA.get(owner)
        hit = close(name, known[1] if children else known[0]) if known is not None else []
        if len(_NEAREST) > 4096:
            _NEAREST.clear()
        _NEAREST[key] = hit
    return list(hit)


def did_you_mean(names: Sequence[str], tags: bool = True) -> str:
    """``"; did you mean <collision>?"`` (``'name'`` for attributes), or ``""``."""
    if not names:
        return ""
    quoted = [f"<{n}>" if tags else repr(n) for n in names]
    return f"; did you mean {' or '.join(quoted)}?"


# --------------------------------------------------------------------------- PyBullet's limits

#: PyBullet's state queries (getJointState, getLinkState, getBasePositionAndOrientation) fail
#: on bodies with more links than this (128 joints: its MAX_DEGREE_OF_FREEDOM); the simulating
#: commands and U208 stop at this many, where a body of one-dof joints already reads wrong
#: (see MAX_STATE_COORDINATES).
MAX_STATE_LINKS = 128
#: What those queries hold, measured on 3.2.7 (tests/test_agree_big.py): 128 position and 128
#: velocity coordinates (MAX_DEGREE_OF_FREEDOM), the base's 7 and 6 first, a fixed base too,
#: then each joint's from its ``qIndex`` / ``uIndex``. A body of 128 joints (129 links) or more
#: fails every state query at every index (getLinkState(s), getJointState(s),
#: getBasePositionAndOrientation, getBaseVelocity); below that, a joint whose ``qIndex`` is
#: 128 or more reads 0 in getJointState(s), and resetting any joint puts it back to 0 (its
#: ``resetJointState`` alone moves it), and link 0's reported frame can be wrong (124 links
#: after stepping, 128 without), without an error. ``calculateMassMatrix`` and
#: ``calculateInverseDynamics`` take the joint positions as arguments and answer right on any
#: body of at most 128 degrees of freedom (a fixed base; 600 links with 120 of them too),
#: wrong past it, without a word (measured: 0.02-4% on 129-139).
MAX_STATE_COORDINATES = 128
#: Bodies with more links than this are refused before loading: PyBullet takes minutes.
MAX_LOADABLE_LINKS = 1000
#: Deepest element nesting PyBullet 3.2.7's XML parser (tinyxml2) reads, <robot> counting 1:
#: one level more and loadURDF fails ("Cannot load URDF file").
MAX_XML_DEPTH = 98

#: PyBullet reads a URDF with ``fgets`` into an 8192-byte buffer and joins the pieces with
#: newlines: a line longer than this is broken every 8191 bytes, and a break inside a tag or
#: attribute name makes it refuse the file (or misread it). Measured on 3.2.7 with a tag
#: straddling bytes 8191 and 16382 of one line.
PYBULLET_LINE_BYTES = 8191
#: Longest name (in UTF-8 bytes) of a link, joint, material or robot the guard lets through.
#: PyBullet's fixed buffers count bytes: 700 characters of 'é' are 1,400 bytes.
MAX_NAME_BYTES = 1000
#: Name lengths (UTF-8 bytes) refused even with --no-guard, because PyBullet 3.2.7 segfaults
#: on them: a joint name in loadURDF, a link name in loadURDF, a robot name in getBodyInfo (it
#: loads, then the query crashes). The first crashes were measured at 1264, 2288 and 1042
#: bytes, but near those lengths a buffer overflow does not crash every time, so the limits
#: keep a margin below them (tests/test_guard.py keeps the table and re-measures it).
CRASH_NAME_BYTES = {"joint": 1200, "link": 2200, "robot": 1024}
#: Where a '%' in a name segfaults PyBullet 3.2.7: it quotes a link's name as printf's format
#: string in the warning for a link without <inertial>. Joint, material and robot names with
#: '%' load, and the guard's refusal of them can be lifted.
CRASH_PERCENT_TAGS = frozenset({"link"})

#: The most physics steps one run (drive, sim, a sweep point) may take: 10^8 steps is about
#: a day of a small robot's simulation on one core, and 4.8 days of simulated time at 240 Hz.
#: Past it a duration or time step is a typo (``1e308``, ``1e-300``), refused before it runs.
MAX_STEPS = 100_000_000

#: The link name PyBullet 3.2.7 treats apart: a link so named with no ``<inertial>`` gets mass 0
#: (not the 1 kg every other such link gets), so a ``world`` root makes the base static and a
#: ``world`` child is massless. Measured: case matters (``World`` gets 1 kg), and a ``world``
#: link with an ``<inertial>`` keeps its mass.
WORLD_LINK = "world"


def default_mass(link_name: str | None) -> float:
    """The mass PyBullet gives a link that has no ``<inertial>``: 0 for ``world``, else 1 kg."""
    return 0.0 if link_name == WORLD_LINK else 1.0


# --------------------------------------------------------------------------- numbers


class _HasGet(Protocol):
    def get(self, key: str, /) -> str | None: ...


def finite(value: Any) -> float:
    """``value`` as a finite float, or ValueError saying what it was.

    The one number check of the library: the builder wraps the error in a ModelError, the
    run configurations in a ParameterError naming their parameter.
    """
    try:
        x = float(value)
    except (TypeError, ValueError, OverflowError):
        raise ValueError(f"expected a number, got {value!r}") from None
    if not math.isfinite(x):
        raise ValueError(f"expected a finite number, got {value!r}")
    return x


# PyBullet 3.2.7 reads every number of a URDF with C's atof (strtod): a token is read as far
# as a number goes, 0 where none starts it (measured: mass "8abc" is 8 kg, "0x1p3" 8 kg, "1_0"
# 1 kg, "８" 0). Python's float() differs both ways: it refuses C's hexadecimal numbers and
# takes "1_0" as 10 and other scripts' digits, so no number here is read by float() alone.

#: A C hexadecimal floating number, whole (strtod's grammar; float.fromhex reads it).
_C_HEX = re.compile(r"[+-]?0[xX](?:[0-9a-fA-F]+\.?[0-9a-fA-F]*|\.[0-9a-fA-F]+)(?:[pP][+-]?[0-9]+)?")
#: The start of a token as C's atof reads it: hexadecimal, infinity, NaN or decimal.
_C_PREFIX = re.compile(r"[+-]?(?:0[xX](?:[0-9a-fA-F]+\.?[0-9a-fA-F]*|\.[0-9a-fA-F]+)"
                       r"(?:[pP][+-]?[0-9]+)?|inf(?:inity)?|nan|(?:[0-9]+\.?[0-9]*|\.[0-9]+)"
                       r"(?:[eE][+-]?[0-9]+)?)", re.IGNORECASE)


def c_number(token: str) -> float | None:
    """A whole token as C's strtod reads it (decimal, hexadecimal, inf, nan), else None.

    None for a token strtod reads only part of (``8abc``, ``1_0``): what
    :func:`atof` makes of it is not what it says.
    """
    if token.isascii() and "_" not in token:
        try:  # the common case: Python's and C's grammars agree on ASCII without "_"
            return float(token)
        except ValueError:
            if _C_HEX.fullmatch(token):
                return float.fromhex(token)
    return None


def atof(token: str) -> float:
    """A token as PyBullet reads it: C's atof of its start, 0 where no number starts it."""
    match = _C_PREFIX.match(token)
    if match is None:
        return 0.0
    text = match.group()
    return float.fromhex(text) if "x" in text or "X" in text else float(text)


def is_hex(text: str) -> bool:
    """Whether ``text`` holds a C hexadecimal number (PyBullet reads it; most readers do not)."""
    return ("x" in text or "X" in text) and any(map(_C_HEX.fullmatch, text.split()))


def numbers(text: str | None) -> list[float] | None:
    """The whitespace-separated numbers in ``text``; None when absent or malformed.

    Each is read by :func:`c_number`. Non-finite values (``nan``, ``inf``) parse; callers that
    need finite ones use :func:`vector`.
    """
    if text is None:
        return None
    out = []
    for token in text.split():
        x = c_number(token)
        if x is None:
            return None
        out.append(x)
    return out


def vector(text: str | None, n: int) -> tuple[float, ...] | None:
    """Exactly ``n`` finite numbers from ``text``, else None (missing, malformed, wrong length).

    Answers are kept per process (bounded): real files repeat ``"0 0 0"`` thousands of times.
    """
    if text is None:
        return None
    key = (text, n)
    found = _VECTORS.get(key, _NONE)
    if found is not _NONE:
        return found
    listed = numbers(text)
    vals = tuple(listed) if listed is not None else None
    if vals is not None and (len(vals) != n or not all(map(math.isfinite, vals))):
        vals = None
    if len(_VECTORS) >= _VECTORS_MAX:
        _VECTORS.clear()
    _VECTORS[key] = vals
    return vals


#: :func:`vector`'s answers by (text, n); emptied past _VECTORS_MAX.
_VECTORS: dict[tuple[str, int], tuple[float, ...] | None] = {}
_VECTORS_MAX = 4096
_NONE: Any = object()


def attr_vec(el: _HasGet | None, attr: str, n: int,
             default: Sequence[float] | None = None) -> tuple[float, ...] | None:
    """``n`` finite numbers from attribute ``attr`` of ``el``, else ``default``."""
    vals = vector(el.get(attr), n) if el is not None else None
    if vals is not None:
        return vals
    return None if default is None else tuple(map(float, default))


def attr_float(el: _HasGet | None, attr: str, default: float | None = None) -> float | None:
    """One finite number from attribute ``attr`` of ``el``, else ``default``."""
    text = el.get(attr) if el is not None else None
    if text is None:
        return default
    x = c_number(text.strip())
    return x if x is not None and math.isfinite(x) else default


# --------------------------------------------------------------------------- rotations

_HALF = math.sqrt(0.5)
#: Base orientations (x, y, z, w) that stand a model up whose "up" is the given axis (many
#: CAD-exported and graphics models are Y-up): that axis is turned onto the world's +Z.
UpAxis = Literal["z", "y", "x"]
UP_AXES: dict[str, tuple[float, float, float, float]] = {
    "z": (0.0, 0.0, 0.0, 1.0), "y": (_HALF, 0.0, 0.0, _HALF), "x": (0.0, -_HALF, 0.0, _HALF)}

Vec3 = tuple[float, float, float]
Matrix3 = tuple[Vec3, Vec3, Vec3]


def quat_mul(a: Sequence[float], b: Sequence[float]) -> tuple[float, float, float, float]:
    """The quaternion product a * b (x, y, z, w): rotate by ``b`` first, then by ``a``."""
    ax, ay, az, aw = a
    bx, by, bz, bw = b
    return (aw * bx + ax * bw + ay * bz - az * by, aw * by - ax * bz + ay * bw + az * bx,
            aw * bz + ax * by - ay * bx + az * bw, aw * bw - ax * bx - ay * by - az * bz)


def rpy_to_matrix(rpy: Sequence[float]) -> Matrix3:
    """Rotation matrix of URDF roll-pitch-yaw (fixed axes X, Y, Z): ``R = Rz(y) Ry(p) Rx(r)``."""
    r, p, y = rpy
    cr, sr, cp, sp, cy, sy = math.cos(r), math.sin(r), math.cos(p), math.sin(p), math.cos(y), \
        math.sin(y)
    return (
        (cy * cp, cy * sp * sr - sy * cr, cy * sp * cr + sy * sr),
        (sy * cp, sy * sp * sr + cy * cr, sy * sp * cr - cy * sr),
        (-sp, cp * sr, cp * cr),
    )


def rpy_to_quat(roll: float, pitch: float, yaw: float) -> tuple[float, float, float, float]:
    """Quaternion (x, y, z, w) of roll-pitch-yaw, as PyBullet's ``getQuaternionFromEuler``."""
    cr, sr = math.cos(roll / 2), math.sin(roll / 2)
    cp, sp = math.cos(pitch / 2), math.sin(pitch / 2)
    cy, sy = math.cos(yaw / 2), math.sin(yaw / 2)
    return (sr * cp * cy - cr * sp * sy, cr * sp * cy + sr * cp * sy,
            cr * cp * sy - sr * sp * cy, cr * cp * cy + sr * sp * sy)


def rpy_to_unit_quat(roll: float, pitch: float, yaw: float
                     ) -> tuple[float, float, float, float]:
    """:func:`rpy_to_quat` scaled to unit length: PyBullet's ``getQuaternionFromEuler``.

    Bit for bit: PyBullet normalises the product (each part divided by the root of the sum
    of squares, summed in order); the unscaled one differs from it in the last bit for about
    a third of all angles (tests/test_engine_seam.py compares the two over random angles).
    """
    q = rpy_to_quat(roll, pitch, yaw)
    n = math.sqrt(q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3])
    return (q[0] / n, q[1] / n, q[2] / n, q[3] / n)


def quat_to_matrix(q: Sequence[float]) -> Matrix3:
    """Rotation matrix of a unit quaternion (x, y, z, w), PyBullet's order."""
    x, y, z, w = q
    return (
        (1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)),
        (2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)),
        (2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)),
    )


def axis_angle_matrix(axis: Sequence[float], angle: float) -> Matrix3:
    """Rotation by ``angle`` (rad) about ``axis`` (normalised here; zero gives identity)."""
    norm = math.sqrt(sum(a * a for a in axis))
    if norm == 0:
        return ((1.0, 0.0, 0.0), (0.0, 1.0, 0.0), (0.0, 0.0, 1.0))
    x, y, z = (a / norm for a in axis)
    c, s = math.cos(angle), math.sin(angle)
    t = 1 - c
    return ((t * x * x + c, t * x * y - s * z, t * x * z + s * y),
            (t * x * y + s * z, t * y * y + c, t * y * z - s * x),
            (t * x * z - s * y, t * y * z + s * x, t * z * z + c))


def euler_from_quat(q: Sequence[float]) -> Vec3:
    """Roll, pitch, yaw of a quaternion (x, y, z, w): PyBullet's ``getEulerFromQuaternion``.

    Bit for bit (its formula, in its order; tests/test_engine_seam.py compares the two over
    random quaternions), for what reports as PyBullet did (drive's trajectories, on every
    engine). Within 0.0045 rad of a pitch of +-pi/2 the pitch is +-pi/2, roll 0 and yaw takes
    the sum (:func:`quat_to_rpy` is exact there).
    """
    x, y, z, w = q
    sqx, sqy, sqz, squ = x * x, y * y, z * z, w * w
    sarg = -2 * (x * z - w * y)
    if sarg <= -0.99999:
        return (0.0, -0.5 * math.pi, 2 * math.atan2(x, -y))
    if sarg >= 0.99999:
        return (0.0, 0.5 * math.pi, 2 * math.atan2(-x, y))
    return (math.atan2(2 * (y * z + w * x), squ - sqx - sqy + sqz), math.asin(sarg),
            math.atan2(2 * (x * y + w * z), squ + sqx - sqy - sqz))


def quat_to_rpy(q: Sequence[float]) -> Vec3:
    """Roll, pitch, yaw (URDF's fixed-axis X-Y-Z convention) of a quaternion (x, y, z, w).

    PyBullet's ``getEulerFromQuaternion`` to 1e-6 and exact near a pitch of +-pi/2, where
    PyBullet's (:func:`euler_from_quat`) snaps to +-pi/2 (r2d2's -1.57075 reads -pi/2 there).
    """
    x, y, z, w = q
    roll = math.atan2(2 * (w * x + y * z), 1 - 2 * (x * x + y * y))
    pitch = math.asin(max(-1.0, min(1.0, 2 * (w * y - z * x))))
    yaw = math.atan2(2 * (w * z + x * y), 1 - 2 * (y * y + z * z))
    return (_clean(roll), _clean(pitch), _clean(yaw))


def _clean(x: float) -> float:
    # -0.0 and 1e-17 noise make tables and golden files churn.
    return 0.0 if abs(x) < 1e-12 else x


def matmul(a: Matrix3, b: Matrix3) -> Matrix3:
    """The product of two 3x3 matrices (written out: check computes several per link)."""
    (a0, a1, a2), (a3, a4, a5), (a6, a7, a8) = a
    (b0, b1, b2), (b3, b4, b5), (b6, b7, b8) = b
    return ((a0 * b0 + a1 * b3 + a2 * b6, a0 * b1 + a1 * b4 + a2 * b7,
             a0 * b2 + a1 * b5 + a2 * b8),
            (a3 * b0 + a4 * b3 + a5 * b6, a3 * b1 + a4 * b4 + a5 * b7,
             a3 * b2 + a4 * b5 + a5 * b8),
            (a6 * b0 + a7 * b3 + a8 * b6, a6 * b1 + a7 * b4 + a8 * b7,
             a6 * b2 + a7 * b5 + a8 * b8))


def transpose(a: Matrix3) -> Matrix3:
    """The transpose (for a rotation, its inverse)."""
    (a0, a1, a2), (a3, a4, a5), (a6, a7, a8) = a
    return ((a0, a3, a6), (a1, a4, a7), (a2, a5, a8))


def rotate(m: Matrix3, v: Sequence[float]) -> Vec3:
    """``m @ v``."""
    return (m[0][0] * v[0] + m[0][1] * v[1] + m[0][2] * v[2],
            m[1][0] * v[0] + m[1][1] * v[1] + m[1][2] * v[2],
            m[2][0] * v[0] + m[2][1] * v[1] + m[2][2] * v[2])


def rotate_back(m: Matrix3, v: Sequence[float]) -> Vec3:
    """``m^T @ v``: a world vector in the frame ``m`` describes."""
    return (m[0][0] * v[0] + m[1][0] * v[1] + m[2][0] * v[2],
            m[0][1] * v[0] + m[1][1] * v[1] + m[2][1] * v[2],
            m[0][2] * v[0] + m[1][2] * v[1] + m[2][2] * v[2])


# --------------------------------------------------------------------------- solids
# Plain-float formulas on which the builder (derived <inertia>) and check (plausibility of a
# file's <inertia>) agree. Floats overflow to inf here, never to OverflowError: ``x * x``, not
# ``x ** 2``, so a 1e308 in a file becomes a finding, not a traceback.

#: Shapes whose solid volume and inertia have closed forms, with the sizes they take.
SOLIDS = {"box": ("x", "y", "z"), "cylinder": ("radius", "length"), "sphere": ("radius",),
          "capsule": ("radius", "length")}


def solid_volume(kind: str, dims: Sequence[float]) -> float:
    """Volume (m^3) of a solid box (x, y, z), cylinder or capsule (radius, length), sphere."""
    if kind == "box":
        return dims[0] * dims[1] * dims[2]
    r = dims[0]
    ball = 4 / 3 * math.pi * r * r * r
    if kind == "sphere":
        return ball
    tube = math.pi * r * r * dims[1]
    return tube if kind == "cylinder" else tube + ball


def solid_inertia(kind: str, dims: Sequence[float], mass: float) -> Vec3:
    """Principal moments (ixx, iyy, izz) about the centre, in the shape's frame (axis z)."""
    if kind == "box":
        x, y, z = dims
        k = mass / 12
        return (k * (y * y + z * z), k * (x * x + z * z), k * (x * x + y * y))
    r = dims[0]
    if kind == "sphere":
        i = 2 / 5 * mass * r * r
        return (i, i, i)
    h = dims[1]
    if kind == "cylinder":
        radial = mass * (3 * r * r + h * h) / 12
        return (radial, radial, mass * r * r / 2)
    v_tube, v_caps = math.pi * r * r * h, 4 / 3 * math.pi * r * r * r
    m_tube = mass * v_tube / (v_tube + v_caps)
    m_caps = mass - m_tube
    # The two hemispheres form a sphere split in half and pushed apart by h: each half's
    # centre of mass sits 3r/8 from its flat face, so h/2 + 3r/8 from the capsule centre.
    radial = (m_tube * (3 * r * r + h * h) / 12
              + m_caps * (2 * r * r / 5 + h * h / 4 + 3 * h * r / 8))
    return (radial, radial, m_tube * r * r / 2 + m_caps * 2 * r * r / 5)


def sym_eigenvalues(m: Sequence[Sequence[float]]) -> Vec3:
    """Eigenvalues of a real symmetric 3x3 matrix, ascending (closed form, Smith 1961)."""
    p1 = m[0][1] * m[0][1] + m[0][2] * m[0][2] + m[1][2] * m[1][2]
    q = (m[0][0] + m[1][1] + m[2][2]) / 3
    if p1 == 0:
        a, b, c = sorted((m[0][0], m[1][1], m[2][2]))
        return (a, b, c)
    p2 = sum((m[i][i] - q) * (m[i][i] - q) for i in range(3)) + 2 * p1
    p = math.sqrt(p2 / 6)
    b_ = [[(m[i][j] - (q if i == j else 0)) / p for j in range(3)] for i in range(3)]
    det_b = (
        b_[0][0] * (b_[1][1] * b_[2][2] - b_[1][2] * b_[2][1])
        - b_[0][1] * (b_[1][0] * b_[2][2] - b_[1][2] * b_[2][0])
        + b_[0][2] * (b_[1][0] * b_[2][1] - b_[1][1] * b_[2][0])
    )
    r = max(-1.0, min(1.0, det_b / 2)) if math.isfinite(det_b) else 0.0
    phi = math.acos(r) / 3
    e1 = q + 2 * p * math.cos(phi)
    e3 = q + 2 * p * math.cos(phi + 2 * math.pi / 3)
    lo, mid, hi = sorted((e1, 3 * q - e1 - e3, e3))
    return (lo, mid, hi)


# --------------------------------------------------------------------------- joint order

K = TypeVar("K", bound=Hashable)
E = TypeVar("E")


def depth_first(root: K, below: Mapping[K, Sequence[E]], child: Callable[[E], K]) -> list[E]:
    """The edges of a tree in PyBullet's joint order: depth-first from ``root``, file order.

    PyBullet numbers joints in a pre-order walk from the root link, taking each link's child
    joints in the order the file declares them. Iterative, so a 1000-link chain cannot
    overflow the stack; an edge whose child was already reached (a cycle, a second parent)
    is skipped, since the guard refuses such files before they get here.

    Args:
        root: The root link.
        below: Each link's outgoing edges (joints), in file order.
        child: The link an edge leads to.
    """
    order: list[E] = []
    seen = {root}
    stack: list[E] = list(reversed(below.get(root, ())))
    while stack:
        edge = stack.pop()
        link = child(edge)
        if link in seen:
            continue
        seen.add(link)
        order.append(edge)
        stack.extend(reversed(below.get(link, ())))
    return order
