"""``fix``'s edits to one file, spliced into its text and made on its parsed tree alike.

:class:`Splice` finds an element's start tag and span in the text (quotes, comments, CDATA and
processing instructions minded), sets an attribute in the element's own quotes, inserts a
child at the indent its siblings use, replaces an element, and at the end applies the edits to
the text and requires the result to parse to the edited tree (:meth:`Splice.finish`): a
mismatch is a bug in urdfkit, raised rather than written. What to edit is decided in
:mod:`urdfkit.checks.fix_plan`.
"""

from __future__ import annotations

import re
from typing import Any

from lxml import etree

from urdfkit.model.xmlio import parse_xml, start_tags

#: What may follow an element's start tag up to its end tag: end tags, start tags (``<``
#: then a name), and comments, CDATA and processing instructions, whose ``<`` start nothing.
_TOKEN = re.compile(r"<!--.*?-->|<!\[CDATA\[.*?\]\]>|<\?.*?\?>|</[^>]*>|<(?=[^!?/])", re.DOTALL)


class Splice:
    """The edits to one file's text, each made on its tree too: ``(start, end, new text)``."""

    def __init__(self, text: str, root: etree._Element, file: str) -> None:
        self.text = text
        self.root = root
        self.file = file
        self.edits: list[tuple[int, int, str]] = []
        # Every element's start tag by its path: exact past line 65,535 (where lxml's
        # sourceline stops), for prefixed tags, and with tags quoted in comments.
        # Keyed by the element itself (the map keeps each proxy alive, so lxml hands back the
        # same one): an element a repair inserted has no start tag in the text, and is skipped.
        elements = (el for el in root.iter() if isinstance(el.tag, str))
        self.tag_at: dict[etree._Element, int] = dict(
            zip(elements, start_tags(text), strict=False))

    # ---- edits, on the text and the tree alike

    def replace(self, el: etree._Element, xml: str) -> None:
        """Replace the whole element (start tag to end tag) with ``xml``."""
        start, end = self.span(el)
        self.edits.append((start, end, xml))
        new = etree.fromstring(xml)
        new.tail = el.tail
        parent = el.getparent()
        assert parent is not None
        parent.replace(el, new)

    def set_attribute(self, el: etree._Element, name: str, value: str) -> None:
        """Set an attribute the element has, in the quotes it is written in."""
        start, tag_end, _ = self._start_tag(el)
        tag = self.text[start:tag_end]
        m = re.search(rf"(\s{re.escape(name)}\s*=\s*)([\"'])(.*?)\2", tag, re.S)
        if m is None:  # pragma: no cover - the rules found the attribute in this element
            raise AssertionError(f"attribute {name} not found in {tag!r}")
        quote = m.group(2)
        escaped = attr(value) if quote == '"' else attr(value).replace("'", "&apos;")
        self.edits.append((start + m.start(3), start + m.end(3), escaped))
        el.set(name, value)

    def insert_first_child(self, parent: etree._Element, lines: list[str]) -> None:
        """Insert lines as the first child; a leading tab in a line is one more indent.

        The text only: the caller makes the tree's edit (:func:`prepend`).
        """
        start, tag_end, closed = self._start_tag(parent)
        indent = self._indent(start)
        # The first child written in the text (not one an earlier repair inserted).
        first = next((c for c in parent if not isinstance(c.tag, str) or c in self.tag_at),
                     None)
        if first is not None and not closed:
            inner = self._indent(self._start_tag(first)[0]) if isinstance(first.tag, str) \
                else None
            child = inner if inner is not None and inner.startswith(indent) and inner != indent \
                else indent + self._unit()
        else:
            child = indent + self._unit()
        unit = self._unit()
        body = "\n".join(child + unit * (len(x) - len(x.lstrip("\t"))) + x.lstrip("\t")
                         for x in lines)
        if closed:  # <link name="x"/> becomes <link name="x"> ... </link>
            head = self.text[start:tag_end].rstrip(">").rstrip().rstrip("/").rstrip()
            self.edits.append((start, tag_end, f"{head}>\n{body}\n{indent}</{parent.tag!s}>"))
        else:
            self.edits.append((tag_end, tag_end, "\n" + body))

    def insert_last_child(self, parent: etree._Element, xml: str) -> None:
        """Insert ``xml`` as the last child (the text only, as :meth:`insert_first_child`)."""
        start, end = self.span(parent)
        if self.text[end - 2:end] == "/>":  # <inertial/>: open it
            self.insert_first_child(parent, [xml])
            return
        close = self.text.rindex("</", start, end)
        own_line = self.text[self.text.rfind("\n", 0, close) + 1:close]
        if own_line.strip() == "":  # the end tag on a line of its own: a child line above it
            self.edits.append((close, close, f"{self._unit()}{xml}\n{own_line}"))
        else:  # all on one line: stay on it
            self.edits.append((close, close, xml))

    # ---- finding elements in the text

    def _start_tag(self, el: etree._Element) -> tuple[int, int, bool]:
        """(start, end, self-closing) of the element's start tag in the text."""
        start = self.tag_at[el]
        end, closed = self._tag_end(start)
        return start, end, closed

    def _tag_end(self, start: int) -> tuple[int, bool]:
        """The end of the start tag at ``start`` (past its ``>``, quotes minded), self-closing."""
        i, quote = start + 1, ""
        while True:
            ch = self.text[i]
            if quote:
                quote = "" if ch == quote else quote
            elif ch in "\"'":
                quote = ch
            elif ch == ">":
                return i + 1, self.text[i - 1] == "/"
            i += 1

    def span(self, el: etree._Element) -> tuple[int, int]:
        """(start, end) of the whole element in the text, start tag to end tag."""
        start, tag_end, closed = self._start_tag(el)
        if closed:
            return start, tag_end
        depth, pos = 1, tag_end
        while True:
            m = _TOKEN.search(self.text, pos)
            if m is None:  # pragma: no cover - the document is well formed
                raise AssertionError(f"no end of <{el.tag!s}>")
            if m.group().startswith("</"):
                depth -= 1
                if depth == 0:
                    return start, m.end()
                pos = m.end()
            elif m.group() == "<":
                pos, closed = self._tag_end(m.start())
                depth += not closed
            else:  # a comment, CDATA or processing instruction: no tags in it
                pos = m.end()

    def _indent(self, pos: int) -> str:
        line_start = self.text.rfind("\n", 0, pos) + 1
        lead = self.text[line_start:pos]
        return lead if lead.strip() == "" else ""

    def _unit(self) -> str:
        first = next((x for x in self.root if isinstance(x.tag, str) and x in self.tag_at),
                     None)
        if first is not None:
            unit = self._indent(self._start_tag(first)[0])
            if unit:
                return unit
        return "  "

    # ---- the result

    def finish(self) -> bytes:
        """The edited text, checked to parse to the edited tree."""
        if not self.edits:
            return self.text.encode("utf-8")
        out = self.text
        for start, end, new in sorted(self.edits, key=lambda e: (e[0], e[1]), reverse=True):
            out = out[:start] + new + out[end:]
        data = out.encode("utf-8")
        got = _shape(parse_xml(data, self.file).getroot())
        if got != _shape(self.root):  # pragma: no cover - a bug in the splicing above
            raise AssertionError(f"{self.file}: the edited text does not parse to the edited "
                                 "tree; nothing written")
        return data


def prepend(parent: etree._Element, new: etree._Element) -> None:
    """Make ``new`` the tree's first child of ``parent``, where the text edit puts it.

    :meth:`Splice.insert_first_child` writes it right after the start tag, so any text the
    parent held before its first child (a stray ``>`` of ``<robot name="r">>``, as youBot's
    xacro writes) now follows ``new``.
    """
    parent.insert(0, new)
    new.tail, parent.text = parent.text, None


def attr(text: str) -> str:
    """``text`` as a double-quoted attribute value that parses back to ``text``.

    Tabs and line breaks are written as character references: XML turns a literal one in an
    attribute into a space (a material named ``"a&#9;b"`` would come back ``"a b"``).
    """
    return (text.replace("&", "&amp;").replace('"', "&quot;").replace("<", "&lt;")
            .replace("\t", "&#9;").replace("\n", "&#10;").replace("\r", "&#13;"))


def _shape(el: etree._Element) -> Any:
    """An element as nested tuples: tag, attributes, stripped text, children (comments too)."""
    return (str(el.tag), tuple(sorted(el.attrib.items())), (el.text or "").strip(),
            tuple(_shape(c) for c in el))
