"""What a result depends on: every file read, and every path looked at, while it was made.

``check``'s result cache stores a file's findings with the paths that made them: the file,
its xacro includes and YAML, its meshes, the ``package.xml`` files and folders a
``package://`` lookup walked past, and the places a missing mesh was looked for (a mesh that
appears later changes the findings as surely as one that changes). Readers and probes call
:func:`note`; it costs nothing unless :func:`record` is active.

A path's signature is what ``stat`` says: for a file its size, modification time (ns), inode
and mode; for a folder only that it is one; ``None`` for nothing there. A result is reused only
while every signature is unchanged.
"""

from __future__ import annotations

import os
import stat
from collections.abc import Iterator, Mapping
from contextlib import contextmanager

#: A path's signature: (size, mtime_ns, inode, mode) for a file, ("dir",) for a folder, None
#: when nothing is there, or ("other", mode) for a FIFO, device or socket.
Signature = tuple[int, int, int, int] | tuple[str] | tuple[str, int] | None

_active: list[dict[str, Signature]] = []


def signature(path: str) -> Signature:
    """What ``stat`` says of ``path`` now (following symlinks), as compared for reuse."""
    try:
        st = os.stat(path)
    except (OSError, ValueError):
        return None
    if stat.S_ISREG(st.st_mode):
        return (st.st_size, st.st_mtime_ns, st.st_ino, st.st_mode)
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


def unchanged(recorded: Mapping[str, object]) -> bool:
    """Whether every recorded path still has the signature it had (lists compare as tuples)."""
    for path, was in recorded.items():
        if path.endswith(os.sep):  # a folder listing: its mtime
            try:
                now: object = ("listing", os.stat(path).st_mtime_ns)
            except (OSError, ValueError):
                now = None
        else:
            now = signature(path)
        if (tuple(was) if isinstance(was, list) else was) != now:
            return False
    return True
