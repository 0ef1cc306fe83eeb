"""Where a URDF's file references point: ``package://``, ``file://`` and relative paths.

One resolver, used by loading (:mod:`urdfkit.sources.resolve`, which rewrites the references to
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
import re
from collections.abc import Iterator, Mapping, Sequence
from contextlib import contextmanager
from pathlib import Path
from typing import NamedTuple

from urdfkit.core import deps
from urdfkit.core.errors import ParameterError


def pybullet_search(rest: str, base: Path) -> Path | None:
    """Where PyBullet 3.2.7 finds a mesh path: the file's folder, then every folder above it.

    Measured: a relative ``filename`` (and a ``package://`` or ``model://`` one, with just
    that prefix dropped: ``package://pkg/m.stl`` is looked for as ``pkg/m.stl``) is tried in
    the URDF's folder and then in each folder above it, deepest first, up to the root (a mesh
    twelve folders up is found; measured on every depth from 0 to 12); the first that exists
    wins. PyBullet then also tries ``.``, ``..`` and ``../..`` of the working directory, which
    urdfkit does not: a result that depends on where the command runs would differ between
    two runs of it.
    """
    if not rest:
        return None
    for folder in [base, *base.parents]:
        if _is_file(folder / rest):
            return folder / rest
    return None


def pybullet_data_path() -> Path | None:
    """The folder of PyBullet's bundled models, if pybullet_data is installed."""
    try:
        import pybullet_data
    except ImportError:  # pragma: no cover - ships with pybullet
        return None
    return Path(pybullet_data.getDataPath())


_PACKAGE_NAME = re.compile(rb"<name>\s*([^<\s]+)\s*</name>")
#: Folders a package search never descends into (build trees, VCS, caches).
_SKIP_DIRS = frozenset({".git", ".hg", ".svn", "build", "install", "log", "__pycache__",
                        "node_modules", ".venv", "venv"})


def package_xml_name(folder: str) -> str | None:
    """The ``<name>`` in ``folder/package.xml``, or None."""
    try:
        with open(os.path.join(folder, "package.xml"), "rb") as f:
            head = f.read(65536)
    except OSError:
        return None
    m = _PACKAGE_NAME.search(head)
    return m.group(1).decode("utf-8", "replace") if m else None


class PackageIndex(Mapping[str, Path]):
    """Where ROS packages are, without ROS, in the order a user expects.

    1. ``explicit``: ``NAME=PATH`` pairs (``--package``);
    2. ``search``: folders searched recursively for a ``package.xml`` whose ``<name>`` is the
       package (``--package-path``);
    3. ``ROS_PACKAGE_PATH`` (searched the same way) and ``AMENT_PREFIX_PATH``
       (``PREFIX/share/NAME``), unless ``env`` is False.

    :func:`resolve_uri` and xacro's ``$(find NAME)`` then fall back to walking up from the
    file (:func:`find_package`). Folders are scanned once, lazily, on the first lookup that
    the explicit pairs do not answer; a package folder is not searched further down.
    """

    def __init__(self, explicit: Mapping[str, Path] | None = None,
                 search: Sequence[str | Path] = (), env: bool = True):
        self.explicit = {k: Path(v) for k, v in (explicit or {}).items()}
        self.search = [str(p) for p in search]
        if env:
            self.search += [p for p in os.environ.get("ROS_PACKAGE_PATH", "").split(os.pathsep)
                            if p]
            self.search += [os.path.join(p, "share") for p in
                            os.environ.get("AMENT_PREFIX_PATH", "").split(os.pathsep) if p]
        self._found: dict[str, Path] | None = None

    def _scan(self) -> dict[str, Path]:
        """Every package under the search folders, following symlinked folders.

        A workspace often links its packages into ``src/`` (``ln -s ~/repos/pkg src/``);
        catkin's package search (catkin_pkg, ``os.walk(followlinks=True)``) and rospack
        follow such links, so this does too. Each real folder is entered once, so a link
        back up the tree ends the walk there instead of looping.
        """
        if self._found is None:
            found: dict[str, Path] = {}
            seen: set[str] = set()
            for root in self.search:
                stack = [root]
                while stack:
                    folder = stack.pop()
                    real = os.path.realpath(folder)
                    if real in seen:
                        continue
                    seen.add(real)
                    name = package_xml_name(folder)
                    if name is not None:
                        found.setdefault(name, Path(folder))
                        continue  # packages do not nest
                    try:
                        with os.scandir(folder) as it:
                            subdirs = sorted(e.path for e in it if e.name not in _SKIP_DIRS
                                             and not e.name.startswith(".")
                                             and e.is_dir(follow_symlinks=True))
                    except OSError:
                        continue
                    stack.extend(reversed(subdirs))
            self._found = found
        return self._found

    def __getitem__(self, name: str) -> Path:
        if name in self.explicit:
            return self.explicit[name]
        return self._scan()[name]

    def __iter__(self) -> Iterator[str]:
        return iter({**self._scan(), **self.explicit})

    def __len__(self) -> int:
        return len({**self._scan(), **self.explicit})

    def to_json(self) -> dict[str, object]:
        """What a subprocess needs to rebuild this index (the xacro worker)."""
        return {"explicit": {k: str(v) for k, v in self.explicit.items()},
                "search": self.search}

    @classmethod
    def from_json(cls, data: Mapping[str, object]) -> PackageIndex:
        """The inverse of :meth:`to_json` (the environment was read by the parent)."""
        explicit = data.get("explicit") or {}
        search = data.get("search") or []
        assert isinstance(explicit, Mapping) and isinstance(search, list)
        return cls(explicit, search, env=False)


def find_package(name: str, start: Path) -> Path | None:
    """The folder of ROS package ``name``, found by walking up from ``start``; None if absent.

    Within :func:`settled` the answer for a (name, folder) is worked out once: check asks
    for each ``package://`` mesh of every file, and each walk up to ``/`` takes ~90 us. The
    paths it looked at are noted again on every answer, for the result cache.
    """
    memo = _SETTLED[-1] if _SETTLED else None
    key = (name, str(start))
    hit = memo.get(key) if memo is not None else None
    if hit is None:
        looked: list[Path] = []
        hit = (_find_package(name, start, looked), looked)
        if memo is not None:
            memo[key] = hit
    for path in hit[1]:
        deps.note(path)
    return hit[0]


def _find_package(name: str, start: Path, looked: list[Path]) -> Path | None:
    for folder in [start, *start.parents]:
        if folder.name == name:
            return folder
        try:
            looked += (folder / name, folder / "package.xml")
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


#: The memo of each :func:`settled` block, innermost last.
_SETTLED: list[dict[tuple[str, str], tuple[Path | None, list[Path]]]] = []


@contextmanager
def settled() -> Iterator[None]:
    """A block in which the file system is taken as settled: package lookups are kept.

    For one ``check`` run, which writes no package.xml. Not for ``view``, whose reloads must
    see a package that appeared since.
    """
    _SETTLED.append({})
    try:
        yield
    finally:
        _SETTLED.pop()


class Target(NamedTuple):
    """Where a file reference points.

    Attributes:
        path: The file it names, or None when it cannot be resolved.
        package: The ROS package it names (``package://`` only), else None.
        problem: Why ``path`` is None: what the user should do.
    """

    path: Path | None
    package: str | None = None
    problem: str | None = None


def climbs_out(rest: str) -> bool:
    """Whether a relative path leaves the folder it starts from (its ``..`` go above it).

    Read as written, not through symlinks: ``meshes/../meshes/a.stl`` stays, ``../a.stl``
    and ``a/../../b.stl`` leave.
    """
    depth = 0
    for part in rest.replace("\\", "/").split("/"):
        if part == "..":
            depth -= 1
            if depth < 0:
                return True
        elif part not in ("", "."):
            depth += 1
    return False


def _package_root(base: Path) -> Path | None:
    """The nearest folder at or above ``base`` with a ``package.xml``, or None."""
    for folder in [base, *base.parents]:
        if _is_file(folder / "package.xml"):
            return folder
    return None


def _climbing(uri: str, base: Path) -> Target | None:
    """A reference that climbs out of its package with ``..``, refused; else None.

    ``package://NAME/rest`` (and ``model://``) whose ``rest`` climbs above the package; a
    relative path that leaves the package the file is in (a file in no package has none to
    leave). An absolute path is taken as written.
    """
    scheme, sep, stripped = uri.partition("://")
    if sep and scheme in ("package", "model"):
        pkg, _, rest = stripped.partition("/")
        if not climbs_out(rest):
            return None
        return Target(None, pkg if scheme == "package" else None,
                      f"{uri!r} climbs out of {scheme} {pkg!r} with '..'; nothing from outside "
                      "a package is read: name the file inside its package")
    if sep or ".." not in Path(uri).parts or Path(uri).is_absolute():
        return None
    root = _package_root(base)
    if root is None:
        return None
    target = os.path.normpath(base / uri)
    if target == str(root) or target.startswith(str(root).rstrip(os.sep) + os.sep):
        return None
    return Target(None, None, f"{uri!r} climbs out of package "
                  f"{package_xml_name(str(root)) or root.name!r} ({root}) with '..'; nothing "
                  "from outside a package is read: move the file into it, or name its "
                  "package with package://")


def resolve_uri(uri: str, base: Path, packages: Mapping[str, Path] | None = None) -> Target:
    """Resolve a ``filename`` attribute written in a URDF whose folder is ``base``.

    One rule for every command: nothing from outside a package. A ``package://NAME/rest``
    (or ``model://``) whose ``rest`` climbs above the package with ``..``, and a relative
    path that climbs out of the package the file is in, resolve to nothing (``problem``
    says why); an absolute path is taken as written.
    """
    uri = uri.strip()
    if ".." in uri:
        climbing = _climbing(uri, base)
        if climbing is not None:
            return climbing
    if uri.startswith("package://"):
        stripped = uri[len("package://"):]
        pkg, _, rest = stripped.partition("/")
        if not pkg:  # package:///rest: PyBullet searches the file's folder and all above
            found_at = pybullet_search(rest, base)
            if found_at is not None:
                return Target(found_at)
            return Target(None, "", f"{uri!r} has no package name and {rest!r} is not in the "
                          "file's folder or any folder above it")
        found = (packages or {}).get(pkg) or find_package(pkg, base)
        if found is None:
            # Not a package urdfkit can find; PyBullet drops "package://" and searches the
            # file's folder and those above for NAME/rest: follow it when that finds it.
            found_at = pybullet_search(stripped, base)
            if found_at is not None:
                return Target(found_at, pkg)
            return Target(None, pkg, f"package {pkg!r} not found near the file (nor "
                          f"{stripped!r} in its folder or any above, where PyBullet looks); "
                          f"map it with `packages` ({pkg}=PATH)")
        path = found / rest
        if not _is_file(path):
            # The package's folder lacks it (package.xml at a repository's root, meshes under
            # share/NAME/): PyBullet, which knows no packages, may still find it above.
            found_at = pybullet_search(stripped, base)
            if found_at is not None:
                return Target(found_at, pkg)
        return Target(path, pkg)
    if uri.startswith("model://"):  # Gazebo's; PyBullet drops the prefix and searches
        stripped = uri[len("model://"):]
        return Target(pybullet_search(stripped, base) or base / stripped)
    if uri.startswith("file://"):
        uri = uri[len("file://"):]
    path = Path(uri)
    if path.is_absolute():
        return Target(path)
    if not _is_file(base / path):
        # PyBullet looks a relative path up in every folder above the file too.
        found_at = pybullet_search(uri, base)
        if found_at is not None:
            return Target(found_at)
    return Target(base / path)


def rebased(filename: str, base: Path, folder: Path) -> str | None:
    """A relative ``filename`` of a URDF in ``base``, rewritten for a copy in ``folder``.

    What PyBullet opens for it from ``base`` (:func:`pybullet_search`: that folder, then
    those above), named from ``folder``: relative, unless that would climb out of a package
    ``folder`` is in (which every loader refuses), then absolute. None when nothing needs to
    change: not a plain relative path (``package://``, ``file://``, absolute), a file PyBullet
    does not find from ``base`` either (``check`` reports it), or one it finds from ``folder``
    as it is.
    """
    fn = filename.strip()
    if not fn or "://" in fn or os.path.isabs(fn):
        return None
    found = pybullet_search(fn, base)
    if found is None:
        return None
    real = os.path.realpath(found)
    there = pybullet_search(fn, folder)
    if there is not None and os.path.realpath(there) == real:
        return None
    home = Path(os.path.realpath(folder))
    new = Path(os.path.relpath(real, home)).as_posix()
    return real if _climbing(new, home) is not None else new


def not_a_file(path: Path) -> str | None:
    """Why ``path`` cannot be read as a mesh or texture, or None if it is a regular file.

    Only ``stat`` is called, never ``open``: opening a FIFO blocks forever, reading a device
    never ends, and PyBullet does both (a directory makes it abort with std::bad_alloc).
    ``"missing"`` means nothing is there (PyBullet then warns and draws nothing).
    """
    import errno
    import stat

    deps.note(path)  # check's result cache: a mesh that appears or changes counts
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
    deps.note(path)
    try:
        return os.path.isfile(path)
    except (OSError, ValueError):
        return False


def parse_packages(items: list[str] | None,
                   package_paths: list[str] | None = None) -> PackageIndex:
    """Where packages are, as a :class:`urdfkit.sources.uris.PackageIndex`.

    ``NAME=PATH`` items (``--package``) first, then ``package_paths`` (``--package-path``),
    then ROS_PACKAGE_PATH and AMENT_PREFIX_PATH.
    """
    out: dict[str, Path] = {}
    for item in items or []:
        name, sep, path = item.partition("=")
        if not sep or not name or not path:
            raise ParameterError(f"`packages` expects NAME=PATH, got {item!r}", param="packages")
        if not Path(path).is_dir():
            raise ParameterError(f"`packages` {name}: folder {path!r} does not exist",
                                 param="packages")
        out[name] = Path(path).resolve()
    for folder in package_paths or []:
        if not Path(folder).is_dir():
            raise ParameterError(f"`package_paths`: folder {folder!r} does not exist",
                                 param="package_paths")
    return PackageIndex(out, [str(Path(p).resolve()) for p in package_paths or []])
