"""One spec: every command accepts and refuses the same documents.

Four lists of joint types and shapes once disagreed, and ``build`` refused a spherical joint that
``check`` and ``joints`` accepted. Each case here goes through every reader: the builder model,
``build`` (as a xacro with no xacro in it), ``check``, and the loading commands. Accepted means
accepted by all of them (PyBullet extensions get an info note from check); refused means refused
by all of them, each with a message naming the file.
"""

from __future__ import annotations

import json
from pathlib import Path

import pytest
from typer.testing import CliRunner

from urdfkit.builder import Robot
from urdfkit.cli import app
from urdfkit.core.errors import ModelError
from urdfkit.model.spec import JOINT_TYPES, PYBULLET_JOINT_TYPES, PYBULLET_SHAPES, SHAPES

runner = CliRunner()

INERTIAL = ('<inertial><mass value="1"/><inertia ixx="0.01" ixy="0" ixz="0" iyy="0.01" '
            'iyz="0" izz="0.01"/></inertial>')


def robot(joint_type: str = "fixed", shape: str = '<box size="0.1 0.1 0.1"/>',
          joint_inner: str = "") -> str:
    return f"""<?xml version="1.0"?>
<robot name="agree">
  <link name="base">{INERTIAL}
    <collision><geometry>{shape}</geometry></collision>
  </link>
  <link name="tip">{INERTIAL}
    <collision><geometry><sphere radius="0.05"/></geometry></collision>
  </link>
  <joint name="j" type="{joint_type}">
    <parent link="base"/><child link="tip"/><origin xyz="0 0 0.2"/>{joint_inner}
  </joint>
</robot>
"""


LIMIT = '<axis xyz="0 0 1"/><limit lower="-1" upper="1" effort="1" velocity="1"/>'

ACCEPTED = {
    "spherical joint": robot("spherical"),
    "capsule": robot(shape='<capsule radius="0.05" length="0.2"/>'),
    "plane": robot(shape='<plane normal="0 0 1"/>'),
    "planar joint": robot("planar", joint_inner='<axis xyz="0 0 1"/>'),
    "revolute joint": robot("revolute", joint_inner=LIMIT),
    "continuous joint": robot("continuous", joint_inner='<axis xyz="0 1 0"/>'),
    # PyBullet ignores an <origin> after the shape; check warns (U504), nobody refuses.
    "origin after the shape": robot(shape='<box size="0.1 0.1 0.1"/><origin xyz="0 0 1"/>'),
}
# PyBullet loads these, but not as written: two shapes in one <geometry> load as the first
# (measured, issue 24.19). check warns and every loading command loads them and says so; the
# model API (Robot.from_file, strict) refuses, as writing it back would drop the rest.
WARNED = {
    "two shapes": (robot(shape='<box size="1 1 1"/><sphere radius="1"/>'), "U507"),
}
# Not URDF by the spec: PyBullet refuses these or silently misreads them, so every command
# refuses them.
REFUSED = {
    "unknown joint type": robot("hinge"),
    "unknown shape": robot(shape='<cone radius="0.1" length="0.2"/>'),
    "revolute without limit": robot("revolute", joint_inner='<axis xyz="0 0 1"/>'),
    "origin before the shape": robot(shape='<origin xyz="0 0 1"/><box size="0.1 0.1 0.1"/>'),
    "inertia missing a component": robot().replace('izz="0.01"', "", 1),
    "inertial without inertia": robot().replace(
        '<inertia ixx="0.01" ixy="0" ixz="0" iyy="0.01" iyz="0" izz="0.01"/>', "", 1),
}
# URDF with a wrong value: check reports an error, the model and build refuse to write it, and
# the loading commands still load it, as PyBullet does (pybullet_data's laikago has zero-radius
# spheres, and users inspect it).
VALUE_ERRORS = {
    "non-positive size": robot(shape='<box size="0.1 0 0.1"/>'),
    "lower above upper": robot("revolute", joint_inner='<axis xyz="0 0 1"/><limit lower="1" '
                                                       'upper="-1" effort="1" velocity="1"/>'),
}

LOADING = (["joints", "--json"], ["links", "--json"], ["info", "--json"], ["tree", "--json"])


def _write(tmp_path: Path, name: str, text: str) -> Path:
    path = tmp_path / (name.replace(" ", "_") + ".urdf")
    path.write_text(text)
    return path


def test_the_cases_cover_the_spec_extensions() -> None:
    said = " ".join(ACCEPTED)
    assert all(t in said for t in PYBULLET_JOINT_TYPES)
    assert all(s in said for s in PYBULLET_SHAPES if s != "cdf")  # cdf needs an SDF file
    assert set(PYBULLET_JOINT_TYPES) <= set(JOINT_TYPES)
    assert set(PYBULLET_SHAPES) <= set(SHAPES)


@pytest.mark.parametrize("case", sorted(ACCEPTED))
def test_every_command_accepts(case: str, tmp_path: Path) -> None:
    path = _write(tmp_path, case, ACCEPTED[case])
    robot_model = Robot.from_file(path)
    assert robot_model.to_bytes()  # writes back too
    result = runner.invoke(app, ["check", str(path), "--json"])
    assert result.exit_code == 0, result.output
    findings = json.loads(result.stdout)["findings"]
    assert not [f for f in findings if f["level"] == "error"], findings
    xacro = tmp_path / (path.stem + ".urdf.xacro")
    xacro.write_text(ACCEPTED[case])
    built = runner.invoke(app, ["build", str(xacro), "-o", str(tmp_path / "out.urdf")])
    assert built.exit_code == 0, built.output
    for command in LOADING:
        result = runner.invoke(app, [command[0], str(path), *command[1:]])
        assert result.exit_code == 0, (command, result.output)
        json.loads(result.stdout)


@pytest.mark.parametrize("case", sorted(WARNED))
def test_every_loading_command_loads_and_warns(case: str, tmp_path: Path) -> None:
    text, code = WARNED[case]
    path = _write(tmp_path, case, text)
    result = runner.invoke(app, ["check", str(path), "--json"])
    assert result.exit_code == 0, result.output
    findings = json.loads(result.stdout)["findings"]
    assert not [f for f in findings if f["level"] == "error"], findings
    assert [f["level"] for f in findings if f["code"] == code] == ["warning"]
    for command in LOADING:
        result = runner.invoke(app, [command[0], str(path), *command[1:]])
        assert result.exit_code == 0, (command, result.output)
        json.loads(result.stdout)
        assert f"({code})" in result.stderr, (command, result.stderr)
    with pytest.raises(ModelError):
        Robot.from_file(path)


@pytest.mark.parametrize("case", sorted(REFUSED))
def test_every_command_refuses(case: str, tmp_path: Path) -> None:
    path = _write(tmp_path, case, REFUSED[case])
    with pytest.raises(ModelError) as err:
        Robot.from_file(path)
    assert str(path) in str(err.value)
    result = runner.invoke(app, ["check", str(path), "--json"])
    assert result.exit_code == 1, result.output
    assert [f for f in json.loads(result.stdout)["findings"] if f["level"] == "error"]
    xacro = tmp_path / (path.stem + ".urdf.xacro")
    xacro.write_text(REFUSED[case])
    built = runner.invoke(app, ["build", str(xacro), "-o", str(tmp_path / "out.urdf")])
    assert built.exit_code == 2, built.output
    assert xacro.name in built.output
    for command in LOADING:
        result = runner.invoke(app, [command[0], str(path), *command[1:]])
        assert result.exit_code == 2, (command, result.output)
        assert path.name in result.output


@pytest.mark.parametrize("case", sorted(VALUE_ERRORS))
def test_value_errors_are_findings_everywhere_and_loadable(case: str, tmp_path: Path) -> None:
    path = _write(tmp_path, case, VALUE_ERRORS[case])
    with pytest.raises(ModelError) as err:
        Robot.from_file(path)
    assert str(path) in str(err.value)
    result = runner.invoke(app, ["check", str(path), "--json"])
    assert result.exit_code == 1, result.output
    xacro = tmp_path / (path.stem + ".urdf.xacro")
    xacro.write_text(VALUE_ERRORS[case])
    # build writes what PyBullet loads, the error as a warning naming the line (issue 24.9);
    # --strict refuses it with exit 1 and writes nothing.
    built = runner.invoke(app, ["build", str(xacro), "-o", str(tmp_path / "out.urdf")])
    assert built.exit_code == 0 and xacro.name in built.stderr, built.output
    assert "warning" in built.stderr and (tmp_path / "out.urdf").exists()
    strict = runner.invoke(app, ["build", str(xacro), "-o", str(tmp_path / "strict.urdf"),
                                 "--strict"])
    assert strict.exit_code == 1 and xacro.name in strict.stderr, strict.output
    assert not (tmp_path / "strict.urdf").exists()
    for command in LOADING:
        result = runner.invoke(app, [command[0], str(path), *command[1:]])
        assert result.exit_code == 0, (command, result.output)


def test_check_notes_pybullet_extensions_for_portability(tmp_path: Path) -> None:
    path = _write(tmp_path, "spherical", ACCEPTED["spherical joint"])
    result = runner.invoke(app, ["check", str(path), "--json"])
    notes = [f for f in json.loads(result.stdout)["findings"] if f["code"] == "U901"]
    assert len(notes) == 1 and notes[0]["level"] == "info" and "spherical" in notes[0]["message"]


def test_what_build_writes_yourdfpy_reads(tmp_path: Path) -> None:
    """An independent reader: yourdfpy's validate() accepts what build writes from a template."""
    yourdfpy = pytest.importorskip("yourdfpy")
    out = tmp_path / "car.urdf"
    assert runner.invoke(app, ["build", "simplecar", "-o", str(out)]).exit_code == 0
    urdf = yourdfpy.URDF.load(str(out), load_meshes=False, build_scene_graph=False,
                              build_collision_scene_graph=False)
    assert urdf.validate(validation_fn=lambda errors: not errors), urdf._errors
    assert {j.name for j in urdf.robot.joints} == {j.name for j in Robot.from_file(out).joints}
