"""Writing files: the one pre-check, the one atomic write, the one streaming writer.

Nothing is lost and nothing is clobbered:

- :func:`check_output` refuses, before any work, a path that exists (a dangling symlink
  counts) unless ``force``; one that is a folder, a FIFO, a device or a socket, even with
  ``force`` (``build -o /dev/null --force`` must not replace /dev/null); a wrong suffix; a
  missing folder.
- :func:`atomic_write` writes a temp file beside the target and renames it into place: a
  crash or SIGKILL leaves the old file or the new one, never a mix. Stale temp files of ours
  for the same name are removed first. A file it replaces keeps its mode and owner (a 600
  secret stays 600, a 755 script owned by another user stays theirs), and a symlink to a
  regular file is written through: the target is replaced, the link stays a link.
- :class:`StreamingFile` does the same for output produced over a long run (trajectories,
  simulation rows): rows go to disk as they come, and on Ctrl-C/SIGTERM the complete rows so
  far are kept.

Every OS error (a full disk, a read-only folder, a missing permission, a name too long)
becomes one :class:`~urdfkit.core.errors.OutputError` naming the file, and the temp file is
removed.
"""

from __future__ import annotations

import errno
import os
import re
import stat
import time
from collections.abc import Sequence
from pathlib import Path
from types import TracebackType

from urdfkit.core.errors import OutputError

#: Temp files of ours older than this (seconds) are stale: a killed run left them.
STALE_AFTER = 600.0

_WHY = {errno.ENOSPC: "the disk is full", errno.EDQUOT: "the disk quota is exceeded",
        errno.EROFS: "the file system is read-only", errno.EACCES: "permission denied",
        errno.EPERM: "permission denied", errno.ENAMETOOLONG: "the name is too long",
        errno.ENOENT: "its folder does not exist", errno.ENOTDIR: "a part of the path is not a "
        "folder", errno.EISDIR: "it is a folder",
        errno.EFBIG: "the file size limit is reached (ulimit -f)"}


def _oserror(e: OSError, path: Path) -> OutputError:
    why = _WHY.get(e.errno or 0, e.strerror or type(e).__name__)
    return OutputError(f"cannot write: {why}", file=path)


def output_error(e: OSError, path: Path) -> OutputError:
    """The one line an OS error writing ``path`` becomes (a full disk, a read-only folder)."""
    return _oserror(e, path)


def check_output(path: str | Path, *, force: bool = False,
                 suffixes: Sequence[str] | None = None, what: str = "the output") -> Path:
    """Refuse an output path that can or must not be written; see the module doc.

    Commands that work for a while before writing call this first, so a run never ends in
    a refusal; the writers call it again at write time.
    """
    path = Path(path)
    if suffixes is not None and path.suffix.lower() not in suffixes:
        raise OutputError(f"{what} must end in {' or '.join(suffixes)}", file=path)
    try:
        st = os.lstat(path)
    except FileNotFoundError:
        st = None
    except OSError as e:
        raise _oserror(e, path) from None
    if st is not None:
        target: os.stat_result | None = st
        if stat.S_ISLNK(st.st_mode):
            try:
                target = os.stat(path)
            except OSError:
                target = None  # dangling: the link itself exists, and is what we would replace
        if target is not None and stat.S_ISDIR(target.st_mode):
            raise OutputError("is a folder", file=path)
        if target is not None and not stat.S_ISREG(target.st_mode):
            raise OutputError("is not a regular file (a FIFO, device or socket); urdfkit never "
                              "replaces one, even with --force", file=path)
        if not force:
            raise OutputError("exists; pass `force=True` to overwrite it", file=path,
                              param="force")
    folder = path.parent if str(path.parent) else Path(".")
    if not folder.is_dir():
        raise OutputError(f"folder {folder} does not exist", file=path)
    return path


def _temp_pattern(name: str) -> re.Pattern[str]:
    return re.compile(rf"^\.{re.escape(name)}\.[A-Za-z0-9_]{{8}}\.tmp$")


def clean_stale(path: Path) -> None:
    """Remove temp files a killed run left for ``path`` (``.NAME.XXXXXXXX.tmp``, old)."""
    folder = path.parent if str(path.parent) else Path(".")
    pattern, now = _temp_pattern(path.name), time.time()
    try:
        with os.scandir(folder) as it:
            for entry in it:
                if pattern.match(entry.name):
                    try:
                        info = entry.stat(follow_symlinks=False)
                        if stat.S_ISREG(info.st_mode) and now - info.st_mtime > STALE_AFTER:
                            os.unlink(entry.path)
                    except OSError:
                        continue
    except OSError:
        pass


class StreamingFile:
    """Write a file as it is produced; it appears, complete, only when closed.

    ``with StreamingFile(path, force=...) as out: out.write(b"...")``. On a normal exit what
    was written is renamed into place. With ``keep_on_interrupt``, so is it on
    KeyboardInterrupt (Ctrl-C, and SIGTERM/SIGHUP in the CLI): the complete rows so far are
    kept; call :meth:`write` with whole rows only. On any other error the temp file is
    removed and the target is untouched.
    """

    def __init__(self, path: str | Path, *, force: bool = False,
                 suffixes: Sequence[str] | None = None, keep_on_interrupt: bool = False,
                 like: str | Path | None = None, temp_suffix: str = ".tmp"):
        self.path = check_output(path, force=force, suffixes=suffixes)
        self.force = force
        self.keep_on_interrupt = keep_on_interrupt
        #: The temp file's name ends so (``.tmp.xml``: MuJoCo reads a file by its suffix).
        self.temp_suffix = temp_suffix
        #: Where the bytes go: the path, or the regular file a symlink at the path points to.
        self.target = _write_target(self.path)
        #: Whose mode and owner the new file takes: ``like``, else the file it replaces.
        self._like = Path(like) if like is not None else self.target
        self._fd: int | None = None
        self._tmp: str | None = None

    def __enter__(self) -> StreamingFile:
        import tempfile

        clean_stale(self.target)
        folder = self.target.parent if str(self.target.parent) else Path(".")
        try:
            self._fd, self._tmp = tempfile.mkstemp(prefix=f".{self.target.name}.",
                                                   suffix=self.temp_suffix, dir=folder)
            _take_mode(self._fd, self._like)
        except OSError as e:
            self._discard()
            raise _oserror(e, self.path) from None
        return self

    def write(self, data: bytes) -> None:
        """Append bytes (whole rows)."""
        assert self._fd is not None, "use StreamingFile as a context manager"
        view = memoryview(data)
        try:
            while view:
                view = view[os.write(self._fd, view):]
        except OSError as e:
            self._discard()
            raise _oserror(e, self.path) from None

    def __exit__(self, kind: type[BaseException] | None, exc: BaseException | None,
                 tb: TracebackType | None) -> None:
        if self._fd is None:
            return
        if kind is None or (self.keep_on_interrupt and issubclass(kind, KeyboardInterrupt)):
            self.commit()
        else:
            self._discard()

    def commit(self) -> None:
        """Flush to disk and rename into place.

        Without ``force``, a file that appeared at the path meanwhile is refused.
        """
        assert self._fd is not None and self._tmp is not None
        try:
            os.fsync(self._fd)
            os.close(self._fd)
            self._fd = None
            if not self.force and os.path.lexists(self.path):
                raise OutputError("exists; pass `force=True` to overwrite it", file=self.path,
                                  param="force")
            os.replace(self._tmp, self.target)
            self._tmp = None
        except OSError as e:
            self._discard()
            raise _oserror(e, self.path) from None
        except BaseException:
            self._discard()
            raise

    @property
    def temp(self) -> Path | None:
        """The temp file the bytes go to until :meth:`commit` (None after it).

        For a caller that checks the written file before it takes its place (``urdfkit export
        --verify`` loads it in MuJoCo).
        """
        return None if self._tmp is None else Path(self._tmp)

    def discard(self) -> None:
        """Remove the temp file: the target stays as it was."""
        self._discard()

    def _discard(self) -> None:
        if self._fd is not None:
            try:
                os.close(self._fd)
            except OSError:
                pass
            self._fd = None
        if self._tmp is not None:
            try:
                os.unlink(self._tmp)
            except OSError:
                pass
            self._tmp = None


def _write_target(path: Path) -> Path:
    """The file a write to ``path`` replaces: the path, or the regular file its symlink names.

    Renaming a temp file over a symlink would replace the link with a file, cutting it from
    what it pointed to (``fix --in-place`` on a linked URDF); writing beside the target and
    renaming there keeps the link and updates what it names. A dangling link is the path.
    """
    if not path.is_symlink():
        return path
    try:
        target = path.resolve(strict=True)
    except (OSError, RuntimeError):
        return path
    return target if target.is_file() else path


def _take_mode(fd: int, like: Path) -> None:
    """Give the new file ``like``'s mode and owner, or open()'s default mode if it is new.

    mkstemp makes 0600. A replaced file keeps its permission bits (setuid/setgid dropped, as
    every editor does) and, where we may (root, or the same owner), its owner and group.
    """
    try:
        st = os.stat(like)
    except OSError:
        st = None
    if st is None or not stat.S_ISREG(st.st_mode):
        umask = os.umask(0)
        os.umask(umask)
        os.fchmod(fd, 0o666 & ~umask)
        return
    if hasattr(os, "fchown"):
        try:
            os.fchown(fd, st.st_uid, st.st_gid)
        except OSError:
            try:  # not root: keep the group at least, where we belong to it
                os.fchown(fd, -1, st.st_gid)
            except OSError:
                pass
    os.fchmod(fd, stat.S_IMODE(st.st_mode) & 0o1777)


def atomic_write(path: str | Path, data: bytes, *, force: bool = False,
                 suffixes: Sequence[str] | None = None, like: str | Path | None = None) -> Path:
    """Write ``data`` to ``path`` atomically (temp file, fsync, rename); see the module doc.

    ``like`` names a file whose mode and owner the new file takes (a backup takes its
    original's); by default a replaced file keeps its own, and a new one gets open()'s mode.
    """
    out = StreamingFile(path, force=force, suffixes=suffixes, like=like)
    with out:
        out.write(data)
    return out.path
