"""Mesh mass properties as check asks for them: the lookup, the cache entries, a run's pack.

Loaded with the check path: ``check`` asks once per mesh of every file, and a warm run
answers every one of them from memory or the run's pack, so this lookup is the mesh rules'
whole cost then. Reading and integrating a mesh, on a miss, is
:mod:`urdfkit.sources.meshes` (imported only then: it loads numpy and its patterns).
"""

from __future__ import annotations

import math
import os
import struct
from collections.abc import Sequence
from pathlib import Path

from urdfkit.core import deps
from urdfkit.model.spec import mesh_suffix
from urdfkit.sources.cache import cache_dir, read_entry, write_entry
from urdfkit.sources.meshdata import (  # noqa: F401 - named here too
    _ENTRY,
    CONCAVE_FRACTION,
    MAX_MESH_BYTES,
    Integrals,
    MeshProperties,
)

try:  # hashlib's own blake2b, without loading OpenSSL for the other digests (2.5 ms)
    from _blake2 import blake2b
except ImportError:  # pragma: no cover - a Python built without it
    from hashlib import blake2b


def _cache_dir() -> Path | None:
    """:func:`cache_dir`, worked out once per value of the variables it reads."""
    env = (os.environ.get("URDFKIT_CACHE_DIR"), os.environ.get("XDG_CACHE_HOME"),
           os.environ.get("HOME"))
    if env not in _CACHE_DIRS:
        _CACHE_DIRS[env] = cache_dir()
    return _CACHE_DIRS[env]


_CACHE_DIRS: dict[tuple[str | None, ...], Path | None] = {}

#: The entries' folder, named for how their values are computed: bump it (and _PACKS) whenever
#: a stored value would come out differently, or entries written before go on being read. The
#: hull-volume convexity test (issue 41) changed depths without a bump: a cache filled before it
#: gave pr2's l_finger_collision.stl a depth of 0.0972 m where a cold run says 0.0501 m.
#: meshes-7: a COLLADA geometry reads its own sources first (jaxon's repeated ids, issue 48).
_FOLDER = "meshes-7"
_MEMORY: dict[str, Integrals | None] = {}
_MISSING = object()


def properties(path: str | os.PathLike[str],
               scale: tuple[float, float, float] = (1.0, 1.0, 1.0), *,
               concavity: bool = False) -> MeshProperties | None:
    """Mass properties of an STL or OBJ mesh, or None if unreadable, unsupported or empty.

    The concavity depth costs as much as the rest together and only the concave-mesh rules
    read it, so it is worked out when ``concavity`` asks for it, once per mesh (the cache
    entry is then rewritten with it); otherwise it may be NaN.
    """
    name = os.fspath(path)
    if not mesh_suffix(name):
        return None
    deps.note(name)
    try:
        st = os.stat(name)
    except (OSError, ValueError):
        return None
    return stated(name, st, scale, concavity=concavity)


def stated(name: str, st: os.stat_result,
           scale: tuple[float, float, float] = (1.0, 1.0, 1.0), *,
           concavity: bool = False) -> MeshProperties | None:
    """:func:`properties` of a mesh whose caller has already taken its first steps.

    For a :class:`urdfkit.sources.guard.Reference` that carries a ``stat`` (check asks once
    per mesh of every file): ``st`` is ``os.stat(name)``, and the reference has already
    noted ``name`` to :mod:`urdfkit.core.deps` (under the same recording: a file's rules run
    within one call) and found a mesh suffix on it, so neither is done again here.
    """
    if st.st_size > MAX_MESH_BYTES:
        return None
    # An absolute name is its own key (normalizing it would cost more than the rare second
    # entry a spelling like "a/../m.stl" makes).
    where = name if name.startswith(_ROOT) else os.path.abspath(name)
    key = where + "".join(f"\0{n}" for n in deps.version(st))
    found = _MEMORY.get(key, _MISSING)
    if found is _MISSING or (concavity and isinstance(found, Integrals)
                             and math.isnan(found.concavity)):
        keep = deps.settled(st)
        found = _MEMORY[key] = _integrals(Path(name), mesh_suffix(name), key, concavity, keep)
    else:
        keep = key in USED or deps.settled(st)
    assert found is None or isinstance(found, Integrals)
    if keep:  # packed for the next run
        USED[key] = found
    return found.scaled(scale) if found is not None else None


# --------------------------------------------------------------------------- a run's pack
# One check run reads every mesh's entry on its own: a thousand small files. The run's pack
# keeps the entries it used in one file, read once at the next run over the same paths. A
# pack entry is keyed like any entry (path, size, mtime, inode), so an edited mesh misses it
# and is looked up as before; a pack that is damaged in any byte is ignored whole.

_PACKS = "mesh-packs-4"
_PACK_MAGIC = b"MP2\n"
#: Each pack entry: its key's length, its entry's length; then the two.
_PACK_HEAD = struct.Struct("<IH")
#: The entry of a path that is no mesh (unreadable, unsupported or empty).
_NO_MESH = _ENTRY + b"-"
#: Packs kept; the oldest beyond this are removed when a new one is written.
MAX_PACKS = 64
#: The entries this process used (its own, and its workers' once merged), by key.
USED: dict[str, Integrals | None] = {}
_PACKED: set[str] = set()


def _pack_path(paths: Sequence[str]) -> Path | None:
    folder = cache_dir()
    if folder is None:
        return None
    h = blake2b(_PACK_MAGIC, digest_size=20)
    for p in (os.getcwd(), *paths):
        h.update(os.fsencode(os.path.abspath(p)) + b"\0")
    return folder / _PACKS / h.hexdigest()


def load_pack(paths: Sequence[str]) -> int:
    """Read the pack of the last run over ``paths`` into memory; how many entries it held."""
    path = _pack_path(paths)
    raw = read_entry(path) if path is not None else None
    if raw is None or not raw.startswith(_PACK_MAGIC) or len(raw) < len(_PACK_MAGIC) + 16:
        return 0
    body, check = raw[len(_PACK_MAGIC):-16], raw[-16:]
    if blake2b(body, digest_size=16).digest() != check:
        return 0  # damaged: trust none of it
    found: dict[str, Integrals | None] = {}
    at, end = 0, len(body)
    head, unpack = _PACK_HEAD.unpack_from, Integrals.unpack
    try:
        while at < end:
            klen, elen = head(body, at)
            at += 6
            key = body[at:at + klen].decode("utf-8", "surrogateescape")
            at += klen
            entry = body[at:at + elen]
            at += elen
            found[key] = None if entry == _NO_MESH else unpack(entry)
    except (ValueError, struct.error):
        return 0
    for key, value in found.items():
        _MEMORY.setdefault(key, value)
    _PACKED.clear()
    _PACKED.update(found)
    return len(found)


def save_pack(paths: Sequence[str]) -> bool:
    """Write the entries this run used as the pack for ``paths``; True if written.

    Nothing is written when the last pack holds exactly these entries.
    """
    if set(USED) == _PACKED:
        return False
    path = _pack_path(paths)
    if path is None:
        return False
    parts = []
    for key, value in USED.items():
        k = key.encode("utf-8", "surrogateescape")
        e = value.pack() if value is not None else _NO_MESH
        parts.append(_PACK_HEAD.pack(len(k), len(e)) + k + e)
    body = b"".join(parts)
    if not write_entry(path, _PACK_MAGIC + body + blake2b(body, digest_size=16).digest()):
        return False
    try:
        with os.scandir(path.parent) as it:
            packs = sorted((e.stat().st_mtime_ns, e.path) for e in it
                           if e.is_file(follow_symlinks=False))
        for _, old in packs[:-MAX_PACKS]:
            os.unlink(old)
    except OSError:
        pass
    return True


def _integrals(path: Path, suffix: str, key: str, concavity: bool,
               keep: bool) -> Integrals | None:
    """The integrals of a mesh missing from memory: its cache entry, else the mesh read.

    ``keep``: whether the mesh is settled (:func:`urdfkit.core.deps.settled`); one changed
    within the clock's grain is read and not written to the cache.
    """
    import hashlib

    from urdfkit.sources import meshes  # the readers (numpy), on a miss only

    folder = _cache_dir()
    entry = (folder / _FOLDER / hashlib.sha1(key.encode("utf-8", "surrogateescape")
                                                ).hexdigest()) if folder else None
    if entry is not None:
        data = read_entry(entry)
        if data == _ENTRY + b"-":
            return None
        if data is not None:
            try:
                cached = Integrals.unpack(data)
            except (ValueError, struct.error):
                pass  # a damaged entry: read the mesh again and rewrite it
            else:
                if not (concavity and math.isnan(cached.concavity)):
                    return cached
    found = meshes.read_integrals(path, suffix, concavity=concavity)
    if entry is not None and keep:
        write_entry(entry, found.pack() if found is not None else _ENTRY + b"-")
    return found


#: An absolute path starts with this (``os.path.isabs`` on POSIX, without its call).
_ROOT = os.sep if os.sep == "/" else ("/", os.sep)
