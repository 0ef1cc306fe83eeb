"""urdfkit.inspect as a library: decoded tables against raw PyBullet, tree, diagnostics."""

from __future__ import annotations

import math
from pathlib import Path

import pytest

from urdfkit.core.errors import ParameterError
from urdfkit.draw.tree import kinematic_tree
from urdfkit.engine.report import inspect_file, tidy_diagnostics
from urdfkit.engine.session import LoadOptions
from urdfkit.inspect import JOINT_INFO_FIELDS, filter_joints
from urdfkit.model.spec import quat_to_rpy
from urdfkit.sources.resolve import open_input, resolve

# A link with an off-diagonal <inertia> and an offset, rotated inertial frame, and a child link
# with no <inertial> at all (which PyBullet gives 1 kg and complains about on stdout).
OFFDIAG = """<robot name="t">
  <link name="a">
    <inertial><origin xyz="0.1 0 0" rpy="0 0 0.3"/><mass value="2"/>
      <inertia ixx="1" ixy="0.2" ixz="0" iyy="2" iyz="0" izz="3"/></inertial>
    <collision><geometry><box size="1 1 1"/></geometry></collision>
  </link>
  <link name="b"/>
  <joint name="j" type="continuous"><parent link="a"/><child link="b"/>
    <axis xyz="0 1 0"/></joint>
</robot>
"""


@pytest.fixture
def offdiag(tmp_path: Path) -> Path:
    path = tmp_path / "offdiag.urdf"
    path.write_text(OFFDIAG)
    return path


def test_joint_table_matches_raw_getjointinfo(simplecar_urdf: Path, pb) -> None:
    p, client = pb
    options = LoadOptions()
    with open_input(simplecar_urdf) as r:
        report = inspect_file(r, options)
    body = p.loadURDF(str(simplecar_urdf), flags=options.flags(p), physicsClientId=client)
    assert len(report.joints) == p.getNumJoints(body, physicsClientId=client) == 6
    for j in report.joints:
        raw = p.getJointInfo(body, j.joint_index, physicsClientId=client)
        d = j.to_dict()
        assert list(d)[:17] == list(JOINT_INFO_FIELDS)
        assert d["jointName"] == raw[1].decode()
        assert d["linkName"] == raw[12].decode()
        assert d["parentFrameOrn"] == list(raw[15])
        rpy = p.getEulerFromQuaternion(raw[15])
        assert j.parent_frame_rpy == pytest.approx(rpy, abs=1e-9)


def test_continuous_joint_is_named_and_unlimited(simplecar_urdf: Path) -> None:
    with open_input(simplecar_urdf) as r:
        joints = {j.joint_name: j for j in inspect_file(r).joints}
    wheel = joints["base_to_left_back_wheel"]
    # PyBullet's own view: REVOLUTE with lower 0 > upper -1, meaning "no limit".
    assert (wheel.joint_type, wheel.joint_lower_limit, wheel.joint_upper_limit) == \
        ("REVOLUTE", 0.0, -1.0)
    assert wheel.urdf_type == "continuous" and not wheel.limited
    hinge = joints["base_to_left_hinge"]
    assert hinge.urdf_type == "revolute" and hinge.limited
    assert (hinge.joint_lower_limit, hinge.joint_upper_limit) == (-0.5, 0.5)
    assert wheel.parent_link_name == "base_link"
    assert joints["left_hinge_to_left_front_wheel"].parent_link_name == "left_hinge"


def test_filter_joints(simplecar_urdf: Path) -> None:
    with open_input(simplecar_urdf) as r:
        joints = inspect_file(r).joints
    assert [j.joint_index for j in filter_joints(joints, types=["continuous"])] == [1, 3, 4, 5]
    # "revolute" matches PyBullet's type, which continuous joints also have.
    assert len(filter_joints(joints, types=["REVOLUTE"])) == 6
    assert filter_joints(joints, movable=True) == joints
    with pytest.raises(ParameterError, match="'hinge' is not a joint type"):
        filter_joints(joints, types=["hinge"])


def test_link_table_shows_file_and_engine_inertia(offdiag: Path) -> None:
    with open_input(offdiag) as r:
        recomputed = inspect_file(r, links=True).links
        from_file = inspect_file(r, LoadOptions(inertia_from_file=True), links=True).links
    a, b = recomputed
    assert (a.link_index, a.link_name, b.link_index, b.link_name) == (-1, "a", 0, "b")
    # Without the flag PyBullet recomputes inertia from the 1 m box: (m/12)(1+1) = 1/3 for
    # each axis of a cube, whatever the file says.
    assert a.mass == 2.0 and not a.mass_differs
    assert a.inertia_differs
    assert a.file is not None
    assert a.file.inertia == (1.0, 0.2, 0.0, 2.0, 0.0, 3.0)
    # With the flag it keeps the file's tensor, diagonalised: its eigenvalues.
    fa = from_file[0]
    assert not fa.inertia_differs
    assert sorted(fa.local_inertia_diagonal) == pytest.approx(fa.file.principal)
    assert fa.file.principal[2] == pytest.approx(3.0)
    assert fa.local_inertial_pos == pytest.approx((0.1, 0.0, 0.0))
    # The link without <inertial> gets 1 kg from PyBullet.
    assert b.file is None and b.mass == 1.0 and b.mass_differs


def test_chatter_is_captured_as_tidy_diagnostics(offdiag: Path) -> None:
    with open_input(offdiag) as r:
        report = inspect_file(r)
    assert report.diagnostics == [
        "No inertial data for link 'b', using mass=1, localinertiadiagonal = 1,1,1, "
        "identity local inertial frame"]


def test_tidy_diagnostics_drops_location_prefixes() -> None:
    raw = ["b3Warning[examples/Importers/ImportURDFDemo/BulletUrdfImporter.cpp,126]:",
           "urdfdom: no axis element for Joint, defaulting to (1,0,0) axis chest",
           "b3Printf: hello", "b3Printf: hello"]
    assert tidy_diagnostics(raw) == [
        "urdfdom: no axis element for Joint, defaulting to (1,0,0) axis chest", "hello"]


def test_summary(simplecar_urdf: Path) -> None:
    with open_input(simplecar_urdf) as r:
        s = inspect_file(r, info=True).summary
    assert s is not None
    assert (s.robot, s.base_link, s.links, s.joints) == ("simplecar", "base_link", 7, 6)
    assert s.joint_types == {"continuous": 4, "revolute": 2}
    assert s.dof == 6
    assert s.total_mass == pytest.approx(6 + 4 * 0.3 + 2 * 0.01)
    assert s.total_mass == pytest.approx(s.file_mass)
    # The body box is 0.5 x 0.3; wheels of radius 0.1 reach below it and past its sides.
    assert s.size[0] > 0.5 and s.size[1] > 0.3 and s.size[2] == pytest.approx(0.2, abs=0.01)


@pytest.mark.parametrize("name", ["r2d2.urdf", "quadruped/minitaur.urdf",
                                  "franka_panda/panda.urdf"])
def test_kinematic_tree_indices_match_pybullet(name: str) -> None:
    """The tree is read from the file alone, yet predicts PyBullet's joint indices."""
    with resolve(name) as r:
        tree = kinematic_tree(r.root)
        joints = inspect_file(r).joints
    nodes = list(tree.walk())
    assert nodes[0].joint is None
    assert nodes[0].link == joints[0].parent_link_name
    predicted = [(n.joint.index, n.joint.name, n.link) for n in nodes[1:] if n.joint]
    assert predicted == [(j.joint_index, j.joint_name, j.link_name) for j in joints]


def test_kinematic_tree_fields(simplecar_urdf: Path) -> None:
    with resolve(simplecar_urdf) as r:
        tree = kinematic_tree(r.root)
    assert tree.link == "base_link"
    hinge = tree.children[0]
    assert hinge.joint is not None
    assert hinge.joint.to_dict() == {
        "name": "base_to_left_hinge", "type": "revolute", "index": 0, "xyz": [0.2, 0.0, 0.0],
        "rpy": [0.0, 0.0, 0.0], "axis": [0.0, 0.0, 1.0], "limit": [-0.5, 0.5]}
    wheel = hinge.children[0]
    assert wheel.joint is not None and wheel.joint.limit is None
    assert wheel.children == []
    flat = tree.to_flat_dict()
    assert flat["base_link"] == "base_link" and flat["links"][:3] == [
        "base_link", "left_hinge", "left_front_wheel"]
    assert [j["index"] for j in flat["joints"]] == list(range(6))
    assert flat["joints"][1]["parent"] == "left_hinge"
    assert flat["joints"][1]["child"] == "left_front_wheel"


def test_quat_to_rpy_matches_pybullet(pb) -> None:
    p, _ = pb
    for rpy in [(0.1, -0.4, 2.0), (0, 0, 0), (3.0, 0.2, -1.0), (0, math.pi / 2 - 1e-6, 0)]:
        q = p.getQuaternionFromEuler(rpy)
        assert quat_to_rpy(q) == pytest.approx(p.getEulerFromQuaternion(q), abs=1e-6)


def test_a_session_reloads_a_file_edited_since_it_loaded_it(tmp_path: Path, pb) -> None:
    from urdfkit.engine.session import Session

    def write(child: str) -> None:
        path.write_text(f'<robot name="r"><link name="a"/><link name="{child}"/><joint name="j" '
                        f'type="fixed"><parent link="a"/><child link="{child}"/></joint>'
                        '</robot>')

    path = tmp_path / "r.urdf"
    # Raw PyBullet keeps the first version for the client's life (its file cache).
    p, client = pb
    write("first")
    p.getJointInfo(p.loadURDF(str(path), physicsClientId=client), 0, physicsClientId=client)
    write("second")
    raw = p.loadURDF(str(path), physicsClientId=client)
    assert p.getJointInfo(raw, 0, physicsClientId=client)[12] == b"first"
    with Session() as s:
        write("first")
        assert s.p.getJointInfo(s.load_urdf(path), 0, physicsClientId=s.client)[12] == b"first"
        write("second")
        body = s.load_urdf(path)
        assert s.p.getJointInfo(body, 0, physicsClientId=s.client)[12] == b"second"
