"""``urdfkit collisions`` and ``check --physics``: self-collision pairs, checked against geometry
and against raw PyBullet."""

from __future__ import annotations

import json
import math
import shutil
from pathlib import Path

import pytest
from lxml import etree
from typer.testing import CliRunner

from urdfkit.checks.check import check_paths
from urdfkit.checks.collisions import self_collisions
from urdfkit.cli import app
from urdfkit.core.errors import ParameterError
from urdfkit.sources.resolve import resolve

MESHES = Path(__file__).parent / "fixtures" / "meshes"
INERTIAL = ('<inertial><mass value="0.1"/><inertia ixx="1e-4" ixy="0" ixz="0" iyy="1e-4" '
            'iyz="0" izz="1e-4"/></inertial>')


def _box_link(name: str, size: str, xyz: str = "0 0 0") -> str:
    return (f'<link name="{name}">{INERTIAL}<collision><origin xyz="{xyz}"/><geometry>'
            f'<box size="{size}"/></geometry></collision></link>')


def _joint(name: str, kind: str, parent: str, child: str, xyz: str = "0 0 0",
           extra: str = "") -> str:
    return (f'<joint name="{name}" type="{kind}"><parent link="{parent}"/><child link="{child}"/>'
            f'<origin xyz="{xyz}"/>{extra}</joint>')


def _write(tmp_path: Path, name: str, body: str) -> Path:
    path = tmp_path / name
    path.write_text(f'<?xml version="1.0"?>\n<robot name="{path.stem}">\n{body}\n</robot>\n')
    return path


@pytest.fixture
def gripper(tmp_path: Path) -> Path:
    """A palm with two fingers 20 mm wide whose centres are 10 mm apart: 10 mm of overlap.

    The right finger mimics the left one mirrored, as real parallel grippers do.
    """
    slide = '<axis xyz="0 1 0"/><limit lower="0" upper="0.04" effort="10" velocity="1"/>'
    return _write(tmp_path, "gripper.urdf", "\n".join([
        _box_link("palm", "0.1 0.1 0.02"),
        _box_link("left_finger", "0.02 0.02 0.06", "0 0 0.04"),
        _box_link("right_finger", "0.02 0.02 0.06", "0 0 0.04"),
        _joint("left_joint", "prismatic", "palm", "left_finger", "0 0.005 0.01", slide),
        _joint("right_joint", "prismatic", "palm", "right_finger", "0 -0.005 0.01",
               slide.replace('0 1 0', '0 -1 0') + '<mimic joint="left_joint"/>'),
    ]))


@pytest.fixture
def sweeper(tmp_path: Path) -> Path:
    """A thin arm 0.6 m long swinging about z over a block 0.3..0.5 m out, |y| <= 0.05.

    The arm (half-width 5 mm) meets the block while |angle| < atan(0.055 / 0.3) = 0.1813 rad,
    about; it never meets its own parent, the base, which overlaps it at the pivot.
    """
    return _write(tmp_path, "sweeper.urdf", "\n".join([
        _box_link("base", "0.1 0.1 0.1"),
        _box_link("block", "0.2 0.1 0.1", "0.4 0 0"),
        _box_link("arm", "0.6 0.01 0.02", "0.3 0 0"),
        _joint("block_mount", "fixed", "base", "block"),
        _joint("swing", "continuous", "base", "arm", extra='<axis xyz="0 0 1"/>'),
    ]))


def test_overlapping_fingers_depth_matches_the_geometry(gripper: Path) -> None:
    with resolve(gripper) as r:
        found = self_collisions(r)
    assert [(x.link_a, x.link_b) for x in found.pairs] == [("left_finger", "right_finger")]
    assert found.pairs[0].distance == pytest.approx(-0.010, abs=2e-4)
    assert found.pairs[0].poses_in_contact == 1 == found.poses
    # The palm overlaps both fingers (their bases sit 10 mm deep in it) but is their parent.
    assert sorted(found.skipped_adjacent) == [("palm", "left_finger"), ("palm", "right_finger")]
    assert found.tested == 1


def test_opening_the_gripper_separates_the_fingers(gripper: Path) -> None:
    with resolve(gripper) as r:
        # 6 mm apart each way: the overlap is gone when the fingers are 2 x 6 mm further out.
        assert not self_collisions(r, joints={"left_joint": 0.006, "right_joint": 0.006}).pairs
        touching = self_collisions(r, joints={"left_joint": 0.004, "right_joint": 0.004})
        assert touching.pairs[0].distance == pytest.approx(-0.002, abs=2e-4)
        assert self_collisions(r, joints={"left_joint": 0.006, "right_joint": 0.006},
                               margin=0.003).pairs  # 2 mm apart, within a 3 mm margin


def test_pinning_the_leader_moves_its_mimic_joint(gripper: Path) -> None:
    # The documented use: hold a gripper open by its leading joint alone.
    with resolve(gripper) as r:
        assert not self_collisions(r, joints={"left_joint": 0.006}).pairs
        assert not self_collisions(r, joints={"left_joint": 0.006}, samples=20).pairs
        with pytest.raises(ParameterError, match="finite"):
            self_collisions(r, joints={"left_joint": float("nan")})


def test_mimic_joints_follow_their_leader_in_samples(gripper: Path) -> None:
    # The right finger mirrors the left: opened by the same amount, they overlap only while
    # each has moved less than 2.5 mm of its 40 mm travel: about 6% of the samples.
    with resolve(gripper) as r:
        found = self_collisions(r, samples=400, seed=3)
    n = found.pairs[0].poses_in_contact - 1  # less the start pose
    assert 400 * 0.0625 - 4 * math.sqrt(400 * 0.0625) < n < 400 * 0.0625 + 4 * math.sqrt(25)


@pytest.mark.parametrize(("angle", "touches"), [(0.0, True), (0.17, True), (-0.17, True),
                                                (0.20, False), (-0.20, False), (3.0, False)])
def test_swinging_arm_meets_the_block_where_geometry_says(sweeper: Path, angle: float,
                                                          touches: bool) -> None:
    with resolve(sweeper) as r:
        found = self_collisions(r, joints={"swing": angle})
    assert [(x.link_a, x.link_b) for x in found.pairs] == ([("block", "arm")] if touches else [])
    assert ("base", "arm") in found.skipped_adjacent


def test_sampled_contact_rate_matches_the_angle_range(sweeper: Path) -> None:
    with resolve(sweeper) as r:
        found = self_collisions(r, samples=2000, seed=11)
        again = self_collisions(r, samples=2000, seed=11)
        other = self_collisions(r, samples=2000, seed=12)
    expected = 2 * math.atan(0.055 / 0.3) / (2 * math.pi) * 2000  # continuous: -pi..pi
    n = found.pairs[0].poses_in_contact - 1
    assert abs(n - expected) < 4 * math.sqrt(expected)
    assert found.to_dict() == again.to_dict()  # the seed fixes the poses
    assert other.pairs[0].poses_in_contact != found.pairs[0].poses_in_contact or \
        other.pairs[0].distance != found.pairs[0].distance


def test_pairs_agree_with_raw_pybullet_self_collision(pb: tuple[object, int]) -> None:
    import pybullet_data

    p, c = pb
    path = Path(pybullet_data.getDataPath()) / "r2d2.urdf"
    pose = {"head_swivel": 0.0, "gripper_extension": -0.38, "left_gripper_joint": 0.5}
    with resolve(path) as r:
        ours = {(x.index_a, x.index_b) for x in self_collisions(r, joints=pose).pairs
                if x.distance < -1e-3}
    body = p.loadURDF(str(path), useFixedBase=True, physicsClientId=c,  # type: ignore[attr-defined]
                      flags=p.URDF_USE_SELF_COLLISION | p.URDF_USE_IMPLICIT_CYLINDER)  # type: ignore[attr-defined]
    names = {p.getJointInfo(body, i, physicsClientId=c)[1].decode(): i  # type: ignore[attr-defined]
             for i in range(p.getNumJoints(body, physicsClientId=c))}  # type: ignore[attr-defined]
    for name, value in pose.items():
        p.resetJointState(body, names[name], value, physicsClientId=c)  # type: ignore[attr-defined]
    p.performCollisionDetection(physicsClientId=c)  # type: ignore[attr-defined]
    raw = {(min(x[3], x[4]), max(x[3], x[4]))
           for x in p.getContactPoints(body, body, physicsClientId=c)  # type: ignore[attr-defined]
           if x[8] < -1e-3}
    assert ours and ours == raw


def test_concave_mesh_pairs_name_the_hull(tmp_path: Path) -> None:
    # A peg in the notch of an L bracket: 0.2 m clear of the bracket's faces, but inside the
    # convex hull PyBullet collides with.
    shutil.copy(MESHES / "l_bracket.obj", tmp_path / "l_bracket.obj")
    path = _write(tmp_path, "notch.urdf", "\n".join([
        _box_link("base", "0.1 0.1 0.1", "-1 -1 0"),
        f'<link name="bracket">{INERTIAL}<collision><geometry><mesh filename="l_bracket.obj"/>'
        '</geometry></collision></link>',
        _box_link("peg", "0.2 0.2 0.2", "1.3 1.3 0.25"),
        _joint("turn", "revolute", "base", "bracket",
               extra='<axis xyz="0 0 1"/><limit lower="-1" upper="1" effort="1" velocity="1"/>'),
        _joint("peg_mount", "fixed", "base", "peg"),
    ]))
    with resolve(path) as r:
        found = self_collisions(r)
    assert [(x.link_a, x.link_b, x.hull) for x in found.pairs] == [("bracket", "peg",
                                                                     ["bracket"])]
    code, out, _ = _cli("collisions", str(path))
    assert code == 1 and "convex hull of bracket" in out
    srdf = _cli("collisions", str(path), "--srdf")[1]
    assert "<!-- bracket: a concave mesh" in srdf and 'link1="bracket"' in srdf


def _cli(*args: str) -> tuple[int, str, str]:
    result = CliRunner().invoke(app, list(args))
    return result.exit_code, result.stdout, result.stderr


def test_cli_json_contract(gripper: Path) -> None:
    code, out, _ = _cli("collisions", str(gripper), "--samples", "20", "--json")
    data = json.loads(out)
    assert code == 1
    assert {"file", "robot", "poses", "pairs"} <= set(data)
    assert data["poses"] == 21 and data["robot"] == "gripper"
    pair = data["pairs"][0]
    assert {"link_a", "link_b", "distance", "poses_in_contact"} <= set(pair)
    assert pair["link_a"] == "left_finger" and pair["distance"] < 0


def test_cli_table_and_exit_codes(sweeper: Path) -> None:
    code, out, _ = _cli("collisions", str(sweeper))
    assert code == 1 and "block" in out and "1 parent-child pairs skipped" not in out
    assert "2 parent-child pairs skipped" in out  # base-block (fixed) and base-arm
    code, out, _ = _cli("collisions", str(sweeper), "--joints", "swing=1.5")
    assert code == 0 and "0 link pair(s) in contact" in out


def test_srdf_lists_pairs_in_contact_in_every_pose(gripper: Path) -> None:
    code, out, _ = _cli("collisions", str(gripper), "--srdf")
    assert code == 0
    root = etree.fromstring(out.encode())
    assert root.tag == "robot" and root.get("name") == "gripper"
    entries = root.findall("disable_collisions")
    assert [(e.get("link1"), e.get("link2"), e.get("reason")) for e in entries] == \
        [("left_finger", "right_finger", "Default")]


def test_srdf_without_pairs_is_a_commented_document() -> None:
    # Issue 49: `collisions r2d2.urdf --samples 50 --srdf` printed nothing at all.
    code, out, _ = _cli("collisions", "r2d2.urdf", "--srdf", "--samples", "50")
    assert code == 0
    root = etree.fromstring(out.encode())
    import pybullet_data

    robot = etree.parse(str(Path(pybullet_data.getDataPath()) / "r2d2.urdf")).getroot()
    assert root.tag == "robot" and root.get("name") == robot.get("name") == "physics"
    assert root.findall("disable_collisions") == []
    said = " ".join(c.text for c in root.itersiblings(etree.Comment, preceding=True)) + \
        " ".join(c.text for c in root.iter(etree.Comment))
    assert "51 poses tested" in said and "nothing to disable" in said


def test_python_output_disables_the_pairs_in_pybullet(gripper: Path,
                                                      pb: tuple[object, int]) -> None:
    code, out, _ = _cli("collisions", str(gripper), "--python")
    assert code == 0 and "setCollisionFilterPair" in out
    p, c = pb

    def contacts(body: int) -> int:
        p.performCollisionDetection(physicsClientId=c)  # type: ignore[attr-defined]
        return len(p.getContactPoints(body, body, physicsClientId=c))  # type: ignore[attr-defined]

    flags = p.URDF_USE_SELF_COLLISION  # type: ignore[attr-defined]
    robot = p.loadURDF(str(gripper), useFixedBase=True, flags=flags,  # type: ignore[attr-defined]
                       physicsClientId=c)
    assert contacts(robot) > 0
    exec(out, {"p": _Bound(p, c), "robot": robot})  # our own output, run as printed
    assert contacts(robot) == 0


class _Bound:
    """``p`` with this test's client id filled in, so the printed calls run as printed."""

    def __init__(self, p: object, client: int):
        self.p, self.client = p, client

    def __getattr__(self, name: str) -> object:
        fn = getattr(self.p, name)
        return lambda *a, **k: fn(*a, physicsClientId=self.client, **k)


def test_bad_input_is_one_line_and_exit_2(gripper: Path, tmp_path: Path) -> None:
    for args, words in [(("--joints", "nope=1"), "no joint named 'nope'"),
                        (("--joints", "left_joint=x"), "not a number"),
                        (("--margin", "-1"), "margin"),
                        (("--json", "--srdf"), "exclusive")]:
        code, out, err = _cli("collisions", str(gripper), *args)
        assert code == 2 and words in err and "Traceback" not in err, (args, err)
    code, _, err = _cli("collisions", str(tmp_path / "missing.urdf"))
    assert code == 2 and "missing.urdf" in err
    with resolve(gripper) as r, pytest.raises(ParameterError, match="samples"):
        self_collisions(r, samples=-1)


def test_check_physics_reports_the_zero_pose_pair_on_the_link_line(gripper: Path) -> None:
    plain = check_paths([gripper], jobs=1)
    assert not [f for f in plain.findings if f.code.startswith("U95")]
    found = [f for f in check_paths([gripper], jobs=1, physics=True).findings
             if f.code == "U950"]
    assert len(found) == 1 and "'left_finger' and 'right_finger'" in found[0].message
    assert "10 mm" in found[0].message
    line = next(i for i, text in enumerate(gripper.read_text().splitlines(), 1)
                if '<link name="left_finger">' in text)
    assert found[0].line == line
    code, out, _ = _cli("check", str(gripper), "--physics", "--select", "U95")
    assert code == 0 and "U950" in out  # a warning: exit 1 only with --fail-on warning
    assert _cli("check", str(gripper), "--physics", "--fail-on", "warning")[0] == 1


def test_check_physics_turns_a_pybullet_refusal_into_u951(gripper: Path,
                                                           monkeypatch: pytest.MonkeyPatch) -> None:
    from urdfkit.core.errors import EngineError
    from urdfkit.engine.session import Session

    def refuse(self: Session, path: object, *args: object, **kwargs: object) -> int:
        raise EngineError("PyBullet could not load it: Could not parse visual element",
                          file=str(path))

    monkeypatch.setattr(Session, "load_urdf", refuse)
    found = [f for f in check_paths([gripper], jobs=1, physics=True).findings
             if f.code.startswith("U95")]
    assert [(f.code, f.level) for f in found] == [("U951", "error")]
    assert "Could not parse visual element" in found[0].message


# ---- values that cannot be simulated (issue: overflow and NaN reach the engine)


def _arm_and_block(tmp_path: Path, name: str, limit: str, box: str = "0.3 0.02 0.02",
                   arm_xyz: str = "0.15 0 0") -> Path:
    """A 0.3 m arm swinging about z over a block 0.2 m out along y: it meets the block
    within one turn, so a sampled turn finds the contact."""
    return _write(tmp_path, name, "\n".join([
        _box_link("base", "0.02 0.02 0.02"),
        _box_link("arm", box, arm_xyz),
        _box_link("block", "0.05 0.05 0.05"),
        _joint("swing", "revolute", "base", "arm", "0 0 0",
               f'<axis xyz="0 0 1"/><limit {limit} effort="1" velocity="1"/>'),
        _joint("fix", "fixed", "base", "block", "0 0.2 0"),
    ]))


@pytest.mark.parametrize("limit", ['lower="-1e308" upper="1e308"', 'lower="-inf" upper="inf"'])
def test_limits_past_any_range_sample_one_turn(tmp_path: Path, limit: str) -> None:
    wide = self_collisions(resolve(str(_arm_and_block(tmp_path, "wide.urdf", limit))),
                           samples=200, seed=3)
    turn = self_collisions(resolve(str(_arm_and_block(
        tmp_path, "turn.urdf", f'lower="{-math.pi!r}" upper="{math.pi!r}"'))), samples=200, seed=3)
    assert [(x.link_a, x.link_b, x.poses_in_contact) for x in wide.pairs] == \
        [(x.link_a, x.link_b, x.poses_in_contact) for x in turn.pairs]
    assert [x.link_b for x in turn.pairs] == ["block"]  # the arm does meet the block
    assert any("one turn" in w for w in wide.warnings)


@pytest.mark.parametrize(("field", "bad"), [("arm_xyz", "nan 0 0"), ("box", "0.3 nan 0.02"),
                                            ("arm_xyz", "0.15 inf 0")])
def test_non_finite_shapes_are_refused_not_reported_clean(tmp_path: Path, field: str,
                                                          bad: str) -> None:
    path = _arm_and_block(tmp_path, "bad.urdf", 'lower="1.3" upper="1.7"', **{field: bad})
    result = CliRunner().invoke(app, ["collisions", str(path)])
    assert result.exit_code == 2, result.output
    line = result.stderr.strip()
    assert "\n" not in line and "Traceback" not in line and "not a finite number" in line
    written = next(n for n, x in enumerate(path.read_text().splitlines(), 1) if bad in x)
    assert f"bad.urdf:{written}:" in line
    # The finite twin at the same pose does collide: a clean report would have been wrong.
    good = _arm_and_block(tmp_path, "good.urdf", 'lower="1.3" upper="1.7"')
    assert self_collisions(resolve(str(good)), joints={"swing": 1.5}).pairs


def test_a_mimic_chain_follows_through(tmp_path: Path) -> None:
    """c follows b, which follows a: pinning a moves c into the block beside it."""
    slide = '<axis xyz="0 1 0"/><limit lower="0" upper="0.04" effort="10" velocity="1"/>'
    path = _write(tmp_path, "chain.urdf", "\n".join([
        _box_link("palm", "0.02 0.02 0.02"),
        _box_link("a", "0.01 0.01 0.01"), _box_link("b", "0.01 0.01 0.01"),
        _box_link("c", "0.01 0.01 0.01"), _box_link("block", "0.02 0.02 0.02"),
        _joint("ja", "prismatic", "palm", "a", "0.1 0 0", slide),
        _joint("jb", "prismatic", "palm", "b", "0.2 0 0", slide + '<mimic joint="ja"/>'),
        _joint("jc", "prismatic", "palm", "c", "0.3 0 0", slide + '<mimic joint="jb"/>'),
        _joint("fix", "fixed", "palm", "block", "0.3 0.045 0"),
    ]))
    # With a at 0.04, c sits at y = 0.04: its face at 0.045 is 10 mm past the block's near
    # face (0.045 - 0.01 = 0.035).
    found = self_collisions(resolve(str(path)), joints={"ja": 0.04})
    assert [(x.link_a, x.link_b) for x in found.pairs] == [("c", "block")]
    assert found.pairs[0].distance == pytest.approx(-0.010, abs=1e-4)
    assert not self_collisions(resolve(str(path)), joints={"ja": 0.0}).pairs


@pytest.mark.parametrize("ring", [("ja",), ("ja", "jb")])
def test_a_mimic_ring_is_refused(tmp_path: Path, ring: tuple[str, ...]) -> None:
    slide = '<axis xyz="0 1 0"/><limit lower="0" upper="0.04" effort="10" velocity="1"/>'
    follows = {name: ring[(k + 1) % len(ring)] for k, name in enumerate(ring)}
    joints = [_joint(n, "prismatic", "palm", n[1], f"0.{k + 1} 0 0",
                     slide + (f'<mimic joint="{follows[n]}"/>' if n in follows else ""))
              for k, n in enumerate(("ja", "jb"))]
    path = _write(tmp_path, "ring.urdf", "\n".join(
        [_box_link("palm", "0.02 0.02 0.02"), _box_link("a", "0.01 0.01 0.01"),
         _box_link("b", "0.01 0.01 0.01"), *joints]))
    result = CliRunner().invoke(app, ["collisions", str(path), "--samples", "5"])
    assert result.exit_code == 2, result.output
    assert "ring (" + " -> ".join([*ring, ring[0]]) + ")" in result.stderr
    assert len(result.stderr.strip().splitlines()) == 1


@pytest.mark.parametrize("multiplier", ["two", "1,5", "nan"])
def test_a_mimic_multiplier_that_is_not_a_number_is_refused_not_sampled_freely(
        tmp_path: Path, multiplier: str) -> None:
    # It once became a free joint, sampled over its limits as if it had no leader.
    slide = '<axis xyz="0 1 0"/><limit lower="0" upper="0.04" effort="10" velocity="1"/>'
    path = _write(tmp_path, "m.urdf", "\n".join([
        _box_link("palm", "0.02 0.02 0.02"),
        _box_link("a", "0.01 0.01 0.01"), _box_link("b", "0.01 0.01 0.01"),
        _joint("ja", "prismatic", "palm", "a", "0.1 0 0", slide),
        _joint("jb", "prismatic", "palm", "b", "0.2 0 0",
               slide + f'<mimic joint="ja" multiplier="{multiplier}"/>'),
    ]))
    result = CliRunner().invoke(app, ["collisions", str(path)])
    assert result.exit_code == 2, result.output
    line = result.stderr.strip()
    written = next(n for n, x in enumerate(path.read_text().splitlines(), 1)
                   if "multiplier" in x)
    assert f"m.urdf:{written}:" in line and "multiplier" in line and "\n" not in line


def test_xacro_left_in_an_origin_is_read_as_pybullet_reads_it() -> None:
    """`$(optenv X 0.5 0.2 0.3)` in a .urdf: PyBullet loads it (atof per token, the first three),
    so collisions does too, with a warning, and finds the contact that reading makes."""
    path = Path(__file__).parent / "fixtures" / "robots" / "xacro_residue.urdf"
    result = CliRunner().invoke(app, ["collisions", str(path), "--json"])
    assert result.exit_code == 1, result.output  # a pair in contact, not a refusal
    report = json.loads(result.stdout)
    assert [(x["link_a"], x["link_b"]) for x in report["pairs"]] == [("imu", "block")]
    assert any("so '0 0 0.5'" in w and "xacro_residue.urdf:20" in w for w in report["warnings"])
    import pybullet as p

    c = p.connect(p.DIRECT)
    try:
        body = p.loadURDF(str(path), useFixedBase=True, flags=p.URDF_USE_SELF_COLLISION,
                          physicsClientId=c)
        assert p.getJointInfo(body, 0, physicsClientId=c)[14] == pytest.approx((0, 0, 0.5))
        assert p.getJointInfo(body, 0, physicsClientId=c)[15] == pytest.approx((0, 0, 0, 1))
        assert p.getClosestPoints(body, body, 0.0, 0, 1, physicsClientId=c)  # raw: in contact
    finally:
        p.disconnect(c)
