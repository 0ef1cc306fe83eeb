"""An export's XML and assets folder, written so that a kill at any step leaves a sound pair.

The assets folder holds files named by their content, ``stem_<8 hex digits of SHA-256>.stl``
(:mod:`urdfkit.formats.mjcf_mesh`): a name always means the same bytes. :func:`write_pair`:

1. refuses an assets path that is a symlink (never followed) or not a folder; creates the
   folder if need be (mode 0777 less the umask, as ``mkdir`` makes it); takes an exclusive
   ``flock`` on it, so no other export writes there meanwhile; and removes what killed runs
   left: temp files in the folder (``.NAME.XXXXXXXX.tmp``), the XML's beside it
   (``.robot.xml.XXXXXXXX.tmp.xml``: MuJoCo reads a file by its suffix), and the
   ``.FOLDER.XXXXXXXX/`` temp folders of urdfkit before content-addressed names;
2. adds each file the new XML names that is not already there, complete (its bytes written
   to a temp name, fsynced, renamed): it only adds, so the old XML still finds all of its
   files. A copied mesh keeps its own mode (a 0600 source stays 0600). Without ``force``
   the folder may hold only files of this very export (complete files a killed first run
   left); anything else is refused;
3. writes the new XML to a temp file beside it, hands it to ``verify`` if given, and renames
   it over the old one: the one step that switches from the old pair to the new;
4. removes every file of the folder the new XML does not name.

A kill before step 3 leaves the old XML (or none) with all its files; after it, the new XML
with all of its own; step 1 of the next run removes the temp files. An error (a full disk,
a refusal by ``verify``) removes the temp files, the files this run added, and the folder if
this run made it: the old pair is left as it was. Every file operation goes through the locked
folder's descriptor (``dir_fd``), so a folder swapped for a symlink meanwhile is not followed.
"""

from __future__ import annotations

import errno
import hashlib
import os
import re
import shutil
import stat
from collections.abc import Callable, Mapping
from pathlib import Path
from types import TracebackType

from urdfkit.core.errors import OutputError, UrdfkitError

#: The steps :func:`write_pair` reports to :func:`_reached`, in order ("temp" and "added"
#: once per file added).
STEPS = ("locked", "cleaned", "temp", "added", "assets", "staged", "verified", "replaced",
         "pruned")
#: A temp file of ours: ``.NAME.XXXXXXXX.tmp`` (core.output's and this module's).
_TEMP = re.compile(r"^\..+\.[A-Za-z0-9_]{8}\.tmp$")
_CHUNK = 1 << 20


def _reached(step: str) -> None:
    """A step of :func:`write_pair` is done; tests replace this to kill the process there."""


def check_asset_dir(folder: Path) -> None:
    """Refuse an assets path that is a symlink or not a folder (before any work)."""
    try:
        st = os.lstat(folder)
    except FileNotFoundError:
        return
    except OSError as e:
        raise _error(e, folder) from None
    if stat.S_ISLNK(st.st_mode):
        raise OutputError("is a symlink; urdfkit never writes an export's assets through one "
                          "(remove it, or choose another output name)", file=folder)
    if not stat.S_ISDIR(st.st_mode):
        raise OutputError("exists and is not a folder", file=folder)


def write_pair(out: Path, xml: bytes, assets: Mapping[str, bytes | Path],
               digests: Mapping[str, str], folder_name: str, *, force: bool = False,
               verify: Callable[[Path], bool] | None = None) -> list[str]:
    """Write ``out`` and its assets folder ``folder_name`` beside it (see the module doc).

    ``assets`` maps each file name to its bytes or the file to copy, ``digests`` each name
    to the SHA-256 (hex) of those bytes. ``verify`` is handed the staged XML (beside ``out``,
    so its assets are found) before it takes ``out``'s place. Without ``force`` the XML must
    not exist, nor the folder hold anything but temp files of killed runs.

    Returns:
        The paths of the pair, the XML first; ``[]`` when ``verify`` returned False (nothing
        of this run is left, the old pair is as it was).

    Raises:
        OutputError: What cannot be written, one line naming the file; nothing of this run
            is left.
    """
    folder = out.parent / folder_name
    check_asset_dir(folder)
    if not assets and not (force and os.path.lexists(folder)):
        return [str(out)] if _replace_xml(out, xml, force, verify) else []
    with _Folder(folder, out, force) as f:
        f.add_all(assets, digests)
        _reached("assets")
        if not _replace_xml(out, xml, force, verify):
            return []
        f.committed = True
        _reached("replaced")
        f.prune(set(assets))
        _reached("pruned")
    return [str(out), *(str(folder / name) for name in assets)]


def _replace_xml(out: Path, xml: bytes, force: bool,
                 verify: Callable[[Path], bool] | None) -> bool:
    """Stage the XML, let ``verify`` judge it, rename it into place; False when refused."""
    from urdfkit.core.output import StreamingFile

    xml_file = StreamingFile(out, force=force, suffixes=(".xml",), temp_suffix=".tmp.xml")
    with xml_file:
        xml_file.write(xml)
        _reached("staged")
        if verify is not None:
            staged = xml_file.temp
            assert staged is not None
            try:
                ok = verify(staged)
            except UrdfkitError as e:  # said of the file the user named
                if e.file == str(staged):
                    e.file = str(out)
                raise
            if not ok:
                xml_file.discard()
                return False
            _reached("verified")
        xml_file.commit()
    return True


class _Folder:
    """The assets folder, locked, while a pair is written (steps 1, 2 and 4)."""

    def __init__(self, folder: Path, out: Path, force: bool) -> None:
        self.folder, self.out, self.force = folder, out, force
        self.fd: int | None = None
        self.made = False               # this run created the folder
        self.temps: list[str] = []      # temp files of this run, not yet renamed
        self.added: list[str] = []      # files this run added
        self.committed = False          # the new XML is in place: nothing to roll back
        self.others: list[str] = []     # what the folder held before, temp files aside

    def __enter__(self) -> _Folder:
        try:
            self.open()
            self.clean()
        except BaseException:
            self.__exit__(None, None, None)
            raise
        return self

    def __exit__(self, kind: type[BaseException] | None, exc: BaseException | None,
                 tb: TracebackType | None) -> None:
        try:
            if kind is not None or not self.committed:
                self.rollback()
        finally:
            if self.fd is not None:
                os.close(self.fd)  # releases the lock
                self.fd = None

    def open(self) -> None:
        import fcntl

        try:
            os.mkdir(self.folder)
            self.made = True
        except FileExistsError:
            pass
        except OSError as e:
            raise _error(e, self.folder) from None
        try:
            self.fd = os.open(self.folder, os.O_RDONLY | os.O_DIRECTORY | os.O_NOFOLLOW)
        except OSError as e:
            if e.errno in (errno.ELOOP, errno.ENOTDIR):
                check_asset_dir(self.folder)  # swapped for a symlink or a file meanwhile
            raise _error(e, self.folder) from None
        try:
            fcntl.flock(self.fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
        except BlockingIOError:
            raise OutputError("another urdfkit export is writing it; try again when it has "
                              "finished", file=self.folder) from None
        _reached("locked")

    def clean(self) -> None:
        """Remove the temp files killed runs left (the lock says no run is alive)."""
        assert self.fd is not None
        others = []
        for entry in os.scandir(self.fd):
            if _TEMP.match(entry.name) and not entry.is_dir(follow_symlinks=False):
                _unlink(entry.name, self.fd)
            else:
                others.append(entry.name)
        beside = self.out.parent
        xml_temp = re.compile(
            rf"^\.{re.escape(self.out.name)}\.[A-Za-z0-9_]{{8}}\.tmp(?:\.xml)?$")
        old_folder = re.compile(rf"^\.{re.escape(self.folder.name)}\.[A-Za-z0-9_]{{8}}$")
        try:
            with os.scandir(beside) as it:
                for entry in it:
                    if xml_temp.match(entry.name) and entry.is_file(follow_symlinks=False):
                        _unlink(entry.path, None)
                    elif old_folder.match(entry.name) and entry.is_dir(follow_symlinks=False):
                        shutil.rmtree(entry.path, ignore_errors=True)
        except OSError:
            pass
        self.others = others
        _reached("cleaned")

    def add_all(self, assets: Mapping[str, bytes | Path], digests: Mapping[str, str]) -> None:
        """Step 2: every file the new XML names, in place and complete.

        Without ``force`` the folder may hold only files of this very export (a killed first
        run left them, complete): anything else would be overwritten or removed.
        """
        assert self.fd is not None
        if not self.force and any(n not in assets or not self.holds(n, digests[n])
                                  for n in self.others):
            raise OutputError("exists; pass `force=True` to overwrite it", file=self.folder,
                              param="force")
        for name, data in assets.items():
            if not self.holds(name, digests[name]):
                self.add(name, data, digests[name])
        try:
            os.fsync(self.fd)  # the renames reach the disk before the XML names them
        except OSError as e:
            raise _error(e, self.folder) from None

    def holds(self, name: str, digest: str) -> bool:
        """Whether the folder has ``name`` as a regular file with those bytes."""
        try:
            fd = os.open(name, os.O_RDONLY | os.O_NOFOLLOW | os.O_NONBLOCK, dir_fd=self.fd)
        except OSError:
            return False
        try:
            if not stat.S_ISREG(os.fstat(fd).st_mode):
                return False
            h = hashlib.sha256()
            while chunk := os.read(fd, _CHUNK):
                h.update(chunk)
            return h.hexdigest() == digest
        except OSError:
            return False
        finally:
            os.close(fd)

    def add(self, name: str, data: bytes | Path, digest: str) -> None:
        """One file: its bytes to a temp name, fsynced, renamed to ``name``."""
        import secrets

        temp = f".{name}.{secrets.token_hex(4)}.tmp"
        try:
            fd = os.open(temp, os.O_WRONLY | os.O_CREAT | os.O_EXCL | os.O_NOFOLLOW, 0o666,
                         dir_fd=self.fd)
        except OSError as e:
            raise _error(e, self.folder / name) from None
        self.temps.append(temp)
        try:
            if isinstance(data, Path):
                _copy(data, fd, digest)
                os.fchmod(fd, stat.S_IMODE(os.stat(data).st_mode) & 0o777)  # its own mode
            else:
                _write_all(fd, data)
            os.fsync(fd)
        except OSError as e:
            raise _error(e, self.folder / name) from None
        finally:
            os.close(fd)
        _reached("temp")
        try:
            os.rename(temp, name, src_dir_fd=self.fd, dst_dir_fd=self.fd)
        except OSError as e:
            raise _error(e, self.folder / name) from None
        self.temps.remove(temp)
        self.added.append(name)
        _reached("added")

    def prune(self, keep: set[str]) -> None:
        """Step 4: remove what the new XML does not name (the folder too, if it names none)."""
        assert self.fd is not None
        try:
            for entry in list(os.scandir(self.fd)):
                if entry.name in keep:
                    continue
                if entry.is_dir(follow_symlinks=False):
                    shutil.rmtree(entry.name, dir_fd=self.fd)
                else:
                    os.unlink(entry.name, dir_fd=self.fd)
            if not keep:
                os.rmdir(self.folder)
        except OSError as e:
            raise _error(e, self.folder) from None

    def rollback(self) -> None:
        """Remove what this run added (the new XML is not in place)."""
        if self.committed or self.fd is None:
            return
        for name in [*self.temps, *self.added]:
            _unlink(name, self.fd)
        self.temps, self.added = [], []
        if self.made:
            try:
                os.rmdir(self.folder)
            except OSError:
                pass


def _copy(source: Path, fd: int, digest: str) -> None:
    """Copy ``source`` to ``fd``; refuse bytes other than those read when it was checked."""
    h = hashlib.sha256()
    with open(source, "rb") as f:
        while chunk := f.read(_CHUNK):
            h.update(chunk)
            _write_all(fd, chunk)
    if h.hexdigest() != digest:
        raise OutputError("changed while it was exported; export again", file=source)


def _write_all(fd: int, data: bytes) -> None:
    view = memoryview(data)
    while view:
        view = view[os.write(fd, view):]


def _unlink(name: str, dir_fd: int | None) -> None:
    try:
        os.unlink(name, dir_fd=dir_fd)
    except OSError:
        pass


def _error(e: OSError, path: Path) -> OutputError:
    from urdfkit.core.output import output_error

    return output_error(e, path)
