"""Where a URDF's file references point, as PyBullet looks them up, and what they hold.

:func:`reference` follows a mesh or texture filename (relative, absolute, ``package://``,
``file://``) to the file PyBullet would open, saying why not where it finds none (U701-U711);
:func:`mesh_crash` asks whether that file is one PyBullet crashes or hangs on (U712-U713).
The guard and ``check``'s rules share them.
"""

from __future__ import annotations

import os
import stat
from collections.abc import Mapping
from functools import lru_cache
from pathlib import Path

from lxml import etree

from urdfkit.core import deps
from urdfkit.model.spec import (
    MESH_FORMATS,
    SEPARATORS,
    mesh_suffix,
    numbers,
    used_shape,
)
from urdfkit.sources.uris import not_a_file, pybullet_data_path, resolve_uri


def label(el: etree._Element) -> str:
    """How a message names an element: ``<link name='base'>``, long names cut short."""
    name = el.get("name")
    if name is None:
        return f"<{el.tag!s}>"
    if len(name) > 60:  # a 3,000-character name would drown the message
        return f"<{el.tag!s} name={name[:40]!r}... ({len(name)} characters)>"
    return f"<{el.tag!s} name={name!r}>"


class Reference:
    """What a ``filename`` attribute points at, and what is wrong with it, if anything.

    Paths are kept as strings (check resolves one per mesh of every file; a Path costs ~4 us
    to make) and given as Paths by :attr:`path` and :attr:`load_path`. A plain slotted class,
    not a frozen dataclass, for the same reason: a frozen dataclass takes ~1.1 us to make,
    this ~0.35 us. Its fields are not to be assigned after it is made.

    Attributes:
        file: The file it means, or None (an unknown package).
        load: What PyBullet must be given, or None when it cannot be loaded.
        code, level, message: The finding, or ``code`` None when the file is fine.
        stat: ``os.stat`` of ``load`` when it was taken on the way (the common case), for the
            mesh rules not to ask again. Only a plain relative path's reference carries it,
            and then ``load`` is a regular file already noted to :mod:`urdfkit.core.deps`
            and, for a "mesh", named with a mesh suffix (:func:`meshstore.stated` relies on
            both). Not part of the reference's value (equality, hash, repr).
    """

    __slots__ = ("file", "load", "code", "level", "message", "stat")

    def __init__(self, file: str | None, load: str | None, code: str | None = None,
                 level: str = "error", message: str = "",
                 stat: os.stat_result | None = None) -> None:
        self.file = file
        self.load = load
        self.code = code
        self.level = level
        self.message = message
        self.stat = stat

    def _value(self) -> tuple[str | None, str | None, str | None, str, str]:
        return (self.file, self.load, self.code, self.level, self.message)

    def __eq__(self, other: object) -> bool:
        if not isinstance(other, Reference):
            return NotImplemented
        return self._value() == other._value()

    def __hash__(self) -> int:
        return hash(self._value())

    def __repr__(self) -> str:
        return (f"Reference(file={self.file!r}, load={self.load!r}, code={self.code!r}, "
                f"level={self.level!r}, message={self.message!r})")

    @property
    def path(self) -> Path | None:
        """The file it means."""
        return None if self.file is None else Path(self.file)

    @property
    def load_path(self) -> Path | None:
        """What PyBullet must be given."""
        return None if self.load is None else Path(self.load)


def reference(tag: str, fn: str, base: Path | str,
              packages: Mapping[str, Path] | None) -> Reference:
    """Resolve and judge one file reference: the one rule check and the loaders share.

    U702 unknown package, U704 not a regular file (folder, FIFO, device, unreadable), U701
    missing, U703 found only in pybullet_data (which ``p.loadURDF`` searches once a user adds
    it to the search path, so loaders point PyBullet there), U705 a mesh format PyBullet does
    not read.
    """
    if ":" not in fn and not fn.startswith("/") and ".." not in fn:
        # The common case, a plain relative path to a regular file: one stat answers what
        # resolve_uri and not_a_file would ask (the same path, the same notes to deps).
        folder = base if isinstance(base, str) else os.fspath(base)
        name = folder + fn if folder.endswith(SEPARATORS) or not folder else \
            folder + os.sep + fn  # os.path.join for a relative fn, without its checks
        deps.note(name)
        try:
            st: os.stat_result | None = os.stat(name)
        except (OSError, ValueError):
            st = None
        # A regular file's name is its last part, so fn's suffix is the path's.
        if st is not None and stat.S_ISREG(st.st_mode) and (
                tag != "mesh" or mesh_suffix(fn)):
            return Reference(name, name, stat=st)
    label = f"<{tag} filename={fn!r}>"
    base = base if isinstance(base, Path) else _folder_path(base)
    target = resolve_uri(fn, base, packages)
    if target.path is None:
        return Reference(None, None, "U702", "error", f"{label}: {target.problem}")
    path = target.path
    why = not_a_file(path)
    if why == "missing":
        data = pybullet_data_path()
        if target.package is None and data is not None and not_a_file(data / fn) is None:
            return Reference(str(path), str(data / fn), "U703", "warning", f"{label}: not "
                             "beside the file, found only in pybullet_data's search path; make "
                             "the path relative to the file")
        return Reference(str(path), None, "U701", "error", f"{label}: file not found ({path})"
                         f"{_near_miss(path)}; PyBullet refuses a URDF whose mesh is missing")
    if why is not None:
        return Reference(str(path), None, "U704", "error", f"{label}: {path} is {why}; "
                         "PyBullet hangs, aborts or fails on it")
    if tag == "mesh" and path.suffix.lower() not in MESH_FORMATS:
        return Reference(str(path), None, "U705", "error", f"{label}: PyBullet reads "
                         f"{', '.join(MESH_FORMATS)} meshes, not {path.suffix or 'this file'}")
    unseen = _only_through_package_xml(fn, base, target.package, packages)
    if unseen is not None:
        return Reference(str(path), str(path), "U711", "warning", f"{label}: found through "
                         f"the package.xml of {unseen}, a folder not named "
                         f"{target.package!r}; PyBullet knows no package.xml (it looks for "
                         f"{target.package}/... in the file's folder and those above), so a raw "
                         "p.loadURDF of this file refuses it: name the package's folder "
                         f"{target.package!r}, or load through urdfkit")
    return Reference(str(path), str(path))


def mesh_crash(mesh: etree._Element, ref: Reference) -> tuple[str, str] | None:
    """U712, U713: what in the file a ``<mesh>`` names makes PyBullet 3.2.7 crash or hang.

    The one rule ``check`` reports and every loader refuses by
    (:mod:`urdfkit.sources.meshfaults` holds the measured facts). ``ref`` is the mesh's
    :func:`reference`; only the first shape of a link's ``<visual>`` or ``<collision>`` is
    judged, as PyBullet opens no other. U712: COLLADA whose reader PyBullet crashes, visual
    or collision alike. U713: NaN vertices in a collision mesh PyBullet builds a convex hull
    of (not ``concave``, which makes a triangle mesh of it; a visual mesh with NaN loads).
    Cheap: a visual STL or OBJ is not opened, nor is meshfaults imported for it.
    """
    load = ref.load
    if load is None:
        return None
    suffix = mesh_suffix(load)
    geometry = mesh.getparent()
    part = geometry.getparent() if geometry is not None else None
    if (not suffix or geometry is None or part is None or part.tag not in ("visual", "collision")
            or geometry.tag != "geometry" or used_shape(geometry) is not mesh):
        return None
    link = part.getparent()
    robot = link.getparent() if link is not None else None
    if link is None or link.tag != "link" or robot is None or robot.getparent() is not None:
        return None  # PyBullet reads the links of the <robot> alone
    hull = part.tag == "collision" and part.get("concave") is None  # any value: a trimesh
    if suffix != ".dae" and not hull:
        return None
    from urdfkit.sources import meshfaults

    fn = (mesh.get("filename") or "").strip()
    name = f"<mesh filename={fn!r}>"
    if suffix == ".dae":
        why = meshfaults.collada_fault(load, ref.stat)
        if why is not None:
            return ("U712", f"{name}: PyBullet 3.2.7's COLLADA reader crashes (a segfault or "
                    f"an abort) on {load}: the file {why}")
    if hull:
        # PyBullet reads the first three numbers, NaN and infinities included.
        vals = numbers(mesh.get("scale"))
        scale = vals[:3] if vals is not None and len(vals) >= 3 else (1.0, 1.0, 1.0)
        why = meshfaults.hull_fault(load, scale, ref.stat)
        if why is not None:
            return ("U713", f"{name} of the <collision> of {label(link)}: its vertices "
                    f"{why}; PyBullet 3.2.7's convex hull of them segfaults, never returns or "
                    "loads, by where the NaN falls: remove the NaN vertices (a visual mesh may "
                    "keep them)")
    return None


@lru_cache(maxsize=256)
def _folder_path(folder: str) -> Path:
    """``Path(folder)``, made once per folder (bounded).

    Each ``package://`` reference of a file asks (~3 us a Path), and a file's references
    share its folder.
    """
    return Path(folder)


def _near_miss(path: Path, limit: int = 2000) -> str:
    """``"; beside it: 'torso.stl'"``: files beside ``path`` it may have meant, or "".

    Those whose name differs only in case (``Link1.STL`` for ``link1.stl``, which a
    case-insensitive file system forgave), or whose stem is the same with a mesh format's
    suffix: Toyota HSR's hsrb4s.urdf names ``torso_v0/torso.std`` where the folder holds
    ``torso.stl``. Not merely close names: ``link_1.stl`` is another part than ``link_2.stl``.
    Only the missing file's own folder is read (bounded).
    """
    folder = path.parent
    deps.note_listing(folder)
    want, stem = path.name.lower(), path.stem.lower()
    found: list[str] = []
    try:
        with os.scandir(folder) as it:
            for count, entry in enumerate(it):
                if count >= limit:
                    break
                name = entry.name.lower()
                root, suffix = os.path.splitext(name)
                if (name == want or (root == stem and suffix in MESH_FORMATS)) \
                        and entry.is_file():
                    found.append(entry.name)
    except OSError:
        return ""
    return "; beside it: " + " or ".join(repr(n) for n in sorted(found)) if found else ""


def _only_through_package_xml(fn: str, base: Path, package: str | None,
                              packages: Mapping[str, Path] | None) -> Path | None:
    """The package folder a ``package://`` reference was found in by its package.xml alone.

    None when PyBullet's own search finds the file too, or when the user mapped the package
    (``--package``, ``--package-path``, ROS_PACKAGE_PATH: urdfkit's loaders use the map, and
    a user who gave it knows). Measured on poppy_ergo_jr_description unpacked under another
    folder name: urdfkit loaded it, raw PyBullet said "Cannot load URDF file."
    """
    if package is None or not fn.startswith("package://"):
        return None
    try:
        if packages is not None and package in packages:
            return None
    except OSError:
        return None
    from urdfkit.sources.uris import find_package, pybullet_search

    folder = find_package(package, base)
    if folder is None or folder.name == package:
        return None  # PyBullet finds NAME/rest from the folder above
    if pybullet_search(fn[len("package://"):], base) is not None:
        return None
    return folder
