"""URDF to MJCF: the robot PyBullet simulates, written for MuJoCo (no mujoco import here).

One body per link that moves (and the root); fixed links fused into their parent body, each
kept as a ``<site>`` named after it at its frame; masses, centres of mass and full inertia
tensors combined exactly; joints named, ordered and limited as PyBullet loads them; meshes
copied, or converted by urdfkit's own readers when MuJoCo cannot read them (COLLADA, ASCII
STL), into a folder beside the XML. Numbers are written with ``repr``: every double round-trips.
What is dropped or approximated is said in :attr:`Export.notes` (docs/export.md lists it all).
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, Any

from urdfkit.core.errors import InputError, ParameterError
from urdfkit.formats.fk import fused, origin_matrix
from urdfkit.formats.mjcf_mesh import MeshAsset, mesh_asset, unusable
from urdfkit.formats.robot import LoadedInertial, LoadedJoint, LoadedLink, LoadedRobot, LoadedShape

if TYPE_CHECKING:
    from lxml import etree

#: ``--actuators`` choices.
ACTUATORS = ("motor", "position", "velocity", "none")
#: Default gains: position kp (N m/rad), velocity kv (N m s/rad).
DEFAULT_GAIN = {"position": 100.0, "velocity": 1.0}
#: Collision bitmasks. Robot geoms have contype 2 / conaffinity 1: two robot geoms never
#: collide ((2 & 1) | (2 & 1) == 0), as PyBullet's default load has no self-collision, while
#: anything with MuJoCo's default 1/1 (and the --ground plane, 1/2) still meets them.
ROBOT_CONTYPE, ROBOT_CONAFFINITY = 2, 1
SELF_CONTYPE, SELF_CONAFFINITY = 3, 3
GROUND_CONTYPE, GROUND_CONAFFINITY = 1, 2
VISUAL_GROUP, COLLISION_GROUP = 2, 3


@dataclass
class ExportOptions:
    """What to write.

    Attributes:
        fixed_base: Weld the root to the world (``useFixedBase``); else a free joint, unless
            the root's own mass is 0, which PyBullet fixes in place.
        self_collision: Let the robot's links collide (``URDF_USE_SELF_COLLISION``).
        actuators: One of :data:`ACTUATORS`.
        gain: kp (position) or kv (velocity) actuators' gain; None for the default.
        ground: Add a plane and a light.
        inertials: Link mass properties to write instead of the file's: PyBullet's own
            (:func:`urdfkit.exchange.bullet.loaded_inertials`), which the command passes. A
            tensor with products of inertia PyBullet diagonalises with Bullet's Jacobi
            sweeps, which leave it up to ~1e-8 relative from the file's (panda_link1: 8.2e-9).
        inertia_from_shapes: Those are PyBullet's recomputation from the collision shapes
            (no notes about links without ``<inertial>``).
        repairs: For each link PyBullet simulates with a singular tensor (zeroed for breaking
            the triangle inequality, or so in the file), what ``urdfkit fix`` writes for it:
            its mass properties, the ``<inertia>`` element, how it was made and why
            (:func:`urdfkit.exchange.bullet.zeroed_repairs`). Written only where the zero
            would leave a moving body MuJoCo refuses; each such link is said and listed.
        geom_names: Name every geom ``g0``, ``g1`` ... and say in :attr:`Export.geom_links`
            which link each comes from (an engine maps contacts back to links with it; a
            fused body holds the geoms of several links).
    """

    fixed_base: bool = False
    self_collision: bool = False
    actuators: str = "motor"
    gain: float | None = None
    ground: bool = False
    inertials: dict[str, LoadedInertial] | None = None
    inertia_from_shapes: bool = False
    repairs: dict[str, tuple[LoadedInertial, str, str, str]] | None = None
    geom_names: bool = False


@dataclass
class Note:
    """One thing dropped, approximated or defaulted on the way to MuJoCo."""

    kind: str        # default, dropped, converted, approximated, mirrored, repaired
    message: str
    line: int | None = None


@dataclass
class Export:
    """An MJCF document and the mesh files it needs.

    Attributes:
        xml: The document.
        assets: File name in the assets folder -> bytes to write, or a Path to copy. Names
            are content-addressed (``stem_<8 hex of SHA-256>.stl``): ``digests`` holds each.
        asset_dir: The assets folder's name (beside the XML, the compiler's meshdir).
        notes: What was dropped, approximated or defaulted.
        bodies, sites: Link names written as bodies / as sites.
        geom_links: With :attr:`ExportOptions.geom_names`, each geom's name and its link.
    """

    xml: bytes
    assets: dict[str, bytes | Path]
    asset_dir: str
    notes: list[Note] = field(default_factory=list)
    bodies: list[str] = field(default_factory=list)
    sites: list[str] = field(default_factory=list)
    paths: list[str] = field(default_factory=list)   # filled by write_export
    repaired: list[str] = field(default_factory=list)   # links given fix's tensor
    digests: dict[str, str] = field(default_factory=dict)   # asset name -> SHA-256 (hex)
    geom_links: dict[str, str] = field(default_factory=dict)


def num(x: float) -> str:
    """A float that reads back to the same double (``-0`` written as ``0``)."""
    x = float(x)
    if x == 0:
        return "0"
    text = repr(x)
    return text[:-2] if text.endswith(".0") else text


def nums(v: Any) -> str:
    """Numbers separated by spaces."""
    return " ".join(num(x) for x in v)


def mat_to_quat(m: Any) -> tuple[float, float, float, float]:
    """A rotation matrix's quaternion (w, x, y, z), MuJoCo's order (Shepperd's method)."""
    tr = m[0][0] + m[1][1] + m[2][2]
    if tr > 0:
        s = math.sqrt(tr + 1.0) * 2
        q = (0.25 * s, (m[2][1] - m[1][2]) / s, (m[0][2] - m[2][0]) / s, (m[1][0] - m[0][1]) / s)
    elif m[0][0] > m[1][1] and m[0][0] > m[2][2]:
        s = math.sqrt(1.0 + m[0][0] - m[1][1] - m[2][2]) * 2
        q = ((m[2][1] - m[1][2]) / s, 0.25 * s, (m[0][1] + m[1][0]) / s, (m[0][2] + m[2][0]) / s)
    elif m[1][1] > m[2][2]:
        s = math.sqrt(1.0 + m[1][1] - m[0][0] - m[2][2]) * 2
        q = ((m[0][2] - m[2][0]) / s, (m[0][1] + m[1][0]) / s, 0.25 * s, (m[1][2] + m[2][1]) / s)
    else:
        s = math.sqrt(1.0 + m[2][2] - m[0][0] - m[1][1]) * 2
        q = ((m[1][0] - m[0][1]) / s, (m[0][2] + m[2][0]) / s, (m[1][2] + m[2][1]) / s, 0.25 * s)
    return (float(q[0]), float(q[1]), float(q[2]), float(q[3]))


def _place(el: etree._Element, t: Any) -> None:
    """Set ``pos`` and ``quat`` of ``el`` from a 4x4 transform (left out when identity)."""
    if any(t[:3, 3]):
        el.set("pos", nums(t[:3, 3]))
    q = mat_to_quat(t[:3, :3])
    if q != (1.0, 0.0, 0.0, 0.0):
        el.set("quat", nums(q))


@dataclass
class _Mass:
    mass: float
    com: Any
    tensor: Any


def combine(parts: list[tuple[LoadedInertial, Any]]) -> _Mass:
    """Mass properties of rigidly joined links: (inertial, link frame in the body) each.

    Each link's centre and tensor are placed in the body's axes, then joined by
    :func:`urdfkit.model.massprops.combine` (the parallel-axis theorem).
    """
    import numpy as np

    from urdfkit.model.massprops import combine as join

    with np.errstate(all="ignore"):  # huge values overflow: check_mass refuses the result
        placed = []
        for i, t in parts:
            r = t[:3, :3]
            com = r @ np.array(i.com) + t[:3, 3]
            tensor = r @ np.array(i.tensor) @ r.T
            placed.append((i.mass, com.tolist(), tensor.tolist()))
    total = join(placed)
    return _Mass(float(total.mass), np.array(total.com), np.array(total.tensor))


class _Writer:
    """Builds one document; see :func:`export_mjcf`."""

    def __init__(self, robot: LoadedRobot, options: ExportOptions, asset_dir: str) -> None:
        from lxml import etree

        self.E = etree
        self.robot = robot
        self.o = options
        self.asset_dir = asset_dir
        self.notes: list[Note] = []
        self.assets: dict[str, bytes | Path] = {}
        self.meshes: dict[tuple[str, tuple[float, ...]], str] = {}
        self.mesh_files: dict[str, MeshAsset | None] = {}
        self.mesh_names: dict[str, str] = {}
        self.digests: dict[str, str] = {}
        self.uses: dict[tuple[str, tuple[float, float, float], bool], str | None] = {}
        self.bodies: list[str] = []
        self.sites: list[str] = []
        self.members: dict[str, list[str]] = {}
        self.locked: list[Any] = []
        self.repaired: list[str] = []
        self.geom_links: dict[str, str] = {}
        self.root = etree.Element("mujoco", model=robot.name or "robot")
        self.compiler = etree.SubElement(self.root, "compiler", angle="radian",
                                         meshdir=asset_dir, autolimits="true")
        etree.SubElement(self.root, "option", integrator="implicitfast")
        self.asset = etree.SubElement(self.root, "asset")
        self.world = etree.SubElement(self.root, "worldbody")

    def note(self, kind: str, message: str, line: int | None = None) -> None:
        self.notes.append(Note(kind, message, line))

    def inertial(self, link: LoadedLink) -> LoadedInertial:
        if link.name in self.repaired and self.o.repairs:
            return self.o.repairs[link.name][0]
        if self.o.inertials is not None and link.name in self.o.inertials:
            return self.o.inertials[link.name]
        return link.inertial

    # ------------------------------------------------------------------ meshes

    def mesh(self, shape: LoadedShape, visual: bool, link: LoadedLink) -> str | None:
        """The asset name of a mesh shape (added on first use), None when it is left out."""
        assert shape.filename is not None
        asset = self.mesh_file(Path(shape.filename), shape.line)
        if asset is None:
            return None
        scale = (shape.scale[0], shape.scale[1], shape.scale[2])
        use = (shape.filename, scale, not visual)
        if use not in self.uses:
            self.uses[use] = unusable(asset, scale, collides=not visual)
        why = self.uses[use]
        if why is not None:
            self.note("dropped", f"{'visual' if visual else 'collision'} of link "
                      f"{link.name!r}: mesh {Path(shape.filename).name}: {why}; left out",
                      shape.line)
            return None
        key = (shape.filename, scale)
        if key not in self.meshes:
            name = f"mesh{len(self.meshes)}"
            # inertia="shell": the bodies' inertia is written, never taken from meshes, and
            # MuJoCo refuses a flat mesh's volume (plane.urdf: "mesh volume is too small")
            el = self.E.SubElement(self.asset, "mesh", name=name,
                                   file=self.mesh_names[str(shape.filename)], inertia="shell")
            if scale != (1.0, 1.0, 1.0):
                el.set("scale", nums(scale))
            self.meshes[key] = name
        return self.meshes[key]

    def mesh_file(self, path: Path, line: int | None) -> MeshAsset | None:
        """A mesh file as it will be written (read, checked, copied or converted once).

        Its name in the assets folder is content-addressed, ``stem_<8 hex of its SHA-256>``:
        the same bytes always get the same name, so a new export never replaces a file an
        old XML names (see :func:`write_export`).
        """
        source = str(path)
        if source in self.mesh_files:
            return self.mesh_files[source]
        found = mesh_asset(path)
        if isinstance(found, str):
            self.note("dropped", f"mesh {path.name}: {found}; its geoms are left out", line)
            self.mesh_files[source] = None
            return None
        stem = "".join(c if c.isalnum() or c in "-_" else "_" for c in path.stem) or "mesh"
        # "_", not ".": "link_3.1e5fa2b0.stl" reads as numbers to a tool that edits them all
        name = f"{stem}_{found.digest[:8]}{found.suffix}"
        if name in self.assets and self.digests[name] != found.digest:
            name = f"{stem}_{found.digest[:16]}{found.suffix}"  # 8 hex digits collided
        self.assets[name] = found.data
        self.digests[name] = found.digest
        if found.converted:
            self.note("converted", f"mesh {path.name}: {found.converted}, as {name}", line)
        self.mesh_files[source] = found
        self.mesh_names[source] = name
        return found

    # ------------------------------------------------------------------ geoms

    def sized(self, shape: LoadedShape, visual: bool, link: LoadedLink) -> bool:
        """Whether the shape has a size in every dimension (a mesh's scale nonzero).

        MuJoCo refuses a geom whose size is not positive ("size 0 must be positive in
        geom") and a mesh scaled to nothing ("mesh surface area is too small"). PyBullet
        keeps such a shape (measured: a 0-radius sphere or a 0 0 0 box is a point the body
        rests on, a 0-length cylinder a disc, a 0 scale component a flat mesh); the files
        that hold one use it as a placeholder for nothing (atlas_drc's ``<sphere
        radius="0"/>``, upkie's ``<box size="0 0 0"/>``), so it is left out, said. A capsule of
        length 0 is a sphere, and is written as one.
        """
        if shape.kind == "plane":
            return True
        if shape.kind == "mesh":
            values: tuple[float, ...] = tuple(shape.scale)
            ok = all(math.isfinite(x) and x != 0 for x in values)  # negative: a mirror
            what = f'<mesh scale="{nums(values)}">'
        else:
            values = tuple(shape.size)
            # a capsule's length may be 0 (a sphere); every other size must be positive
            sizes = values[:1] if shape.kind == "capsule" and values[1:] == (0.0,) else values
            ok = all(math.isfinite(x) and x > 0 for x in sizes)
            what = f'<box size="{nums(values)}">' if shape.kind == "box" else \
                f"<{shape.kind} " + " ".join(f'{a}="{num(v)}"' for a, v in zip(
                    ("radius", "length"), values, strict=False)) + ">"
        if not ok:
            part = "visual" if visual else "collision"
            why = ("squashes the mesh flat (a scale of 0), as a zero-size primitive"
                   if shape.kind == "mesh" else "has a size that is not positive, which MuJoCo "
                   "refuses")
            self.note("dropped", f"{part} of link {link.name!r}: {what} {why}; left out "
                      "(PyBullet keeps it as a point, line or flat shape"
                      + ("" if visual else " it collides with") + ")", shape.line)
        return ok

    def geom(self, body: etree._Element, shape: LoadedShape, at: Any, visual: bool,
             link: LoadedLink) -> None:
        if not self.sized(shape, visual, link):
            return
        t = at @ origin_matrix(shape.xyz, shape.rpy)
        g = self.E.Element("geom")
        if not self.shape_type(g, body, shape, link, visual):
            return
        _place(g, t)
        if self.o.geom_names:
            name = f"g{len(self.geom_links)}"
            g.set("name", name)
            self.geom_links[name] = link.name
        if visual:
            g.set("contype", "0")
            g.set("conaffinity", "0")
            g.set("group", str(VISUAL_GROUP))
            g.set("density", "0")
            if shape.rgba is not None:
                g.set("rgba", nums(shape.rgba))
            if shape.texture:
                self.note("dropped", f"visual of link {link.name!r}: its texture is not "
                          "written (the colour is)", shape.line)
        else:
            ct, ca = ((SELF_CONTYPE, SELF_CONAFFINITY) if self.o.self_collision
                      else (ROBOT_CONTYPE, ROBOT_CONAFFINITY))
            g.set("contype", str(ct))
            g.set("conaffinity", str(ca))
            g.set("group", str(COLLISION_GROUP))
            g.set("density", "0")
            # priority 1: the robot's friction is the contact's, as PyBullet multiplies it
            # by a ground's 1.0 (MuJoCo would otherwise take the larger of the two)
            g.set("priority", "1")
            g.set("friction", nums((link.lateral_friction, link.spinning_friction,
                                    link.rolling_friction)))
            if link.rolling_friction > 0:
                g.set("condim", "6")
            elif link.spinning_friction > 0:
                g.set("condim", "4")
        body.append(g)

    def shape_type(self, g: etree._Element, body: etree._Element, shape: LoadedShape,
                   link: LoadedLink, visual: bool) -> bool:
        """Set the geom's type and size (or mesh); False when it cannot be written."""
        if shape.kind == "box":
            g.set("type", "box")
            g.set("size", nums([s / 2 for s in shape.size]))
        elif shape.kind == "capsule" and shape.size[1] == 0:
            g.set("type", "sphere")
            g.set("size", num(shape.size[0]))
            self.note("converted", f"capsule of link {link.name!r} has length 0: written as "
                      "the sphere it is (MuJoCo refuses a capsule of length 0)", shape.line)
        elif shape.kind in ("cylinder", "capsule"):
            g.set("type", shape.kind)
            g.set("size", nums([shape.size[0], shape.size[1] / 2]))
        elif shape.kind == "sphere":
            g.set("type", "sphere")
            g.set("size", num(shape.size[0]))
        elif shape.kind == "plane":
            if body is not self.world and not self.static_root_body(body):
                self.note("dropped", f"<plane> of link {link.name!r}: MuJoCo allows planes "
                          "only on static bodies", shape.line)
                return False
            g.set("type", "plane")
            g.set("size", "0 0 1")
        else:
            name = self.mesh(shape, visual, link)
            if name is None:
                return False
            g.set("type", "mesh")
            g.set("mesh", name)
        return True

    def static_root_body(self, body: etree._Element) -> bool:
        return body.get("name") == self.robot.root and self.static

    # ------------------------------------------------------------------ bodies

    def build(self) -> None:
        robot = self.robot
        where = fused(robot, split_world=True)
        members: dict[str, list[str]] = {}
        for link, (body, _) in where.items():
            members.setdefault(body, []).append(link)
        self.members = members
        root_link = robot.links[robot.root]
        root_mass = self.inertial(root_link).mass
        self.static = self.o.fixed_base or root_mass == 0
        if not self.o.fixed_base and root_mass == 0:
            self.note("mirrored", f"root link {robot.root!r} has mass 0: PyBullet fixes such "
                      "a base in place, so it is welded (no free joint)", root_link.line)
        elements: dict[str, Any] = {}
        if robot.root == "world":
            elements["world"] = self.world  # MuJoCo's own world body: its children hang there
        else:
            b = self.E.SubElement(self.world, "body", name=robot.root)
            elements[robot.root] = b
            if not self.static:
                self.E.SubElement(b, "freejoint")
            self.bodies.append(robot.root)
            self.fill(b, robot.root, members[robot.root], where)
        if robot.root == "world":
            self.fill(self.world, "world", members["world"], where, inertial=False)
        for j in robot.joints:
            if where[j.child][0] != j.child:
                continue  # fused into its parent's body
            parent_body, at = where[j.parent]
            b = self.E.SubElement(elements[parent_body], "body", name=j.child)
            elements[j.child] = b
            _place(b, at @ origin_matrix(j.xyz, j.rpy))
            self.bodies.append(j.child)
            if j.moves:
                self.joint(b, j)
            self.fill(b, j.child, members[j.child], where, moving=j.moves)

    def fill(self, body: etree._Element, name: str, links: list[str], where: dict[str, Any],
             inertial: bool = True, moving: bool = True) -> None:
        """A body's inertial, geoms and sites, from the links fused into it."""
        robot = self.robot
        if inertial:
            moving = moving and not (name == robot.root and self.static)
            m = self.body_mass(name, links, where, moving)
            self.check_mass(name, m, moving)
            el = self.E.Element("inertial", pos=nums(m.com), mass=num(m.mass))
            t = m.tensor
            if not moving and (m.mass == 0 or not (m.tensor.diagonal() > 0).all()):
                el.set("diaginertia", "0 0 0")
            else:
                el.set("fullinertia", nums((t[0, 0], t[1, 1], t[2, 2], t[0, 1], t[0, 2],
                                            t[1, 2])))
            body.insert(0 if body.find("freejoint") is None else 1, el)
            for n in links:
                link = robot.links[n]
                if link.inertial.given and not self.o.inertia_from_shapes and \
                        self.inertial(link) is not link.inertial and \
                        not any(self.inertial(link).tensor[k][k] for k in range(3)) and \
                        any(link.inertial.tensor[k][k] for k in range(3)):
                    self.note("mirrored", f"link {n!r}: its inertia breaks the triangle "
                              "inequality; PyBullet sets it to zero, and so is it written "
                              "(fused into a body that stays valid)", link.inertial.line)
                if not link.inertial.given and not self.o.inertia_from_shapes:
                    self.note("default", f"link {n!r} has no <inertial>: PyBullet gives it "
                              "1 kg and unit inertia (1, 1, 1) at the link frame; written so",
                              link.line)
        for n in links:
            link = robot.links[n]
            at = where[n][1]
            for s in link.visuals:
                self.geom(body, s, at, True, link)
            for s in link.collisions:
                self.geom(body, s, at, False, link)
            if link.contact_other:
                self.note("dropped", f"<contact> of link {n!r}: {', '.join(link.contact_other)}"
                          " not mapped (MuJoCo's solref/solimp are its own)", link.line)
            if n != name:
                site = self.E.SubElement(body, "site", name=n)
                _place(site, at)
                self.sites.append(n)
        if name == "world":
            self.sites.append("world")
            self.E.SubElement(body, "site", name="world")

    def body_mass(self, name: str, links: list[str], where: dict[str, Any],
                  moving: bool) -> _Mass:
        """A body's mass properties, from the links fused into it.

        Where PyBullet zeroed a link's tensor (the triangle inequality) and that leaves a
        moving body with a zero principal moment, which MuJoCo refuses, the tensor
        ``urdfkit fix`` writes for the link is written instead: a way through, said per link.
        """
        import numpy as np

        def mass() -> _Mass:
            return combine([(self.inertial(self.robot.links[n]), where[n][1]) for n in links])

        m = mass()
        fixable = [n for n in links if n in (self.o.repairs or {})]
        if not moving or not fixable or not np.isfinite(m.tensor).all() \
                or np.linalg.eigvalsh(m.tensor)[0] > 1e-15:  # mjMINVAL, as check_mass
            return m
        assert self.o.repairs is not None
        for n in fixable:
            inertial, xml, how, why = self.o.repairs[n]
            self.repaired.append(n)
            self.note("repaired", f"link {n!r}: PyBullet simulates it with {why}, which "
                      f"leaves the moving body {name!r} without the inertia MuJoCo "
                      f"requires, so written instead: {xml}, {how}. agree lists this link's "
                      "rows as a known difference", inertial.line)
        return mass()

    def check_mass(self, name: str, m: _Mass, moving: bool) -> None:
        """Refuse what MuJoCo refuses, with check's code (U602-U604, U608) and the line."""
        import numpy as np

        link = self.robot.links[name]
        line = link.inertial.line or link.line
        if not (math.isfinite(m.mass) and np.isfinite(m.com).all()
                and np.isfinite(m.tensor).all()):
            nan = math.isnan(m.mass) or np.isnan(m.com).any() or np.isnan(m.tensor).any()
            what = ("are not numbers (NaN) as PyBullet loads them: a mass, origin or inertia "
                    "written nan, or infinities that cancel (urdfkit check names it, U401)"
                    if nan else "overflow a double")
            raise InputError(f"the mass properties of link {name!r} (with the links fused into "
                             f"it) {what}; MuJoCo cannot use them",
                             file=self.robot.file, line=line)
        if not moving:
            return
        if m.mass <= 1e-15:  # mjMINVAL: MuJoCo's floor for a moving body's mass
            what = "0" if m.mass <= 0 else f"{m.mass:.3g} kg, under MuJoCo's floor of 1e-15"
            raise InputError(f"U602: link {name!r} moves but has mass {what} (with the links "
                             "fused into it); MuJoCo refuses a massless moving body",
                             file=self.robot.file, line=line)
        with np.errstate(all="ignore"):
            eig = np.linalg.eigvalsh(m.tensor)
        scale = max(abs(eig).max(), 1e-300)
        if not np.isfinite(eig).all() or not math.isfinite(scale):
            raise InputError(f"the inertia of link {name!r} overflows a double; MuJoCo cannot "
                             "use it", file=self.robot.file, line=line)
        a, b, c = sorted(eig)
        if a <= 1e-15:  # mjMINVAL: MuJoCo's floor for a moving body's principal moments
            # the cause check names: a link's own tensor PyBullet zeroed (U604)
            for n in self.members.get(name, [name]) if not self.o.inertia_from_shapes else ():
                given = self.robot.links[n].inertial
                if given.given and given.mass > 0:
                    self.triangle(n, np.array(given.tensor), given.line)
            raise InputError(f"U608: inertia of link {name!r} (with the links fused into it) "
                             f"has a zero principal moment ({a:.6g}, {b:.6g}, {c:.6g}); "
                             "MuJoCo refuses it for a moving body", file=self.robot.file,
                             line=line)
        if a < -1e-12 * scale:
            raise InputError(f"U603: inertia of link {name!r} is not positive definite (principal "
                             f"moments {a:.6g}, {b:.6g}, {c:.6g}); MuJoCo refuses it",
                             file=self.robot.file, line=line)
        if a + b < c - 1e-9 * scale:
            raise InputError(f"U604: inertia of link {name!r} violates the triangle inequality "
                             f"({a:.6g} + {b:.6g} < {c:.6g}); MuJoCo refuses it",
                             file=self.robot.file, line=line)

    def triangle(self, name: str, tensor: Any, line: int | None) -> None:
        """U604 on a link's own tensor from the file (PyBullet zeroes such a tensor)."""
        import numpy as np

        with np.errstate(all="ignore"):
            eig = np.linalg.eigvalsh(tensor) if np.isfinite(tensor).all() else None
        if eig is None or not np.isfinite(eig).all():
            return
        a, b, c = sorted(eig)
        if a + b < c - 1e-9 * max(abs(c), 1e-300):
            what = (f"U603: inertia of link {name!r} is not positive definite (principal "
                    f"moments {a:.6g}, {b:.6g}, {c:.6g})" if a < 0 else
                    f"U604: inertia of link {name!r} violates the triangle inequality "
                    f"({a:.6g} + {b:.6g} < {c:.6g})")
            # export writes what fix writes where there is one (see body_mass)
            hint = ("`urdfkit fix` can derive one from the shapes" if self.o.repairs is None
                    else "`urdfkit fix` cannot repair it either: it has no collision solid to "
                    "derive one from, and such a tensor cannot be balanced; write its "
                    "<inertial> by hand")
            raise InputError(f"{what}: PyBullet zeroes it and MuJoCo refuses the body it "
                             f"leaves ({hint})", file=self.robot.file, line=line)

    def joint(self, body: etree._Element, j: LoadedJoint) -> None:
        E = self.E
        if j.odd_limit:
            raise InputError(f"joint {j.name!r}: <limit {j.odd_limit}>: PyBullet loads a bound "
                             "that is not a finite number as written; MuJoCo's range cannot "
                             "hold it", file=self.robot.file, line=j.line)
        if j.type == "spherical":
            el = E.SubElement(body, "joint", name=j.name, type="ball")
        else:
            el = E.SubElement(body, "joint", name=j.name,
                              type="slide" if j.type == "prismatic" else "hinge",
                              axis=nums(j.axis))
            if j.limited and j.lower < j.upper:
                el.set("range", nums((j.lower, j.upper)))
            elif j.limited:
                # PyBullet locks a joint whose lower == upper; MuJoCo refuses an empty range
                self.locked.append(j)
        if j.damping:
            el.set("damping", num(j.damping))
        if j.friction:
            self.note("dropped", f"joint {j.name!r}: <dynamics friction> is not written "
                      "(PyBullet 3.2.7 does not simulate it; MuJoCo's frictionloss would)",
                      j.line)
        if j.velocity and j.moves:
            self.velocity_limits.append(j.name)
        if j.declared_type == "floating":
            self.note("mirrored", f"joint {j.name!r} is floating: PyBullet loads it as fixed; "
                      "so is it written", j.line)

    velocity_limits: list[str]

    # ------------------------------------------------------------------ the rest

    def mimics(self) -> list[Any]:
        """The ``<mimic>`` joints written as equalities; each one left out is said.

        Left out, each an ordinary joint as PyBullet has it (with an actuator): a mimic of a
        joint that does not move, of itself (MuJoCo refuses it: "element 'a' is repeated in
        equality constraint") and each of a ring of mimics (``b`` follows ``c`` follows
        ``b``: none has a leader to take its position from, check's U309).
        """
        moving = {j.name for j in self.robot.movable()}
        leader = {j.name: j.mimic[0] for j in self.robot.movable() if j.mimic is not None}
        rings: dict[str, list[str]] = {}
        for start in leader:
            ring, name = [start], leader[start]
            while name in leader and name not in ring:
                ring.append(name)
                name = leader[name]
            if name == start and len(ring) > 1:
                rings[start] = ring
        written = []
        for j in self.robot.movable():
            if j.mimic is None:
                continue
            if j.mimic[0] not in moving:
                why = "which does not move"
            elif j.mimic[0] == j.name:
                why = "itself, which MuJoCo refuses"
            elif j.name in rings:
                ring = rings[j.name]
                why = ("a ring of mimics (" + " -> ".join(repr(n) for n in [*ring, j.name])
                       + "): none has a leader to take its position from")
            else:
                written.append(j)
                continue
            self.note("dropped", f"joint {j.name!r}: <mimic> of {j.mimic[0]!r}, {why}; not "
                      "written (an ordinary joint, as PyBullet has it)", j.line)
        return written

    def actuators(self) -> None:
        E = self.E
        kind = self.o.actuators
        mimics = self.mimics()
        followers = {j.name for j in mimics}
        movable = [j for j in self.robot.movable() if j.type != "spherical"
                   and j.name not in followers]
        if kind != "none" and movable:
            act = E.SubElement(self.root, "actuator")
            gain = self.o.gain if self.o.gain is not None else DEFAULT_GAIN.get(kind)
            for j in movable:
                el = E.SubElement(act, kind, name=j.name, joint=j.name)
                if kind == "motor":
                    if j.effort > 0:
                        el.set("ctrlrange", nums((-j.effort, j.effort)))
                else:
                    el.set("kp" if kind == "position" else "kv", num(gain or 0.0))
                    if j.effort > 0:
                        el.set("forcerange", nums((-j.effort, j.effort)))
                    if kind == "position" and j.limited:
                        el.set("ctrlrange", nums((j.lower, j.upper)))
                    elif kind == "velocity" and j.velocity > 0:
                        el.set("ctrlrange", nums((-j.velocity, j.velocity)))
        eq = E.SubElement(self.root, "equality") if mimics or self.locked else None
        for j in self.locked:
            E.SubElement(eq, "joint", joint1=j.name, polycoef=nums((j.lower, 0, 0, 0, 0)))
            self.note("approximated", f"joint {j.name!r} has lower == upper: PyBullet locks it "
                      "there with a limit; MuJoCo refuses an empty range, so a joint equality "
                      "holds it", j.line)
        for j in mimics:
            leader, mult, offset = j.mimic
            E.SubElement(eq, "joint", joint1=j.name, joint2=leader,
                         polycoef=nums((offset, mult, 0, 0, 0)))
            self.note("approximated", f"joint {j.name!r} mimics {leader!r}: written as a "
                      "joint equality (what the URDF means); PyBullet ignores <mimic>, so "
                      "it is a known difference and has no actuator", j.line)

    def ground(self) -> None:
        E = self.E
        self.world.insert(0, E.Element(
            "geom", name="ground", type="plane", size="0 0 0.05", rgba="0.8 0.8 0.8 1",
            contype=str(GROUND_CONTYPE), conaffinity=str(GROUND_CONAFFINITY),
            friction="1 0 0"))
        self.world.insert(0, E.Element("light", name="sun", pos="0 0 5", dir="0 0 -1",
                                       directional="true"))


def export_mjcf(robot: LoadedRobot, options: ExportOptions | None = None,
                asset_dir: str = "robot_assets") -> Export:
    """The MJCF of ``robot`` and the meshes it needs (nothing is written here).

    Raises:
        InputError: What MuJoCo would refuse (a massless moving body, U602; an inertia that
            is not positive definite, U603, or breaks the triangle inequality, U604), with the
            file and line.
        ParameterError: An unknown ``actuators`` kind.
    """
    o = options or ExportOptions()
    if o.actuators not in ACTUATORS:
        raise ParameterError(f"actuators must be one of {', '.join(ACTUATORS)}, got "
                             f"{o.actuators!r}", param="actuators")
    w = _Writer(robot, o, asset_dir)
    w.velocity_limits = []
    w.build()
    w.actuators()
    if o.ground:
        w.ground()
    if not w.assets:
        w.root.remove(w.compiler)
        w.compiler = w.E.Element("compiler", angle="radian", autolimits="true")
        w.root.insert(0, w.compiler)
    if not len(w.asset):
        w.root.remove(w.asset)
    if w.velocity_limits:
        w.note("dropped", f"velocity limits of {len(w.velocity_limits)} joint(s) "
               f"({', '.join(w.velocity_limits[:4])}{', ...' if len(w.velocity_limits) > 4 else ''}"
               "): MuJoCo has no joint velocity limit (PyBullet does not enforce them in "
               "simulation either)")
    w.note("approximated", "PyBullet damps every link's velocity (linear and angular "
           "damping 0.04); MuJoCo has no per-body damping, so none is written (agree turns "
           "PyBullet's off)")
    w.note("mirrored", "PyBullet's default velocity motors (one per joint, target 0) are not "
           "written: --actuators chooses the actuators")
    w.E.indent(w.root, space="  ")
    xml = w.E.tostring(w.root, xml_declaration=False, encoding="unicode").encode() + b"\n"
    return Export(xml, w.assets, asset_dir, w.notes, w.bodies, w.sites, digests=w.digests,
                  repaired=w.repaired, geom_links=w.geom_links)


def asset_dir_for(path: str | Path) -> str:
    """The assets folder's name for an output file: ``robot.xml`` -> ``robot_assets``."""
    return f"{Path(path).stem}_assets"


def write_export(export: Export, path: str | Path, *, force: bool = False,
                 verify: Callable[[Path], bool] | None = None) -> list[str]:
    """Write the XML and its assets folder beside it, crash-safe; return the paths written.

    At every step the XML on disk, old or new, names only files that are there with the
    bytes it expects (:mod:`urdfkit.formats.mjcf_write`): mesh files are named by their
    content and only added until the new XML replaces the old one atomically; then the
    files it does not name are removed. Without ``force`` neither the XML nor a non-empty
    assets folder may exist. ``verify`` is handed the staged XML before it takes its place:
    when it returns False, nothing of this run is left and ``[]`` is returned.

    Raises:
        OutputError: What cannot be written (a full disk, an assets path that is a symlink),
            one line naming the file; nothing of this run is left.
    """
    from urdfkit.core.output import check_output
    from urdfkit.formats.mjcf_write import write_pair

    out = check_output(path, force=force, suffixes=(".xml",), what="the MJCF file")
    export.paths = write_pair(out, export.xml, export.assets, export.digests, export.asset_dir,
                              force=force, verify=verify)
    return export.paths
