"""Issue 15's two speed goals for `urdfkit.sim.Simulation`, measured in one process.

1. ``reset()`` in place against building a new Simulation (goal: at most 1/5 of it), and
   against the fair baseline, a hand-written PyBullet rebuild of the same world
   (``resetSimulation``, the same engine parameters, both ``loadURDF`` calls, the joints'
   motors off): what a user writing their own reset pays. Wall clock (perf_counter): a reset
   is short and mostly inside PyBullet.
2. Stepping and recording as a scenario asks (a quadruped-like robot with 12 joints, a row
   every 10 steps) against a hand-written PyBullet loop that makes the same queries: per row
   the base pose and velocity and the joint states, plus the joint velocities the step
   before (for the accelerations). Goal: at most 1.05x.

Repetitions alternate the two sides so machine load hits both; CPU time (process_time),
medians. Many short runs (4,000 steps, 25 each) cancel this shared machine's drift better than
a few long ones: 20,000-step runs of 5 scattered 1.02-1.07 on the same code. Not a unit test:
figures go in bench/README.md.

Usage: python bench/sim_bench.py [--steps 4000] [--repeat 25]
"""

from __future__ import annotations

import argparse
import statistics
import time
from pathlib import Path
from typing import Any

ROBOT = Path(__file__).resolve().parent.parent / "tests" / "fixtures" / "robots" / \
    "quadruped_like.urdf"


def scenario(steps: int, every: int) -> dict:
    return {"physics": {"gravity": [0, 0, -9.81]}, "duration": steps / 240.0,
            "record": {"every": every},
            "robots": [{"name": "q", "urdf": str(ROBOT), "position": [0, 0, 0.6]}],
            "ground": "simpleplane"}


def hand_loop(steps: int, every: int) -> float:
    """The same physics and the same queries, written against PyBullet directly."""
    import tempfile

    import pybullet as p

    from urdfkit.engine.session import quiet_stdout
    from urdfkit.model.catalog import build_template

    with tempfile.TemporaryDirectory() as tmp:
        plane = Path(tmp) / "plane.urdf"
        build_template("simpleplane").write(plane)
        with quiet_stdout():
            c = p.connect(p.DIRECT)
        p.setTimeStep(1 / 240, physicsClientId=c)
        p.setGravity(0, 0, -9.81, physicsClientId=c)
        # urdfkit's default: contacts met in sorted order (a reset replays the same run).
        # Without it the loop is not the same work: on the old box ground PyBullet ran
        # 6,114 M instructions in it against urdfkit's 5,120 M, with it 5,120 M (callgrind).
        p.setPhysicsEngineParameter(deterministicOverlappingPairs=1, physicsClientId=c)
        p.setPhysicsEngineParameter(numSolverIterations=50, enableConeFriction=1,
                                    physicsClientId=c)
        with quiet_stdout():  # the loader's warnings go to fd 1
            p.loadURDF(str(plane), useFixedBase=True, physicsClientId=c)
            body = p.loadURDF(str(ROBOT), [0, 0, 0.6], flags=p.URDF_USE_INERTIA_FROM_FILE
                              | p.URDF_USE_IMPLICIT_CYLINDER, physicsClientId=c)
        joints = [j for j in range(p.getNumJoints(body, physicsClientId=c))
                  if p.getJointInfo(body, j, physicsClientId=c)[2] in (0, 1)]
        p.setJointMotorControlArray(body, joints, p.VELOCITY_CONTROL, forces=[0] * len(joints),
                                    physicsClientId=c)
        rows = []
        start = time.process_time()
        for k in range(1, steps + 1):
            p.stepSimulation(physicsClientId=c)
            if (k + 1) % every == 0:
                before = [s[1] for s in p.getJointStates(body, joints, physicsClientId=c)]
            if k % every == 0:
                pos, orn = p.getBasePositionAndOrientation(body, physicsClientId=c)
                lin, ang = p.getBaseVelocity(body, physicsClientId=c)
                states = p.getJointStates(body, joints, physicsClientId=c)
                rows.append((pos, orn, lin, ang, [s[0] for s in states],
                             [(s[1] - b) * 240 for s, b in zip(states, before, strict=True)]))
        cpu = time.process_time() - start
        p.disconnect(physicsClientId=c)
    return cpu


def ours(steps: int, every: int) -> float:
    from urdfkit.sim import Simulation

    with Simulation(scenario(steps, every)) as sim:
        start = time.process_time()
        sim.run()
        return time.process_time() - start


def hand_rebuild(repeat: int) -> tuple[float, int]:
    """A reset written by hand: resetSimulation and rebuild the same world, wall clock.

    Returns the median seconds, and the bodies the world holds after it (the sanity check:
    a plane and the robot, 2).
    """
    import tempfile

    import pybullet as p

    from urdfkit.engine.session import quiet_stdout
    from urdfkit.model.catalog import build_template

    with tempfile.TemporaryDirectory() as tmp:
        plane = Path(tmp) / "plane.urdf"
        build_template("simpleplane").write(plane)
        with quiet_stdout():  # PyBullet's loader warnings (fd 1) are not part of the figure
            c = p.connect(p.DIRECT)
            times = _rebuilds(p, c, plane, repeat)
            count = p.getNumBodies(physicsClientId=c)
        p.disconnect(physicsClientId=c)
    return statistics.median(times), count


def _rebuilds(p: Any, c: int, plane: Path, repeat: int) -> list[float]:
    times = []
    for _ in range(repeat):
        start = time.perf_counter()
        p.resetSimulation(physicsClientId=c)
        p.setTimeStep(1 / 240, physicsClientId=c)
        p.setGravity(0, 0, -9.81, physicsClientId=c)
        p.setPhysicsEngineParameter(deterministicOverlappingPairs=1, physicsClientId=c)
        p.setPhysicsEngineParameter(numSolverIterations=50, enableConeFriction=1,
                                    physicsClientId=c)
        p.loadURDF(str(plane), useFixedBase=True, physicsClientId=c)
        body = p.loadURDF(str(ROBOT), [0, 0, 0.6], flags=p.URDF_USE_INERTIA_FROM_FILE
                          | p.URDF_USE_IMPLICIT_CYLINDER, physicsClientId=c)
        joints = [j for j in range(p.getNumJoints(body, physicsClientId=c))
                  if p.getJointInfo(body, j, physicsClientId=c)[2] in (0, 1)]
        p.setJointMotorControlArray(body, joints, p.VELOCITY_CONTROL,
                                    forces=[0] * len(joints), physicsClientId=c)
        times.append(time.perf_counter() - start)
    return times


def reset_cost(repeat: int) -> tuple[float, float]:
    from urdfkit.sim import Simulation

    builds, resets = [], []
    for _ in range(repeat):
        start = time.perf_counter()
        sim = Simulation(scenario(240, 10))
        builds.append(time.perf_counter() - start)
        sim.run()
        start = time.perf_counter()
        sim.reset()
        resets.append(time.perf_counter() - start)
        sim.close()
    return statistics.median(builds), statistics.median(resets)


def main() -> int:
    ap = argparse.ArgumentParser()
    ap.add_argument("--steps", type=int, default=4000)
    ap.add_argument("--repeat", type=int, default=25)
    a = ap.parse_args()
    build, reset = reset_cost(a.repeat)
    rebuild, count = hand_rebuild(a.repeat)
    print(f"sanity: the hand-written rebuild leaves {count} bodies (a plane and the robot: 2)")
    print(f"wall clock: new Simulation {build * 1000:.1f} ms, hand-written rebuild "
          f"{rebuild * 1000:.2f} ms, reset() in place {reset * 1000:.2f} ms: "
          f"{reset / build:.3f} of a new Simulation (goal <= 0.2), "
          f"{reset / rebuild:.3f} of the hand-written rebuild")
    mine, theirs = [], []
    for _ in range(a.repeat):
        mine.append(ours(a.steps, 10))
        theirs.append(hand_loop(a.steps, 10))
    m, t = statistics.median(mine), statistics.median(theirs)
    print(f"{a.steps} steps, a row every 10: Simulation.run {m:.3f} s CPU, hand loop {t:.3f} s: "
          f"{m / t:.3f} (goal <= 1.05)")
    return 0 if reset / build <= 0.2 and m / t <= 1.05 else 1


if __name__ == "__main__":
    raise SystemExit(main())
