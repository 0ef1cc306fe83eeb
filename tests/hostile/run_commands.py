"""Run one urdfkit command over many files in this process; write one JSON line per file.

Used by tests/test_hostile.py: a subprocess per command keeps the test fast, and if PyBullet
kills the process with a signal, the last ``start`` line in OUT names the file that did it.

Usage: ``python tests/hostile/run_commands.py OUT COMMAND FILE... -- EXTRA_ARGS...``
"""

from __future__ import annotations

import json
import sys
import time
import traceback


def main(argv: list[str]) -> int:
    out, command, *rest = argv
    files, extra = (rest[: rest.index("--")], rest[rest.index("--") + 1:]) if "--" in rest \
        else (rest, [])
    from typer.testing import CliRunner

    from urdfkit.cli import app

    runner = CliRunner()
    with open(out, "w") as log:
        for f in files:
            log.write(json.dumps({"start": f}) + "\n")
            log.flush()
            args = [command, *(a.replace("{file}", f) for a in extra)]
            if not any("{file}" in a for a in extra):
                args.insert(1, f)
            t0 = time.perf_counter()
            r = runner.invoke(app, args, catch_exceptions=True)
            exc = None
            if r.exception is not None and not isinstance(r.exception, SystemExit):
                exc = "".join(traceback.format_exception(r.exception))
            log.write(json.dumps({
                "file": f, "exit": r.exit_code, "stdout": r.stdout, "stderr": r.stderr,
                "exception": exc, "seconds": time.perf_counter() - t0}) + "\n")
            log.flush()
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
