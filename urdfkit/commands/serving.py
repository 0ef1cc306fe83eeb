"""lsp, mcp: urdfkit for editors (a Language Server) and for agents (an MCP server), over stdio."""

from __future__ import annotations

from typing import Annotated

import typer

from urdfkit.commands.shared import ArgOpt, PackageOpt, PackagePathOpt, command, examples

TargetOpt = Annotated[list[str] | None, typer.Option(
    "--target", metavar="NAMES", help="Also what these consumers refuse or change: ros, "
    "pinocchio, drake, mujoco (comma-separated or repeated), as check --target.")]


@command(examples("urdfkit lsp", "urdfkit lsp --target ros,pinocchio"))
def lsp(
    target: TargetOpt = None,
    package: PackageOpt = None,
    package_path: PackagePathOpt = None,
    arg: ArgOpt = None,
) -> None:
    """A Language Server for .urdf, .xacro and .urdf.xacro files, over stdio.

    Diagnostics from check at the line (and file) they were written at, on open, change and
    save; hover on a link or joint (PyBullet's index, type, limits, mass, inertia) or a xacro
    name; go to definition, references, completion, the outline, and fix's repairs as code
    actions. An editor starts it; see docs/editor.md.
    """
    from urdfkit.checks.targets import parse_targets
    from urdfkit.commands.check_run import xacro_args
    from urdfkit.serve.lsp import build_server
    from urdfkit.sources.uris import parse_packages

    server = build_server(parse_targets(target), parse_packages(package, package_path),
                          xacro_args(arg))
    server.start_io()


@command(examples("urdfkit mcp", "urdfkit mcp --root ~/robots"))
def mcp(
    root: Annotated[list[str] | None, typer.Option(
        "--root", metavar="DIR", help="A folder the tools may read and write in, for clients "
        "that send no roots (repeatable; default: the working folder).")] = None,
) -> None:
    """An MCP server over stdio: check, joints, links, info, collisions, fix, build, render, agree.

    Each tool runs the command as a user runs it, in a process of its own, and answers with its
    JSON (render with a PNG); a refusal is a tool error with the command's own line. Paths
    outside the client's roots are refused; fix writes only when asked. See docs/editor.md.
    """
    from urdfkit.serve.mcp import build_mcp

    build_mcp(root or ()).run("stdio")
