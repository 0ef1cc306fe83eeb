"""What every run of the command line shares: its set-up, and what an exception becomes.

Both roads into a command use these: typer's (:func:`urdfkit.cli.main`) and ``check``'s fast
start (:func:`urdfkit.commands.check_run.fast_main`). No typer here.
"""

import gc
import os
import sys

# signal's own functions, without the enums the signal module builds at import (~0.7 ms a
# run); signal itself is imported when a signal comes.
from _signal import SIGHUP, SIGTERM
from _signal import signal as set_handler
from typing import Any

from urdfkit.commands import present as show
from urdfkit.commands.flags import flag_message, input_flags
from urdfkit.core.errors import UrdfkitError

#: Set (to anything) to print the traceback of a bug.
DEBUG_ENV = "URDFKIT_DEBUG"


def prepare() -> None:
    """What every run of the command line sets up before a command runs."""
    # numpy (imported by pybullet) starts an OpenBLAS thread pool whose workers spin on the
    # second core: ~70 ms of CPU per `urdfkit joints`, for nothing, since no command does large
    # linear algebra. One thread, unless the user asks otherwise. Set here, not on import, so
    # library users keep their own setting.
    os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")
    for sig in (SIGTERM, SIGHUP):
        set_handler(sig, _on_signal)
    # What is loaded by now (typer, click, this module) lives until exit. Freezing it keeps the
    # cyclic GC from re-scanning it in every full collection that the imports of numpy and
    # pybullet trigger: ~8 ms of a `urdfkit joints` run. Later garbage is collected as usual.
    gc.freeze()


def _on_signal(signum: int, _frame: Any) -> None:
    # SIGTERM (a CI timeout, `kill`) and SIGHUP (a closed terminal) stop a run the way
    # Ctrl-C does: drive and sim keep the rows simulated so far, temp files are removed.
    import signal

    raise KeyboardInterrupt(signal.Signals(signum).name)


def outcome(e: BaseException) -> int:
    """The exit code of an exception out of a command, its one line said (see cli.run)."""
    if isinstance(e, UrdfkitError):
        # Only errors about a parameter speak of flags; a scenario file's `wheels` stays a key.
        show.error(flag_message(str(e)) if e.param is not None else input_flags(str(e)))
        return e.exit_code
    if isinstance(e, KeyboardInterrupt):
        show.interrupted()
        return 130
    if isinstance(e, BrokenPipeError):
        # `urdfkit check . | head`: the reader went away; that is not an error.
        devnull = os.open(os.devnull, os.O_WRONLY)
        os.dup2(devnull, sys.stdout.fileno())
        return 0
    if not isinstance(e, Exception):
        raise e  # SystemExit, GeneratorExit: not ours to turn into a code
    if os.environ.get(DEBUG_ENV):
        import traceback

        traceback.print_exception(e)
    show.bug(e)
    return 3
