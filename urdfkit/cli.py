"""The ``urdfkit`` command line: parse options, call the library, hand the result to present.

cli.py holds options and calls; what the output looks like lives in :mod:`urdfkit.present`,
and every error takes one road: :class:`UrdfkitGroup.main` is the only place that catches,
turning each outcome into one line on stderr and an exit code:

- 0 ok; 1 findings at or above ``--fail-on`` (check); 2 bad input or usage (a
  :class:`~urdfkit.errors.UrdfkitError`, or a bad option value); 3 an internal error, a
  bug (``URDFKIT_DEBUG=1`` shows the traceback); 130 interrupted (Ctrl-C, SIGTERM, SIGHUP).
- The library names Python parameters in its messages (`` `time_step` ``); the handler shows
  the flag that feeds it (``--time-step``).

Nothing heavy is imported at module level: ``urdfkit --help`` must not pay for PyBullet,
numpy, yourdfpy or trimesh.
"""

import gc
import os
import re
import signal
import sys
from collections.abc import Sequence
from pathlib import Path
from typing import Annotated, Any

import typer
from typer.core import TyperGroup

from . import __version__
from . import present as show
from .errors import UrdfkitError

#: Library parameter -> the flag that feeds it, for messages (`time_step` -> --time-step).
#: A parameter not listed maps to ``--`` plus its name with dashes.
FLAGS = {
    "params": "--set", "template_params": "--set", "xacro_args": "--arg",
    "packages": "--package", "package_paths": "--package-path", "types": "--type",
    "urdf": "--urdf", "force=True": "--force",
    "force": "--force", "joints": "--joints", "views": "--views", "guard=False": "--no-guard",
    "kind": "KIND",
}

DEBUG_ENV = "URDFKIT_DEBUG"


def flag_message(message: str) -> str:
    """A library message with its backquoted parameter names shown as CLI flags."""
    return re.sub(r"`([A-Za-z_][\w]*(?:=True|=False)?)`",
                  lambda m: FLAGS.get(m.group(1), "--" + m.group(1).replace("_", "-")),
                  message)


#: Parameters every loading command takes from the same flags: their names are translated in
#: any message (a xacro or package error deep in a load, a check finding), not only in errors
#: about a parameter. None of them is ever a scenario key.
INPUT_PARAMS = ("xacro_args", "packages", "package_paths")


def input_flags(message: str) -> str:
    """A message with the input parameters (``xacro_args``) shown as their flags (``--arg``)."""
    return re.sub(r"`(" + "|".join(INPUT_PARAMS) + r")`", lambda m: FLAGS[m.group(1)], message)


def _click_error(e: BaseException) -> bool:
    # click's own errors (bad option values, unknown options, missing arguments). Told apart
    # by shape, not class: typer 0.28 carries a private copy of click, older typer uses click.
    return hasattr(e, "format_message") and isinstance(getattr(e, "exit_code", None), int)


def _usage_message(e: Any) -> str:
    ctx = getattr(e, "ctx", None)
    where = f"{ctx.command_path}: " if ctx is not None else ""
    text = " ".join(e.format_message().split())  # one line, however click wrapped it
    option = getattr(e, "option_name", None)
    if option and not getattr(e, "possibilities", None) and ctx is not None:
        from .suggest import hint

        flags = [o for p in ctx.command.params for o in getattr(p, "opts", [])
                 if o.startswith("--")]
        text += hint(option, flags)
    if ctx is not None:
        text += f" (see `{ctx.command_path} --help`)"
    return where + text


def _on_signal(signum: int, _frame: Any) -> None:
    # SIGTERM (a CI timeout, `kill`) and SIGHUP (a closed terminal) stop a run the way
    # Ctrl-C does: drive and sim keep the rows simulated so far, temp files are removed.
    raise KeyboardInterrupt(signal.Signals(signum).name)


class UrdfkitGroup(TyperGroup):
    """urdfkit's click group: its :meth:`main` is the one error handler of the CLI."""

    def main(self, args: Sequence[str] | None = None, prog_name: str | None = None,
             complete_var: str | None = None, standalone_mode: bool = True,
             windows_expand_args: bool = True, **extra: Any) -> Any:
        """Run a command; map every outcome to one stderr line and an exit code."""
        argv = sys.argv[1:] if args is None else list(args)
        prog_name = prog_name or "urdfkit"
        self._main_shell_completion(extra, prog_name, complete_var)
        code = run(self, argv, prog_name, extra)
        if standalone_mode:
            sys.exit(code)
        return code


def run(command: Any, argv: list[str], prog_name: str, extra: dict[str, Any]) -> int:
    """Invoke ``command`` and turn what happens into an exit code (printing one line)."""
    try:
        with command.make_context(prog_name, argv, **extra) as ctx:
            command.invoke(ctx)
        return 0
    except typer.Exit as e:
        return e.exit_code
    except UrdfkitError as e:
        # Only errors about a parameter speak of flags; a scenario file's `wheels` stays a key.
        show.error(flag_message(str(e)) if e.param is not None else input_flags(str(e)))
        return e.exit_code
    except (KeyboardInterrupt, typer.Abort):
        show.interrupted()
        return 130
    except BrokenPipeError:
        # `urdfkit joints big.urdf | head`: the reader went away; that is not an error.
        devnull = os.open(os.devnull, os.O_WRONLY)
        os.dup2(devnull, sys.stdout.fileno())
        return 0
    except Exception as e:  # noqa: BLE001 - the last line of defence: a bug, said so
        if _click_error(e):
            context = getattr(e, "ctx", None)
            if context is not None and type(e).__name__ == "NoArgsIsHelpError":
                sys.stdout.write(context.get_help() + "\n")  # a bare `urdfkit`: the help
            else:
                show.error(_usage_message(e))
            return 2
        if os.environ.get(DEBUG_ENV):
            import traceback

            traceback.print_exc()
        show.bug(e)
        return 3


app = typer.Typer(
    name="urdfkit",
    cls=UrdfkitGroup,
    help="Build, inspect and test-drive URDF robot descriptions with PyBullet.",
    no_args_is_help=True,
    add_completion=True,
    pretty_exceptions_enable=False,
    rich_markup_mode="rich",
    context_settings={"help_option_names": ["-h", "--help"]},
)


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
    """Build, inspect and test-drive URDF robot descriptions with PyBullet.

    Exit codes: 0 ok, 1 findings (check), 2 bad input or usage, 3 a bug in urdfkit,
    130 interrupted. URDFKIT_DEBUG=1 prints the traceback of a bug.
    """


def _examples(*lines: str) -> str:
    """The examples block that ends every command's help (kept verbatim by rich help)."""
    return "\n\n[bold]Examples[/]\n\n" + "\n".join(f"  [dim]$[/] {line}" for line in lines)


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
PackagePathOpt = Annotated[list[str] | None, typer.Option(
    "--package-path", metavar="DIR",
    help="A folder searched for ROS packages (package.xml) for package:// and $(find) "
    "(repeatable); ROS_PACKAGE_PATH and AMENT_PREFIX_PATH are searched too.")]
JsonOpt = Annotated[bool, typer.Option("--json", help="Print one JSON object on stdout.")]
FixedBaseOpt = Annotated[bool, typer.Option("--fixed-base", help="Pin the root link to the world.")]
FlagsOpt = Annotated[str | None, typer.Option(
    "--flags", metavar="NAMES",
    help="Exactly these PyBullet loadURDF flags, comma-separated (URDF_USE_INERTIA_FROM_FILE,"
    "URDF_USE_IMPLICIT_CYLINDER, ...; the URDF_ may be left out), or none: to match your own "
    "p.loadURDF call. Default: URDF_USE_IMPLICIT_CYLINDER (true cylinders).",
    show_default=False)]
NoGuardOpt = Annotated[bool, typer.Option(
    "--no-guard", help="Lift the guard's refusals that are stricter than PyBullet ('%' in a "
    "joint name, names over 1000 bytes); each is printed as a warning. What crashes PyBullet "
    "stays refused.")]


@app.command(epilog=_examples(
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
    (--strict refuses them); what would crash PyBullet is refused.
    """
    from . import build as building
    from .uris import parse_packages

    result = building.build(target, params=set_, xacro_args=arg,
                            packages=parse_packages(package, package_path), strict=strict)
    out = output if output is not None else result.default_output
    for w in result.warnings:
        show.warn(w)
    if out == "-":
        sys.stdout.buffer.write(result.data)
        sys.stdout.flush()
        return
    path = building.write_output(out, result.data, force=force)
    show.wrote(path, f"{result.links} links, {result.joints} joints")


@app.command(epilog=_examples("urdfkit templates", "urdfkit templates --json"))
def templates(
    as_json: Annotated[bool, typer.Option("--json", help="Print JSON.")] = False,
) -> None:
    """List the built-in templates with their parameters and defaults."""
    from .catalog import TEMPLATES

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


# ---- inspect: joints, links, tree, info (urdfkit/inspect.py holds the data)

MovableOpt = Annotated[bool, typer.Option("--movable", help="Only joints that can move.")]
TypeOpt = Annotated[list[str] | None, typer.Option(
    "--type", "-t", metavar="TYPE",
    help="Only joints of this type (repeatable): revolute, continuous, prismatic, fixed, ...")]
AllOpt = Annotated[bool, typer.Option("--all", help="Show every field, however wide.")]
FileArg = Annotated[str, typer.Argument(
    help="A .urdf or .xacro file; a bare name is also looked up in pybullet_data.")]


def _open(file: str, package: list[str] | None, arg: list[str] | None, no_guard: bool,
          package_path: list[str] | None = None, meshes: bool = True) -> Any:
    from .resolve import open_input

    resolved = open_input(file, package, arg, guard=not no_guard, package_paths=package_path,
                          meshes=meshes)
    for w in resolved.warnings:
        show.warn(input_flags(w))
    return resolved


def _inspect(file: str, package: list[str] | None, arg: list[str] | None, *,
             fixed_base: bool = False, inertia_from_file: bool = False,
             links: bool = False, info: bool = False, no_guard: bool = False,
             package_path: list[str] | None = None, flags: str | None = None) -> Any:
    from .report import inspect_file
    from .session import LoadOptions, parse_flags

    if flags is not None:
        if inertia_from_file:
            from .errors import ParameterError

            raise ParameterError("give --inertia-from-file or --flags (with "
                                 "URDF_USE_INERTIA_FROM_FILE in it), not both", param="flags")
        options = LoadOptions(fixed_base=fixed_base, **parse_flags(flags))
    else:
        options = LoadOptions(fixed_base=fixed_base, inertia_from_file=inertia_from_file)
    with _open(file, package, arg, no_guard, package_path) as resolved:
        report = inspect_file(resolved, options, links=links, info=info)
    report.load_flags = options.flag_names()
    return report


def _loaded_with(report: Any) -> None:
    """The flags the robot was loaded with, under the table (text mode)."""
    show.note("loaded with " + (" | ".join(report.load_flags) or "no flags"), stderr=False)


@app.command(epilog=_examples(
    "urdfkit joints r2d2.urdf", "urdfkit joints car.urdf --movable --type continuous",
    "urdfkit joints kuka_iiwa/model.urdf --json | jq '.joints[].jointName'"))
def joints(
    file: FileArg,
    as_json: JsonOpt = False,
    show_all: AllOpt = False,
    movable: MovableOpt = False,
    joint_type: TypeOpt = None,
    fixed_base: FixedBaseOpt = False,
    flags: FlagsOpt = None,
    package: PackageOpt = None,
    package_path: PackagePathOpt = None,
    arg: ArgOpt = None,
    no_guard: NoGuardOpt = False,
) -> None:
    """Every joint as PyBullet's getJointInfo sees it, decoded: index, type, limits, axis.

    --json prints {"file", "robot", "base_link", "joints": [...]} with the 17 getJointInfo
    fields under the Quickstart Guide names (jointIndex ... parentIndex); see docs/inspect.md.
    """
    from .inspect import filter_joints

    report = _inspect(file, package, arg, fixed_base=fixed_base, no_guard=no_guard,
                      package_path=package_path, flags=flags)
    rows = filter_joints(report.joints, movable=movable, types=joint_type or ())
    if as_json:
        show.print_json({**report.header(), "joints": [j.to_dict() for j in rows],
                         "diagnostics": report.diagnostics})
        return
    show.diagnostics(report.diagnostics)
    num, nums = show.num, show.nums
    columns = [("#", 0, "right"), ("joint", 0, "left"), ("type", 0, "left"),
               ("child link", 1, "left"), ("parent", 3, "left"), ("limits", 1, "right"),
               ("axis", 2, "left"), ("origin xyz", 3, "left"), ("origin rpy", 3, "left"),
               ("max force", 3, "right"), ("max vel", 3, "right"),
               ("parentFramePos", 4, "left"), ("parentFrameRpy", 4, "left"), ("q", 5, "right"),
               ("u", 5, "right"), ("damping", 6, "right"), ("friction", 6, "right"),
               ("quat", 9, "left"), ("flags", 9, "right"), ("jointAxis", 9, "left")]
    cells = []
    for j in rows:
        if j.limited:
            limits = f"{num(j.joint_lower_limit)} .. {num(j.joint_upper_limit)}"
        else:
            limits = "unlimited" if j.movable else ""
        cells.append([
            str(j.joint_index), j.joint_name, j.type_label, j.link_name,
            f"{j.parent_index} {j.parent_link_name}", limits,
            # The file's axis (the joint frame); PyBullet's jointAxis is in the child's
            # inertial frame, turned by an <inertial><origin rpy> (its own column).
            nums(j.axis_xyz if j.axis_xyz is not None else j.joint_axis) if j.movable else "",
            nums(j.origin_xyz) if j.origin_xyz is not None else "",
            nums(j.origin_rpy) if j.origin_rpy is not None else "",
            num(j.joint_max_force),
            num(j.joint_max_velocity), nums(j.parent_frame_pos), nums(j.parent_frame_rpy),
            str(j.q_index), str(j.u_index), num(j.joint_damping), num(j.joint_friction),
            nums(j.parent_frame_orn), str(j.flags), nums(j.joint_axis) if j.movable else ""])
    shown = f"{len(rows)} of {len(report.joints)}" if len(rows) != len(report.joints) \
        else str(len(rows))
    show.table(f"{report.robot}: {shown} joints, base link {report.base_link}", columns, cells,
               show_all)
    _loaded_with(report)


@app.command(epilog=_examples(
    "urdfkit links r2d2.urdf", "urdfkit links car.urdf --inertia-from-file",
    "urdfkit links car.urdf --json"))
def links(
    file: FileArg,
    as_json: JsonOpt = False,
    show_all: AllOpt = False,
    inertia_from_file: Annotated[bool, typer.Option(
        "--inertia-from-file",
        help="Load with URDF_USE_INERTIA_FROM_FILE. Without it PyBullet ignores <inertia> "
             "and recomputes it from the collision shapes.")] = False,
    fixed_base: FixedBaseOpt = False,
    flags: FlagsOpt = None,
    package: PackageOpt = None,
    package_path: PackagePathOpt = None,
    arg: ArgOpt = None,
    no_guard: NoGuardOpt = False,
) -> None:
    """Each link's getDynamicsInfo (mass, friction, inertia) beside what the file says.

    A '!' marks engine values that differ from the file's: by default PyBullet recomputes
    inertia from the collision shapes, and a link without <inertial> gets 1 kg.
    """
    report = _inspect(file, package, arg, fixed_base=fixed_base,
                      inertia_from_file=inertia_from_file, links=True, no_guard=no_guard,
                      package_path=package_path, flags=flags)
    inertia_from_file = "URDF_USE_INERTIA_FROM_FILE" in report.load_flags
    if as_json:
        show.print_json({**report.header(), "inertia_from_file": inertia_from_file,
                         "links": [link.to_dict() for link in report.links],
                         "diagnostics": report.diagnostics})
        return
    show.diagnostics(report.diagnostics)
    num, nums = show.num, show.nums
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
            str(link.link_index), link.link_name, num(link.mass) + mass_mark,
            num(f.mass) if f else "none", nums(link.local_inertia_diagonal) + inertia_mark,
            nums(f.principal) if f else "none", num(link.lateral_friction),
            num(link.rolling_friction), num(link.spinning_friction), num(link.restitution),
            num(link.contact_stiffness), num(link.contact_damping),
            nums(link.local_inertial_pos), nums(link.local_inertial_orn)])
    inertia = "from the file" if inertia_from_file else "recomputed by PyBullet"
    show.table(f"{report.robot}: {len(report.links)} links, inertia {inertia}", columns, cells,
               show_all)
    _loaded_with(report)
    if differs and not inertia_from_file:
        show.note("! = PyBullet's value differs from the file's; --inertia-from-file keeps the "
                  "file's <inertia>", stderr=False)


@app.command(epilog=_examples(
    "urdfkit tree r2d2.urdf", "urdfkit tree car.urdf --json",
    "urdfkit tree robot.urdf -o robot.svg"))
def tree(
    file: FileArg,
    as_json: JsonOpt = False,
    package: PackageOpt = None,
    package_path: PackagePathOpt = None,
    arg: ArgOpt = None,
    dot: Annotated[bool, typer.Option(
        "--dot", help="Print the graph as Graphviz DOT (links boxes, joints edges).")] = False,
    output: Annotated[str | None, typer.Option(
        "--output", "-o", help="Write the graph: .dot/.gv as DOT text, .svg/.png/.pdf drawn "
        "by Graphviz `dot` (implies --dot).")] = None,
    force: ForceOpt = False,
    no_guard: NoGuardOpt = False,
) -> None:
    r"""The kinematic tree: links, and the joints between them with type, axis and index.

    Read from the file alone; PyBullet is not loaded. \[n] is the index PyBullet will give
    the joint. --json is flat: every joint with its parent and child link, in index order.
    """
    from .tree import kinematic_tree

    if dot or output is not None:
        _tree_dot(file, package, arg, output, force, as_json, no_guard, package_path)
        return
    with _open(file, package, arg, no_guard, package_path, meshes=False) as resolved:
        root = kinematic_tree(resolved.root)
        robot = resolved.robot_name
    if as_json:
        show.print_json({"file": file, "robot": robot, **root.to_flat_dict()})
        return
    show.tree(root, robot)


@app.command(epilog=_examples(
    "urdfkit info r2d2.urdf", "urdfkit info car.urdf --fixed-base",
    "urdfkit info racecar/racecar.urdf --json"))
def info(
    file: FileArg,
    as_json: JsonOpt = False,
    fixed_base: FixedBaseOpt = False,
    flags: FlagsOpt = None,
    package: PackageOpt = None,
    package_path: PackagePathOpt = None,
    arg: ArgOpt = None,
    no_guard: NoGuardOpt = False,
) -> None:
    """The robot at a glance: links, joints by type, DOF, total mass, bounding box."""
    report = _inspect(file, package, arg, fixed_base=fixed_base, info=True, no_guard=no_guard,
                      package_path=package_path, flags=flags)
    s = report.summary
    if as_json:
        show.print_json({**report.header(), **s.to_dict(), "diagnostics": report.diagnostics})
        return
    show.diagnostics(report.diagnostics)
    num, nums = show.num, show.nums
    types = ", ".join(f"{n} {t}" for t, n in s.joint_types.items()) or "none"
    mass = f"{num(s.total_mass)} kg"
    if abs(s.total_mass - s.file_mass) > 1e-9 * max(1.0, s.file_mass):
        mass += f" (file says {num(s.file_mass)} kg"
        if s.links_without_inertial:
            mass += f"; {len(s.links_without_inertial)} link(s) without <inertial> get 1 kg"
        mass += ")"
    show.fields([(s.robot, "bold")], [
        ("file", str(report.path)), ("base link", s.base_link),
        ("links", str(s.links)), ("joints", f"{s.joints} ({types})"),
        ("degrees of freedom", f"{s.dof}" + ("" if s.fixed_base else " + 6 (floating base)")),
        ("total mass", mass),
        ("bounding box", f"{nums(s.aabb_min)} .. {nums(s.aabb_max)}"),
        ("size", f"{nums(s.size)} m"),
        ("loaded with", " | ".join(report.load_flags) or "no flags (--flags)"),
    ])


# ---- check: validation rules over files and folders (urdfkit/check.py, urdfkit/validate.py)


@app.command(epilog=_examples(
    "urdfkit check robot.urdf", "urdfkit check description/ --fail-on warning",
    "urdfkit check . --json --ignore U9", "urdfkit check . --format sarif > urdfkit.sarif"))
def check(
    paths: Annotated[list[str], typer.Argument(
        metavar="FILE_OR_DIR...", help="URDF/xacro files, or folders searched recursively.")],
    as_json: JsonOpt = False,
    output_format: Annotated[str | None, typer.Option(
        "--format", metavar="text|json|sarif|junit|github",
        help="Output: text, JSON (= --json), SARIF 2.1.0 (GitHub code scanning), JUnit XML, "
        "or GitHub Actions annotations.", show_default="text")] = None,
    fail_on: Annotated[str, typer.Option(
        "--fail-on", metavar="error|warning|info",
        help="Exit 1 when a finding is at or above this level.")] = "error",
    package: PackageOpt = None,
    package_path: PackagePathOpt = None,
    select: Annotated[list[str] | None, typer.Option(
        "--select", metavar="CODES",
        help="Only these codes or prefixes, comma-separated (e.g. U2,U601).")] = None,
    ignore: Annotated[list[str] | None, typer.Option(
        "--ignore", metavar="CODES", help="Drop these codes or prefixes, comma-separated.")]
    = None,
    jobs: Annotated[int | None, typer.Option(
        "--jobs", "-j", min=1, help="Worker processes.", show_default="every core")] = None,
    arg: Annotated[list[str] | None, typer.Option(
        "--arg", "-a", metavar="NAME:=VALUE",
        help="xacro argument for every xacro file checked (repeatable; files that do not "
        "declare it ignore it).")] = None,
    no_exec: Annotated[bool, typer.Option(
        "--no-exec", help="Treat xacro as untrusted: do not expand it (xacro runs Python); "
        "each xacro file gets a U006 warning instead. URDFKIT_NO_EXEC=1 does the same.")]
    = False,
    show_all: Annotated[bool, typer.Option(
        "--all", help="Text: list every finding (by default a code seen more than 4 times in "
        "a file shows 3 and a count).")] = False,
    physics: Annotated[bool, typer.Option(
        "--physics", help="Also load each file without errors in PyBullet and test its zero "
        "pose for links in contact (U950; slower).")] = False,
    no_cache: Annotated[bool, typer.Option(
        "--no-cache", help="Check every file afresh: do not read or write the result cache "
        "(a file's findings, reused while neither it nor anything it read changed). "
        "URDFKIT_CACHE_DIR= also turns it off.")] = False,
) -> None:
    """Check URDF files for errors PyBullet crashes on, physics mistakes and typos.

    Exit 0: nothing at or above --fail-on; 1: findings at or above it; 2: unusable
    invocation; 3: a bug in urdfkit. See docs/check.md for every rule code.
    """
    from .check import check_paths, parse_codes
    from .errors import ParameterError
    from .uris import parse_packages

    if fail_on not in ("error", "warning", "info"):
        from .suggest import hint

        raise ParameterError(f"`fail_on` expects error, warning or info, got {fail_on!r}"
                             f"{hint(fail_on, ('error', 'warning', 'info'))}", param="fail_on")
    fmt = _check_format(output_format, as_json)
    result = check_paths(paths, packages=parse_packages(package, package_path),
                         select=parse_codes(select, "`select`"),
                         ignore=parse_codes(ignore, "`ignore`"), jobs=jobs, no_exec=no_exec,
                         xacro_args=_xacro_args(arg), physics=physics, cache=not no_cache)
    import dataclasses

    for fr in result.files:  # a xacro or package problem speaks of flags, not parameters
        fr.findings = [dataclasses.replace(f, message=input_flags(f.message))
                       for f in fr.findings]
    show.check_output(result, fmt, fail_on, show_all)
    raise typer.Exit(result.exit_code(fail_on))


def _check_format(output_format: str | None, as_json: bool) -> str:
    from .ci import FORMATS
    from .errors import ParameterError

    if output_format is not None and output_format not in FORMATS:
        from .suggest import hint

        raise ParameterError(f"`format` expects {', '.join(FORMATS)}, got {output_format!r}"
                             f"{hint(output_format, FORMATS)}", param="format")
    if as_json and output_format not in (None, "json"):
        raise ParameterError(f"`json` means `format` json; it cannot be combined with "
                             f"`format` {output_format}", param="format")
    return "json" if as_json else output_format or "text"


def _xacro_args(items: list[str] | None) -> dict[str, str]:
    if not items:
        return {}
    from .catalog import parse_assignments  # imports the builder: only when needed

    return parse_assignments(items, "xacro_args")


# ---- diff: two robots compared in meaning (urdfkit/diff.py)


@app.command(epilog=_examples(
    "urdfkit diff arm.urdf arm_v2.urdf",
    "urdfkit diff old/robot.urdf.xacro robot.urdf.xacro --arg prefix:=left_",
    "urdfkit diff a.urdf b.urdf --json | jq '.index_shifts[]'"))
def diff(
    old: Annotated[str, typer.Argument(
        metavar="OLD", help="The first (old) robot: a .urdf or .xacro file.")],
    new: Annotated[str, typer.Argument(metavar="NEW", help="The second (new) robot.")],
    as_json: JsonOpt = False,
    tolerance: Annotated[float, typer.Option(
        "--tolerance", metavar="TOL",
        help="Floats this close are equal, absolutely or relatively.")] = 1e-9,
    package: PackageOpt = None,
    package_path: PackagePathOpt = None,
    arg: ArgOpt = None,
    no_guard: NoGuardOpt = False,
) -> None:
    """Compare two robots in meaning: what was added, removed, renamed or changed.

    Links and joints (matched by name, then by structure), each changed field with its old
    and new value, PyBullet joint indices that shift, total mass and DOF. Whitespace,
    attribute order, comments and float spelling are not differences. Read from the files
    alone; PyBullet is not loaded. Exit 0 when the robots are the same, 1 when they differ.
    --package, --package-path and --arg apply to both files; see docs/diff.md.
    """
    from .diff import diff_files

    result = diff_files(old, new, tolerance=tolerance, packages=package, xacro_args=arg,
                        guard=not no_guard, package_paths=package_path)
    for w in result.warnings:
        show.warn(w)
    if as_json:
        show.print_json(result.to_dict())
    else:
        show.diff_report(result)
    if not result.same:
        raise typer.Exit(1)


@app.command(epilog=_examples(
    "urdfkit fix robot.urdf -o robot_fixed.urdf", "urdfkit fix robot.urdf --diff",
    "urdfkit fix robot.urdf --in-place --balance", "urdfkit fix robot.urdf -o - > out.urdf"))
def fix(
    file: Annotated[str, typer.Argument(metavar="FILE", help="The URDF to repair.")],
    output: Annotated[str | None, typer.Option(
        "--output", "-o", help="Where to write the repaired URDF ('-' for stdout).")] = None,
    in_place: Annotated[bool, typer.Option(
        "--in-place", "-i", help="Rewrite FILE itself, keeping the original as FILE.orig.")]
    = False,
    show_diff: Annotated[bool, typer.Option(
        "--diff", help="Print a unified diff of the repairs; write nothing.")] = False,
    balance: Annotated[bool, typer.Option(
        "--balance", help="Keep the file's inertia where possible: balance triangle-inequality "
        "violations (MuJoCo's balanceinertia) instead of deriving from the shapes.")] = False,
    density: Annotated[float | None, typer.Option(
        "--density", metavar="KG/M3",
        help="Give links with no mass (no <inertial>, or mass <= 0) the mass of their "
        "collision shapes at this density (1000: water). Without it fix invents no mass.")]
    = None,
    allow_mass_change: Annotated[bool, typer.Option(
        "--allow-mass-change", help="Write the file even if the robot's total mass changes by "
        "more than 1% (--density gives massless links a mass).")] = False,
    select: Annotated[list[str] | None, typer.Option(
        "--select", metavar="CODES", help="Only these codes or prefixes (e.g. U6,U708).")]
    = None,
    as_json: JsonOpt = False,
    force: ForceOpt = False,
    package: PackageOpt = None,
    package_path: PackagePathOpt = None,
) -> None:
    """Repair inertia, massless links, undefined materials and package:/// paths.

    Only what it fixes changes: comments, order and formatting elsewhere stay byte for byte,
    and joints are never touched. Each fix is listed with its rule code (docs/fix.md). Exit 0:
    nothing left to fix; 1: findings were left (listed), or --diff shows changes; 2: bad
    input or usage.
    """
    from .check import parse_codes
    from .errors import ParameterError
    from .fix import FIXABLE, fix_file
    from .output import atomic_write, check_output
    from .uris import parse_packages

    if sum((output is not None, in_place, show_diff)) != 1:
        raise ParameterError("say where the repaired file goes: -o OUT, --in-place, or --diff "
                             "to preview (one of them)")
    if as_json and (show_diff or output == "-"):
        raise ParameterError("--json describes the fixes of -o FILE or --in-place; --diff and "
                             "-o - print text on stdout")
    if output is not None and not output.strip():
        raise ParameterError("-o needs a file name (or - for stdout)")
    codes = parse_codes(select, "`select`")
    if any(not any(f.startswith(c) for f in FIXABLE) for c in codes):
        raise ParameterError(f"`select`: fix repairs {', '.join(FIXABLE)} only")
    backup = f"{file}.orig"
    if output not in (None, "-"):
        check_output(output, force=force)
    result = fix_file(file, balance=balance, density=density,
                      packages=parse_packages(package, package_path), select=codes)
    # The file's mass, and the mass PyBullet loads (1 kg for each link without <inertial>):
    # both said whenever they change. The file's changing by more than 1% writes nothing
    # unless asked; PyBullet's alone changing is frames losing the kilogram PyBullet makes up
    # for them (the file's own masses untouched): said, not refused (16 of 24 real robots
    # would otherwise need the flag for fix to do anything).
    for what, before, after, guarded in (
            ("total mass", result.mass_before, result.mass_after, True),
            ("mass as PyBullet loads it", result.loaded_before, result.loaded_after, False)):
        if after == before:
            continue
        change = (f"{(after - before) / before:+.1%}" if before > 0 else "from none")
        line = f"{file}: {what} {before:.6g} kg -> {after:.6g} kg ({change})"
        if not guarded:
            line += " (links without <inertial> no longer get PyBullet's 1 kg)"
        moved = before <= 0 or abs(after - before) > 0.01 * before
        if guarded and moved and not allow_mass_change and not show_diff:
            raise ParameterError(f"{line}: more than 1%, so nothing was written; pass "
                                 "--allow-mass-change to write it")
        if not as_json:
            show.note(line)
    if in_place and result.changed:
        check_output(backup, force=force, what="the backup")
    to_stdout = output == "-" or show_diff

    def report() -> None:  # after the write: nothing is said "fixed" that was not written
        if as_json and not to_stdout:
            show.print_json(result.to_dict())
        else:
            show.fix_report(result, stderr=to_stdout)

    if show_diff:
        report()
        sys.stdout.write(result.diff())
        raise typer.Exit(1 if result.changed or result.left or result.other_errors else 0)
    if output == "-":
        report()
        sys.stdout.buffer.write(result.fixed)
        sys.stdout.flush()
    elif in_place:
        if result.changed:
            atomic_write(backup, result.original, force=force, like=file)
            atomic_write(file, result.fixed, force=True)
        report()
        if result.changed and not as_json:
            show.wrote(Path(file), f"original kept as {backup}")
    else:
        assert output is not None
        if result.relative_paths and \
                Path(output).absolute().parent.resolve() != Path(file).absolute().parent.resolve():
            show.warn(f"{output}: {len(result.relative_paths)} mesh or texture path(s) in it are "
                      f"relative to {file}'s folder ({result.relative_paths[0]!r}, ...) and "
                      "do not resolve from where it is written: write it beside the original "
                      "(or --in-place), or copy what it names")
        path = atomic_write(output, result.fixed, force=force)
        report()
        if not as_json:
            show.wrote(path, f"{len(result.repairs)} fix(es)")
    if result.left or result.other_errors:
        raise typer.Exit(1)


# ---- drive: a headless throttle/steer run (urdfkit/drive.py, vehicle.py, plot.py)


def _split_joints(items: list[str] | None) -> list[str] | None:
    if items is None:
        return None
    return [j.strip() for item in items for j in item.split(",") if j.strip()]


# Options of `drive` that `sweep drive` takes too.
ThrottleOpt = Annotated[float, typer.Option(
    help="Wheel speed, rad/s: of a wheel on the car's centre line (each wheel turns as "
    "its path needs); with --drivetrain locked, of every wheel. Negative reverses.")]
SteerOpt = Annotated[float, typer.Option(
    help="Steering angle, rad, of the kinematic bicycle model (hinges get Ackermann "
    "angles); positive turns left. Without hinges (skid steer): the yaw rate, rad/s.")]
DrivetrainOpt = Annotated[str, typer.Option(
    "--drivetrain", metavar="differential|rear|locked",
    help="differential: every wheel at the speed its path needs; rear: rear wheels so, "
    "fronts roll free; locked: every wheel at --throttle, as the tutorial.")]
SecondsOpt = Annotated[float | None, typer.Option(
    help="Simulated duration in seconds.", show_default="10")]
StepsOpt = Annotated[int | None, typer.Option(help="Number of physics steps instead.")]
TimeStepOpt = Annotated[float, typer.Option(help="Physics time step, s.", show_default="1/240")]
MaxForceOpt = Annotated[float | None, typer.Option(
    help="Wheel motor torque limit, N m.", show_default="10")]
UrdfOpt = Annotated[str | None, typer.Option(
    help="Car to drive (.urdf/.xacro; pybullet_data names work).",
    show_default="the built-in simplecar")]
PlaneOpt = Annotated[str | None, typer.Option(
    help="Ground to drive on.", show_default="the built-in simpleplane")]
UpOpt = Annotated[str, typer.Option(
    "--up", metavar="z|y|x", help="The car's up axis: y stands up a Y-up model.")]
# drive --view and sim --view: the run streamed to a browser page (urdfkit/view.py).
ViewOpt = Annotated[bool, typer.Option(
    "--view", help="Stream the run to a browser page (urdfkit view) while it simulates "
    "headless; the page stays up after the run until Ctrl-C.")]
SpeedOpt = Annotated[str, typer.Option(
    "--speed", metavar="FACTOR|max", help="With --view: simulated seconds per wall second "
    "(max: no pacing).")]
RunPortOpt = Annotated[int | None, typer.Option(
    "--port", min=1, max=65535, help="With --view: the port to serve on.",
    show_default="a free one")]


@app.command(epilog=_examples(
    "urdfkit drive --throttle 10 --steer 0.2",
    "urdfkit drive --urdf racecar/racecar.urdf --seconds 5 --json",
    "urdfkit drive --urdf husky/husky.urdf --steer 0.5   # skid steer: 0.5 rad/s of yaw",
    "urdfkit drive --steer 0.3 --trajectory run.csv --plot run.png"))
def drive(
    throttle: ThrottleOpt = 10.0,
    steer: SteerOpt = 0.0,
    drivetrain: DrivetrainOpt = "differential",
    tutorial: Annotated[bool, typer.Option(
        "--tutorial", help="Reproduce the PyBullet tutorial's loop exactly: locked wheels, "
        "PyBullet's default motor force, no load flags, car at 0 0 0.1 before the plane.")]
    = False,
    seconds: SecondsOpt = None,
    steps: StepsOpt = None,
    time_step: TimeStepOpt = 1.0 / 240.0,
    max_force: MaxForceOpt = None,
    urdf: UrdfOpt = None,
    plane: PlaneOpt = None,
    set_: SetOpt = None,
    arg: ArgOpt = None,
    package: PackageOpt = None,
    package_path: PackagePathOpt = None,
    wheels: Annotated[list[str] | None, typer.Option(
        metavar="JOINTS", help="Wheel joints (names or indices, comma-separated) instead of "
        "the detected ones.")] = None,
    hinges: Annotated[list[str] | None, typer.Option(
        metavar="JOINTS", help="Steering hinge joints instead of the detected ones.")] = None,
    trajectory: Annotated[str | None, typer.Option(
        metavar="FILE", help="Write samples to FILE.csv or FILE.jsonl.")] = None,
    sample_every: Annotated[int | None, typer.Option(
        help="Steps between samples.", show_default="20 samples per simulated second")]
    = None,
    plot: Annotated[str | None, typer.Option(
        metavar="FILE.png", help="Draw the path and speed (needs urdfkit\\[plot]).")] = None,
    force: ForceOpt = False,
    gui: Annotated[bool, typer.Option(
        "--gui", help="Open the PyBullet GUI with Steering and Throttle sliders.")] = False,
    as_json: JsonOpt = False,
    no_guard: NoGuardOpt = False,
    up: UpOpt = "z",
    limp: Annotated[bool, typer.Option(
        "--limp", help="Let joints that are neither wheels, hinges nor casters go limp "
        "instead of holding their start angle (with the URDF's effort).")] = False,
    view: ViewOpt = False,
    speed: SpeedOpt = "1",
    port: RunPortOpt = None,
) -> None:
    """Drive a car headless at a fixed throttle and steer, and report where it went.

    Wheels (continuous joints about a horizontal axis) and steering hinges (revolute joints
    about a vertical axis that carry wheels) are detected. See docs/drive.md.
    """
    from .drive import DriveConfig, Scenario, trajectory_format
    from .errors import ParameterError

    if seconds is not None and steps is not None:
        raise ParameterError("give `seconds` or `steps`, not both", param="seconds")
    if tutorial and (drivetrain != "differential" or max_force is not None):
        raise ParameterError("`tutorial` fixes the drivetrain (locked) and the motor force "
                             "(PyBullet's default); drop --drivetrain and --max-force",
                             param="tutorial")
    from .session import has_display

    if view and gui:
        raise ParameterError("`view` replaces `gui`: give one of them", param="view")
    pace = _speed(speed) if view else None
    if gui and not has_display():
        raise ParameterError("`gui` needs a display (DISPLAY is not set); drop it to drive "
                             "headless, or use --view", param="gui")
    # Check the outputs before a long run, not after it.
    if trajectory is not None:
        from .output import check_output

        trajectory_format(trajectory)
        check_output(trajectory, force=force)
    if plot is not None:
        from .plot import check_plot_path

        check_plot_path(plot, force=force)
    params = None
    if set_:
        from .catalog import parse_assignments  # imports the builder: only when needed

        params = parse_assignments(set_, "template_params")
    config = DriveConfig(
        urdf=urdf, plane=plane, template_params=params,
        packages=package, xacro_args=arg, seconds=10.0 if seconds is None else seconds,
        steps=steps, time_step=time_step, throttle=throttle, steer=steer,
        max_force=10.0 if max_force is None else max_force, drivetrain=drivetrain,
        tutorial=tutorial, keep_trajectory=plot is not None,
        wheels=_split_joints(wheels), hinges=_split_joints(hinges), sample_every=sample_every,
        gui=gui, guard=not no_guard, package_paths=package_path, up=up, limp=limp)
    with Scenario(config) as sc:
        t = sc.drivetrain

        def names(joints: list[int]) -> str:
            return ", ".join(t.joint_names[j] for j in joints) or "none"

        casters = [t.joint_names[j] for j in t.casters] + \
            [t.link_names.get(k, str(k)) for k in t.caster_links]
        show.note(f"{sc.model}: wheels {names(t.wheels)}; hinges {names(t.hinges)}; "
                  f"casters {', '.join(casters) or 'none'}; held {names(list(sc.held))}; "
                  f"limp {names(sc.limp)}; drivetrain {t.mode} ({t.steering} steering)")
        for w in sc.warnings:
            show.warn(w)
        said = list(sc.warnings)
        stream = _run_view(sc, config, pace, port) if view else None
        progress, stop = show.progress("driving", "steps", enabled=not as_json and not view)
        written = []
        try:
            if trajectory is None:
                result = sc.run(progress, sink=stream)
            else:
                from .drive import drive_to_file

                result, path = drive_to_file(sc, trajectory, force=force, progress=progress,
                                             sink=stream)
                written.append(path)
            if stream is not None:
                stream.finish(_run_view_summary(result))
        except BaseException:
            if stream is not None:
                stream.viewer.close()
            raise
        finally:
            stop()
    if plot is not None:
        from .plot import write_plot

        written.append(write_plot(result, plot, force=force))
    if as_json:
        data = result.to_dict()
        data["files"] = [str(w) for w in written]
        show.print_json(data)
    else:
        _drive_summary(result, said)
        for path in written:
            show.wrote(path)
    if result.interrupted:
        if stream is not None:
            stream.viewer.close()
        show.interrupted("interrupted; the results cover the steps simulated")
        raise typer.Exit(130)
    if stream is not None:
        _serve_until_interrupted(stream.viewer, "the run is over; its page")
    if result.problems:  # the run is physically suspect: a finding, for CI
        raise typer.Exit(1)


def _speed(text: str) -> float | None:
    """``--speed``: a positive factor, or None for ``max``."""
    import math

    from .errors import ParameterError

    if text.strip().lower() == "max":
        return None
    try:
        value = float(text)
    except ValueError:
        value = math.nan
    if not (math.isfinite(value) and value > 0):
        raise ParameterError(f"`speed` takes a positive factor or max, got {text!r}",
                             param="speed")
    return value


def _run_view(sc: Any, config: Any, pace: float | None, port: int | None) -> Any:
    """Start the page a run streams to (drive --view), and say where it is."""
    import math

    from .view import RunStream, Viewer

    total = config.total_steps * config.time_step
    reach = abs(config.throttle) * sc.drivetrain.reference_radius * total
    viewer = Viewer(sc.car_file, packages=config.packages, package_paths=config.package_paths,
                    xacro_args=config.xacro_args, inertia_from_file=not config.tutorial,
                    port=port, watch=False, ground=float(max(4, math.ceil(2 * reach + 2))))
    try:
        stream = RunStream(viewer, sc.link_poses, pace, total)
        stream.push()
    except BaseException:
        viewer.close()
        raise
    _say_streaming("drive", viewer, pace)
    return stream


def _say_streaming(command: str, viewer: Any, pace: float | None) -> None:
    """Where a run streams, and how fast (on stderr: stdout stays the command's own)."""
    pacing = "as fast as it goes" if pace is None else \
        ("in real time" if pace == 1 else f"at {pace:g}x real time")
    show.line(f"urdfkit {command}: {viewer.url} (the run streams there {pacing})", stderr=True)


def _run_view_summary(r: Any) -> str:
    """The run's summary, as the page shows it at the end."""
    x, y, _ = r.final_position
    radius = "none" if r.turning_radius is None else f"{r.turning_radius:.3f} m"
    text = (f"**Done**: {r.sim_time:.2f} s simulated; {r.distance:.3f} m along the path to "
            f"x {x:.3f}, y {y:.3f}; heading change {r.heading_change:.3f} rad; turning radius "
            f"{radius}")
    if r.problems:
        text += "\n\n**Problems**: " + "; ".join(r.problems)
    return text


def _serve_until_interrupted(viewer: Any, what: str, command: str = "drive") -> None:
    """Keep a page up until Ctrl-C, then close it (the command's exit code is its own)."""
    import time

    try:  # the line inside: a Ctrl-C right after it still closes the page, exit unchanged
        show.line(f"urdfkit {command}: {what} stays at {viewer.url} until Ctrl-C", stderr=True)
        while True:
            time.sleep(3600)
    except KeyboardInterrupt:
        pass
    finally:
        viewer.close()


# ---- sweep: many drives or scenario runs (urdfkit/sweep.py)


@app.command(epilog=_examples(
    "urdfkit sweep drive --vary steer=0.1,0.2,0.3 --seconds 5",
    "urdfkit sweep drive --vary wheel_radius=0.08:0.14:4 --vary steer=0.1,0.3 --out r.csv "
    "--plot turning_radius",
    "urdfkit sweep sim arm.toml --vary 'robots[0].motor.kp=50:400:8' --jobs 2 --out r.jsonl",
    "urdfkit sweep drive --vary steer=0:0.4:41 --backend ray --address auto --out r.parquet"))
def sweep(
    kind: Annotated[str, typer.Argument(
        metavar="drive|sim", help="What each point runs: a drive, or a scenario.")],
    scenario: Annotated[str | None, typer.Argument(
        metavar="[SCENARIO]", help="With sim: the scenario file (.json or .toml).",
        show_default=False)] = None,
    vary: Annotated[list[str] | None, typer.Option(
        "--vary", "-v", metavar="NAME=VALUES",
        help="A drive option, simplecar parameter or scenario key path, and its values: "
        "a,b,c or start:stop:count (repeatable: a grid).")] = None,
    zip_: Annotated[bool, typer.Option(
        "--zip", help="Pair the --vary lists point by point instead of a grid.")] = False,
    jobs: Annotated[int | None, typer.Option(
        "--jobs", "-j", min=1, help="Worker processes (1: in this process).",
        show_default="every core")] = None,
    backend: Annotated[str, typer.Option(
        "--backend", metavar="local|ray", help="local: a process pool; ray: Ray tasks "
        "(pip install 'urdfkit\\[ray]').")] = "local",
    address: Annotated[str | None, typer.Option(
        "--address", metavar="auto|ray://HOST:PORT",
        help="With --backend ray: the cluster to run on.", show_default="a local Ray")]
    = None,
    out: Annotated[str | None, typer.Option(
        "--out", "-o", metavar="FILE", help="Write the rows to FILE.csv, .jsonl or .parquet, "
        "as points finish (FILE.partial until the sweep ends).")] = None,
    resume: Annotated[bool, typer.Option(
        "--resume", help="Skip the points already in --out (or its .partial) without an "
        "error.")] = False,
    plot: Annotated[str | None, typer.Option(
        "--plot", metavar="METRIC", help="Draw METRIC against the varied value(s) (needs "
        "urdfkit\\[plot]).")] = None,
    plot_file: Annotated[str | None, typer.Option(
        "--plot-file", metavar="FILE.png", help="Where --plot draws.",
        show_default="sweep-METRIC.png")] = None,
    as_json: JsonOpt = False,
    show_all: AllOpt = False,
    force: ForceOpt = False,
    throttle: ThrottleOpt = 10.0,
    steer: SteerOpt = 0.0,
    drivetrain: DrivetrainOpt = "differential",
    seconds: SecondsOpt = None,
    steps: StepsOpt = None,
    time_step: TimeStepOpt = 1.0 / 240.0,
    max_force: MaxForceOpt = None,
    urdf: UrdfOpt = None,
    plane: PlaneOpt = None,
    set_: SetOpt = None,
    arg: ArgOpt = None,
    package: PackageOpt = None,
    package_path: PackagePathOpt = None,
    up: UpOpt = "z",
) -> None:
    """Run many drives or scenario runs, one row of results per point.

    Several --vary form a grid; --zip pairs them. The drive options (--throttle, --seconds,
    ...) hold for every point of a drive sweep. Every value is checked before any point runs;
    rows are written as points finish. Exit 0: every point ran; 1: some failed (their rows say
    why); 2: bad input; 130: interrupted (the rows so far are kept). See docs/sweep.md.
    """
    from . import sweep as sweeping
    from .errors import ParameterError

    if kind == "sim":
        if scenario is None:
            raise ParameterError("sweep sim needs the scenario file: urdfkit sweep sim "
                                 "scenario.toml --vary PATH=VALUES", param="kind")
        changed = [name for name, value, default in (
            ("--throttle", throttle, 10.0), ("--steer", steer, 0.0),
            ("--drivetrain", drivetrain, "differential"), ("--seconds", seconds, None),
            ("--steps", steps, None), ("--time-step", time_step, 1.0 / 240.0),
            ("--max-force", max_force, None), ("--urdf", urdf, None), ("--plane", plane, None),
            ("--set", set_, None), ("--arg", arg, None), ("--package", package, None),
            ("--package-path", package_path, None), ("--up", up, "z")) if value != default]
        if changed:
            raise ParameterError(f"{', '.join(changed)}: drive options; a sim sweep varies the "
                                 "scenario's keys (--vary 'physics.time_step=...')")
        base: Any = scenario
    elif kind == "drive":
        if scenario is not None:
            raise ParameterError(f"sweep drive takes no scenario file (got {scenario!r}); "
                                 "drive options are flags", param="kind")
        if seconds is not None and steps is not None:
            raise ParameterError("give `seconds` or `steps`, not both", param="seconds")
        params = None
        if set_:
            from .catalog import parse_assignments

            params = parse_assignments(set_, "template_params")
        base = {"throttle": throttle, "steer": steer, "drivetrain": drivetrain,
                "seconds": 10.0 if seconds is None else seconds, "steps": steps,
                "time_step": time_step, "max_force": 10.0 if max_force is None else max_force,
                "urdf": urdf, "plane": plane, "template_params": params, "xacro_args": arg,
                "packages": package, "package_paths": package_path, "up": up}
    else:
        raise ParameterError(f"`kind` must be drive or sim, got {kind!r}", param="kind")
    if not vary:
        raise ParameterError("give at least one --vary NAME=VALUES", param="vary")
    if plot_file is not None and plot is None:
        raise ParameterError("--plot-file says where --plot draws: give --plot METRIC too")
    if kind == "drive":
        given = {"throttle": throttle != 10.0, "steer": steer != 0.0,
                 "drivetrain": drivetrain != "differential", "seconds": seconds is not None,
                 "steps": steps is not None, "time_step": time_step != 1.0 / 240.0,
                 "max_force": max_force is not None, "urdf": urdf is not None,
                 "plane": plane is not None, "up": up != "z"}
        set_names = {item.replace(":=", "=").partition("=")[0].strip() for item in set_ or []}
        for item in vary:
            name = item.partition("=")[0].strip()
            if given.get(name) or name in set_names:
                how = "--set" if name in set_names else "--" + name.replace("_", "-")
                raise ParameterError(f"{name} is given both by {how} and by --vary; a varied "
                                     "value replaces the fixed one in every point: drop one")
    if resume and out is None:
        raise ParameterError("--resume carries on the rows of --out: give --out",
                             param="resume")
    plan = sweeping.plan(kind, base, vary, zip_=zip_)  # every point checked before any runs
    picture = None
    if plot is not None:
        from .plot import check_plot_path

        picture = plot_file or f"sweep-{plot}.png"
        check_plot_path(picture, force=force)
        if kind == "drive":  # known columns: refuse a typo before the run
            sweeping.check_metric(kind, [], plan.names, plot)
        else:
            sweeping.check_sim_metric(plan, plot)
    journal = None
    if out is not None:
        journal = sweeping.Journal(Path(out), plan.names, resume=resume, force=force,
                                   assignments=plan.assignments)
        journal.open()
        for note in journal.notes:
            show.warn(note)
    noted = len(journal.notes) if journal is not None else 0
    keep = out is None or plot is not None or as_json
    rows: list[dict[str, Any]] = list(journal.done) if journal is not None and keep else []
    skip = journal.finished if journal is not None and resume else None
    total = len(plan.assignments)
    before = total - sum(1 for a in plan.assignments if skip is not None and skip(a))
    progress, stop = show.progress("sweeping", "points", enabled=not as_json, rate=True)
    failed = done = 0
    interrupted = False
    try:
        for row in sweeping.execute(plan, jobs=jobs, backend=backend, address=address,
                                    skip=skip):
            done += 1
            failed += bool(row.get("error"))
            if journal is not None:
                journal.add(row)
            if keep:
                rows.append(row)
            if progress is not None:
                progress(done, before)
    except KeyboardInterrupt:
        interrupted = True
    finally:
        stop()
        written = journal.finish() if journal is not None else None
    for note in journal.notes[noted:] if journal is not None else []:
        show.warn(note)
    written_plot: Path | None = None
    failed_plot = False
    if picture is not None and rows:
        from .errors import UrdfkitError
        from .plot import write_sweep_plot

        assert plot is not None
        try:  # a scenario's joint names are known only now: the rows are kept either way
            sweeping.check_metric(kind, rows, plan.names, plot)
        except UrdfkitError as e:
            show.warn(f"no plot: {input_flags(flag_message(e.message))}")
            failed_plot = True
        else:
            written_plot = write_sweep_plot(rows, plan.names, plot, picture, force=force)
    skipped = total - before
    if as_json:
        show.print_json({"kind": kind, "points": total, "ran": done, "skipped": skipped,
                         "failed": failed, "out": None if written is None else str(written),
                         "plot": None if written_plot is None else str(written_plot),
                         "interrupted": interrupted, "rows": rows})
    else:
        show.sweep_report(plan, rows if out is None else [], done, failed, skipped, show_all)
        for path in (written, written_plot):
            if path is not None:
                show.wrote(path)
    if interrupted:
        show.interrupted("interrupted; the rows so far are kept")
        raise typer.Exit(130)
    if failed or failed_plot:
        raise typer.Exit(1)


def _drive_summary(r: Any, said: list[str]) -> None:
    x, y, z = r.final_position
    model = {"ackermann": "kinematic bicycle model", "differential": "v / omega"}.get(
        r.drivetrain.steering, "model")
    bicycle = ("" if r.expected_radius is None
               else f" ({model}: {r.expected_radius:.3f} m)")
    turn = (f"none: {r.radius_note}{bicycle}" if r.turning_radius is None else
            f"{r.turning_radius:.3f} m around ({r.turn_center[0]:.2f}, {r.turn_center[1]:.2f})"
            f"{bicycle}")
    sim = r.simulated
    force = (f"PyBullet's default ({sim['wheel_force']:g} N m)" if sim["wheel_force_default"]
             else f"{sim['wheel_force']:g} N m")
    flags = ", ".join(sim["load_flags"]) or "none"
    unit = "rad/s of yaw" if r.drivetrain.yaw_steered else "rad"
    show.fields([("drive", "bold"), f" {r.model}: throttle {r.throttle:g} rad/s, "
                 f"steer {r.steer:g} {unit}"], [
        ("final position", f"x {x:.3f}  y {y:.3f}  z {z:.3f} m"),
        ("final yaw", f"{r.final_yaw:.3f} rad ({r.final_yaw * 57.29577951308232:.1f} deg)"),
        ("heading change", f"{r.heading_change:.3f} rad"),
        ("distance", f"{r.distance:.3f} m along the path"),
        ("mean speed", f"{r.mean_speed:.3f} m/s"),
        ("turning radius", turn),
        ("drivetrain", f"{sim['drivetrain']}, {sim['steering']} steering; wheel force "
                       f"{force}"),
        ("load flags", flags),
        ("simulated", f"{r.sim_time:.3f} s in {r.steps:,} steps of {r.time_step:.5g} s; link "
                      f"damping {sim['link_damping']['linear']:g} (PyBullet's default)"),
        ("wall time", f"{r.wall_time:.3f} s (real-time factor {r.real_time_factor:.1f}x)"),
    ])
    # Every warning shows in text too, not only in JSON: those found by the run itself (a
    # base turning at a fraction of its command, the problems) after the summary.
    for w in r.warnings:
        if w not in said:
            show.warn(w)


# ---- render: headless PNG pictures (urdfkit/render.py) and tree --dot (urdfkit/graph.py)


@app.command(epilog=_examples(
    "urdfkit render r2d2.urdf", "urdfkit render car.urdf --views all -o car.png",
    "urdfkit render arm.urdf --joints elbow=1.2 --frames --collision -o arm.png"))
def render(
    file: FileArg,
    output: Annotated[str | None, typer.Option(
        "--output", "-o", help="The PNG to write; '-' for stdout.",
        show_default="<name>.png here")] = None,
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
    up: Annotated[str, typer.Option(
        "--up", metavar="z|y|x", help="The model's up axis: y stands up a Y-up model (CAD "
        "and graphics exports) that would otherwise lie down.")] = "z",
    as_json: Annotated[bool, typer.Option(
        "--json", help="Print what was drawn (cameras, bounding box) as JSON.")] = False,
    force: ForceOpt = False,
    package: PackageOpt = None,
    package_path: PackagePathOpt = None,
    arg: ArgOpt = None,
    no_guard: NoGuardOpt = False,
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
        joints=rendering.parse_joint_positions(joints), collision=collision, frames=frames,
        up=up)
    out = output if output is not None else f"{Path(file).name.split('.')[0] or 'robot'}.png"
    if out != "-":  # refuse before the work, not after it
        rendering.check_output(out, force=force)
    picture = rendering.render_file(file, options, packages=package, xacro_args=arg,
                                    guard=not no_guard, package_paths=package_path)
    for w in picture.warnings:
        show.warn(w)
    if out == "-":
        sys.stdout.buffer.write(picture.png_bytes())
        sys.stdout.flush()
        return
    path = rendering.write_png(picture, out, force=force)
    if as_json:
        show.print_json({"output": str(path), **picture.to_dict()})
        return
    show.wrote(path, f"{picture.width}x{picture.height}, {', '.join(chosen)}"
               f"{', collision shapes' if collision else ''}")


@app.command(epilog=_examples(
    "urdfkit view r2d2.urdf", "urdfkit view arm.urdf.xacro --arg prefix:=left_ --open",
    "urdfkit view robot.urdf --host 0.0.0.0 --port 8080"))
def view(
    file: FileArg,
    port: Annotated[int | None, typer.Option(
        "--port", min=1, max=65535, help="The port to serve on.", show_default="a free one")]
    = None,
    host: Annotated[str, typer.Option(
        "--host", help="The address to serve on; 0.0.0.0 serves beyond this machine.")]
    = "127.0.0.1",
    open_browser: Annotated[bool, typer.Option("--open", help="Open the page in a browser.")]
    = False,
    inertia_from_file: Annotated[bool, typer.Option(
        "--inertia-from-file", help="Load the file's <inertia> (URDF_USE_INERTIA_FROM_FILE) "
        "instead of PyBullet's recomputed one.")] = False,
    package: PackageOpt = None,
    package_path: PackagePathOpt = None,
    arg: ArgOpt = None,
) -> None:
    """Show the robot in a browser as PyBullet loads it, with check's findings on its links.

    Joint sliders, visual and collision shapes, frames, centres of mass and inertia boxes;
    the page reloads when the file or its includes and meshes change.
    Serves until Ctrl-C (exit 130). See docs/view.md.
    """
    from .view import Viewer

    viewer = Viewer(file, packages=package, package_paths=package_path, xacro_args=arg,
                    inertia_from_file=inertia_from_file, host=host, port=port)
    try:
        show.line(f"urdfkit view: {viewer.url} (Ctrl-C to stop)")
        if open_browser:
            import webbrowser

            webbrowser.open(viewer.url)
        import time

        while True:
            time.sleep(3600)
    finally:
        viewer.close()


@app.command(epilog=_examples(
    "urdfkit collisions panda.urdf", "urdfkit collisions arm.urdf --samples 100 --json",
    "urdfkit collisions arm.urdf --samples 200 --srdf >> arm.srdf",
    "urdfkit collisions hand.urdf --joints finger_joint=0.04 --python"))
def collisions(
    file: FileArg,
    joints: Annotated[list[str] | None, typer.Option(
        "--joints", "-j", metavar="NAME=VALUE",
        help="The start pose, in rad or m, held in every sampled pose too (repeatable, or "
        "a=1,b=2).")] = None,
    samples: Annotated[int, typer.Option(
        "--samples", "-n", min=0, help="Random poses within the joint limits to test besides "
        "the start pose.")] = 0,
    seed: Annotated[int, typer.Option("--seed", help="Seed of the random poses.")] = 0,
    margin: Annotated[float, typer.Option(
        "--margin", metavar="M", help="Count links closer than this (m) as touching.")] = 0.0,
    as_json: JsonOpt = False,
    srdf: Annotated[bool, typer.Option(
        "--srdf", help="Print MoveIt <disable_collisions> entries for the pairs in contact "
        "in every pose.")] = False,
    python: Annotated[bool, typer.Option(
        "--python", help="Print p.setCollisionFilterPair calls for the pairs in contact in "
        "every pose.")] = False,
    show_all: AllOpt = False,
    package: PackageOpt = None,
    package_path: PackagePathOpt = None,
    arg: ArgOpt = None,
    no_guard: NoGuardOpt = False,
) -> None:
    """Link pairs whose collision shapes touch: robots that jitter under self-collision.

    Exit 0: no pair touches; 1: pairs touch (the table and --json); --srdf and --python exit
    0, they print filters. Parent-child pairs are skipped: PyBullet never tests them. See
    docs/collisions.md.
    """
    from .collisions import self_collisions
    from .errors import ParameterError
    from .render import parse_joint_positions
    from .uris import parse_packages

    if sum((as_json, srdf, python)) > 1:
        raise ParameterError("--json, --srdf and --python are exclusive: pick one")
    with _open(file, package, arg, no_guard, package_path) as resolved:
        result = self_collisions(resolved, joints=parse_joint_positions(joints),
                                 samples=samples, seed=seed, margin=margin,
                                 packages=parse_packages(package, package_path))
    if srdf or python:
        for w in result.warnings:
            show.warn(w)
        sys.stdout.write(result.srdf() if srdf else result.python())
        return
    if as_json:
        show.print_json(result.to_dict())
    else:
        show.collisions_report(result, show_all)
    raise typer.Exit(1 if result.pairs else 0)


def _tree_dot(file: str, package: list[str] | None, arg: list[str] | None,
              output: str | None, force: bool, as_json: bool, no_guard: bool,
              package_path: list[str] | None) -> None:
    """``tree --dot`` / ``tree -o graph.svg``: the kinematic graph as DOT text or a drawing."""
    from .errors import ParameterError
    from .graph import check_output, dot_graph, write_graph

    if as_json:
        raise ParameterError("--json and --dot/-o are different outputs; choose one")
    if output is not None and output != "-":
        check_output(output, force=force)
    with _open(file, package, arg, no_guard, package_path) as resolved:
        text = dot_graph(resolved.root)
    if output is None or output == "-":
        sys.stdout.write(text)
        sys.stdout.flush()
        return
    show.wrote(write_graph(text, output, force=force))


# ---- sim: scenario files (urdfkit/scenario.py) run by urdfkit/sim.py


@app.command(epilog=_examples(
    "urdfkit sim scenario.toml -o rows.csv", "urdfkit sim scenario.toml --gui",
    "urdfkit sim configs/robot.json   # a simulation_and_control config",
    "urdfkit sim convert configs/robot.json -o scenario.toml"))
def sim(
    scenario: Annotated[str, typer.Argument(
        help="A scenario file (.json or .toml): robots, controllers, physics. See "
             "docs/scenario.md. A simulation_and_control config runs as it is. Or the word "
             "convert, then a simulation_and_control config: write it as a native scenario.",
        metavar="SCENARIO")],
    config: Annotated[str | None, typer.Argument(
        help="With convert: the simulation_and_control config (.json).",
        show_default=False)] = None,
    out: Annotated[str | None, typer.Option(
        "--out", "-o", metavar="FILE",
        help="Write the observation rows to FILE.jsonl, FILE.csv or FILE.parquet (with "
             "convert: the scenario to FILE.toml; default standard output).")] = None,
    gui: Annotated[bool, typer.Option(
        "--gui", help="Watch the run in PyBullet's GUI window, in real time (needs a "
                      "display).")] = False,
    real_time: Annotated[bool, typer.Option(
        "--real-time", help="Pace the steps to the wall clock.")] = False,
    as_json: JsonOpt = False,
    force: ForceOpt = False,
    view: ViewOpt = False,
    speed: SpeedOpt = "1",
    port: RunPortOpt = None,
) -> None:
    """Simulate a scenario of one or more robots and record their observations.

    Without --out a summary per robot prints; with --json, one JSON object (holding the rows
    too when there is no --out).
    """
    from . import sim as simulation
    from .errors import ParameterError

    if scenario == "convert":
        if config is None:
            raise ParameterError("convert needs the simulation_and_control config: "
                                 "urdfkit sim convert conf.json -o scenario.toml",
                                 param="scenario")
        if gui or real_time or as_json or view:
            raise ParameterError("convert writes a file; --gui, --real-time, --view and --json "
                                 "do not apply", param="scenario")
        _sim_convert(config, out, force)
        return
    if config is not None:
        raise ParameterError(f"one scenario at a time; got {scenario!r} and {config!r} (to "
                             "convert a config: urdfkit sim convert conf.json)",
                             param="scenario")
    from .session import has_display

    if view and (gui or real_time):
        raise ParameterError("`view` paces the run itself (--speed) and replaces `gui`: drop "
                             "--gui and --real-time", param="view")
    pace = _speed(speed) if view else None
    if gui and not has_display():
        raise ParameterError("`gui` needs a display (DISPLAY is not set); drop it to run "
                             "headless, or use --view", param="gui")
    if out is not None:
        simulation.check_output(out, force=force)  # fail before the run, not after it
    written = None
    stream: Any = None
    with simulation.Simulation.from_file(scenario, gui=gui) as s:
        for note in s.config.notes:
            show.warn(note)
        if view:
            stream = _sim_view(s, pace, port)
        tick = None if stream is None else (lambda _batch: stream.tick(s.t))
        try:
            if out is None:
                result = s.run(real_time=real_time or gui, sink=tick)
            else:
                result, written = simulation.run_to_file(s, out, force=force,
                                                         real_time=real_time or gui,
                                                         also=tick)
            if stream is not None:
                stream.finish(f"**Done**: {result.steps:,} steps of {result.time_step:.5g} s "
                              f"simulated, {result.row_count:,} rows")
        except BaseException:
            if stream is not None:
                stream.viewer.close()
            raise
    if stream is not None and result.interrupted:
        stream.viewer.close()
        stream = None
    rows = result.to_dicts()
    summaries = simulation.summarize(result)
    if as_json:
        data: dict[str, Any] = {
            "scenario": scenario, "time_step": result.time_step, "steps": result.steps,
            "duration": result.steps * result.time_step, "rows": result.row_count,
            "robots": [x.to_dict() for x in summaries],
            "out": None if written is None else str(written),
            "interrupted": result.interrupted}
        if written is None:
            data["observations"] = rows
        show.print_json(data)
        if result.interrupted:
            show.interrupted("interrupted; the rows cover the steps simulated")
            raise typer.Exit(130)
        if stream is not None:
            _serve_until_interrupted(stream.viewer, "the run is over; its page", "sim")
        return
    fixed = show.fixed
    show.table(f"sim {scenario}: {result.steps:,} steps of {result.time_step:.5g} s", [
        ("robot", 0, "left"), ("rows", 0, "right"), ("end x y z (m)", 0, "left"),
        ("moved m", 1, "right"), ("top m/s", 1, "right"), ("yaw deg", 1, "right")], [
        [x.robot, str(x.rows), " ".join(fixed(v) for v in x.end), fixed(x.distance),
         fixed(x.top_speed), fixed(x.heading_deg, 1)] for x in summaries])
    for x in summaries:
        if x.final_joints:
            joints = ", ".join(f"{k} {fixed(v)}" for k, v in x.final_joints.items())
            show.line((x.robot, "cyan"), f" final joints: {joints}")
    if written is not None:
        show.wrote(written, f"{result.row_count:,} rows")
    if result.interrupted:
        show.interrupted("interrupted; the rows cover the steps simulated")
        raise typer.Exit(130)
    if stream is not None:
        _serve_until_interrupted(stream.viewer, "the run is over; its page", "sim")


def _sim_view(s: Any, pace: float | None, port: int | None) -> Any:
    """Start the page a scenario streams to (sim --view): every robot, and say where."""
    from .view import RunStream, Viewer

    bodies = [b for b in s.bodies.values() if b.loaded is not None]
    if not bodies:
        from .errors import ParameterError

        raise ParameterError("the scenario has no robot to show", param="view")
    first, options = bodies[0].loaded
    viewer = Viewer(first, inertia_from_file=options.inertia_from_file, port=port,
                    watch=False, ground=20.0)
    try:
        for b in bodies[1:]:
            viewer.add_robot(b.loaded[0], inertia_from_file=b.loaded[1].inertia_from_file)
        stream = RunStream(viewer, s.link_poses, pace, s.total_steps * s.time_step,
                           robots=True)
        stream.push()
    except BaseException:
        viewer.close()
        raise
    _say_streaming("sim", viewer, pace)
    return stream


def _sim_convert(config: str, out: str | None, force: bool) -> None:
    """``sim convert``: a simulation_and_control config as a native TOML scenario."""
    from . import sac
    from .errors import InputError
    from .output import atomic_write, check_output
    from .scenario import read_document

    if out is not None and out != "-":
        check_output(out, force=force, suffixes=(".toml",), what="the scenario")
    data = read_document(config)
    if not sac.is_config(data):
        raise InputError("not a simulation_and_control config (no sim, robot_pybullet, "
                         "env_pybullet or robot_pin section); it is already a scenario",
                         file=config)
    imported = sac.convert(data, source=config)
    from .scenario import parse_scenario

    parse_scenario(imported.scenario, source=config)  # what is written must load
    for note in imported.notes:
        show.warn(note)
    if out is None or out == "-":
        sys.stdout.write(sac.to_toml(imported, source=config, out_dir=None))
        sys.stdout.flush()
        return
    text = sac.to_toml(imported, source=config, out_dir=Path(out).parent)
    show.wrote(atomic_write(out, text.encode("utf-8"), force=force),
               f"{len(imported.scenario['robots'])} robot(s)")


def _reflow(doc: str) -> str:
    """A docstring's paragraphs each on one line: rich help keeps single line breaks."""
    return "\n\n".join(" ".join(line.strip() for line in para.splitlines())
                       for para in doc.strip().split("\n\n"))


for _info in app.registered_commands:
    if _info.help is None and _info.callback is not None and _info.callback.__doc__:
        import inspect

        _info.help = _reflow(inspect.cleandoc(_info.callback.__doc__))


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
    single = typer.Typer(name=app.info.name, cls=UrdfkitGroup, add_completion=False,
                         pretty_exceptions_enable=False, rich_markup_mode="rich",
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
    for sig in (signal.SIGTERM, signal.SIGHUP):
        signal.signal(sig, _on_signal)
    # What is loaded by now (typer, click, this module) lives until exit. Freezing it keeps the
    # cyclic GC from re-scanning it in every full collection that the imports of numpy and
    # pybullet trigger: ~8 ms of a `urdfkit joints` run. Later garbage is collected as usual.
    gc.freeze()
    argv = sys.argv[1:]
    single = _single_command_app(argv[0]) if argv and not argv[0].startswith("-") else None
    (single or app)()
