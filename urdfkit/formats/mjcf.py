"""URDF to MJCF: the robot PyBullet simulates, written for MuJoCo (no mujoco import here).

One body per link that moves (and the root); fixed links fused into their parent body, each
kept as a ``<site>`` named after it at its frame; masses, centres of mass and full inertia
tensors combined exactly; joints named, ordered and limited as PyBullet loads them; meshes
copied, or converted by urdfkit's own readers when MuJoCo cannot read them (COLLADA, ASCII
STL), into a folder beside the XML. Numbers are written with ``repr``: every double round-trips.
What is dropped or approximated is said in :attr:`Export.notes` (docs/export.md lists it all).
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, Any

from urdfkit.core.errors import InputError, ParameterError
from urdfkit.formats.fk import fused, origin_matrix
from urdfkit.formats.mjcf_geoms import (
    COLLISION_GROUP,
    ROBOT_CONAFFINITY,
    ROBOT_CONTYPE,
    SELF_CONAFFINITY,
    SELF_CONTYPE,
    VISUAL_GROUP,
    Geoms,
    Meshes,
)
from urdfkit.formats.mjcf_mass import Masses, combine
from urdfkit.formats.mjcf_text import mat_to_quat, num, nums, place
from urdfkit.formats.robot import LoadedInertial, LoadedJoint, LoadedRobot

if TYPE_CHECKING:
    from lxml import etree

#: ``--actuators`` choices.
ACTUATORS = ("motor", "position", "velocity", "none")
#: Default gains: position kp (N m/rad), velocity kv (N m s/rad).
DEFAULT_GAIN = {"position": 100.0, "velocity": 1.0}
#: The --ground plane's collision bitmasks (the robot's are :mod:`urdfkit.formats.mjcf_geoms`').
GROUND_CONTYPE, GROUND_CONAFFINITY = 1, 2


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


class _Writer:
    """Builds one document; see :func:`export_mjcf`.

    The document's skeleton, its bodies, sites and joints, and its actuators and equalities
    are written here; each body's mass properties come from its :class:`Masses`, its geoms
    from its :class:`Geoms`, and the mesh assets they name from its :class:`Meshes`.
    """

    def __init__(self, robot: LoadedRobot, options: ExportOptions, asset_dir: str) -> None:
        from lxml import etree

        self.E = etree
        self.robot = robot
        self.o = options
        self.asset_dir = asset_dir
        self.notes: list[Note] = []
        self.bodies: list[str] = []
        self.sites: list[str] = []
        self.locked: list[Any] = []
        self.root = etree.Element("mujoco", model=robot.name or "robot")
        self.compiler = etree.SubElement(self.root, "compiler", angle="radian",
                                         meshdir=asset_dir, autolimits="true")
        etree.SubElement(self.root, "option", integrator="implicitfast")
        self.asset = etree.SubElement(self.root, "asset")
        self.world = etree.SubElement(self.root, "worldbody")
        self.masses = Masses(robot, options.inertials, options.repairs,
                             options.inertia_from_shapes, self.note)
        self.meshes = Meshes(self.asset, self.note)
        self.geoms = Geoms(self.world, robot.root, self.meshes, options.geom_names,
                           options.self_collision, self.note)

    def note(self, kind: str, message: str, line: int | None = None) -> None:
        self.notes.append(Note(kind, message, line))

    # ------------------------------------------------------------------ bodies

    def build(self) -> None:
        robot = self.robot
        where = fused(robot, split_world=True)
        members: dict[str, list[str]] = {}
        for link, (body, _) in where.items():
            members.setdefault(body, []).append(link)
        self.masses.members = members
        root_link = robot.links[robot.root]
        root_mass = self.masses.inertial(root_link).mass
        self.static = self.o.fixed_base or root_mass == 0
        self.geoms.static = self.static
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
            place(b, at @ origin_matrix(j.xyz, j.rpy))
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
            m = self.masses.body_mass(name, links, where, moving)
            self.masses.check_mass(name, m, moving)
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
                        self.masses.inertial(link) is not link.inertial and \
                        not any(self.masses.inertial(link).tensor[k][k] for k in range(3)) and \
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
                self.geoms.geom(body, s, at, True, link)
            for s in link.collisions:
                self.geoms.geom(body, s, at, False, link)
            if link.contact_other:
                self.note("dropped", f"<contact> of link {n!r}: {', '.join(link.contact_other)}"
                          " not mapped (MuJoCo's solref/solimp are its own)", link.line)
            if n != name:
                site = self.E.SubElement(body, "site", name=n)
                place(site, at)
                self.sites.append(n)
        if name == "world":
            self.sites.append("world")
            self.E.SubElement(body, "site", name="world")

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
    if not w.meshes.assets:
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
    return Export(xml, w.meshes.assets, asset_dir, w.notes, w.bodies, w.sites,
                  digests=w.meshes.digests, repaired=w.masses.repaired,
                  geom_links=w.geoms.geom_links)


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


__all__ = ["ACTUATORS", "COLLISION_GROUP", "DEFAULT_GAIN", "GROUND_CONAFFINITY", "GROUND_CONTYPE",
           "ROBOT_CONAFFINITY", "ROBOT_CONTYPE", "SELF_CONAFFINITY", "SELF_CONTYPE", "VISUAL_GROUP",
           "Export", "ExportOptions", "Note", "asset_dir_for", "combine", "export_mjcf",
           "mat_to_quat", "num", "nums", "write_export"]
