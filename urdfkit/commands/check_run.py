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
                "--physics": "physics", "--no-cache": "no_cache"}
#: Options with one value each (given once), and options that may be repeated.
VALUE_OPTIONS = {"--format": "output_format", "--fail-on": "fail_on", "--jobs": "jobs",
                 "-j": "jobs"}
LIST_OPTIONS = {"--select": "select", "--ignore": "ignore", "--arg": "arg", "-a": "arg",
                "--package": "package", "-p": "package", "--package-path": "package_path"}


def run_check(paths: list[str], as_json: bool = False, output_format: str | None = None,
              fail_on: str = "error", package: list[str] | None = None,
              package_path: list[str] | None = None, select: list[str] | None = None,
              ignore: list[str] | None = None, jobs: int | None = None,
              arg: list[str] | None = None, no_exec: bool = False, show_all: bool = False,
              physics: bool = False, no_cache: bool = False) -> int:
    """Check ``paths`` and print the findings in ``output_format``; the exit code.

    Raises:
        ParameterError: a bad option value (exit code 2).
    """
    from urdfkit.checks.check import check_paths, parse_codes
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
                             cache=not no_cache)
    finally:
        if enabled:
            gc.enable()
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
