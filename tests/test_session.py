"""Session.bullet binds the session's client to every call: checked against raw PyBullet."""

from __future__ import annotations

from pathlib import Path

import pybullet as p
import pybullet_data
import pytest

from urdfkit.engine.session import Session, restore_clean


def test_each_session_reaches_only_its_own_client(simplecar_urdf: Path) -> None:
    with Session() as a, Session() as b:
        assert a.client != b.client
        car = a.load_urdf(simplecar_urdf)
        assert a.bullet.getNumBodies() == p.getNumBodies(physicsClientId=a.client) == 1
        assert b.bullet.getNumBodies() == p.getNumBodies(physicsClientId=b.client) == 0
        assert a.bullet.getNumJoints(car) == p.getNumJoints(car, physicsClientId=a.client)
        # Keywords pass through with the id; constants and the error type are the module's.
        a.bullet.resetJointState(car, 1, targetValue=0.5)
        assert p.getJointState(car, 1, physicsClientId=a.client)[0] == 0.5
        assert a.bullet.JOINT_REVOLUTE == p.JOINT_REVOLUTE and a.bullet.error is p.error


def test_a_closed_session_never_reaches_a_later_client(simplecar_urdf: Path) -> None:
    old = Session()
    old.close()
    with Session() as new:  # PyBullet hands out the freed id again
        new.load_urdf(simplecar_urdf)
        with pytest.raises(p.error):
            old.bullet.getNumBodies()
        with pytest.raises(p.error):
            old.call("getNumBodies")
        assert new.bullet.getNumBodies() == 1


def _run(s: Session, body: int, steps: int) -> list[tuple[float, ...]]:
    out = []
    for _ in range(steps):
        s.bullet.stepSimulation()
        out.append(tuple(p.getBasePositionAndOrientation(body, physicsClientId=s.client)[0]))
    return out


def test_restore_clean_takes_the_binding_or_the_module_and_id(simplecar_urdf: Path) -> None:
    # Both forms reset the same way: the steps after each are bitwise the same.
    with Session() as s:
        s.bullet.setGravity(0, 0, -10)
        s.bullet.loadURDF(str(Path(pybullet_data.getDataPath()) / "plane.urdf"))
        car = s.load_urdf(simplecar_urdf)
        start = p.saveState(physicsClientId=s.client)
        first = _run(s, car, 120)
        restore_clean(s.bullet, start, [car])
        after_bound = _run(s, car, 120)
        restore_clean(p, s.client, start, [car])
        after_plain = _run(s, car, 120)
    assert after_bound == after_plain
    assert first[-1][2] != first[0][2]  # the car settled: the steps did something
