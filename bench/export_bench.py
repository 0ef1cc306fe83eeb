"""Bench section for issue 40: ``urdfkit export mjcf`` of kuka_iiwa against ``urdfkit joints``.

Goal from the issue: an export (resolve, guard, read the URDF, write the MJCF, copy 16 STL
meshes) costs at most 2x one ``urdfkit joints`` run of the same robot (which loads it in
PyBullet). Both are timed as fresh subprocesses in the same rounds::

    python bench/run.py -n 20 export_bench

``--verify`` (both engines, 100 poses, a 1 s swing) is timed too, against no goal: it is the
proof, paid only when asked for.
"""

from __future__ import annotations

import sys
from pathlib import Path

BENCH = Path(__file__).resolve().parent
sys.path.insert(0, str(BENCH))

from run import Case, Context  # noqa: E402

#: Highest acceptable ratio of ``export mjcf`` to ``joints`` (the issue's).
RATIO_GOAL = 2.0
ROBOT = "kuka_iiwa/model.urdf"


def cases(ctx: Context) -> list[Case]:
    out = str(ctx.tmp / "iiwa.xml")
    return [
        Case("urdfkit joints kuka_iiwa", [*ctx.urdfkit, "joints", ROBOT]),
        Case("urdfkit export mjcf kuka_iiwa",
             [*ctx.urdfkit, "export", "mjcf", ROBOT, "-o", out, "--force"],
             [("urdfkit joints kuka_iiwa", RATIO_GOAL)]),
        Case("urdfkit export mjcf kuka_iiwa --verify",
             [*ctx.urdfkit, "export", "mjcf", ROBOT, "-o", out, "--force", "--verify"]),
    ]
