"""Fragments: a file another checked file includes, and that is no robot alone, gets a note.

The fixture package splits a cart as Clearpath and Rethink packages do: a gazebo fragment and a
gripper fragment with joints to the includer's base_link (U202/U205 alone), and an include-only
placeholder reached through ``$(optenv VAR empty.urdf)`` (U002/U003 alone).
"""

from __future__ import annotations

import json
from pathlib import Path

from typer.testing import CliRunner

from urdfkit.cli import app

PACKAGE = Path(__file__).parent / "fixtures" / "packages" / "fragments" / "cart_description"
URDF = PACKAGE / "urdf"
FRAGMENTS = ("cart.gazebo.xacro", "gripper.urdf.xacro", "empty.urdf")


def _check(*paths: Path) -> dict[str, list[dict[str, object]]]:
    r = CliRunner().invoke(app, ["check", *map(str, paths), "--json", "--no-cache"])
    data = json.loads(r.stdout)
    out: dict[str, list[dict[str, object]]] = {Path(f).name: [] for f in data["files"]}
    for f in data["findings"]:
        out[Path(str(f["file"])).name].append(f)
    return out


def test_alone_each_fragment_is_judged_a_robot() -> None:
    """The premise: checked alone, each is no robot (the errors a folder check used to show)."""
    for name, codes in (("cart.gazebo.xacro", {"U002", "U202"}),
                        ("gripper.urdf.xacro", {"U002", "U202"}),
                        ("empty.urdf", {"U002", "U003"})):
        found = {str(f["code"]) for f in _check(URDF / name)[name]}
        assert codes <= found, (name, found)


def test_folder_check_notes_fragments() -> None:
    found = _check(PACKAGE)
    for name in FRAGMENTS:
        assert [f["code"] for f in found[name]] == ["U010"], found[name]
        assert found[name][0]["level"] == "info"
        assert "cart.urdf.xacro" in str(found[name][0]["message"])
    # The includer is checked as the robot, the fragments' content in it.
    assert not [f for f in found["cart.urdf.xacro"] if f["level"] == "error"]
    # A file nobody includes is still judged as a robot.
    assert "U002" in {f["code"] for f in found["lonely.urdf"]}


def test_fragment_with_its_includer_named_on_the_command_line() -> None:
    found = _check(URDF / "cart.urdf.xacro", URDF / "gripper.urdf.xacro")
    assert [f["code"] for f in found["gripper.urdf.xacro"]] == ["U010"]
