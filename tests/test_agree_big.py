"""`urdfkit agree` on bodies past PyBullet's state queries (issue 48: icub, 212 joints, exit 3).

What PyBullet 3.2.7 cannot answer is measured here in raw PyBullet on generated chains
(urdfkit/model/spec.py's MAX_STATE_COORDINATES cites these tests), then agree is run on a
chain written by the test: it compares what PyBullet answers right, says in the row why it
compares nothing else, and its exact forward-kinematics rows still cover every frame.
"""

from __future__ import annotations

import json
from collections.abc import Callable
from pathlib import Path
from typing import Any

import pytest
from typer.testing import CliRunner

from urdfkit.cli import app
from urdfkit.exchange.bullet_state import unreadable_state

mujoco = pytest.importorskip("mujoco")  # in the test extra: CI never skips it
runner = CliRunner()


def chain(links: int, fixed_every: int = 0) -> str:
    """A URDF chain of ``links`` links, each joint revolute (every ``fixed_every``-th fixed)."""
    out = ['<robot name="chain">']
    out += [f'<link name="l{i}"><inertial><mass value="1"/><inertia ixx="0.01" iyy="0.02" '
            f'izz="0.03" ixy="0" ixz="0" iyz="0"/></inertial><collision><origin '
            f'xyz="0.05 0 0"/><geometry><sphere radius="0.001"/></geometry></collision></link>'
            for i in range(links)]
    for i in range(1, links):
        kind = "fixed" if fixed_every and i % fixed_every == 0 else "revolute"
        out.append(f'<joint name="j{i}" type="{kind}"><parent link="l{i - 1}"/><child '
                   f'link="l{i}"/><origin xyz="0.01 0 0.002" rpy="0.1 0 0"/><axis xyz="0 1 0"/>'
                   '<limit lower="-2" upper="2" effort="1" velocity="1"/></joint>')
    return "\n".join([*out, "</robot>"])


@pytest.fixture
def bullet(pb: tuple[Any, int]) -> Any:
    """Conftest's raw PyBullet client, its id bound to every call."""
    from urdfkit.engine.session import Bullet

    return Bullet(*pb)


@pytest.fixture
def load(bullet: Any, tmp_path: Path) -> Callable[..., int]:
    def go(links: int, fixed_every: int = 0) -> int:
        path = tmp_path / f"chain{links}.urdf"
        path.write_text(chain(links, fixed_every))
        return int(bullet.loadURDF(str(path), useFixedBase=True))
    return go


@pytest.mark.parametrize("links", [128, 129])
def test_every_state_query_fails_from_128_joints_at_every_index(
        bullet: Any, load: Callable[..., int], links: int) -> None:
    body = load(links)
    queries = [lambda: bullet.getBasePositionAndOrientation(body),
               lambda: bullet.getLinkState(body, 0), lambda: bullet.getJointState(body, 0),
               lambda: bullet.getLinkStates(body, [0]), lambda: bullet.getJointStates(body, [0])]
    if links == 128:  # 127 joints
        for query in queries:
            query()
        return
    for query in queries:
        with pytest.raises(bullet.error, match="failed"):
            query()


def test_a_joint_past_128_coordinates_reads_0_and_any_reset_zeroes_it(
        bullet: Any, load: Callable[..., int], tmp_path: Path) -> None:
    from urdfkit.engine.api import LoadSettings
    from urdfkit.engine.pybullet import PyBulletEngine

    body = load(123)  # 122 revolute joints: the last one's qIndex is 7 + 121 = 128
    assert [bullet.getJointInfo(body, i)[3] for i in (120, 121)] == [127, 128]

    def sphere(link: int) -> tuple[float, ...]:  # an AABB is no state query
        return tuple(bullet.getAABB(body, link)[0])

    bullet.resetJointState(body, 120, 0.5)
    rest = sphere(121)
    bullet.resetJointState(body, 121, 0.5)
    assert bullet.getJointState(body, 120)[0] == 0.5
    assert bullet.getJointState(body, 121)[0] == 0.0  # misread: its sphere, 5 cm out, moved
    assert max(abs(a - b) for a, b in zip(sphere(121), rest, strict=True)) > 0.01
    bullet.resetJointState(body, 5, 0.2)
    bullet.resetJointState(body, 5, 0.0)  # another joint, and back: joint 121 is at 0 again
    assert sphere(121) == pytest.approx(rest, abs=1e-12)
    engine = PyBulletEngine()  # the same chain's joints as agree reads them
    try:
        joints = engine.joints(engine.load(str(tmp_path / "chain123.urdf"),
                                           LoadSettings(fixed_base=True)))
    finally:
        engine.close()
    assert [j.q_index for j in joints[120:]] == [127, 128]
    assert "from joint j122 on" in unreadable_state(joints)
    assert unreadable_state(joints[:121]) == ""


def _agree(tmp_path: Path, links: int, fixed_every: int = 0) -> dict[str, dict]:
    urdf, xml = tmp_path / "chain.urdf", tmp_path / "chain.xml"
    urdf.write_text(chain(links, fixed_every))
    r = runner.invoke(app, ["export", "mjcf", str(urdf), "-o", str(xml)])
    assert r.exit_code == 0, r.output
    r = runner.invoke(app, ["agree", str(urdf), str(xml), "--json", "--poses", "10"])
    assert r.exit_code == 0, r.output  # exit 3 (getLinkState failed) before
    return {row["check"]: row for row in json.loads(r.stdout)["rows"]}


def test_agree_on_140_links_compares_what_pybullet_answers(tmp_path: Path) -> None:
    rows = _agree(tmp_path, 140, fixed_every=10)  # 139 joints, 126 of them revolute
    for what in ("frames vs PyBullet: position", "frames vs PyBullet: rotation"):
        assert rows[what]["status"] == "known"
        assert rows[what]["detail"].startswith("not compared: PyBullet's state queries stop "
                                               "at 128 links")
        assert "of 140" in rows[what]["detail"]
    for what in ("frames vs exact FK: position", "frames vs exact FK: rotation"):
        assert rows[what]["status"] == "pass"
        assert "(140 frames x 10 poses)" in rows[what]["detail"]
    # 126 degrees of freedom: PyBullet's mass matrix and inverse dynamics answer, and agree
    assert rows["mass matrix"]["status"] == rows["inverse dynamics"]["status"] == "pass"
    assert rows["free swing"]["status"] == "known"
    assert "stop at 128 links" in rows["free swing"]["detail"]


def test_agree_on_125_links_does_not_trust_the_misread_frames(tmp_path: Path) -> None:
    rows = _agree(tmp_path, 125)  # 124 joints: getLinkState answers, wrong (it failed by 0.01 m)
    assert rows["frames vs PyBullet: position"]["status"] == "known"
    assert "from joint j122 on" in rows["frames vs PyBullet: position"]["detail"]
    assert rows["frames vs exact FK: position"]["status"] == "pass"
    assert rows["mass matrix"]["status"] == "pass"
    assert rows["free swing"]["status"] == "known"


def test_pybullets_dynamics_are_wrong_past_128_degrees_of_freedom(
        bullet: Any, load: Callable[..., int], tmp_path: Path) -> None:
    import numpy as np

    from urdfkit.engine.mujoco_file import open_mjcf

    rows = _agree(tmp_path, 131)  # 130 revolute joints
    row = rows["mass matrix, inverse dynamics"]
    assert row["status"] == "known"
    assert "past 128 degrees of freedom" in row["detail"] and "has 130" in row["detail"]
    # raw PyBullet against MuJoCo's mass matrix of the same export: percent off, no error
    body = load(131)
    q = [0.3] * 130
    ours = np.array(bullet.calculateMassMatrix(body, q))
    with open_mjcf(tmp_path / "chain.xml") as mjcf:
        fixed = mjcf.fixed
    d = mujoco.MjData(fixed)
    d.qpos[:] = q
    mujoco.mj_forward(fixed, d)
    theirs = np.zeros((fixed.nv, fixed.nv))
    mujoco.mj_fullM(fixed, d, theirs)
    assert np.abs(ours - theirs).max() / np.abs(theirs).max() > 1e-4
