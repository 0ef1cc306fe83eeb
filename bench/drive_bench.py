"""Benchmark: `urdfkit drive` (whole process) against hand-written PyBullet loops.

Three commands, each a fresh Python process, drive the same simplecar on the same
simpleplane for the same number of steps with the same load flags, gravity and time step:

- ``urdfkit``: ``urdfkit drive --steps N --throttle 10 --steer 0.2`` (builds the
  templates, detects the wheels, samples a trajectory, prints the summary).
- ``tutorial``: the PyBullet tutorial's loop, re-sending ``setJointMotorControl2`` for every
  wheel and hinge on every step.
- ``bare``: sets the motors once, then only calls ``stepSimulation``: the physics floor.

Repetitions are interleaved (u, t, b, u, t, b, ...) so that load from other processes hits
all three alike; medians and ratios are reported. Goals: urdfkit / tutorial <= 1.0 and
urdfkit / bare <= 1.10.

Usage: python bench/drive_bench.py [--steps 20000] [--repeat 5] [--json]
"""

from __future__ import annotations

import argparse
import json
import os
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

GOAL_TUTORIAL = 1.0
URDFKIT = str(Path(sys.executable).with_name("urdfkit"))
GOAL_BARE = 1.10

# The baselines load with the same flags as `urdfkit drive`: implicit cylinders and the
# file's inertia (see urdfkit/motion/drive.py).
BASELINE = """
import sys
import pybullet as p
car_file, plane_file = sys.argv[1], sys.argv[2]
steps, per_step = int(sys.argv[3]), sys.argv[4] == "1"
p.connect(p.DIRECT)
p.setGravity(0, 0, -10)
p.setTimeStep(1 / 240)
p.loadURDF(plane_file, useFixedBase=True)
flags = p.URDF_USE_IMPLICIT_CYLINDER | p.URDF_USE_INERTIA_FROM_FILE
car = p.loadURDF(car_file, [0, 0, 0.1], flags=flags)
wheels, hinges = [1, 3, 4, 5], [0, 2]
throttle, steer = 10.0, 0.2
if per_step:
    # The tutorial: every command re-sent on every step.
    for _ in range(steps):
        for w in wheels:
            p.setJointMotorControl2(car, w, p.VELOCITY_CONTROL, targetVelocity=throttle, force=10)
        for h in hinges:
            p.setJointMotorControl2(car, h, p.POSITION_CONTROL, targetPosition=steer)
        p.stepSimulation()
else:
    for w in wheels:
        p.setJointMotorControl2(car, w, p.VELOCITY_CONTROL, targetVelocity=throttle, force=10)
    for h in hinges:
        p.setJointMotorControl2(car, h, p.POSITION_CONTROL, targetPosition=steer)
    for _ in range(steps):
        p.stepSimulation()
print(p.getBasePositionAndOrientation(car)[0])
"""


def _time(cmd: list[str]) -> tuple[float, float]:
    """Wall time and CPU time (user + sys) of one run of ``cmd``."""
    start = time.perf_counter()
    proc = subprocess.Popen(cmd, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    _, status, usage = os.wait4(proc.pid, 0)
    wall = time.perf_counter() - start
    proc.returncode = os.waitstatus_to_exitcode(status)
    if proc.returncode != 0:
        raise SystemExit(f"failed ({proc.returncode}): {' '.join(cmd)}")
    return wall, usage.ru_utime + usage.ru_stime


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--steps", type=int, default=20000)
    ap.add_argument("--repeat", type=int, default=5)
    ap.add_argument("--json", action="store_true")
    args = ap.parse_args()

    from urdfkit.model.catalog import build_template

    with tempfile.TemporaryDirectory(prefix="urdfkit-bench-") as tmp:
        folder = Path(tmp)
        car, plane = folder / "simplecar.urdf", folder / "simpleplane.urdf"
        build_template("simplecar").write(car, force=True)  # another section may have written it
        build_template("simpleplane").write(plane)
        script = folder / "baseline.py"
        script.write_text(BASELINE)

        def commands_for(steps: int) -> dict[str, list[str]]:
            n = str(steps)
            return {
                # The installed console script, as users run it (`python -m` adds runpy).
                "urdfkit": [URDFKIT, "drive", "--steps", n,
                            "--throttle", "10", "--steer", "0.2"],
                "tutorial": [sys.executable, str(script), str(car), str(plane), n, "1"],
                "bare": [sys.executable, str(script), str(car), str(plane), n, "0"],
            }

        for cmd in commands_for(10).values():  # warm the file cache; not timed
            _time(cmd)
        commands = commands_for(args.steps)
        wall: dict[str, list[float]] = {k: [] for k in commands}
        cpu: dict[str, list[float]] = {k: [] for k in commands}
        for _ in range(args.repeat):
            for name, cmd in commands.items():
                w, c = _time(cmd)
                wall[name].append(w)
                cpu[name].append(c)

    report: dict[str, dict[str, object]] = {}
    for label, times in (("cpu", cpu), ("wall", wall)):
        med = {k: statistics.median(v) for k, v in times.items()}
        report[label] = {"times": times, "median": med,
                         "ratios": {"urdfkit/tutorial": med["urdfkit"] / med["tutorial"],
                                    "urdfkit/bare": med["urdfkit"] / med["bare"]}}
    # Goals are judged on CPU time (user + sys of the whole process): on a shared machine
    # wall time mostly measures the neighbours. Wall time is reported alongside.
    r = report["cpu"]["ratios"]
    assert isinstance(r, dict)
    ok = r["urdfkit/tutorial"] <= GOAL_TUTORIAL and r["urdfkit/bare"] <= GOAL_BARE
    if args.json:
        print(json.dumps({"steps": args.steps, "repeat": args.repeat, **report,
                          "goals_met": ok}, indent=2))
    else:
        print(f"drive benchmark: {args.steps:,} steps, {args.repeat} interleaved repetitions")
        for label in ("cpu", "wall"):
            rep = report[label]
            print(f" {label} time (s), median (all runs):")
            for name, m in rep["median"].items():  # type: ignore[attr-defined]
                spread = ", ".join(f"{t:.2f}" for t in rep["times"][name])  # type: ignore[index]
                print(f"  {name:<9} {m:.3f}  ({spread})")
            ratios = rep["ratios"]
            print(f"  urdfkit / tutorial = {ratios['urdfkit/tutorial']:.3f}  "  # type: ignore[index]
                  f"(goal <= {GOAL_TUTORIAL})")
            print(f"  urdfkit / bare     = {ratios['urdfkit/bare']:.3f}  "  # type: ignore[index]
                  f"(goal <= {GOAL_BARE})")
        print("goals met (judged on CPU time)" if ok else "GOALS NOT MET (judged on CPU time)")
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main())
