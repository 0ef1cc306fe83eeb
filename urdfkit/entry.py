"""The ``urdfkit`` console script: ``urdfkit check`` starts without typer, the rest with it.

``check`` is what CI and pre-commit hooks run again and again, so its plain command lines
are read by :func:`urdfkit.commands.check_run.fast_main` (typer and building its command
cost ~20 ms of a ~250 ms check of pybullet_data); everything else, and any ``check`` command
line that is not plain (``--help``, a usage error), goes to :func:`urdfkit.cli.main`.
"""

import sys


def main() -> None:
    """Entry point of the ``urdfkit`` console script (and ``python -m urdfkit``)."""
    argv = sys.argv[1:]
    if argv[:1] == ["check"]:
        from urdfkit.commands.check_run import fast_main

        code = fast_main(argv[1:])
        if code is not None:
            sys.exit(code)
    from urdfkit.cli import main as typer_main

    typer_main()
