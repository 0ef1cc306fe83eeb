"""Safe XML parsing and deterministic XML text.

Every URDF that urdfkit reads goes through :func:`parse_xml`, which refuses external
entities, network access and huge trees, so a hostile file cannot read ``/etc/passwd``
through an entity or exhaust memory with a billion-laughs bomb.
"""

from __future__ import annotations

import errno
import math
import os
import re
import stat
from _thread import _local as thread_local  # threading.local, without threading (~0.5 ms)
from collections.abc import Iterator
from pathlib import Path

from lxml import etree

from urdfkit.core import deps as _deps
from urdfkit.core.errors import InputError
from urdfkit.model.spec import PYBULLET_LINE_BYTES

#: Files larger than this are refused before parsing; real URDFs are far smaller.
MAX_FILE_BYTES = 32 * 1024 * 1024


#: libxml2 keeps an element's line in 16 bits; past this it finds the true line from the
#: whitespace text after the tag, which ``remove_blank_text`` drops (every later element
#: then reads 65,535).
BIG_LINES = 65535


def _parser(lines: int = 0) -> etree.XMLParser:
    """The parser for a document of ``lines`` lines, made once per thread for each kind."""
    big = lines >= BIG_LINES
    parsers = getattr(_PARSERS, "made", None)
    if parsers is None:
        parsers = _PARSERS.made = {}
    parser = parsers.get(big)
    if parser is None:
        parser = parsers[big] = _new_parser(big)
    return parser


#: lxml parsers are not shared between threads (the viewer parses in its own).
_PARSERS = thread_local()


def _new_parser(big: bool) -> etree.XMLParser:
    return etree.XMLParser(
        resolve_entities=False,
        no_network=True,
        huge_tree=False,
        load_dtd=False,
        dtd_validation=False,
        remove_comments=False,
        # Blank text is dropped for speed, except in a file long enough that findings past
        # line 65,535 need it to carry their line (nothing reads URDF element text).
        remove_blank_text=not big,
    )


def read_bytes(path: str | Path) -> bytes:
    """Read a URDF (or xacro, or mesh) file for parsing; see :func:`read_regular`."""
    return read_regular(path)


def read_regular(path: str | Path, *, limit: int = MAX_FILE_BYTES,
                 kind: str = "URDF file", track: bool = True) -> bytes:
    """Read a regular file: never a FIFO, device, socket or folder; never more than ``limit``.

    Every file urdfkit reads comes through here (URDF, xacro output, scenarios and configs,
    sweep rows, meshes, cache entries). The file is opened non-blocking (a FIFO would
    otherwise wait forever for a writer), then ``fstat`` on the open descriptor decides: only
    a regular file is read. The size cap counts bytes as they are read, never trusting
    ``st_size`` (0 for /dev/zero behind a symlink). ``kind`` names what was expected.

    Raises:
        InputError: one line naming the file.
    """
    name = os.fspath(path)
    if track:  # check's result cache: this result depends on the file (cache entries do not)
        _deps.note(name)
    try:
        fd = os.open(name, _READ_FLAGS)
    except FileNotFoundError:
        dangling = os.path.islink(name)
        raise InputError("no such file: it is a symlink to nothing" if dangling
                         else "no such file", file=Path(name)) from None
    except IsADirectoryError:
        raise InputError(f"is a directory, not a {kind}", file=Path(name)) from None
    except OSError as e:
        why = {errno.ENAMETOOLONG: "a path component is longer than the file system allows",
               errno.EACCES: "permission denied", errno.ELOOP: "a symlink loop"}
        raise InputError(f"cannot read: {why.get(e.errno or 0, e.strerror)}",
                         file=Path(name)) from None
    except ValueError:  # a NUL byte in the name
        raise InputError("cannot read: the path holds a NUL byte", file=Path(name)) from None
    try:
        st = os.fstat(fd)
        mode = st.st_mode
        if not stat.S_ISREG(mode):
            what = ("a directory" if stat.S_ISDIR(mode) else "a FIFO (named pipe)"
                    if stat.S_ISFIFO(mode) else "a device" if stat.S_ISCHR(mode) or
                    stat.S_ISBLK(mode) else "a socket" if stat.S_ISSOCK(mode) else "special")
            raise InputError(f"is {what}, not a regular file; urdfkit reads only regular "
                             "files", file=Path(name))
        chunks, size = [], 0
        # Ask for one byte more than the file holds: a shorter answer is the end of the file,
        # so the common case is one read, not two (a file growing meanwhile reads on).
        want = min(st.st_size, limit) + 1
        while True:
            try:
                chunk = os.read(fd, want)
            except BlockingIOError:  # pragma: no cover - regular files never block
                continue
            except OSError as e:
                raise InputError(f"cannot read: {e.strerror}", file=Path(name)) from None
            if not chunk:
                break
            size += len(chunk)
            if size > limit:
                raise InputError(f"file is over {_size(limit)}; urdfkit refuses larger "
                                 f"{kind}s", file=Path(name))
            chunks.append(chunk)
            if len(chunk) < want and size >= st.st_size:
                break
            want = 1 << 20
        return chunks[0] if len(chunks) == 1 else b"".join(chunks)
    finally:
        os.close(fd)


_READ_FLAGS = os.O_RDONLY | getattr(os, "O_NONBLOCK", 0) | getattr(os, "O_CLOEXEC", 0)


def _size(n: int) -> str:
    return f"{n / (1 << 30):g} GiB" if n >= 1 << 30 else f"{n / (1 << 20):g} MiB" \
        if n >= 1 << 20 else f"{n:,} bytes"


#: An XML declaration anywhere near the start of a file.
_DECL = re.compile(rb"<\?xml\s[^>]*?\?>")


#: A line after the first that PyBullet would break: the leading newline lets the search jump
#: from line to line (a pattern starting with a literal is searched for at C speed).
_LONG_LINE = re.compile(rb"\n[^\n]{%d}" % (PYBULLET_LINE_BYTES + 1))


def long_line(data: bytes) -> tuple[int, int] | None:
    """The first line PyBullet would break (longer than PYBULLET_LINE_BYTES): (line, bytes)."""
    size = len(data)
    if size <= PYBULLET_LINE_BYTES:
        return None
    first = data.find(b"\n")
    if (size if first < 0 else first) > PYBULLET_LINE_BYTES:
        start = 0
    else:
        m = _LONG_LINE.search(data)
        if m is None:
            return None
        start = m.start() + 1
    end = data.find(b"\n", start)
    return data.count(b"\n", 0, start) + 1, (size if end < 0 else end) - start


def tolerate_quirks(data: bytes) -> tuple[bytes, list[tuple[int, str]]]:
    """Repair the XML quirks PyBullet's tinyxml2 accepts but libxml2 refuses.

    pybullet_data itself ships such files (``plane.urdf`` declares ``version="0.0"``,
    ``humanoid.urdf`` ends in a NUL byte, ``biped2d_pybullet.urdf`` has blank lines before the
    declaration), and Gazebo extensions in real packages use namespace prefixes they never
    declare (``<sensor:camera>``). Refusing them would refuse files PyBullet loads. Line
    numbers are kept.

    Returns:
        The repaired bytes and ``(line, note)`` pairs saying what was repaired.
    """
    data, notes = _declaration_quirks(data)
    return _declare_prefixes(data, notes)


#: A prefixed name, cheaply (a tag ``<sensor:camera`` or an attribute ``sensor:x=``); a start
#: tag with its attributes; a prefixed attribute; a namespace declaration.
_PREFIXED = re.compile(rb"[<\s]([A-Za-z_][\w.-]*):[A-Za-z_]")
#: A colon a name follows: where a prefix ends (a literal first character, so the search runs
#: at C speed instead of trying a match at every blank).
_COLON = re.compile(rb":[A-Za-z_]")
#: The bytes of an XML name as _PREFIXED reads one (a bytes pattern's \w is ASCII).
_NAME_BYTES = b"ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789_.-"
_NAME_STARTS = frozenset(b"ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz_")
_BEFORE_NAME = frozenset(b"< \t\n\r\f\v")
_TAG = re.compile(rb"<(/?)(?![?!])([^\s/>]+)([^>]*?)(/?)>")
_ATTR = re.compile(rb"\s([A-Za-z_][\w.-]*):([A-Za-z_][\w.-]*)\s*=")
_DECLARED = re.compile(rb"xmlns:([A-Za-z_][\w.-]*)\s*=")
_START = re.compile(rb"<(?![?!/])[^\s/>]+")
#: What no parser reads as markup: comments, CDATA sections, processing instructions.
_NOT_MARKUP = re.compile(rb"<!--.*?-->|<!\[CDATA\[.*?\]\]>|<\?.*?\?>", re.DOTALL)


def used_prefixes(data: bytes) -> set[bytes]:
    """``set(_PREFIXED.findall(data))``: every prefix written before a colon, from each colon.

    The pattern itself tries a match at every ``<`` and blank of the file (11 ms over
    pybullet_data's 42 files that hold a colon); a colon followed by a name is rare, and the
    name before it is the run of name bytes that ends there (``bytes.rstrip`` at C speed),
    which must start with a letter or ``_`` right after a ``<`` or a blank. The two agree on
    every input (tests/test_quirks.py holds them to it).
    """
    found: set[bytes] = set()
    for m in _COLON.finditer(data):
        end = m.start()
        width = 64
        while True:  # widen the window until the run starts inside it (or at the file start)
            low = max(0, end - width)
            start = low + len(data[low:end].rstrip(_NAME_BYTES))
            if start > low or low == 0:
                break
            width *= 4
        if start < end and start > 0 and data[start] in _NAME_STARTS \
                and data[start - 1] in _BEFORE_NAME:
            found.add(data[start:end])
    return found


def _markup_only(data: bytes) -> bytes:
    """``data`` with comments, CDATA and processing instructions blanked, offsets kept.

    A commented-out ``<!-- <xacro:include .../> -->`` declares nothing and uses nothing.
    """
    if b"<!" not in data and b"<?" not in data:
        return data
    return _NOT_MARKUP.sub(lambda m: b" " * len(m.group(0)), data)


def _declare_prefixes(data: bytes, notes: list[tuple[int, str]]
                      ) -> tuple[bytes, list[tuple[int, str]]]:
    """Declare the namespace prefixes a document uses but never declares.

    tinyxml2 knows nothing of namespaces: to PyBullet ``<sensor:camera>`` is just an element it
    does not read, ``<link sensor:x="1">`` an attribute it does not read. libxml2 refuses the
    document. Comments, CDATA and processing instructions are not looked in; a declaration
    holds inside its element only, as in libxml2. Each such prefix is declared in the root's
    start tag (no newline added, so no line number moves; declarations further in still
    shadow it), and noted.
    """
    if b":" not in data:
        return data, notes  # no prefix anywhere
    root = _START.search(data)
    prefixes = used_prefixes(data) - {b"xml", b"xmlns"}
    if root is None or not prefixes:
        return data, notes
    root_tag = data[root.start():data.find(b">", root.start()) + 1]
    if prefixes <= set(_DECLARED.findall(root_tag)):
        return data, notes  # the common case, without looking at each tag
    markup = _markup_only(data)
    root = _START.search(markup)
    if root is None:
        return data, notes
    if not prefixes & set(_DECLARED.findall(markup)):
        first = _first_uses(markup, prefixes)  # declared nowhere: no walk needed
    else:
        first = _first_uses_out_of_scope(markup)
    return _declare(data, markup, root, first, notes)


def _first_uses(markup: bytes, prefixes: set[bytes]) -> dict[bytes, tuple[int, str]]:
    """{prefix: (offset, what uses it)} of the first use of each prefix declared nowhere.

    With no declaration anywhere, the first use is the first out of scope: found by a search
    per prefix, without walking the tags.
    """
    first: dict[bytes, tuple[int, str]] = {}
    for prefix in sorted(prefixes):
        p = re.escape(prefix)
        element = re.search(rb"<" + p + rb":[^\s/>]+", markup)
        attribute = re.search(rb"(?<=\s)" + p + rb":[A-Za-z_][\w.-]*(?=\s*=)", markup)
        for m, shown in ((element, "<{}>"), (attribute, "{}=...")):
            if m is not None and (prefix not in first or m.start() < first[prefix][0]):
                text = m.group(0).decode("utf-8", "replace").lstrip("<")
                first[prefix] = (m.start(), shown.format(text))
    return first


def _first_uses_out_of_scope(markup: bytes) -> dict[bytes, tuple[int, str]]:
    """{prefix: (offset, what uses it)} of the first use of each prefix out of its scope.

    Walks the tags with the declarations in scope: a prefix declared on one ``<gazebo>`` is
    not declared on the next one.
    """
    first: dict[bytes, tuple[int, str]] = {}
    scopes: list[set[bytes]] = []
    in_scope: set[bytes] = {b"xml", b"xmlns"}
    for tag in _TAG.finditer(markup):
        if tag.group(1):  # an end tag
            if scopes:
                in_scope = scopes.pop()
            continue
        raw, attrs = tag.group(2), tag.group(3)
        here = in_scope | set(_DECLARED.findall(attrs))
        name = raw.decode("utf-8", "replace")
        if b":" in raw and raw.partition(b":")[0] not in here:
            first.setdefault(raw.partition(b":")[0], (tag.start(), f"<{name}>"))
        for attr in _ATTR.finditer(attrs):
            if attr.group(1) not in here:  # an attribute (PyBullet ignores it too)
                what = f"<{name} {attr.group(0).decode().strip()}...>"
                first.setdefault(attr.group(1), (tag.start(3) + attr.start(1), what))
        if not tag.group(4):  # not <empty/>: its declarations hold until its end tag
            scopes.append(in_scope)
            in_scope = here
    return first


def _declare(data: bytes, markup: bytes, root: re.Match[bytes],
             first: dict[bytes, tuple[int, str]], notes: list[tuple[int, str]]
             ) -> tuple[bytes, list[tuple[int, str]]]:
    """Note each prefix of ``first`` and declare it in the root's start tag."""
    missing = sorted(first, key=lambda prefix: first[prefix][0])
    if not missing:
        return data, notes
    for prefix in missing:
        at, used = first[prefix]
        name = prefix.decode()
        notes.append((data.count(b"\n", 0, at) + 1,
                      f"namespace prefix {name!r} is used ({used}) where it is not declared: "
                      "PyBullet ignores what it names, other XML parsers refuse the file; "
                      f"declare xmlns:{name} on <robot>"))
    extra = b"".join(b' xmlns:' + prefix + b'="urn:urdfkit:undeclared:' + prefix + b'"'
                     for prefix in missing)
    return data[:root.end()] + extra + data[root.end():], notes


#: What only xacro writes and expands: an element of it, a ``${...}`` expression or a
#: ``$(arg ...)``-style substitution. Not the ``xmlns:xacro`` declaration alone, which xacro's
#: own output keeps (17 expanded files in the corpus declare it and hold no xacro).
_XACRO = re.compile(rb"<xacro:|\$\{[^}\n]{0,200}\}"
                    rb"|\$\((?:arg|find|env|optenv|eval|dirname|cwd)\b")


def xacro_marker(data: bytes) -> tuple[int, str] | None:
    """``(line, what)`` of the first thing in ``data`` only xacro writes, or None.

    A ``.urdf`` holding xacro (ROS 2 packages ship these) is URDF to nobody: read as it is,
    its links are named ``${prefix}base_link``.
    """
    if b"$" not in data and b"<xacro:" not in data:
        return None  # what every match needs (a scan at C speed)
    m = _XACRO.search(data)
    while m is not None:
        opened = data.rfind(b"<!--", 0, m.start())
        if opened < 0 or data.find(b"-->", opened, m.start()) >= 0:
            break  # not inside a comment
        closed = data.find(b"-->", m.start())
        m = _XACRO.search(data, closed + 3) if closed >= 0 else None
    if m is None:
        return None
    found = m.group(0).decode("utf-8", "replace")
    return data.count(b"\n", 0, m.start()) + 1, found if len(found) <= 60 else found[:57] + "..."


def xacro_note(what: str) -> str:
    """What to say of a ``.urdf`` holding xacro (``what``: :func:`xacro_marker`'s)."""
    return (f"holds xacro ({what}) but is not a .xacro file: it is read as plain URDF, "
            "expressions and all taken literally (links named '${prefix}base_link'); expand "
            "it first: urdfkit build FILE")


def undeclared_prefixes(data: bytes) -> list[tuple[int, str]]:
    """``(line, note)`` for each namespace prefix ``data`` uses but never declares."""
    return _declare_prefixes(data, [])[1]


def _declaration_quirks(data: bytes) -> tuple[bytes, list[tuple[int, str]]]:
    """The quirks of NUL bytes and the XML declaration (see :func:`tolerate_quirks`)."""
    notes: list[tuple[int, str]] = []
    trimmed = data.rstrip(b"\0 \t\r\n")
    if b"\0" in data[len(trimmed):]:
        # tinyxml2 reads the file as a C string: everything after a NUL is invisible to it.
        notes.append((trimmed.count(b"\n") + 1, "the file ends in NUL bytes; PyBullet ignores "
                      "them but other XML parsers refuse the file: remove them"))
        data = trimmed
    # Every declaration holds "<?xml": most files have none, and a find runs at C speed.
    m = _DECL.search(data, 0, 4096) if data.find(b"<?xml", 0, 4096) >= 0 else None
    if m is None:
        return data, notes
    decl = m.group(0)
    line = data.count(b"\n", 0, m.start()) + 1
    version = re.search(rb"""version\s*=\s*["']([^"']*)["']""", decl)
    if m.start() > 0 and not data[:m.start()].strip(b" \t\r\n\xef\xbb\xbf"):
        notes.append((line, "the XML declaration is not at the very start of the file; remove "
                      "the blank lines before it"))
        enc = re.search(rb"""encoding\s*=\s*["']([^"']*)["']""", decl)
        if enc and enc.group(1).lower() not in (b"utf-8", b"utf8", b"ascii", b"us-ascii"):
            try:
                data = data.decode(enc.group(1).decode("ascii")).encode("utf-8")
            except (LookupError, UnicodeError):
                return data, notes
            m = _DECL.search(data, 0, 4096)
            if m is None:  # pragma: no cover - the declaration survives re-encoding
                return data, notes
        # Blank the declaration out, keeping every newline so lines still match the file.
        data = data[:m.start()] + b" " * len(m.group(0)) + data[m.end():]
    elif version and not version.group(1).startswith(b"1."):
        said = version.group(1).decode("ascii", "replace")
        notes.append((line, f"the XML declaration says version=\"{said}\"; PyBullet ignores "
                      "it but other XML parsers refuse it: write version=\"1.0\""))
        fixed = decl[:version.start(1)] + b"1.0" + decl[version.end(1):]
        data = data[:m.start()] + fixed + data[m.end():]
    return data, notes


def parse_xml(data: bytes, file: str | Path, *, tolerated: bool = False) -> etree._ElementTree:
    """Parse XML bytes safely; malformed input raises :class:`InputError` with the line.

    ``tolerated``: ``data`` already went through :func:`tolerate_quirks` (check reads its
    notes first), so it is not repaired twice.
    """
    if not data.strip():
        raise InputError("file is empty", file=file)
    if not tolerated:
        data, _ = tolerate_quirks(data)
    try:
        # Lines are counted only where there can be BIG_LINES of them (a line is a byte).
        lines = data.count(b"\n") if len(data) >= BIG_LINES else 0
        root = etree.fromstring(data, _parser(lines))
    except etree.XMLSyntaxError as e:
        line = e.lineno if e.lineno else None
        msg = str(e.msg if hasattr(e, "msg") and e.msg else e)
        # lxml appends "(line N, column M)"; we report the line ourselves.
        msg = msg.split(", line ")[0]
        raise InputError(f"not well-formed XML: {msg}", file=file, line=line) from None
    except ValueError as e:  # e.g. unicode strings with encoding declarations
        raise InputError(f"not well-formed XML: {e}", file=file) from None
    if b"&" in data or b"<!" in data:  # no entity and no DTD without either (a C scan)
        _refuse_entities(root, file)
    if lines >= BIG_LINES:
        _remember_lines(root, data)
    return root.getroottree()


#: Start tags, and what may hide a ``<`` that starts none (comments, CDATA, PIs, a DOCTYPE
#: with its internal subset). ``<`` cannot stand in attribute values or text in XML.
_TAGS = (r"<!--.*?-->|<!\[CDATA\[.*?\]\]>|<\?.*?\?>|<!DOCTYPE(?:[^>\[]|\[.*?\])*>"
         r"|<(?=[^/!?])")
_TAGS_BYTES = re.compile(_TAGS.encode(), re.DOTALL)
_TAGS_TEXT = re.compile(_TAGS, re.DOTALL)

#: The true lines of the elements of the last few long documents, by document key and
#: element path: lxml reads 65,535 for every element past that line.
_BIG: dict[str, dict[str, int]] = {}
_BIG_KEEP = 8


def start_tags(data: bytes | str) -> list[int]:
    """Offsets of the element start tags in ``data`` (bytes or text), in document order.

    The n-th offset is the n-th element of ``root.iter()`` (elements only): a position for
    every element that relies neither on lxml's line numbers nor on finding its tag name
    (a prefixed ``<xacro:arg>``, a ``<link`` inside a comment).
    """
    found = _TAGS_TEXT.finditer(data) if isinstance(data, str) else _TAGS_BYTES.finditer(data)
    return [m.start() for m in found if m.end() - m.start() == 1]


def _remember_lines(root: etree._Element, data: bytes) -> None:
    import bisect

    newlines = [m.start() for m in re.finditer(rb"\n", data)]
    elements = (el for el in root.iter() if isinstance(el.tag, str))
    tree = root.getroottree()
    lines = {tree.getpath(el): bisect.bisect_left(newlines, pos) + 1
             for el, pos in zip(elements, start_tags(data), strict=False)}
    key = f"urdfkit-big-lines:{next(_KEYS)}"
    tree.docinfo.URL = key  # survives with the document, unlike Python attributes on proxies
    _BIG[key] = lines
    while len(_BIG) > _BIG_KEEP:
        del _BIG[next(iter(_BIG))]


_KEYS = iter(range(1, 1 << 62))


def line_of(el: etree._Element) -> int | None:
    """The line an element starts on, past 65,535 too (where lxml's ``sourceline`` stops)."""
    line = el.sourceline
    if line is None or line < BIG_LINES:
        return line
    tree = el.getroottree()
    found = _BIG.get(tree.docinfo.URL or "")
    return found.get(tree.getpath(el), line) if found is not None else line


def _refuse_entities(root: etree._Element, file: str | Path) -> None:
    # With resolve_entities=False, entity references survive as nodes; a URDF has no
    # business declaring them, and expanding them is how XXE and entity bombs work.
    docinfo = root.getroottree().docinfo
    if docinfo.internalDTD is not None and len(list(docinfo.internalDTD.iterentities())) > 0:
        raise InputError("declares XML entities; urdfkit refuses them (XXE / entity bombs)",
                         file=file, line=1)
    for node in root.iter(etree.Entity):
        raise InputError("uses an XML entity reference; urdfkit refuses them",
                         file=file, line=line_of(node))


def load_xml(path: str | Path) -> etree._ElementTree:
    """Read and safely parse an XML file."""
    return parse_xml(read_bytes(path), path)


def fmt_float(x: float, digits: int = 10) -> str:
    """Format a float deterministically: fixed significant digits, no ``-0``.

    ``0.1 * 3`` prints as ``0.3``, not ``0.30000000000000004``, so golden files never churn.
    """
    if not math.isfinite(x):
        raise ValueError(f"cannot write non-finite number {x!r}")
    s = f"{x:.{digits}g}"
    if float(s) == 0.0:
        return "0"
    return s


def fmt_vec(v: tuple[float, ...] | list[float]) -> str:
    """Format a vector as space-separated deterministic floats."""
    return " ".join(fmt_float(x) for x in v)


def to_bytes(root: etree._Element) -> bytes:
    """Serialize pretty-printed with an XML declaration and a trailing newline."""
    etree.indent(root, space="  ")
    body = etree.tostring(root, encoding="utf-8", pretty_print=True)
    return b'<?xml version="1.0" encoding="utf-8"?>\n' + body


# --------------------------------------------------------------------------- reading values


def children(root: etree._Element, tag: str) -> Iterator[etree._Element]:
    """Direct child elements named ``tag`` (filtered by lxml, in C)."""
    return root.iterchildren(tag)
