"""Issue 16's speed goals for urdfkit/SimpleDriving-v0, against the tutorial's env as written.

bench/tutorial_driving.py is the tutorial's part-2 env (resetSimulation and three loadURDF
per reset; steering and wheels set every step). Goals: a step at most 1.05x the tutorial's,
a reset at most 0.3x. Both envs run the same random actions; repetitions alternate; CPU time
(process_time), medians. Not a unit test: figures go in bench/README.md.

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


def steps_cost(env, n: int) -> float:
    rng = np.random.default_rng(0)
    actions = rng.uniform([0, -0.6], [1, 0.6], size=(n, 2)).astype(np.float32)
    env.reset(seed=0)
    start = time.process_time()
    for a in actions:
        if env.step(a)[2]:
            env.reset()  # episodes end: resets counted here are a few in thousands
    return (time.process_time() - start) / n


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
    for _ in range(a.repeat):
        step_ours.append(steps_cost(ours, a.steps))
        step_theirs.append(steps_cost(theirs, a.steps))
        reset_ours.append(resets_cost(ours, a.resets))
        reset_theirs.append(resets_cost(theirs, a.resets))
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
