"""urdfkit's benchmark: wall time of real commands as ratios against baselines, in one run.

Usage::

    python bench/run.py                 # every section, 30 rounds
    python bench/run.py -n 60 inspect   # one section, more rounds

Each round runs every command once, in a shuffled order, as a fresh subprocess (so import
cost counts, as it does for users). Ratios are computed from the same run, so a busy machine
slows baselines and urdfkit alike. The ratio of minimums is the headline (least noise); the
ratio of medians is printed beside it. Exit status 1 if any goal is missed.

Adding a section: write ``bench/<topic>.py`` with ``def cases(ctx: Context) -> list[Case]``
and add its name to :data:`SECTIONS`.
"""

from __future__ import annotations

import argparse
import importlib
import json
import os
import pty
import random
import statistics
import subprocess
import sys
import tempfile
import time
from collections.abc import Sequence
from dataclasses import dataclass, field
from pathlib import Path

BENCH = Path(__file__).resolve().parent
sys.path.insert(0, str(BENCH))

#: Section modules under bench/, each with ``cases(ctx) -> list[Case]``.
SECTIONS = ["inspect_bench", "build_bench", "output_bench", "check_cli_bench", "export_bench",
            "engine_bench"]


@dataclass
class Context:
    """What sections share: the interpreter, the urdfkit executable, a scratch folder."""

    python: str
    urdfkit: list[str]
    tmp: Path
    baselines: Path = BENCH / "baselines"


@dataclass
class Case:
    """One command to time.

    Attributes:
        name: Label in the report; baselines are referred to by it.
        argv: The command.
        goals: (baseline name, highest acceptable ratio) pairs; empty for a baseline.
        ok: Exit statuses that count as success (``check`` exits 1 on findings).
        env: Extra environment variables for the command.
    """

    name: str
    argv: list[str]
    goals: list[tuple[str, float]] = field(default_factory=list)
    times: list[float] = field(default_factory=list)
    terminal: bool = False
    ok: tuple[int, ...] = (0,)
    env: dict[str, str] = field(default_factory=dict)


#: Size of the pseudo-terminal that ``terminal`` cases write to: a common laptop window.
TERMINAL_ROWS, TERMINAL_COLUMNS = 50, 140


def time_once(case: Case) -> float:
    """Wall time of one run; stdout goes to /dev/null, or to a pseudo-terminal."""
    if not case.terminal:
        start = time.perf_counter()
        proc = subprocess.run(case.argv, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL,
                              env={**os.environ, **case.env})
        elapsed = time.perf_counter() - start
        returncode = proc.returncode
    else:
        import fcntl
        import struct
        import termios

        master, slave = pty.openpty()
        fcntl.ioctl(slave, termios.TIOCSWINSZ,
                    struct.pack("HHHH", TERMINAL_ROWS, TERMINAL_COLUMNS, 0, 0))
        env = {k: v for k, v in {**os.environ, **case.env}.items()
               if k not in ("COLUMNS", "NO_COLOR")}
        env["TERM"] = "xterm-256color"
        start = time.perf_counter()
        child = subprocess.Popen(case.argv, stdout=slave, stderr=subprocess.DEVNULL, env=env)
        os.close(slave)
        while True:  # drain the terminal as a terminal emulator would, until the child is gone
            try:
                if not os.read(master, 65536):
                    break
            except OSError:  # EIO: every writer has closed the terminal
                break
        returncode = child.wait()
        elapsed = time.perf_counter() - start
        os.close(master)
    if returncode not in case.ok:
        raise SystemExit(f"bench: command failed ({returncode}): {' '.join(case.argv)}")
    return elapsed


def editable_install() -> bool:
    """Whether urdfkit is installed in editable mode (PEP 610 direct_url.json)."""
    from importlib import metadata

    try:
        text = metadata.distribution("urdfkit").read_text("direct_url.json")
    except metadata.PackageNotFoundError:
        return False
    return bool(text and json.loads(text).get("dir_info", {}).get("editable"))


def main(argv: Sequence[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("sections", nargs="*", default=SECTIONS)
    parser.add_argument("-n", "--rounds", type=int, default=30)
    args = parser.parse_args(argv)
    if editable_install():
        print("bench: warning: urdfkit is an editable install; its import hook slows every "
              "Python start-up, baselines included, which flatters the ratios. For figures, "
              "`pip install .` into a fresh venv.", file=sys.stderr)
    script = Path(sys.executable).parent / "urdfkit"
    urdfkit = [str(script)] if script.exists() else [sys.executable, "-m", "urdfkit"]
    with tempfile.TemporaryDirectory(prefix="urdfkit-bench-") as tmp:
        ctx = Context(sys.executable, urdfkit, Path(tmp))
        cases: list[Case] = []
        for name in args.sections:
            cases += importlib.import_module(name).cases(ctx)
        by_name = {c.name: c for c in cases}
        for c in cases:  # warm the page cache and catch broken commands before timing
            time_once(c)
        order = list(cases)
        for _ in range(args.rounds):
            random.shuffle(order)
            for c in order:
                c.times.append(time_once(c))
    return report(cases, by_name, args.rounds)


def report(cases: list[Case], by_name: dict[str, Case], rounds: int) -> int:
    print(f"{rounds} rounds, python {sys.version.split()[0]}\n")
    print(f"{'command':<40} {'min ms':>8} {'median ms':>10}")
    for c in cases:
        print(f"{c.name:<40} {min(c.times) * 1e3:8.1f} {statistics.median(c.times) * 1e3:10.1f}")
    print(f"\n{'ratio':<64} {'min':>6} {'median':>7} {'goal':>6}")
    missed = 0
    for c in cases:
        for baseline, goal in c.goals:
            b = by_name[baseline]
            r_min = min(c.times) / min(b.times)
            r_med = statistics.median(c.times) / statistics.median(b.times)
            ok = r_min <= goal
            missed += not ok
            label = f"{c.name} / {b.name}"
            print(f"{label:<64} {r_min:6.2f} {r_med:7.2f} {goal:6.2f}  "
                  f"{'ok' if ok else 'MISSED'}")
    return 1 if missed else 0


if __name__ == "__main__":
    sys.exit(main())
