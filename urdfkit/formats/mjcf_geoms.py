"""The geoms the MJCF writer gives a body, and the meshes they name.

:class:`Geoms` writes a link's visual or collision shape as a geom (a shape MuJoCo would
refuse, said and left out; collision bitmasks, groups, friction and contact dimensions as
PyBullet collides); :class:`Meshes` writes each mesh file once, content-addressed, into the
assets (:mod:`urdfkit.formats.mjcf_mesh` reads and checks it first) and one ``<mesh>`` per
file and scale.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from pathlib import Path
from typing import TYPE_CHECKING, Any

from urdfkit.formats.fk import origin_matrix
from urdfkit.formats.mjcf_mesh import MeshAsset, mesh_asset, unusable
from urdfkit.formats.mjcf_text import num, nums, place
from urdfkit.formats.robot import LoadedLink, LoadedShape

if TYPE_CHECKING:
    from lxml import etree

#: Collision bitmasks. Robot geoms have contype 2 / conaffinity 1: two robot geoms never
#: collide ((2 & 1) | (2 & 1) == 0), as PyBullet's default load has no self-collision, while
#: anything with MuJoCo's default 1/1 (and the --ground plane, 1/2) still meets them.
ROBOT_CONTYPE, ROBOT_CONAFFINITY = 2, 1
SELF_CONTYPE, SELF_CONAFFINITY = 3, 3
VISUAL_GROUP, COLLISION_GROUP = 2, 3


class Meshes:
    """The mesh files an export writes, and the ``<mesh>`` assets that name them."""

    def __init__(self, asset: etree._Element, note: Callable[[str, str, int | None], None]
                 ) -> None:
        from lxml import etree

        self.E = etree
        #: The document's ``<asset>``.
        self.asset = asset
        self.note = note
        #: File name in the assets folder -> its bytes or the Path to copy, and its SHA-256.
        self.assets: dict[str, bytes | Path] = {}
        self.digests: dict[str, str] = {}
        self.meshes: dict[tuple[str, tuple[float, ...]], str] = {}
        self.mesh_files: dict[str, MeshAsset | None] = {}
        self.mesh_names: dict[str, str] = {}
        self.uses: dict[tuple[str, tuple[float, float, float], bool], str | None] = {}

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
        old XML names (see :func:`urdfkit.formats.mjcf.write_export`).
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



class Geoms:
    """A body's geoms, one per visual and collision shape that MuJoCo can hold."""

    def __init__(self, world: etree._Element, root: str, meshes: Meshes, geom_names: bool,
                 self_collision: bool, note: Callable[[str, str, int | None], None]) -> None:
        from lxml import etree

        self.E = etree
        #: The document's ``<worldbody>``, and the name of the robot's root link.
        self.world = world
        self.root = root
        self.meshes = meshes
        #: :class:`urdfkit.formats.mjcf.ExportOptions`' two for geoms.
        self.geom_names = geom_names
        self.self_collision = self_collision
        self.note = note
        #: Whether the root body is welded to the world (set by the writer before any geom).
        self.static = False
        #: With ``geom_names``, each geom's name and its link.
        self.geom_links: dict[str, str] = {}

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
        """Append the shape's geom to ``body`` (``at``: the link's frame in the body)."""
        if not self.sized(shape, visual, link):
            return
        t = at @ origin_matrix(shape.xyz, shape.rpy)
        g = self.E.Element("geom")
        if not self.shape_type(g, body, shape, link, visual):
            return
        place(g, t)
        if self.geom_names:
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
            ct, ca = ((SELF_CONTYPE, SELF_CONAFFINITY) if self.self_collision
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
            name = self.meshes.mesh(shape, visual, link)
            if name is None:
                return False
            g.set("type", "mesh")
            g.set("mesh", name)
        return True

    def static_root_body(self, body: etree._Element) -> bool:
        """Whether ``body`` is the root's, welded to the world."""
        return body.get("name") == self.root and self.static
