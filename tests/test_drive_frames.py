"""drive reads the robot in its base link's frame, not PyBullet's inertial frame (issue 24,
items 1 and 3): inertia products rotate the inertial frame and grow getAABB; an
<inertial><origin rpy> turns it. Neither may change which wheels drive, where the car starts,
or the yaw it reports."""

from __future__ import annotations

import math
import re
from pathlib import Path

import pybullet as p
import pytest

from urdfkit.model.catalog import build_template
from urdfkit.motion.drive import DriveConfig, drive


def _car(tmp_path: Path, name: str, inertial: str | None = None,
         products: bool = False) -> Path:
    text = build_template("simplecar").to_bytes().decode()
    i = text.index('<link name="base_link">')
    j = text.index("</link>", i)
    body = text[i:j]
    if products:
        body = re.sub(r'ixy="[^"]*"', 'ixy="0.02"', body, count=1)
        body = re.sub(r'ixz="[^"]*"', 'ixz="0.02"', body, count=1)
    if inertial is not None:
        body = body.replace("<inertial>", f"<inertial>{inertial}", 1)
    path = tmp_path / name
    path.write_text(text[:i] + body + text[j:])
    return path


def _run(path: Path, seconds: float = 6.0) -> object:
    return drive(DriveConfig(urdf=str(path), throttle=10, steer=0.2, seconds=seconds))


def test_inertia_products_change_neither_wheels_nor_start(tmp_path: Path) -> None:
    plain = _run(_car(tmp_path, "plain.urdf"))
    tilted = _car(tmp_path, "products.urdf", products=True)
    # The products do rotate PyBullet's inertial frame, and grow the AABB below the shapes.
    c = p.connect(p.DIRECT)
    try:
        body = p.loadURDF(str(tilted), flags=p.URDF_USE_INERTIA_FROM_FILE, physicsClientId=c)
        assert abs(p.getDynamicsInfo(body, -1, physicsClientId=c)[4][3]) < 0.999
    finally:
        p.disconnect(physicsClientId=c)
    products = _run(tilted)
    for r in (plain, products):
        d = r.to_dict()  # type: ignore[attr-defined]
        assert len(d["drivetrain"]["wheels"]) == 4 and len(d["drivetrain"]["hinges"]) == 2
        assert d["drivetrain"]["steering"] == "ackermann"
    start = [r.trajectory.rows[0] for r in (plain, products)]  # type: ignore[attr-defined]
    assert start[1][3] == pytest.approx(start[0][3], abs=1e-6)  # the same start height
    assert start[1][6] == pytest.approx(0.0, abs=1e-9)  # and no yaw at rest
    # The same circle: only the inertia tensor differs, which a steady turn barely feels.
    radii = [r.to_dict()["turning_radius"] for r in (plain, products)]  # type: ignore[attr-defined]
    assert radii[1] == pytest.approx(radii[0], rel=0.01)


def test_a_turned_inertial_frame_does_not_turn_the_reported_yaw(tmp_path: Path) -> None:
    car = _car(tmp_path, "turned.urdf", inertial='<origin xyz="0.02 0 0" rpy="0 0 0.16"/>')
    r = _run(car, seconds=3.0)
    rows = r.trajectory.rows  # type: ignore[attr-defined]
    assert rows[0][6] == pytest.approx(0.0, abs=1e-6)  # yaw at rest: the link's, 0 (to float32)
    d = r.to_dict()  # type: ignore[attr-defined]
    # Less than half a turn: the final yaw is the heading change itself.
    assert abs(d["heading_change"]) < math.pi
    assert d["final_yaw"] == pytest.approx(d["heading_change"], abs=1e-5)
    # The path is the link frame's: at rest it starts at the origin, not 2 cm ahead of it.
    # (to float32: PyBullet's poses are single precision)
    assert rows[0][1] == pytest.approx(0.0, abs=1e-6) and rows[0][2] == pytest.approx(0.0,
                                                                                    abs=1e-6)


def test_a_wheel_whose_inertial_frame_is_turned_still_turns_about_its_own_axis(
        tmp_path: Path) -> None:
    """getJointInfo's axis is in the child's inertial frame: an <inertial><origin rpy> (or
    inertia products, with the file's inertia) turns that frame, and the axis must turn with
    it. A PR2 caster swivel read 32 degrees off vertical before, so its wheels were taken for
    skid-steered ones."""
    text = build_template("simplecar").to_bytes().decode()
    text = text.replace('<inertial>\n      <mass value="0.3"/>',
                        '<inertial>\n      <origin rpy="0.9 0 0.6"/>\n      <mass value="0.3"/>')
    assert text.count('rpy="0.9 0 0.6"') == 4  # every wheel
    path = tmp_path / "turned_wheels.urdf"
    path.write_text(text)
    c = p.connect(p.DIRECT)
    try:
        body = p.loadURDF(str(path), flags=p.URDF_USE_INERTIA_FROM_FILE, physicsClientId=c)
        wheel = next(j for j in range(p.getNumJoints(body, physicsClientId=c))
                     if p.getJointInfo(body, j, physicsClientId=c)[1] == b"base_to_left_back_wheel")
        # The reported axis is far from the file's (0 1 0) in the link frame...
        assert abs(p.getJointInfo(body, wheel, physicsClientId=c)[13][1]) < 0.6
    finally:
        p.disconnect(physicsClientId=c)
    plain, turned = _run(_car(tmp_path, "plain.urdf")), _run(path)
    for r in (plain, turned):  # ...yet all four wheels and both hinges are found, and drive
        d = r.to_dict()  # type: ignore[attr-defined]
        assert len(d["drivetrain"]["wheels"]) == 4 and len(d["drivetrain"]["hinges"]) == 2
    radii = [r.to_dict()["turning_radius"] for r in (plain, turned)]  # type: ignore[attr-defined]
    assert radii[1] == pytest.approx(radii[0], rel=0.02)
