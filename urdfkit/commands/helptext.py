r"""``--help`` laid out as click lays it out: every word whole, at any width, without rich.

typer draws help with rich: boxed panels and an option table of six columns laid out for the
terminal's width. A word wider than its column is cut in two (``differential|rear|locke d``
at 80 columns) or to an ellipsis (a 55-character word at 100 columns), on a terminal and in
a pipe alike. Here the same help is written as an option and then its text, wrapped at
spaces only: a word longer than the line (a long path, an example command) runs past the
edge, never across two lines. The help strings are written in rich markup (``[bold]``,
``\[plot]``); the markup is taken out. On a terminal the headings are bold.
"""

from __future__ import annotations

import re
import textwrap
from typing import Any

#: rich markup in urdfkit's own help strings: the styles it uses, and escaped brackets.
_TAG = re.compile(r"(?<!\\)\[/?(?:bold|dim|italic|cyan|green|yellow|red)?\]")
#: Widest first column before an option's text goes to the next line (click's col_max).
FIRST_COLUMN = 30
#: The help is wrapped to at most this width, however wide the terminal says it is.
MOST = 100


def unmarked(text: str) -> str:
    r"""``text`` without rich markup: styles dropped, ``\[`` unescaped."""
    return _TAG.sub("", text).replace("\\[", "[")


def _wrap(text: str, width: int, indent: str = "", first: str | None = None) -> list[str]:
    """Lines of ``text`` at most ``width`` wide where a space allows; a word is never cut."""
    return textwrap.wrap(text, width, initial_indent=indent if first is None else first,
                         subsequent_indent=indent, break_long_words=False,
                         break_on_hyphens=False) or [indent]


def _paragraphs(text: str, width: int, indent: str) -> list[str]:
    """A help text's paragraphs, each wrapped; indented lines (examples) kept as written."""
    out: list[str] = []
    for para in unmarked(text).strip("\n").split("\n\n"):
        lines = para.split("\n")
        if all(line.startswith("  ") for line in lines if line.strip()):
            body = [indent + line.rstrip() for line in lines]  # examples: never re-wrapped
        else:
            body = _wrap(" ".join(line.strip() for line in lines), width, indent)
        if out:
            out.append("")
        out += body
    return out


def _rows(rows: list[tuple[str, str]], width: int) -> list[str]:
    """The definition list of click: the names, then their text, wrapped beside or below them."""
    first = min(max((len(n) for n, _ in rows), default=0), FIRST_COLUMN)
    text_at = 2 + first + 2
    out: list[str] = []
    for names, text in rows:
        head = "  " + names
        text = unmarked(text)
        if not text:
            out.append(head)
        elif len(names) <= first:
            out += _wrap(text, width, " " * text_at, head.ljust(text_at))
        else:
            out.append(head)
            out += _wrap(text, width, " " * text_at)
    return out


def plain_help(command: Any, ctx: Any, width: int, styled: bool = False) -> str:
    """The help of a click command (or typer's group) as text, ``width`` at most.

    ``styled``: headings in bold (ANSI), for a terminal.
    """
    width = max(40, min(width, MOST))

    def heading(text: str) -> str:
        return f"\x1b[1m{text}\x1b[0m" if styled else text

    pieces = command.collect_usage_pieces(ctx)
    out = [f"{heading('Usage:')} {ctx.command_path} {' '.join(pieces)}".rstrip(), ""]
    if command.help:
        out += _paragraphs(command.help, width, "  ") + [""]
    arguments: list[tuple[str, str]] = []
    options: list[tuple[str, str]] = []
    for param in command.get_params(ctx):
        record = param.get_help_record(ctx)
        if record is not None:
            (arguments if param.param_type_name == "argument" else options).append(record)
    for title, rows in (("Arguments", arguments), ("Options", options)):
        if rows:
            out += [heading(f"{title}:"), *_rows(rows, width), ""]
    commands = [(name, command.get_command(ctx, name))
                for name in getattr(command, "list_commands", lambda _: [])(ctx)]
    shown = [(name, c) for name, c in commands if c is not None and not c.hidden]
    if shown:  # each command's first sentence whole, not cut to one line with "..."
        out += [heading("Commands:"), *_rows([(n, c.get_short_help_str(10_000)) for n, c in shown],
                                    width), ""]
    if command.epilog:
        out += [heading(line) if line == "Examples" else line
                for line in _paragraphs(command.epilog, width, "")] + [""]
    return "\n".join(out).rstrip("\n")
