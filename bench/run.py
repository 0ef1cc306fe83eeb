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
SECTIONS = ["inspect_bench"]


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
    """

    name: str
    argv: list[str]
    goals: list[tuple[str, float]] = field(default_factory=list)
    times: list[float] = field(default_factory=list)


def time_once(argv: Sequence[str]) -> float:
    start = time.perf_counter()
    proc = subprocess.run(argv, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    elapsed = time.perf_counter() - start
    if proc.returncode != 0:
        raise SystemExit(f"bench: command failed ({proc.returncode}): {' '.join(argv)}")
    return elapsed


def main(argv: Sequence[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("sections", nargs="*", default=SECTIONS)
    parser.add_argument("-n", "--rounds", type=int, default=30)
    args = parser.parse_args(argv)
    script = Path(sys.executable).parent / "urdfkit"
    urdfkit = [str(script)] if script.exists() else [sys.executable, "-m", "urdfkit"]
    with tempfile.TemporaryDirectory(prefix="urdfkit-bench-") as tmp:
        ctx = Context(sys.executable, urdfkit, Path(tmp))
        cases: list[Case] = []
        for name in args.sections:
            cases += importlib.import_module(name).cases(ctx)
        by_name = {c.name: c for c in cases}
        for c in cases:  # warm the page cache and catch broken commands before timing
            time_once(c.argv)
        order = list(cases)
        for _ in range(args.rounds):
            random.shuffle(order)
            for c in order:
                c.times.append(time_once(c.argv))
    return report(cases, by_name, args.rounds)


def report(cases: list[Case], by_name: dict[str, Case], rounds: int) -> int:
    print(f"{rounds} rounds, python {sys.version.split()[0]}\n")
    print(f"{'command':<34} {'min ms':>8} {'median ms':>10}")
    for c in cases:
        print(f"{c.name:<34} {min(c.times) * 1e3:8.1f} {statistics.median(c.times) * 1e3:10.1f}")
    print(f"\n{'ratio':<52} {'min':>6} {'median':>7} {'goal':>6}")
    missed = 0
    for c in cases:
        for baseline, goal in c.goals:
            b = by_name[baseline]
            r_min = min(c.times) / min(b.times)
            r_med = statistics.median(c.times) / statistics.median(b.times)
            ok = r_min <= goal
            missed += not ok
            label = f"{c.name} / {b.name}"
            print(f"{label:<52} {r_min:6.2f} {r_med:7.2f} {goal:6.2f}  "
                  f"{'ok' if ok else 'MISSED'}")
    return 1 if missed else 0


if __name__ == "__main__":
    sys.exit(main())
