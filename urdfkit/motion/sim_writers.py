"""Rows to files: flat columns, ``.jsonl``/``.csv`` text batch by batch, ``.parquet``.

Re-exported by :mod:`urdfkit.sim`.
"""

from __future__ import annotations

import csv
import io
import json
from collections.abc import Iterable, Mapping, Sequence
from pathlib import Path
from types import ModuleType
from typing import TYPE_CHECKING

from urdfkit.core.errors import MissingDependencyError, OutputError

if TYPE_CHECKING:
    from urdfkit.core.output import StreamingFile

OUTPUT_FORMATS = (".jsonl", ".csv", ".parquet")
#: Column suffixes of flattened vectors, by length (position, quaternion, wrench).
_AXES = {3: ("x", "y", "z"), 4: ("x", "y", "z", "w"), 6: ("fx", "fy", "fz", "mx", "my", "mz")}


# --------------------------------------------------------------------------- writers


def flatten(row: Mapping[str, object]) -> dict[str, object]:
    """A nested row as flat columns: ``motor_angles.hinge``, ``base_position.x``."""
    out: dict[str, object] = {}

    def put(prefix: str, value: object) -> None:
        if isinstance(value, Mapping):
            for k, v in value.items():
                put(f"{prefix}.{k}", v)
        elif isinstance(value, (list, tuple)):
            names = _AXES.get(len(value), tuple(str(i) for i in range(len(value))))
            for k, v in zip(names, value, strict=False):
                out[f"{prefix}.{k}"] = v
        else:
            out[prefix] = value

    for key, value in row.items():
        put(key, value)
    return out


def _columns(rows: Iterable[Mapping[str, object]]) -> list[str]:
    seen: dict[str, None] = {}
    for row in rows:
        seen.update(dict.fromkeys(row))
    return list(seen)


def _pyarrow() -> ModuleType:  # pyarrow: untyped (a module's attributes read as Any)
    try:
        import pyarrow
        import pyarrow.parquet
    except ImportError as e:
        raise MissingDependencyError("writing .parquet needs pyarrow: "
                                     "pip install 'urdfkit[parquet]'") from e
    return pyarrow


def check_rows_output(path: str | Path, *, force: bool) -> None:
    """Refuse a bad ``--out`` before simulating: unknown format, existing file, no pyarrow."""
    from urdfkit.core.output import check_output as check

    check(path, force=force, suffixes=OUTPUT_FORMATS, what="the rows file")
    if Path(path).suffix.lower() == ".parquet":
        _pyarrow()


class RowText:
    """Rows as ``.jsonl`` (nested) or ``.csv`` (flattened) text, batch by batch.

    The CSV columns are those of the first batch (every robot's first row): the robot set
    and each robot's fields are fixed for a run.
    """

    def __init__(self, fmt: str):
        if fmt not in (".jsonl", ".csv"):
            raise OutputError(f"{fmt!r} cannot be written row by row; use .jsonl or .csv")
        self.fmt = fmt
        self.columns: list[str] | None = None

    def encode(self, rows: Sequence[Mapping[str, object]]) -> bytes:
        """The text of ``rows`` (with the CSV header before the first batch)."""
        if self.fmt == ".jsonl":
            return "".join(json.dumps(r, allow_nan=False) + "\n" for r in rows).encode("utf-8")
        flat = [flatten(r) for r in rows]
        text = io.StringIO()
        header = self.columns is None
        if self.columns is None:
            self.columns = _columns(flat)
        writer = csv.DictWriter(text, fieldnames=self.columns, lineterminator="\n")
        if header:
            writer.writeheader()
        writer.writerows(flat)
        # A name that is not UTF-8 (a Latin-1 file name, read as surrogates) is written
        # escaped (\udce9), so the file stays UTF-8 text, as the JSON rows are.
        return text.getvalue().encode("utf-8", "backslashreplace")


def rows_to_bytes(rows: Sequence[Mapping[str, object]], fmt: str) -> bytes:
    """Serialise rows as ``.jsonl`` (nested), ``.csv`` or ``.parquet`` (flattened)."""
    if fmt in (".jsonl", ".csv"):
        return RowText(fmt).encode(rows)
    flat = [flatten(r) for r in rows]
    columns = _columns(flat)
    if fmt == ".parquet":
        pa = _pyarrow()
        table = pa.table({c: [r.get(c) for r in flat] for c in columns})
        sink = pa.BufferOutputStream()
        pa.parquet.write_table(table, sink)
        return bytes(sink.getvalue().to_pybytes())
    raise OutputError(f"unknown output format {fmt!r}; use {', '.join(OUTPUT_FORMATS)}")


def write_rows(path: str | Path, rows: Sequence[Mapping[str, object]], *, force: bool) -> Path:
    """Write rows in the format the suffix names, atomically; never replace without ``force``."""
    from urdfkit.core.output import atomic_write

    check_rows_output(path, force=force)
    return atomic_write(path, rows_to_bytes(rows, Path(path).suffix.lower()), force=force)


class _ByteSink:
    """The file-like face pyarrow writes through, onto a StreamingFile."""

    def __init__(self, out: StreamingFile):
        self.out = out
        self.closed = False
        self.position = 0

    def write(self, data: bytes) -> int:
        self.out.write(bytes(data))
        self.position += len(data)
        return len(data)

    def tell(self) -> int:
        return self.position

    def flush(self) -> None:
        pass

    def close(self) -> None:
        self.closed = True
