"""The build and templates commands: a URDF from a template or a xacro file."""

import sys
from pathlib import Path
from typing import Annotated

import typer

from urdfkit.commands import present as show
from urdfkit.commands.shared import (
    ArgOpt,
    ForceOpt,
    PackageOpt,
    PackagePathOpt,
    SetOpt,
    command,
    examples,
)


@command(examples(
    "urdfkit build simplecar", "urdfkit build simplecar --set wheel_radius=0.12 -o car.urdf",
    "urdfkit build my_robot.urdf.xacro --arg prefix:=left_ -o -"))
def build(
    target: Annotated[str, typer.Argument(
        help="A template name (simplecar, simpleplane) or your own .xacro file.")],
    output: Annotated[str | None, typer.Option(
        "--output", "-o", help="Where to write; '-' for stdout. Default: <name>.urdf here.")]
    = None,
    set_: SetOpt = None,
    arg: ArgOpt = None,
    force: ForceOpt = False,
    package: PackageOpt = None,
    package_path: PackagePathOpt = None,
    strict: Annotated[bool, typer.Option(
        "--strict", help="Refuse (exit 1, nothing written) when check finds errors in the "
        "expanded file, instead of writing it with warnings.")] = False,
) -> None:
    """Build a URDF from a template or a xacro file, check it, and write it atomically.

    A .xacro file (or a .urdf holding xacro) is expanded in a subprocess with a timeout:
    xacro's ${...} expressions run Python code, so only expand files you trust (see
    docs/security.md). What PyBullet loads is written: check's errors on it are warnings
    (--strict refuses them); what would crash PyBullet, or what it refuses to load (a
    missing mesh), is refused, nothing written.
    """
    from urdfkit.checks import build as building
    from urdfkit.sources.uris import parse_packages

    result = building.build(target, params=set_, xacro_args=arg,
                            packages=parse_packages(package, package_path), strict=strict)
    out = output if output is not None else result.default_output
    for w in result.warnings:
        show.warn(w)
    if out == "-":
        here = result.written_at(Path.cwd() / "-")[1]  # what would move for a file here
        if here:
            show.warn(f"{target}: {len(here)} mesh or texture path(s) are relative to its "
                      f"folder ({here[0][0]!r}, ...) and are written as they are: save the "
                      "output in that folder, or use -o FILE, which rewrites them for where "
                      "it writes")
        sys.stdout.buffer.write(result.data)
        sys.stdout.flush()
        return
    data, moved = result.written_at(out)
    lost = building.unreachable_packages(data, Path(out))
    if lost is not None:
        show.warn(lost)
    path = building.write_output(out, data, force=force)
    show.wrote(path, f"{show.counted(result.links, 'link')}, "
                     f"{show.counted(result.joints, 'joint')}"
                     + (f"; {len(moved)} relative mesh or texture path(s) rewritten for its "
                        "folder" if moved else ""))


@command(examples("urdfkit templates", "urdfkit templates --json"))
def templates(
    as_json: Annotated[bool, typer.Option("--json", help="Print JSON.")] = False,
) -> None:
    """List the built-in templates with their parameters and defaults."""
    from urdfkit.model.catalog import TEMPLATES

    if as_json:
        show.print_json({"templates": [
            {"name": t.name, "description": t.description, "file": t.file,
             "params": [{"name": p.name, "type": p.kind, "default": p.default, "help": p.help}
                        for p in t.params]}
            for t in TEMPLATES.values()]})
        return
    columns = [("parameter", 0, "left"), ("default", 0, "right"), ("meaning", 1, "left")]
    for n, t in enumerate(TEMPLATES.values()):
        if n:
            show.line("")
        show.table(f"{t.name}: {t.description}", columns,
                   [[p.name, p.show(p.default), p.help] for p in t.params])
