"""tree reads the file only (issue 24.16): a mesh whose package cannot be found is a note, not
a refusal; the commands that load the robot in PyBullet still need it."""

from __future__ import annotations

import json
from pathlib import Path

from typer.testing import CliRunner

from urdfkit.cli import app

ROBOT = """<robot name="r">
<link name="a"><visual><geometry><mesh filename="package://nopkg/meshes/a.stl"/></geometry>
</visual></link>
<link name="b"/>
<joint name="j" type="fixed"><parent link="a"/><child link="b"/></joint>
</robot>
"""


def test_tree_draws_a_robot_whose_mesh_package_is_missing(tmp_path: Path) -> None:
    path = tmp_path / "r.urdf"
    path.write_text(ROBOT)
    result = CliRunner().invoke(app, ["tree", str(path)])
    assert result.exit_code == 0, result.stderr
    assert "[0] j (fixed) -> b" in result.stdout
    [note] = [ln for ln in result.stderr.splitlines() if ln.strip()]
    assert note.startswith("urdfkit: warning:") and "nopkg" in note and "--package" in note
    as_json = CliRunner().invoke(app, ["tree", str(path), "--json"])
    assert as_json.exit_code == 0
    data = json.loads(as_json.stdout)
    assert [j["name"] for j in data["joints"]] == ["j"]
    # joints loads the robot in PyBullet: there the missing package is still an error
    loaded = CliRunner().invoke(app, ["joints", str(path)])
    assert loaded.exit_code == 2 and "nopkg" in loaded.stderr
