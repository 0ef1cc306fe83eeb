"""What every run of the command line sets up before its command runs."""

import gc
import os
import signal
from typing import Any


def prepare() -> None:
    """What every run of the command line sets up before a command runs."""
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


def _on_signal(signum: int, _frame: Any) -> None:
    # SIGTERM (a CI timeout, `kill`) and SIGHUP (a closed terminal) stop a run the way
    # Ctrl-C does: drive and sim keep the rows simulated so far, temp files are removed.
    raise KeyboardInterrupt(signal.Signals(signum).name)
