"""What in a mesh file makes PyBullet 3.2.7 crash or hang: the facts the guard's mesh rule states.

Two classes, both measured against raw ``p.loadURDF`` in a subprocess
(tests/test_guard_meshes.py keeps the table):

- **COLLADA that PyBullet's reader dereferences a null pointer on** (:func:`collada_fault`).
  LoadMeshFromCollada parses the file with tinyxml2 and then takes for granted that the root
  element has an ``<asset>`` child and a ``<library_geometries>`` child, that an
  ``<asset><unit>`` has a ``meter`` attribute and that an ``<asset><up_axis>`` holds text.
  A file without one of them segfaults (or aborts) every load, visual or collision alike. A
  file tinyxml2 cannot parse, or an empty one, is skipped by PyBullet, and not refused here.
- **A NaN vertex in a collision mesh PyBullet builds a convex hull of** (:func:`hull_fault`).
  btConvexHullComputer scales each axis by the finite vertices' extent, casts each coordinate
  to a 32-bit integer (NaN becomes INT_MIN) and then overflows its exact integer arithmetic:
  by where the NaN falls it segfaults, never returns (still running after 300 s) or builds a
  hull. The crash needs an axis on which NaN stands beside numbers: an axis that is NaN for
  every vertex, or that holds an infinity (which makes the whole axis NaN before the cast),
  collapses to one integer and loads. Visual meshes and ``<collision concave="...">`` (a
  triangle mesh, no hull) load with NaN; so does an ASCII STL, which PyBullet does not read.

Both are cheap on the common case, as the guard runs on every load: a COLLADA file is
pull-parsed until its ``<asset>`` and ``<library_geometries>`` have been seen (its head), and
a collision mesh is scanned for a non-finite number at C speed (every vertex float's exponent
byte of a binary STL, ~0.2 ms a megabyte; the text ``nan``/``inf`` of an OBJ or COLLADA,
~2 ms a megabyte) without numpy. Only a
file that fails the scan is read into vertices (:func:`urdfkit.sources.meshes.parse_mesh`).
Answers are kept per file version (path, size, mtime, inode) for the process.
"""

from __future__ import annotations

import os
import re
from collections.abc import Callable, Sequence
from pathlib import Path
from typing import Any

from urdfkit.core import deps
from urdfkit.core.errors import InputError

#: The largest mesh scanned for a crash. PyBullet reads a larger one as well, so the limit is
#: far above check's (:data:`urdfkit.sources.meshdata.MAX_MESH_BYTES`); scanning 10 MB takes
#: ~3 ms.
MAX_SCANNED_BYTES = 512 * 1024 * 1024

#: Answers by (path, size, mtime, inode, question).
_ANSWERS: dict[tuple[object, ...], str | None] = {}


def _remembered(path: str, st: os.stat_result | None, question: tuple[object, ...],
                answer: Callable[[], str | None]) -> str | None:
    """``answer()``, once per version of the file at ``path`` and ``question`` (bounded)."""
    if st is None:
        try:
            st = os.stat(path)
        except (OSError, ValueError):
            return None  # missing or unreadable: the reference says so (U701, U704)
    key = (path, *deps.version(st), *question)
    found = _ANSWERS.get(key, _UNSEEN)
    if found is _UNSEEN:
        if len(_ANSWERS) > 4096:
            _ANSWERS.clear()
        found = _ANSWERS[key] = _stored(key, answer, deps.settled(st))
    return found


#: The on-disk answers' folder, named for how they are worked out: bump it whenever an answer
#: would come out differently. Each run of `check` over pybullet_data reads 1,062 collision
#: meshes for them: 160 ms of its 450 (measured); with the entries it takes 360 (its 290 before
#: the rule: the entries are 1,062 small reads, which a pack as the mesh cache's would save).
_FOLDER = "mesh-faults-1"


def _stored(key: tuple[object, ...], answer: Callable[[], str | None], keep: bool
            ) -> str | None:
    """``answer()`` from the cache folder when a run before worked it out, else worked out.

    What is worked out is kept if ``keep`` (the file is settled: :func:`urdfkit.core.deps.
    settled`); a file's version is in the key, as in the mesh cache's, so an edited mesh misses.
    """
    import hashlib

    from urdfkit.sources.cache import cache_dir, read_entry, write_entry

    folder = cache_dir()
    entry = folder / _FOLDER / hashlib.sha1(repr(key).encode("utf-8", "surrogateescape")
                                            ).hexdigest() if folder else None
    if entry is not None:
        data = read_entry(entry)
        if data is not None:
            return None if data == b"-" else data.decode("utf-8", "replace")
    found = answer()
    if entry is not None and keep:
        write_entry(entry, b"-" if found is None else found.encode("utf-8"))
    return found


_UNSEEN: Any = object()


def _read(path: str) -> bytes | None:
    from urdfkit.model.xmlio import read_regular

    try:  # U704 says what is not a regular file
        return read_regular(Path(path), limit=MAX_SCANNED_BYTES, kind="mesh")
    except InputError:
        return None


# --------------------------------------------------------------------------- COLLADA


def collada_fault(path: str, st: os.stat_result | None = None) -> str | None:
    """What PyBullet 3.2.7's COLLADA reader crashes on in the file at ``path``, or None.

    A clause to follow "the file" ("has no <asset> element ...; add ..."). ``st``: the path's
    ``os.stat``, when the caller has it.
    """
    return _remembered(path, st, ("collada",), lambda: _collada_file_fault(path))


def _collada_file_fault(path: str) -> str | None:
    data = _read(path)
    return None if data is None else collada_data_fault(data, path)


#: Root children PyBullet's reader takes for granted, in the order it looks for them.
_ASSUMED = ("asset", "library_geometries")


def collada_data_fault(data: bytes, path: str | Path = "mesh.dae") -> str | None:
    """:func:`collada_fault` of a file's bytes."""
    if not data.strip():
        return None  # PyBullet reads nothing of an empty file (check's U715 says so)
    from lxml import etree

    # The head first: <asset> is the root's first child in COLLADA's schema, and
    # <library_geometries> starts before the geometry it holds. Read no further once both
    # have been seen and the asset is sound; anything else is judged on the whole file.
    parser = etree.XMLPullParser(events=("start", "end"), resolve_entities=False,
                                 no_network=True, huge_tree=False, load_dtd=False)
    seen: dict[str, Any] = {}
    try:
        for at in range(0, len(data), 1 << 16):
            parser.feed(data[at:at + (1 << 16)])
            for event, el in parser.read_events():
                parent = el.getparent()
                if parent is None or parent.getparent() is not None:
                    continue  # only the root's children
                name = _tinyxml_name(el)
                if name in _ASSUMED and name not in seen and (
                        event == "end" or name == "library_geometries"):
                    seen[name] = el
            if len(seen) == len(_ASSUMED):
                return _asset_fault(seen["asset"]) and _collada_tree_fault(data, path)
    except etree.XMLSyntaxError:
        pass
    return _collada_tree_fault(data, path)


def _collada_tree_fault(data: bytes, path: str | Path) -> str | None:
    """:func:`collada_data_fault` judged on the whole document."""
    from urdfkit.model.xmlio import parse_xml

    try:  # tolerant of what tinyxml2 tolerates (undeclared prefixes, declaration quirks)
        root = parse_xml(data, path).getroot()
    except InputError:
        # tinyxml2 fails on it too, and PyBullet then skips the file; unless it holds no
        # element at all, which tinyxml2 parses and PyBullet reads as a null root.
        return None if _holds_an_element(data) else \
            "holds no XML element (only a declaration, comments or a DOCTYPE)"
    for name in _ASSUMED:
        if _first_child(root, name) is None:
            return (f"has no <{name}> element in its <{_tinyxml_name(root)}>"
                    + ("; add <asset><unit meter=\"1\"/><up_axis>Z_UP</up_axis></asset> as "
                       "its first child" if name == "asset" else ""))
    return _asset_fault(_first_child(root, "asset"))


def _asset_fault(asset: Any) -> str | None:
    unit = _first_child(asset, "unit")
    if unit is not None and unit.get("meter") is None:  # atof(NULL)
        return "has an <asset><unit> without a meter attribute; add meter=\"1\""
    up = _first_child(asset, "up_axis")
    if up is not None and not (up.text or "").strip():  # std::string(NULL): an abort
        return "has an <asset><up_axis> without text; write Z_UP or Y_UP in it"
    return None


def _tinyxml_name(el: Any) -> str:
    """An element's name as tinyxml2 compares it: the prefix and the local name."""
    tag = el.tag if isinstance(el.tag, str) else ""
    local = tag.rpartition("}")[2]
    return f"{el.prefix}:{local}" if el.prefix else local


def _first_child(el: Any, name: str) -> Any:
    """tinyxml2's ``FirstChildElement(name)``: the first child element named exactly so."""
    for child in el:
        if isinstance(child.tag, str) and _tinyxml_name(child) == name:
            return child
    return None


#: What may stand in a document beside its elements: comments, PIs (the declaration), a
#: DOCTYPE with its internal subset.
_NOT_ELEMENTS = re.compile(rb"<!--.*?-->|<\?.*?\?>|<!DOCTYPE(?:[^>\[]|\[.*?\])*>", re.DOTALL)


def _holds_an_element(data: bytes) -> bool:
    """Whether ``data`` has markup other than comments, PIs and a DOCTYPE (or none at all)."""
    rest = _NOT_ELEMENTS.sub(b"", data)
    return b"<" in rest or rest == data


# --------------------------------------------------------------------------- convex hulls


def hull_fault(path: str, scale: Sequence[float] = (1.0, 1.0, 1.0),
               st: os.stat_result | None = None) -> str | None:
    """What makes PyBullet 3.2.7's convex hull of this collision mesh crash or hang, or None.

    ``scale`` is the ``<mesh scale>``, which PyBullet applies before the hull. A clause to
    follow "its vertices" ("mix NaN with numbers along y ..."); ``st`` as in
    :func:`collada_fault`.
    """
    three = (float(scale[0]), float(scale[1]), float(scale[2]))
    return _remembered(path, st, ("hull", *three), lambda: _hull_file_fault(path, three))


#: An exponent past float32's, in lower-case text (PyBullet keeps vertices as float: 1e39 is
#: an infinity to it), where it ends a number.
_BIG_EXPONENT = re.compile(rb"e\+?0*(?:3[89]|[4-9][0-9]|[1-9][0-9]{2,})(?![0-9a-z_.])")
#: What may stand before a number in an OBJ or COLLADA file (a space, a tag's end, a sign, a
#: quote); "minfilter" and "feature45" are no numbers.
_BEFORE_NUMBER = frozenset(b" \t\r\n\x0b\x0c>+-\"',;:=(/")
_IN_MANTISSA = frozenset(b"0123456789.")


def _text_all_finite(data: bytes) -> bool:
    """Whether the text of an OBJ or COLLADA file spells no non-finite number.

    No number that starts with ``nan`` or ``inf`` in any case (``-nan``, ``Infinity``: C's
    atof reads them all), and none whose exponent float32 overflows at. Cheap: one lower-case
    copy, searches at C speed (~2 ms a megabyte), and Python only at the few words that hold
    "nan" or "inf" ("minfilter" in a textured COLLADA) or an "e" followed by digits.
    """
    low = data.lower()
    for word in (b"nan", b"inf"):
        at = low.find(word)
        while at >= 0:
            if at == 0 or low[at - 1] in _BEFORE_NUMBER:
                return False
            at = low.find(word, at + 3)
    return not any(m.start() > 0 and low[m.start() - 1] in _IN_MANTISSA
                   for m in _BIG_EXPONENT.finditer(low))


def _hull_file_fault(path: str, scale: tuple[float, float, float]) -> str | None:
    suffix = os.path.splitext(path)[1].lower()
    data = _read(path)
    if data is None:
        return None
    if suffix == ".stl":
        count = int.from_bytes(data[80:84], "little") if len(data) >= 84 else -1
        if 84 + 50 * count != len(data):
            return None  # not a binary STL: PyBullet 3.2.7 reads no other (nothing collides)
        if _stl_all_finite(data):
            return None
    elif suffix in (".obj", ".dae"):
        if _text_all_finite(data):
            return None
    else:
        return None
    # Only finite vertices stay finite under any scale, or turn a whole axis NaN or infinite
    # (scale NaN, inf): no mixed axis can come of them, and the common case ends above.
    return _vertices_fault(data, suffix, path, scale)


def _stl_all_finite(data: bytes) -> bool:
    """Whether every vertex float of a binary STL is finite (and below 2^127 in size).

    Each 50-byte triangle holds its normal, nine vertex floats (little-endian) and two bytes.
    A float is NaN or infinite only when its exponent is all ones, which puts 0x7F or 0xFF in
    its last byte (so does a finite one of 1.7e38 or more): the last byte of each of the nine
    is taken from every triangle by a strided slice, and searched, at C speed.
    """
    for j in range(9):
        high = data[84 + 12 + 4 * j + 3::50]
        if b"\x7f" in high or b"\xff" in high:
            return False
    return True


def _vertices_fault(data: bytes, suffix: str, path: str,
                    scale: tuple[float, float, float]) -> str | None:
    """The hull test on the vertices PyBullet hulls, read from the file (numpy)."""
    import numpy as np

    from urdfkit.sources.meshes import parse_mesh

    if suffix == ".stl":  # every corner, as written (PyBullet keeps them all)
        count = (len(data) - 84) // 50
        rec = np.frombuffer(data, dtype=np.dtype([("n", "<f4", 3), ("v", "<f4", (3, 3)),
                                                  ("a", "<u2")]), count=count, offset=84)
        pieces = [rec["v"].reshape(-1, 3)]
    else:
        parsed = parse_mesh(data, suffix, Path(path))
        if parsed is None:
            return None
        vertices, faces, starts = parsed
        vertices = np.asarray(vertices, dtype=np.float32)  # PyBullet's vertices are float
        faces = np.asarray(faces)
        faces = faces[((faces >= 0) & (faces < len(vertices))).all(axis=1)]
        # The vertices the triangles use (PyBullet hulls no other), one hull per OBJ object.
        bounds = [0, *starts, len(faces)]
        pieces = [vertices[np.unique(faces[lo:hi])] for lo, hi in zip(bounds, bounds[1:],
                                                                      strict=False) if hi > lo]
    for number, corners in enumerate(pieces, 1):
        with np.errstate(invalid="ignore", over="ignore"):  # inf * 0 is NaN, as in PyBullet
            placed = corners.astype(np.float64) * np.array(scale)
        why = _mixed_axes(placed)
        if why is not None:
            where = f" in object {number} of {len(pieces)}" if len(pieces) > 1 else ""
            return f"{why}{where}"
    return None


def _mixed_axes(points: Any) -> str | None:
    """Which axes of ``points`` hold NaN beside numbers (and no infinity), said; or None."""
    import numpy as np

    nan = np.isnan(points)
    mixed = nan.any(axis=0) & ~nan.all(axis=0) & ~np.isinf(points).any(axis=0)
    if not mixed.any():
        return None
    axes = " and ".join("xyz"[a] for a in np.flatnonzero(mixed).tolist())
    bad = int(nan[:, mixed].any(axis=1).sum())
    return (f"mix NaN with numbers along {axes} ({bad} of {len(points)} vertices have a NaN "
            "there)")
