"""``urdfkit check``'s work, and its fast start: the command without typer.

``check`` is the command CI and pre-commit hooks run over and over, where start-up is a large
part of the time: over pybullet_data, typer and the command-building it does cost ~20 ms of a
~250 ms run. :func:`fast_main` reads the plain command lines (paths, and the options below,
written ``--opt value`` or ``--opt=value``) itself and runs :func:`run_check`, the same
function the typer command calls, with the same error handling as :func:`urdfkit.cli.run`.
Anything else (``--help``, a misspelt or repeated option, a value that starts with ``-``, a
short option run together with its value, ``--``) is left to typer, so every usage error is
still typer's.

Nothing heavy is imported here, and no typer.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

from urdfkit.commands import present as show
from urdfkit.commands.flags import input_flags
from urdfkit.commands.startup import outcome, prepare

if TYPE_CHECKING:
    from urdfkit.checks.ci import CheckFormat
    from urdfkit.core.finding import Level

#: Flags of ``check`` (no value), by option name: the keyword of :func:`run_check`.
FLAG_OPTIONS = {"--json": "as_json", "--no-exec": "no_exec", "--all": "show_all",
                "--physics": "physics", "--no-cache": "no_cache", "--strict": "strict"}
#: Options with one value each (given once), and options that may be repeated.
VALUE_OPTIONS = {"--format": "output_format", "--fail-on": "fail_on", "--jobs": "jobs",
                 "-j": "jobs"}
LIST_OPTIONS = {"--select": "select", "--ignore": "ignore", "--arg": "arg", "-a": "arg",
                "--package": "package", "-p": "package", "--package-path": "package_path",
                "--target": "target"}


def run_check(paths: list[str], as_json: bool = False, output_format: str | None = None,
              fail_on: str = "error", package: list[str] | None = None,
              package_path: list[str] | None = None, select: list[str] | None = None,
              ignore: list[str] | None = None, jobs: int | None = None,
              arg: list[str] | None = None, no_exec: bool = False, show_all: bool = False,
              physics: bool = False, no_cache: bool = False, strict: bool = False,
              target: list[str] | None = None) -> int:
    """Check ``paths`` and print the findings in ``output_format``; the exit code.

    A folder given that holds no robot file is said (a warning): a CI run over the wrong
    folder would otherwise pass on nothing. With ``strict`` that is a usage error instead.

    Raises:
        ParameterError: a bad option value, or (``strict``) a folder with no robot file
            (exit code 2).
    """
    from urdfkit.checks.check import check_paths, parse_codes
    from urdfkit.checks.targets import parse_targets
    from urdfkit.core.errors import ParameterError
    from urdfkit.core.finding import Finding
    from urdfkit.sources.uris import parse_packages

    level = fail_on_level(fail_on)
    fmt = chosen_format(output_format, as_json)
    import gc

    # A run makes millions of short-lived objects and no reference cycles (tests/
    # test_check_memory.py holds it to that), so the cyclic collector finds nothing, yet
    # scans every young object: ~4% of a check of pybullet_data. Off for the run.
    enabled = gc.isenabled()
    gc.disable()
    try:
        result = check_paths(paths, packages=parse_packages(package, package_path),
                             select=parse_codes(select, "`select`"),
                             ignore=parse_codes(ignore, "`ignore`"), jobs=jobs,
                             no_exec=no_exec, xacro_args=xacro_args(arg), physics=physics,
                             cache=not no_cache, targets=parse_targets(target))
    finally:
        if enabled:
            gc.enable()
    if arg and not no_exec:
        for line in unknown_args(paths, xacro_args(arg), parse_packages(package, package_path)):
            show.warn(input_flags(line))
    for folder in empty_folders(paths, [fr.file for fr in result.files]):
        line = (f"{folder}: no robot file in this folder (no *.urdf or *.xacro, any case, in it "
                "or below)")
        if strict:
            raise ParameterError(f"{line}; --strict refuses a folder with nothing to check")
        show.warn(line)
    for fr in result.files:  # a xacro or package problem speaks of flags, not parameters
        fr.findings = [Finding(f.code, f.level, input_flags(f.message), f.file, f.line, f.origin)
                       if "`" in f.message else f for f in fr.findings]
    show.check_formatted(result, fmt, level, show_all)
    return result.exit_code(level)


def fail_on_level(fail_on: str) -> Level:
    """``--fail-on``, checked: the level itself."""
    from urdfkit.core.finding import LEVELS

    if fail_on not in LEVELS:
        from urdfkit.core.errors import ParameterError
        from urdfkit.core.suggest import hint

        raise ParameterError(f"`fail_on` expects error, warning or info, got {fail_on!r}"
                             f"{hint(fail_on, ('error', 'warning', 'info'))}", param="fail_on")
    return next(level for level in LEVELS if level == fail_on)


def unknown_args(paths: list[str], args: dict[str, str], packages: Any) -> list[str]:
    """``--arg`` names that none of the xacro files named on the command line declares.

    ``check`` passes its ``--arg`` values to every xacro file, and a file ignores one it does
    not declare; a misspelt name (``prefx``) would be ignored by all of them, silently. Each
    named file is expanded strictly (once more per unknown name; folders are not searched, as
    a tree's files declare different arguments by design), and a name every one rejects is
    said with xacro's own message (its nearest declared name).
    """
    import os

    from urdfkit.checks.check import _is_xacro
    from urdfkit.core.errors import ParameterError, UrdfkitError
    from urdfkit.sources.expand import expand_xacro

    named = [p for p in paths if _is_xacro(p) and os.path.isfile(p)]
    if not args or not named:
        return []
    unknown: dict[str, str] | None = None
    for path in named:
        left, mine = dict(args), {}
        while left:
            try:
                expand_xacro(path, left, display=path, packages=packages, strict_args=True)
                break
            except ParameterError as e:
                name = next((n for n in left if f"{n!r} is not an argument" in e.message), None)
                if name is None:
                    return []  # not about the arguments: check says what is wrong
                mine[name] = f"{path}: {e.message}; check ignores it"
                del left[name]
            except UrdfkitError:
                return []  # the file's own problem, which check reports as a finding
        unknown = mine if unknown is None else {n: m for n, m in unknown.items() if n in mine}
    return list((unknown or {}).values())


def empty_folders(paths: list[str], checked: list[str]) -> list[str]:
    """The folders in ``paths`` under which none of the ``checked`` files lies."""
    import os

    from urdfkit.checks.check import SUFFIXES

    out = []
    for item in paths:
        if not os.path.isdir(item) or os.path.splitext(item)[1].lower() in SUFFIXES:
            continue
        prefix = os.path.join(item, "")
        if not any(name.startswith(prefix) for name in checked):
            out.append(item)
    return out


def chosen_format(output_format: str | None, as_json: bool) -> CheckFormat:
    """The output format ``--format`` and ``--json`` choose, checked."""
    from urdfkit.checks.ci import FORMATS
    from urdfkit.core.errors import ParameterError

    if output_format is not None and output_format not in FORMATS:
        from urdfkit.core.suggest import hint

        raise ParameterError(f"`format` expects {', '.join(FORMATS)}, got {output_format!r}"
                             f"{hint(output_format, FORMATS)}", param="format")
    if as_json and output_format not in (None, "json"):
        raise ParameterError(f"`json` means `format` json; it cannot be combined with "
                             f"`format` {output_format}", param="format")
    wanted = "json" if as_json else output_format or "text"
    return next(fmt for fmt in FORMATS if fmt == wanted)


def xacro_args(items: list[str] | None) -> dict[str, str]:
    """``--arg NAME:=VALUE`` values as a mapping."""
    if not items:
        return {}
    from urdfkit.model.catalog import parse_assignments  # imports the builder: only when needed

    return parse_assignments(items, "xacro_args")


def parse_argv(args: list[str]) -> dict[str, Any] | None:
    """:func:`run_check`'s keywords from the words after ``check``, or None for typer.

    None whenever the words are not plainly paths and known options, each valued option with
    one value not starting with ``-``, given once: typer then parses them, and says what is
    wrong.
    """
    out: dict[str, Any] = {"paths": []}
    n = 0
    while n < len(args):
        word = args[n]
        n += 1
        if not word.startswith("-"):
            out["paths"].append(word)
            continue
        name, eq, value = word.partition("=")
        if name in FLAG_OPTIONS:
            if eq or FLAG_OPTIONS[name] in out:
                return None
            out[FLAG_OPTIONS[name]] = True
            continue
        key = VALUE_OPTIONS.get(name) or LIST_OPTIONS.get(name)
        if key is None or (eq and not name.startswith("--")):
            return None  # --help, an unknown option, -j4 or -j=4
        if not eq:
            if n == len(args):
                return None
            value = args[n]
            n += 1
        if not value or value.startswith("-"):
            return None
        if name in LIST_OPTIONS:
            out.setdefault(key, []).append(value)
            continue
        if key in out:
            return None
        if key == "jobs":
            if not (value.isascii() and value.isdigit()) or int(value) < 1:
                return None
            out[key] = int(value)
        else:
            out[key] = value
    return out if out["paths"] else None


def fast_main(args: list[str]) -> int | None:
    """Run ``urdfkit check`` with ``args`` without typer; None when typer must parse them.

    Set up as every run of the command line is (:func:`~urdfkit.commands.startup.prepare`);
    errors take the road of :func:`urdfkit.cli.run`: one line on stderr and the exit code.
    """
    options = parse_argv(args)
    if options is None:
        return None
    prepare()
    try:
        return run_check(**options)
    except BaseException as e:  # noqa: BLE001 - handled as the typer command's are
        return outcome(e)
