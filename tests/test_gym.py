"""Gymnasium environments: the checker, determinism, isolation, vector envs, and physics.

SimpleDriving-v0 is compared step by step with bench/tutorial_driving.py, the tutorial's env
as its part 2 writes it (resetSimulation and reloading every file on reset).
"""

from __future__ import annotations

import math
import sys
import warnings
from pathlib import Path

import numpy as np
import pytest

gym = pytest.importorskip("gymnasium")

from gymnasium.utils.env_checker import check_env  # noqa: E402

from urdfkit.core.errors import InputError, ParameterError  # noqa: E402
from urdfkit.gym import SIMPLE_DRIVING_ID, ScenarioEnv, SimpleDrivingEnv  # noqa: E402

ROOT = Path(__file__).parent.parent
sys.path.insert(0, str(ROOT / "bench"))
from tutorial_driving import TutorialDrivingEnv  # noqa: E402

PENDULUM = str(ROOT / "examples" / "pendulum.urdf")
QUADRUPED = str(ROOT / "tests" / "fixtures" / "robots" / "quadruped_like.urdf")


def _rollout(env, seed: int, steps: int, action_seed: int = 9) -> np.ndarray:
    rng = np.random.default_rng(action_seed)
    obs, _ = env.reset(seed=seed)
    out = [obs]
    for _ in range(steps):
        obs, _, terminated, truncated, _ = env.step(_act(env, rng))
        out.append(obs)
        if terminated or truncated:
            break
    return np.array(out)


def _act(env, rng):
    low, high = env.action_space.low, env.action_space.high
    return rng.uniform(low, high).astype(np.float32)


def _quiet_check(env) -> None:
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # the checker's advice on unbounded observations
        check_env(env)


# --------------------------------------------------------------------------- SimpleDriving


def test_simple_driving_passes_the_checker_with_its_render_check():
    env = SimpleDrivingEnv(render_mode="rgb_array")
    try:
        _quiet_check(env)
    finally:
        env.close()


def test_registered_and_made_by_the_module_form():
    env = gym.make("urdfkit.gym:" + SIMPLE_DRIVING_ID)
    try:
        assert env.spec.max_episode_steps == 250
        obs, _ = env.reset(seed=0)
        assert obs.shape == (8,) and obs.dtype == np.float32
    finally:
        env.close()


def test_spaces_are_the_tutorials():
    env = SimpleDrivingEnv()
    try:
        assert env.action_space.low.tolist() == [0.0, pytest.approx(-0.6)]
        assert env.action_space.high.tolist() == [1.0, pytest.approx(0.6)]
        assert env.observation_space.shape == (8,)
        obs, _ = env.reset(seed=3)
        x, y, c, s, vx, vy, gx, gy = obs
        assert (x, y, c, s, vx, vy) == (0, 0, 1, 0, 0, 0)
        assert 5 <= abs(gx) <= 9 and 5 <= abs(gy) <= 9
    finally:
        env.close()


def test_in_place_reset_is_exact_whatever_came_before_and_follows_reloading():
    # An episode after a reset in place is bitwise the same after any history; and it is the
    # tutorial's own episode (resetSimulation, load plane, car and goal again) to float level
    # at first, then within chaos's growth of those differences in contact order. Measured
    # with the simplecar whose hinge arms clear each other: 1.5e-11 after one step, 8.9e-7 by
    # step 9, 1.5e-4 at step 24 (the arms' changed inertia moved the old 1e-4 over 30 steps).
    # A reset that kept anything of the last episode differs by far more from the first step.
    import pybullet as p

    ours = SimpleDrivingEnv()
    theirs = TutorialDrivingEnv(flags=p.URDF_USE_INERTIA_FROM_FILE, deterministic=True)
    try:
        first = _rollout(ours, seed=5, steps=200)
        for warm in (1, 40, 150):
            _rollout(ours, seed=1, steps=warm, action_seed=2)
            assert np.array_equal(_rollout(ours, seed=5, steps=200), first)
        reloaded = _rollout(theirs, seed=5, steps=30)
        assert np.abs(first[:10] - reloaded[:10]).max() < 1e-6
        assert np.abs(first[:31] - reloaded).max() < 1e-3
    finally:
        ours.close()
        theirs.close()


def test_same_seed_same_actions_same_observations_and_two_envs_do_not_interfere():
    one, two = SimpleDrivingEnv(), SimpleDrivingEnv()
    try:
        first = _rollout(one, seed=11, steps=120)
        rng = np.random.default_rng(0)
        two.reset(seed=4)
        # Interleave: stepping `two` between `one`'s steps changes nothing of `one`.
        obs, _ = one.reset(seed=11)
        again = [obs]
        actions = np.random.default_rng(9)
        for _ in range(len(first) - 1):
            two.step(_act(two, rng))
            obs, *_ = one.step(_act(one, actions))
            again.append(obs)
        assert np.array_equal(first, np.array(again))
    finally:
        one.close()
        two.close()


def test_reward_is_progress_and_the_goal_pays_fifty():
    env = SimpleDrivingEnv()
    try:
        obs, info = env.reset(seed=0, options={"goal": (6.0, 0.0)})
        assert info["distance"] == pytest.approx(6.0)
        total, before = 0.0, 6.0
        for _ in range(250):
            obs, reward, terminated, truncated, info = env.step([1.0, 0.0])
            if terminated:
                break
            assert reward == pytest.approx(max(before - info["distance"], 0.0), abs=1e-9)
            total += reward
            before = info["distance"]
        assert terminated and info["is_success"] and reward == 50.0
        # Straight ahead: the progress paid adds up to the distance covered (6 m to < 1 m).
        assert 5.0 - 0.15 <= total <= 5.0 + 1e-6
    finally:
        env.close()


def _wheel_speed(t: float, throttle_for: float) -> float:
    """The tutorial's wheel-speed model as a differential equation, solved exactly.

    The tutorial publishes dv/dt = 20 u - 0.2 v - 0.01 v^2 (u the throttle). With u = 1 it is
    a Riccati equation, -0.01 (v - a)(v - b) with roots a = 35.83 and b = -55.83 rad/s, so from
    rest (v - a)/(v - b) = (a/b) e^(-0.01 (a - b) t). Coasting (u = 0) from v0 it is
    v = 0.2 / ((0.2/v0 + 0.01) e^(0.2 t) - 0.01).
    """
    a = (-0.2 + math.sqrt(0.04 + 4 * 0.01 * 20)) / 0.02
    b = (-0.2 - math.sqrt(0.04 + 4 * 0.01 * 20)) / 0.02

    def driven(s: float) -> float:
        r = a / b * math.exp(-0.01 * (a - b) * s)
        return (a - r * b) / (1 - r)

    if t <= throttle_for:
        return driven(t)
    v0 = driven(throttle_for)
    return 0.2 / ((0.2 / v0 + 0.01) * math.exp(0.2 * (t - throttle_for)) - 0.01)


def test_throttle_model_integrates_the_tutorials_wheel_speed():
    # The env steps that equation at 30 Hz, as the tutorial does (explicit Euler). On a
    # contracting equation Euler's global error is about (h/2)|dv/dt| <= (1/60) 20 = 0.33
    # rad/s; that is the tolerance. The terminal speed 35.8 rad/s is 3.58 m/s on 0.1 m
    # wheels; the car's ground speed follows it (its 1.2 N m motors slip).
    env = SimpleDrivingEnv()
    try:
        env.reset(seed=0, options={"goal": (-9.0, -9.0)})
        for k in range(90):
            throttle = 1.0 if k < 60 else 0.0
            obs, *_ = env.step([throttle, 0.0])
            exact = _wheel_speed((k + 1) / 30, 2.0)
            assert abs(env._speed - exact) <= (1 / 60) * 20, k
            if k == 59:
                assert 0.7 * 35.83 < env._speed < 35.83
                assert 0.7 * env._speed * 0.1 < obs[4] <= env._speed * 0.1 * 1.01
    finally:
        env.close()


def test_leaving_the_arena_ends_the_episode_inside_the_declared_space():
    env = SimpleDrivingEnv()
    try:
        env.reset(seed=0, options={"goal": (-9.0, -9.0)})
        for _ in range(400):
            obs, reward, terminated, truncated, info = env.step([1.0, 0.0])
            assert env.observation_space.contains(obs)
            if terminated:
                break
        assert terminated and not info["is_success"] and obs[0] >= 10.0
    finally:
        env.close()


def test_rgb_frames_show_the_goal_in_the_overview():
    env = SimpleDrivingEnv(render_mode="rgb_array", camera="overview", width=320, height=240)

    def green(frame: np.ndarray) -> np.ndarray:
        return (frame[:, :, 1] > 150) & (frame[:, :, 0] < 80) & (frame[:, :, 2] < 80)

    try:
        env.reset(seed=0, options={"goal": (6.0, 6.0)})
        frame = env.render()
        assert frame.shape == (240, 320, 3) and frame.dtype == np.uint8
        cols = np.nonzero(green(frame))[1]
        assert len(cols) > 20 and cols.mean() > 160  # a green post, right of centre (+x)
        env.reset(seed=0, options={"goal": (-6.0, 6.0)})
        cols = np.nonzero(green(env.render()))[1]
        assert len(cols) > 20 and cols.mean() < 160
    finally:
        env.close()


def test_bad_actions_and_options_are_refused():
    env = SimpleDrivingEnv()
    try:
        env.reset(seed=0)
        with pytest.raises(ValueError, match="finite"):
            env.step([math.nan, 0.0])
        with pytest.raises(ValueError, match="two numbers"):
            env.step([1.0, 0.0, 0.0])
        with pytest.raises(ValueError, match="two numbers"):
            env.reset(options={"goal": "far"})
    finally:
        env.close()
    with pytest.raises(ParameterError, match="render_mode"):
        SimpleDrivingEnv(render_mode="video")
    with pytest.raises(ParameterError, match="camera"):
        SimpleDrivingEnv(camera="drone")


@pytest.mark.parametrize("mode", ["sync", "async"])
def test_vector_envs(mode):
    import urdfkit.gym  # noqa: F401  (registers the id in this process)

    envs = gym.make_vec(SIMPLE_DRIVING_ID, num_envs=2, vectorization_mode=mode)
    try:
        obs, _ = envs.reset(seed=[1, 2])
        assert obs.shape == (2, 8)
        for _ in range(5):
            obs, reward, terminated, truncated, _ = envs.step(
                np.array([[1.0, 0.0], [0.5, 0.3]], dtype=np.float32))
        assert obs.shape == (2, 8) and reward.shape == (2,)
        assert obs[0, 4] > 0 and obs[1, 4] > 0  # both cars drive
        assert not np.array_equal(obs[0, 6:], obs[1, 6:])  # their own goals
    finally:
        envs.close()


# --------------------------------------------------------------------------- ScenarioEnv


def _pendulum(**robot: object) -> dict:
    return {"physics": {"time_step": 0.01}, "duration": 2.0,
            "robots": [{"name": "pendulum", "urdf": PENDULUM, "base": "fixed",
                        "initial_joints": {"hinge": 0.5}, **robot}]}


def test_scenario_env_passes_the_checker_with_torque_actions():
    env = ScenarioEnv(_pendulum(joints=[{"until": 1.0, "mode": "torque",
                                         "targets": {"hinge": 0.0}}]),
                      render_mode="rgb_array",
                      reward=lambda o: -abs(o.motor_angles["hinge"]))
    try:
        _quiet_check(env)
        assert env.action_names == ["hinge"]
        assert env.observation_names == ["motor_angles.hinge", "motor_velocities.hinge"]
    finally:
        env.close()


def test_scenario_env_holding_torque_holds_the_pendulum():
    # m g l sin(q) at q = 0.5 with the bob 0.5 m below the hinge: the torque that holds it.
    hold = 1.0 * 9.81 * 0.5 * math.sin(0.5)
    env = ScenarioEnv(_pendulum(joints=[{"until": 1.0, "mode": "torque",
                                         "targets": {"hinge": 0.0}}]),
                      action_bounds={"hinge": (-5.0, 5.0)})
    try:
        env.reset(seed=0)
        for _ in range(100):
            obs, *_ = env.step([hold])
        assert obs[0] == pytest.approx(0.5, abs=1e-3)
        env.reset(seed=0)
        for _ in range(100):
            obs, *_ = env.step([0.0])
        assert obs[0] < 0.3  # let go, it swings down
    finally:
        env.close()


def test_scenario_env_reset_is_deterministic_with_noise_and_contacts():
    doc = {"physics": {"time_step": 1 / 240}, "ground": "simpleplane", "duration": 1.0,
           "robots": [{"name": "dog", "urdf": QUADRUPED, "position": [0, 0, 0.45],
                       "motor": {"kp": 40.0, "kd": 1.0},
                       "noise": {"motor_angles": 0.01}, "delay": 2}]}
    env = ScenarioEnv(doc, frame_skip=4)
    try:
        assert env.action_space.shape == (12,)
        assert "base_position.z" in env.observation_names  # a floating base
        first = _rollout(env, seed=7, steps=40)
        _rollout(env, seed=1, steps=25, action_seed=3)
        again = _rollout(env, seed=7, steps=40)
        assert np.array_equal(first, again)
        other = _rollout(env, seed=8, steps=40)
        assert not np.array_equal(first, other)  # the noise follows the seed
    finally:
        env.close()


def test_scenario_env_drive_actions_and_truncation():
    doc = {"physics": {"time_step": 1 / 240}, "ground": "simpleplane", "duration": 1.0,
           "robots": [{"name": "car", "template": "simplecar", "position": [0, 0, 0.1],
                       "drive": [{"until": 1.0, "throttle": 0.0}]}]}
    env = ScenarioEnv(doc, frame_skip=8, observation="dict")
    try:
        assert env.action_names == ["throttle", "steer"]
        assert env.action_space.high[1] == pytest.approx(0.5)  # the hinges' limit
        assert env.max_episode_steps == 30
        obs, _ = env.reset(seed=0)
        assert set(obs) == {"motor_angles", "motor_velocities", "base_position",
                            "base_orientation", "base_lin_vel", "base_ang_vel"}
        for k in range(30):
            obs, reward, terminated, truncated, _ = env.step([15.0, 0.0])
            assert truncated == (k == 29) and not terminated and reward == 0.0
        assert obs["base_position"][0] > 0.2  # it drove forward
    finally:
        env.close()


def test_scenario_randomize_draws_each_episode_within_its_ranges():
    doc = _pendulum(joints=[{"until": 1.0, "mode": "torque", "targets": {"hinge": 0.0}}],
                    randomize={"initial_joints": {"hinge": [-0.4, 0.4]},
                               "mass_scale": {"arm": [0.5, 2.0]}})
    env = ScenarioEnv(doc)
    try:
        starts, masses = [], []
        for seed in range(6):
            obs, _ = env.reset(seed=seed)
            starts.append(float(obs[0]))
            masses.append(env.sim.mass_matrix("pendulum")[0][0])
        assert all(-0.4 <= q <= 0.4 for q in starts) and len(set(starts)) == 6
        # M = m l^2 + I (+ the file's inertia): it follows the drawn mass.
        assert min(masses) < 0.25 * 1.0 < max(masses)
        obs, _ = env.reset(seed=0)
        assert float(obs[0]) == starts[0]
    finally:
        env.close()


def test_scenario_env_refusals():
    with pytest.raises(ParameterError, match="no robot has a controller"):
        ScenarioEnv(_pendulum())
    with pytest.raises(ParameterError, match="action_bounds names elbow"):
        ScenarioEnv(_pendulum(joints=[{"until": 1.0, "targets": {"hinge": 0.0}}]),
                    action_bounds={"elbow": (0, 1)})
    with pytest.raises(InputError, match=r"randomize.initial_joints.elbow"):
        ScenarioEnv(_pendulum(joints=[{"until": 1.0, "targets": {"hinge": 0.0}}],
                              randomize={"initial_joints": {"elbow": [0, 1]}}))
    with pytest.raises(InputError, match=r"low 1.0 is above high 0.0"):
        ScenarioEnv(_pendulum(joints=[{"until": 1.0, "targets": {"hinge": 0.0}}],
                              randomize={"initial_joints": {"hinge": [1, 0]}}))
    env = ScenarioEnv(_pendulum(joints=[{"until": 1.0, "targets": {"hinge": 0.0}}]))
    try:
        env.reset(seed=0)
        with pytest.raises(ValueError, match="1 values"):
            env.step([0.0, 1.0])
        with pytest.raises(ValueError, match="finite"):
            env.step([math.inf])
    finally:
        env.close()


def test_registered_env_passes_the_checker_headless(monkeypatch):
    # check_env makes the registered env in every listed render mode, human included: without
    # a display, human runs without a window (with a warning) instead of failing.
    monkeypatch.delenv("DISPLAY", raising=False)
    monkeypatch.delenv("WAYLAND_DISPLAY", raising=False)
    env = gym.make("urdfkit/SimpleDriving-v0")
    try:
        _quiet_check(env.unwrapped)
    finally:
        env.close()
    with pytest.warns(UserWarning, match="needs a display"):
        human = SimpleDrivingEnv(render_mode="human")
    try:
        human.reset(seed=0)
        assert human.step(np.array([1.0, 0.0], dtype=np.float32))[0].shape == (8,)
        assert human.render() is None
    finally:
        human.close()
