"""urdfkit's on-disk cache: one folder, small entries, written atomically, never required.

Two things are cached: built default templates (``drive``) and the mass properties of mesh
files (``check``). Every entry's name is its key, made of everything its value depends on,
so a stale entry cannot be hit; a cache that cannot be read or written is simply skipped.
``URDFKIT_CACHE_DIR`` names another folder, or turns the cache off when empty.
"""

from __future__ import annotations

import os
from pathlib import Path


def cache_dir() -> Path | None:
    """The cache folder, or None when ``URDFKIT_CACHE_DIR=""`` turns caching off."""
    env = os.environ.get("URDFKIT_CACHE_DIR")
    if env is not None:
        return Path(env) if env else None
    base = os.environ.get("XDG_CACHE_HOME") or os.path.join(os.path.expanduser("~"), ".cache")
    return Path(base) / "urdfkit"


#: No entry of ours is near this; a larger file in the cache folder is not ours.
MAX_ENTRY_BYTES = 64 * 1024 * 1024


def read_entry(path: Path) -> bytes | None:
    """An entry's bytes, or None when it is absent or unreadable."""
    from urdfkit.core.errors import InputError
    from urdfkit.model.xmlio import read_regular

    try:  # a FIFO planted in the cache folder must not hang a run
        return read_regular(path, limit=MAX_ENTRY_BYTES, kind="cache entry", track=False)
    except InputError:
        return None


def write_entry(path: Path, data: bytes) -> bool:
    """Write an entry atomically (concurrent runs never see half of one); False on failure."""
    try:
        path.parent.mkdir(parents=True, exist_ok=True)
        import tempfile  # here: with shutil, bz2 and lzma, 3 ms of every check start-up

        fd, tmp = tempfile.mkstemp(prefix=f".{path.name[:40]}.", suffix=".tmp", dir=path.parent)
        try:
            with os.fdopen(fd, "wb") as f:
                f.write(data)
            os.replace(tmp, path)
        except BaseException:
            os.unlink(tmp)
            raise
    except OSError:
        return False
    return True
