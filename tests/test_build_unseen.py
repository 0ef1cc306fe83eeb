"""build on xacro as real packages write it (issue 24, items 9-11): what PyBullet loads is
written (check's errors as warnings naming the file and line they were written on), inline and
empty-named materials expand as xacro itself expands them, and a .urdf holding xacro is said
to be one by every command and expanded by build. References: the xacro package's own
expansion and raw p.loadURDF."""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

import pytest

from urdfkit.engine.session import quiet_stdout

INERTIAL = ('<inertial><mass value="1"/><inertia ixx="0.01" iyy="0.01" izz="0.01" ixy="0" '
            'ixz="0" iyz="0"/></inertial>')

INCLUDE = """<?xml version="1.0"?>
<robot xmlns:xacro="http://www.ros.org/wiki/xacro">
  <xacro:macro name="part" params="name rgba">
    <link name="${name}">
      INERTIAL
      <visual>
        <geometry><box size="0.1 0.1 0.1"/></geometry>
        <material name="">
          <color rgba="${rgba}"/>
        </material>
      </visual>
    </link>
  </xacro:macro>
  <xacro:macro name="antenna" params="name">
    <link name="${name}">
      <inertial>
        <mass value="0.1"/>
        <inertia ixx="0.01" iyy="0.01" izz="0.5" ixy="0" ixz="0" iyz="0"/>
      </inertial>
    </link>
  </xacro:macro>
  <xacro:macro name="crasher" params="name">
    <link name="${name}%x"/>
  </xacro:macro>
</robot>
""".replace("INERTIAL", INERTIAL)


def _top(body: str) -> str:
    return ('<?xml version="1.0"?>\n<robot name="t" xmlns:xacro="http://www.ros.org/wiki/xacro">\n'
            '  <xacro:include filename="inc.xacro"/>\n' + body + "</robot>\n")


def _files(tmp_path: Path, body: str, name: str = "top.urdf.xacro") -> Path:
    (tmp_path / "inc.xacro").write_text(INCLUDE)
    path = tmp_path / name
    path.write_text(_top(body))
    return path


def _cli(*args: str, cwd: Path | None = None) -> subprocess.CompletedProcess[str]:
    return subprocess.run([sys.executable, "-m", "urdfkit", *args], capture_output=True,
                          text=True, timeout=120, cwd=cwd)


def _xacro_expand(path: Path) -> str:
    """The xacro package's own expansion, written out (the independent reference)."""
    import xacro

    return xacro.process_file(str(path)).toprettyxml(indent="  ")


def _raw_colours(path: Path) -> list[tuple[str, tuple[float, ...]]]:
    import pybullet as p

    with quiet_stdout():
        c = p.connect(p.DIRECT)
    try:
        with quiet_stdout():
            body = p.loadURDF(str(path), physicsClientId=c)
        names = {-1: p.getBodyInfo(body, physicsClientId=c)[0].decode()}
        for j in range(p.getNumJoints(body, physicsClientId=c)):
            names[j] = p.getJointInfo(body, j, physicsClientId=c)[12].decode()
        return [(names[v[1]], tuple(round(x, 5) for x in v[7]))
                for v in p.getVisualShapeData(body, physicsClientId=c)]
    finally:
        p.disconnect(physicsClientId=c)


def test_inline_materials_with_empty_names_build_as_xacro_expands_them(tmp_path: Path) -> None:
    path = _files(tmp_path, '  <xacro:part name="a" rgba="0.8 0.1 0.1 1"/>\n'
                            '  <xacro:part name="b" rgba="0.1 0.8 0.1 1"/>\n'
                            '  <joint name="j" type="fixed"><parent link="a"/>'
                            '<child link="b"/></joint>\n')
    out = tmp_path / "out.urdf"
    r = _cli("build", str(path), "-o", str(out))
    assert r.returncode == 0, r.stderr
    reference = tmp_path / "reference.urdf"
    reference.write_text(_xacro_expand(path))
    # The same bodies as xacro's own expansion, loaded by raw PyBullet: colour for colour.
    assert _raw_colours(out) == _raw_colours(reference)
    assert len(_raw_colours(out)) == 2


def test_a_physics_error_is_a_warning_naming_the_included_line(tmp_path: Path) -> None:
    path = _files(tmp_path, f'  <link name="base">{INERTIAL}</link>\n'
                            '  <xacro:antenna name="ant"/>\n'
                            '  <joint name="j" type="fixed"><parent link="base"/>'
                            '<child link="ant"/></joint>\n')
    line = next(i for i, t in enumerate(INCLUDE.splitlines(), 1) if 'izz="0.5"' in t)
    out = tmp_path / "out.urdf"
    r = _cli("build", str(path), "-o", str(out))
    assert r.returncode == 0, r.stderr
    warned = [ln for ln in r.stderr.splitlines() if ln.startswith("urdfkit: warning:")]
    assert len(warned) == 1 and f"inc.xacro:{line}:" in warned[0] and "(U604)" in warned[0]
    import pybullet as p

    with quiet_stdout():
        c = p.connect(p.DIRECT)
    try:
        with quiet_stdout():
            body = p.loadURDF(str(out), physicsClientId=c)  # PyBullet loads what was written
        assert p.getNumJoints(body, physicsClientId=c) == 1
    finally:
        p.disconnect(physicsClientId=c)
    # --strict refuses it: exit 1, the same line, nothing written.
    strict_out = tmp_path / "strict.urdf"
    r = _cli("build", str(path), "-o", str(strict_out), "--strict")
    assert r.returncode == 1 and f"inc.xacro:{line}:" in r.stderr and not strict_out.exists()
    assert r.stderr.count("\n") == 1


def test_what_crashes_pybullet_is_refused_at_the_line_it_was_written(tmp_path: Path) -> None:
    path = _files(tmp_path, f'  <link name="base">{INERTIAL}</link>\n'
                            '  <xacro:crasher name="ant"/>\n'
                            '  <joint name="j" type="fixed"><parent link="base"/>'
                            '<child link="ant%x"/></joint>\n')
    line = next(i for i, t in enumerate(INCLUDE.splitlines(), 1) if "%x" in t)
    out = tmp_path / "out.urdf"
    r = _cli("build", str(path), "-o", str(out))
    assert r.returncode == 2 and not out.exists()
    assert f"inc.xacro:{line}:" in r.stderr and "crashes PyBullet" in r.stderr
    assert r.stderr.count("\n") == 1


def test_a_urdf_holding_xacro_is_said_to_be_one_and_build_expands_it(tmp_path: Path) -> None:
    path = tmp_path / "robot.urdf"  # as ROS 2 packages ship them
    path.write_text('<?xml version="1.0"?>\n<robot name="r" '
                    'xmlns:xacro="http://www.ros.org/wiki/xacro">\n'
                    '  <xacro:arg name="prefix" default="left_"/>\n'
                    '  <xacro:property name="prefix" value="$(arg prefix)"/>\n'
                    f'  <link name="${{prefix}}base">{INERTIAL}</link>\n'
                    f'  <link name="${{prefix}}arm">{INERTIAL}</link>\n'
                    '  <joint name="${prefix}j" type="revolute"><parent link="${prefix}base"/>'
                    '<child link="${prefix}arm"/><axis xyz="0 0 1"/><limit lower="-1" '
                    'upper="1" effort="1" velocity="1"/></joint>\n</robot>\n')
    joints = _cli("joints", str(path), "--json")
    assert joints.returncode == 0, joints.stderr
    # Read literally, as PyBullet reads it, and said so.
    assert json.loads(joints.stdout)["joints"][0]["jointName"] == "${prefix}j"
    assert f"{path}:3: holds xacro (<xacro:)" in joints.stderr and "(U009)" in joints.stderr
    check = json.loads(_cli("check", str(path), "--json").stdout)
    assert [(f["code"], f["level"]) for f in check["findings"] if f["code"] == "U009"] == [
        ("U009", "warning")]
    # build expands it, as xacro does, to a name of its own (never the input's).
    r = _cli("build", str(path), cwd=tmp_path)
    assert r.returncode == 0, r.stderr
    out = tmp_path / "robot.expanded.urdf"
    reference = tmp_path / "reference.urdf"
    reference.write_text(_xacro_expand(path))
    import pybullet as p

    with quiet_stdout():
        c = p.connect(p.DIRECT)
    try:
        names = []
        for f in (out, reference):
            with quiet_stdout():
                body = p.loadURDF(str(f), physicsClientId=c)
            names.append([p.getJointInfo(body, j, physicsClientId=c)[1].decode()
                          for j in range(p.getNumJoints(body, physicsClientId=c))])
    finally:
        p.disconnect(physicsClientId=c)
    assert names[0] == names[1] == ["left_j"]


def test_a_plain_urdf_is_still_already_urdf(tmp_path: Path) -> None:
    path = tmp_path / "plain.urdf"
    path.write_text(f'<robot name="p"><link name="a">{INERTIAL}</link></robot>')
    r = _cli("build", str(path))
    assert r.returncode == 2 and "already URDF (it holds no xacro)" in r.stderr


@pytest.mark.parametrize("text", ['<link name="${x}"/>', "$(arg y)", "<xacro:if value='1'>"])
def test_the_marks_of_xacro_are_found(text: str) -> None:
    from urdfkit.model.xmlio import xacro_marker

    assert xacro_marker(f"<robot>\n\n{text}\n</robot>".encode()) is not None
    assert xacro_marker(b'<robot name="r"><link name="a$b{c}"/></robot>') is None
    # xacro's own output keeps the namespace declaration: that alone is no xacro.
    assert xacro_marker(b'<robot name="r" xmlns:xacro="http://www.ros.org/wiki/xacro">'
                        b'<link name="a"/></robot>') is None
    # Commented out, it is not there (a real file kept its old <xacro:include> so).
    assert xacro_marker(f"<robot>\n<!-- {text} -->\n</robot>".encode()) is None
    after = xacro_marker(f"<robot><!-- c -->\n{text}</robot>".encode())
    assert after is not None and after[0] == 2  # after a comment: found, on its line
