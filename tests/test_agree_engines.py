"""`urdfkit agree --engine pinocchio|drake|mujoco-loader`: the URDF as each engine loads it.

Each figure is held against the engine itself, asked here through its own API (Pinocchio's
model, Drake's plant, MuJoCo's compiled URDF) and against raw PyBullet: the joint indices, the
masses PyBullet invents, a continuous joint's limits Drake keeps. A model tampered with (a
mass matrix off by 1e-6) fails, and every refusal is one line with exit 2.
"""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pinocchio as pin
import pybullet as p
import pybullet_data
import pytest
from pydrake.all import MultibodyPlant, Parser
from typer.testing import CliRunner

from urdfkit.cli import app

runner = CliRunner()
DATA = Path(pybullet_data.getDataPath())
ENGINES = ["pinocchio", "drake"]


def _agree(robot: str | Path, engine: str, *args: str) -> tuple[int, dict]:
    r = runner.invoke(app, ["agree", str(robot), "--engine", engine, "--json", "--poses",
                            "20", *args])
    assert r.exit_code in (0, 1), r.output
    return r.exit_code, json.loads(r.stdout)


def _rows(data: dict) -> dict[str, dict]:
    return {r["check"]: r for r in data["rows"]}


def _drake(path: Path, root: str) -> MultibodyPlant:
    plant = MultibodyPlant(0.0)
    Parser(plant).AddModels(str(path))
    plant.WeldFrames(plant.world_frame(), plant.GetBodyByName(root).body_frame())
    plant.Finalize()
    return plant


@pytest.mark.parametrize("engine", ENGINES)
@pytest.mark.parametrize("robot", ["kuka_iiwa/model.urdf", "r2d2.urdf", "racecar/racecar.urdf"])
def test_frames_and_dynamics_agree_on_pybullet_data(engine: str, robot: str) -> None:
    _, data = _agree(robot, engine)
    rows = _rows(data)
    for what in ("frames vs PyBullet: position", "frames vs exact FK: position",
                 "frames vs exact FK: rotation", "mass matrix", "inverse dynamics"):
        assert rows[what]["status"] == "pass", rows[what]
    assert "(0 frames" not in rows["frames vs exact FK: position"]["detail"]
    assert rows["mass matrix"]["value"] < 1e-12 and rows["inverse dynamics"]["value"] < 1e-12


def test_the_index_table_is_each_engines_own() -> None:
    """Pinocchio's q and v indices and Drake's, as their own models number the joints."""
    path = DATA / "r2d2.urdf"
    _, pin_data = _agree(path, "pinocchio")
    _, drake_data = _agree(path, "drake")
    model = pin.buildModelFromUrdf(str(path))
    plant = _drake(path, "base_link")
    client = p.connect(p.DIRECT)
    try:
        body = p.loadURDF(str(path), useFixedBase=True, physicsClientId=client)
        bullet = {p.getJointInfo(body, i, physicsClientId=client)[1].decode(): i
                  for i in range(p.getNumJoints(body, physicsClientId=client))}
    finally:
        p.disconnect(client)
    assert [r["joint"] for r in pin_data["indices"]] == [
        n for n, i in sorted(bullet.items(), key=lambda x: x[1])
        if n in {model.names[k] for k in range(1, model.njoints)}]
    for row in pin_data["indices"]:
        j = model.joints[model.getJointId(row["joint"])]
        assert (row["engine"]["q"], row["engine"]["nq"], row["engine"]["v"]) == \
            (j.idx_q, j.nq, j.idx_v)
        assert row["pybullet"]["index"] == bullet[row["joint"]]
    for row in drake_data["indices"]:
        j = plant.GetJointByName(row["joint"])
        assert (row["engine"]["q"], row["engine"]["v"]) == (j.position_start(),
                                                           j.velocity_start())
    # Pinocchio sorts r2d2's joints otherwise than PyBullet: said, and known (not failed)
    order = _rows(pin_data)["joint order"]
    assert order["status"] == "known" and "left_back_wheel_joint" in order["detail"]
    # its continuous wheels hold cos and sin
    assert _rows(pin_data)["continuous joints' positions"]["value"] == sum(
        1 for j in model.joints[1:] if j.nq == 2)


MISSING_INERTIAL = """<robot name="m">
  <link name="base"><inertial><mass value="2"/>
    <inertia ixx="0.1" ixy="0" ixz="0" iyy="0.1" iyz="0" izz="0.1"/></inertial></link>
  <link name="arm"/>
  <joint name="j" type="revolute"><parent link="base"/><child link="arm"/>
    <origin xyz="0 0 0.5"/><axis xyz="0 1 0"/>
    <limit lower="-1" upper="1" effort="10" velocity="2"/></joint>
  <link name="tip"><inertial><origin xyz="0 0 0.2"/><mass value="0.5"/>
    <inertia ixx="0.01" ixy="0" ixz="0" iyy="0.01" iyz="0" izz="0.01"/></inertial></link>
  <joint name="k" type="revolute"><parent link="arm"/><child link="tip"/>
    <origin xyz="0 0 0.3"/><axis xyz="1 0 0"/>
    <limit lower="-1" upper="1" effort="10" velocity="2"/></joint>
</robot>
"""


@pytest.mark.parametrize("engine", ENGINES)
def test_a_link_without_inertial_is_named_with_pybullets_1_kg(engine: str,
                                                              tmp_path: Path) -> None:
    path = tmp_path / "m.urdf"
    path.write_text(MISSING_INERTIAL)
    code, data = _agree(path, engine)
    rows = _rows(data)
    assert code == 1
    total = rows["total mass"]
    assert total["status"] == "fail" and "arm" in total["detail"] and "1 kg" in total["detail"]
    # the figures are the engines' own: raw PyBullet's masses and the engine's
    client = p.connect(p.DIRECT)
    try:
        body = p.loadURDF(str(path), flags=p.URDF_USE_INERTIA_FROM_FILE,
                          physicsClientId=client)
        bullet = sum(p.getDynamicsInfo(body, i, physicsClientId=client)[0]
                     for i in range(-1, p.getNumJoints(body, physicsClientId=client)))
    finally:
        p.disconnect(client)
    if engine == "pinocchio":
        theirs = sum(i.mass for i in pin.buildModelFromUrdf(str(path)).inertias)
    else:
        plant = _drake(path, "base")
        theirs = sum(plant.GetBodyByName(n).default_mass() for n in ("base", "arm", "tip"))
    assert bullet == pytest.approx(3.5) and theirs == pytest.approx(2.5)
    assert total["value"] == pytest.approx(abs(bullet - theirs) / max(bullet, theirs))
    # the 1 kg changes the dynamics too: the mass matrix and torques disagree
    assert rows["mass matrix"]["status"] == "fail"
    assert rows["inverse dynamics"]["status"] == "fail"


CONTINUOUS_WITH_LIMIT = """<robot name="c">
  <link name="base"><inertial><mass value="1"/>
    <inertia ixx="0.1" ixy="0" ixz="0" iyy="0.1" iyz="0" izz="0.1"/></inertial></link>
  <link name="wheel"><inertial><mass value="1"/>
    <inertia ixx="0.1" ixy="0" ixz="0" iyy="0.1" iyz="0" izz="0.1"/></inertial></link>
  <joint name="spin" type="continuous"><parent link="base"/><child link="wheel"/>
    <axis xyz="0 0 1"/><dynamics damping="0.25"/>
    <limit lower="-0.5" upper="0.5" effort="3" velocity="4"/></joint>
</robot>
"""


def test_drake_keeps_a_continuous_joints_limit_pinocchio_does_not(tmp_path: Path) -> None:
    path = tmp_path / "c.urdf"
    path.write_text(CONTINUOUS_WITH_LIMIT)
    code, drake = _agree(path, "drake")
    limits = _rows(drake)["joint limits"]
    assert code == 1 and limits["status"] == "fail" and "spin" in limits["detail"]
    j = _drake(path, "base").GetJointByName("spin")
    assert (j.position_lower_limits()[0], j.position_upper_limits()[0]) == (-0.5, 0.5)
    code, pinocchio = _agree(path, "pinocchio")
    assert code == 0, [r for r in pinocchio["rows"] if r["status"] == "fail"]
    model = pin.buildModelFromUrdf(str(path))
    assert model.joints[1].nq == 2  # unbounded: no limit held
    # the damping both read is PyBullet's (raw getJointInfo)
    assert _rows(pinocchio)["joint damping"]["value"] == 0.0
    assert float(model.damping[0]) == 0.25


def test_a_tampered_mass_matrix_fails(monkeypatch: pytest.MonkeyPatch) -> None:
    from urdfkit.engine import pinocchio_model

    real = pinocchio_model.PinocchioModel._engine_mass_matrix

    def off(self: object) -> object:
        return real(self) * (1 + 1e-6)  # type: ignore[arg-type]

    monkeypatch.setattr(pinocchio_model.PinocchioModel, "_engine_mass_matrix", off)
    code, data = _agree("kuka_iiwa/model.urdf", "pinocchio")
    assert code == 1 and _rows(data)["mass matrix"]["status"] == "fail"


def test_the_jacobian_is_pybullets(tmp_path: Path) -> None:
    """The seam's jacobian: a point of a link, against PyBullet's calculateJacobian."""
    from urdfkit.engine.api import LoadSettings
    from urdfkit.engine.drake_model import DrakeModel
    from urdfkit.engine.pinocchio_model import PinocchioModel
    from urdfkit.engine.pybullet import PyBulletEngine

    path = str(DATA / "kuka_iiwa/model.urdf")
    e = PyBulletEngine()
    try:
        body = e.load(path, LoadSettings(fixed_base=True, inertia_from_file=True), path)
        joints = e.joints(body)
        q = [0.3, -0.4, 0.5, 1.1, -0.2, 0.7, 0.1]
        want = e.jacobian(body, 6, (0.01, 0.02, 0.05), q)
        for kind in (PinocchioModel, DrakeModel):
            got = kind(path, path, "lbr_iiwa_link_0", joints).jacobian(0, 6, (0.01, 0.02, 0.05),
                                                                       q)
            for a, b in zip(got, want, strict=True):
                assert np.allclose(a, b, atol=2e-6), kind
    finally:
        e.close()


def test_mujoco_loader_reads_the_urdf_as_mujoco_does() -> None:
    """MuJoCo's URDF reader fuses kuka's massless welded base into its world (no body)."""
    import mujoco

    r = runner.invoke(app, ["agree", "kuka_iiwa/model.urdf", "--engine", "mujoco-loader",
                            "--json", "--poses", "5"])
    assert r.exit_code == 1, r.output
    data = json.loads(r.stdout)
    assert data["engine"] == "MuJoCo's URDF reader"
    m = mujoco.MjModel.from_xml_path(str(DATA / "kuka_iiwa/model.urdf"))
    have = {m.body(i).name for i in range(m.nbody)}
    assert "lbr_iiwa_link_0" not in have and data["unmatched_links"] == ["lbr_iiwa_link_0"]
    rows = _rows(data)
    assert rows["mass matrix"]["status"] == "pass"
    assert rows["total mass"]["status"] == "pass"


@pytest.mark.parametrize(("args", "said"), [
    (["--engine", "bullet3"], "no engine named 'bullet3'"),
    (["iiwa.xml", "--engine", "pinocchio"], "MODEL.xml"),
    ([], "MODEL.xml"),
    (["--engine", "drake", "--map", "a=b"], "--map"),
])
def test_usage_errors_exit_2(args: list[str], said: str) -> None:
    r = runner.invoke(app, ["agree", "kuka_iiwa/model.urdf", *args])
    assert r.exit_code == 2 and said in r.output, r.output


@pytest.mark.parametrize("engine", ENGINES)
def test_a_file_the_engine_refuses_is_one_line_exit_2(engine: str, tmp_path: Path) -> None:
    """husky.urdf's `$(optenv ...)` origin: PyBullet loads it, urdfdom and Drake do not."""
    r = runner.invoke(app, ["agree", "husky/husky.urdf", "--engine", engine])
    assert r.exit_code == 2, r.output
    # urdfkit's own warning on the xacro left in the file, then the engine's refusal; nothing
    # of urdfdom's C-level lines
    lines = r.stderr.strip().splitlines()
    assert len(lines) == 2 and "(U009)" in lines[0], lines
    assert "husky.urdf" in lines[1] and "cannot load it" in lines[1] and "$(optenv" in lines[1]
    with pytest.raises(Exception):  # noqa: B017, PT011 - the engine's own refusal
        if engine == "pinocchio":
            pin.buildModelFromUrdf(str(DATA / "husky/husky.urdf"))
        else:
            _drake(DATA / "husky/husky.urdf", "base_link")


def _two_links(inertia: str) -> str:
    return f"""<robot name="t">
  <link name="base"><inertial><mass value="1"/>
    <inertia ixx="0.1" ixy="0" ixz="0" iyy="0.1" iyz="0" izz="0.1"/></inertial></link>
  <link name="arm"><inertial><origin xyz="0.1 0.02 0.3" rpy="0.3 0.2 0.1"/><mass value="2"/>
    <inertia {inertia}/></inertial></link>
  <joint name="j" type="revolute"><parent link="base"/><child link="arm"/>
    <axis xyz="0.3 0.4 0.866"/><limit lower="-2" upper="2" effort="5" velocity="3"/></joint>
  <link name="tip"><inertial><mass value="0.5"/>
    <inertia ixx="0.01" ixy="0" ixz="0" iyy="0.01" iyz="0" izz="0.01"/></inertial></link>
  <joint name="k" type="revolute"><parent link="arm"/><child link="tip"/>
    <origin xyz="0 0 0.4"/><axis xyz="1 0 0"/>
    <limit lower="-2" upper="2" effort="5" velocity="3"/></joint>
</robot>
"""


def _bullet_tensor(path: Path, link: int) -> np.ndarray:
    client = p.connect(p.DIRECT)
    try:
        body = p.loadURDF(str(path), flags=p.URDF_USE_INERTIA_FROM_FILE,
                          physicsClientId=client)
        mass, _, moments, _, turn = p.getDynamicsInfo(body, link, physicsClientId=client)[:5]
    finally:
        p.disconnect(client)
    r = np.array(p.getMatrixFromQuaternion(turn)).reshape(3, 3)
    return r @ np.diag(moments) @ r.T


@pytest.mark.parametrize("engine", ENGINES)
def test_products_of_inertia_pass_within_bullets_diagonalisation(engine: str,
                                                                 tmp_path: Path) -> None:
    """PyBullet diagonalises a tensor with products and drops what its sweeps leave."""
    path = tmp_path / "t.urdf"
    path.write_text(_two_links('ixx="0.03" ixy="0.004" ixz="-0.002" iyy="0.05" iyz="0.0015" '
                               'izz="0.04"'))
    code, data = _agree(path, engine)
    rows = _rows(data)
    assert code == 0, [r for r in data["rows"] if r["status"] == "fail"]
    assert "diagonalisation allowed for" in rows["inertia tensors"]["detail"]
    # raw PyBullet's tensor (in the inertial frame's axes) is off the file's, within the
    # bound allowed: 2e-6 x its trace
    file = np.array([[0.03, 0.004, -0.002], [0.004, 0.05, 0.0015], [-0.002, 0.0015, 0.04]])
    turn = np.array(p.getMatrixFromQuaternion(p.getQuaternionFromEuler((0.3, 0.2, 0.1))))
    turn = turn.reshape(3, 3)
    off = np.linalg.norm(_bullet_tensor(path, 0) - turn @ file @ turn.T, 2)
    assert 0 < off <= 2e-6 * np.trace(file)


@pytest.mark.parametrize("engine", ENGINES)
def test_a_tensor_bullet_zeroes_fails_naming_the_link(engine: str, tmp_path: Path) -> None:
    """ixx > iyy + izz: Bullet zeroes the tensor; Pinocchio and Drake keep the file's."""
    path = tmp_path / "t.urdf"
    path.write_text(_two_links('ixx="0.3" ixy="0" ixz="0" iyy="0.05" iyz="0" izz="0.05"'))
    assert not np.any(_bullet_tensor(path, 0))
    code, data = _agree(path, engine)
    rows = _rows(data)
    assert code == 1
    assert rows["inertia tensors"]["status"] == "fail"
    assert "zero tensor on arm" in rows["inertia tensors"]["detail"]
    assert rows["mass matrix"]["status"] == "fail"
