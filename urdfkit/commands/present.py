"""Presentation in one room: every line urdfkit prints is shaped here.

``cli.py`` parses options, calls the library, and hands the result to one function of this
module. Tables, trees, key/value blocks, progress bars, number formats, JSON and the one-line
error and warning printers all live here, so every command looks and pipes alike:

- On a terminal, output is styled with rich (imported only then: ~25 ms).
- Piped (CI logs, ``| grep``, ``> file``) it is plain aligned text with every column a wide
  terminal would show: nothing is truncated, wrapped or hidden, and rich is not imported.
- JSON is plain ``json.dumps``: valid whatever the terminal, linear in the size of the data,
  and non-finite numbers become ``null`` with a diagnostic instead of invalid JSON.
"""

from __future__ import annotations

import gc
import math
import os
import re
import sys
from collections.abc import Callable, Iterable, Sequence
from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:
    from urdfkit.checks.ci import CheckFormat
    from urdfkit.core.finding import Level

Part = str | tuple[str, str]
"""A piece of a line: plain text, or ``(text, rich style)``."""

Column = tuple[str, int, str]
"""(header, priority, justify) of a fitted table column; see :func:`table`."""

LEVEL_STYLE = {"error": "bold red", "warning": "yellow", "info": "cyan"}


# --------------------------------------------------------------------------- streams



def counted(n: int, noun: str) -> str:
    """``"1 joint"``, ``"2 joints"``: a count with its noun in the right number."""
    return f"{n} {noun}" if n == 1 else f"{n} {noun}s"

def styled(stream: Any) -> bool:
    """Whether ``stream`` gets colours: a terminal, or FORCE_COLOR set (NO_COLOR wins)."""
    if os.environ.get("NO_COLOR"):
        return False
    try:
        tty = stream.isatty()
    except (AttributeError, ValueError):
        tty = False
    return tty or bool(os.environ.get("FORCE_COLOR"))


def console(stderr: bool = False) -> Any:
    """A rich Console on stdout (or stderr). Only called when styling is wanted."""
    if "rich.console" not in sys.modules:
        # Importing rich allocates tens of thousands of objects, and each full collection
        # that triggers would re-scan everything loaded before (numpy, pybullet, ...), which
        # lives until exit anyway: freeze it first, as main() does at start-up (~4 ms).
        gc.freeze()
    from rich.console import Console

    return Console(stderr=stderr, highlight=False)


def _write(stream: Any, text: str) -> None:
    from urdfkit.core.stdio import LOCK

    with LOCK:  # never while another thread has fd 1 captured (urdfkit.core.stdio)
        try:
            stream.write(text)
        except UnicodeEncodeError:
            # A file name that is not UTF-8 (kept by Python as surrogates), or a terminal
            # whose encoding lacks a character: escape it rather than fail.
            encoding = getattr(stream, "encoding", None) or "utf-8"
            stream.write(text.encode(encoding, "backslashreplace").decode(encoding))
        stream.flush()


def line(*parts: Part, stderr: bool = False) -> None:
    """Print one line made of plain strings and ``(text, rich style)`` pairs.

    On a terminal rich styles it; elsewhere it is written as plain text, which is what rich
    would print there too, without paying for the import. User text needs no markup escaping:
    it never passes through rich's markup parser.
    """
    stream = sys.stderr if stderr else sys.stdout
    if styled(stream):
        from rich.text import Text

        from urdfkit.core.stdio import LOCK

        with LOCK:
            console(stderr).print(Text.assemble(*parts), soft_wrap=True)
    else:
        _write(stream, "".join(p if isinstance(p, str) else p[0] for p in parts) + "\n")


def error(message: str) -> None:
    """The one error line: ``urdfkit: error: <message>`` on stderr."""
    line(("urdfkit: error:", "bold red"), " ", _one_line(message), stderr=True)


def bug(exc: BaseException) -> None:
    """The line for an internal error: says it is a bug and how to see the traceback."""
    line(("urdfkit: internal error (a bug in urdfkit):", "bold red"), " ",
         _one_line(f"{type(exc).__name__}: {exc}"),
         " (rerun with URDFKIT_DEBUG=1 for the traceback, and please report it)", stderr=True)


def warn(message: str) -> None:
    """A warning line on stderr."""
    line(("urdfkit: warning:", "yellow"), " ", _one_line(message), stderr=True)


def note(message: str, *, stderr: bool = True) -> None:
    """A dim line: context that is not a warning (detected wheels, hidden columns, ...)."""
    line((message, "dim"), stderr=stderr)


def wrote(path: Any, detail: str = "") -> None:
    """``wrote FILE (detail)`` on stderr, so stdout stays the command's output."""
    line("wrote ", (str(path), "bold"), f" ({detail})" if detail else "", stderr=True)


def interrupted(message: str = "interrupted") -> None:
    """The yellow ``urdfkit: interrupted`` line (Ctrl-C, SIGTERM, SIGHUP)."""
    line((f"urdfkit: {message}", "yellow"), stderr=True)


def diagnostics(lines: Iterable[str]) -> None:
    """PyBullet's own messages, captured from its C stdout, as warnings."""
    for text in lines:
        warn(f"pybullet: {text}")


LONGEST_WORD = 200
"""The longest run without a space a message line quotes whole (a value, a name, a path)."""
LONGEST_LINE = 2000
"""The longest message line; past it the middle is left out, with a count."""


def _clip_word(m: re.Match[str]) -> str:
    word = m.group(0)
    core = word.rstrip(":,;")
    return f"{core[:120]}...{core[-40:]} ({len(core):,} characters){word[len(core):]}"


def _one_line(text: str) -> str:
    # A message must stay one line whatever it quotes (a file name with a newline, a
    # multi-line xacro error): escape what would break it. And it stays short whatever it
    # quotes: a 20 MB string in a config or a 10,000-character mesh name is cut to its
    # ends and its length, so every error and warning line is bounded.
    text = text.replace("\r", "\\r").replace("\n", " | ")
    text = _LONG_WORD.sub(_clip_word, text)
    if len(text) > LONGEST_LINE:
        left = len(text) - LONGEST_LINE + 200
        text = f"{text[:LONGEST_LINE - 400]} ...({left:,} characters left out)... {text[-200:]}"
    return text


_LONG_WORD = re.compile(rf"\S{{{LONGEST_WORD + 1},}}")


# --------------------------------------------------------------------------- numbers


def num(x: float) -> str:
    """A compact number: 4 significant digits, no ``-0``."""
    s = f"{x:.4g}"
    return "0" if s in ("-0", "0") else s


def nums(v: Iterable[float]) -> str:
    """Numbers formatted by :func:`num`, space-separated."""
    return " ".join(num(x) for x in v)


#: A decimal number in text, with more significant digits than a reader can use.
_NOISY = re.compile(r"(?<![\w.])-?(?=(?:\d\.?){13})\d+\.\d+(?:e[-+]?\d+)?(?![\w.])")


def tidy(text: str) -> str:
    """``text`` with each number of 13 or more significant digits cut to 12.

    For human text built by the library with exact values (agree's "PyBullet
    65.24999999999999 kg"): float noise goes (65.25), a real difference of one part in
    10^11 stays. JSON keeps the exact text.
    """
    return _NOISY.sub(lambda m: f"{float(m.group()):.12g}", text) if "." in text else text


def fixed(x: float, digits: int = 3) -> str:
    """Fixed decimals, without a ``-`` on a value that rounds to zero."""
    text = f"{x:.{digits}f}"
    return text[1:] if text.startswith("-") and not text.strip("-0.") else text


# --------------------------------------------------------------------------- JSON


def _finite(data: Any, path: str, bad: list[str]) -> Any:
    if isinstance(data, float):
        if math.isfinite(data):
            return data
        bad.append(path or "$")
        return None
    if isinstance(data, dict):
        return {k: _finite(v, f"{path}.{k}" if path else str(k), bad) for k, v in data.items()}
    if isinstance(data, list | tuple):
        return [_finite(v, f"{path}[{i}]", bad) for i, v in enumerate(data)]
    return data


def json_text(data: Any) -> str:
    """``data`` as JSON that always parses.

    NaN and infinities (from a file that holds them, or a simulation that blew up) are not
    JSON: they become ``null``, and a diagnostic naming where they were is added to the
    object's ``diagnostics`` list (created if needed) and printed as a warning. The common
    case pays one ``json.dumps``; only output that holds such numbers is walked.
    """
    from urdfkit.core.jsontext import dumps

    try:
        return dumps(data)  # json.dumps(data, indent=2, allow_nan=False)'s text, faster
    except ValueError:
        pass
    bad: list[str] = []
    clean = _finite(data, "", bad)
    message = (f"{len(bad)} non-finite number(s) written as null (first at {bad[0]})"
               if bad else "")
    if bad:
        warn(message)
        if isinstance(clean, dict):
            clean["diagnostics"] = [*clean.get("diagnostics", []), message]
    return dumps(clean)


def print_json(data: Any) -> None:
    """One JSON document on stdout (plain print, not rich: it must parse anywhere)."""
    text = json_text(data)
    _write(sys.stdout, text)  # then the newline: no second copy of a long document
    _write(sys.stdout, "\n")


# --------------------------------------------------------------------------- tables


def terminal_width() -> int:
    """$COLUMNS, else the terminal stdout is on, else the one stderr is on, else 80."""
    try:
        return int(os.environ["COLUMNS"])
    except (KeyError, ValueError):
        pass
    for stream in (sys.stdout, sys.stderr):
        try:
            return os.get_terminal_size(stream.fileno()).columns
        except (AttributeError, OSError, ValueError):
            continue
    return 80


def table(title: str, columns: Sequence[Column], rows: Sequence[Sequence[str]],
          show_all: bool = False) -> None:
    """A table of the columns that fit, most important first; nothing lost when piped.

    ``columns`` holds (header, priority, justify): priority 0 always shows, then 1, 2, ...
    join while they fit the terminal; 9 shows only with ``show_all``. On a terminal the
    columns left out are announced in one dim line. With ``show_all`` and too little width,
    each row becomes a block of "field value" lines instead, so nothing is squeezed.

    Piped, every column a wide terminal would show (all but priority 9, unless
    ``show_all``) is printed as plain aligned text: no truncation, no box drawing, no rich.
    """
    tty = styled(sys.stdout)
    width = terminal_width() if tty else sys.maxsize
    needed = [max([len(h), *(len(r[i]) for r in rows)]) + 3
              for i, (h, _, _) in enumerate(columns)]
    blocks = show_all and sum(needed) > width
    keep: list[int] = []
    used = 0
    for i in sorted(range(len(columns)), key=lambda i: columns[i][1]):
        prio = columns[i][1]
        if not (show_all or prio == 0 or (prio < 9 and used + needed[i] <= width)):
            break  # a column of this priority does not fit: drop all less important ones
        keep.append(i)
        used += needed[i]
    keep.sort()
    if not tty:
        _plain_table(title, columns, rows, keep)
        return
    _rich_table(title, columns, rows, keep, blocks)
    hidden = [columns[i][0] for i in range(len(columns)) if i not in keep]
    if hidden and not show_all:
        note(f"{len(hidden)} column(s) hidden: --all or a wider terminal", stderr=False)


def _plain_table(title: str, columns: Sequence[Column], rows: Sequence[Sequence[str]],
                 keep: list[int]) -> None:
    grid = [[columns[i][0] for i in keep], *([r[i] for i in keep] for r in rows)]
    widths = [max(len(cells[k]) for cells in grid) for k in range(len(keep))]
    out = [title] if title else []
    for cells in grid:
        padded = [cell.rjust(w) if columns[i][2] == "right" else cell.ljust(w)
                  for i, cell, w in zip(keep, cells, widths, strict=True)]
        out.append("  ".join(padded).rstrip())
    _write(sys.stdout, "\n".join(out) + "\n")


def _rich_table(title: str, columns: Sequence[Column], rows: Sequence[Sequence[str]],
                keep: list[int], blocks: bool) -> None:
    from rich.table import Table
    from rich.text import Text

    heading = Text(title)
    heading.stylize("bold", 0, max(title.find(":"), 0))  # the robot's name
    if blocks:
        from rich.console import Group

        parts: list[Any] = [heading]
        for r in rows:
            block = Table(show_header=False, show_edge=False, box=None, padding=(0, 1))
            block.add_column(style="bold")
            block.add_column()
            for (header, _, _), cell in zip(columns, r, strict=False):
                block.add_row(Text(header), Text(cell))
            parts += ["", block]
        console().print(Group(*parts))
        return
    grid = Table(title=heading if title else None, title_justify="left", show_edge=False,
                 header_style="bold")
    for i in keep:
        header, _, justify = columns[i]
        # Text, not str: no markup or emoji parsing (rich's emoji table alone costs ~2 ms).
        grid.add_column(Text(header), justify=justify)  # type: ignore[arg-type]
    for r in rows:
        grid.add_row(*(Text(r[i]) for i in keep))
    console().print(grid)


def fields(title: Sequence[Part], rows: Sequence[tuple[str, str]]) -> None:
    """A block of aligned ``key  value`` lines under a title line (info, drive)."""
    line(*title)
    width = max((len(k) for k, _ in rows), default=0)
    for key, value in rows:
        line("  ", (f"{key:<{width}}", "cyan"), "  ", value)


# --------------------------------------------------------------------------- trees


def tree(root: Any, robot: str) -> None:
    """The kinematic tree (:class:`urdfkit.draw.tree.TreeNode`), one line per link.

    Piped, it is indented text that holds every joint however deep the chain; on a
    terminal, a rich tree with guide lines.
    """

    def label(node: Any) -> str:
        j = node.joint
        if j is None:
            return node.link
        extra = f" axis {nums(j.axis)}" if j.axis is not None else ""
        if j.limit is not None:
            extra += f" [{num(j.limit[0])} .. {num(j.limit[1])}]"
        return f"[{j.index}] {j.name} ({j.type}{extra}) -> {node.link}"

    if not styled(sys.stdout):
        # The guide lines rich draws, written directly: every joint, however deep.
        out = [f"{root.link} ({robot})"]
        stack = [(child, "", k == len(root.children) - 1)
                 for k, child in reversed(list(enumerate(root.children)))]
        while stack:  # iterative: chains are deeper than Python's recursion limit
            node, prefix, last = stack.pop()
            out.append(f"{prefix}{'└── ' if last else '├── '}{label(node)}")
            below = prefix + ("    " if last else "│   ")
            stack.extend((child, below, k == len(node.children) - 1)
                         for k, child in reversed(list(enumerate(node.children))))
        _write(sys.stdout, "\n".join(out) + "\n")
        return
    from rich.text import Text
    from rich.tree import Tree

    def styled_label(node: Any) -> Text:
        text = Text(label(node))
        if node.joint is not None:
            close = text.plain.index("]") + 1
            text.stylize("dim", 0, close)
            text.stylize("cyan", close + 1, close + 1 + len(node.joint.name))
        text.stylize("bold", len(text.plain) - len(node.link))
        return text

    top = Tree(Text.assemble(styled_label(root), (f" ({robot})", "dim")))
    stack2: list[tuple[Any, Any]] = [(root, top)]
    while stack2:
        node, branch = stack2.pop()
        stack2.extend((child, branch.add(styled_label(child))) for child in node.children)
    console().print(top)


# --------------------------------------------------------------------------- check


def check_report(result: Any, show_all: bool = False) -> None:
    """``urdfkit check``'s text: findings grouped by file, then one summary line.

    Piped it is written as plain lines in one go (no rich), so text costs about what
    ``--json`` costs over thousands of files.
    """
    s = result.summary()
    colour = "red" if s["error"] else ("yellow" if s["warning"] else "green")
    summary = (f"{s['files']} file(s) checked: {s['error']} error(s), {s['warning']} "
               f"warning(s), {s['info']} note(s); {s['files_with_errors']} file(s) with errors")
    if not styled(sys.stdout):
        out: list[str] = []
        for fr in result.files:
            if fr.findings:
                out.append(_one_line(fr.file))
                for f, more in _grouped(fr.findings, show_all):
                    if more:
                        out.append(f"  {'':>5}  {f.level:<7}  {f.code}  {more}")
                    else:
                        out.append(f"  {f.line if f.line is not None else '-':>5}  "
                                   f"{f.level:<7}  {f.code}  {_one_line(f.text)}")
        out.append(summary)
        _write(sys.stdout, "\n".join(out) + "\n")
        return
    from rich.text import Text

    screen = console()
    for fr in result.files:
        if not fr.findings:
            continue
        screen.print(Text(_one_line(fr.file), style="bold"), soft_wrap=True)
        for f, more in _grouped(fr.findings, show_all):
            where = f"{f.line:>5}" if f.line is not None and not more else "    -"
            screen.print(Text.assemble(f"  {where}  ", (f"{f.level:<7}", LEVEL_STYLE[f.level]),
                                       "  ", (f.code, "dim"), "  ",
                                       (more, "dim") if more else _one_line(f.text)),
                         soft_wrap=True)
    screen.print(Text(summary, style=colour), soft_wrap=True)


def check_formatted(result: Any, fmt: CheckFormat = "text", fail_on: Level = "error",
                    show_all: bool = False) -> None:
    """``urdfkit check --format``: text, JSON, or a CI format (:mod:`urdfkit.checks.ci`) on stdout.

    The CI formats are written whole and unstyled, terminal or not: they are for files and
    logs. ``fail_on`` decides which files JUnit counts as failed.
    """
    if fmt == "text":
        check_report(result, show_all)
        return
    if fmt == "json":
        print_json(result.to_dict())
        return
    from urdfkit.checks import ci

    if fmt == "sarif":
        print_json(ci.sarif_log(result))
    elif fmt == "junit":
        _write(sys.stdout, ci.junit_xml(result, fail_on))
    elif fmt == "github":
        _write(sys.stdout, "".join(f"{command}\n" for command in ci.github_commands(result)))
    else:
        raise ValueError(f"no check format {fmt!r}; expected one of {', '.join(ci.FORMATS)}")


#: Text output shows this many findings of one code per file, then one line for the rest.
GROUP_AFTER = 3


def _grouped(findings: Sequence[Any], show_all: bool = False) -> list[tuple[Any, str]]:
    """Findings to print: ``(finding, "")`` for each one shown.

    A code seen more than GROUP_AFTER times in a file shows its first ones, then
    ``(next, summary)`` for the rest (--json keeps them all); ``show_all`` shows every one.
    """
    if show_all:
        return [(f, "") for f in findings]
    count: dict[str, int] = {}
    for f in findings:
        count[f.code] = count.get(f.code, 0) + 1
    shown: dict[str, int] = {}
    out: list[tuple[Any, str]] = []
    for f in findings:
        n = shown.get(f.code, 0)
        shown[f.code] = n + 1
        if n < GROUP_AFTER or count[f.code] == GROUP_AFTER + 1:
            out.append((f, ""))
        elif n == GROUP_AFTER:
            rest = count[f.code] - GROUP_AFTER
            out.append((f, f"... and {rest} more {f.code} in this file (--all or --json lists "
                           "every one)"))
    return out


# --------------------------------------------------------------------------- diff


def diff_value(value: Any) -> str:
    """A value of ``urdfkit diff`` as text: exact enough to tell 23.7 from 23.70001.

    Floats get 15 significant digits (not :func:`num`'s 4, which would print two values the
    tolerance tells apart as one), absent values a ``-``, a whole visual its fields.
    """
    if value is None:
        return "-"
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, float):
        text = f"{value:.15g}"
        return "0" if text == "-0" else text
    if isinstance(value, tuple | list):
        return " ".join(diff_value(v) for v in value)
    if isinstance(value, dict):
        return "; ".join(f"{k} {diff_value(v)}" for k, v in value.items() if v is not None)
    return str(value)


def diff_report(result: Any) -> None:
    """``urdfkit diff``'s text: one line when the robots are the same, else a table.

    Rows go removed, added, renamed, changed, index shifts, totals: what a reader fixing a
    script needs first is what disappeared.
    """
    a, b = result.a, result.b
    if result.same:
        line((b.robot, "bold"), f": {a.file} and {b.file} are the same robot "
             f"({counted(b.links, 'link')}, {counted(b.joints, 'joint')}; "
             f"tolerance {result.tolerance:g})")
        return
    v = diff_value

    def joint_note(e: Any) -> str:
        return f"index {e.index}, {e.type}" if e.kind == "joint" else ""

    rows = [["removed", f"{e.kind} {e.name}", "", joint_note(e) or "-", "-"]
            for e in result.removed]
    rows += [["added", f"{e.kind} {e.name}", "", "-", joint_note(e) or "-"]
             for e in result.added]
    rows += [["renamed", f"{r.kind} {r.new}", "name", r.old, r.new] for r in result.renamed]
    rows += [["changed", f"{c.kind} {c.name}", c.field, v(c.old), v(c.new)]
             for c in result.changes]
    rows += [["index", f"joint {s.joint}", "jointIndex", str(s.old), str(s.new)]
             for s in result.index_shifts]
    for what, total, unit in (("mass", result.mass, " kg"), ("dof", result.dof, "")):
        if total.changed:
            rows.append(["total", f"robot {b.robot}", what, v(total.old) + unit,
                         v(total.new) + unit])
    columns = [("change", 0, "left"), ("element", 0, "left"), ("field", 0, "left"),
               ("old", 0, "left"), ("new", 0, "left")]
    table(f"{b.robot}: {result.count} difference(s) from {a.file} to {b.file}", columns, rows)


# --------------------------------------------------------------------------- progress


def _isatty(stream: Any) -> bool:
    try:
        return bool(stream.isatty())
    except (AttributeError, ValueError):
        return False


def progress(label: str, unit: str, enabled: bool = True, rate: bool = False
             ) -> tuple[Callable[[int, int], None] | None, Callable[[], None]]:
    """A progress callback that shows a bar on stderr once a run looks longer than ~1 s.

    Returns ``(update(done, total), stop())``; ``update`` is None when not ``enabled`` or
    when stderr, where the bar goes, is not a terminal (a bar in a log file is noise). A
    piped stdout (``urdfkit drive | tee run.txt``) still gets it on the terminal: the bar
    never touches stdout. The bar shows the time left; ``rate`` adds units per second.
    """
    if not (enabled and _isatty(sys.stderr)):
        return None, lambda: None
    import time

    state: dict[str, Any] = {"start": time.perf_counter(), "bar": None, "task": None}

    def update(done: int, total: int) -> None:
        bar = state["bar"]
        if bar is None:
            elapsed = time.perf_counter() - state["start"]
            if elapsed < 0.25 or elapsed * total / max(done, 1) < 1.0:
                return
            from rich.progress import BarColumn, Progress, TextColumn, TimeRemainingColumn

            columns = [TextColumn(label), BarColumn(),
                       TextColumn("{task.completed:,}/{task.total:,} " + unit)]
            if rate:
                columns.append(TextColumn("{task.fields[rate]}"))
            bar = Progress(*columns, TimeRemainingColumn(), console=console(stderr=True),
                           transient=True)
            state["task"] = bar.add_task(label, total=total, rate="")
            bar.start()
            state["bar"] = bar
        elapsed = time.perf_counter() - state["start"]
        bar.update(state["task"], completed=done,
                   rate=f"{done / elapsed:.2f} {unit}/s" if rate and elapsed > 0 else "")

    def stop() -> None:
        if state["bar"] is not None:
            state["bar"].stop()

    return update, stop


# --------------------------------------------------------------------------- collisions


def collisions_report(result: Any, show_all: bool = False) -> None:
    """``urdfkit collisions``' table: pairs in contact, most often and deepest first."""
    for w in result.warnings:
        warn(w)
    rows = []
    for x in result.pairs:
        if abs(x.distance) < 5e-7:  # 0 or -0 to the display's precision
            depth = "touching"
        elif x.distance < 0:
            depth = f"{-x.distance * 1000:.3g} mm deep"
        else:
            depth = f"{x.distance * 1000:.3g} mm apart"
        note_text = f"convex hull of {', '.join(x.hull)}" if x.hull else ""
        rows.append([x.link_a, x.link_b, depth, f"{x.poses_in_contact}/{result.poses}",
                     f"{x.index_a} {x.index_b}", note_text])
    columns: list[Column] = [("link a", 0, "left"), ("link b", 0, "left"),
                             ("worst", 0, "right"), ("poses", 0, "right"),
                             ("indices", 2, "right"), ("note", 1, "left")]
    samples = f" (start + {result.samples} random, seed {result.seed})" if result.samples else \
        " (the start pose)"
    title = (f"{result.robot}: {len(result.pairs)} link pair(s) in contact over "
             f"{result.poses} pose(s){samples}")
    if rows:
        table(title, columns, rows, show_all)
    else:
        line((title, "green"))
    always = len(result.always())
    tail = [f"{result.tested} pairs tested; {len(result.skipped_adjacent)} parent-child pairs "
            "skipped (PyBullet never tests a link against its parent)"]
    if result.without_shapes:
        tail.append(f"{len(result.without_shapes)} link(s) without collision shapes")
    if always:
        where = "in every pose" if result.samples else "at the one pose tested (--samples N " \
            "tests more before you filter)"
        tail.append(f"{always} pair(s) in contact {where}: --srdf or --python prints the "
                    "filters")
    if any(x.hull for x in result.pairs):
        tail.append("concave meshes collide as their convex hull in PyBullet")
    note("; ".join(tail), stderr=False)


# --------------------------------------------------------------------------- fix


def fix_report(result: Any, stderr: bool = False) -> None:
    """``urdfkit fix``: each fix with its code and line, then what was left and why."""
    name = _one_line(result.file)
    for x in result.repairs:
        line((f"{name}:{x.line or '-'}: ", "dim"), ("fixed ", "green"), (x.code, "bold"),
             f" {_one_line(x.message)}", stderr=stderr)
    for x in result.left:
        line((f"{name}:{x.line or '-'}: ", "dim"), ("left ", "yellow"), (x.code, "bold"),
             f" {_one_line(x.message)}", stderr=stderr)
    if result.other_errors:
        codes = ", ".join(sorted({x.code for x in result.other_errors}))
        line((f"{name}: {len(result.other_errors)} other error(s) fix does not repair ({codes}): "
              "urdfkit check explains them", "yellow"), stderr=stderr)
    if not result.repairs and not result.left:
        note(f"{name}: nothing to fix", stderr=stderr)


# --------------------------------------------------------------------------- sweep


def sweep_report(plan: Any, rows: Sequence[Any], done: int, failed: int, skipped: int,
                 show_all: bool = False) -> None:
    """``urdfkit sweep``: the rows (when they are not going to a file) and a summary line."""
    if rows:
        names = list(plan.names)
        wanted = {"drive": ["turning_radius", "expected_radius", "distance", "mean_speed",
                            "final_x", "final_y", "heading_change", "problems"],
                  "sim": []}[plan.kind]
        every = list(dict.fromkeys(k for r in rows for k in r
                                   if k not in names and k not in ("point", "error")))
        metrics = [k for k in wanted if k in every] if wanted and not show_all else every
        columns: list[Column] = [("point", 0, "right")]
        columns += [(n, 0, "right") for n in names]
        columns += [(m, 1 if k < 4 else 3, "left" if m == "problems" else "right")
                    for k, m in enumerate(metrics)]
        columns.append(("error", 0, "left"))

        def cell(v: Any) -> str:
            if v is None:
                return "-"
            if isinstance(v, float):
                return fixed(v)
            return str(v)

        table(f"sweep {plan.label}: {len(rows)} point(s)", columns,
              [[str(r.get("point")), *(diff_value(r.get(n)) for n in names),
                *(cell(r.get(m)) for m in metrics), _one_line(r.get("error") or "")]
               for r in sorted(rows, key=lambda r: r.get("point", 0))], show_all)
    tail = f"{done} point(s) ran, {failed} failed"
    if skipped:
        tail += f", {skipped} skipped (done before: --resume)"
    line((tail, "red" if failed else "green"))
