"""Issue 16's speed goals for urdfkit/SimpleDriving-v0, against the tutorial's env as written.

bench/tutorial_driving.py is the tutorial's part-2 env (resetSimulation and three loadURDF
per reset; steering and wheels set every step). Goals: a step at most 1.05x the tutorial's,
a reset at most 0.3x. Both envs run the same random actions; repetitions alternate; CPU time
(process_time), medians. Steps and resets are timed apart: when an episode ends inside the
step loop, its reset runs off the clock (the tutorial's resets reload three URDFs, and once
cost its steps 15%). Each env's sanity is printed: how many steps ran, how many episodes
ended, and that a reset leaves one car and one goal in the world. Not a unit test: figures go
in bench/README.md, from a regular install (pip install .).

Usage: python bench/gym_bench.py [--steps 3000] [--resets 200] [--repeat 9]
"""

from __future__ import annotations

import argparse
import statistics
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))


def steps_cost(env, n: int) -> tuple[float, int]:
    """CPU seconds per step, and how many episodes ended (their resets are not timed)."""
    rng = np.random.default_rng(0)
    actions = rng.uniform([0, -0.6], [1, 0.6], size=(n, 2)).astype(np.float32)
    env.reset(seed=0)
    spent = 0.0
    ended = 0
    for a in actions:
        start = time.process_time()
        done = env.step(a)[2]
        spent += time.process_time() - start
        if done:
            ended += 1
            env.reset()  # off the clock
    return spent / n, ended


def bodies(env) -> int:
    """How many bodies the env's world holds (a car, a goal and a plane after a reset)."""
    if hasattr(env, "engine"):  # urdfkit's: PyBullet through the engine's escape hatch
        return env.engine.bullet.getNumBodies()
    return env.p.getNumBodies(physicsClientId=env.client)  # the tutorial's


def resets_cost(env, n: int) -> float:
    start = time.process_time()
    for k in range(n):
        env.reset(seed=k)
    return (time.process_time() - start) / n


def main() -> int:
    from tutorial_driving import TutorialDrivingEnv

    from urdfkit.gym import SimpleDrivingEnv

    ap = argparse.ArgumentParser()
    ap.add_argument("--steps", type=int, default=3000)
    ap.add_argument("--resets", type=int, default=200)
    ap.add_argument("--repeat", type=int, default=9)
    a = ap.parse_args()
    ours, theirs = SimpleDrivingEnv(), TutorialDrivingEnv()
    step_ours, step_theirs, reset_ours, reset_theirs = [], [], [], []
    ended = {"urdfkit": 0, "tutorial": 0}
    for _ in range(a.repeat):
        cost, n = steps_cost(ours, a.steps)
        step_ours.append(cost)
        ended["urdfkit"] += n
        cost, n = steps_cost(theirs, a.steps)
        step_theirs.append(cost)
        ended["tutorial"] += n
        reset_ours.append(resets_cost(ours, a.resets))
        reset_theirs.append(resets_cost(theirs, a.resets))
    # Sanity: both did the same work (steps, episodes that ended) and a reset leaves the same
    # world (a broken baseline that loads nothing would make any ratio look good).
    print(f"sanity: {a.repeat} x {a.steps} steps each; episodes ended: {ended}; bodies after a "
          f"reset: urdfkit {bodies(ours)}, tutorial {bodies(theirs)}")
    so, st = statistics.median(step_ours), statistics.median(step_theirs)
    ro, rt = statistics.median(reset_ours), statistics.median(reset_theirs)
    print(f"step: urdfkit {so * 1e6:.1f} us, tutorial {st * 1e6:.1f} us: {so / st:.3f} "
          "(goal <= 1.05)")
    print(f"reset: urdfkit {ro * 1e3:.3f} ms, tutorial {rt * 1e3:.3f} ms: {ro / rt:.3f} "
          "(goal <= 0.3)")
    ours.close()
    theirs.close()
    return 0 if so / st <= 1.05 and ro / rt <= 0.3 else 1


if __name__ == "__main__":
    raise SystemExit(main())
