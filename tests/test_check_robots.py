"""check's mass and material rules as real ROS packages meet them (issue 24, items 12, 13, 20),
each checked against raw PyBullet."""

from __future__ import annotations

from pathlib import Path

import pybullet as p
import pytest

from urdfkit.checks.check import check_paths

FOOTPRINT = """<?xml version="1.0"?>
<robot name="base">
  <link name="base_footprint">{footprint}</link>
  <link name="base_link">
    <inertial><mass value="28"/>
      <inertia ixx="1" iyy="1" izz="1" ixy="0" ixz="0" iyz="0"/></inertial>
    <collision><geometry><box size="0.6 0.4 0.2"/></geometry></collision>
  </link>
  <joint name="footprint_joint" type="fixed">
    <parent link="base_footprint"/><child link="base_link"/><origin xyz="0 0 0.1"/>
  </joint>
</robot>
"""
MASS0 = ('<inertial><mass value="0"/>'
         '<inertia ixx="0" iyy="0" izz="0" ixy="0" ixz="0" iyz="0"/></inertial>')


def _drop(path: Path) -> float:
    """How far the base falls in 1 s when loaded 1 m up in raw PyBullet."""
    c = p.connect(p.DIRECT)
    try:
        p.setGravity(0, 0, -9.81, physicsClientId=c)
        body = p.loadURDF(str(path), [0, 0, 1.0], flags=p.URDF_USE_INERTIA_FROM_FILE,
                          physicsClientId=c)
        for _ in range(240):
            p.stepSimulation(physicsClientId=c)
        return 1.0 - p.getBasePositionAndOrientation(body, physicsClientId=c)[0][2]
    finally:
        p.disconnect(physicsClientId=c)


def _findings(path: Path, code: str) -> list[object]:
    return [f for f in check_paths([path], jobs=1, cache=False).findings if f.code == code]


def test_a_mass_0_root_over_a_heavy_fixed_child_is_static_and_said(tmp_path: Path) -> None:
    static = tmp_path / "static.urdf"
    static.write_text(FOOTPRINT.format(footprint=MASS0))
    assert _drop(static) == pytest.approx(0.0, abs=1e-9)  # PyBullet: it hangs in the air
    found = _findings(static, "U611")
    assert len(found) == 1 and found[0].level == "warning"  # type: ignore[attr-defined]
    assert "28 kg" in found[0].message  # type: ignore[attr-defined]
    # With a mass of its own the same robot falls, and U611 is silent.
    falls = tmp_path / "falls.urdf"
    falls.write_text(FOOTPRINT.format(footprint=MASS0.replace('value="0"', 'value="0.1"')
                                      .replace('"0"/>', '"0.001"/>', 3)))
    assert _drop(falls) > 0.5
    assert _findings(falls, "U611") == []


def test_a_root_without_inertial_is_never_told_mass_0(tmp_path: Path) -> None:
    path = tmp_path / "r.urdf"
    path.write_text(FOOTPRINT.format(footprint=""))
    assert _drop(path) > 0.5  # no <inertial>: PyBullet gives it 1 kg, and it falls
    found = _findings(path, "U606")
    assert len(found) == 1
    message = found[0].message  # type: ignore[attr-defined]
    assert "(mass 0 for a frame)" not in message and "real mass" in message
    assert _findings(path, "U611") == []


# --------------------------------------------------------------------------- materials

BOX = '<geometry><box size="0.1 0.1 0.1"/></geometry>'


def _robot(*visual_materials: str, top: str = "") -> str:
    links = "".join(f'<link name="l{i}"><visual>{BOX}{m}</visual></link>'
                    for i, m in enumerate(visual_materials))
    joints = "".join(f'<joint name="j{i}" type="fixed"><parent link="l0"/>'
                     f'<child link="l{i}"/></joint>' for i in range(1, len(visual_materials)))
    return f'<robot name="r">{top}{links}{joints}</robot>\n'


def _load(path: Path) -> list[tuple[float, ...]] | str:
    """The colours PyBullet draws each visual in, or its refusal."""
    c = p.connect(p.DIRECT)
    try:
        body = p.loadURDF(str(path), physicsClientId=c)
    except p.error as e:
        return str(e)
    try:
        return [tuple(v[7]) for v in p.getVisualShapeData(body, physicsClientId=c)]
    finally:
        p.disconnect(physicsClientId=c)


def test_a_visual_material_without_a_name_is_refused_as_pybullet_refuses_it(
        tmp_path: Path) -> None:
    from typer.testing import CliRunner

    from urdfkit.cli import app

    nameless = tmp_path / "nameless.urdf"
    nameless.write_text(_robot('<material><color rgba="1 0 0 1"/></material>'))
    empty = tmp_path / "empty.urdf"
    empty.write_text(_robot('<material name=""><color rgba="1 0 0 1"/></material>'))
    assert _load(nameless) == "Cannot load URDF file."  # PyBullet refuses it
    assert _load(empty) == [(1.0, 0.0, 0.0, 1.0)]  # name="" loads, in its colour
    found = _findings(nameless, "U110")
    assert len(found) == 1 and found[0].level == "error" and found[0].line == 1  # type: ignore[attr-defined]
    assert _findings(empty, "U110") == []
    for command in ("joints", "links", "info"):
        result = CliRunner().invoke(app, [command, str(nameless)])
        assert result.exit_code == 2
        assert result.stderr.startswith(f"urdfkit: error: {nameless}:1: <material> of a")
        assert "b3Error" not in result.stderr
        assert CliRunner().invoke(app, [command, str(empty)]).exit_code == 0


def test_a_top_level_material_without_a_name_loads_with_a_warning(tmp_path: Path) -> None:
    from typer.testing import CliRunner

    from urdfkit.cli import app

    for top in ('<material><color rgba="1 0 0 1"/></material>',
                '<material name=""><color rgba="1 0 0 1"/></material>'):
        path = tmp_path / "top.urdf"
        path.write_text(_robot('<material name="m"><color rgba="0 0 1 1"/></material>',
                               top=top))
        assert isinstance(_load(path), list)  # PyBullet loads it
        assert [f.level for f in _findings(path, "U109")] == ["warning"]  # type: ignore[attr-defined]
        assert CliRunner().invoke(app, ["joints", str(path)]).exit_code == 0


def test_one_material_name_with_several_colours_is_drawn_in_one(tmp_path: Path) -> None:
    path = tmp_path / "shared.urdf"
    path.write_text(_robot(*(f'<material name=""><color rgba="{c}"/></material>'
                             for c in ("0 0 1 1", "1 0 0 1", "0 1 0 1"))))
    drawn = _load(path)
    assert isinstance(drawn, list) and len(set(drawn)) == 1  # PyBullet: one colour for all
    found = _findings(path, "U710")
    assert len(found) == 1
    message = found[0].message  # type: ignore[attr-defined]
    assert "0 0 1 1, 1 0 0 1, 0 1 0 1" in message
    # the colour the warning names is the one PyBullet draws
    named = message.split("rgba ")[1].split(";")[0]
    assert tuple(float(x) for x in named.split()) == drawn[0]
    distinct = tmp_path / "distinct.urdf"
    distinct.write_text(_robot('<material name="a"><color rgba="1 0 0 1"/></material>',
                               '<material name="b"><color rgba="0 1 0 1"/></material>'))
    assert len(set(_load(distinct))) == 2 and _findings(distinct, "U710") == []
