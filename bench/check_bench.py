"""`urdfkit check` over pybullet_data on ONE worker against a plain lxml parse loop (issue 11).

Goal: at most 3x a loop that only parses the same files with ``lxml.etree.parse`` (the floor
any validator pays). Both run in this process, alternated, min of ``-n`` repetitions, so a busy
machine slows both alike. Also prints the CLI's wall time with ``--jobs 1`` and with every
core. Not a unit test: figures go in bench/README.md.

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

from urdfkit.check import check_paths, discover

GOAL = 3.0


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
