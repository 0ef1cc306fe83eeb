"""The robot as ``urdfkit view`` shows it: read from PyBullet, through the engine seam.

:class:`ViewedRobot` reads a body loaded in a :class:`~urdfkit.engine.api.Simulator` (PyBullet's)
into plain data: every link's visual and collision shapes (``visual_shapes`` and
``collision_shapes``: PyBullet's ``getVisualShapeData`` and ``getCollisionShapeData``, so
colours follow PyBullet's material rules and collision meshes are the convex hulls PyBullet
collides with), its inertial frame, mass and principal moments (``dynamics``), the movable
joints in PyBullet's index order, mimic joints, and the findings of ``check`` mapped to links.
It poses the body with ``reset_joint`` and reads link frames back from the engine
(``link_frames``); it never computes kinematics.

Frames, measured on PyBullet 3.2.7 and relied on here: a visual shape's frame is in the URDF
link frame; a collision shape's is in the link's inertial frame (its centre of mass), as is
the diagonal inertia, which PyBullet has already turned to principal axes. A fixed base reads
mass 0, so the body is loaded free and never stepped.
"""

from __future__ import annotations

import math
import re
import threading
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Literal

from urdfkit.core.errors import UrdfkitError
from urdfkit.core.finding import Finding
from urdfkit.engine.api import JointInfo, LoadSettings, ShapeKind, Simulator

#: Tints of links with findings (RGB 0..255): check's error red and warning amber.
TINTS = {"error": (220, 38, 38), "warning": (245, 158, 11)}
#: Links touching another at the current pose (self-collision pairs).
TOUCHING_RGB = (200, 0, 200)
#: The selected link.
SELECTED_RGB = (86, 180, 233)
#: Colour of collision shapes; of those PyBullet replaces by a hull of a concave mesh.
COLLISION_RGB = (213, 94, 0)
CONCAVE_RGB = (204, 121, 167)
#: Meshes with more triangles than this are thinned for display (only: PyBullet keeps all).
MAX_DISPLAY_FACES = 200_000

Vec3 = tuple[float, float, float]
Quat = tuple[float, float, float, float]  # x, y, z, w as PyBullet gives them


#: What a drawn shape was in the file (``mesh`` for a mesh, whatever PyBullet made of it).
DrawnKind = Literal["box", "sphere", "cylinder", "capsule", "plane", "mesh"]
#: The layers of the scene the page shows or hides: shapes, link frames, inertia boxes.
Layer = Literal["visual", "collision", "frames", "inertia"]


@dataclass
class Shape:
    """One visual or collision shape, ready to draw: triangles in the shape's own frame.

    Attributes:
        kind: ``box``, ``sphere``, ``cylinder``, ``capsule``, ``mesh`` or ``plane``.
        vertices: N x 3 float array (metres, scale applied).
        faces: M x 3 int array.
        pos: Position in the link frame.
        quat: Orientation in the link frame (x, y, z, w).
        rgb: Colour, 0..255.
        opacity: 1 for opaque.
        note: What the page should say about it (a hull of a concave mesh, a thinned mesh).
    """

    kind: DrawnKind
    vertices: Any
    faces: Any
    pos: Vec3
    quat: Quat
    rgb: tuple[int, int, int]
    opacity: float = 1.0
    note: str = ""


@dataclass
class LinkView:
    """A link as PyBullet holds it.

    Attributes:
        index: PyBullet's link index (-1: the base).
        name: The link's name.
        visuals: Visual shapes, posed in the link frame.
        collisions: Collision shapes, posed in the link frame.
        mass: PyBullet's mass (kg).
        inertial_pos: The inertial frame (centre of mass) in the link frame.
        inertial_quat: Its orientation: the principal axes.
        moments: PyBullet's principal moments of inertia (kg m^2).
        level: ``error`` or ``warning`` when check found something on this link, else None.
    """

    index: int
    name: str
    visuals: list[Shape] = field(default_factory=list)
    collisions: list[Shape] = field(default_factory=list)
    mass: float = 0.0
    inertial_pos: Vec3 = (0.0, 0.0, 0.0)
    inertial_quat: Quat = (0.0, 0.0, 0.0, 1.0)
    moments: Vec3 = (0.0, 0.0, 0.0)
    level: str | None = None

    @property
    def inertia_box(self) -> Vec3 | None:
        """Sides of the uniform box with this mass and these principal moments, or None.

        For a box of sides a, b, c: I1 = m (b^2 + c^2) / 12 and so on, so
        a^2 = 6 (I2 + I3 - I1) / m. A negative square (moments that break the triangle
        inequality, which no body has) is drawn as 0.
        """
        if not self.mass > 0 or not all(math.isfinite(v) for v in self.moments):
            return None
        i1, i2, i3 = self.moments
        sq = (6 * (i2 + i3 - i1) / self.mass, 6 * (i1 + i3 - i2) / self.mass,
              6 * (i1 + i2 - i3) / self.mass)
        return (math.sqrt(max(sq[0], 0.0)), math.sqrt(max(sq[1], 0.0)),
                math.sqrt(max(sq[2], 0.0)))


@dataclass(frozen=True)
class TableJoint:
    """One row of the page's joint table: a joint as the engine loaded it, and its URDF type.

    Attributes:
        info: The engine's record.
        urdf_type: The file's ``type`` (``continuous`` where the engine says revolute), or
            None if no ``<joint>`` has its name.
        parent_link_name: Its parent link's name.
    """

    info: JointInfo
    urdf_type: str | None
    parent_link_name: str

    @property
    def joint_index(self) -> int:
        """The engine's joint (and child link) index."""
        return self.info.index

    @property
    def joint_name(self) -> str:
        """The joint's name."""
        return self.info.name

    @property
    def link_name(self) -> str:
        """Its child link's name."""
        return self.info.link

    @property
    def joint_type(self) -> str:
        """PyBullet's type name (``REVOLUTE`` ... ``FIXED``)."""
        return self.info.kind.upper()

    @property
    def joint_lower_limit(self) -> float:
        """The lower limit, as the engine reports it."""
        return self.info.lower

    @property
    def joint_upper_limit(self) -> float:
        """The upper limit, as the engine reports it."""
        return self.info.upper

    @property
    def limited(self) -> bool:
        """Whether the joint has limits: a continuous joint's reported ``<limit>`` is none."""
        return self.info.limited and self.urdf_type != "continuous"

    @property
    def type_label(self) -> str:
        """The type, with the URDF type where that says more (continuous)."""
        return "REVOLUTE (continuous)" if self.urdf_type == "continuous" else self.joint_type


@dataclass
class JointControl:
    """A movable joint: what its slider shows.

    Attributes:
        index: PyBullet's joint index.
        name: The joint's name.
        urdf_type: ``revolute``, ``continuous`` or ``prismatic``.
        lower: The slider's lower end (continuous: -pi).
        upper: The slider's upper end (continuous: pi).
        axis: The joint axis in the child link frame.
        link: The child link's index.
        mimic: (leader joint name, multiplier, offset) for a mimic joint.
    """

    index: int
    name: str
    urdf_type: str
    lower: float
    upper: float
    axis: Vec3
    link: int
    mimic: tuple[str, float, float] | None = None


def _primitive(kind: ShapeKind, dims: Sequence[float]) -> tuple[DrawnKind, Any, Any] | None:
    import trimesh

    if kind == "box":
        m = trimesh.creation.box(extents=[abs(float(d)) for d in dims[:3]])
        return "box", m.vertices, m.faces
    if kind == "sphere":
        m = trimesh.creation.icosphere(subdivisions=2, radius=abs(float(dims[0])))
        return "sphere", m.vertices, m.faces
    if kind == "cylinder":
        m = trimesh.creation.cylinder(radius=abs(float(dims[1])), height=abs(float(dims[0])),
                                      sections=32)
        return "cylinder", m.vertices, m.faces
    if kind == "capsule":
        m = trimesh.creation.capsule(height=abs(float(dims[0])), radius=abs(float(dims[1])))
        return "capsule", m.vertices, m.faces
    if kind == "plane":
        m = trimesh.creation.box(extents=[20.0, 20.0, 0.001])
        return "plane", m.vertices, m.faces
    return None


def read_mesh(path: str | Path) -> tuple[Any, Any] | None:
    """Vertices and triangles of an STL, OBJ or DAE file as urdfkit reads them for PyBullet.

    DAE files are placed and scaled the way PyBullet does (see :mod:`urdfkit.sources.meshes`).
    None when the file cannot be read.
    """
    import struct

    from urdfkit.core import deps
    from urdfkit.core.errors import InputError
    from urdfkit.model.xmlio import read_regular
    from urdfkit.sources.meshes import MAX_MESH_BYTES, _dae, _obj, _stl

    path = Path(path)
    deps.note(path)
    suffix = path.suffix.lower()
    try:
        data = read_regular(path, limit=MAX_MESH_BYTES, kind="mesh")
        if suffix == ".stl":
            return _stl(data)
        if suffix == ".obj":
            vertices, faces, _ = _obj(data)
            return vertices, faces
        if suffix == ".dae":
            return _dae(data, path)
    except (InputError, ValueError, struct.error, IndexError, OverflowError, KeyError,
            AttributeError, StopIteration, TypeError):
        return None
    return None


class ViewedRobot:
    """A file loaded in its own PyBullet world, read into what the viewer draws.

    Attributes:
        resolved: The resolved file (:func:`urdfkit.sources.resolve.open_input`).
        engine: The engine holding the body (PyBullet's); closed by :meth:`close`.
        body: The body id.
        links: Every link, base first (index -1).
        joints: The movable joints in PyBullet's index order.
        table: Every joint, with its URDF type (the page's joint table).
        findings: ``check``'s findings on the file.
        notes: What the page should say (unreadable meshes, PyBullet's warnings).
        depends: Every path the model was read from, with its signature (for live reload).
    """

    def __init__(self, file: str, *, packages: Sequence[str] | None = None,
                 package_paths: Sequence[str] | None = None,
                 xacro_args: Sequence[str] | None = None,
                 inertia_from_file: bool = False, display: str | None = None) -> None:
        from urdfkit.core import deps
        from urdfkit.engine.registry import open_engine
        from urdfkit.sources.resolve import open_input

        #: The file as the user knows it (a template's name, not its cache path): in findings.
        self.file = display or file
        self.notes: list[str] = []
        self.lock = threading.RLock()
        self.engine: Simulator | None = None
        self._probe: tuple[Simulator, int, list[tuple[int, int]]] | None = None
        with deps.record() as recorded:
            deps.note(file)
            try:
                self.resolved = open_input(file, packages=list(packages or []),
                                           xacro_args=list(xacro_args or []),
                                           package_paths=list(package_paths or []))
                if display:
                    self.resolved.name = display
                deps.note(self.resolved.source)
                self.engine = open_engine("pybullet")
                self.body = self.engine.load(str(self.resolved.load_path),
                                             LoadSettings(inertia_from_file=inertia_from_file),
                                             display=self.resolved.name)
                self.engine.require_state_queries(self.body, self.resolved.name)
                self._read()
                self.findings = self._check(packages, package_paths, xacro_args)
            except BaseException:
                self.depends = dict(recorded)
                self.close()
                raise
        self.depends = dict(recorded)

    # ------------------------------------------------------------------ reading

    @property
    def world(self) -> Simulator:
        """The open engine (a closed robot has none)."""
        if self.engine is None:
            raise UrdfkitError(f"{self.file}: the viewer's robot is closed")
        return self.engine

    def _read(self) -> None:
        from urdfkit.model.xmlio import children

        e, body = self.world, self.body
        joints = e.joints(body)
        names = e.link_names(body)
        types = {el.get("name", ""): el.get("type", "") for el in children(self.resolved.root,
                                                                          "joint")}
        self.table = [TableJoint(j, types.get(j.name), names[j.parent + 1]) for j in joints]
        self.links = [LinkView(i, names[i + 1]) for i in range(-1, len(joints))]
        for link in self.links:
            d = e.dynamics(body, link.index)
            link.mass = float(d.mass)
            link.moments = _floats3(d.inertia)
            link.inertial_pos = _floats3(d.inertial_position)
            link.inertial_quat = _floats4(d.inertial_orientation)
        for v in e.visual_shapes(body):
            shape = self._shape(v.kind, v.dimensions, v.filename, v.position, v.orientation,
                                collision=False, rgba=v.rgba)
            if shape is not None:
                self.links[v.link + 1].visuals.append(shape)
        concave = self._concave()
        for link in self.links:
            for c in e.collision_shapes(body, link.index):
                # Relative to the inertial frame: move it into the link frame.
                pos, quat = _compose(link.inertial_pos, link.inertial_quat, c.position,
                                     c.orientation)
                shape = self._shape(c.kind, c.dimensions, c.filename, pos, quat,
                                    collision=True, concave=link.name in concave)
                if shape is not None:
                    link.collisions.append(shape)
        self.joints = self._controls()
        self.notes.extend(self.resolved.warnings)
        from urdfkit.sources.resolve import undrawn_note

        undrawn = undrawn_note(self.resolved)
        if undrawn is not None:
            self.notes.append(undrawn)

    def _shape(self, kind: ShapeKind, dims: Sequence[float], name: str,
               pos: Sequence[float], quat: Sequence[float], *, collision: bool,
               rgba: Sequence[float] = (1.0, 1.0, 1.0, 1.0), concave: bool = False
               ) -> Shape | None:
        import numpy as np

        note = ""
        if kind == "mesh":
            if not name:  # a cylinder PyBullet made a mesh of: nothing to read back
                return None
            mesh = read_mesh(name)
            if mesh is None:
                self.notes.append(f"cannot read mesh {name}: not drawn")
                return None
            vertices = np.asarray(mesh[0], dtype=float) * np.asarray(dims[:3], dtype=float)
            faces = np.asarray(mesh[1], dtype=np.int64)
            kind_name: DrawnKind = "mesh"
            if collision:  # what PyBullet collides with: the hull (urdfkit.sources.hull)
                from urdfkit.sources.hull import HULL_POINTS, convex_hull

                hull = convex_hull(vertices)
                if hull is not None:
                    thinned = len(vertices) > HULL_POINTS
                    vertices, faces = hull
                    note = ("convex hull of a concave mesh" if concave else "convex hull") + \
                        (" (of its points thinned on a grid, for display)" if thinned else "")
            elif len(faces) > MAX_DISPLAY_FACES:
                from urdfkit.draw.displaymesh import decimate

                before = len(faces)
                vertices, faces = decimate(vertices, faces, MAX_DISPLAY_FACES)
                note = (f"{Path(name).name}: {before} triangles, drawn as {len(faces)} "
                        "(vertex clustering, for display only: PyBullet keeps them all)")
                self.notes.append(note)
        else:
            made = _primitive(kind, dims)
            if made is None:
                return None
            kind_name, vertices, faces = made
        if collision:
            rgb = CONCAVE_RGB if concave else COLLISION_RGB
            opacity = 0.6
        else:
            rgb = tuple(int(round(min(max(float(x), 0.0), 1.0) * 255)) for x in rgba[:3])  # type: ignore[assignment]
            opacity = float(rgba[3]) if len(rgba) > 3 else 1.0
        return Shape(kind_name, np.asarray(vertices, dtype=np.float32),
                     np.asarray(faces, dtype=np.uint32), tuple(float(x) for x in pos),  # type: ignore[arg-type]
                     tuple(float(x) for x in quat), rgb, opacity, note)  # type: ignore[arg-type]

    def _concave(self) -> set[str]:
        from urdfkit.checks.collisions import _concave_links

        try:
            return _concave_links(self.resolved, None)
        except UrdfkitError:
            return set()

    def _controls(self) -> list[JointControl]:
        from urdfkit.model.spec import vector

        elements = {j.get("name"): j for j in self.resolved.root.iterchildren("joint")}
        out = []
        for j in self.table:
            if j.joint_type not in ("REVOLUTE", "PRISMATIC"):
                continue
            kind = j.urdf_type or j.info.kind
            if j.limited:
                lower, upper = j.joint_lower_limit, j.joint_upper_limit
            else:
                lower, upper = -math.pi, math.pi
            mimic = None
            el = elements.get(j.joint_name)
            m = el.find("mimic") if el is not None else None
            if m is not None and m.get("joint"):
                mult = vector(m.get("multiplier"), 1) or [1.0]
                off = vector(m.get("offset"), 1) or [0.0]
                mimic = (str(m.get("joint")), float(mult[0]), float(off[0]))
            out.append(JointControl(j.joint_index, j.joint_name, kind, float(lower),
                                    float(upper), _floats3(j.info.axis), j.joint_index, mimic))
        names = {jc.name for jc in out}
        for jc in out:  # a mimic of a joint that cannot move is just a joint
            if jc.mimic is not None and jc.mimic[0] not in names:
                jc.mimic = None
        return out

    def _check(self, packages: Sequence[str] | None, package_paths: Sequence[str] | None,
               xacro_args: Sequence[str] | None) -> list[Finding]:
        """Run ``check`` on the file and tint the links its findings are about."""
        from urdfkit.checks.check import check_file
        from urdfkit.sources.uris import parse_packages

        args: dict[str, str] = {}
        if xacro_args:
            from urdfkit.model.catalog import parse_assignments

            args = dict(parse_assignments(list(xacro_args), "xacro_args"))
        result = check_file(self.resolved.name, self.resolved.source,
                            parse_packages(list(packages or []), list(package_paths or [])),
                            xacro_args=args)
        by_name = {link.name: link for link in self.links}
        child_of = {j.joint_name: j.link_name for j in self.table}
        for f in result.findings:
            if f.level not in TINTS:
                continue
            for name in self.finding_links(f, child_of):
                link = by_name.get(name)
                if link is not None and link.level != "error":
                    link.level = f.level
        return result.findings

    def finding_links(self, f: Finding, child_of: Mapping[str, str] | None = None
                      ) -> list[str]:
        """The links a finding is about: the element on its line, else those it names.

        A joint's finding marks its child link, the one the joint moves.
        """
        from urdfkit.model.xmlio import line_of

        if child_of is None:
            child_of = {j.joint_name: j.link_name for j in self.table}
        found: list[str] = []
        if f.line is not None and self.resolved.source.suffix != ".xacro":
            for el in self.resolved.root.iter("link", "joint"):
                first, last = line_of(el), _last_line(el)
                if first is not None and first <= f.line <= last:
                    found.append(str(el.get("name")) if el.tag == "link"
                                 else child_of.get(str(el.get("name")), ""))
                    break
        if not found:
            for tag, _, name in _NAMED.findall(f.message):
                found.append(name if tag == "link" else child_of.get(name, ""))
        return [n for n in found if n]

    # ------------------------------------------------------------------ posing

    def set_positions(self, values: Mapping[str, float]) -> dict[str, float]:
        """Set joints by name with ``reset_joint``; mimic joints follow their leader.

        Returns every movable joint's position as the engine now reports it.
        """
        with self.lock:
            e = self.world
            by_name = {j.name: j for j in self.joints}
            wanted = {k: float(v) for k, v in values.items() if k in by_name}
            for name, value in wanted.items():
                if by_name[name].mimic is None:
                    e.reset_joint(self.body, by_name[name].index, value)
            now = self.positions()
            for j in self.joints:  # leaders first in a chain: index order is depth order
                if j.mimic is not None and j.mimic[0] in now:
                    value = now[j.mimic[0]] * j.mimic[1] + j.mimic[2]
                    e.reset_joint(self.body, j.index, value)
                    now[j.name] = value
            return self.positions()

    def positions(self) -> dict[str, float]:
        """Every movable joint's position, read from the engine (``joint_rows``)."""
        with self.lock:
            rows = self.world.joint_rows(self.body, [j.index for j in self.joints])
            return {j.name: float(row[0]) for j, row in zip(self.joints, rows, strict=True)}

    def link_poses(self) -> list[tuple[Vec3, Quat]]:
        """World pose of every URDF link frame, base first, as the engine reports it."""
        with self.lock:
            return [(_floats3(a), _floats4(b)) for a, b in self.world.link_frames(self.body)]

    def bounds(self) -> tuple[Vec3, Vec3]:
        """The posed robot's box, for the camera: getAABB over links, and the visual shapes.

        PyBullet's boxes hold the collision shapes only: a link with visual shapes alone (an
        arm sketched without ``<collision>``) adds a point, and a camera framed on that was
        inside the arm. Each visual shape's own box, posed, counts too (planes aside).
        """
        import numpy as np

        from urdfkit.draw.framing import corners
        from urdfkit.model.spec import quat_to_matrix

        with self.lock:
            e = self.world
            lo, hi = [math.inf] * 3, [-math.inf] * 3
            for link in self.links:
                a, b = e.aabb(self.body, link.index)
                if all(math.isfinite(x) for x in (*a, *b)) and all(
                        b[k] >= a[k] for k in range(3)):
                    lo = [min(lo[k], a[k]) for k in range(3)]
                    hi = [max(hi[k], b[k]) for k in range(3)]
            for link, (pos, quat) in zip(self.links, self.link_poses(), strict=True):
                for sh in link.visuals:
                    v = np.asarray(sh.vertices, dtype=float)
                    if sh.kind == "plane" or not len(v) or not np.all(np.isfinite(v)):
                        continue
                    box = corners(v.min(axis=0), v.max(axis=0))
                    box = box @ np.asarray(quat_to_matrix(sh.quat)).T + np.asarray(sh.pos)
                    box = box @ np.asarray(quat_to_matrix(quat)).T + np.asarray(pos)
                    lo = [min(lo[k], float(box[:, k].min())) for k in range(3)]
                    hi = [max(hi[k], float(box[:, k].max())) for k in range(3)]
            if not all(math.isfinite(x) for x in lo + hi):
                return (-0.5, -0.5, -0.5), (0.5, 0.5, 0.5)
            return tuple(lo), tuple(hi)  # type: ignore[return-value]

    def touching(self) -> list[tuple[str, str, float]]:
        """Link pairs touching or interpenetrating at the current pose, as ``collisions`` sees them.

        Measured in a second world, its body loaded with self-collision (without it
        PyBullet's getClosestPoints finds nothing between a body's own links) and pinned,
        posed like the shown one; links joined by a joint are not tested, as in ``urdfkit
        collisions``. Returns (link a, link b, signed distance in m), deepest first.
        """
        with self.lock:
            if self._probe is None:
                self._probe = self._open_probe()
            probe, body, pairs = self._probe
            now = self.world.joint_rows(self.body, [j.index for j in self.joints])
            for j, row in zip(self.joints, now, strict=True):
                probe.reset_joint(body, j.index, row[0])
            out = []
            for a, b in pairs:
                points = probe.closest_points(body, body, 0.0, a, b)
                if points:
                    out.append((self.links[a + 1].name, self.links[b + 1].name,
                                float(min(pt.distance for pt in points))))
            return sorted(out, key=lambda x: x[2])

    def _open_probe(self) -> tuple[Simulator, int, list[tuple[int, int]]]:
        from urdfkit.engine.registry import open_engine

        probe = open_engine("pybullet")
        try:
            body = probe.load(str(self.resolved.load_path),
                              LoadSettings(fixed_base=True, self_collision=True),
                              display=self.resolved.name)
        except BaseException:
            probe.close()
            raise
        shaped = [lk.index for lk in self.links if lk.collisions]
        parent = {j.joint_index: j.info.parent for j in self.table}
        pairs = [(a, b) for k, a in enumerate(shaped) for b in shaped[k + 1:]
                 if parent.get(b) != a and parent.get(a) != b]
        return probe, body, pairs

    def joint_vector(self) -> tuple[str, str]:
        """The current joints as a Python list (index order) and as ``--joints`` text."""
        now = self.positions()
        values = [round(now[j.name], 6) for j in self.joints]
        text = ",".join(f"{j.name}={round(now[j.name], 6):g}" for j in self.joints)
        return repr(values), f"--joints {text}" if text else ""

    def close(self) -> None:
        """Close the engine and drop the resolved temp copy."""
        if self.engine is not None:
            self.engine.close()
            self.engine = None
        probe = getattr(self, "_probe", None)
        if probe is not None:
            probe[0].close()
            self._probe = None
        resolved = getattr(self, "resolved", None)
        if resolved is not None:
            resolved.close()


def _floats3(v: Sequence[float]) -> Vec3:
    return float(v[0]), float(v[1]), float(v[2])


def _floats4(v: Sequence[float]) -> Quat:
    return float(v[0]), float(v[1]), float(v[2]), float(v[3])


def _compose(pos: Vec3, quat: Quat, local: Sequence[float], turn: Sequence[float]
             ) -> tuple[Vec3, Quat]:
    """The frame ``(local, turn)`` given in the frame ``(pos, quat)``, in that frame's parent.

    In double precision (PyBullet's ``multiplyTransforms``, used before the seam, rounds to
    float32: on 13 robots the two differ by 2.6e-8 m and 1.4e-7 in a quaternion at most).
    """
    from urdfkit.model.spec import quat_mul, quat_to_matrix, rotate

    at = rotate(quat_to_matrix(quat), local)
    return (pos[0] + at[0], pos[1] + at[1], pos[2] + at[2]), quat_mul(quat, turn)


#: ``<link name='x'>`` / ``<joint name="x">`` as check's messages name elements.
_NAMED = re.compile(r"<(link|joint) name=(['\"])(.*?)\2>")


def _last_line(el: Any) -> int:
    from urdfkit.model.xmlio import line_of

    last = line_of(el) or 0
    for sub in el.iter():
        last = max(last, line_of(sub) or 0)
    return last

