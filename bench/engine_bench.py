"""Bench section for issue 50: ``urdfkit drive --engine mujoco`` against a hand-written
MuJoCo loop over the same exported car, start-up included in both.

Both run 20,000 steps of simplecar on a ground at 1/240 s as fresh processes in the same
rounds::

    python bench/run.py -n 20 engine_bench

- ``mujoco loop``: ``baselines/mujoco_loop.py`` over ``urdfkit export mjcf car.urdf --ground
  --actuators velocity`` (written once, before the rounds): import mujoco, load the file,
  ``mj_step`` 20,000 times with the wheels' velocity actuators at 10 rad/s. It checks the
  car moved.
- ``urdfkit drive --engine mujoco``: the same car and steps through urdfkit: the car read
  and guarded, PyBullet's mass properties, the export built in memory, drive's detection,
  PyBullet's motors as MuJoCo constraint rows set every step, samples and the summary.
- ``urdfkit drive`` (PyBullet), for the picture; no goal.

Goal (the issue's): drive on MuJoCo at most 1.2x the hand-written loop.
"""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

BENCH = Path(__file__).resolve().parent
sys.path.insert(0, str(BENCH))

from run import Case, Context  # noqa: E402

#: Highest acceptable ratio of ``drive --engine mujoco`` to the hand-written loop.
RATIO_GOAL = 1.2
STEPS = "20000"


def cases(ctx: Context) -> list[Case]:
    car, xml = ctx.tmp / "car.urdf", ctx.tmp / "car.xml"
    subprocess.run([*ctx.urdfkit, "build", "simplecar", "-o", str(car), "--force"],
                   check=True, capture_output=True)
    subprocess.run([*ctx.urdfkit, "export", "mjcf", str(car), "-o", str(xml), "--ground",
                    "--actuators", "velocity", "--force"], check=True, capture_output=True)
    loop = "hand-written MuJoCo loop, 20k steps"
    return [
        Case(loop, [ctx.python, str(ctx.baselines / "mujoco_loop.py"), str(xml), STEPS]),
        Case("urdfkit drive --engine mujoco, 20k steps",
             [*ctx.urdfkit, "drive", "--engine", "mujoco", "--steps", STEPS],
             [(loop, RATIO_GOAL)]),
        Case("urdfkit drive (PyBullet), 20k steps", [*ctx.urdfkit, "drive", "--steps", STEPS]),
    ]
