"""check, diff, fix, collisions: findings over files, two robots compared, repairs."""

import sys
from collections.abc import Callable
from pathlib import Path
from typing import Annotated, Any

import typer

from urdfkit.commands import present as show
from urdfkit.commands.shared import (
    AllOpt,
    ArgOpt,
    FileArg,
    ForceOpt,
    JsonOpt,
    NoGuardOpt,
    PackageOpt,
    PackagePathOpt,
    command,
    examples,
    open_input_and_warn,
)


@command(examples(
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
    strict: Annotated[bool, typer.Option(
        "--strict", help="Exit 2 when a folder given holds no robot file (else a warning), "
        "so a CI run cannot pass on nothing.")] = False,
    target: Annotated[list[str] | None, typer.Option(
        "--target", metavar="ros,pinocchio,drake,mujoco",
        help="Also what these consumers of the file refuse (errors) or silently change "
        "(warnings), comma-separated; none needs installing (T codes, docs/check.md). "
        "PyBullet is always a target.")] = None,
) -> None:
    """Check URDF files for errors PyBullet crashes on, physics mistakes and typos.

    Exit 0: nothing at or above --fail-on; 1: findings at or above it; 2: unusable
    invocation; 3: a bug in urdfkit. See docs/check.md for every rule code.
    """
    from urdfkit.commands.check_run import run_check

    raise typer.Exit(run_check(paths, as_json, output_format, fail_on, package, package_path,
                               select, ignore, jobs, arg, no_exec, show_all, physics, no_cache,
                               strict, target))


# ---- diff: two robots compared in meaning (urdfkit/diff.py)


@command(examples(
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
    from urdfkit.checks.diff import diff_files

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


@command(examples(
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
    gazebo_contacts: Annotated[bool, typer.Option(
        "--gazebo-contacts", help="Carry each link's <gazebo> mu1/mu2 and kp/kd (U803), which "
        "PyBullet ignores, over to its <contact>: lateral_friction (the smaller of mu1 and "
        "mu2), stiffness and damping (only as a pair).")] = False,
    as_json: JsonOpt = False,
    force: ForceOpt = False,
    package: PackageOpt = None,
    package_path: PackagePathOpt = None,
) -> None:
    """Repair inertia, massless links, undefined materials, package:/// paths; Gazebo contacts.

    Only what it fixes changes: comments, order and formatting elsewhere stay byte for byte,
    and joints are never touched. Each fix is listed with its rule code (docs/fix.md). Exit 0:
    nothing left to fix; 1: findings were left (listed), or --diff shows changes; 2: bad
    input or usage.
    """
    from urdfkit.checks.fix import fix_file
    from urdfkit.core.errors import ParameterError
    from urdfkit.core.output import check_output
    from urdfkit.sources.resolve import locate
    from urdfkit.sources.uris import parse_packages

    codes = _check_fix_options(output, in_place, show_diff, as_json, select)
    if in_place and not Path(file).expanduser().exists() and locate(file).exists():
        raise ParameterError(f"{file}: not a file here (found in pybullet_data, or a built-in "
                             "template), which --in-place would rewrite; write the repaired "
                             "copy with -o FILE")
    backup = f"{file}.orig"
    if output not in (None, "-"):
        check_output(output, force=force)
    result = fix_file(file, balance=balance, density=density,
                      packages=parse_packages(package, package_path), select=codes,
                      gazebo_contacts=gazebo_contacts,
                      output=output if output not in (None, "-") else None)
    _say_mass_changes(file, result, refuse=not allow_mass_change and not show_diff,
                      quiet=as_json)
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
    _write_fixed(file, result, output, in_place=in_place, force=force, as_json=as_json,
                 report=report)
    if result.left or result.other_errors:
        raise typer.Exit(1)


def _check_fix_options(output: str | None, in_place: bool, show_diff: bool, as_json: bool,
                       select: list[str] | None) -> tuple[str, ...]:
    """Refuse options that do not go together; the rule codes ``--select`` keeps."""
    from urdfkit.checks.check import parse_codes
    from urdfkit.checks.fix import FIXABLE
    from urdfkit.core.errors import ParameterError

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
    return codes


def _say_mass_changes(file: str, result: Any, *, refuse: bool, quiet: bool) -> None:
    """Say how the masses change; refuse (``refuse``) when the file's moves more than 1%.

    The file's mass, and the mass PyBullet loads (1 kg for each link without <inertial>):
    both said whenever they change. The file's changing by more than 1% writes nothing
    unless asked; PyBullet's alone changing is frames losing the kilogram PyBullet makes up
    for them (the file's own masses untouched): said, not refused (16 of 24 real robots
    would otherwise need the flag for fix to do anything).
    """
    from urdfkit.core.errors import ParameterError

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
        if guarded and moved and refuse:
            raise ParameterError(f"{line}: more than 1%, so nothing was written; pass "
                                 "--allow-mass-change to write it")
        if not quiet:
            show.note(line)


def _write_fixed(file: str, result: Any, output: str | None, *, in_place: bool, force: bool,
                 as_json: bool, report: Callable[[], None]) -> None:
    """Write the repaired file to stdout, in place (keeping FILE.orig) or to ``output``."""
    from urdfkit.core.output import atomic_write
    from urdfkit.sources.resolve import locate

    backup = f"{file}.orig"
    if output == "-":
        if result.relative_paths and Path.cwd().resolve() != \
                locate(file).absolute().parent.resolve():
            show.warn(f"{file}: {len(result.relative_paths)} mesh or texture path(s) are "
                      f"relative to its folder ({result.relative_paths[0]!r}, ...) and are "
                      "written as they are: save the output in that folder, or use -o FILE, "
                      "which rewrites them for where it writes")
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
        from urdfkit.checks.build import unreachable_packages

        lost = unreachable_packages(result.fixed, Path(output))
        if lost is not None:
            show.warn(lost)
        path = atomic_write(output, result.fixed, force=force)
        report()
        if not as_json:
            moved = (f"; {len(result.moved_paths)} relative mesh or texture path(s) rewritten "
                     "for its folder" if result.moved_paths else "")
            show.wrote(path, f"{len(result.repairs)} fix(es){moved}")


# ---- drive: a headless throttle/steer run (urdfkit/drive.py, vehicle.py, plot.py)


@command(examples(
    "urdfkit collisions panda.urdf", "urdfkit collisions arm.urdf --samples 100 --json",
    "urdfkit collisions arm.urdf --samples 200 --srdf > arm_collisions.srdf",
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
        "--srdf", help="Print a MoveIt SRDF document with <disable_collisions> entries for "
        "the pairs in contact in every pose.")] = False,
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
    from urdfkit.checks.collisions import self_collisions
    from urdfkit.core.errors import ParameterError
    from urdfkit.draw.render import parse_joint_positions
    from urdfkit.sources.uris import parse_packages

    if sum((as_json, srdf, python)) > 1:
        raise ParameterError("--json, --srdf and --python are exclusive: pick one")
    with open_input_and_warn(file, packages=package, xacro_args=arg, guard=not no_guard,
                             package_paths=package_path) as resolved:
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
