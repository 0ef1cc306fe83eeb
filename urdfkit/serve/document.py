"""Where each name is in a URDF or xacro text, for an editor: definitions, uses, positions.

An editor asks by line and column, which lxml does not keep (it keeps an element's line, and
gives up on a half-typed file). This reads the text as it is being typed: each start tag and
its quoted attributes, comments skipped, and each ``${...}`` and ``$(arg ...)``. What is
defined (links, joints, xacro macros, properties and args) and what refers to it (a joint's
``parent`` and ``child`` links, a ``<mimic joint>``, a macro call, a property in an
expression, an arg) are :class:`Name` records with their 0-based line and columns.
"""

from __future__ import annotations

import bisect
import re
from dataclasses import dataclass, field

#: A start tag with its attributes (across lines); an unfinished one is taken up to where it
#: stops being a tag, so that a half-typed file still has its names.
_TAG = re.compile(r"<([A-Za-z_][\w:.-]*)((?:\s+[\w:.-]+\s*=\s*(?:\"[^\"<]*\"|'[^'<]*'))*)\s*(/?)>?")
_ATTR = re.compile(r"([\w:.-]+)\s*=\s*(?:\"([^\"<]*)\"|'([^'<]*)')")
_COMMENT = re.compile(r"<!--.*?(?:-->|\Z)", re.S)
_EXPR = re.compile(r"\$\{([^}]*)\}?")
_IDENT = re.compile(r"[A-Za-z_]\w*")
_ARG = re.compile(r"\$\(\s*arg\s+([\w.-]+)\s*\)")
#: xacro's own instructions: a ``xacro:`` tag of another name calls a macro.
XACRO_TAGS = frozenset({"macro", "property", "arg", "include", "if", "unless", "insert_block",
                        "call", "element", "attribute", "eval-comments"})
#: Names an expression may use that no property defines.
_BUILTINS = frozenset({"pi", "e", "radians", "degrees", "sin", "cos", "tan", "asin", "acos",
                       "atan", "atan2", "sqrt", "abs", "min", "max", "int", "float", "str",
                       "len", "round", "floor", "ceil", "pow", "True", "False", "None", "and",
                       "or", "not", "in", "if", "else", "xacro", "math", "load_yaml",
                       "dotify", "list", "dict", "tuple", "range", "sum", "bool", "inf", "nan",
                       "python"})


@dataclass(frozen=True)
class Span:
    """A stretch of one line: 0-based line, start and end columns (Python characters)."""

    line: int
    start: int
    end: int

    def holds(self, line: int, column: int) -> bool:
        """Whether the position is inside (or just after) the span."""
        return self.line == line and self.start <= column <= self.end


@dataclass(frozen=True)
class Name:
    """One name in the text.

    Attributes:
        kind: ``link``, ``joint``, ``macro``, ``property``, ``arg``: a definition, or a use of
            one with ``use`` True; ``include`` for an included file's name.
        name: The name.
        span: Where it is written.
        tag: The element it is in (``link``, ``xacro:macro``, ``parent``...).
        detail: A macro's params, a property's value, an arg's default.
        element: Where the element starts (its ``<``).
    """

    kind: str
    name: str
    span: Span
    tag: str
    use: bool = False
    detail: str = ""
    element: Span | None = None


@dataclass
class Tag:
    """One start tag: its name, attributes (name -> value span and text), where it starts."""

    name: str
    start: int
    end: int
    attrs: dict[str, tuple[int, int, str]] = field(default_factory=dict)
    closed: bool = False


class Document:
    """A text's tags and names, read once (:func:`read`)."""

    def __init__(self, text: str) -> None:
        self.text = text
        self._starts = [0] + [m.end() for m in re.finditer("\n", text)]
        self.tags: list[Tag] = []
        self.names: list[Name] = []
        comments = [(m.start(), m.end()) for m in _COMMENT.finditer(text)]
        self._comments = comments
        for m in _TAG.finditer(text):
            if self._commented(m.start()):
                continue
            tag = Tag(m.group(1), m.start(), m.end(), closed=bool(m.group(3)))
            base = m.start(2)
            for a in _ATTR.finditer(m.group(2)):
                value = a.group(2) if a.group(2) is not None else a.group(3)
                vstart = base + a.start(2 if a.group(2) is not None else 3)
                tag.attrs[a.group(1)] = (vstart, vstart + len(value), value)
            self.tags.append(tag)
            self._names_of(tag)
        self._expressions()

    # ---- positions

    def position(self, offset: int) -> tuple[int, int]:
        """An offset as (0-based line, column)."""
        line = bisect.bisect_right(self._starts, offset) - 1
        return line, offset - self._starts[line]

    def offset(self, line: int, column: int) -> int:
        """A (line, column) as an offset (clamped to the text)."""
        if line >= len(self._starts):
            return len(self.text)
        return min(self._starts[line] + column, len(self.text))

    def span(self, start: int, end: int) -> Span:
        """The span of ``text[start:end]`` (on the line it starts on)."""
        line, col = self.position(start)
        return Span(line, col, col + (end - start))

    def _commented(self, offset: int) -> bool:
        i = bisect.bisect_right(self._comments, (offset, len(self.text) + 1)) - 1
        return i >= 0 and self._comments[i][0] <= offset < self._comments[i][1]

    # ---- names

    def _add(self, kind: str, tag: Tag, attr: str, use: bool = False, detail: str = "") -> None:
        if attr not in tag.attrs:
            return
        start, end, value = tag.attrs[attr]
        if not value:
            return
        self.names.append(Name(kind, value, self.span(start, end), tag.name, use, detail,
                               self.span(tag.start, tag.start + 1)))

    def _names_of(self, tag: Tag) -> None:
        t = tag.name
        if t == "link":
            self._add("link", tag, "name")
        elif t == "joint":
            self._add("joint", tag, "name")
        elif t in ("parent", "child"):
            self._add("link", tag, "link", use=True)
        elif t == "mimic":
            self._add("joint", tag, "joint", use=True)
        elif t.startswith("xacro:"):
            word = t[6:]
            if word == "macro":
                self._add("macro", tag, "name", detail=tag.attrs.get("params", (0, 0, ""))[2])
            elif word == "property":
                value = tag.attrs.get("value", (0, 0, ""))[2]
                self._add("property", tag, "name", detail=value)
            elif word == "arg":
                self._add("arg", tag, "name", detail=tag.attrs.get("default", (0, 0, ""))[2])
            elif word == "include":
                self._add("include", tag, "filename")
            elif word not in XACRO_TAGS:
                start = tag.start + 1 + len("xacro:")
                self.names.append(Name("macro", word, self.span(start, start + len(word)),
                                       t, True, element=self.span(tag.start, tag.start + 1)))

    def _expressions(self) -> None:
        for m in _EXPR.finditer(self.text):
            if self._commented(m.start()):
                continue
            body, base = m.group(1), m.start(1)
            for ident in _IDENT.finditer(body):
                before = body[:ident.start()].rstrip()
                if ident.group() in _BUILTINS or before.endswith(".") or \
                        _quoted(body, ident.start()):
                    continue
                start = base + ident.start()
                self.names.append(Name("property", ident.group(),
                                       self.span(start, start + len(ident.group())),
                                       "${}", True))
        for m in _ARG.finditer(self.text):
            if not self._commented(m.start()):
                self.names.append(Name("arg", m.group(1), self.span(m.start(1), m.end(1)),
                                       "$(arg)", True))

    # ---- questions

    def at(self, line: int, column: int) -> Name | None:
        """The name at a position, if any."""
        return next((n for n in self.names if n.span.holds(line, column)), None)

    def definitions(self, kind: str, name: str) -> list[Name]:
        """Where ``name`` of ``kind`` is defined in this text."""
        return [n for n in self.names if n.kind == kind and n.name == name and not n.use]

    def uses(self, kind: str, name: str) -> list[Name]:
        """Where ``name`` of ``kind`` is used in this text."""
        return [n for n in self.names if n.kind == kind and n.name == name and n.use]

    def defined(self, kind: str) -> list[Name]:
        """Every definition of ``kind``, in text order."""
        return [n for n in self.names if n.kind == kind and not n.use]

    def tag_at(self, offset: int) -> Tag | None:
        """The start tag the offset is in (up to its ``>``), if any."""
        for tag in reversed(self.tags):
            if tag.start < offset <= max(tag.end, tag.start + 1):
                return tag
            if tag.start < offset and tag.end >= offset:
                return tag
        return None

    def parent_tag(self, offset: int) -> str | None:
        """The element the offset is inside: the last start tag before it not closed since."""
        depth: list[str] = []
        pos = 0
        for m in re.finditer(r"<(/?)([A-Za-z_][\w:.-]*)[^<>]*?(/?)>", self.text[:offset]):
            pos = m.start()
            if self._commented(pos):
                continue
            if m.group(1):
                if depth and depth[-1] == m.group(2):
                    depth.pop()
            elif not m.group(3):
                depth.append(m.group(2))
        return depth[-1] if depth else None


def _quoted(body: str, index: int) -> bool:
    """Whether ``body[index]`` is inside a quoted string of the expression."""
    return body[:index].count("'") % 2 == 1 or body[:index].count('"') % 2 == 1


def read(text: str) -> Document:
    """The text's tags and names."""
    return Document(text)
