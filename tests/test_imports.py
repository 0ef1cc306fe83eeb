"""Heavy modules stay unimported where they are not needed (typer's test_rich_import idea).

yourdfpy costs ~0.9 s through trimesh, matplotlib more; `urdfkit --help` must not even pay for
PyBullet and numpy. Each case runs the CLI in a fresh interpreter and lists sys.modules.
"""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

import pytest

HEAVY = ("yourdfpy", "trimesh", "matplotlib", "pydantic", "PIL")

PROBE = """
import json, sys
from urdfkit.cli import main
sys.argv = ["urdfkit", *sys.argv[1:]]
try:
    main()  # the console script's entry point, as users run it
except SystemExit as e:
    sys.stderr.write(f"\\nEXIT:{e.code}")
sys.stderr.write("\\nMODULES:" + json.dumps(sorted(sys.modules)))
"""


def loaded_modules(*args: str, top_level: bool = True,
                   ) -> tuple[subprocess.CompletedProcess[str], set[str]]:
    """Run the CLI with ``args``; return the process and the modules it imported (top-level
    package names unless ``top_level`` is false)."""
    proc = subprocess.run([sys.executable, "-c", PROBE, *args], capture_output=True, text=True,
                          timeout=60)
    marker = proc.stderr.rindex("MODULES:")
    names = json.loads(proc.stderr[marker + len("MODULES:"):])
    return proc, {n.split(".")[0] for n in names} if top_level else set(names)


def test_help_imports_nothing_heavy() -> None:
    proc, modules = loaded_modules("--help")
    assert "joints" in proc.stdout
    assert modules.isdisjoint({*HEAVY, "pybullet", "numpy", "lxml"}), modules & {
        *HEAVY, "pybullet", "numpy", "lxml"}


def test_joints_json_imports_only_pybullet(simplecar_urdf: Path) -> None:
    proc, modules = loaded_modules("joints", str(simplecar_urdf), "--json")
    assert len(json.loads(proc.stdout)["joints"]) == 6
    assert "pybullet" in modules
    assert modules.isdisjoint(HEAVY), modules & set(HEAVY)


def test_piped_joints_table_needs_no_rich(simplecar_urdf: Path) -> None:
    # Off a terminal the table is plain text, so rich (~25 ms to import) stays out; nor does
    # the joints path load the link/summary and tree modules.
    proc, modules = loaded_modules("joints", str(simplecar_urdf), top_level=False)
    assert "base_to_right_back_wheel" in proc.stdout and "│" not in proc.stdout
    assert "rich" not in modules
    imported = {"urdfkit.engine.body", "urdfkit.draw.tree", "urdfkit.builder",
                "urdfkit.model.robot"}
    assert modules.isdisjoint(imported), modules


@pytest.mark.parametrize("command", ["links", "info", "tree"])
def test_other_inspect_commands_import_nothing_heavy(command: str, simplecar_urdf: Path) -> None:
    proc, modules = loaded_modules(command, str(simplecar_urdf), "--json")
    assert json.loads(proc.stdout)["robot"] == "simplecar"
    assert modules.isdisjoint(HEAVY), modules & set(HEAVY)
    if command == "tree":
        assert "pybullet" not in modules


def test_installed_console_script_help() -> None:
    script = Path(sys.executable).parent / "urdfkit"
    proc = subprocess.run([str(script), "--help"], capture_output=True, text=True, timeout=60)
    assert proc.returncode == 0
    for command in ("joints", "links", "tree", "info"):
        assert command in proc.stdout


COMPOUND_DAMPED = """<robot name="compound">
  <link name="base">
    <inertial><mass value="3"/>
      <inertia ixx="0.001" ixy="0" ixz="0" iyy="0.006" iyz="0" izz="0.007"/></inertial>
    <collision><origin xyz="-0.4 0 0"/><geometry><box size="0.8 0.5 0.2"/></geometry></collision>
    <collision><origin xyz="0.4 0 0" rpy="0 0 0.3"/><geometry><box size="0.8 0.5 0.2"/></geometry>
    </collision>
  </link>
  <link name="finger">
    <inertial><mass value="0.01"/>
      <inertia ixx="1e-6" ixy="0" ixz="0" iyy="1e-6" iyz="0" izz="1e-6"/></inertial>
    <collision><geometry><box size="0.02 0.02 0.02"/></geometry></collision>
  </link>
  <joint name="hinge" type="revolute">
    <parent link="base"/><child link="finger"/><origin xyz="0.8 0 0.1" rpy="0.2 0 0"/>
    <axis xyz="0 1 0"/><limit lower="-1" upper="1" effort="1" velocity="1"/>
    <dynamics damping="0.1"/>
  </joint>
</robot>
"""


def test_check_of_damped_joints_and_compound_links_imports_no_numpy(tmp_path: Path) -> None:
    """U311 places links with urdfkit.formats.fk and check joins a link's collision solids with
    urdfkit.model.massprops, both plain Python: numpy (~65 ms to import) stays out of check
    unless a mesh is read or U311's Gershgorin bound passes 2."""
    path = tmp_path / "compound.urdf"
    path.write_text(COMPOUND_DAMPED)
    proc, modules = loaded_modules("check", str(path), "--json", "--no-cache")
    codes = {f["code"] for f in json.loads(proc.stdout)["findings"]}
    assert {"U311", "U605"} <= codes, codes  # the damping judged; base against its two boxes
    assert "numpy" not in modules
