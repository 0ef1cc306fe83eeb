"""``check --target`` (issue 51): every rule's fixture loaded in the real consumer.

A refusal rule's fixture is refused by the engine itself (urdfdom's ``check_urdf`` exits 255,
Pinocchio raises); a change rule's fixture loads, and the engine's model holds what the rule
says (Pinocchio's masses, coordinates, joint order, kinematics; urdfdom's own log). Each
fixture has a twin without the fault that the engine loads and that gets no finding of the
rule. Over all of pybullet_data (the slow run), ``check --target`` reports an error exactly
where the engine refuses the file.
"""

from __future__ import annotations

import json
import math
import os
import subprocess
from pathlib import Path

import pytest
from engine_loaders import cmeel_prefix, load

from urdfkit.checks.check import check_file, check_paths
from urdfkit.checks.targets import TARGET_CODES, parse_targets
from urdfkit.core.errors import ParameterError

LIM = '<limit lower="-1" upper="1" effort="1" velocity="1"/>'
INERTIAL = ('<inertial><mass value="1"/><inertia ixx="1" ixy="0" ixz="0" iyy="1" iyz="0" '
            'izz="1"/></inertial>')


def joint(kind: str = "revolute", inner: str = LIM, *, name: str = "j",
          version: str = "") -> str:
    """Two links and one joint between them (links with inertia: Pinocchio's masses)."""
    v = f' version="{version}"' if version else ""
    return (f'<robot name="r"{v}><link name="a">{INERTIAL}</link><link name="b">{INERTIAL}'
            f'</link><joint name="{name}" type="{kind}"><parent link="a"/><child link="b"/>'
            f'{inner}</joint></robot>')


def links(inner: str, version: str = "") -> str:
    v = f' version="{version}"' if version else ""
    return f'<robot name="r"{v}><link name="a">{inner}</link></robot>'


#: What urdfdom refuses: code -> (fixture, its twin that loads).
REFUSED: dict[str, tuple[str, str]] = {
    "T102": ('<model name="r"><link name="a"/></model>', links("")),
    "T103": ('<robot><link name="a"/></robot>', links("")),
    "T104": ('<robot name="r" version="1.3"><link name="a"/></robot>', links("", "1.2")),
    "T105": ('<robot name="r"></robot>', links("")),
    "T106": ('<robot name="r"><link name="a"/><link name="a"/></robot>', links("")),
    "T107": ('<robot name="r"><link name="a"/><link name="b"/><link name="c"/><joint name="j" '
             'type="fixed"><parent link="a"/><child link="b"/></joint><joint name="j" '
             'type="fixed"><parent link="a"/><child link="c"/></joint></robot>',
             joint("fixed", "")),
    "T108": ('<robot name="r"><material name="m"><color rgba="1 0 0 1"/></material><material '
             'name="m"><color rgba="0 1 0 1"/></material><link name="a"/></robot>', links("")),
    "T109": ('<robot name="r"><link name="a"/><link name="b"/><joint type="fixed"><parent '
             'link="a"/><child link="b"/></joint></robot>', joint("fixed", "")),
    "T110": (joint("", "").replace(' type=""', ""), joint("fixed", "")),
    "T111": (joint("spherical", ""), joint("fixed", "")),
    "T112": (joint("revolute", ""), joint()),
    "T114": (joint("revolute", '<limit lower="-1" upper="1" velocity="1"/>'), joint()),
    "T116": (joint("revolute", '<limit lower="-1.57." upper="1" effort="1" velocity="1"/>'),
             joint("revolute", '<limit lower="-1.57" upper="1" effort="1" velocity="1"/>')),
    "T117": (joint("revolute", '<limit lower="1" upper="-1" effort="1" velocity="1"/>',
                   version="1.2"), joint(version="1.2")),
    "T120": (joint("fixed", '<origin xyz="0 0 $(optenv Z 0.1)"/>'),
             joint("fixed", '<origin xyz="0 0 0.1"/>')),
    "T121": (joint("fixed", '<origin rpy="0 0 1" quat_xyzw="0 0 0.7071068 0.7071068"/>',
                   version="1.1"), joint("fixed", '<origin rpy="0 0 1"/>', version="1.1")),
    "T122": (joint("revolute", '<axis xyz="0 1"/>' + LIM),
             joint("revolute", '<axis xyz="0 1 0"/>' + LIM)),
    "T123": (joint("revolute", LIM + "<dynamics/>"),
             joint("revolute", LIM + '<dynamics damping="0.1"/>')),
    "T124": (joint("revolute", LIM + '<safety_controller soft_lower_limit="-1" '
                   'soft_upper_limit="1" k_position="1"/>'),
             joint("revolute", LIM + '<safety_controller k_velocity="1"/>')),
    "T125": (joint("revolute", LIM + '<calibration rising="x"/>'),
             joint("revolute", LIM + '<calibration rising="0.5"/>')),
    "T126": (joint("revolute", LIM + '<mimic multiplier="2"/>'),
             joint("revolute", LIM)),
    "T127": ('<robot name="r"><link name="a"/><link name="b"/><joint name="j" type="fixed">'
             '<child link="b"/></joint></robot>', joint("fixed", "")),
    "T128": ('<robot name="r"><link name="a"/><joint name="j" type="fixed"><parent link="a"/>'
             '<child link="zz"/></joint></robot>', joint("fixed", "")),
    "T130": ('<robot name="r"><link name="a"/><link name="b"/></robot>', links("")),
    "T131": ('<robot name="r"><link name="a"/><link name="b"/><joint name="j1" type="fixed">'
             '<parent link="a"/><child link="b"/></joint><joint name="j2" type="fixed">'
             '<parent link="b"/><child link="a"/></joint></robot>', joint("fixed", "")),
}


def _write(tmp_path: Path, text: str, name: str = "r.urdf") -> Path:
    path = tmp_path / name
    path.write_text(text, encoding="utf-8")
    return path


def _codes(path: Path, targets: tuple[str, ...]) -> dict[str, str]:
    return {f.code: f.level for f in check_file(str(path), path, targets=targets).findings
            if f.code.startswith("T")}


def check_urdf(path: Path) -> tuple[int, str]:
    """urdfdom's own ``check_urdf``: its exit status and its log."""
    prefix = cmeel_prefix()
    assert prefix is not None, "pip install pin (urdfkit[engines]) brings urdfdom's check_urdf"
    p = subprocess.run([str(prefix / "bin" / "check_urdf"), str(path)], capture_output=True,
                       text=True, errors="replace", timeout=20,
                       env=dict(os.environ, LD_LIBRARY_PATH=str(prefix / "lib")))
    return p.returncode, p.stderr


def pinocchio_model(path: Path):  # type: ignore[no-untyped-def]
    import pinocchio

    return pinocchio.buildModelFromUrdf(str(path))


@pytest.mark.parametrize("code", sorted(REFUSED))
def test_each_urdfdom_refusal_is_refused_by_urdfdom_and_pinocchio(code: str,
                                                                   tmp_path: Path) -> None:
    bad, good = REFUSED[code]
    path = _write(tmp_path, bad)
    found = _codes(path, ("ros", "pinocchio"))
    assert found.get(code) == "error" and found.get("T200") == "error", found
    status, log = check_urdf(path)
    assert status == 255, (status, log)
    with pytest.raises(ValueError, match="valid URDF model"):
        pinocchio_model(path)
    twin = _write(tmp_path, good, "twin.urdf")
    assert not any(level == "error" for level in _codes(twin, ("ros", "pinocchio")).values())
    assert check_urdf(twin)[0] == 0
    pinocchio_model(twin)


#: What urdfdom loads but logs it could not read: code -> (fixture, urdfdom's log line).
DROPPED = {
    "inertial without mass": (links('<inertial><inertia ixx="1" ixy="0" ixz="0" iyy="1" '
                                    'iyz="0" izz="1"/></inertial>'), "Could not parse inertial"),
    "mass with a trailing space": (links('<inertial><mass value="1 "/><inertia ixx="1" ixy="0" '
                                         'ixz="0" iyy="1" iyz="0" izz="1"/></inertial>'),
                                   "Could not parse inertial"),
    "box of two sizes": (links('<visual><geometry><box size="1 1"/></geometry></visual>'
                               '<collision><geometry><box size="1 1 1"/></geometry></collision>'),
                         "Could not parse visual"),
    "mesh scale of four": (links('<collision><geometry><mesh filename="m.stl" scale="1 1 1 1"/>'
                                 '</geometry></collision>'), "Could not parse collision"),
    "PyBullet's plane shape": (links('<collision><geometry><plane normal="0 0 1"/></geometry>'
                                     '</collision>'), "Could not parse collision"),
    "capsule before 1.1": (links('<collision><geometry><capsule radius="0.1" length="1"/>'
                                 '</geometry></collision>'), "Could not parse collision"),
}


@pytest.mark.parametrize("case", sorted(DROPPED))
def test_a_link_part_urdfdom_cannot_read_is_dropped_not_refused(case: str,
                                                                 tmp_path: Path) -> None:
    text, logged = DROPPED[case]
    path = _write(tmp_path, text)
    assert _codes(path, ("ros",)) == {"T150": "warning"}
    status, log = check_urdf(path)
    assert status == 0 and logged in log, (status, log)


@pytest.mark.parametrize(("depth", "refused"), [(300, False), (496, False), (497, True)])
def test_nesting_lxml_refuses_is_judged_as_tinyxml2_reads_it(depth: int, refused: bool,
                                                              tmp_path: Path) -> None:
    """lxml stops at 256 levels (U000), urdfdom's tinyxml2 at 498: the target says which."""
    path = _write(tmp_path, '<robot name="r"><link name="a">' + "<x>" * depth + "</x>" * depth
                  + "</link></robot>")
    found = check_file(str(path), path, targets=("ros", "pinocchio")).findings
    assert "U000" in {f.code for f in found}
    errors = {f.code for f in found if f.level == "error" and f.code.startswith("T")}
    assert errors == ({"T101", "T200"} if refused else set())
    assert (check_urdf(path)[0] == 255) is refused


def test_bytes_that_are_no_utf8_are_read_as_urdfdom_reads_them(tmp_path: Path) -> None:
    path = tmp_path / "r.urdf"
    path.write_bytes(b'<robot name="r\xff"><link name="a"/><link name="b"/></robot>')
    found = check_file(str(path), path, targets=("ros",)).findings
    assert "U000" in {f.code for f in found}
    assert [f.code for f in found if f.code.startswith("T")] == ["T130"]  # two roots, read
    assert check_urdf(path)[0] == 255
    path.write_bytes(b'<robot name="r\xff"><link name="a"/></robot>')
    assert not [f for f in check_file(str(path), path, targets=("ros",)).findings
                if f.code.startswith("T")]
    assert check_urdf(path)[0] == 0


def test_a_limit_without_lower_and_upper_pins_the_joint_at_zero(tmp_path: Path) -> None:
    path = _write(tmp_path, joint("revolute", '<limit effort="1" velocity="1"/>'))
    assert _codes(path, ("ros",)).get("T163") == "warning"
    m = pinocchio_model(path)  # urdfdom's reading, as Pinocchio builds its model from it
    assert (m.lowerPositionLimit[0], m.upperPositionLimit[0]) == (0.0, 0.0)
    assert "T163" not in _codes(_write(tmp_path, joint(), "twin.urdf"), ("ros",))


@pytest.mark.parametrize("axis", ['<axis/>', '<axis xyz="0 0 0"/>'])
def test_a_zero_axis_breaks_pinocchio_kinematics(axis: str, tmp_path: Path) -> None:
    import numpy as np
    import pinocchio

    path = _write(tmp_path, joint("revolute", axis + LIM))
    found = _codes(path, ("ros", "pinocchio"))
    assert found.get("T226") == "warning"
    assert ("T169" in found) == (axis == "<axis/>")
    m = pinocchio_model(path)
    d = m.createData()
    pinocchio.forwardKinematics(m, d, np.array([1.0]))
    rot = d.oMi[1].rotation
    assert not np.allclose(rot @ rot.T, np.eye(3))  # no rotation: what the rule says
    twin = _write(tmp_path, joint("revolute", '<axis xyz="0 0 1"/>' + LIM), "twin.urdf")
    assert "T226" not in _codes(twin, ("pinocchio",))


def test_pinocchio_refuses_negative_effort_and_a_child_of_two_joints(tmp_path: Path) -> None:
    neg = _write(tmp_path, joint("revolute", '<limit lower="-1" upper="1" effort="-5" '
                                 'velocity="1"/>'))
    assert _codes(neg, ("pinocchio",)).get("T201") == "error"
    assert "T117" not in _codes(neg, ("ros",))  # URDF 1.0: urdfdom takes it
    assert check_urdf(neg)[0] == 0
    with pytest.raises(ValueError, match="min_effort"):
        pinocchio_model(neg)
    two = _write(tmp_path, '<robot name="r"><link name="r"/><link name="a"/><link name="b"/>'
                 '<link name="c"/><joint name="j1" type="fixed"><parent link="r"/><child '
                 'link="a"/></joint><joint name="j2" type="fixed"><parent link="r"/><child '
                 'link="b"/></joint><joint name="j3" type="fixed"><parent link="a"/><child '
                 'link="c"/></joint><joint name="j4" type="fixed"><parent link="b"/><child '
                 'link="c"/></joint></robot>', "two.urdf")
    assert _codes(two, ("pinocchio",)).get("T204") == "error"
    with pytest.raises(ValueError, match="does not have any body"):
        pinocchio_model(two)


def test_pinocchio_masses_coordinates_and_fixed_joints(tmp_path: Path) -> None:
    """T222 (no inertial: 0 kg), T223 (continuous: nq 2), T220 (fixed: a frame, merged)."""
    bare = _write(tmp_path, '<robot name="r"><link name="a"/><link name="b"/><joint name="j" '
                  f'type="revolute"><parent link="a"/><child link="b"/>{LIM}</joint></robot>')
    assert _codes(bare, ("pinocchio",)).get("T222") == "warning"
    assert pinocchio_model(bare).inertias[1].mass == 0.0
    spin = _write(tmp_path, joint("continuous", ""), "spin.urdf")
    assert _codes(spin, ("pinocchio",)).get("T223") == "info"
    m = pinocchio_model(spin)
    assert (m.nq, m.nv) == (2, 1)
    welded = _write(tmp_path, '<robot name="r"><link name="a"/><link name="b">' + INERTIAL +
                    '</link><link name="c"><inertial><mass value="2"/><inertia ixx="1" ixy="0" '
                    'ixz="0" iyy="1" iyz="0" izz="1"/></inertial></link><joint name="j" '
                    f'type="revolute"><parent link="a"/><child link="b"/>{LIM}</joint><joint '
                    'name="f" type="fixed"><parent link="b"/><child link="c"/></joint></robot>',
                    "welded.urdf")
    assert _codes(welded, ("pinocchio",)).get("T220") == "info"
    m = pinocchio_model(welded)
    assert list(m.names) == ["universe", "j"] and m.inertias[1].mass == 3.0


def test_a_planar_joint_moves_in_xy_in_pinocchio_whatever_its_axis(tmp_path: Path) -> None:
    import numpy as np
    import pinocchio

    path = _write(tmp_path, joint("planar", '<axis xyz="1 0 0"/>'))
    assert _codes(path, ("pinocchio",)).get("T225") == "warning"
    m = pinocchio_model(path)
    d = m.createData()
    pinocchio.forwardKinematics(m, d, np.array([0.5, 0.0, 1.0, 0.0]))
    # along x, the axis itself: no motion in the plane normal to (1, 0, 0) would go there
    assert np.allclose(d.oMi[1].translation, [0.5, 0.0, 0.0])


def test_pinocchio_joint_order_against_pybullet(tmp_path: Path) -> None:
    """T227's two orders are the engines' own: PyBullet's joint indices, Pinocchio's names."""
    from urdfkit.engine.api import LoadSettings
    from urdfkit.engine.pybullet import PyBulletEngine

    text = ('<robot name="r"><link name="base">' + INERTIAL + '</link>' +
            "".join(f'<link name="l{i}">{INERTIAL}</link>' for i in range(1, 5)) +
            "".join(f'<joint name="{n}" type="revolute"><parent link="{p}"/><child '
                    f'link="{c}"/>{LIM}</joint>'
                    for n, p, c in (("zeta", "base", "l1"), ("alpha", "base", "l2"),
                                    ("mid", "l1", "l3"), ("beta", "l2", "l4"))) + "</robot>")
    path = _write(tmp_path, text)
    findings = [f for f in check_file(str(path), path, targets=("pinocchio",)).findings
                if f.code == "T227"]
    assert len(findings) == 1
    engine = PyBulletEngine()
    try:
        body = engine.load(str(path), LoadSettings())
        pybullet = [j.name for j in engine.joints(body)]
    finally:
        engine.close()
    pinocchio = list(pinocchio_model(path).names)[1:]
    assert pybullet == ["zeta", "mid", "alpha", "beta"]
    assert pinocchio == ["alpha", "beta", "zeta", "mid"]
    assert "PyBullet has zeta, mid, alpha, Pinocchio alpha, beta, zeta" in findings[0].message


def test_a_floating_joint_is_a_free_flyer_in_pinocchio_and_fixed_in_pybullet(
        tmp_path: Path) -> None:
    from urdfkit.engine.api import LoadSettings
    from urdfkit.engine.pybullet import PyBulletEngine

    path = _write(tmp_path, joint("floating", ""))
    assert _codes(path, ("pinocchio",)).get("T224") == "warning"
    m = pinocchio_model(path)
    assert (m.nq, m.nv) == (7, 6)
    engine = PyBulletEngine()
    try:
        kinds = [j.kind for j in engine.joints(engine.load(str(path), LoadSettings()))]
    finally:
        engine.close()
    assert kinds == ["fixed"]


# ---- over pybullet_data: an error exactly where the engine refuses


def _pybullet_data_urdfs(limit_random: bool) -> list[str]:
    import pybullet_data

    root = Path(pybullet_data.getDataPath())
    return sorted(str(p) for p in root.rglob("*.urdf")
                  if not (limit_random and "random_urdfs" in p.parts))


def _agreement(paths: list[str], target: str, prefix: str) -> list[str]:
    result = check_paths(paths, targets=(target,), cache=False, jobs=1)
    predicted = {fr.file: any(f.level == "error" and f.code.startswith(prefix)
                              for f in fr.findings) for fr in result.files}
    actual = load(target, paths)
    return [f"{p}: predicted {'refused' if predicted[p] else 'loads'}, {target} "
            f"{'refused: ' + actual[p].message if actual[p].refused else 'loads'}"
            for p in paths if predicted[p] != actual[p].refused]


@pytest.mark.slow
@pytest.mark.parametrize("target,prefix", [("ros", "T1"), ("pinocchio", "T2"), ("drake", "T3"),
                                           ("mujoco", "T4")])
def test_an_error_exactly_where_the_engine_refuses_all_of_pybullet_data(
        target: str, prefix: str) -> None:
    paths = _pybullet_data_urdfs(limit_random=False)
    assert len(paths) > 1000
    assert _agreement(paths, target, prefix) == []


def test_target_findings_are_cached_apart_and_in_every_format(tmp_path: Path,
                                                             monkeypatch: pytest.MonkeyPatch
                                                             ) -> None:
    monkeypatch.setenv("URDFKIT_CACHE_DIR", str(tmp_path / "cache"))
    path = _write(tmp_path, REFUSED["T120"][0])
    plain = check_paths([str(path)])
    aimed = check_paths([str(path)], targets=("ros",))
    again = check_paths([str(path)], targets=("ros",))
    assert not any(f.code.startswith("T") for f in plain.findings)
    assert [f.code for f in aimed.findings if f.code.startswith("T")] == ["T120"]
    assert again.files[0].cached and again.findings == aimed.findings
    out = subprocess.run(["urdfkit", "check", str(path), "--target", "ros", "--format",
                          "sarif"], capture_output=True, text=True)
    sarif = json.loads(out.stdout)
    assert out.returncode == 1
    assert any(r["ruleId"] == "T120" for r in sarif["runs"][0]["results"])
    assert any(rule["id"] == "T120" for rule in sarif["runs"][0]["tool"]["driver"]["rules"])


@pytest.mark.slow
@pytest.mark.parametrize("target,prefix", [("ros", "T1"), ("pinocchio", "T2"), ("drake", "T3"),
                                           ("mujoco", "T4")])
def test_at_least_98_percent_agreement_on_seeded_mutants(target: str, prefix: str,
                                                          tmp_path: Path) -> None:
    """The fuzzer's mutants of real robots (tests/fuzz): byte flips, deleted and moved
    elements, hostile numbers and names. Measured: 99.3-99.9% on 1,000 (docs/engines.md)."""
    import random

    from fuzz.mutate import mutate, seeds

    rng = random.Random(1)
    pool = seeds()
    names = sorted(pool)
    paths = []
    for k in range(300):
        name = names[rng.randrange(len(names))]
        path = tmp_path / f"m{k:04d}.urdf"
        path.write_bytes(mutate(name, pool[name], rng).data)
        paths.append(str(path))
    wrong = _agreement(paths, target, prefix)
    assert len(wrong) <= 0.02 * len(paths), wrong


# ---- Drake (its MultibodyPlant: kinematics and dynamics)

I3 = ('<inertial><mass value="1"/><inertia ixx="0.1" iyy="0.1" izz="0.1" ixy="0" ixz="0" '
      'iyz="0"/></inertial>')

#: What Drake refuses: code -> (fixture, its twin that loads).
DRAKE_REFUSED: dict[str, tuple[str, str]] = {
    "T301": ('<model name="r"><link name="a"/></model>', links(I3)),
    "T303": (f'<robot><link name="a">{I3}</link></robot>', links(I3)),
    "T305": (f'<robot name="r"><link name="a">{I3}</link><link>{I3}</link></robot>',
             links(I3)),
    "T307": (f'<robot name="r"><link name="a">{I3}</link><link name="a">{I3}</link></robot>',
             links(I3)),
    "T309": (joint("revolute").replace(' type="revolute"', ""), joint()),
    "T311": ('<robot name="r"><link name="a">' + I3 + '</link><link name="b">' + I3 +
             f'</link><joint name="j" type="revolute"><child link="b"/>{LIM}</joint></robot>',
             joint()),
    "T312": ('<robot name="r"><link name="a">' + I3 + '</link><joint name="j" '
             f'type="revolute"><parent link="a"/><child link="zz"/>{LIM}</joint></robot>',
             joint()),
    "T313": (joint("spherical", ""), joint("fixed", "")),
    "T315": (joint("revolute", LIM + '<axis xyz="0 0 0"/>'),
             joint("revolute", LIM + '<axis xyz="0 0 1"/>')),
    "T316": (joint("fixed", '<origin xyz="0 0 $(optenv Z 0.1)"/>'),
             joint("fixed", '<origin xyz="0 0 0.1"/>')),
    "T317": (joint("revolute", '<limit lower="-inf" upper="1" effort="1" velocity="1"/>'),
             joint()),
    "T318": (joint("revolute", '<limit lower="1" upper="-1" effort="1" velocity="1"/>'),
             joint()),
    "T321": ('<robot name="r"><link name="a">' + I3 + '</link><link name="b">' + I3 +
             '</link><link name="c">' + I3 + '</link><joint name="j1" type="fixed"><parent '
             'link="a"/><child link="b"/></joint><joint name="j2" type="fixed"><parent '
             'link="b"/><child link="c"/></joint><joint name="j3" type="fixed"><parent '
             'link="c"/><child link="a"/></joint></robot>', joint("fixed", "")),
    "T324": ('<robot name="r"><material name="m"/><link name="a">' + I3 + '</link></robot>',
             '<robot name="r"><material name="m"><color rgba="1 0 0 1"/></material><link '
             'name="a">' + I3 + '</link></robot>'),
    "T328": (joint("revolute", LIM + '<mimic joint="zz"/>'), joint()),
    "T329": (joint("revolute", LIM).replace("</robot>", '<transmission name="t"><joint '
             'name="j"/><actuator name="m"/></transmission></robot>'),
             joint("revolute", LIM).replace("</robot>", '<transmission name="t"><type>'
             'transmission_interface/SimpleTransmission</type><joint name="j"/><actuator '
             'name="m"/></transmission></robot>')),
}


BOX = '<collision><geometry><box size="0.2 0.2 0.2"/></geometry></collision>'

#: What Drake refuses in geometry, as a simulation loads it (a plant with a SceneGraph).
DRAKE_GEOMETRY: dict[str, tuple[str, str]] = {
    "T331": (links(I3 + "<collision><origin/></collision>"), links(I3 + BOX)),
    "T334": (links(I3 + '<collision><geometry><cylinder radius="0" length="1"/></geometry>'
                   "</collision>"),
             links(I3 + '<collision><geometry><cylinder radius="0.1" length="1"/></geometry>'
                   "</collision>")),
    "T336": (links(I3 + '<visual><geometry><mesh filename="package://nopkg/m.obj"/>'
                   "</geometry></visual>"), links(I3 + BOX)),
    "T338": (links(I3 + '<visual><geometry><mesh filename="nope.obj"/></geometry></visual>'),
             links(I3 + BOX)),
    "T339": (links(I3 + '<collision><geometry><mesh filename="m.stl"/></geometry>'
                   "</collision>"),
             links(I3 + '<collision><geometry><mesh filename="m.obj"/></geometry>'
                   "</collision>")),
    "T340": (links(I3 + '<visual><geometry><box size="1 1 1"/></geometry><material '
                   'name="nope"/></visual>'),
             links(I3 + '<visual><geometry><box size="1 1 1"/></geometry><material '
                   'name="red"><color rgba="1 0 0 1"/></material></visual>')),
}

OBJ_TETRA = "v 0 0 0\nv 0.1 0 0\nv 0 0.1 0\nv 0 0 0.1\nf 1 3 2\nf 1 2 4\nf 1 4 3\nf 2 3 4\n"


@pytest.mark.parametrize("code", sorted(DRAKE_GEOMETRY))
def test_each_drake_geometry_refusal_is_refused_by_drake(code: str, tmp_path: Path) -> None:
    import struct

    (tmp_path / "m.obj").write_text(OBJ_TETRA, encoding="ascii")
    (tmp_path / "m.stl").write_bytes(b"\0" * 80 + struct.pack("<I", 1) +
                                     struct.pack("<12f", 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1, 0)
                                     + b"\0\0")
    bad, good = DRAKE_GEOMETRY[code]
    path = _write(tmp_path, bad)
    assert _codes(path, ("drake",)).get(code) == "error"
    assert _drake(path).refused  # type: ignore[attr-defined]
    twin = _write(tmp_path, good, "twin.urdf")
    assert not any(level == "error" for level in _codes(twin, ("drake",)).values())
    assert not _drake(twin).refused  # type: ignore[attr-defined]


def _drake(path: Path) -> object:
    return load("drake", [str(path)])[str(path)]


@pytest.mark.parametrize("code", sorted(DRAKE_REFUSED))
def test_each_drake_refusal_is_refused_by_drake(code: str, tmp_path: Path) -> None:
    bad, good = DRAKE_REFUSED[code]
    path = _write(tmp_path, bad)
    assert _codes(path, ("drake",)).get(code) == "error"
    outcome = _drake(path)
    assert outcome.refused, outcome  # type: ignore[attr-defined]
    twin = _write(tmp_path, good, "twin.urdf")
    assert not any(level == "error" for level in _codes(twin, ("drake",)).values())
    assert not _drake(twin).refused  # type: ignore[attr-defined]


def test_drake_masses_and_dropped_joints(tmp_path: Path) -> None:
    """T353 (no inertial: 0 kg), T355 (mass 0 with inertia: 1 kg), T361 (1,5 read as 1),
    T363 and T370 (a floating or nameless joint dropped: its child a free body, nq 14)."""
    cases = {
        "T353": ('<robot name="r"><link name="a">' + I3 + '</link><link name="b"/><joint '
                 f'name="j" type="revolute"><parent link="a"/><child link="b"/>{LIM}</joint>'
                 '</robot>', "b", 0.0),
        "T355": (joint().replace('<link name="b"><inertial><mass value="1"/>',
                                 '<link name="b"><inertial><mass value="0"/>'), "b", 1.0),
        "T361": (joint().replace('<link name="b"><inertial><mass value="1"/>',
                                 '<link name="b"><inertial><mass value="2,5"/>'), "b", 2.0),
    }
    for code, (text, link, mass) in cases.items():
        path = _write(tmp_path, text, f"{code}.urdf")
        assert _codes(path, ("drake",)).get(code) == "warning", code
        outcome = _drake(path)
        got = outcome.model["masses"][link]  # type: ignore[attr-defined]
        assert math.isclose(got, mass, abs_tol=1e-12), (code, outcome)
    for code, text in (("T363", joint("floating", "")),
                       ("T370", joint("revolute").replace('name="j"', 'name=""'))):
        path = _write(tmp_path, text, f"{code}.urdf")
        assert _codes(path, ("drake",)).get(code) == "warning", code
        assert _drake(path).model["nq"] == 14, code  # type: ignore[attr-defined]
    assert _drake(_write(tmp_path, joint(), "twin.urdf")).model["nq"] == 8  # type: ignore[attr-defined]


def test_drake_drops_joint_friction_with_a_warning(tmp_path: Path) -> None:
    import logging

    from pydrake.multibody.parsing import Parser
    from pydrake.multibody.plant import MultibodyPlant

    path = _write(tmp_path, joint("revolute", LIM + '<dynamics damping="0.1" friction="0.2"/>'))
    assert _codes(path, ("drake",)).get("T362") == "warning"
    said: list[str] = []

    class Keep(logging.Handler):
        def emit(self, record: logging.LogRecord) -> None:
            said.append(record.getMessage())

    handler = Keep()
    logging.getLogger("drake").addHandler(handler)
    try:
        plant = MultibodyPlant(0.0)
        Parser(plant).AddModels(str(path))
    finally:
        logging.getLogger("drake").removeHandler(handler)
    assert any("friction" in m for m in said), said


# ---- MuJoCo's own URDF reader

#: What MuJoCo's reader refuses: code -> (fixture, its twin that loads).
MUJOCO_REFUSED: dict[str, tuple[str, str]] = {
    "T401": ('<model name="r"><link name="a"/></model>', links(I3)),
    "T403": (joint("revolute", LIM + "<axis/>"), joint("revolute", LIM + '<axis xyz="0 0 1"/>')),
    "T404": (links(I3 + "<collision/>"), links(I3 + BOX)),
    "T405": (joint("fixed", '<origin xyz="0 0 1"/><origin xyz="0 0 1"/>'),
             joint("fixed", '<origin xyz="0 0 1"/>')),
    "T406": (f'<robot name="r"><link name="a">{I3}</link><link name="a">{I3}</link></robot>',
             links(I3)),
    "T407": (joint("fixed", "").replace('<parent link="a"/>', '<parent link="world"/>'),
             joint("fixed", "")),
    "T408": (DRAKE_REFUSED["T321"][0], joint("fixed", "")),
    "T410": (joint("hinge", LIM), joint("revolute", LIM)),
    "T411": (joint("revolute", '<limit lower="-1.57." upper="1" effort="1" velocity="1"/>'),
             joint()),
    "T412": (joint("fixed", '<origin rpy="0 0 0 0"/>'), joint("fixed", '<origin rpy="0 0 0"/>')),
    "T414": (links(I3 + '<collision><geometry><plane normal="0 0 1"/></geometry></collision>'),
             links(I3 + BOX)),
    "T420": ('<robot name="r"><link name="a">' + I3 + '</link><link name="b"/><joint name="j" '
             f'type="revolute"><parent link="a"/><child link="b"/>{LIM}</joint></robot>',
             joint()),
    "T421": (joint().replace('<link name="b"><inertial><mass value="1"/><inertia ixx="1" ixy="0" '
                             'ixz="0" iyy="1" iyz="0" izz="1"/>', '<link name="b"><inertial><mass '
                             'value="1"/><inertia ixx="0.1" ixy="0" ixz="0" iyy="0.1" iyz="0" '
                             'izz="0.5"/>'), joint()),
    "T423": (joint("revolute", LIM + '<axis xyz="0 0 0"/>'),
             joint("revolute", LIM + '<axis xyz="0 0 1"/>')),
    "T424": (links(I3 + '<collision><geometry><sphere radius="0"/></geometry></collision>'),
             links(I3 + '<collision><geometry><sphere radius="0.1"/></geometry></collision>')),
    "T425": ('<robot name="r"><link name="a">' + I3 + '</link><link name="b">' + I3 + '</link>'
             '<link name="c">' + I3 + f'</link><joint name="j" type="revolute"><parent link="a"/>'
             f'<child link="b"/>{LIM}</joint><joint name="f" type="floating"><parent link="b"/>'
             '<child link="c"/></joint></robot>', joint("floating", "")),
    "T426": (links(I3 + '<collision><geometry><mesh filename="package://nopkg/m.stl"/>'
                   '</geometry></collision>'), links(I3 + BOX)),
}


@pytest.mark.parametrize("code", sorted(MUJOCO_REFUSED))
def test_each_mujoco_refusal_is_refused_by_mujoco(code: str, tmp_path: Path) -> None:
    bad, good = MUJOCO_REFUSED[code]
    path = _write(tmp_path, bad)
    assert _codes(path, ("mujoco",)).get(code) == "error"
    outcome = load("mujoco", [str(path)])[str(path)]
    assert outcome.refused, outcome
    twin = _write(tmp_path, good, "twin.urdf")
    assert not any(level == "error" for level in _codes(twin, ("mujoco",)).values())
    assert not load("mujoco", [str(twin)])[str(twin)].refused


def test_mujoco_meshes_as_its_reader_finds_and_decodes_them(tmp_path: Path) -> None:
    """T426: an ASCII STL and COLLADA refuse; the extension's meshdir is where meshes are."""
    import struct

    (tmp_path / "m").mkdir()
    faces = (((0, 0, 0), (0.1, 0, 0), (0, 0.1, 0)), ((0, 0, 0), (0, 0, 0.1), (0.1, 0, 0)),
             ((0, 0, 0), (0, 0.1, 0), (0, 0, 0.1)), ((0.1, 0, 0), (0, 0, 0.1), (0, 0.1, 0)))
    tetrahedron = b"".join(struct.pack("<12f", 0, 0, 0, *a, *b, *c) + b"\0\0"
                           for a, b, c in faces)  # normal, three corners, attribute
    (tmp_path / "m" / "t.stl").write_bytes(b"\0" * 80 + struct.pack("<I", 4) + tetrahedron)
    (tmp_path / "m" / "a.stl").write_text("solid a\nendsolid a\n", encoding="ascii")
    mesh = '<collision><geometry><mesh filename="{}"/></geometry></collision>'
    cases = {
        "binary STL beside meshdir": ('<robot name="r"><mujoco><compiler meshdir="m"/></mujoco>'
                                      '<link name="a">' + I3 + mesh.format("t.stl") +
                                      "</link></robot>", False),
        "the same without meshdir": (links(I3 + mesh.format("t.stl")), True),
        "ASCII STL": (links(I3 + mesh.format("m/a.stl")), True),
        "package:// with strippath": ('<robot name="r"><mujoco><compiler meshdir="m" '
                                      'strippath="true"/></mujoco><link name="a">' + I3 +
                                      mesh.format("package://p/t.stl") + "</link></robot>",
                                      False),
    }
    for case, (text, refused) in cases.items():
        path = _write(tmp_path, text, "r.urdf")
        assert ("T426" in _codes(path, ("mujoco",))) is refused, case
        assert load("mujoco", [str(path)])[str(path)].refused is refused, case


def test_mujoco_welds_fuses_fills_and_drops_limits(tmp_path: Path) -> None:
    """T450 (the root welded: no free joint), T451 (a fixed child fused away), T453 (a link
    without <inertial> weighs its shapes in water), T455 (limits dropped)."""
    welded = _write(tmp_path, joint(), "welded.urdf")
    assert _codes(welded, ("mujoco",)).get("T450") == "warning"
    model = load("mujoco", [str(welded)])[str(welded)].model
    assert model["nq"] == 1 and "a" not in model["bodies"]  # PyBullet: a free base, nq 7 + 1
    fused = _write(tmp_path, joint("revolute").replace("</robot>", '<link name="c">' + I3 +
                   '</link><joint name="f" type="fixed"><parent link="b"/><child link="c"/>'
                   "</joint></robot>"), "fused.urdf")
    assert _codes(fused, ("mujoco",)).get("T451") == "info"
    model = load("mujoco", [str(fused)])[str(fused)].model
    assert "c" not in model["bodies"] and math.isclose(model["masses"]["b"], 2.0)
    water = _write(tmp_path, '<robot name="r"><link name="a">' + I3 + '</link><link name="b">'
                   f'{BOX}</link><joint name="j" type="revolute"><parent link="a"/><child '
                   f'link="b"/>{LIM}</joint></robot>', "water.urdf")
    assert _codes(water, ("mujoco",)).get("T453") == "warning"
    model = load("mujoco", [str(water)])[str(water)].model
    assert math.isclose(model["masses"]["b"], 1000 * 0.2 ** 3)  # PyBullet: 1 kg
    for inner in ('<limit lower="-1" effort="1" velocity="1"/>', LIM):
        kind = "continuous" if inner == LIM else "revolute"
        path = _write(tmp_path, joint(kind, inner), "limit.urdf")
        assert _codes(path, ("mujoco",)).get("T455") == "warning"
        assert load("mujoco", [str(path)])[str(path)].model["limited"] == [False]
    assert load("mujoco", [str(welded)])[str(welded)].model["limited"] == [True]


@pytest.mark.parametrize("value", ["", " ", "nan", "1e309", "-inf", "1 2", "abc", "0x1", "1,5",
                                   "0.1abc", "-1e308", "1e-320", "-0"])
def test_no_value_in_any_number_stops_a_target(value: str, tmp_path: Path) -> None:
    """Every numeric attribute given a hostile value: each target judges the file, none
    raises (a limit's empty ``lower`` once did, in MuJoCo's limit rule)."""
    import re

    base = joint("revolute", LIM + '<axis xyz="0 0 1"/><dynamics damping="0.1" '
                 'friction="0.1"/><mimic joint="j" multiplier="1" offset="0"/>')
    base = base.replace("<link name=\"b\">", '<link name="b"><collision><origin xyz="0 0 0"/>'
                        '<geometry><box size="1 1 1"/></geometry></collision><collision>'
                        '<geometry><cylinder radius="0.1" length="0.2"/></geometry>'
                        '</collision><visual><geometry><sphere radius="0.1"/></geometry>'
                        '<material name="m"><color rgba="1 0 0 1"/></material></visual>'
                        '<visual><geometry><mesh filename="m.obj" scale="1 1 1"/></geometry>'
                        '</visual>')
    spots = list(re.finditer(r'(\w+)="([^"]*)"', base))
    for k, m in enumerate(spots):
        if m.group(1) in ("name", "type", "link", "joint"):
            continue
        text = base[:m.start(2)] + value + base[m.end(2):]
        path = _write(tmp_path, text, f"v{k}.urdf")
        found = check_file(str(path), path, targets=("ros", "pinocchio", "drake", "mujoco"))
        assert all(f.code != "U000" for f in found.findings), (m.group(1), found.findings)


def test_a_missing_texture_refuses_drake(tmp_path: Path) -> None:
    """Drake resolves a material's texture as it resolves a mesh (T338, T336)."""
    for where in ("visual", "top"):
        material = '<material name="m"><texture filename="t.png"/></material>'
        text = ('<robot name="r">' + (material if where == "top" else "") + '<link name="a">'
                + I3 + '<visual><geometry><box size="1 1 1"/></geometry>'
                + (material if where == "visual" else '<material name="m"/>')
                + "</visual></link></robot>")
        path = _write(tmp_path, text, f"{where}.urdf")
        (tmp_path / "t.png").unlink(missing_ok=True)
        assert _codes(path, ("drake",)).get("T338") == "error", where
        assert _drake(path).refused, where  # type: ignore[attr-defined]
        (tmp_path / "t.png").write_bytes(b"\x89PNG\r\n\x1a\n")
        assert "T338" not in _codes(path, ("drake",)), where
        assert not _drake(path).refused, where  # type: ignore[attr-defined]


def test_mujoco_reads_hexadecimal_numbers_as_strtod_does(tmp_path: Path) -> None:
    path = _write(tmp_path, joint("revolute", '<limit lower="-0x1" upper="0x1.8p0" effort="1" '
                                  'velocity="1"/>'))
    assert not any(level == "error" for level in _codes(path, ("mujoco",)).values())
    outcome = load("mujoco", [str(path)])[str(path)]
    assert not outcome.refused and outcome.model["limited"] == [True]


def test_an_empty_target_or_a_selection_of_codes_not_targeted_is_refused(
        tmp_path: Path) -> None:
    from urdfkit.checks.targets import check_selection

    for given in ([""], [","], [" , "]):
        with pytest.raises(ParameterError, match="names no target"):
            parse_targets(given)
    with pytest.raises(ParameterError, match="--target drake"):
        check_selection(("T3",), ("ros",))
    with pytest.raises(ParameterError, match="--target mujoco"):
        check_selection(("T426",), ())
    check_selection(("T", "U6"), ("mujoco",))  # some target's codes: fine
    path = _write(tmp_path, joint())
    with pytest.raises(ParameterError):
        check_paths([str(path)], select=("T1",), cache=False)


#: Every target code, and the test above that holds it against its engine.
TESTED = {*REFUSED, "T101", "T150", "T163", "T169", "T200", "T201", "T204", "T220", "T222", "T223",
          "T224", "T225", "T226", "T227", "T353", "T355", "T361", "T362", "T363", "T370",
          *DRAKE_REFUSED, *DRAKE_GEOMETRY, *MUJOCO_REFUSED, "T450", "T451", "T453", "T455"}


def test_every_target_code_has_a_summary_a_test_and_targets_are_checked() -> None:
    assert set(TARGET_CODES) == TESTED
    assert all(code.startswith("T") and text for code, text in TARGET_CODES.items())
    assert parse_targets(["ros,pinocchio", "pybullet"]) == ("ros", "pinocchio")
    with pytest.raises(ParameterError, match="did you mean 'ros'"):
        parse_targets(["rso"])
