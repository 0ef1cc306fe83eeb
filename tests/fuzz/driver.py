"""Run urdfkit commands over fuzz mutants: one warm process, one fork per command.

Importing urdfkit, PyBullet and numpy once and forking per command makes a run cost the
command's own work (tens of milliseconds) instead of a fresh interpreter (half a second),
while a segfault or a hang still kills only that command's child, and is attributed to it.

Usage: ``python tests/fuzz/driver.py JOBS.json RESULTS.jsonl``; JOBS holds
``[{"id", "dir", "commands": [[arg, ...], ...], "timeout"}]``. Each result line is
``{"id", "command", "code", "signal", "hang", "stdout", "stderr", "seconds"}``.
"""

from __future__ import annotations

import contextlib
import json
import os
import signal
import sys
import time


def run_one(workdir: str, argv: list[str], timeout: float) -> dict[str, object]:
    out_path, err_path = os.path.join(workdir, ".out"), os.path.join(workdir, ".err")
    sys.stdout.flush()
    sys.stderr.flush()
    start = time.perf_counter()
    pid = os.fork()
    if pid == 0:  # the child: become `urdfkit ARGV` in the mutant's folder
        code = 99
        try:
            os.chdir(workdir)
            out = os.open(out_path, os.O_WRONLY | os.O_CREAT | os.O_TRUNC, 0o644)
            err = os.open(err_path, os.O_WRONLY | os.O_CREAT | os.O_TRUNC, 0o644)
            os.dup2(out, 1)
            os.dup2(err, 2)
            sys.argv = ["urdfkit", *argv]
            from urdfkit.cli import main

            try:
                main()
                code = 0
            except SystemExit as e:
                code = e.code if isinstance(e.code, int) else (0 if e.code is None else 1)
        except BaseException:  # noqa: BLE001 - a traceback here is a finding
            import traceback

            traceback.print_exc()
            code = 98
        finally:
            with contextlib.suppress(BaseException):
                sys.stdout.flush()
                sys.stderr.flush()
            os._exit(code)
    deadline = start + timeout
    status, hang = None, False
    while True:
        done, st = os.waitpid(pid, os.WNOHANG)
        if done:
            status = st
            break
        if time.perf_counter() > deadline:
            os.kill(pid, signal.SIGKILL)
            os.waitpid(pid, 0)
            hang = True
            break
        time.sleep(0.002)
    seconds = time.perf_counter() - start

    def read(path: str) -> str:
        try:
            with open(path, "rb") as f:
                return f.read(200_000).decode("utf-8", "replace")
        except OSError:
            return ""

    code = sig = None
    if status is not None:
        if os.WIFSIGNALED(status):
            sig = os.WTERMSIG(status)
        else:
            code = os.WEXITSTATUS(status)
    return {"command": argv, "code": code, "signal": sig, "hang": hang, "stdout": read(out_path),
            "stderr": read(err_path), "seconds": round(seconds, 4)}


def main(argv: list[str]) -> int:
    jobs_file, results_file = argv
    os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")
    import pybullet  # noqa: F401 - warm: every child inherits the import

    import urdfkit.cli  # noqa: F401

    with open(jobs_file) as f:
        jobs = json.load(f)
    with open(results_file, "w") as out:
        for job in jobs:
            for command in job["commands"]:
                result = run_one(job["dir"], command, job["timeout"])
                result["id"] = job["id"]
                out.write(json.dumps(result) + "\n")
                out.flush()
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
