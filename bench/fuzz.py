"""The full fuzz run (issues 11, 12 and 48): mutants of real robots through every command.

Usage: ``python bench/fuzz.py --mutants 1500 --seed 1 --jobs 2 [--keep /tmp/fuzz]``, and
``--campaign mjcf`` for mutants of real MJCF exports through ``urdfkit agree``.

Prints runs by class and command with mean seconds per run, lists every failure (signal, hang,
traceback, bug, bad exit, multi-line error, unnamed refusal, dirty JSON), saves each failing
mutant with its command and stderr under ``--keep``, and exits 1 if anything failed. The CI
test (tests/test_fuzz.py) runs a seeded sample of the same campaign.
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent.parent / "tests"))

from fuzz.runner import campaign, mjcf_campaign  # noqa: E402


def main() -> int:
    ap = argparse.ArgumentParser()
    ap.add_argument("--mutants", type=int, default=1500)
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--jobs", type=int, default=2)
    ap.add_argument("--timeout", type=float, default=30.0)
    ap.add_argument("--keep", type=Path, default=None)
    ap.add_argument("--campaign", choices=["urdf", "mjcf"], default="urdf")
    a = ap.parse_args()
    start = time.perf_counter()
    run = campaign if a.campaign == "urdf" else mjcf_campaign
    report = run(a.mutants, a.seed, jobs=a.jobs, timeout=a.timeout, keep=a.keep)
    print(f"{report.mutants} mutants, {report.runs} runs, seed {a.seed}, "
          f"{time.perf_counter() - start:.0f} s")
    print(report.table())
    for f in report.failures:
        last = str(f["stderr"]).strip().splitlines()[-1:] or [""]
        print(f"FAIL {f['class']}: {' '.join(map(str, f['command']))} <- {f['seed']} "
              f"{f['mutations']}: {last[0][:200]}")
    print(f"{len(report.failures)} failure(s)")
    return 1 if report.failures else 0


if __name__ == "__main__":
    raise SystemExit(main())
