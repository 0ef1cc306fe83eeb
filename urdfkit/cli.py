"""The ``urdfkit`` command line: parse options, call the library, present the result.

Nothing heavy is imported at module level: ``urdfkit --help`` must not pay for PyBullet,
numpy, yourdfpy or trimesh. Library errors (:class:`~urdfkit.errors.UrdfkitError`) are caught
once, in :func:`_handle_errors`, and become one red line on stderr plus an exit code.
"""


import functools
import gc
import json
import os
import sys
from collections.abc import Callable
from pathlib import Path
from typing import Annotated, Any, TypeVar

import typer

from . import __version__
from .errors import UrdfkitError

app = typer.Typer(
    name="urdfkit",
    help="Build, inspect and test-drive URDF robot descriptions with PyBullet.",
    no_args_is_help=True,
    add_completion=False,
    pretty_exceptions_enable=False,
    context_settings={"help_option_names": ["-h", "--help"]},
)

F = TypeVar("F", bound=Callable[..., Any])


# --------------------------------------------------------------------------- presentation


def _console(stderr: bool = False) -> Any:
    if "rich.console" not in sys.modules:
        # Importing rich allocates tens of thousands of objects, and each full collection
        # that triggers would re-scan everything loaded before (numpy, pybullet, ...), which
        # lives until exit anyway: freeze it first, as main() does at start-up (~4 ms).
        gc.freeze()
    from rich.console import Console

    # rich honours NO_COLOR and drops styling when the stream is not a terminal.
    return Console(stderr=stderr, highlight=False)


Part = str | tuple[str, str]


def _styled(stream: Any) -> bool:
    try:
        tty = stream.isatty()
    except (AttributeError, ValueError):
        tty = False
    return tty or bool(os.environ.get("FORCE_COLOR"))


def _line(*parts: Part, stderr: bool = False) -> None:
    """Print one line made of plain strings and ``(text, rich style)`` pairs.

    On a terminal rich styles it; elsewhere (pipes, CI, tests) it is written as plain text,
    which is what rich would print there too, without paying ~15 ms to import rich. User
    text needs no markup escaping: it never passes through the markup parser.
    """
    stream = sys.stderr if stderr else sys.stdout
    if _styled(stream):
        from rich.text import Text

        _console(stderr).print(Text.assemble(*parts), soft_wrap=True)
    else:
        stream.write("".join(p if isinstance(p, str) else p[0] for p in parts) + "\n")
        stream.flush()


def _fail(message: str, code: int = 2) -> None:
    # One line, however narrow the terminal.
    _line(("urdfkit: error:", "bold red"), " ", message, stderr=True)
    raise typer.Exit(code)


def _warn(message: str) -> None:
    _line(("urdfkit: warning:", "yellow"), " ", message, stderr=True)


def _escape(text: str) -> str:
    from rich.markup import escape

    return escape(text)


def _print_json(data: Any) -> None:
    # Plain print, not rich: JSON must parse whatever the terminal is. The encoder recurses
    # per nesting level, and `tree --json` nests three levels per link of a (guard-capped,
    # 1000-link) chain: give it room.
    sys.setrecursionlimit(max(sys.getrecursionlimit(), 10_000))
    sys.stdout.write(json.dumps(data, indent=2, allow_nan=False) + "\n")
    sys.stdout.flush()


def _handle_errors(fn: F) -> F:
    @functools.wraps(fn)
    def wrapper(*args: Any, **kwargs: Any) -> Any:
        try:
            return fn(*args, **kwargs)
        except UrdfkitError as e:
            _fail(str(e), e.exit_code)
        except KeyboardInterrupt:
            _line(("urdfkit: interrupted", "yellow"), stderr=True)
            raise typer.Exit(130) from None
        except BrokenPipeError:
            # `urdfkit joints big.urdf | head`: the reader went away; that is not an error.
            devnull = os.open(os.devnull, os.O_WRONLY)
            os.dup2(devnull, sys.stdout.fileno())
            raise typer.Exit(0) from None

    return wrapper  # type: ignore[return-value]


def _version_callback(value: bool) -> None:
    if value:
        sys.stdout.write(f"urdfkit {__version__}\n")
        raise typer.Exit()


@app.callback()
def _root(
    version: Annotated[bool, typer.Option("--version", callback=_version_callback,
                                          is_eager=True, help="Show the version and exit.")]
    = False,
) -> None:
    """Build, inspect and test-drive URDF robot descriptions with PyBullet."""


# --------------------------------------------------------------------------- build

SetOpt = Annotated[list[str] | None, typer.Option(
    "--set", "-s", metavar="KEY=VALUE",
    help="Template parameter (repeatable). See `urdfkit templates`.")]
ArgOpt = Annotated[list[str] | None, typer.Option(
    "--arg", "-a", metavar="NAME:=VALUE", help="xacro argument (repeatable).")]
ForceOpt = Annotated[bool, typer.Option("--force", "-f", help="Overwrite an existing file.")]
# Options shared by every command that reads a robot file (resolve.open_input takes them raw).
PackageOpt = Annotated[list[str] | None, typer.Option(
    "--package", "-p", metavar="NAME=PATH",
    help="Where package://NAME/ points (repeatable); else found by walking up from the file.")]
JsonOpt = Annotated[bool, typer.Option("--json", help="Print one JSON object on stdout.")]
FixedBaseOpt = Annotated[bool, typer.Option("--fixed-base", help="Pin the root link to the world.")]


@app.command()
@_handle_errors
def build(
    target: Annotated[str, typer.Argument(
        help="A template name (simplecar, simpleplane) or your own .xacro file.")],
    output: Annotated[str | None, typer.Option(
        "--output", "-o", help="Where to write; '-' for stdout. Default: <name>.urdf here.")]
    = None,
    set_: SetOpt = None,
    arg: ArgOpt = None,
    force: ForceOpt = False,
) -> None:
    """Build a URDF from a template or a xacro file, check it, and write it atomically.

    A .xacro file is expanded in a subprocess with a timeout: xacro's ${...} expressions run
    Python code, so only expand files you trust.
    """
    from . import build as building

    result = building.build(target, params=set_, xacro_args=arg)
    out = output if output is not None else result.default_output
    if out == "-":
        sys.stdout.buffer.write(result.data)
        sys.stdout.flush()
        return
    path = building.write_output(out, result.data, force=force)
    for w in result.warnings:
        _warn(w)
    _line("wrote ", (str(path), "bold"), f" ({result.links} links, {result.joints} joints)",
          stderr=True)


@app.command()
@_handle_errors
def templates(
    as_json: Annotated[bool, typer.Option("--json", help="Print JSON.")] = False,
) -> None:
    """List the built-in templates with their parameters and defaults."""
    from .catalog import TEMPLATES

    if as_json:
        _print_json({"templates": [
            {"name": t.name, "description": t.description, "file": t.file,
             "params": [{"name": p.name, "type": p.kind, "default": p.default, "help": p.help}
                        for p in t.params]}
            for t in TEMPLATES.values()]})
        return
    from rich.table import Table

    console = _console()
    for t in TEMPLATES.values():
        table = Table(title=f"[bold]{t.name}[/]: {_escape(t.description)}", title_justify="left",
                      show_edge=False)
        table.add_column("parameter", style="cyan")
        table.add_column("default", justify="right")
        table.add_column("meaning")
        for p in t.params:
            table.add_row(p.name, p.show(p.default), p.help)
        console.print(table)
        console.print()


# ---- inspect: joints, links, tree, info (urdfkit/inspect.py holds the data)

MovableOpt = Annotated[bool, typer.Option("--movable", help="Only joints that can move.")]
TypeOpt = Annotated[list[str] | None, typer.Option(
    "--type", "-t", metavar="TYPE",
    help="Only joints of this type (repeatable): revolute, continuous, prismatic, fixed, ...")]
AllOpt = Annotated[bool, typer.Option("--all", help="Show every field, however wide.")]
FileArg = Annotated[str, typer.Argument(
    help="A .urdf or .xacro file; a bare name is also looked up in pybullet_data.")]


def _inspect(file: str, package: list[str] | None, arg: list[str] | None, *,
             fixed_base: bool = False, inertia_from_file: bool = False,
             links: bool = False, info: bool = False) -> Any:
    from .report import inspect_file
    from .resolve import open_input
    from .session import LoadOptions

    options = LoadOptions(fixed_base=fixed_base, inertia_from_file=inertia_from_file)
    with open_input(file, package, arg) as resolved:
        return inspect_file(resolved, options, links=links, info=info)


def _num(x: float) -> str:
    s = f"{x:.4g}"
    return "0" if s in ("-0", "0") else s


def _nums(v: Any) -> str:
    return " ".join(_num(x) for x in v)


def _show_diagnostics(lines: list[str]) -> None:
    for line in lines:
        _warn(f"pybullet: {line}")


def _terminal_width() -> int:
    # $COLUMNS, else the terminal stdout is on, else the one stderr is on (`urdfkit joints x |
    # less` is still read on that screen), else 80, as rich assumes.
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


def _print_fitted_table(title: str, columns: list[tuple[str, int, str]],
                        rows: list[list[str]], show_all: bool) -> None:
    """Print the columns that fit the terminal, most important first.

    ``columns`` holds (header, priority, justify): priority 0 always shows, then priorities
    1, 2, ... join while they fit; 9 shows only with ``--all``. With ``--all`` and too little
    width for every column, each row becomes a block of "field value" lines instead, so
    nothing is squeezed into ellipses.

    On a terminal this is a rich table. Piped (CI logs, ``| grep``, ``> file``) it is plain
    text in aligned columns, no box drawing and no truncation, as rich's styling would be
    dropped there anyway, and without paying ~25 ms to import rich.
    """
    width = _terminal_width()
    needed = [max([len(h), *(len(r[i]) for r in rows)]) + 3 for i, (h, _, _) in
              enumerate(columns)]
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
    if not _styled(sys.stdout):
        _plain_table(title, columns, rows, keep, blocks)
        return
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
        _console().print(Group(*parts))
        return
    table = Table(title=heading, title_justify="left", show_edge=False, header_style="bold")
    for i in keep:
        header, _, justify = columns[i]
        # Text, not str: no markup or emoji parsing (rich's emoji table alone costs ~2 ms).
        table.add_column(Text(header), justify=justify)  # type: ignore[arg-type]
    for r in rows:
        table.add_row(*(Text(r[i]) for i in keep))
    _console().print(table)


def _plain_table(title: str, columns: list[tuple[str, int, str]], rows: list[list[str]],
                 keep: list[int], blocks: bool) -> None:
    out = [title]
    if blocks:
        label = max(len(h) for h, _, _ in columns)
        for r in rows:
            out.append("")
            out += [f"{h:<{label}}  {cell}".rstrip()
                    for (h, _, _), cell in zip(columns, r, strict=True)]
    else:
        grid = [[columns[i][0] for i in keep], *([r[i] for i in keep] for r in rows)]
        widths = [max(len(line[k]) for line in grid) for k in range(len(keep))]
        for line in grid:
            cells = [cell.rjust(w) if columns[i][2] == "right" else cell.ljust(w)
                     for i, cell, w in zip(keep, line, widths, strict=True)]
            out.append("  ".join(cells).rstrip())
    sys.stdout.write("\n".join(out) + "\n")
    sys.stdout.flush()


@app.command()
@_handle_errors
def joints(
    file: FileArg,
    as_json: JsonOpt = False,
    show_all: AllOpt = False,
    movable: MovableOpt = False,
    joint_type: TypeOpt = None,
    fixed_base: FixedBaseOpt = False,
    package: PackageOpt = None,
    arg: ArgOpt = None,
) -> None:
    """Every joint as PyBullet's getJointInfo sees it, decoded: index, type, limits, axis.

    --json prints {"file", "robot", "base_link", "joints": [...]} with the 17 getJointInfo
    fields under the Quickstart Guide names (jointIndex ... parentIndex); see docs/inspect.md.
    """
    from .inspect import filter_joints

    report = _inspect(file, package, arg, fixed_base=fixed_base)
    rows = filter_joints(report.joints, movable=movable, types=joint_type or ())
    if as_json:
        _print_json({**report.header(), "joints": [j.to_dict() for j in rows],
                     "diagnostics": report.diagnostics})
        return
    _show_diagnostics(report.diagnostics)
    columns = [("#", 0, "right"), ("joint", 0, "left"), ("type", 0, "left"),
               ("child link", 1, "left"), ("parent", 3, "left"), ("limits", 1, "right"),
               ("axis", 2, "left"), ("max force", 3, "right"), ("max vel", 3, "right"),
               ("xyz", 4, "left"), ("rpy", 4, "left"), ("q", 5, "right"), ("u", 5, "right"),
               ("damping", 6, "right"), ("friction", 6, "right"), ("quat", 9, "left"),
               ("flags", 9, "right")]
    cells = []
    for j in rows:
        if j.limited:
            limits = f"{_num(j.joint_lower_limit)} .. {_num(j.joint_upper_limit)}"
        else:
            limits = "unlimited" if j.movable else ""
        cells.append([
            str(j.joint_index), j.joint_name, j.type_label, j.link_name,
            f"{j.parent_index} {j.parent_link_name}", limits,
            _nums(j.joint_axis) if j.movable else "", _num(j.joint_max_force),
            _num(j.joint_max_velocity), _nums(j.parent_frame_pos), _nums(j.parent_frame_rpy),
            str(j.q_index), str(j.u_index), _num(j.joint_damping), _num(j.joint_friction),
            _nums(j.parent_frame_orn), str(j.flags)])
    shown = f"{len(rows)} of {len(report.joints)}" if len(rows) != len(report.joints) \
        else str(len(rows))
    _print_fitted_table(f"{report.robot}: {shown} joints, base link {report.base_link}",
                        columns, cells, show_all)


@app.command()
@_handle_errors
def links(
    file: FileArg,
    as_json: JsonOpt = False,
    show_all: AllOpt = False,
    inertia_from_file: Annotated[bool, typer.Option(
        "--inertia-from-file",
        help="Load with URDF_USE_INERTIA_FROM_FILE. Without it PyBullet ignores <inertia> "
             "and recomputes it from the collision shapes.")] = False,
    fixed_base: FixedBaseOpt = False,
    package: PackageOpt = None,
    arg: ArgOpt = None,
) -> None:
    """Each link's getDynamicsInfo (mass, friction, inertia) beside what the file says.

    A '!' marks engine values that differ from the file's: by default PyBullet recomputes
    inertia from the collision shapes, and a link without <inertial> gets 1 kg.
    """
    report = _inspect(file, package, arg, fixed_base=fixed_base,
                      inertia_from_file=inertia_from_file, links=True)
    if as_json:
        _print_json({**report.header(), "inertia_from_file": inertia_from_file,
                     "links": [link.to_dict() for link in report.links],
                     "diagnostics": report.diagnostics})
        return
    _show_diagnostics(report.diagnostics)
    columns = [("#", 0, "right"), ("link", 0, "left"), ("mass", 0, "right"),
               ("file mass", 1, "right"), ("inertia diagonal", 0, "left"),
               ("file principal inertia", 1, "left"), ("lateral", 2, "right"),
               ("rolling", 3, "right"), ("spinning", 3, "right"), ("restitution", 4, "right"),
               ("stiffness", 5, "right"), ("damping", 5, "right"), ("com xyz", 4, "left"),
               ("com quat", 9, "left")]
    cells = []
    differs = False
    for link in report.links:
        f = link.file
        mass_mark = " !" if link.mass_differs else ""
        inertia_mark = " !" if link.inertia_differs else ""
        differs = differs or bool(mass_mark or inertia_mark)
        cells.append([
            str(link.link_index), link.link_name, _num(link.mass) + mass_mark,
            _num(f.mass) if f else "none", _nums(link.local_inertia_diagonal) + inertia_mark,
            _nums(f.principal) if f else "none", _num(link.lateral_friction),
            _num(link.rolling_friction), _num(link.spinning_friction), _num(link.restitution),
            _num(link.contact_stiffness), _num(link.contact_damping),
            _nums(link.local_inertial_pos), _nums(link.local_inertial_orn)])
    inertia = "from the file" if inertia_from_file else "recomputed by PyBullet"
    _print_fitted_table(f"{report.robot}: {len(report.links)} links, inertia {inertia}",
                        columns, cells, show_all)
    if differs and not inertia_from_file:
        _line(("! = PyBullet's value differs from the file's; --inertia-from-file keeps the "
               "file's <inertia>", "dim"))


@app.command()
@_handle_errors
def tree(
    file: FileArg,
    as_json: JsonOpt = False,
    package: PackageOpt = None,
    arg: ArgOpt = None,
    dot: Annotated[bool, typer.Option(
        "--dot", help="Print the graph as Graphviz DOT (links boxes, joints edges).")] = False,
    output: Annotated[str | None, typer.Option(
        "--output", "-o", help="Write the graph: .dot/.gv as DOT text, .svg/.png/.pdf drawn "
        "by Graphviz `dot` (implies --dot).")] = None,
    force: ForceOpt = False,
) -> None:
    """The kinematic tree: links, and the joints between them with type, axis and index.

    Read from the file alone; PyBullet is not loaded. [n] is the index PyBullet will give
    the joint.
    """
    from .resolve import open_input
    from .tree import TreeNode, kinematic_tree

    if dot or output is not None:
        _tree_dot(file, package, arg, output, force, as_json)  # see "# ---- render"
        return
    with open_input(file, package, arg) as resolved:
        root = kinematic_tree(resolved.root)
        robot = resolved.robot_name
    if as_json:
        _print_json({"file": file, "robot": robot, "tree": root.to_dict()})
        return
    from rich.tree import Tree

    def label(node: TreeNode) -> str:
        j = node.joint
        if j is None:
            return f"[bold]{_escape(node.link)}[/]"
        extra = f" axis {_nums(j.axis)}" if j.axis is not None else ""
        if j.limit is not None:
            extra += f" [{_num(j.limit[0])} .. {_num(j.limit[1])}]"
        return (f"[dim]\\[{j.index}][/] [cyan]{_escape(j.name)}[/] ({j.type}"
                f"{_escape(extra)}) -> [bold]{_escape(node.link)}[/]")

    top = Tree(f"{label(root)} [dim]({_escape(robot)})[/]")
    stack: list[tuple[TreeNode, Any]] = [(root, top)]
    while stack:  # iterative: chains may be deeper than Python's recursion limit
        node, branch = stack.pop()
        stack.extend((child, branch.add(label(child))) for child in node.children)
    _console().print(top)


@app.command()
@_handle_errors
def info(
    file: FileArg,
    as_json: JsonOpt = False,
    fixed_base: FixedBaseOpt = False,
    package: PackageOpt = None,
    arg: ArgOpt = None,
) -> None:
    """The robot at a glance: links, joints by type, DOF, total mass, bounding box."""
    report = _inspect(file, package, arg, fixed_base=fixed_base, info=True)
    s = report.summary
    if as_json:
        _print_json({**report.header(), **s.to_dict(), "diagnostics": report.diagnostics})
        return
    _show_diagnostics(report.diagnostics)
    from rich.table import Table

    table = Table(show_header=False, show_edge=False, box=None)
    table.add_column(style="bold")
    table.add_column()
    types = ", ".join(f"{n} {t}" for t, n in s.joint_types.items()) or "none"
    mass = f"{_num(s.total_mass)} kg"
    if abs(s.total_mass - s.file_mass) > 1e-9 * max(1.0, s.file_mass):
        mass += f" (file says {_num(s.file_mass)} kg"
        if s.links_without_inertial:
            mass += f"; {len(s.links_without_inertial)} link(s) without <inertial> get 1 kg"
        mass += ")"
    for key, value in (
        ("robot", s.robot), ("file", report.path), ("base link", s.base_link),
        ("links", str(s.links)), ("joints", f"{s.joints} ({types})"),
        ("degrees of freedom", f"{s.dof}" + ("" if s.fixed_base else " + 6 (floating base)")),
        ("total mass", mass),
        ("bounding box", f"{_nums(s.aabb_min)} .. {_nums(s.aabb_max)}"),
        ("size", f"{_nums(s.size)} m"),
    ):
        table.add_row(key, _escape(value))
    _console().print(table)


# ---- check: validation rules over files and folders (urdfkit/check.py, urdfkit/validate.py)

_LEVEL_STYLE = {"error": "bold red", "warning": "yellow", "info": "cyan"}


@app.command()
@_handle_errors
def check(
    paths: Annotated[list[str], typer.Argument(
        metavar="FILE_OR_DIR...", help="URDF/xacro files, or folders searched recursively.")],
    as_json: JsonOpt = False,
    fail_on: Annotated[str, typer.Option(
        "--fail-on", metavar="error|warning",
        help="Exit 1 when a finding is at or above this level.")] = "error",
    package: PackageOpt = None,
    select: Annotated[list[str] | None, typer.Option(
        "--select", metavar="CODES",
        help="Only these codes or prefixes, comma-separated (e.g. U2,U601).")] = None,
    ignore: Annotated[list[str] | None, typer.Option(
        "--ignore", metavar="CODES", help="Drop these codes or prefixes, comma-separated.")]
    = None,
) -> None:
    """Check URDF files for errors PyBullet crashes on, physics mistakes and typos.

    Exit 0: nothing at or above --fail-on; 1: findings at or above it; 2: unusable invocation.
    See docs/check.md for every rule code.
    """
    from .check import check_paths, parse_codes
    from .errors import ParameterError
    from .resolve import parse_packages

    if fail_on not in ("error", "warning", "info"):
        raise ParameterError(f"--fail-on expects error, warning or info, got {fail_on!r}")
    result = check_paths(paths, packages=parse_packages(package),
                         select=parse_codes(select, "--select"),
                         ignore=parse_codes(ignore, "--ignore"))
    if as_json:
        _print_json(result.to_dict())
    else:
        console = _console()
        for fr in result.files:
            if not fr.findings:
                continue
            console.print(f"[bold]{_escape(fr.file)}[/]", soft_wrap=True)
            for f in fr.findings:
                line = f"{f.line:>5}" if f.line is not None else "    -"
                style = _LEVEL_STYLE[f.level]
                console.print(f"  {line}  [{style}]{f.level:<7}[/] [dim]{f.code}[/]  "
                              f"{_escape(f.message)}", soft_wrap=True)
        s = result.summary()
        colour = "red" if s["error"] else ("yellow" if s["warning"] else "green")
        console.print(f"[{colour}]{s['files']} file(s) checked: {s['error']} error(s), "
                      f"{s['warning']} warning(s), {s['info']} note(s); "
                      f"{s['files_with_errors']} file(s) with errors[/]", soft_wrap=True)
    raise typer.Exit(result.exit_code(fail_on))


# ---- drive: a headless throttle/steer run (urdfkit/drive.py, vehicle.py, plot.py)


def _split_joints(items: list[str] | None) -> list[str] | None:
    if items is None:
        return None
    return [j.strip() for item in items for j in item.split(",") if j.strip()]


def _drive_progress(as_json: bool) -> tuple[Callable[[int, int], None] | None, Callable[[], None]]:
    """A progress callback that shows a rich bar on a terminal once a run looks longer than ~1 s.

    Returns the callback (None when output is piped or --json) and a function that stops it.
    """
    if as_json or not (sys.stdout.isatty() and sys.stderr.isatty()):
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

            bar = Progress(TextColumn("driving"), BarColumn(), TextColumn("{task.completed:,}/"
                           "{task.total:,} steps"), TimeRemainingColumn(),
                           console=_console(stderr=True), transient=True)
            state["task"] = bar.add_task("drive", total=total)
            bar.start()
            state["bar"] = bar
        bar.update(state["task"], completed=done)

    def stop() -> None:
        if state["bar"] is not None:
            state["bar"].stop()

    return update, stop


@app.command()
@_handle_errors
def drive(
    throttle: Annotated[float, typer.Option(
        help="Target wheel speed, rad/s (VELOCITY_CONTROL on every wheel); negative reverses.")]
    = 10.0,
    steer: Annotated[float, typer.Option(
        help="Steering angle, rad (POSITION_CONTROL on the hinges); positive turns left.")]
    = 0.0,
    seconds: Annotated[float | None, typer.Option(
        help="Simulated duration in seconds (default 10).")] = None,
    steps: Annotated[int | None, typer.Option(help="Number of physics steps instead.")] = None,
    time_step: Annotated[float, typer.Option(help="Physics time step, s.")] = 1.0 / 240.0,
    max_force: Annotated[float, typer.Option(help="Wheel motor torque limit, N m.")] = 10.0,
    urdf: Annotated[str | None, typer.Option(
        help="Car to drive (.urdf/.xacro; pybullet_data names work). Default: simplecar.")]
    = None,
    plane: Annotated[str | None, typer.Option(
        help="Ground to drive on. Default: the built-in simpleplane.")] = None,
    set_: SetOpt = None,
    arg: ArgOpt = None,
    package: PackageOpt = None,
    wheels: Annotated[list[str] | None, typer.Option(
        metavar="JOINTS", help="Wheel joints (names or indices, comma-separated) instead of "
        "the detected ones.")] = None,
    hinges: Annotated[list[str] | None, typer.Option(
        metavar="JOINTS", help="Steering hinge joints instead of the detected ones.")] = None,
    trajectory: Annotated[str | None, typer.Option(
        metavar="FILE", help="Write samples to FILE.csv or FILE.jsonl.")] = None,
    sample_every: Annotated[int | None, typer.Option(
        help="Steps between samples (default: 20 per simulated second).")] = None,
    plot: Annotated[str | None, typer.Option(
        metavar="FILE.png", help="Draw the path and speed (needs urdfkit[plot]).")] = None,
    force: ForceOpt = False,
    gui: Annotated[bool, typer.Option(
        "--gui", help="Open the PyBullet GUI with Steering and Throttle sliders.")] = False,
    as_json: JsonOpt = False,
) -> None:
    """Drive a car headless at a fixed throttle and steer, and report where it went.

    Wheels (continuous joints about a horizontal axis) and steering hinges (revolute joints
    about a vertical axis that carry wheels) are detected. See docs/drive.md.
    """
    from pathlib import Path as _Path

    from .drive import DriveConfig, Scenario, trajectory_format
    from .errors import OutputError, ParameterError

    if seconds is not None and steps is not None:
        raise ParameterError("give --seconds or --steps, not both")
    if gui and not (os.environ.get("DISPLAY") or os.environ.get("WAYLAND_DISPLAY")
                    or sys.platform in ("darwin", "win32")):
        raise ParameterError("--gui needs a display (DISPLAY is not set); drop --gui to "
                             "drive headless")
    # Check the outputs before a long run, not after it.
    for out in (trajectory, plot):
        if out is not None and _Path(out).exists() and not force:
            raise OutputError("exists; pass --force to overwrite it", file=out)
    if trajectory is not None:
        trajectory_format(trajectory)
    if plot is not None:
        from .plot import check_plot_path

        check_plot_path(plot)
    params = None
    if set_:
        from .catalog import parse_assignments  # imports the builder: only when needed

        params = parse_assignments(set_)
    config = DriveConfig(
        urdf=urdf, plane=plane, template_params=params,
        packages=package, xacro_args=arg, seconds=10.0 if seconds is None else seconds,
        steps=steps, time_step=time_step, throttle=throttle, steer=steer, max_force=max_force,
        wheels=_split_joints(wheels), hinges=_split_joints(hinges), sample_every=sample_every,
        gui=gui)
    with Scenario(config) as sc:
        t = sc.drivetrain

        def names(joints: list[int]) -> str:
            return ", ".join(t.joint_names[j] for j in joints) or "none"

        _line((f"{sc.model}: wheels {names(t.wheels)}; hinges {names(t.hinges)}; "
               f"passive {names(t.passive)}", "dim"), stderr=True)
        for w in sc.warnings:
            _warn(w)
        progress, stop = _drive_progress(as_json)
        try:
            result = sc.run(progress)
        finally:
            stop()
    written = []
    if trajectory is not None:
        from .drive import write_trajectory

        written.append(write_trajectory(result.trajectory, trajectory, force=force))
    if plot is not None:
        from .plot import write_plot

        written.append(write_plot(result, plot, force=force))
    if as_json:
        data = result.to_dict()
        data["files"] = [str(w) for w in written]
        _print_json(data)
    else:
        _drive_summary(result)
        for path in written:
            _line("wrote ", (str(path), "bold"), stderr=True)
    if result.interrupted:
        _line(("urdfkit: interrupted; the results cover the steps simulated", "yellow"),
              stderr=True)
        raise typer.Exit(130)


def _drive_summary(r: Any) -> None:
    # Aligned lines rather than a rich Table, plain off a terminal: the same look, and no
    # rich import (~15 ms), which matters for the drive benchmark (whole process against a
    # bare PyBullet loop).
    x, y, z = r.final_position
    turn = ("straight (no settled turn)" if r.turning_radius is None else
            f"{r.turning_radius:.3f} m around ({r.turn_center[0]:.2f}, {r.turn_center[1]:.2f})")
    rows = [
        ("final position", f"x {x:.3f}  y {y:.3f}  z {z:.3f} m"),
        ("final yaw", f"{r.final_yaw:.3f} rad ({r.final_yaw * 57.29577951308232:.1f} deg)"),
        ("heading change", f"{r.heading_change:.3f} rad"),
        ("distance", f"{r.distance:.3f} m along the path"),
        ("mean speed", f"{r.mean_speed:.3f} m/s"),
        ("turning radius", turn),
        ("simulated", f"{r.sim_time:.3f} s in {r.steps:,} steps of {r.time_step:.5g} s"),
        ("wall time", f"{r.wall_time:.3f} s (real-time factor {r.real_time_factor:.1f}x)"),
    ]
    _line(("drive", "bold"), f" {r.model}: throttle {r.throttle:g} rad/s, steer {r.steer:g} rad")
    for key, value in rows:
        _line(" ", (f"{key:<15}", "cyan"), " ", value)


# ---- render: headless PNG pictures (urdfkit/render.py) and tree --dot (urdfkit/graph.py)


@app.command()
@_handle_errors
def render(
    file: FileArg,
    output: Annotated[str | None, typer.Option(
        "--output", "-o", help="The PNG to write; '-' for stdout. Default: <name>.png here.")]
    = None,
    view: Annotated[str, typer.Option(
        "--view", help="Camera: iso, front, side or top.")] = "iso",
    views: Annotated[str | None, typer.Option(
        "--views", metavar="all|V,V,V,V",
        help="Four views as a labelled 2x2 grid: 'all' (iso, front, side, top) or a list.")]
    = None,
    size: Annotated[str, typer.Option("--size", metavar="WxH", help="Image size in pixels.")]
    = "800x600",
    ground: Annotated[str, typer.Option(
        "--ground", help="grid (lines), plane (shaded, with shadow) or none.")] = "grid",
    joints: Annotated[list[str] | None, typer.Option(
        "--joints", "-j", metavar="NAME=VALUE",
        help="Pose a joint before the shot, in rad or m (repeatable, or a=1,b=2).")] = None,
    collision: Annotated[bool, typer.Option(
        "--collision", help="Draw the collision shapes instead of the visuals.")] = False,
    frames: Annotated[bool, typer.Option(
        "--frames", help="Mark link frames (x red, y green, z blue) and joint axes.")] = False,
    as_json: Annotated[bool, typer.Option(
        "--json", help="Print what was drawn (cameras, bounding box) as JSON.")] = False,
    force: ForceOpt = False,
    package: PackageOpt = None,
    arg: ArgOpt = None,
) -> None:
    """Draw a robot to a PNG, headless (PyBullet's TinyRenderer: no GPU, no display)."""
    from . import render as rendering

    width, height = rendering.parse_size(size)
    if views is None:
        chosen: tuple[str, ...] = (view,)
    elif views.strip() == "all":
        chosen = rendering.ALL_VIEWS
    else:
        chosen = tuple(v.strip() for v in views.split(",") if v.strip())
    options = rendering.RenderOptions(
        views=chosen, width=width, height=height, ground=ground,
        joints=rendering.parse_joint_positions(joints), collision=collision, frames=frames)
    out = output if output is not None else f"{Path(file).name.split('.')[0] or 'robot'}.png"
    if out != "-":  # refuse before the work, not after it
        rendering.check_output(out, force=force)
    picture = rendering.render_file(file, options, packages=package, xacro_args=arg)
    for w in picture.warnings:
        _warn(w)
    if out == "-":
        sys.stdout.buffer.write(picture.png_bytes())
        sys.stdout.flush()
        return
    path = rendering.write_png(picture, out, force=force)
    if as_json:
        _print_json({"output": str(path), **picture.to_dict()})
        return
    _line("wrote ", (str(path), "bold"), f" ({picture.width}x{picture.height}, "
          f"{', '.join(chosen)}{', collision shapes' if collision else ''})", stderr=True)


def _tree_dot(file: str, package: list[str] | None, arg: list[str] | None,
              output: str | None, force: bool, as_json: bool) -> None:
    """``tree --dot`` / ``tree -o graph.svg``: the kinematic graph as DOT text or a drawing."""
    from .errors import ParameterError
    from .graph import check_output, dot_graph, write_graph
    from .resolve import open_input

    if as_json:
        raise ParameterError("--json and --dot/-o are different outputs; choose one")
    if output is not None and output != "-":
        check_output(output, force=force)
    with open_input(file, package, arg) as resolved:
        text = dot_graph(resolved.root)
    if output is None or output == "-":
        sys.stdout.write(text)
        sys.stdout.flush()
        return
    path = write_graph(text, output, force=force)
    _line("wrote ", (str(path), "bold"), stderr=True)


# ---- sim: scenario files (urdfkit/scenario.py) run by urdfkit/sim.py


@app.command()
@_handle_errors
def sim(
    scenario: Annotated[str, typer.Argument(
        help="A scenario file (.json or .toml): robots, controllers, physics. See "
             "docs/scenario.md.")],
    out: Annotated[str | None, typer.Option(
        "--out", "-o", metavar="FILE",
        help="Write the observation rows to FILE.jsonl, FILE.csv or FILE.parquet.")] = None,
    as_json: JsonOpt = False,
    force: ForceOpt = False,
) -> None:
    """Simulate a scenario of one or more robots and record their observations.

    Without --out a summary per robot prints; with --json, one JSON object (holding the rows
    too when there is no --out).
    """
    from . import sim as simulation

    if out is not None:
        simulation.check_output(out, force=force)  # fail before the run, not after it
    with simulation.Simulation.from_file(scenario) as s:
        result = s.run()
    rows = result.to_dicts()
    written = None if out is None else simulation.write_rows(out, rows, force=force)
    summaries = simulation.summarize(result)
    if as_json:
        data: dict[str, Any] = {
            "scenario": scenario, "time_step": result.time_step, "steps": result.steps,
            "duration": result.steps * result.time_step, "rows": len(rows),
            "robots": [x.to_dict() for x in summaries],
            "out": None if written is None else str(written)}
        if written is None:
            data["observations"] = rows
        _print_json(data)
        return
    _sim_summary(scenario, result, summaries)
    if written is not None:
        _line("wrote ", (str(written), "bold"), f" ({len(rows):,} rows)", stderr=True)


def _sim_summary(scenario: str, result: Any, summaries: list[Any]) -> None:
    from rich.table import Table

    table = Table(title=f"[bold]sim[/] {_escape(scenario)}: {result.steps:,} steps of "
                  f"{result.time_step:.5g} s", title_justify="left", show_edge=False)
    table.add_column("robot", style="cyan")
    table.add_column("rows", justify="right")
    table.add_column("end x y z (m)", no_wrap=True)
    table.add_column("moved m", justify="right")
    table.add_column("top m/s", justify="right")
    table.add_column("yaw deg", justify="right")

    def num(v: float, digits: int = 3) -> str:
        text = f"{v:.{digits}f}"
        return text[1:] if text.startswith("-") and not text.strip("-0.") else text

    for x in summaries:
        table.add_row(_escape(x.robot), str(x.rows), " ".join(num(v) for v in x.end),
                      num(x.distance), num(x.top_speed), num(x.heading_deg, 1))
    console = _console()
    console.print(table)
    for x in summaries:
        if x.final_joints:
            joints = ", ".join(f"{k} {num(v)}" for k, v in x.final_joints.items())
            console.print(f"[cyan]{_escape(x.robot)}[/] final joints: {_escape(joints)}")


def _command_name(info: Any) -> str:
    return info.name or info.callback.__name__.replace("_", "-")


def _single_command_app(name: str) -> typer.Typer | None:
    """A copy of :data:`app` that holds only the command ``name``, or None if unknown.

    typer builds the click command of *every* registered command on each run (signature
    and type-hint evaluation, ~1 ms each). A user runs one command at a time, so the entry
    point builds just that one; ``urdfkit --help`` still builds them all.
    """
    infos = [i for i in app.registered_commands if _command_name(i) == name]
    if not infos:
        return None
    # no_args_is_help off: with one command, typer would otherwise treat a lone
    # `urdfkit joints` as the group's own help request.
    single = typer.Typer(name=app.info.name, add_completion=False,
                         pretty_exceptions_enable=False,
                         context_settings={"help_option_names": ["-h", "--help"]})
    single.registered_callback = app.registered_callback
    single.registered_commands = infos
    return single


def main() -> None:
    """Entry point of the ``urdfkit`` console script."""
    # numpy (imported by pybullet) starts an OpenBLAS thread pool whose workers spin on the
    # second core: ~70 ms of CPU per `urdfkit joints`, for nothing, since no command does large
    # linear algebra. One thread, unless the user asks otherwise. Set here, not on import, so
    # library users keep their own setting.
    os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")
    # What is loaded by now (typer, click, this module) lives until exit. Freezing it keeps the
    # cyclic GC from re-scanning it in every full collection that the imports of numpy and
    # pybullet trigger: ~8 ms of a `urdfkit joints` run. Later garbage is collected as usual.
    gc.freeze()
    argv = sys.argv[1:]
    single = _single_command_app(argv[0]) if argv and not argv[0].startswith("-") else None
    (single or app)()
