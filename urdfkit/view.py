"""``urdfkit view``: the robot in a browser, as PyBullet loaded it, with ``check``'s findings on it.

Two halves:

- :class:`Model` reads a loaded body into plain data: every link's visual and collision shapes
  (from ``getVisualShapeData`` and ``getCollisionShapeData``, so colours follow PyBullet's
  material rules and collision meshes are the convex hulls PyBullet collides with), its
  inertial frame, mass and principal moments, the movable joints in PyBullet's index order,
  mimic joints, and the findings of ``check`` mapped to links. It poses the body with
  ``resetJointState`` and reads link poses back from PyBullet; it never computes kinematics.
- :class:`Viewer` shows a :class:`Model` with viser (a web server whose client ships in its
  wheel, so it works offline), and reloads it when the file or anything it read changes.

Frames, measured on PyBullet 3.2.7 and relied on here: ``getVisualShapeData``'s local frame is
relative to the URDF link frame; ``getCollisionShapeData``'s is relative to the link's inertial
frame (its centre of mass), as is ``getDynamicsInfo``'s diagonal inertia, which PyBullet has
already turned to principal axes; ``getBasePositionAndOrientation`` is the base's inertial
frame. A fixed base reads mass 0, so the body is loaded free and never stepped.
"""

from __future__ import annotations

import math
import re
import threading
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from .errors import EngineError, MissingDependencyError, UrdfkitError
from .finding import Finding

#: Tints of links with findings (RGB 0..255): check's error red and warning amber.
TINTS = {"error": (220, 38, 38), "warning": (245, 158, 11)}
#: Colour of collision shapes; of those PyBullet replaces by a hull of a concave mesh.
COLLISION_RGB = (213, 94, 0)
CONCAVE_RGB = (204, 121, 167)
#: Links touching another at the current pose (self-collision pairs).
TOUCHING_RGB = (200, 0, 200)
#: The selected link.
SELECTED_RGB = (86, 180, 233)
#: The selection dropdown's entry for no link.
NO_LINK = "(none)"
#: How often the watcher looks at the files the robot was read from (s).
POLL_SECONDS = 0.25
#: Meshes with more triangles than this are thinned for display (only: PyBullet keeps all).
MAX_DISPLAY_FACES = 200_000

# PyBullet's geometry codes (p.GEOM_*), spelled here so reading them needs no import.
_SPHERE, _BOX, _CYLINDER, _MESH, _PLANE, _CAPSULE = 2, 3, 4, 5, 6, 7

Vec3 = tuple[float, float, float]
Quat = tuple[float, float, float, float]  # x, y, z, w as PyBullet gives them


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

    kind: str
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


def _viser() -> Any:
    try:
        import viser
    except ImportError as e:
        raise MissingDependencyError("urdfkit view needs viser: pip install viser") from e
    return viser


def _primitive(kind: int, dims: Sequence[float]) -> tuple[str, Any, Any] | None:
    import trimesh

    if kind == _BOX:
        m = trimesh.creation.box(extents=[abs(float(d)) for d in dims[:3]])
        return "box", m.vertices, m.faces
    if kind == _SPHERE:
        m = trimesh.creation.icosphere(subdivisions=2, radius=abs(float(dims[0])))
        return "sphere", m.vertices, m.faces
    if kind == _CYLINDER:
        m = trimesh.creation.cylinder(radius=abs(float(dims[1])), height=abs(float(dims[0])),
                                      sections=32)
        return "cylinder", m.vertices, m.faces
    if kind == _CAPSULE:
        m = trimesh.creation.capsule(height=abs(float(dims[0])), radius=abs(float(dims[1])))
        return "capsule", m.vertices, m.faces
    if kind == _PLANE:
        m = trimesh.creation.box(extents=[20.0, 20.0, 0.001])
        return "plane", m.vertices, m.faces
    return None


def read_mesh(path: str | Path) -> tuple[Any, Any] | None:
    """Vertices and triangles of an STL, OBJ or DAE file as urdfkit reads them for PyBullet.

    DAE files are placed and scaled the way PyBullet does (see :mod:`urdfkit.meshes`).
    None when the file cannot be read.
    """
    import struct

    from . import deps
    from .errors import InputError
    from .meshes import MAX_MESH_BYTES, _dae, _obj, _stl
    from .xmlio import read_regular

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


class Model:
    """A file loaded in its own PyBullet session, read into what the viewer draws.

    Attributes:
        resolved: The resolved file (:func:`urdfkit.resolve.open_input`).
        session: The PyBullet session holding the body; closed by :meth:`close`.
        body: The body id.
        links: Every link, base first (index -1).
        joints: The movable joints in PyBullet's index order.
        table: The whole joint table (as ``urdfkit joints`` shows it).
        findings: ``check``'s findings on the file.
        notes: What the page should say (unreadable meshes, PyBullet's warnings).
        depends: Every path the model was read from, with its signature (for live reload).
    """

    def __init__(self, file: str, *, packages: Sequence[str] | None = None,
                 package_paths: Sequence[str] | None = None,
                 xacro_args: Sequence[str] | None = None,
                 inertia_from_file: bool = False) -> None:
        from . import deps
        from .resolve import open_input
        from .session import LoadOptions, Session

        self.file = file
        self.notes: list[str] = []
        self.lock = threading.RLock()
        self.session: Any = None
        self._probe: tuple[Any, int, list[tuple[int, int]]] | None = None
        with deps.record() as recorded:
            deps.note(file)
            try:
                self.resolved = open_input(file, list(packages or []), list(xacro_args or []),
                                           package_paths=list(package_paths or []))
                deps.note(self.resolved.source)
                self.session = Session()
                options = LoadOptions(inertia_from_file=inertia_from_file)
                self.body = self.session.load_urdf(self.resolved.load_path, options,
                                                   display=self.resolved.name)
                self.session.require_state_queries(self.body, self.resolved.name)
                self._read()
                self.findings = self._check(packages, package_paths, xacro_args)
            except BaseException:
                self.depends = dict(recorded)
                self.close()
                raise
        self.depends = dict(recorded)

    # ------------------------------------------------------------------ reading

    def _read(self) -> None:
        from .inspect import base_link_name, joint_table
        from .session import quiet_stdout

        s, body = self.session, self.body
        p, c = s.p, s.client
        with quiet_stdout() as out:
            self.table = joint_table(s, body, self.resolved.root)
            names = [base_link_name(s, body)] + [j.link_name for j in self.table]
            self.links = [LinkView(i, names[i + 1]) for i in range(-1, len(self.table))]
            for link in self.links:
                info = p.getDynamicsInfo(body, link.index, physicsClientId=c)
                link.mass = float(info[0])
                link.moments = tuple(float(v) for v in info[2])  # type: ignore[assignment]
                link.inertial_pos = tuple(float(v) for v in info[3])  # type: ignore[assignment]
                link.inertial_quat = tuple(float(v) for v in info[4])  # type: ignore[assignment]
            for v in p.getVisualShapeData(body, physicsClientId=c):
                shape = self._shape(v[2], v[3], v[4], v[5], v[6], collision=False,
                                    rgba=v[7])
                if shape is not None:
                    self.links[v[1] + 1].visuals.append(shape)
            concave = self._concave()
            for link in self.links:
                for v in p.getCollisionShapeData(body, link.index, physicsClientId=c):
                    # Relative to the inertial frame: move it into the link frame.
                    pos, quat = p.multiplyTransforms(link.inertial_pos, link.inertial_quat,
                                                     v[5], v[6])
                    shape = self._shape(v[2], v[3], v[4], pos, quat, collision=True,
                                        concave=link.name in concave)
                    if shape is not None:
                        link.collisions.append(shape)
        self.session.diagnostics.extend(out.lines)
        self.joints = self._controls()
        self.notes.extend(self.resolved.warnings)

    def _shape(self, kind: int, dims: Sequence[float], filename: bytes,
               pos: Sequence[float], quat: Sequence[float], *, collision: bool,
               rgba: Sequence[float] = (1.0, 1.0, 1.0, 1.0), concave: bool = False
               ) -> Shape | None:
        import numpy as np

        note = ""
        if kind == _MESH:
            name = filename.decode("utf-8", "replace") if isinstance(filename, bytes) \
                else str(filename)
            if not name:  # a cylinder PyBullet made a mesh of: nothing to read back
                return None
            mesh = read_mesh(name)
            if mesh is None:
                self.notes.append(f"cannot read mesh {name}: not drawn")
                return None
            vertices = np.asarray(mesh[0], dtype=float) * np.asarray(dims[:3], dtype=float)
            faces = np.asarray(mesh[1], dtype=np.int64)
            kind_name = "mesh"
            if collision:  # what PyBullet collides with: the hull (urdfkit.displaymesh)
                from .displaymesh import HULL_POINTS, convex_hull

                hull = convex_hull(vertices)
                if hull is not None:
                    thinned = len(vertices) > HULL_POINTS
                    vertices, faces = hull
                    note = ("convex hull of a concave mesh" if concave else "convex hull") + \
                        (" (of its points thinned on a grid, for display)" if thinned else "")
            elif len(faces) > MAX_DISPLAY_FACES:
                from .displaymesh import decimate

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
        from .collisions import _concave_links

        try:
            return _concave_links(self.resolved, None)
        except UrdfkitError:
            return set()

    def _controls(self) -> list[JointControl]:
        from .spec import vector

        elements = {j.get("name"): j for j in self.resolved.root.iterchildren("joint")}
        out = []
        for j in self.table:
            if j.joint_type not in ("REVOLUTE", "PRISMATIC"):
                continue
            kind = j.urdf_type or j.joint_type.lower()
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
                                    float(upper), tuple(float(a) for a in j.joint_axis),  # type: ignore[arg-type]
                                    j.joint_index, mimic))
        names = {jc.name for jc in out}
        for jc in out:  # a mimic of a joint that cannot move is just a joint
            if jc.mimic is not None and jc.mimic[0] not in names:
                jc.mimic = None
        return out

    def _check(self, packages: Sequence[str] | None, package_paths: Sequence[str] | None,
               xacro_args: Sequence[str] | None) -> list[Finding]:
        """Run ``check`` on the file and tint the links its findings are about."""
        from .check import check_file
        from .uris import parse_packages

        args: dict[str, str] = {}
        if xacro_args:
            from .catalog import parse_assignments

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
        from .xmlio import line_of

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
        """Set joints by name with ``resetJointState``; mimic joints follow their leader.

        Returns every movable joint's position as PyBullet now reports it.
        """
        with self.lock:
            p, c = self.session.p, self.session.client
            by_name = {j.name: j for j in self.joints}
            wanted = {k: float(v) for k, v in values.items() if k in by_name}
            for name, value in wanted.items():
                if by_name[name].mimic is None:
                    p.resetJointState(self.body, by_name[name].index, value, physicsClientId=c)
            now = self.positions()
            for j in self.joints:  # leaders first in a chain: index order is depth order
                if j.mimic is not None and j.mimic[0] in now:
                    value = now[j.mimic[0]] * j.mimic[1] + j.mimic[2]
                    p.resetJointState(self.body, j.index, value, physicsClientId=c)
                    now[j.name] = value
            return self.positions()

    def positions(self) -> dict[str, float]:
        """Every movable joint's position, read from PyBullet (``getJointState``)."""
        with self.lock:
            p, c = self.session.p, self.session.client
            return {j.name: float(p.getJointState(self.body, j.index, physicsClientId=c)[0])
                    for j in self.joints}

    def link_poses(self) -> list[tuple[Vec3, Quat]]:
        """World pose of every URDF link frame, base first, as PyBullet reports it."""
        with self.lock:
            p, c = self.session.p, self.session.client
            pos, orn = p.getBasePositionAndOrientation(self.body, physicsClientId=c)
            base = self.links[0]
            inv = p.invertTransform(base.inertial_pos, base.inertial_quat)
            out = [p.multiplyTransforms(pos, orn, inv[0], inv[1])]
            for link in self.links[1:]:
                state = p.getLinkState(self.body, link.index, computeForwardKinematics=1,
                                       physicsClientId=c)
                out.append((state[4], state[5]))
            return [(tuple(float(x) for x in a), tuple(float(x) for x in b))  # type: ignore[misc]
                    for a, b in out]

    def bounds(self) -> tuple[Vec3, Vec3]:
        """The posed robot's box (union of getAABB over links), for the camera."""
        with self.lock:
            p, c = self.session.p, self.session.client
            lo, hi = [math.inf] * 3, [-math.inf] * 3
            for link in self.links:
                a, b = p.getAABB(self.body, link.index, physicsClientId=c)
                if all(math.isfinite(x) for x in (*a, *b)) and all(
                        b[k] >= a[k] for k in range(3)):
                    lo = [min(lo[k], a[k]) for k in range(3)]
                    hi = [max(hi[k], b[k]) for k in range(3)]
            if not all(math.isfinite(x) for x in lo + hi):
                return (-0.5, -0.5, -0.5), (0.5, 0.5, 0.5)
            return tuple(lo), tuple(hi)  # type: ignore[return-value]

    def touching(self) -> list[tuple[str, str, float]]:
        """Link pairs touching or interpenetrating at the current pose, as ``collisions`` sees them.

        Measured in a second body loaded with URDF_USE_SELF_COLLISION (without it PyBullet's
        getClosestPoints finds nothing between a body's own links) and pinned, posed like the
        shown one; links joined by a joint are not tested, as in ``urdfkit collisions``.
        Returns (link a, link b, signed distance in m), deepest first.
        """
        with self.lock:
            if self._probe is None:
                self._probe = self._open_probe()
            session, body, pairs = self._probe
            p, c = session.p, session.client
            for j in self.joints:
                p.resetJointState(body, j.index, p.getJointState(
                    self.body, j.index, physicsClientId=self.session.client)[0],
                    physicsClientId=c)
            out = []
            for a, b in pairs:
                points = p.getClosestPoints(body, body, 0.0, a, b, physicsClientId=c)
                if points:
                    out.append((self.links[a + 1].name, self.links[b + 1].name,
                                float(min(pt[8] for pt in points))))
            return sorted(out, key=lambda x: x[2])

    def _open_probe(self) -> tuple[Any, int, list[tuple[int, int]]]:
        from .session import LoadOptions, Session

        session = Session()
        try:
            body = session.load_urdf(self.resolved.load_path, LoadOptions(
                fixed_base=True, self_collision=True), display=self.resolved.name)
        except BaseException:
            session.close()
            raise
        shaped = [lk.index for lk in self.links if lk.collisions]
        parent = {j.joint_index: j.parent_index for j in self.table}
        pairs = [(a, b) for k, a in enumerate(shaped) for b in shaped[k + 1:]
                 if parent.get(b) != a and parent.get(a) != b]
        return session, body, pairs

    def joint_vector(self) -> tuple[str, str]:
        """The current joints as a Python list (index order) and as ``--joints`` text."""
        now = self.positions()
        values = [round(now[j.name], 6) for j in self.joints]
        text = ",".join(f"{j.name}={round(now[j.name], 6):g}" for j in self.joints)
        return repr(values), f"--joints {text}" if text else ""

    def close(self) -> None:
        """Disconnect the session and drop the resolved temp copy."""
        if self.session is not None:
            self.session.close()
            self.session = None
        probe = getattr(self, "_probe", None)
        if probe is not None:
            probe[0].close()
            self._probe = None
        resolved = getattr(self, "resolved", None)
        if resolved is not None:
            resolved.close()


#: ``<link name='x'>`` / ``<joint name="x">`` as check's messages name elements.
_NAMED = re.compile(r"<(link|joint) name=(['\"])(.*?)\2>")


def _last_line(el: Any) -> int:
    from .xmlio import line_of

    last = line_of(el) or 0
    for sub in el.iter():
        last = max(last, line_of(sub) or 0)
    return last


def _wxyz(q: Sequence[float]) -> tuple[float, float, float, float]:
    return (float(q[3]), float(q[0]), float(q[1]), float(q[2]))


#: Seconds the web server may take to start. viser waits on its server thread without a time
#: limit, and that thread dies silently on anything but a port in use: a hang, never a
#: message. Bounded here.
SERVER_START_TIMEOUT = 60.0


def _start_server(viser: Any, host: str, port: int) -> Any:
    """``viser.ViserServer``, started in a thread of its own.

    Waited for at most :data:`SERVER_START_TIMEOUT` seconds (TimeoutError past it); its
    errors are re-raised here.
    """
    box: dict[str, Any] = {}

    def start() -> None:
        try:
            with _quiet():  # viser prints a banner with rich whatever `verbose` says
                box["server"] = viser.ViserServer(host=host, port=port, verbose=False)
        except BaseException as e:  # handed to the caller's thread
            box["error"] = e

    thread = threading.Thread(target=start, name="urdfkit-view-start", daemon=True)
    thread.start()
    thread.join(SERVER_START_TIMEOUT)
    if thread.is_alive():
        raise TimeoutError
    if "error" in box:
        raise box["error"]
    return box["server"]


def free_port(host: str) -> int:
    """A TCP port nothing listens on now."""
    import socket

    family = socket.AF_INET6 if ":" in host else socket.AF_INET
    with socket.socket(family, socket.SOCK_STREAM) as sock:
        sock.bind((host, 0))
        return int(sock.getsockname()[1])


class Viewer:
    """A viser server showing a :class:`Model`, reloaded when its files change.

    The server never dies on a bad file: a load that fails keeps the last good robot and shows
    the error in the page (:attr:`error`).

    Attributes:
        model: The robot on show (the last one that loaded).
        error: The last reload's error message, or None.
        url: Where the page is.
        reloads: How many times the robot was reloaded.
    """

    def __init__(self, file: str, *, packages: Sequence[str] | None = None,
                 package_paths: Sequence[str] | None = None,
                 xacro_args: Sequence[str] | None = None, inertia_from_file: bool = False,
                 host: str = "127.0.0.1", port: int | None = None, watch: bool = True,
                 ground: float = 4.0) -> None:
        self._load_args: dict[str, Any] = {
            "packages": packages, "package_paths": package_paths, "xacro_args": xacro_args,
            "inertia_from_file": inertia_from_file}
        self.file = file
        self.model = Model(file, **self._load_args)  # a bad file fails here, before serving
        self.error: str | None = None
        self.reloads = 0
        self._failed: dict[str, Any] | None = None
        self._lock = threading.RLock()
        self._setting = False
        self._nodes: dict[str, list[Any]] = {}
        self._frames: list[Any] = []
        #: The page shows poses given from outside (a run, :meth:`show_poses`): the model's
        #: own joints no longer move the scene, even from a late slider callback.
        self.external_poses = False
        #: More robots on the page (sim --view): each model and its link frames.
        self.extra: list[tuple[Model, list[Any]]] = []
        self._gui: list[Any] = []
        self.sliders: dict[str, Any] = {}
        viser = _viser()
        self.host = host
        self.port = free_port(host) if not port else port
        try:
            self.server = _start_server(viser, host, self.port)
        except OSError as e:
            self.model.close()
            raise EngineError(f"cannot serve on {host}:{self.port}: {e.strerror or e}",
                              param="port") from None
        except TimeoutError:
            self.model.close()
            raise EngineError(f"the server on {host}:{self.port} did not start within "
                              f"{SERVER_START_TIMEOUT:g} s", param="port") from None
        self.port = int(self.server.get_port())
        self.url = f"http://{'localhost' if host in ('127.0.0.1', '::1') else host}:{self.port}"
        self.server.scene.set_up_direction("+z")
        self.server.scene.add_grid("/ground", width=ground, height=ground,
                                   cell_size=0.1 if ground <= 4.0 else 0.5, section_size=1.0)
        self._static_gui()
        self._show_model()
        # Mimic joints to their leaders' zero pose (offsets included). Self-collisions are
        # first measured by the watcher, so their second load does not delay the first draw.
        self.set_joints(self.zero(), touching=False)
        self._aim_camera()
        self._stop = threading.Event()
        # A run on show (drive --view) is not reloaded under it: no watcher then.
        self._watcher = threading.Thread(target=self._watch if watch else lambda: None,
                                         name="urdfkit-view-watch", daemon=True)
        self._watcher.start()

    # ------------------------------------------------------------------ the page

    def _static_gui(self) -> None:
        gui = self.server.gui
        self.status = gui.add_markdown("", order=0)
        with gui.add_folder("Show", order=1):
            self.show_visual = gui.add_checkbox("Visual", True)
            self.show_collision = gui.add_checkbox("Collision", False)
            self.show_frames = gui.add_checkbox("Frames and axes", False)
            self.show_inertia = gui.add_checkbox("COM and inertia boxes", False)
            self.show_touching = gui.add_checkbox(
                "Self-collisions", True, hint="Links touching at this pose, as urdfkit "
                "collisions measures them, in magenta")
            self.touching_text = gui.add_markdown("")
        for box in (self.show_visual, self.show_collision, self.show_frames, self.show_inertia):
            box.on_update(lambda _event: self.apply_toggles())
        self.show_touching.on_update(lambda _event: self.update_touching())
        self.touching: list[tuple[str, str, float]] = []
        self.selected: str | None = None
        with gui.add_folder("Selection", order=1.5):
            self.select_link = gui.add_dropdown(
                "Link", [NO_LINK], initial_value=NO_LINK,
                hint="Or click a link in the scene, or a finding")
            self.selected_text = gui.add_markdown("")
        self.select_link.on_update(lambda _event: self._dropdown_moved())
        self.joints_folder = gui.add_folder("Joints", order=2)
        with self.joints_folder:
            self.reset_button = gui.add_button("Reset to zero")
            self.reset_button.on_click(lambda _event: self.reset())
            self.vector_text = gui.add_text("Python list", "[]", disabled=True)
            self.joints_text = gui.add_text("--joints", "", disabled=True)
        self.findings_folder = gui.add_folder("Findings", order=3)
        self.table_folder = gui.add_folder("Joint table", order=4, expand_by_default=False)

    def _show_model(self) -> None:
        """Put the model's shapes and controls on the page (replacing the previous ones)."""
        import numpy as np

        scene, gui, m = self.server.scene, self.server.gui, self.model
        for h in self._frames + self._gui:  # a link's frame takes its shapes with it
            h.remove()
        self._nodes = {"visual": [], "collision": [], "frames": [], "inertia": []}
        self._frames, self._gui, self.sliders = [], [], {}
        poses = m.link_poses()
        size = max(max(hi - lo for lo, hi in zip(*m.bounds(), strict=True)), 0.05)
        by_index = {j.link: j for j in m.joints}
        for link, (pos, quat) in zip(m.links, poses, strict=True):
            root = f"/robot/link{link.index + 1}"
            frame = scene.add_frame(root, show_axes=False, position=pos, wxyz=_wxyz(quat))
            self._frames.append(frame)
            tint = TINTS.get(link.level or "")
            for kind, shapes in (("visual", link.visuals), ("collision", link.collisions)):
                for k, sh in enumerate(shapes):
                    mesh = scene.add_mesh_simple(
                        f"{root}/{kind}{k}", sh.vertices, sh.faces, color=tint or sh.rgb,
                        opacity=None if sh.opacity >= 1 else sh.opacity,
                        # No shadow pass: it doubles the first draw in software WebGL.
                        cast_shadow=False, receive_shadow=False,
                        position=sh.pos, wxyz=_wxyz(sh.quat))
                    # Clicking a link in the scene selects it (and its joint's row).
                    mesh.on_click(lambda _event, name=link.name: self.select(name))
                    self._nodes[kind].append(mesh)
            self._nodes["frames"].append(scene.add_frame(
                f"{root}/axes", axes_length=size * 0.08, axes_radius=size * 0.004))
            joint = by_index.get(link.index)
            if joint is not None:  # PyBullet's axis is in the inertial frame: into the link's
                from .spec import quat_to_matrix, rotate

                axis = np.asarray(rotate(quat_to_matrix(link.inertial_quat), joint.axis),
                                  dtype=float)
                points = np.array([[-axis, axis]], dtype=np.float32) * size * 0.1
                self._nodes["frames"].append(scene.add_line_segments(
                    f"{root}/joint_axis", points, (204, 121, 167), thickness=size * 0.006))
            com = scene.add_frame(f"{root}/com", show_axes=False, position=link.inertial_pos,
                                  wxyz=_wxyz(link.inertial_quat))
            self._nodes["inertia"].append(com)
            self._nodes["inertia"].append(scene.add_icosphere(
                f"{root}/com/dot", radius=size * 0.012, color=(20, 20, 20)))
            box = link.inertia_box
            if box is not None:
                self._nodes["inertia"].append(scene.add_box(
                    f"{root}/com/box", dimensions=box, color=(0, 114, 178), opacity=0.35))
        self.apply_toggles()
        listed, flags = m.joint_vector()
        self.vector_text.value, self.joints_text.value = listed, flags
        now = m.positions()
        with self.joints_folder:
            for j in m.joints:
                step = (j.upper - j.lower) / 1000 if j.upper > j.lower else 0.001
                hint = f"{j.urdf_type}, PyBullet joint {j.index}"
                if j.mimic is not None:
                    hint += f"; mimics {j.mimic[0]} x {j.mimic[1]:g} + {j.mimic[2]:g}"
                s = gui.add_slider(j.name, min=j.lower, max=max(j.upper, j.lower + step),
                                   step=step, initial_value=min(max(now[j.name], j.lower), j.upper),
                                   disabled=j.mimic is not None, hint=hint)
                s.on_update(lambda _event, name=j.name: self._slider_moved(name))
                self.sliders[j.name] = s
                self._gui.append(s)
        with self.findings_folder:
            self._gui.append(gui.add_markdown(self._findings_text()))
            # One button per finding on a link: clicking it selects that link.
            for f in (f for f in m.findings if f.level in TINTS):
                links = m.finding_links(f)
                if not links:
                    continue
                where = f"line {f.line}" if f.line is not None else f.file
                button = gui.add_button(f"{f.code} {where}: {links[0]}",
                                        hint=f.text[:300])
                button.on_click(lambda _event, name=links[0]: self.select(name))
                self._gui.append(button)
        names = [lk.name for lk in m.links]
        self.select_link.options = [NO_LINK, *names]
        if self.selected not in names:
            self.selected = None
        self.select(self.selected)
        with self.table_folder:
            self._gui.append(gui.add_markdown(self._table_text()))
        self._refresh_status()

    def _findings_text(self) -> str:
        m = self.model
        shown = [f for f in m.findings if f.level in ("error", "warning")]
        lines = []
        for f in shown:
            where = f.file if f.line is None else f"{f.file}:{f.line}"
            links = ", ".join(m.finding_links(f))
            lines.append(f"- **{f.level} {f.code}** `{where}`{' (' + links + ')' if links else ''}"
                         f": {_md(f.text)}")
        hidden = len(m.findings) - len(shown)
        if hidden:
            lines.append(f"- and {hidden} note(s): `urdfkit check {m.file}`")
        lines += [f"- note: {_md(n)}" for n in m.notes]
        return "\n".join(lines) or "No errors or warnings."

    def _table_text(self) -> str:
        rows = ["| # | joint | type | child | limits |", "|---|---|---|---|---|"]
        for j in self.model.table:
            limits = f"{j.joint_lower_limit:g} .. {j.joint_upper_limit:g}" if j.limited else ""
            rows.append(f"| {j.joint_index} | {_md(j.joint_name)} | {j.type_label} | "
                        f"{_md(j.link_name)} | {limits} |")
        return "\n".join(rows)

    def _refresh_status(self) -> None:
        m = self.model
        head = f"**{_md(m.resolved.robot_name or m.file)}**: {len(m.links)} links, " \
               f"{len(m.joints)} movable joints"
        self.status.content = head if self.error is None else \
            f"{head}\n\n**Reload failed**, showing the last good robot: {_md(self.error)}"

    def _aim_camera(self) -> None:
        lo, hi = self.model.bounds()
        mid = [(a + b) / 2 for a, b in zip(lo, hi, strict=True)]
        size = max(max(b - a for a, b in zip(lo, hi, strict=True)), 0.1)
        cam = self.server.initial_camera
        cam.look_at = tuple(mid)
        cam.position = (mid[0] + 1.3 * size, mid[1] - 1.3 * size, mid[2] + 0.9 * size)

    def apply_toggles(self) -> None:
        """Show or hide each layer as the Show checkboxes say."""
        with self._lock:
            want = {"visual": self.show_visual.value, "collision": self.show_collision.value,
                    "frames": self.show_frames.value, "inertia": self.show_inertia.value}
            for kind, handles in self._nodes.items():
                for h in handles:
                    h.visible = bool(want[kind])

    def visible(self, kind: str) -> bool:
        """Whether a layer (visual, collision, frames, inertia) is shown."""
        handles = self._nodes.get(kind, [])
        return bool(handles) and all(h.visible for h in handles)

    # ------------------------------------------------------------------ moving

    def _slider_moved(self, name: str) -> None:
        if self._setting:
            return
        self.set_joints({name: float(self.sliders[name].value)})

    def set_joints(self, values: Mapping[str, float], touching: bool = True
                   ) -> dict[str, float]:
        """Move joints (by name) in PyBullet and update the scene; return the new positions.

        ``touching=False`` leaves the self-collision highlight as it was.
        """
        with self._lock:
            now = self.model.set_positions(values)
            self._setting = True
            try:
                for name, value in now.items():
                    s = self.sliders.get(name)
                    if s is not None and abs(float(s.value) - value) > 1e-12:
                        s.value = value
            finally:
                self._setting = False
            self.update_poses()
            if touching:
                self.update_touching()
            listed, flags = self.model.joint_vector()
            self.vector_text.value = listed
            self.joints_text.value = flags
            return now

    def update_poses(self) -> None:
        """Move every link node to the pose PyBullet reports (not while a run is shown)."""
        if self.external_poses:
            return
        with self._lock, self.server.atomic():
            for frame, (pos, quat) in zip(self._frames, self.model.link_poses(), strict=True):
                frame.position = pos
                frame.wxyz = _wxyz(quat)

    def _recolour(self) -> None:
        """Each link's colour: selected, else touching, else its findings' tint, else its own."""
        with self._lock:
            hit = {name for a, b, _ in self.touching for name in (a, b)}
            for link, k in zip(self.model.links, range(len(self.model.links)), strict=True):
                base = TINTS.get(link.level or "")
                for kind, shapes in (("visual", link.visuals), ("collision", link.collisions)):
                    handles = [h for h in self._nodes.get(kind, [])
                               if h.name.startswith(f"/robot/link{k}/")]
                    for h, sh in zip(handles, shapes, strict=True):
                        want = SELECTED_RGB if link.name == self.selected else \
                            TOUCHING_RGB if link.name in hit else (base or sh.rgb)
                        if tuple(h.color) != tuple(want):
                            h.color = want

    def _dropdown_moved(self) -> None:
        if self._setting:
            return
        value = str(self.select_link.value)
        self.select(None if value == NO_LINK else value)

    def select(self, link: str | None) -> None:
        """Select a link (None: none): highlight it, show its joint's row and its findings.

        Clicking the link in the scene, choosing it in the Selection dropdown, or clicking a
        finding about it all come here.
        """
        with self._lock:
            m = self.model
            if link is not None and link not in {lk.name for lk in m.links}:
                raise KeyError(link)
            self.selected = link
            self._setting = True
            try:
                want = NO_LINK if link is None else link
                if self.select_link.value != want:
                    self.select_link.value = want
            finally:
                self._setting = False
            self._recolour()
            if link is None:
                self.selected_text.content = ""
                return
            row = next((j for j in m.table if j.link_name == link), None)
            lines = [f"**{_md(link)}**: " + (
                "the base" if row is None else
                f"child of joint {row.joint_index} **{_md(row.joint_name)}** "
                f"({row.type_label}"
                + (f", {row.joint_lower_limit:g} .. {row.joint_upper_limit:g}"
                   if row.limited else "") + f"), parent {_md(row.parent_link_name)}")]
            view = next(lk for lk in m.links if lk.name == link)
            lines.append(f"mass {view.mass:g} kg")
            for f in m.findings:
                if f.level in TINTS and link in m.finding_links(f):
                    where = f.file if f.line is None else f"{f.file}:{f.line}"
                    lines.append(f"- **{f.level} {f.code}** `{where}`: {_md(f.text)}")
            self.selected_text.content = "\n\n".join(lines[:2]) + (
                "\n\n" + "\n".join(lines[2:]) if lines[2:] else "")

    def update_touching(self) -> None:
        """Measure the touching pairs (when shown) and colour their links magenta."""
        with self._lock:
            self.touching = self.model.touching() if self.show_touching.value else []
            self._recolour()
            self.touching_text.content = "\n".join(
                f"- touching: {_md(a)} and {_md(b)} "
                f"({'by' if d < 0 else 'at'} {abs(d) * 1000:.3g} mm)"
                for a, b, d in self.touching)

    def zero(self) -> dict[str, float]:
        """Every joint at zero, or at its nearest limit when zero is outside them."""
        return {j.name: min(max(0.0, j.lower), j.upper) for j in self.model.joints}

    def reset(self) -> None:
        """Every joint to :meth:`zero`."""
        self.set_joints(self.zero())

    def link_pose(self, name: str) -> tuple[Vec3, tuple[float, float, float, float]]:
        """A link node's pose in the scene: (position, wxyz)."""
        for link, frame in zip(self.model.links, self._frames, strict=True):
            if link.name == name:
                return (tuple(float(x) for x in frame.position),  # type: ignore[return-value]
                        tuple(float(x) for x in frame.wxyz))
        raise KeyError(name)

    def add_robot(self, file: str, *, inertia_from_file: bool = False) -> int:
        """Draw one more robot (its visual and collision shapes, no controls); its number.

        For a scenario of several robots (``sim --view``): robot 0 is :attr:`model`, the
        others come here, and :meth:`show_poses` places each.
        """
        m = Model(file, inertia_from_file=inertia_from_file)
        k = len(self.extra) + 1
        scene, frames = self.server.scene, []
        with self._lock:
            for link, (pos, quat) in zip(m.links, m.link_poses(), strict=True):
                root = f"/robot{k}/link{link.index + 1}"
                frames.append(scene.add_frame(root, show_axes=False, position=pos,
                                              wxyz=_wxyz(quat)))
                for kind, shapes in (("visual", link.visuals), ("collision", link.collisions)):
                    for n, sh in enumerate(shapes):
                        self._nodes[kind].append(scene.add_mesh_simple(
                            f"{root}/{kind}{n}", sh.vertices, sh.faces, color=sh.rgb,
                            opacity=None if sh.opacity >= 1 else sh.opacity,
                            cast_shadow=False, receive_shadow=False, position=sh.pos,
                            wxyz=_wxyz(sh.quat)))
            self.extra.append((m, frames))
            self.apply_toggles()
        return k

    def show_poses(self, poses: Sequence[tuple[Sequence[float], Sequence[float]]],
                   robot: int = 0) -> None:
        """Put every link node of a robot at a world pose (``(xyz, xyzw)``, base first).

        For a run simulated elsewhere (``drive --view``, ``sim --view``): the poses come from
        that session, not from this viewer's models. ``robot`` 0 is :attr:`model`; others
        were added with :meth:`add_robot`.
        """
        self.external_poses = True
        frames = self._frames if robot == 0 else self.extra[robot - 1][1]
        if len(poses) != len(frames):
            raise EngineError(f"the run has {len(poses)} links, the view {len(frames)}")
        with self._lock, self.server.atomic():
            for frame, (pos, quat) in zip(frames, poses, strict=True):
                frame.position = tuple(float(x) for x in pos)
                frame.wxyz = _wxyz(quat)

    def robot_pose(self, robot: int, link: int = 0) -> tuple[Vec3, tuple[float, ...]]:
        """A link node's pose in the scene, by robot number and link position (base 0)."""
        frame = (self._frames if robot == 0 else self.extra[robot - 1][1])[link]
        return (tuple(float(x) for x in frame.position),  # type: ignore[return-value]
                tuple(float(x) for x in frame.wxyz))

    def nodes(self, kind: str, link: str) -> list[Any]:
        """The scene handles of one layer of one link (for tests and tools)."""
        index = next(i for i, lk in enumerate(self.model.links) if lk.name == link)
        prefix = f"/robot/link{index}/"
        return [h for h in self._nodes.get(kind, []) if h.name.startswith(prefix)]

    # ------------------------------------------------------------------ reloading

    def _watch(self) -> None:
        from . import deps

        try:
            self.update_touching()
        except Exception as e:  # noqa: BLE001 - the server outlives a probe that fails
            self.error = f"self-collisions not measured: {e}"
            self._refresh_status()
        while not self._stop.wait(POLL_SECONDS):
            recorded = self._failed if self._failed is not None else self.model.depends
            try:
                if deps.unchanged(recorded):
                    continue
                self.reload()
            except Exception as e:  # noqa: BLE001 - the server outlives any bad file
                self.error = f"{type(e).__name__}: {e}"
                self._refresh_status()

    def reload(self) -> bool:
        """Load the file again; on success show it, keeping joint values by name.

        Returns whether the new robot is on show. A failure keeps the old one and sets
        :attr:`error`; the next change of any file tried is retried.
        """
        from . import deps

        kept = self.model.positions()
        try:
            model = Model(self.file, **self._load_args)
        except Exception as e:  # noqa: BLE001 - any failure keeps the last good robot
            self.error = str(e) if isinstance(e, UrdfkitError) else \
                f"internal error (a bug in urdfkit): {type(e).__name__}: {e}"
            # Not retried until a file changes again: a bad file is not loaded 4 times a second.
            with deps.record() as recorded:  # what the failed attempt depends on
                deps.note(self.file)
                for path in self.model.depends:
                    deps.note(path)
            self._failed = recorded
            self._refresh_status()
            return False
        with self._lock:
            old, self.model = self.model, model
            self._failed = None
            self.error = None
            self.reloads += 1
            self._show_model()
            old.close()
            self.set_joints({k: v for k, v in kept.items()
                             if k in {j.name for j in model.joints}})
        return True

    def close(self) -> None:
        """Stop watching and serving, and disconnect PyBullet."""
        self._stop.set()
        self._watcher.join(timeout=5)
        with _quiet():
            self.server.stop()
        self.model.close()
        for m, _ in self.extra:
            m.close()


#: Frames pushed to the page per second of wall time, at most, while a run streams.
STREAM_FPS = 30.0
#: Points of a run's path kept on the page (halved by dropping every other one past this).
PATH_POINTS = 2000


class RunStream:
    """Stream a simulated run to a :class:`Viewer`: link poses, the path, then the summary.

    Use it as the run's ``sink`` (called with each trajectory sample): it paces the run to
    ``speed`` times real time (``None``: as fast as it goes), pushes the robot's link poses,
    read from the run's own PyBullet session, at most :data:`STREAM_FPS` times a second of
    wall time, and draws the base's path on the ground.

    Args:
        viewer: The page (loaded from the same file as the run; more robots added with
            :meth:`Viewer.add_robot`).
        poses: Returns every link's world pose in the run's session, base first: one list,
            or (``robots=True``) a list of them, one per robot in the viewer's order.
        speed: Simulated seconds per wall second; None for no pacing.
        total: The run's simulated duration (for the status line).
        robots: ``poses`` gives one list per robot.
    """

    def __init__(self, viewer: Viewer, poses: Any, speed: float | None,
                 total: float, robots: bool = False) -> None:
        import time

        self.viewer, self.speed, self.total = viewer, speed, total
        self.poses = poses if robots else (lambda: [poses()])
        self.path: list[tuple[float, float, float]] = []
        #: Each robot's base path, sampled as frames are pushed (:meth:`tick`).
        self.paths: list[list[tuple[float, float, float]]] = []
        self.frames = 0
        self._clock = time.perf_counter
        self._sleep = time.sleep
        self._start = self._clock()
        self._last = -1.0
        self._stride = 1
        self._seen = 0
        viewer.status.content = f"**Running**: 0.0 of {total:g} s simulated"
        # The page shows the run, not the model's own joints: its controls would fight it.
        for control in (*viewer.sliders.values(), viewer.reset_button):
            control.disabled = True

    def __call__(self, row: Sequence[float]) -> None:
        """Take one drive sample ``(t, x, y, z, ...)``: pace, record, maybe push."""
        t = float(row[0])
        self._seen += 1
        if self._seen % self._stride == 0:
            self.path.append((float(row[1]), float(row[2]), float(row[3])))
            if len(self.path) > PATH_POINTS:
                self.path = self.path[::2]
                self._stride *= 2
        self.tick(t)

    def tick(self, t: float) -> None:
        """The run is at simulated time ``t``: wait for the wall clock (paced), maybe push."""
        if self.speed is not None:
            ahead = self._start + t / self.speed - self._clock()
            if ahead > 0:
                self._sleep(ahead)
        now = self._clock()
        if now - self._last >= 1.0 / STREAM_FPS:
            self._last = now
            self.push(f"**Running**: {t:.1f} of {self.total:g} s simulated")

    def push(self, status: str | None = None) -> None:
        """Show the run's current pose and path now."""
        import numpy as np

        every = self.poses()
        for k, poses in enumerate(every):
            self.viewer.show_poses(poses, robot=k)
        self.frames += 1
        paths = [self.path]
        if not self._seen:  # not fed drive samples: each robot's path from its base poses
            while len(self.paths) < len(every):
                self.paths.append([])
            for path, poses in zip(self.paths, every, strict=False):
                path.append(tuple(float(x) for x in poses[0][0]))  # type: ignore[arg-type]
                if len(path) > PATH_POINTS:
                    path[:] = path[::2]
            paths = self.paths
        for k, path in enumerate(paths):
            if len(path) < 2:
                continue
            pts = np.asarray(path, dtype=np.float32)
            pts[:, 2] = 0.002  # on the ground, not at the base's height
            segments = np.stack([pts[:-1], pts[1:]], axis=1)
            self.viewer.server.scene.add_line_segments(
                f"/run/path{k or ''}", segments, (230, 97, 0), thickness=3.0,
                thickness_units="screen")
        if status is not None:
            self.viewer.status.content = status

    def finish(self, summary: str) -> None:
        """The final pose and path, and the run's summary in the page."""
        self.push(summary)


def _quiet() -> Any:
    """Keep what viser prints on sys.stdout (its banner, "Server stopped") off ours."""
    import contextlib
    import io

    return contextlib.redirect_stdout(io.StringIO())


def _md(text: str) -> str:
    """Text safe inside markdown (no tables or emphasis broken by names)."""
    return re.sub(r"([\\`*_|<>\[\]])", r"\\\1", text)
