"""``check``'s result cache: a file's findings, reused while nothing they came from changed.

As ruff and mypy keep theirs. An entry is found by a key made of everything that decides the
findings and is known before checking: the file's content (BLAKE2b), its absolute path and the
name it is shown by, urdfkit's own code (the size and mtime of each of its modules, so an edit
or an upgrade misses), the options that change findings (``--arg``, ``--package``,
``--no-exec``, ``--physics``) and the environment that finds packages (ROS_PACKAGE_PATH,
AMENT_PREFIX_PATH, URDFKIT_NO_EXEC). ``--select`` and ``--ignore`` are not in it: the entry
keeps every finding and the filter runs after.

What is only known after checking is in the entry: every path the check read or looked for
(:mod:`urdfkit.core.deps`: xacro includes and YAML, meshes, ``package.xml`` files, the places a
missing mesh was sought) with its ``stat`` signature. A hit is used only if each is unchanged,
so a change to any dependency invalidates exactly the files that used it.

An entry is written atomically and read as untrusted: anything that does not parse, or has
the wrong shape, is a miss (and is rewritten). Results that depend on the machine's load (a
xacro expansion stopped by its time or memory limit) are never stored. The folder is capped
(:data:`MAX_BYTES`): past it, the oldest entries are removed. ``--no-cache`` or
``URDFKIT_CACHE_DIR=`` turns the cache off.
"""

from __future__ import annotations

import json
import os
import stat
import time
from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import Any

from urdfkit.core import deps

try:  # the BLAKE2 module alone: hashlib would also load OpenSSL (~2 ms of every cached run)
    from _blake2 import blake2b
except ImportError:  # pragma: no cover - a Python built without it
    from hashlib import blake2b
from urdfkit.core.finding import Finding
from urdfkit.sources.cache import MAX_ENTRY_BYTES, cache_dir, write_entry

#: The largest file keyed (:data:`urdfkit.model.xmlio.MAX_FILE_BYTES`, not imported: lxml is slow
#: to load, and a cached run never needs it). A larger file is checked uncached.
MAX_FILE_BYTES = 32 * 1024 * 1024
#: The subfolder of the cache folder.
FOLDER = "check-v1"
#: The most the result cache may hold; past it the oldest entries go, down to 3/4 of it.
MAX_BYTES = 64 * 1024 * 1024
#: Environment variables that change how packages are found or whether xacro runs.
ENV_KEYS = ("ROS_PACKAGE_PATH", "AMENT_PREFIX_PATH", "URDFKIT_NO_EXEC")
#: Messages of results that say more about the machine than the file: never stored.
TRANSIENT = ("took longer than", "ran out of memory", "was killed", "ran out of CPU time",
             "died of signal")
_FIELDS = ("code", "level", "message", "file", "line", "origin")

_code_key: str | None = None


def code_key() -> str:
    """A digest of urdfkit's own modules (name, size, mtime): a new version or an edit misses."""
    global _code_key
    if _code_key is None:
        from urdfkit import __version__

        h = blake2b(__version__.encode(), digest_size=16)
        package = Path(__file__).parents[1]
        folders = [os.fspath(package)]
        while folders:  # the package and its sub-packages, in a fixed order
            folder = folders.pop()
            with os.scandir(folder) as it:
                for entry in sorted(it, key=lambda e: e.name):
                    if entry.name.endswith(".py"):
                        st = entry.stat()
                        name = os.path.relpath(entry.path, package)
                        h.update(f"{name}\0{st.st_size}\0{st.st_mtime_ns}\0".encode())
                    elif entry.is_dir() and not entry.name.startswith(("_", ".")):
                        folders.append(entry.path)
        _code_key = h.hexdigest()
    return _code_key


def _read_regular(path: str, limit: int) -> bytes | None:
    """A regular file's bytes, or None (absent, special, unreadable or over ``limit``).

    :func:`urdfkit.model.xmlio.read_regular`'s rules without its messages or pathlib: this runs
    twice per file on a warm re-run, where it is most of the cost.
    """
    try:
        fd = os.open(path, os.O_RDONLY | os.O_NONBLOCK | os.O_CLOEXEC)
    except (OSError, ValueError):
        return None
    try:
        st = os.fstat(fd)
        if not stat.S_ISREG(st.st_mode) or st.st_size > limit:
            return None
        chunks = []
        size = 0
        while True:
            chunk = os.read(fd, max(st.st_size + 1 - size, 65536))
            if not chunk:
                break
            size += len(chunk)
            if size > limit:
                return None
            chunks.append(chunk)
        return b"".join(chunks)
    except OSError:
        return None
    finally:
        os.close(fd)


def valid_findings(findings: object) -> bool:
    """Whether ``findings``, read from a cache file, has the shape of stored findings."""
    if not isinstance(findings, list):
        return False
    for f in findings:
        if not (isinstance(f, dict) and set(f) == set(_FIELDS)
                and isinstance(f["code"], str) and isinstance(f["level"], str)
                and isinstance(f["message"], str) and isinstance(f["file"], str)
                and (f["line"] is None or type(f["line"]) is int)
                and (f["origin"] is None or isinstance(f["origin"], str))):
            return False
    return True


class ResultCache:
    """Entries under ``<cache>/check-v1``; see the module docstring."""

    def __init__(self, folder: Path, options: Mapping[str, Any]) -> None:
        self.folder = folder
        self._root = os.fspath(folder)
        settings = {"options": dict(options), "env": {k: os.environ.get(k) for k in ENV_KEYS},
                    "code": code_key()}
        self._prefix = json.dumps(settings, sort_keys=True, default=str).encode(
            "utf-8", "surrogateescape")
        self.wrote = 0

    @classmethod
    def open(cls, options: Mapping[str, Any], enabled: bool = True) -> ResultCache | None:
        """The cache for a run with these options; None when it is turned off."""
        folder = cache_dir() if enabled else None
        return cls(folder / FOLDER, options) if folder is not None else None

    def key(self, display: str, path: str | Path) -> str | None:
        """The entry key of a file; None if it is not a readable regular file.

        Such a file is checked uncached, and the check says why it cannot be read.
        """
        data = _read_regular(os.fspath(path), MAX_FILE_BYTES)
        if data is None:
            return None
        h = blake2b(self._prefix, digest_size=20)
        where = f"\0{display}\0{os.path.abspath(path)}\0".encode("utf-8", "surrogateescape")
        h.update(where)
        h.update(data)
        return h.hexdigest()

    def _entry(self, key: str) -> str:
        return os.path.join(self._root, key[:2], f"{key}.json")

    def get(self, key: str) -> list[dict[str, Any]] | None:
        """The findings stored under ``key`` (as dicts), if every dependency is unchanged."""
        entry = self.get_entry(key)
        return entry[1] if entry is not None else None

    def get_entry(self, key: str, memo: dict[str, tuple[object, bool]] | None = None
                  ) -> tuple[dict[str, Any], list[dict[str, Any]]] | None:
        """The dependencies and findings stored under ``key``, if every dependency is unchanged."""
        raw = _read_regular(self._entry(key), MAX_ENTRY_BYTES)
        if raw is None:
            return None
        try:
            entry = json.loads(raw)
            recorded, findings = entry["deps"], entry["findings"]
        except (ValueError, KeyError, TypeError):  # damaged: a miss, never trusted
            return None
        if not (isinstance(recorded, dict) and valid_findings(findings)):
            return None
        if not deps.unchanged(recorded, memo):
            return None
        return recorded, findings

    def put(self, key: str, recorded: Mapping[str, deps.Signature],
            findings: list[dict[str, Any]]) -> bool:
        """Store a result, unless it depends on the machine's load.

        Returns:
            Whether the result may be kept (it is stored unless the folder cannot be written).
        """
        if any(any(t in str(f.get("message")) for t in TRANSIENT) for f in findings):
            return False
        try:
            data = json.dumps({"deps": recorded, "findings": findings}, allow_nan=False,
                              ensure_ascii=True).encode("ascii")
        except (ValueError, TypeError):
            return False
        if write_entry(Path(self._entry(key)), data):
            self.wrote += 1
        return True

    def trim(self, limit: int = MAX_BYTES) -> int:
        """Remove the oldest entries while the folder holds more than ``limit`` bytes.

        Returns:
            How many entries were removed.
        """
        entries: list[tuple[int, int, str]] = []
        total = 0
        try:
            with os.scandir(self.folder) as shards:
                for shard in shards:
                    if not shard.is_dir(follow_symlinks=False):
                        continue
                    with os.scandir(shard.path) as it:
                        for e in it:
                            if e.is_file(follow_symlinks=False):
                                st = e.stat(follow_symlinks=False)
                                entries.append((st.st_mtime_ns, st.st_size, e.path))
                                total += st.st_size
        except OSError:
            return 0
        removed = 0
        if total > limit:
            for _, size, path in sorted(entries):
                if total <= limit * 3 // 4:
                    break
                try:
                    os.unlink(path)
                except OSError:
                    continue
                total -= size
                removed += 1
        return removed


#: What a manifest keeps of a file's own ``stat``: size, mtime, inode, ctime.
FileStat = tuple[int, int, int, int]
#: A file changed this close to the start of the run that recorded it is read again, as git
#: treats a "racily clean" index entry: within the clock's grain an edit can keep the stat.
RACY_NS = deps.RACY_NS


def file_stat(path: str) -> FileStat | None:
    """The signature a manifest keeps of a checked file, or None if it cannot be stat'ed."""
    try:
        st = os.stat(path)
    except (OSError, ValueError):
        return None
    return deps.version(st)


def _pack(findings: list[dict[str, Any]], display: str) -> list[list[Any]]:
    """Findings as rows ``[code, level, message, line, origin, file]``; file None: the file's own.

    Half the size of dicts to read back: the manifest is read whole on every warm run.
    """
    return [[f["code"], f["level"], f["message"], f["line"], f["origin"],
             None if f["file"] == display else f["file"]] for f in findings]


def _unpack(rows: list[Any], display: str) -> list[Finding] | None:
    """:func:`_pack`'s rows back as findings; None if any row has the wrong shape."""
    out = []
    for row in rows:
        if not (type(row) is list and len(row) == 6):
            return None
        code, level, message, line, origin, file = row
        if not (type(code) is str and type(level) is str and type(message) is str
                and (line is None or type(line) is int)
                and (origin is None or type(origin) is str)
                and (file is None or type(file) is str)):
            return None
        out.append(Finding(code, level, message, display if file is None else file, line, origin))
    return out


class RunManifest:
    """One run's results, by path: a re-run over an unchanged tree reads one file, not one each.

    The per-file entries stay the cache; the manifest only saves their lookups. A file whose
    ``stat`` is what the last run saw (and was not modified within :data:`RACY_NS` of that run's
    start) keeps the result recorded for it, if its dependencies are unchanged too; any other
    file is looked up by its content as before. The manifest is read as untrusted (a record of
    the wrong shape is a miss) and rewritten, atomically, after any run that was not all hits.
    """

    def __init__(self, cache: ResultCache, paths: Sequence[str]) -> None:
        h = blake2b(cache._prefix, digest_size=20)
        for p in (os.getcwd(), *paths):
            h.update(os.fsencode(p) + b"\0")
        self.path = os.path.join(cache._root, "runs", f"{h.hexdigest()}.json")
        self.started = time.time_ns()
        self.memo: dict[str, tuple[object, bool]] = {}
        self._old_started, self._old = self._load()
        self._new: dict[str, list[Any]] = {}
        self.misses = 0

    def _load(self) -> tuple[int, dict[str, Any]]:
        raw = _read_regular(self.path, MAX_ENTRY_BYTES)
        if raw is None:
            return 0, {}
        import gc

        collecting = gc.isenabled()
        gc.disable()  # a large document of small containers: no collections while it parses
        try:
            data = json.loads(raw)
            started, files = data["started"], data["files"]
        except (ValueError, KeyError, TypeError):
            return 0, {}
        finally:
            if collecting:
                gc.enable()
        if type(started) is not int or not isinstance(files, dict):
            return 0, {}
        return started, files

    def lookup(self, display: str, path: str) -> list[Finding] | None:
        """The findings recorded for ``path`` if neither it nor anything it read changed."""
        absolute = os.path.abspath(path)
        record = self._old.get(absolute)
        if not (isinstance(record, list) and len(record) == 4 and record[0] == display
                and isinstance(record[1], list) and len(record[1]) == 4
                and isinstance(record[2], dict) and isinstance(record[3], list)):
            return None
        now = file_stat(path)
        if now is None or list(now) != record[1] or now[3] + RACY_NS >= self._old_started:
            return None
        findings = _unpack(record[3], display)
        if findings is None or not deps.unchanged(record[2], self.memo):
            return None
        self._new[absolute] = record
        return findings

    def add(self, display: str, path: str, entry: tuple[FileStat, dict[str, Any],
                                                      list[dict[str, Any]]] | None) -> None:
        """Record a result found another way (``entry`` None: not cacheable)."""
        self.misses += 1
        if entry is not None:
            self._new[os.path.abspath(path)] = [display, list(entry[0]), entry[1],
                                                _pack(entry[2], display)]

    def save(self) -> None:
        """Write the manifest if this run found anything the old one did not hold."""
        if not self.misses:
            return
        try:
            data = json.dumps({"started": self.started, "files": self._new}, allow_nan=False,
                              ensure_ascii=True).encode("ascii")
        except (ValueError, TypeError):
            return
        if len(data) <= MAX_ENTRY_BYTES:
            write_entry(Path(self.path), data)
