"""Bench section for issue 18: ``urdfkit sweep``.

Goals from the issue, each measured in one run:

- one worker, 8 points: at most 0.8x eight separate ``urdfkit drive`` commands (start-up is
  paid once) -- subprocess cases, as a section of ``bench/run.py``;
- two workers on this 2-core machine: at most 0.6x one worker -- likewise;
- per-point overhead over the bare in-process :func:`urdfkit.motion.drive.drive`: at most 5% --
  in-process, standalone (``python bench/sweep_bench.py``);
- memory flat with the number of points -- peak RSS of sweeps of 8, 32 and 128 points;
- the Ray backend's overhead per point on a local cluster (standalone, when Ray is
  installed), and from it an estimate of throughput on N machines.

Run::

    python bench/run.py -n 10 sweep_bench     # the subprocess ratios
    python bench/sweep_bench.py -n 5          # in-process overhead, memory, Ray
"""

from __future__ import annotations

import argparse
import json
import shlex
import statistics
import subprocess
import sys
import time
from pathlib import Path

BENCH = Path(__file__).resolve().parent
sys.path.insert(0, str(BENCH))

from run import Case, Context  # noqa: E402

#: The 8 points: the tutorial's steer range, 10 s of driving each (the default drive).
STEERS = (0.05, 0.1, 0.15, 0.2, 0.25, 0.3, 0.35, 0.4)
ONE_WORKER_GOAL = 0.8
TWO_WORKERS_GOAL = 0.6
OVERHEAD_GOAL = 0.05


def cases(ctx: Context) -> list[Case]:
    urdfkit = " ".join(shlex.quote(a) for a in ctx.urdfkit)
    separate = "; ".join(f"{urdfkit} drive --throttle 10 --steer {s} > /dev/null"
                         for s in STEERS)
    vary = ["--vary", "steer=" + ",".join(str(s) for s in STEERS)]
    return [
        Case("8 x urdfkit drive", ["sh", "-c", separate]),
        Case("urdfkit sweep drive, 8 points, -j 1", [*ctx.urdfkit, "sweep", "drive", *vary,
                                                     "-j", "1"],
             [("8 x urdfkit drive", ONE_WORKER_GOAL)]),
        Case("urdfkit sweep drive, 8 points, -j 2", [*ctx.urdfkit, "sweep", "drive", *vary,
                                                     "-j", "2"],
             [("urdfkit sweep drive, 8 points, -j 1", TWO_WORKERS_GOAL)]),
    ]


def in_process(rounds: int) -> tuple[float, float]:
    """Median seconds for the 8 points: bare ``drive()`` calls, and ``sweep.run(jobs=1)``.

    Interleaved round by round, so the machine's noise hits both alike.
    """
    from urdfkit import sweep
    from urdfkit.motion.drive import DriveConfig, drive

    drive(DriveConfig(seconds=1.0, keep_trajectory=False))  # imports, template cache
    bare, swept = [], []
    for _ in range(rounds):
        start = time.perf_counter()
        for s in STEERS:
            drive(DriveConfig(steer=s, keep_trajectory=False))
        bare.append(time.perf_counter() - start)
        start = time.perf_counter()
        rows = list(sweep.run("drive", {}, ["steer=" + ",".join(map(str, STEERS))], jobs=1))
        swept.append(time.perf_counter() - start)
        assert len(rows) == len(STEERS) and not any(r["error"] for r in rows)
    return statistics.median(bare), statistics.median(swept)


_MEMORY = """
import resource, sys
from urdfkit import sweep
n = int(sys.argv[1])
for row in sweep.run("drive", {"seconds": 0.5}, [f"steer=0:0.4:{n}"], jobs=1):
    pass
print(resource.getrusage(resource.RUSAGE_SELF).ru_maxrss)
"""


def memory(counts: tuple[int, ...] = (8, 32, 128)) -> dict[int, float]:
    """Peak RSS (MiB) of a one-worker sweep of each number of points, in a fresh process."""
    out = {}
    for n in counts:
        text = subprocess.run([sys.executable, "-c", _MEMORY, str(n)], capture_output=True,
                              text=True, check=True).stdout
        out[n] = int(text.strip().splitlines()[-1]) / 1024
    return out


def ray_overhead(points: int = 16) -> dict[str, float] | None:
    """Per-point cost on a local Ray (2 CPUs) against the local pool of 2, and a no-op task."""
    try:
        import ray
    except ImportError:
        return None
    from urdfkit import sweep

    vary = [f"steer=0.05:0.4:{points}", "seconds=2"]
    list(sweep.run("drive", {}, vary[:1] + ["seconds=0.1"], jobs=2))  # warm the cache
    start = time.perf_counter()
    local = list(sweep.run("drive", {}, vary, jobs=2))
    t_local = time.perf_counter() - start
    ray.init(num_cpus=2, include_dashboard=False, log_to_driver=False, configure_logging=False)
    try:
        noop = ray.remote(lambda: None)
        ray.get([noop.remote() for _ in range(200)])  # start the workers
        start = time.perf_counter()
        ray.get([noop.remote() for _ in range(1000)])
        t_task = (time.perf_counter() - start) / 1000
        list(sweep.run("drive", {}, vary[:1] + ["seconds=0.1"], backend="ray"))  # warm
        start = time.perf_counter()
        remote = list(sweep.run("drive", {}, vary, backend="ray"))
        t_ray = time.perf_counter() - start
    finally:
        ray.shutdown()
    same = sorted(local, key=lambda r: r["point"]) == sorted(remote, key=lambda r: r["point"])
    return {"points": points, "local_s": t_local, "ray_s": t_ray,
            "per_point_overhead_ms": (t_ray - t_local) / points * 1000,
            "noop_task_ms": t_task * 1000, "per_point_s": t_local * 2 / points,
            "same_rows": float(same)}


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("-n", "--rounds", type=int, default=5)
    ap.add_argument("--json", action="store_true")
    a = ap.parse_args()
    bare, swept = in_process(a.rounds)
    overhead = swept / bare - 1
    mem = memory()
    ray = ray_overhead()
    report = {"bare_drive_8_s": bare, "sweep_8_s": swept, "overhead": overhead,
              "peak_rss_mib": mem, "ray": ray}
    if a.json:
        print(json.dumps(report, indent=2))
    else:
        ok = overhead <= OVERHEAD_GOAL
        print(f"in process, 8 points of 10 s: bare drive() {bare:.3f} s, sweep.run {swept:.3f} s:"
              f" overhead {overhead * 100:+.1f}% (goal <= {OVERHEAD_GOAL * 100:.0f}%) "
              f"{'ok' if ok else 'MISSED'}")
        print("peak RSS by points: " + ", ".join(f"{n}: {m:.0f} MiB" for n, m in mem.items()))
        if ray is None:
            print("ray: not installed (pip install 'urdfkit[ray]')")
        else:
            print(f"ray, {ray['points']:.0f} points of 2 s on 2 CPUs: local pool "
                  f"{ray['local_s']:.2f} s, ray {ray['ray_s']:.2f} s: "
                  f"{ray['per_point_overhead_ms']:.1f} ms more per point; a no-op task "
                  f"{ray['noop_task_ms']:.2f} ms; rows identical: {bool(ray['same_rows'])}")
    return 0 if overhead <= OVERHEAD_GOAL else 1


if __name__ == "__main__":
    raise SystemExit(main())
