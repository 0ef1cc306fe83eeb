"""Built-in templates as files: drive's car and ground, and a template name given as a robot file.

``urdfkit joints simplecar`` reads the template built with its defaults, as ``drive`` drives
it: built once into the cache folder (keyed by the template's source, the parameters and the
urdfkit version), or, with caching off, into a temp folder removed at exit. Nothing is ever
written to the user's folder.
"""

from __future__ import annotations

import re
from collections.abc import Mapping
from pathlib import Path

from urdfkit.sources.cache import cache_dir, write_entry

#: What a template's name looks like (a file name without folder or suffix).
_NAME = re.compile(r"[a-z][a-z0-9_]*")
_built: dict[str, Path] = {}


def builtin_file(name: str, params: Mapping[str, str] | None = None) -> Path | None:
    """A built-in template, built with ``params``, from the cache (built on a miss).

    Expanding simplecar with xacro and checking it through the builder costs ~0.07 s of CPU,
    as much as 400 physics steps, on every ``urdfkit drive``. The result depends only on the
    template's source, the parameters and the urdfkit version, which make the cache key; a
    stale or broken entry can therefore not be hit. Returns None (build into a temp folder
    instead) when the cache cannot be written. Nothing is ever written to the user's folder.
    """
    import zlib

    from urdfkit import __version__
    from urdfkit.model.templatedir import template_dir

    folder = cache_dir()
    if folder is None:
        return None
    # The package folder directly: importlib.resources (and the zipfile it imports) would
    # cost more than the lookup saves. A zipped install simply skips the cache.
    try:
        source = (template_dir() / f"{name}.urdf.xacro").read_bytes()
    except (OSError, TypeError):
        return None
    given = "".join(f"{k}={v};" for k, v in sorted((params or {}).items())).encode()
    key = f"{zlib.crc32(source):08x}{len(source):x}-{zlib.crc32(given):08x}-{__version__}" \
        if given else f"{zlib.crc32(source):08x}{len(source):x}-{__version__}"
    path = folder / f"{name}-{key}.urdf"
    if path.is_file():
        return path
    from urdfkit.model.catalog import build_template

    data = build_template(name, params).to_bytes()
    return path if write_entry(path, data) else None


def template_names() -> list[str]:
    """The built-in templates' names, from their files (the catalog is not imported)."""
    from urdfkit.model.templatedir import template_dir

    try:
        return sorted(p.name.removesuffix(".urdf.xacro")
                      for p in template_dir().glob("*.urdf.xacro"))
    except OSError:  # pragma: no cover - the package's own folder
        return []


def template_file(name: str) -> Path | None:
    """The built-in template ``name`` built with its defaults, as a file; None if no such.

    Only a bare name (``simplecar``) is a template's: a path or a name with a suffix never is.
    """
    if not _NAME.fullmatch(name) or name not in template_names():
        return None
    cached = builtin_file(name)
    if cached is not None:
        return cached
    if name not in _built:  # caching off: a temp folder, removed at exit
        import atexit
        import shutil
        import tempfile

        from urdfkit.model.catalog import build_template

        folder = tempfile.mkdtemp(prefix="urdfkit-template-")
        atexit.register(shutil.rmtree, folder, True)
        _built[name] = build_template(name).write(Path(folder) / f"{name}.urdf")
    return _built[name]
