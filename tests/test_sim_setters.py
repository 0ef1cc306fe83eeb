"""Simulation's physical setters, each tested by what it does to the motion (issue 27.12):
set_restitution by the rebound, set_joint_damping by the decay of a free spin, set_link_damping
by the slowing of a drifting body; each against its closed form."""

from __future__ import annotations

import math
from pathlib import Path

import pytest

from urdfkit.sim import Simulation

PENDULUM = str(Path(__file__).parent.parent / "examples" / "pendulum.urdf")
BALL = """<robot name="ball"><link name="b"><inertial><mass value="1"/>
<inertia ixx="0.004" iyy="0.004" izz="0.004" ixy="0" ixz="0" iyz="0"/></inertial>
<collision><geometry><sphere radius="0.1"/></geometry></collision></link></robot>"""


def _ball(tmp_path: Path) -> str:
    path = tmp_path / "ball.urdf"
    path.write_text(BALL)
    return str(path)


def _rebound(ball: str, restitution: float) -> float:
    """Rebound speed over impact speed of a ball dropped 0.9 m onto the floor."""
    doc = {"physics": {"time_step": 0.001}, "ground": {"urdf": "plane.urdf"},
           "robots": [{"name": "ball", "urdf": ball, "position": [0, 0, 1.0]}]}
    with Simulation(doc) as s:
        s.set_link_damping("ball", 0.0, 0.0)  # Bullet's damping slows a fall (v^2 term)
        s.set_restitution("ball", None, restitution)
        s.set_restitution("ground", None, restitution)
        impact = rebound = 0.0
        for _ in range(1500):
            s.step()
            vz = s.observe("ball", ideal=True).base_lin_vel[2]
            if rebound == 0.0 and vz < 0:
                impact = min(impact, vz)
            if vz > 0.01 or rebound:
                rebound = max(rebound, vz)
    assert impact == pytest.approx(-math.sqrt(2 * 9.81 * 0.9), rel=0.01)  # it fell 0.9 m
    return rebound / -impact


@pytest.mark.parametrize("e", [0.5, 0.9])
def test_restitution_sets_the_rebound(tmp_path: Path, e: float) -> None:
    ball = _ball(tmp_path)
    # PyBullet combines two bodies' restitution by product: the ball leaves at e * e of its
    # impact speed. The solver's push-out of the contact adds a little: measured with e = 0
    # (no bounce at all), it bounds what is not restitution.
    push_out = _rebound(ball, 0.0)
    assert 0 < push_out < 0.05
    assert e * e <= _rebound(ball, e) <= e * e + push_out + 0.005


def test_joint_damping_decays_a_free_spin_exponentially() -> None:
    # No gravity, no link damping: the hinge's only torque is -b qd, so qd(t) = qd0
    # exp(-b t / M), M the joint-space inertia (constant for one hinge on a fixed base).
    # Explicit steps differ from the exponential by (h b / M)^2 / 2 per step: 2e-5 over 1 s.
    doc = {"physics": {"time_step": 0.001, "gravity": [0, 0, 0]},
           "robots": [{"name": "pendulum", "urdf": PENDULUM, "base": "fixed",
                       "initial_joints": {"hinge": {"position": 0.0, "velocity": 2.0}}}]}
    with Simulation(doc) as s:
        s.set_link_damping("pendulum", 0.0, 0.0)
        p, c, body = s.session.p, s.session.client, s.bodies["pendulum"].body
        m = p.calculateMassMatrix(body, [0.0], physicsClientId=c)[0][0]
        s.step(1000)
        undamped = s.joint_velocities("pendulum")["hinge"]
        s.reset()
        s.set_link_damping("pendulum", 0.0, 0.0)
        s.set_joint_damping("pendulum", "hinge", 0.05)
        s.step(1000)
        damped = s.joint_velocities("pendulum")["hinge"]
    assert undamped == pytest.approx(2.0, rel=1e-9)
    assert damped == pytest.approx(2.0 * math.exp(-0.05 * 1.0 / m), rel=1e-4)


def test_link_damping_slows_a_drifting_body_as_bullet_damps_it(tmp_path: Path) -> None:
    # Bullet's multibody damping is linear plus quadratic: dv/dt = -d (v + |v| v). From v0
    # that gives v(t) = 1 / ((1/v0 + 1) e^(d t) - 1), not e^(-d t) (0.4353 against 0.6065
    # after 1 s at d = 0.5).
    doc = {"physics": {"time_step": 0.001, "gravity": [0, 0, 0]},
           "robots": [{"name": "ball", "urdf": _ball(tmp_path), "position": [0, 0, 1.0],
                       "base_velocity": [1.0, 0.0, 0.0]}]}
    with Simulation(doc) as s:
        s.set_link_damping("ball", 0.5, 0.5)
        s.step(1000)
        v = s.observe("ball", ideal=True).base_lin_vel[0]
    assert v == pytest.approx(1 / (2 * math.exp(0.5) - 1), rel=2e-3)
