"""drive's built-in ground (issue 41, item 1): a slab whose top is z = 0, not the tutorial's box.

The tutorial's box (centred on its link origin) makes MiR100 veer at steer 0 with its wheels
loaded as implicit cylinders; the fixture mir_like.urdf is MiR100 with its mesh collisions
replaced by boxes, and veers the same way on that box. PyBullet's infinite plane fixes MiR but
lets six_cylinders.urdf (six wheels of one radius) circle; the slab (a box whose collision lies
below its link origin) drives both straight. Expectations are physics (rolling without slip:
v = omega r; a differential base turning at omega: R = v / omega) and PyBullet's own shape
queries.
"""

from __future__ import annotations

from pathlib import Path

import pytest

from urdfkit.model.catalog import build_template
from urdfkit.motion.drive import DriveConfig, Scenario, drive

MIR = str(Path(__file__).parent / "fixtures" / "robots" / "mir_like.urdf")
SIX = str(Path(__file__).parent / "fixtures" / "robots" / "six_cylinders.urdf")
WHEEL_R = 0.0625  # mir_like's drive wheels
THROTTLE = 10.0


@pytest.mark.parametrize("robot", [MIR, SIX], ids=["mir_like", "six_cylinders"])
def test_a_base_with_casters_drives_straight_on_the_default_ground(robot: str) -> None:
    seconds = 5.5  # 3.4 m at v = omega r
    d = drive(DriveConfig(urdf=robot, throttle=THROTTLE, steer=0.0, seconds=seconds)).to_dict()
    x, y = d["final_position"][:2]
    assert x > 3.0
    assert x == pytest.approx(THROTTLE * WHEEL_R * seconds, rel=0.05)
    assert abs(y) < 0.05
    assert abs(d["final_yaw"]) < 0.02
    assert d["problems"] == [] and d["warnings"] == []


def test_the_same_bases_veer_on_the_tutorials_box_and_on_the_infinite_plane(
        tmp_path: Path) -> None:
    """What the slab fixes: MiR on the tutorial's box, six cylinders on the plane."""
    box = build_template("simpleplane", {"shape": "box"}).write(tmp_path / "box.urdf")
    d = drive(DriveConfig(urdf=MIR, throttle=THROTTLE, steer=0.0, seconds=3.0,
                          plane=str(box))).to_dict()
    assert abs(d["final_yaw"]) > 0.1 or abs(d["final_position"][1]) > 0.05
    plane = build_template("simpleplane", {"shape": "plane"}).write(tmp_path / "plane.urdf")
    d = drive(DriveConfig(urdf=SIX, throttle=THROTTLE, steer=0.0, seconds=5.0,
                          plane=str(plane))).to_dict()
    assert abs(d["final_yaw"]) > 0.1 or abs(d["final_position"][1]) > 0.05


def test_a_mir_like_base_turns_at_v_over_omega_on_the_default_ground() -> None:
    omega = 0.3
    d = drive(DriveConfig(urdf=MIR, throttle=THROTTLE, steer=omega, seconds=25)).to_dict()
    model = THROTTLE * WHEEL_R / omega  # the axle sits under the base origin
    assert d["turning_radius"] == pytest.approx(model, rel=0.03)
    assert d["yaw_rate"] == pytest.approx(omega, rel=0.03)


def _ground_shape(sc: Scenario) -> tuple[int, tuple[float, ...]]:
    assert sc.session is not None
    p = sc.session.bullet
    shape = p.getCollisionShapeData(sc.plane, -1)[0]
    return shape[2], shape[3]


def test_the_default_ground_is_a_slab_topped_at_z0_and_the_tutorial_keeps_its_box() -> None:
    import pybullet as pb

    with Scenario(DriveConfig(seconds=0.1)) as sc:
        kind, size = _ground_shape(sc)
        assert kind == pb.GEOM_BOX and size[:3] == pytest.approx((20.0, 20.0, 0.01))
        # PyBullet wraps a collision placed off its link origin in a compound shape, whose
        # getAABB carries Bullet's 1 mm collision margin above the top face.
        assert sc.ground_top == pytest.approx(0.001, abs=1e-6)
        assert sc.ground_bounds == pytest.approx((-10.0, 10.0, -10.0, 10.0), abs=0.01)
        # The car rests on the slab: its lowest point 1 mm above the reported top.
        assert sc.session is not None
        lo = min(sc.session.bullet.getAABB(sc.body, j)[0][2]
                 for j in range(-1, sc.session.bullet.getNumJoints(sc.body)))
        assert lo == pytest.approx(0.002, abs=0.002)
    with Scenario(DriveConfig(seconds=60, keep_trajectory=False)) as sc:
        # A long run gets a slab with room for it: 10 rad/s x 0.05 m x 60 s = 30 m each way.
        _, size = _ground_shape(sc)
        assert size[0] >= 2 * 30.0
    with Scenario(DriveConfig(tutorial=True, seconds=0.1)) as sc:
        kind, size = _ground_shape(sc)
        assert kind == pb.GEOM_BOX
        assert size[:3] == pytest.approx((20.0, 20.0, 0.01))
        assert sc.ground_top == pytest.approx(0.005, abs=1e-6)  # a bare box: no margin


def test_the_gym_tutorial_env_keeps_the_tutorials_box() -> None:
    pytest.importorskip("gymnasium")
    import pybullet as pb

    from urdfkit.gym import SimpleDrivingEnv

    env = SimpleDrivingEnv()
    try:
        env.reset(seed=0)
        p = env.engine.bullet  # type: ignore[attr-defined]  # PyBullet's escape hatch
        grounds = [b for b in range(p.getNumBodies())
                   if p.getBodyInfo(b)[1].decode() == "simpleplane"]
        assert len(grounds) == 1
        shape = p.getCollisionShapeData(grounds[0], -1)[0]
        assert shape[2] == pb.GEOM_BOX and shape[3][:3] == pytest.approx((20.0, 20.0, 0.01))
    finally:
        env.close()
