"""An MJCF file as ``agree`` loads it: :class:`MjcfModel` answers as the URDF in PyBullet does.

The file is the export (``urdfkit export mjcf``) compiled by MuJoCo's own loader; the model is
its base-welded copy in PyBullet's indices, link and joint names matched as the export keeps
them. Each answer is held against raw PyBullet on the same URDF, loaded fixed: joints, link
frames (PyBullet's are float32), the mass matrix, inverse dynamics and Jacobians; a link the
export fuses into its parent's body is a site there, without mass of its own.
"""

from __future__ import annotations

from collections.abc import Iterator
from pathlib import Path
from typing import Any

import pytest
from typer.testing import CliRunner

from urdfkit.cli import app
from urdfkit.core.errors import EngineError, ParameterError
from urdfkit.engine.api import LoadSettings
from urdfkit.engine.pybullet import PyBulletEngine

mujoco = pytest.importorskip("mujoco")  # in the test extra: CI never skips it
runner = CliRunner()


def _export(robot: str, out: Path) -> Path:
    r = runner.invoke(app, ["export", "mjcf", robot, "-o", str(out)])
    assert r.exit_code == 0, r.output
    return out


@pytest.fixture(scope="module")
def kuka(tmp_path_factory: pytest.TempPathFactory) -> Path:
    return _export("kuka_iiwa/model.urdf", tmp_path_factory.mktemp("kuka") / "iiwa.xml")


@pytest.fixture(scope="module")
def r2d2(tmp_path_factory: pytest.TempPathFactory) -> Path:
    return _export("r2d2.urdf", tmp_path_factory.mktemp("r2d2") / "r2d2.xml")


def _urdf(name: str) -> str:
    import pybullet_data

    return str(Path(pybullet_data.getDataPath()) / name)


@pytest.fixture
def both(request: pytest.FixtureRequest) -> Iterator[Any]:
    """(engine, body, model): the URDF loaded fixed in PyBullet, the export's MjcfModel."""
    from urdfkit.engine.mujoco_file import open_mjcf
    from urdfkit.engine.mujoco_file_model import MjcfModel

    urdf, xml = request.param
    engine = PyBulletEngine()
    try:
        body = engine.load(_urdf(urdf), LoadSettings(fixed_base=True, inertia_from_file=True))
        engine.set_gravity((0.0, 0.0, -9.81))
        with open_mjcf(request.getfixturevalue(xml)) as f:
            names = engine.link_names(body)
            frames = {n: ("body", f.tree.bodies[n]) if n in f.tree.bodies else
                      ("site", f.tree.sites[n]) for n in names}
            model = MjcfModel(f, names[0], engine.joints(body), frames, f.tree.joints)
            yield engine, body, model
    finally:
        engine.close()


@pytest.mark.parametrize("both", [("kuka_iiwa/model.urdf", "kuka")], indirect=True)
def test_the_files_joints_are_pybullets(both: Any) -> None:
    import numpy as np

    from urdfkit.model.spec import quat_to_matrix

    engine, body, model = both
    ours, theirs = engine.joints(body), model.joints(0)
    assert [j.name for j in theirs] == [j.name for j in ours]
    for a, b in zip(ours, theirs, strict=True):
        assert (b.kind, b.limited, b.index, b.link) == (a.kind, a.limited, a.index, a.link)
        assert (b.lower, b.upper, b.damping) == pytest.approx((a.lower, a.upper, a.damping),
                                                              abs=1e-12)
        # each axis in its link's inertial frame, turned back into the link frame: the URDF's
        # <axis xyz="0 0 1"> on both sides (the file's inertial frames are MuJoCo's own)
        for side, j in ((engine, a), (model, b)):
            turn = np.array(quat_to_matrix(side.dynamics(0 if side is model else body,
                                                         j.index).inertial_orientation))
            assert turn @ np.array(j.axis) == pytest.approx([0.0, 0.0, 1.0], abs=1e-9)


@pytest.mark.parametrize("both", [("kuka_iiwa/model.urdf", "kuka")], indirect=True)
def test_frames_mass_matrix_inverse_dynamics_and_jacobians_are_pybullets(both: Any) -> None:
    import numpy as np

    engine, body, model = both
    rng = np.random.default_rng(5)
    n = len(model.joints(0))
    for _ in range(5):
        q, qd, qdd = (list(rng.uniform(-1.5, 1.5, n)) for _ in range(3))
        engine.set_joint_positions(body, q)
        model.set_joint_positions(0, q)
        for (p, o), (mp, mo) in zip(engine.link_frames(body), model.link_frames(0),
                                    strict=True):
            assert mp == pytest.approx(p, abs=1e-6)  # PyBullet's frames are float32
            assert abs(float(np.dot(mo, o))) == pytest.approx(1.0, abs=1e-6)
        pm, mm = np.array(engine.mass_matrix(body, q)), np.array(model.mass_matrix(0, q))
        assert np.abs(pm - mm).max() <= 1e-9 * np.abs(pm).max()
        tau, mtau = (np.array(engine.inverse_dynamics(body, q, qd, qdd)),
                     np.array(model.inverse_dynamics(0, q, qd, qdd)))
        assert np.abs(tau - mtau).max() <= 1e-9 * np.abs(tau).max()
        # kuka's <inertial> frames are not turned: PyBullet's point and rows are the link's
        for side, b in ((engine, body), (model, 0)):
            lin, ang = side.jacobian(b, 5, (0.1, 0.0, 0.05), q)
            if side is engine:
                want = np.array(lin), np.array(ang)
            else:
                assert np.array(lin) == pytest.approx(want[0], abs=1e-9)
                assert np.array(ang) == pytest.approx(want[1], abs=1e-9)


@pytest.mark.parametrize("both", [("r2d2.urdf", "r2d2")], indirect=True)
def test_a_fused_link_is_a_site_without_mass_where_pybullet_puts_its_frame(both: Any) -> None:
    engine, body, model = both
    links = range(-1, len(model.joints(0)))
    # masses from a floating load: PyBullet reports 0 kg for a fixed base's root
    free = engine.load(_urdf("r2d2.urdf"), LoadSettings(inertia_from_file=True))
    ours = [engine.dynamics(free, k).mass for k in links]
    engine.remove_body(free)
    theirs = [model.dynamics(0, k).mass for k in links]
    # right_base hangs from right_leg, right_leg from base_link, by fixed joints: sites of
    # base_link's body, which carries their mass, as PyBullet's links do
    names = model.link_names(0)
    for fused in ("right_leg", "right_base", "left_leg", "left_base"):
        k = names.index(fused)
        assert theirs[k] == 0.0 < ours[k]
    assert sum(theirs) == pytest.approx(sum(ours), rel=1e-12)
    assert theirs[0] == pytest.approx(sum(ours[names.index(n)] for n in (
        "base_link", "right_leg", "right_base", "left_leg", "left_base")), rel=1e-12)
    model.set_joint_positions(0, [0.3] * sum(j.kind != "fixed" for j in model.joints(0)))
    engine.set_joint_positions(body, [0.3] * sum(j.kind != "fixed" for j in engine.joints(body)))
    for (p, _), (mp, _) in zip(engine.link_frames(body), model.link_frames(0), strict=True):
        assert mp == pytest.approx(p, abs=1e-6)


@pytest.mark.parametrize("both", [("kuka_iiwa/model.urdf", "kuka")], indirect=True)
def test_what_the_file_cannot_answer_is_refused_by_name(both: Any) -> None:
    from urdfkit.engine.mujoco_file_model import MjcfModel

    engine, body, model = both
    with pytest.raises(ParameterError, match="no floating base"):
        model.floating_mass_matrix(0, (0.0, 0.0, 0.0), (0.0, 0.0, 0.0, 1.0), [0.0] * 7)
    with pytest.raises(ParameterError, match="body 0, not 1"):
        model.joints(1)
    partial = MjcfModel(model.file, model.link_names(0)[0], engine.joints(body),
                        {"lbr_iiwa_link_0": ("body", 1)}, {})
    with pytest.raises(EngineError, match="link 'lbr_iiwa_link_1' has no body or site"):
        partial.link_frames(0)
    assert {j.kind for j in partial.joints(0)} == {"fixed"}  # nothing matched moves


def test_a_swing_of_the_file_is_pybullets_swing(kuka: Path) -> None:
    """Swing, the file's side of agree's swing, against PyBullet's own step by step."""
    from urdfkit.engine.mujoco_file import open_mjcf
    from urdfkit.engine.mujoco_file_swing import Swing

    engine = PyBulletEngine()
    try:
        body = engine.load(_urdf("kuka_iiwa/model.urdf"),
                           LoadSettings(fixed_base=True, inertia_from_file=True))
        engine.set_gravity((0.0, 0.0, -9.81))
        engine.set_time_step(1e-3)
        with open_mjcf(kuka) as f:
            ids = [f.tree.joints[j.name] for j in engine.joints(body)]
            swing = Swing(f, False, {}, 1e-3, None, ids)
            swing.start(dict.fromkeys(ids, 0.4), {})
            for k in range(7):
                engine.reset_joint(body, k, 0.4)
                engine.change_dynamics(body, k, linearDamping=0.0, angularDamping=0.0)
            engine.change_dynamics(body, -1, linearDamping=0.0, angularDamping=0.0)
            engine.motors(body, list(range(7)), "velocity", [0.0] * 7, forces=[0.0] * 7)
            for _ in range(200):
                swing.step()
                engine.step()
            moved = [r[0] for r in engine.joint_rows(body, range(7))]
            assert swing.positions() == pytest.approx(moved, abs=1e-9)
            assert max(abs(x - 0.4) for x in moved) > 0.01  # it swung
    finally:
        engine.close()
