"""The rows file of a sweep: written as points finish, locked, resumed (``sweep --out``).

Split from :mod:`urdfkit.sweep`, which re-exports :class:`Journal` and :func:`read_rows`.
"""

from __future__ import annotations

import math
import os
import re
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path

from urdfkit.core.errors import InputError, OutputError


def parse_value(text: str) -> bool | int | float | str:
    """A value as typed: a number where it reads as one, true/false, else the text."""
    t = text.strip()
    if t.lower() in ("true", "false"):
        return t.lower() == "true"
    try:
        number = float(t)
    except ValueError:
        return t
    if not math.isfinite(number):
        return t  # "nan", "inf": refused where the value is checked, as text
    if re.fullmatch(r"[+-]?\d+", t):
        return int(t)
    return number


@dataclass
class Journal:
    """Rows written as points finish, to ``OUT.partial`` (JSON lines), then to ``OUT``.

    A crash leaves ``OUT.partial`` with every finished row; ``resume`` reads it (and ``OUT``,
    if a finished sweep left one) to skip the points done. :meth:`finish` writes ``OUT``
    atomically in its format (``.csv``, ``.jsonl`` or ``.parquet``) and removes the partial
    file; it is also called on Ctrl-C, so the rows so far land in ``OUT``.

    The journal is locked (``flock``) from :meth:`open` to :meth:`finish`: a second sweep on
    the same output is refused at once instead of redoing points and clobbering rows. A last
    row cut short (a crash, a full disk) is dropped and its point runs again, with a note in
    :attr:`notes`; a damaged row anywhere else is refused with its line.
    """

    path: Path
    names: list[str]
    resume: bool = False
    force: bool = False
    done: list[dict[str, object]] = field(default_factory=list)
    assignments: Sequence[dict[str, object]] = field(default_factory=list)
    #: What the caller should tell the user (rows dropped, and why).
    notes: list[str] = field(default_factory=list)
    _fd: int | None = None
    _keys: set[tuple[str, ...]] | None = None
    _nonfinite: bool = False

    @property
    def partial(self) -> Path:
        """The journal file beside the output."""
        return self.path.with_name(self.path.name + ".partial")

    def open(self) -> None:
        """Check the output, lock the journal, read what a previous run did, start writing."""
        from urdfkit.motion.sim_writers import check_rows_output

        exists = os.path.lexists(self.path)  # a dangling symlink is there: never replaced
        check_rows_output(self.path, force=self.force or (self.resume and exists) or not exists)
        had_partial = os.path.lexists(self.partial)
        if had_partial and not self.resume and not self.force:
            raise InputError("a sweep that did not finish left its rows here: add "
                             "--resume to carry on, or --force to start again",
                             file=self.partial)
        self._lock()
        try:
            if self.resume:
                found = read_rows(self.path, notes=self.notes) if exists else []
                if had_partial:
                    found += read_rows(self.partial, ".jsonl", notes=self.notes)
                self.done = self._same_sweep(found)
            # Keep what a previous run finished: the journal restarts with those rows.
            assert self._fd is not None
            os.ftruncate(self._fd, 0)
            for row in self.done:
                self._write(row)
        except BaseException:
            if not had_partial:  # refused before any row: leave nothing behind
                try:
                    self.partial.unlink()
                except OSError:
                    pass
            self._unlock()
            raise

    def _lock(self) -> None:
        import errno
        import fcntl

        from urdfkit.core.output import check_output as check_target

        check_target(self.partial, force=True, what="the journal")  # no FIFO, no folder
        try:
            fd = os.open(self.partial, os.O_RDWR | os.O_CREAT | getattr(os, "O_CLOEXEC", 0),
                         0o666)
        except OSError as e:
            raise OutputError(f"cannot write the journal: {e.strerror}",
                              file=self.partial) from None
        try:
            fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
        except OSError as e:
            os.close(fd)
            if e.errno in (errno.EWOULDBLOCK, errno.EAGAIN, errno.EACCES):
                raise InputError("another sweep is writing this output now: wait for it, "
                                 "or give another --out", file=self.path) from None
            raise OutputError(f"cannot lock the journal: {e.strerror}",
                              file=self.partial) from None
        self._fd = fd

    def _unlock(self) -> None:
        if self._fd is not None:
            try:
                os.close(self._fd)  # closing releases the lock
            except OSError:
                pass
            self._fd = None

    def _same_sweep(self, rows: list[dict[str, object]]) -> list[dict[str, object]]:
        """The rows to keep: each must be a point of this sweep; failed ones run again.

        Raises:
            InputError: a row that is not the same point of this sweep (another grid, other
                names): resuming would mix two sweeps in one file.
        """
        kept: dict[int, dict[str, object]] = {}
        for row in rows:
            point = row.get("point")
            if isinstance(point, float) and point.is_integer():
                point = int(point)
            if not isinstance(point, int) or not 0 <= point < len(self.assignments) or \
                    _key(row, self.names) != _key(self.assignments[point], self.names) or \
                    any(n not in row for n in self.names):
                shown = clip(", ".join(f"{n}={row.get(n)}" for n in self.names))
                raise InputError(f"holds rows of another sweep (point {clip(str(point))}: "
                                 f"{shown} is not that point of this one): --resume carries "
                                 "on the same command; give another --out, or --force to "
                                 "start again", file=self.path)
            if not row.get("error"):
                kept[point] = row  # a point that failed runs again, and its new row replaces
        return [kept[p] for p in sorted(kept)]

    def _write(self, row: Mapping[str, object]) -> None:
        import json

        assert self._fd is not None, "open() the journal first"
        data = (json.dumps(row, allow_nan=False, default=str) + "\n").encode("utf-8")
        try:
            view = memoryview(data)
            while view:
                view = view[os.write(self._fd, view):]
        except OSError as e:
            raise _write_error(e, self.partial) from None

    def add(self, row: Mapping[str, object]) -> None:
        """Record a finished point.

        A metric that is not finite (a robot whose file holds NaN blew up) is recorded as
        null, as ``--json`` writes it, with one note for the run: JSON has no NaN.
        """
        bad = [k for k, v in row.items() if isinstance(v, float) and not math.isfinite(v)]
        if bad:
            row = {k: None if k in bad else v for k, v in row.items()}
            if not self._nonfinite:
                self._nonfinite = True
                self.notes.append(f"point {row.get('point')}: {', '.join(bad[:3])}"
                                  f"{' ...' if len(bad) > 3 else ''} not finite (the "
                                  "simulation blew up): written as null")
        self._write(row)

    def finished(self, values: Mapping[str, object]) -> bool:
        """Whether a point with these values has a row without an error (for ``skip``)."""
        if self._keys is None:
            self._keys = {_key(r, self.names) for r in self.done if not r.get("error")}
        return _key(values, self.names) in self._keys

    def finish(self) -> Path:
        """Write ``OUT`` from the journal (atomically), remove the journal, unlock."""
        try:
            if self._fd is not None:
                try:
                    os.fsync(self._fd)
                except OSError as e:
                    raise _write_error(e, self.partial) from None
            rows = read_rows(self.partial, ".jsonl", notes=self.notes)
            from urdfkit.motion.sim_writers import write_rows

            path = write_rows(self.path, rows, force=True)
            self.partial.unlink()
            return path
        finally:
            self._unlock()


def _write_error(e: OSError, path: Path) -> OutputError:
    import errno

    why = {errno.ENOSPC: "the disk is full", errno.EDQUOT: "the disk quota is exceeded",
           errno.EROFS: "the file system is read-only"}.get(e.errno or 0, e.strerror or str(e))
    return OutputError(f"cannot write the journal: {why}; the rows so far are kept here "
                       "(--resume carries on)", file=path)


def clip(text: str, most: int = 200) -> str:
    """``text``, or its first ``most`` characters and its length: error lines stay bounded."""
    return text if len(text) <= most else f"{text[:most]}... ({len(text):,} characters)"


def _key(row: Mapping[str, object], names: Sequence[str]) -> tuple[str, ...]:
    """The varied values of a row, comparable across formats (CSV gives text back)."""
    out = []
    for n in names:
        v = row.get(n)
        if isinstance(v, str):
            v = parse_value(v)
        out.append(repr(float(v)) if isinstance(v, (int, float)) and not isinstance(v, bool)
                   else str(v))
    return tuple(out)


#: A million rows of a few hundred bytes; a larger file is not a sweep's rows.
MAX_ROWS_BYTES = 1 << 30


def read_rows(path: Path, fmt: str | None = None, *,
              notes: list[str] | None = None) -> list[dict[str, object]]:
    """The rows of a sweep's output (``.csv``, ``.jsonl``, ``.parquet``) or journal.

    A last row cut short (the file does not end its line: a crash or a full disk) is dropped,
    with a note in ``notes``; its point runs again. object other row that does not read is
    damage, and refused with its line.

    Raises:
        InputError: unreadable, not a rows file, or a damaged row.
    """
    fmt = fmt or path.suffix.lower()
    if fmt not in (".jsonl", ".csv", ".parquet"):
        raise InputError("rows are .csv, .jsonl or .parquet", file=path)
    from urdfkit.model.xmlio import read_regular

    data = read_regular(path, limit=MAX_ROWS_BYTES, kind="rows file")
    if fmt == ".parquet":
        return _parquet_rows(path, data)
    try:
        text = data.decode("utf-8")
    except UnicodeDecodeError as e:
        raise InputError(f"cannot read the rows to resume from: not UTF-8 (byte {e.start})",
                         file=path) from None
    lines = text.split("\n")
    cut = lines.pop() != ""  # text after the last newline: a row cut short
    if cut and notes is not None:
        notes.append(f"{path}: its last row was cut short (line {len(lines) + 1}); that point "
                     "runs again")
    if fmt == ".jsonl":
        return _jsonl_rows(path, lines)
    return _csv_rows(path, lines)


def _jsonl_rows(path: Path, lines: list[str]) -> list[dict[str, object]]:
    import json

    rows = []
    for n, line in enumerate(lines, 1):
        if not line.strip():
            continue
        try:
            row = json.loads(line)
        except (json.JSONDecodeError, RecursionError):
            row = None
        if not isinstance(row, dict):
            raise InputError(f"row {n} is not a JSON object ({clip(line, 80)!r}): the rows "
                             "file is damaged; --force starts the sweep again",
                             file=path, line=n)
        rows.append(row)
    return rows


def _csv_rows(path: Path, lines: list[str]) -> list[dict[str, object]]:
    import csv

    reader = csv.reader(lines)
    try:
        header = next(reader)
    except StopIteration:
        return []
    except csv.Error as e:
        raise InputError(f"not a rows file: {e}", file=path, line=1) from None
    rows = []
    try:
        for values in reader:
            if len(values) != len(header):
                raise InputError(f"row {reader.line_num} has {len(values)} values for "
                                 f"{len(header)} columns: the rows file is damaged; --force "
                                 "starts the sweep again", file=path, line=reader.line_num)
            rows.append({k: _csv_value(v) for k, v in zip(header, values, strict=True)})
    except csv.Error as e:
        raise InputError(f"a row does not read as CSV ({e}): the rows file is damaged",
                         file=path, line=reader.line_num) from None
    return rows


def _parquet_rows(path: Path, data: bytes) -> list[dict[str, object]]:
    from urdfkit.motion.sim_writers import _pyarrow

    _pyarrow()
    import pyarrow as pa
    import pyarrow.parquet as pq

    try:
        return [dict(r) for r in pq.read_table(pa.BufferReader(data)).to_pylist()]
    except (OSError, ValueError, pa.ArrowException) as e:
        raise InputError(f"cannot read the rows to resume from: {clip(str(e))}",
                         file=path) from None


def _csv_value(text: str | None) -> object:
    if text is None or text == "":
        return None
    return parse_value(text)
