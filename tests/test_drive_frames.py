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

from urdfkit.catalog import build_template
from urdfkit.drive import DriveConfig, drive


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
