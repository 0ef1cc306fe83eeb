"""The gym envs under misuse: actions that are not real numbers, steps after the end, calls after
close, nonsense episode lengths, and a NaN in a vector env (issue 26, class 8)."""

from __future__ import annotations

import warnings
from pathlib import Path

import numpy as np
import pytest

gym = pytest.importorskip("gymnasium", reason="urdfkit.gym needs the gym extra")

from urdfkit.core.errors import ParameterError  # noqa: E402
from urdfkit.gym import ScenarioEnv, SimpleDrivingEnv  # noqa: E402

PENDULUM = Path(__file__).resolve().parents[1] / "examples" / "pendulum_servo.json"


@pytest.mark.parametrize("action", [np.array([1 + 2j, 0.1]), [np.nan, 0.0], [0.5, np.inf],
                                    [1, 2, 3], ["a", "b"], None])
def test_simple_driving_refuses_an_action_that_is_not_two_real_numbers(action: object) -> None:
    env = SimpleDrivingEnv()
    try:
        env.reset(seed=0)
        before = env.engine.base_pose(env.car)
        with pytest.raises(ValueError, match="two numbers|finite"):
            env.step(action)
        after = env.engine.base_pose(env.car)
        assert before == after  # refused before anything reached PyBullet
    finally:
        env.close()


def test_scenario_env_refuses_complex_and_nan_actions() -> None:
    env = ScenarioEnv(PENDULUM)
    try:
        env.reset(seed=0)
        t = env.sim.step_count
        with pytest.raises(ValueError, match="real numbers, got complex128"):
            env.step(np.array([1 + 1j]))
        with pytest.raises(ValueError, match="finite"):
            env.step([np.nan])
        assert env.sim.step_count == t
    finally:
        env.close()


@pytest.mark.parametrize("bad", [-5, 0, 2.5, True])
def test_max_episode_steps_must_be_a_positive_integer(bad: object) -> None:
    with pytest.raises(ParameterError, match="max_episode_steps must be an integer >= 1"):
        ScenarioEnv(PENDULUM, max_episode_steps=bad)  # type: ignore[arg-type]


def test_a_step_after_the_episode_ended_warns_once_and_reset_clears_it() -> None:
    env = ScenarioEnv(PENDULUM, max_episode_steps=2)
    try:
        env.reset(seed=0)
        with warnings.catch_warnings():
            warnings.simplefilter("error")  # no warning while the episode runs
            assert env.step([0.1])[3] is False
            assert env.step([0.1])[3] is True  # truncated at 2 steps
        with pytest.warns(UserWarning, match="after the episode ended"):
            env.step([0.1])
        with warnings.catch_warnings():
            warnings.simplefilter("error")
            env.step([0.1])  # once per episode, not every step
            env.reset(seed=1)
            env.step([0.1])
    finally:
        env.close()


@pytest.mark.parametrize("make", [SimpleDrivingEnv, lambda: ScenarioEnv(PENDULUM)])
def test_reset_and_step_after_close_say_the_env_is_closed(make: object) -> None:
    env = make()  # type: ignore[operator]
    env.reset(seed=0)
    env.close()
    env.close()  # twice is fine
    with pytest.raises(RuntimeError, match="is closed; make a new one"):
        env.reset()
    with pytest.raises(RuntimeError, match="is closed"):
        env.step(env.action_space.sample())


def test_a_nan_action_in_an_async_vector_env_comes_back_as_the_envs_error() -> None:
    vec = gym.vector.AsyncVectorEnv([lambda: ScenarioEnv(PENDULUM) for _ in range(2)])
    try:
        vec.reset(seed=0)
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")  # gymnasium prints the worker's traceback
            with pytest.raises(ValueError, match=r"the action must be finite, got \[nan\]"):
                vec.step(np.array([[np.nan], [0.0]]))
    finally:
        vec.close(terminate=True)
