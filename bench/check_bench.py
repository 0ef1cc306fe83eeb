"""`urdfkit check` over pybullet_data on ONE worker, in process, against a bare parse loop.

The issue's goal (at most 3x a plain ``lxml.etree.parse`` loop) is measured as programs, the
way users run them, by ``bench/run.py check_cli_bench``. This script is the in-process view:
the same files, ``check_paths(jobs=1)`` against ``etree.parse`` alone, which shows what the
rules themselves cost beyond the parse (no start-up, no walk on either side). Not a unit
test: figures go in bench/README.md.

Usage: python bench/check_bench.py [-n 5]
"""

from __future__ import annotations

import argparse
import subprocess
import sys
import time
from pathlib import Path

import pybullet_data
from lxml import etree

from urdfkit.checks.check import check_paths, discover

GOAL = 3.0  # the goal, applied here to the rules alone (stricter than the CLI's)


def parse_loop(files: list[Path]) -> None:
    parser = etree.XMLParser(resolve_entities=False, no_network=True)
    for f in files:
        try:
            etree.parse(str(f), parser)
        except etree.XMLSyntaxError:
            pass


def main() -> int:
    ap = argparse.ArgumentParser()
    ap.add_argument("-n", type=int, default=5)
    n = ap.parse_args().n
    data = Path(pybullet_data.getDataPath())
    files = [p for _, p, problem in discover([data]) if problem is None
             and p.suffix == ".urdf"]
    base, ours = [], []
    for _ in range(n):
        t = time.perf_counter()
        parse_loop(files)
        base.append(time.perf_counter() - t)
        t = time.perf_counter()
        check_paths(files, jobs=1)
        ours.append(time.perf_counter() - t)
    ratio = min(ours) / min(base)
    print(f"{len(files)} URDFs in pybullet_data, min of {n}")
    print(f"  lxml.etree.parse loop       {min(base) * 1000:8.1f} ms")
    print(f"  check_paths(jobs=1)         {min(ours) * 1000:8.1f} ms")
    print(f"  ratio {ratio:.2f}x (goal <= {GOAL:g}x): {'ok' if ratio <= GOAL else 'MISSED'}")
    for jobs in (["--jobs", "1"], []):
        t = time.perf_counter()
        subprocess.run([sys.executable, "-m", "urdfkit", "check", str(data), "--json", *jobs],
                       stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
        label = " ".join(jobs) or "(every core)"
        print(f"  urdfkit check pybullet_data --json {label:<12} {time.perf_counter() - t:6.2f} s")
    return 0 if ratio <= GOAL else 1


if __name__ == "__main__":
    raise SystemExit(main())
