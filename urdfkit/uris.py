"""Where a URDF's file references point: ``package://``, ``file://`` and relative paths.

One resolver, used by loading (:mod:`urdfkit.resolve`, which rewrites the references to
absolute paths for PyBullet) and by ``urdfkit check`` (the mesh rules), so the two never
disagree about which file a ``<mesh filename=...>`` means.

ROS layout without ROS: ``package://NAME/rest`` is looked up in ``--package NAME=PATH``, else
in the first folder at or above the URDF's that is named NAME, holds a NAME/ folder, or holds a
``package.xml`` declaring ``<name>NAME</name>``. ``package:///rest`` (an empty package name, seen
in real files) is looked up as PyBullet does: ``rest`` in the file's folder and up to five
folders above it.
"""

from __future__ import annotations

import os
from collections.abc import Mapping
from dataclasses import dataclass
from pathlib import Path

#: How many folders above the file PyBullet searches for a ``package://`` path.
PYBULLET_SEARCH_DEPTH = 5


def pybullet_data_path() -> Path | None:
    """The folder of PyBullet's bundled models, if pybullet_data is installed."""
    try:
        import pybullet_data
    except ImportError:  # pragma: no cover - ships with pybullet
        return None
    return Path(pybullet_data.getDataPath())


def find_package(name: str, start: Path) -> Path | None:
    """The folder of ROS package ``name``, found by walking up from ``start``; None if absent."""
    for folder in [start, *start.parents]:
        if folder.name == name:
            return folder
        try:
            if (folder / name).is_dir():
                return folder / name
            pkg = folder / "package.xml"
            if pkg.is_file():
                text = pkg.read_text("utf-8", "replace")
                if f"<name>{name}</name>" in text:
                    return folder
        except OSError:  # unreadable folders, names too long: not this one
            continue
    return None


@dataclass(frozen=True)
class Target:
    """Where a file reference points.

    Attributes:
        path: The file it names, or None when it cannot be resolved.
        package: The ROS package it names (``package://`` only), else None.
        problem: Why ``path`` is None: what the user should do.
    """

    path: Path | None
    package: str | None = None
    problem: str | None = None


def resolve_uri(uri: str, base: Path, packages: Mapping[str, Path] | None = None) -> Target:
    """Resolve a ``filename`` attribute written in a URDF whose folder is ``base``."""
    uri = uri.strip()
    if uri.startswith("package://"):
        pkg, _, rest = uri[len("package://"):].partition("/")
        if not pkg:  # package:///rest: PyBullet searches the file's folder and five above
            for folder in [base, *list(base.parents)[:PYBULLET_SEARCH_DEPTH]]:
                if _is_file(folder / rest):
                    return Target(folder / rest)
            return Target(None, "", f"{uri!r} has no package name and {rest!r} is not in the "
                          f"file's folder or the {PYBULLET_SEARCH_DEPTH} above it")
        found = (packages or {}).get(pkg) or find_package(pkg, base)
        if found is None:
            return Target(None, pkg, f"package {pkg!r} not found near the file; map it with "
                          f"`packages` ({pkg}=PATH)")
        return Target(found / rest, pkg)
    if uri.startswith("file://"):
        uri = uri[len("file://"):]
    path = Path(uri)
    return Target(path if path.is_absolute() else base / path)


def not_a_file(path: Path) -> str | None:
    """Why ``path`` cannot be read as a mesh or texture, or None if it is a regular file.

    Only ``stat`` is called, never ``open``: opening a FIFO blocks forever, reading a device
    never ends, and PyBullet does both (a directory makes it abort with std::bad_alloc).
    ``"missing"`` means nothing is there (PyBullet then warns and draws nothing).
    """
    import errno
    import stat

    try:
        mode = os.stat(path).st_mode
    except FileNotFoundError:
        return "missing"
    except OSError as e:
        reasons = {errno.ENAMETOOLONG: "a path with a component longer than the file system "
                   "allows", errno.EACCES: "unreadable (permission denied on the way)",
                   errno.ELOOP: "a symlink loop", errno.ENOTDIR: "missing"}
        return reasons.get(e.errno or 0, f"unreadable ({os.strerror(e.errno or 0)})")
    except ValueError:  # an embedded NUL byte
        return "a path holding a NUL byte"
    if stat.S_ISREG(mode):
        return None
    for test, what in ((stat.S_ISDIR, "a directory"), (stat.S_ISFIFO, "a FIFO (named pipe)"),
                       (stat.S_ISCHR, "a character device"), (stat.S_ISBLK, "a block device"),
                       (stat.S_ISSOCK, "a socket")):
        if test(mode):
            return what
    return "not a regular file"


def _is_file(path: Path) -> bool:
    try:
        return os.path.isfile(path)
    except (OSError, ValueError):
        return False
