"""The ``urdfkit`` command line: parse options, call the library, present the result.

Nothing heavy is imported at module level: ``urdfkit --help`` must not pay for PyBullet,
numpy, yourdfpy or trimesh. Library errors (:class:`~urdfkit.errors.UrdfkitError`) are caught
once, in :func:`_handle_errors`, and become one red line on stderr plus an exit code.
"""

from __future__ import annotations

import functools
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
    from rich.console import Console

    # rich honours NO_COLOR and drops styling when the stream is not a terminal.
    return Console(stderr=stderr, highlight=False)


def _fail(message: str, code: int = 2) -> None:
    # soft_wrap: an error is one line, however narrow the terminal.
    _console(stderr=True).print(f"[bold red]urdfkit: error:[/] {_escape(message)}",
                                soft_wrap=True)
    raise typer.Exit(code)


def _warn(message: str) -> None:
    _console(stderr=True).print(f"[yellow]urdfkit: warning:[/] {_escape(message)}",
                                soft_wrap=True)


def _escape(text: str) -> str:
    from rich.markup import escape

    return escape(text)


def _print_json(data: Any) -> None:
    # Plain print, not rich: JSON must parse whatever the terminal is.
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
            _console(stderr=True).print("[yellow]urdfkit: interrupted[/]")
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
    _console(stderr=True).print(
        f"wrote [bold]{_escape(str(path))}[/] ({result.links} links, {result.joints} joints)")


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


def main() -> None:
    """Entry point of the ``urdfkit`` console script."""
    app()
