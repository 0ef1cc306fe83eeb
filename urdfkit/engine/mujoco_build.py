"""One robot made ready for the MuJoCo engine's world: the export, its records, its contacts.

:func:`prepare` turns a guarded URDF into a :class:`Loaded`: PyBullet's own mass properties
(:mod:`urdfkit.engine.inertials`), urdfkit's MJCF export built in memory (no file written), the
MJCF parsed into an ``MjSpec`` ready to be attached to the world's, and what the engine keeps
about each link and motor. :func:`pairs` lists the contacts the world must test, with
PyBullet's combined friction. :mod:`urdfkit.engine.mujoco` holds the engine itself.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from urdfkit.core.errors import InputError, ParameterError
from urdfkit.engine.api import LinkDynamics, LoadSettings, Quat, Vec3
from urdfkit.engine.mujoco_motors import Motor
from urdfkit.formats.robot import LoadedRobot

#: The export's groups of visual and collision geoms (``formats.mjcf``'s).
VISUAL_GROUP, COLLISION_GROUP = 2, 3
#: Bullet's clamp on a combined friction coefficient (btManifoldResult).
MAX_FRICTION = 10.0
#: The export's codes for what MuJoCo refuses in a link's mass properties; ``urdfkit fix``
#: repairs each (checks/fix.py FIXABLE).
FIXABLE_INERTIA = ("U602", "U603", "U604", "U608")


@dataclass
class WorldLink:
    """One URDF link in the world.

    Attributes:
        name: The URDF's link name.
        body: The link the MuJoCo body it belongs to is named after (itself, or the link a
            fixed joint fused it into).
        frame: The link frame in that body's frame (4x4).
        dynamics: Its mass properties and contact coefficients: PyBullet's at load, then as
            ``change_dynamics`` set them.
    """

    name: str
    body: str
    frame: Any
    dynamics: LinkDynamics


@dataclass
class Loaded:
    """A robot exported and parsed, with what the engine keeps about it.

    Attributes:
        robot: The URDF as PyBullet reads it (joints in PyBullet's order).
        display: The file as the caller named it (for messages).
        settings: How it was loaded.
        spec: Its MJCF parsed, collision geoms left to explicit pairs, mimics left out.
        assets: Mesh bytes by the name the spec's meshes give (``assets/<name>``).
        links: The root first, then link ``i`` at ``i + 1``.
        geom_links: Each geom's name (unprefixed) and its link.
        collisions: The collision geoms: (name, link, body), in the export's order.
        static: The MuJoCo bodies welded to the world (by link name).
        parents: Each moving body's parent body (by link name).
        placed: Each collision and visual geom's pose in its MuJoCo body as the export
            wrote it (MuJoCo moves a mesh's geom to the mesh's own centre when it compiles).
        motors: By joint index, every revolute and prismatic joint's motor.
        notes: What the export dropped, approximated or defaulted, and what the engine
            left out, one line each.
        visuals: The visual geoms: (name, link), in the export's order.
        mesh_files: Each mesh (by its unprefixed name) and the file it was read from, ""
            where the export converted it (a DAE, an STL it repaired).
    """

    robot: LoadedRobot
    display: str
    settings: LoadSettings
    spec: Any
    assets: dict[str, bytes]
    links: list[WorldLink]
    geom_links: dict[str, str]
    collisions: list[tuple[str, str, str]]
    static: set[str]
    parents: dict[str, str]
    placed: dict[str, tuple[Vec3, Quat]] = field(default_factory=dict)
    motors: dict[int, Motor] = field(default_factory=dict)
    notes: list[str] = field(default_factory=list)
    visuals: list[tuple[str, str]] = field(default_factory=list)
    mesh_files: dict[str, str] = field(default_factory=dict)

    def link(self, index: int) -> WorldLink:
        """Link ``index`` (-1: the root), or a ParameterError naming the range."""
        if not -1 <= index < len(self.links) - 1:
            raise ParameterError(f"`link` {index} is not a link of {self.display} (it has -1 "
                                 f"to {len(self.links) - 2})", param="link")
        return self.links[index + 1]

    def root_offset(self) -> tuple[Vec3, Quat]:
        """The root's inertial frame in its link frame, as PyBullet loaded it."""
        d = self.links[0].dynamics
        return d.inertial_position, d.inertial_orientation


def prepare(mujoco: Any, path: str, settings: LoadSettings, display: str | None) -> Loaded:
    """Export a guarded URDF for MuJoCo in memory and parse it (see the module).

    Raises:
        InputError: What MuJoCo refuses (a massless moving link, an impossible inertia),
            naming the link and, where it can, the ``urdfkit fix`` that repairs it.
        ParameterError: A load setting MuJoCo cannot honour.
    """
    from urdfkit.engine.inertials import link_tensor, loaded_dynamics
    from urdfkit.formats.fk import fused
    from urdfkit.formats.mjcf import ExportOptions, export_mjcf
    from urdfkit.formats.robot import LoadedInertial, read_robot
    from urdfkit.sources.resolve import resolve

    name = display or str(path)
    # Guarded by the caller, with its own choice of --no-guard: re-read here, not re-judged.
    with resolve(path, guard=False) as resolved:
        robot = read_robot(resolved.root, name)
        if not settings.implicit_cylinder and any(
                s.kind == "cylinder" for link in robot.links.values() for s in link.collisions):
            raise ParameterError("`implicit_cylinder` False: PyBullet then collides with a "
                                 "mesh of each cylinder; MuJoCo's cylinders are true ones",
                                 param="implicit_cylinder")
        loaded = loaded_dynamics(resolved.load_path, inertia_from_file=settings.inertia_from_file,
                                 display=name)
        inertials = {n: LoadedInertial(d.mass, d.inertial_position, link_tensor(d))
                     for n, d in loaded.items()}
        try:
            e = export_mjcf(robot, ExportOptions(
                fixed_base=settings.fixed_base, self_collision=settings.self_collision,
                actuators="none", inertials=inertials,
                inertia_from_shapes=not settings.inertia_from_file, geom_names=True), "assets")
        except InputError as err:
            raise _with_fix(err, name) from None
        assets = {f"assets/{k}": v if isinstance(v, bytes) else v.read_bytes()
                  for k, v in e.assets.items()}
    spec = _parse(mujoco, e.xml, assets, name)
    notes = [n.message for n in e.notes]
    notes += _drop_mimics(mujoco, spec)
    where = fused(robot, split_world=True)
    collisions = []
    visuals = []
    placed: dict[str, tuple[Vec3, Quat]] = {}
    for g in spec.geoms:
        if g.group == COLLISION_GROUP:
            g.contype = 0  # every contact is an explicit pair (see pairs)
            g.conaffinity = 0
            collisions.append((g.name, e.geom_links[g.name], where[e.geom_links[g.name]][0]))
        elif g.group == VISUAL_GROUP:
            visuals.append((g.name, e.geom_links[g.name]))
        else:
            continue
        w, x, y, z = (float(v) for v in g.quat)
        placed[g.name] = ((float(g.pos[0]), float(g.pos[1]), float(g.pos[2])), (x, y, z, w))
    read = {k: str(v) for k, v in e.assets.items() if not isinstance(v, bytes)}
    mesh_files = {mesh.name: read.get(Path(mesh.file).name, "") for mesh in spec.meshes}
    links = [WorldLink(robot.root, where[robot.root][0], where[robot.root][1], loaded[robot.root])]
    links += [WorldLink(j.child, where[j.child][0], where[j.child][1], loaded[j.child])
              for j in robot.joints]
    root_mass = loaded[robot.root].mass
    static = {robot.root} if settings.fixed_base or root_mass == 0 or robot.root == "world" \
        else set()
    parents = {}
    for j in robot.joints:
        body, parent = where[j.child][0], where[j.parent][0]
        if body == j.child and body != parent:
            parents[body] = parent
            if parent in static and not j.moves:
                static.add(body)  # welded to a static root that is MuJoCo's world
    motors = {i: Motor() for i, j in enumerate(robot.joints)
              if j.type in ("revolute", "continuous", "prismatic")}
    return Loaded(robot, name, settings, spec, assets, links, e.geom_links, collisions, static,
                  parents, placed, motors, notes, visuals, mesh_files)


def _parse(mujoco: Any, xml: bytes, assets: dict[str, bytes], name: str) -> Any:
    import warnings

    from urdfkit.formats.mjwarn import mujoco_warnings

    try:
        with warnings.catch_warnings(), mujoco_warnings(mujoco):
            warnings.simplefilter("ignore")  # the export's notes say what MuJoCo would
            return mujoco.MjSpec.from_string(xml.decode(), assets=assets)
    except (ValueError, RuntimeError) as e:
        first = str(e).strip().splitlines()[0] if str(e).strip() else type(e).__name__
        raise InputError(f"MuJoCo cannot read its export: {first}", file=name) from None


def _with_fix(err: InputError, name: str) -> InputError:
    """The export's refusal, with the ``urdfkit fix`` that repairs it where there is one."""
    message = err.message
    if message[:4] in FIXABLE_INERTIA and "urdfkit fix" not in message:
        message += f"; `urdfkit fix {name}` writes one MuJoCo accepts"
    return InputError(message, file=err.file or name, line=err.line)


def _drop_mimics(mujoco: Any, spec: Any) -> list[str]:
    """Leave out the joint equalities the export writes for ``<mimic>``: PyBullet ignores it.

    The equalities that lock a joint whose limits meet stay (PyBullet holds such a joint).
    """
    said = []
    for eq in list(spec.equalities):
        if eq.type == mujoco.mjtEq.mjEQ_JOINT and eq.name2:
            said.append(f"joint {eq.name1!r}: its <mimic> of {eq.name2!r} is left out, as "
                        "PyBullet ignores it")
            spec.delete(eq)
    return said


def combined_friction(a: LinkDynamics, b: LinkDynamics) -> tuple[list[float], int]:
    """The friction of a contact between two links, as Bullet combines it, and its condim.

    Lateral: the product; spinning and rolling: each link's times the other's lateral, summed
    (btManifoldResult); each clamped to 10. MuJoCo's own rule (the larger of the two) would
    give a link of 0.5 on pybullet_data's plane (1.0) a friction of 1.0, not PyBullet's 0.5.
    """
    def clamp(x: float) -> float:
        return max(-MAX_FRICTION, min(MAX_FRICTION, x))

    lateral = clamp(a.lateral_friction * b.lateral_friction)
    spinning = clamp(a.spinning_friction * b.lateral_friction
                     + b.spinning_friction * a.lateral_friction)
    rolling = clamp(a.rolling_friction * b.lateral_friction
                    + b.rolling_friction * a.lateral_friction)
    condim = 6 if rolling > 0 else 4 if spinning > 0 else 3
    return [lateral, lateral, spinning, rolling, rolling], condim


@dataclass(frozen=True)
class Pair:
    """One pair of collision geoms the world tests: (robot, geom name, link) each side."""

    robot_a: int
    geom_a: str
    link_a: str
    robot_b: int
    geom_b: str
    link_b: str


def pairs(robots: list[Loaded], new: int) -> list[Pair]:
    """The pairs robot ``new`` adds: with every robot before it, and its own.

    PyBullet tests every pair of bodies, and a body's own links only with
    ``URDF_USE_SELF_COLLISION`` (never a link with its parent). Two geoms welded to the world
    never meet.
    """
    out = []
    mine = robots[new].collisions
    static_new = robots[new].static
    for k in range(new):
        for ga, la, ba in robots[k].collisions:
            for gb, lb, bb in mine:
                if ba in robots[k].static and bb in static_new:
                    continue
                out.append(Pair(k, ga, la, new, gb, lb))
    r = robots[new]
    if r.settings.self_collision:
        for i, (ga, la, ba) in enumerate(mine):
            for gb, lb, bb in mine[i + 1:]:
                if ba == bb or r.parents.get(ba) == bb or r.parents.get(bb) == ba or \
                        (ba in r.static and bb in r.static):
                    continue
                out.append(Pair(new, ga, la, new, gb, lb))
    return out
