"""A real editor against `urdfkit lsp`: Neovim (Debian's package), headless.

Neovim opens a xacro with a misspelt tag and a bad inertia and receives both diagnostics at
their lines, then applies the nearest-tag action; it opens a URDF, applies `urdfkit fix`'s code
action and saves, and the file is byte for byte what `urdfkit fix` writes. The Lua that drives
it is tests/editor/nvim_lsp.lua. CI installs Neovim (.ci/run), so this runs there, never skips.
"""

from __future__ import annotations

import os
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

BAD = """<?xml version="1.0"?>
<robot name="bad">
  <link name="base">
    <inertial>
      <mass value="2"/>
      <inertia ixx="1" ixy="0" ixz="0" iyy="0.1" iyz="0" izz="0.1"/>
    </inertial>
    <collision>
      <geometry><box size="0.2 0.2 0.2"/></geometry>
    </collision>
  </link>
</robot>
"""

LUA = Path(__file__).parent / "editor" / "nvim_lsp.lua"
XACRO = """<?xml version="1.0"?>
<robot name="x" xmlns:xacro="http://www.ros.org/wiki/xacro">
  <xacro:property name="m" value="2"/>
  <link name="base">
    <inertial>
      <mass value="${m}"/>
      <inertia ixx="1" ixy="0" ixz="0" iyy="0.1" iyz="0" izz="0.1"/>
    </inertial>
    <visul><geometry><box size="0.2 0.2 0.2"/></geometry></visul>
    <collision><geometry><box size="0.2 0.2 0.2"/></geometry></collision>
  </link>
</robot>
"""


def _nvim(file: Path, out: Path, action: str, want: int) -> list[str]:
    nvim = shutil.which("nvim")
    if nvim is None:
        pytest.skip("Neovim is not installed (CI installs Debian's neovim)")
    env = {**os.environ, "URDFKIT_PYTHON": sys.executable, "URDFKIT_FILE": str(file),
           "URDFKIT_OUT": str(out), "URDFKIT_ACTION": action, "URDFKIT_WANT": str(want)}
    subprocess.run([nvim, "--headless", "--clean", "-u", "NONE", "-c", f"luafile {LUA}"],
                   env=env, capture_output=True, timeout=180, check=False,
                   stdin=subprocess.DEVNULL)
    return out.read_text().splitlines()


def _line(text: str, needle: str) -> int:
    return next(i for i, line in enumerate(text.splitlines()) if needle in line)


def _built(path: Path, out: Path) -> bytes:
    subprocess.run([sys.executable, "-m", "urdfkit", "build", str(path), "-o", str(out),
                    "--force"], capture_output=True, check=False)
    return out.read_bytes()


def test_neovim_gets_a_xacros_diagnostics_and_applies_fix_in_the_xacro(tmp_path: Path) -> None:
    """Both diagnostics at their xacro lines; fix's action written into the xacro itself.

    fix edits URDF: the xacro fixed in Neovim must expand to exactly what `urdfkit fix`
    writes for the xacro's expansion.
    """
    robot = tmp_path / "robot.urdf.xacro"
    robot.write_text(XACRO)
    expanded = _built(robot, tmp_path / "expanded.urdf")
    subprocess.run([sys.executable, "-m", "urdfkit", "fix", str(tmp_path / "expanded.urdf"),
                    "-o", str(tmp_path / "fixed.urdf")], capture_output=True, check=False)
    said = _nvim(robot, tmp_path / "out.txt", "urdfkit fix", 3)
    found = {tuple(line.split()) for line in said if not line.startswith("applied")}
    assert ("U801", str(_line(XACRO, "<visul>"))) in found
    assert ("U604", str(_line(XACRO, 'ixx="1"'))) in found
    assert said[-1].startswith("applied urdfkit fix")
    assert robot.read_text() != XACRO and "${m}" in robot.read_text()
    assert _built(robot, tmp_path / "after.urdf") == (tmp_path / "fixed.urdf").read_bytes() \
        != expanded


def test_neovim_applies_fix_and_the_file_is_fixs_output(tmp_path: Path) -> None:
    robot = tmp_path / "robot.urdf"
    robot.write_text(BAD)
    expected = tmp_path / "expected.urdf"
    subprocess.run([sys.executable, "-m", "urdfkit", "fix", str(robot), "-o", str(expected)],
                   capture_output=True, check=False)
    said = _nvim(robot, tmp_path / "out.txt", "urdfkit fix", 2)
    assert ("U604", str(_line(BAD, 'ixx="1"'))) in {tuple(s.split()) for s in said[:-1]}
    assert said[-1].startswith("applied urdfkit fix")
    assert robot.read_bytes() == expected.read_bytes() != BAD.encode()
