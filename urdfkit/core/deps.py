"""What a result depends on: every file read, and every path looked at, while it was made.

``check``'s result cache stores a file's findings with the paths that made them: the file,
its xacro includes and YAML, its meshes, the ``package.xml`` files and folders a
``package://`` lookup walked past, and the places a missing mesh was looked for (a mesh that
appears later changes the findings as surely as one that changes). Readers and probes call
:func:`note`; it costs nothing unless :func:`record` is active.

A path's signature is what ``stat`` says, and for a file also a digest of its bytes: its
size, modification time, inode, mode, change time (ns) and BLAKE2b. A result is reused only
while every path is unchanged, judged as git judges its index: the same ``stat`` is unchanged
at no cost; a different ``stat`` with the same size is read and compared by digest (a fresh
checkout in CI gives every file a new modification time, not new bytes). A file changed within
:data:`RACY_NS` of being signed is always compared by digest. A folder signs as only being one;
nothing there as ``None``.
"""

from __future__ import annotations

import os
import stat
from collections.abc import Iterator, Mapping
from contextlib import contextmanager

#: A path's signature: (size, mtime_ns, inode, mode, ctime_ns, digest) for a file, ("dir",)
#: for a folder, None when nothing is there, or ("other", mode) for a FIFO, device or socket.
Signature = tuple[int, int, int, int, int, str] | tuple[str] | tuple[str, int] | None
#: Within this of a file's last change its ``stat`` may not show the next change (the clock's
#: grain; git's "racily clean" index entry), so a file changed this recently is never trusted
#: by its ``stat`` alone.
RACY_NS = 2_000_000_000
#: A file larger than this is judged by its stat alone (never read just to sign it).
MAX_DIGEST_BYTES = 256 * 1024 * 1024

_active: list[dict[str, Signature]] = []


def version(st: os.stat_result) -> tuple[int, int, int, int]:
    """The key of a file's version by its ``stat``: size, mtime, inode and ctime (ns).

    An edit in place can keep the size (a binary STL rescaled keeps its triangle count) and put
    the mtime back (``touch -r``, ``rsync -t``, ``tar``); the ctime still changes, and no call
    can set it. Caches keyed by ``stat`` key by this.
    """
    return (st.st_size, st.st_mtime_ns, st.st_ino, st.st_ctime_ns)


def settled(st: os.stat_result) -> bool:
    """Whether a file last changed more than :data:`RACY_NS` ago.

    Only then will its :func:`version` show its next change: an answer about a file not
    settled is not kept on disk.
    """
    import time

    return time.time_ns() - st.st_ctime_ns > RACY_NS


def digest(path: str, size: int) -> str:
    """BLAKE2b of a regular file's bytes ("" if it cannot be read or is too large to sign)."""
    import hashlib

    if size > MAX_DIGEST_BYTES:
        return ""
    h = hashlib.blake2b(digest_size=16)
    try:
        fd = os.open(path, os.O_RDONLY | os.O_NONBLOCK | os.O_CLOEXEC)
    except (OSError, ValueError):
        return ""
    try:
        if not stat.S_ISREG(os.fstat(fd).st_mode):
            return ""
        while chunk := os.read(fd, 1 << 20):
            h.update(chunk)
    except OSError:
        return ""
    finally:
        os.close(fd)
    return h.hexdigest()


def signature(path: str) -> Signature:
    """What ``stat`` says of ``path`` now (following symlinks), and a file's digest."""
    try:
        st = os.stat(path)
    except (OSError, ValueError):
        return None
    if stat.S_ISREG(st.st_mode):
        # A file not settled signs with a ctime that matches nothing, so the next run compares
        # its bytes: an edit within the clock's grain keeps the stat, never the digest.
        return (st.st_size, st.st_mtime_ns, st.st_ino, st.st_mode,
                st.st_ctime_ns if settled(st) else -1, digest(path, st.st_size))
    if stat.S_ISDIR(st.st_mode):
        return ("dir",)
    return ("other", st.st_mode)


def note(path: str | os.PathLike[str]) -> None:
    """Record that the result being made depends on ``path`` (read, or looked for)."""
    if not _active:
        return
    key = os.path.abspath(os.fspath(path))
    for seen in _active:
        if key not in seen:
            seen[key] = signature(key)


def note_listing(folder: str | os.PathLike[str]) -> None:
    """Record that the result depends on a folder's entries (a "did you mean" list).

    A folder's modification time changes when an entry is added, removed or renamed.
    """
    if not _active:
        return
    key = os.path.abspath(os.fspath(folder))
    try:
        mtime: Signature = ("listing", os.stat(key).st_mtime_ns)
    except (OSError, ValueError):
        mtime = None
    for seen in _active:
        seen.setdefault(key + os.sep, mtime)


@contextmanager
def record() -> Iterator[dict[str, Signature]]:
    """Collect, into the dict yielded, every path noted until the block ends."""
    seen: dict[str, Signature] = {}
    _active.append(seen)
    try:
        yield seen
    finally:
        _active.remove(seen)


def unchanged(recorded: Mapping[str, object],
              memo: dict[str, tuple[object, bool]] | None = None) -> bool:
    """Whether every recorded path is as it was (see the module docstring).

    ``memo`` keeps each path's verdict within one run, where many files share a mesh or an
    include: a path judged once against the same recorded signature is not judged again.
    """
    if memo is None:
        return all(_unchanged(path, was) for path, was in recorded.items())
    for path, was in recorded.items():
        known = memo.get(path)
        if known is not None and known[0] == was:
            ok = known[1]
        else:
            ok = _unchanged(path, was)
            memo[path] = (was, ok)
        if not ok:
            return False
    return True


def _unchanged(path: str, was: object) -> bool:
    """Whether one recorded path is as it was."""
    was = tuple(was) if isinstance(was, list) else was
    if path.endswith(os.sep):  # a folder listing: its mtime
        try:
            now: object = ("listing", os.stat(path).st_mtime_ns)
        except (OSError, ValueError):
            now = None
        return was == now
    try:
        st = os.stat(path)
    except (OSError, ValueError):
        return was is None
    if not stat.S_ISREG(st.st_mode):
        return was == (("dir",) if stat.S_ISDIR(st.st_mode) else ("other", st.st_mode))
    if not (isinstance(was, tuple) and len(was) == 6):
        return False
    if was[:5] == (st.st_size, st.st_mtime_ns, st.st_ino, st.st_mode, st.st_ctime_ns):
        return True  # the same stat: the same file, as git's index judges it
    return bool(was[0] == st.st_size and was[5] and digest(path, st.st_size) == was[5])
