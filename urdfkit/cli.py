"""The ``urdfkit`` command line: parse options, call the library, hand the result to present.

cli.py holds the app and the error handler; each command lives in a module of
:mod:`urdfkit.commands` (options and calls), what the output looks like in
:mod:`urdfkit.commands.present`,
and every error takes one road: :class:`UrdfkitGroup.main` is the only place that catches,
turning each outcome into one line on stderr and an exit code:

- 0 ok; 1 findings at or above ``--fail-on`` (check); 2 bad input or usage (a
  :class:`~urdfkit.core.errors.UrdfkitError`, or a bad option value); 3 an internal error, a
  bug (``URDFKIT_DEBUG=1`` shows the traceback); 130 interrupted (Ctrl-C, SIGTERM, SIGHUP).
- The library names Python parameters in its messages (`` `time_step` ``); the handler shows
  the flag that feeds it (``--time-step``).

Nothing heavy is imported at module level: ``urdfkit --help`` must not pay for PyBullet,
numpy, yourdfpy or trimesh.
"""

import importlib
import os
import sys
from collections.abc import Callable, Iterable, Sequence
from typing import Annotated, Any

import typer
from typer.core import TyperCommand, TyperGroup

from urdfkit import __version__
from urdfkit.commands import present as show
from urdfkit.commands.startup import outcome, prepare
from urdfkit.core.errors import UrdfkitError

#: Every command, in the order of ``urdfkit --help``, and the module of :mod:`urdfkit.commands`
#: that holds it. Only the invoked command's module is imported.
COMMANDS = {
    "build": "build", "templates": "build",
    "joints": "inspecting", "links": "inspecting", "tree": "inspecting", "info": "inspecting",
    "check": "checking", "diff": "checking", "fix": "checking",
    "drive": "driving", "sweep": "driving",
    "render": "drawing", "view": "drawing", "collisions": "checking", "sim": "simulating",
    "export": "exporting", "agree": "exporting", "lsp": "serving", "mcp": "serving",
}


def _click_error(e: BaseException) -> bool:
    # click's own errors (bad option values, unknown options, missing arguments). Told apart
    # by shape, not class: typer 0.28 carries a private copy of click, older typer uses click.
    return hasattr(e, "format_message") and isinstance(getattr(e, "exit_code", None), int)


def _usage_message(e: Any) -> str:
    ctx = getattr(e, "ctx", None)
    # "urdfkit: error: drive: ...", not "urdfkit: error: urdfkit drive: ...": the program
    # is named once, by the error line's own prefix.
    sub = ctx.command_path.partition(" ")[2] if ctx is not None else ""
    where = f"{sub}: " if sub else ""
    text = " ".join(e.format_message().split())  # one line, however click wrapped it
    option = getattr(e, "option_name", None)
    if option and not getattr(e, "possibilities", None) and ctx is not None:
        from urdfkit.core.suggest import hint

        flags = [o for p in ctx.command.params for o in getattr(p, "opts", [])
                 if o.startswith("--")]
        text += hint(option, flags)
    if ctx is not None:
        text += f" (see `{ctx.command_path} --help`)"
    return where + text


def _help(command: Any, ctx: Any, formatter: Any) -> None:
    """Write ``command``'s help, words whole at any width (:mod:`urdfkit.commands.helptext`).

    Not typer's rich panels: their option table cuts a word wider than its column in two,
    or to an ellipsis, at any common terminal width.
    """
    from urdfkit.commands.helptext import plain_help

    ctx.ensure_object(dict)
    if isinstance(ctx.obj, dict):  # typer escapes "[default: ...]" for rich unless told not
        ctx.obj["TYPER_RICH_MARKUP_MODE"] = None
    formatter.write(plain_help(command, ctx, show.terminal_width(),
                               styled=show.styled(sys.stdout)) + "\n")


class UrdfkitCommand(TyperCommand):
    """A command whose help keeps every word whole (:func:`_help`)."""

    def format_help(self, ctx: Any, formatter: Any) -> None:
        """The help, laid out by :func:`_help`."""
        _help(self, ctx, formatter)


class UrdfkitGroup(TyperGroup):
    """urdfkit's click group: its :meth:`main` is the one error handler of the CLI."""

    def format_help(self, ctx: Any, formatter: Any) -> None:
        """The list of commands, laid out by :func:`_help`."""
        _help(self, ctx, formatter)

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
    except typer.Abort:
        show.interrupted()
        return 130
    except Exception as e:  # noqa: BLE001 - the last line of defence: a bug, said so
        if not isinstance(e, (UrdfkitError, BrokenPipeError)) and _click_error(e):
            context = getattr(e, "ctx", None)
            if context is not None and type(e).__name__ == "NoArgsIsHelpError":
                sys.stdout.write(context.get_help() + "\n")  # a bare `urdfkit`: the help
            else:
                show.error(_usage_message(e))
            return 2
        return outcome(e)  # an error's one line, a broken pipe, or a bug
    except KeyboardInterrupt as e:
        return outcome(e)


def _new_app(**settings: Any) -> typer.Typer:
    return typer.Typer(name="urdfkit", cls=UrdfkitGroup, pretty_exceptions_enable=False,
                       rich_markup_mode="rich",
                       context_settings={"help_option_names": ["-h", "--help"]}, **settings)


def _version_callback(value: bool) -> None:
    if value:
        sys.stdout.write(f"urdfkit {__version__}\n")
        raise typer.Exit()


def _root(
    version: Annotated[bool, typer.Option("--version", callback=_version_callback,
                                          is_eager=True, help="Show the version and exit.")]
    = False,
) -> None:
    """Build, inspect and test-drive URDF robot descriptions with PyBullet.

    Exit codes: 0 ok, 1 findings (check), 2 bad input or usage, 3 a bug in urdfkit,
    130 interrupted. URDFKIT_DEBUG=1 prints the traceback of a bug.
    """


def _reflow(doc: str) -> str:
    """A docstring's paragraphs each on one line: rich help keeps single line breaks."""
    return "\n\n".join(" ".join(line.strip() for line in para.splitlines())
                       for para in doc.strip().split("\n\n"))


def _command(name: str, library_defaults: bool) -> Callable[..., Any]:
    """The function of command ``name``, from its module under :mod:`urdfkit.commands`.

    With ``library_defaults``, the defaults the library owns (DriveConfig's) are put in its
    signature first: that imports the library, which ``urdfkit --help`` does not need.
    """
    module = importlib.import_module(f"urdfkit.commands.{COMMANDS[name]}")
    if library_defaults and hasattr(module, "use_library_defaults"):
        module.use_library_defaults()
    return getattr(module, name)


def _listed() -> None:
    """Stands for every command in ``urdfkit --help``, which lists commands, not options."""


def _build(names: Iterable[str], *, library_defaults: bool = True, listing: bool = False,
           **settings: Any) -> typer.Typer:
    """An app holding the commands ``names``, each with its examples and reflowed help.

    A ``listing`` holds each command's name and help but not its options: typer reads every
    parameter of every command it builds (~0.4 ms a command), and ``urdfkit --help`` shows
    none of them.
    """
    import inspect

    built = _new_app(**settings)
    built.callback()(_root)
    for name in names:
        func = _command(name, library_defaults and not listing)
        built.command(name=name, cls=UrdfkitCommand, epilog=func.__dict__["epilog"],
                      help=_reflow(inspect.cleandoc(func.__doc__ or "")))(
            _listed if listing else func)
    return built


def _full_app(library_defaults: bool = True, listing: bool = False) -> typer.Typer:
    """The app with every command (``urdfkit --help``, shell completion, the tests)."""
    return _build(COMMANDS, library_defaults=library_defaults, listing=listing,
                  help="Build, inspect and test-drive URDF robot descriptions with PyBullet.",
                  no_args_is_help=True, add_completion=True)


_app: typer.Typer | None = None


def __getattr__(name: str) -> Any:
    # `from urdfkit.cli import app`: the whole app, built on first use, so that `main` (which
    # builds one command) never pays for the others.
    global _app
    if name == "app":
        if _app is None:
            _app = _full_app()
        return _app
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")


def main() -> None:
    """The command line through typer.

    :func:`urdfkit.entry.main`, the console script, comes here for all but plain ``check``
    runs.
    """
    prepare()
    argv = sys.argv[1:]
    if argv and argv[0] in COMMANDS:
        # typer builds the click command of every registered command on each run (signature
        # and type-hint evaluation, ~1 ms each), and each command's module costs its import:
        # a user runs one command at a time, so only that one is imported and built.
        # no_args_is_help off: with one command, typer would otherwise treat a lone
        # `urdfkit joints` as the group's own help request.
        _build([argv[0]], add_completion=False)()
    elif os.environ.get("_URDFKIT_COMPLETE"):
        # Shell completion (typer's variable for prog name urdfkit): every command and its
        # options, without the library's defaults (nothing is parsed or shown with them).
        _full_app(library_defaults=False)()
    else:
        # `urdfkit --help`, a bare `urdfkit`, --version, an unknown command: the list of
        # commands, none of their options.
        _full_app(listing=True)()
