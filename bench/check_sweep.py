"""Time `urdfkit check --json` over every URDF in pybullet_data (goal: < 30 s on 2 cores).

Runs the installed CLI in a subprocess, as a user would, and verifies that every file found on
disk is listed in the JSON. Also times a single-process run (URDFKIT_CHECK_JOBS is not an
option, so it calls the library with jobs=1) to show what the process pool buys.

Usage: python bench/check_sweep.py
"""

from __future__ import annotations

import json
import subprocess
import sys
import time
from collections import Counter
from pathlib import Path

import pybullet_data


def main() -> int:
    data = Path(pybullet_data.getDataPath())
    on_disk = sorted(str(p) for p in data.rglob("*") if p.suffix in (".urdf", ".xacro"))
    t0 = time.perf_counter()
    proc = subprocess.run([sys.executable, "-m", "urdfkit", "check", str(data), "--json"],
                          capture_output=True, text=True)
    wall = time.perf_counter() - t0
    result = json.loads(proc.stdout)
    listed = sorted(result["files"])
    from urdfkit.checks.check import check_paths

    t1 = time.perf_counter()
    check_paths([data], jobs=1)
    serial = time.perf_counter() - t1
    codes = Counter(f["code"] for f in result["findings"])
    print(f"files on disk: {len(on_disk)}, listed in JSON: {len(listed)}, "
          f"all listed: {listed == on_disk}")
    print(f"urdfkit check (CLI, all cores): {wall:.2f} s (exit {proc.returncode}); "
          f"library, one process: {serial:.2f} s; goal < 30 s")
    print("summary:", result["summary"])
    print("findings by code:", dict(sorted(codes.items())))
    return 0 if listed == on_disk and wall < 30 else 1


if __name__ == "__main__":
    sys.exit(main())
