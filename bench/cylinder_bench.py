"""What URDF_USE_IMPLICIT_CYLINDER costs per physics step, and what it buys.

Without the flag PyBullet turns every ``<cylinder>`` into a convex mesh, so simplecar's wheels
roll on facets. The flag keeps them true cylinders. This drives the built-in simplecar
straight for N steps both ways, in fresh processes, interleaved, and reports:

- CPU time per step, and the ratio (the cost);
- how smooth the ride is: the base's vertical wobble (standard deviation of z over the second
  half) and its sideways drift after the run (what the flag buys).

Not a unit test: figures go in bench/README.md and docs/drive.md.

Usage: python bench/cylinder_bench.py [--steps 20000] [--repeat 5]
"""

from __future__ import annotations

import argparse
import json
import statistics
import subprocess
import sys
import tempfile
from pathlib import Path

RUN = """
import json, statistics, sys, time
import pybullet as p
car_file, plane_file = sys.argv[1], sys.argv[2]
steps, implicit = int(sys.argv[3]), sys.argv[4] == "1"
p.connect(p.DIRECT)
p.setGravity(0, 0, -10)
p.setTimeStep(1 / 240)
p.loadURDF(plane_file, useFixedBase=True)
flags = p.URDF_USE_INERTIA_FROM_FILE | (p.URDF_USE_IMPLICIT_CYLINDER if implicit else 0)
car = p.loadURDF(car_file, [0, 0, 0.106], flags=flags)
for w in [1, 3, 4, 5]:
    p.setJointMotorControl2(car, w, p.VELOCITY_CONTROL, targetVelocity=10, force=10)
for h in [0, 2]:
    p.setJointMotorControl2(car, h, p.POSITION_CONTROL, targetPosition=0)
zs = []
start = time.process_time()
for i in range(steps):
    p.stepSimulation()
    if i >= steps // 2 and i % 24 == 0:
        zs.append(p.getBasePositionAndOrientation(car)[0][2])
cpu = time.process_time() - start
x, y, _ = p.getBasePositionAndOrientation(car)[0]
print(json.dumps({"cpu": cpu, "z_std": statistics.pstdev(zs), "x": x, "y": y}))
"""


def main() -> int:
    ap = argparse.ArgumentParser()
    ap.add_argument("--steps", type=int, default=20000)
    ap.add_argument("--repeat", type=int, default=5)
    a = ap.parse_args()
    from urdfkit.model.catalog import build_template

    with tempfile.TemporaryDirectory() as tmp:
        car, plane = Path(tmp) / "car.urdf", Path(tmp) / "plane.urdf"
        build_template("simplecar").write(car)
        build_template("simpleplane", {"size": "500"}).write(plane)
        runs: dict[str, list[dict[str, float]]] = {"implicit": [], "mesh": []}
        for _ in range(a.repeat):
            for name, flag in (("implicit", "1"), ("mesh", "0")):
                out = subprocess.run([sys.executable, "-c", RUN, str(car), str(plane),
                                      str(a.steps), flag], capture_output=True, text=True,
                                     check=True).stdout
                runs[name].append(json.loads(out.strip().splitlines()[-1]))
    med = {k: statistics.median(r["cpu"] for r in v) for k, v in runs.items()}
    print(f"{a.steps} steps of simplecar driving straight, {a.repeat} interleaved runs each")
    for k, v in runs.items():
        last = v[-1]
        print(f"  {k:8s} {med[k] / a.steps * 1e6:7.1f} us/step   z wobble "
              f"{last['z_std'] * 1000:7.3f} mm   sideways drift {last['y'] * 1000:8.1f} mm "
              f"after {last['x']:.1f} m")
    print(f"  cost of URDF_USE_IMPLICIT_CYLINDER: {med['implicit'] / med['mesh']:.2f}x per step")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
