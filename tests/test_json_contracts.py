"""docs/json.md is a contract: every key it lists is what the command prints, no more, no less."""

from __future__ import annotations

import json
import re
import shutil
from pathlib import Path
from typing import Any

import pytest
from typer.testing import CliRunner

from urdfkit.cli import app

ROOT = Path(__file__).parent.parent
DOC = ROOT / "docs" / "json.md"
EXAMPLES = ROOT / "examples"


def contracts() -> dict[str, dict[str, set[str]]]:
    """{command: {path: keys}} from the lists under each ``## `urdfkit CMD ... --json` ``."""
    out: dict[str, dict[str, set[str]]] = {}
    command = ""
    paths: list[str] = []  # the places of the list item being read
    for line in DOC.read_text().splitlines():
        heading = re.match(r"## `urdfkit (\w+)", line)
        if heading:
            command, paths = heading.group(1), []
            out[command] = {}
            continue
        if paths and re.match(r"\s+\S", line):  # an item continued on an indented line
            for path in paths:
                out[command][path] |= set(re.findall(r"`(\w+)`", line))
            continue
        paths = []
        # `- `.a`, `.b` (a note): `key`, `key``: one or more places with the same keys.
        item = re.match(r"- ((?:`\.[^`]*`(?:, )?)+)(?: \([^)]*\))?: (.*)", line)
        if item and command:
            paths = re.findall(r"`(\.[^`]*)`", item.group(1))
            for path in paths:
                out[command][path] = set(re.findall(r"`(\w+)`", item.group(2)))
    return out


def at(doc: Any, path: str) -> Any:
    """The object at ``.a[].b`` (the first element of each list)."""
    node = doc
    for part in filter(None, path.split(".")):
        name = part.removesuffix("[]")
        node = node[name]
        if part.endswith("[]"):
            node = node[0]
    return node


def diff_pair(tmp: Path) -> tuple[Path, Path]:
    """Two versions of a robot with one of every kind of difference, so no list is empty.

    NEW drops ``old_link`` and adds ``new_link`` (a fixed joint each, at different origins),
    renames ``j2`` and its link, raises ``j1``'s effort and declares it first (its index
    shifts), and adds mass.
    """
    inertial = ('<inertial><mass value="1"/><inertia ixx="0.01" ixy="0" ixz="0" iyy="0.01" '
                'iyz="0" izz="0.01"/></inertial>')

    def robot(links: list[str], joints: list[tuple[str, str, str, str, str]]) -> str:
        body = "".join(f'<link name="{x}">{inertial}</link>' for x in ["base", *links])
        for name, kind, child, xyz, effort in joints:
            limit = f'<limit lower="-1" upper="1" effort="{effort}" velocity="1"/>' \
                if kind == "revolute" else ""
            body += (f'<joint name="{name}" type="{kind}"><parent link="base"/>'
                     f'<child link="{child}"/><origin xyz="{xyz}"/><axis xyz="0 0 1"/>'
                     f"{limit}</joint>")
        return f'<robot name="r">{body}</robot>'

    old = robot(["l1", "l2", "old_link"], [("j_old", "fixed", "old_link", "0 0 1", ""),
                                           ("j1", "revolute", "l1", "1 0 0", "1"),
                                           ("j2", "fixed", "l2", "0 1 0", "")])
    new = robot(["l1", "l2_renamed", "new_link", "extra"], [
        ("j1", "revolute", "l1", "1 0 0", "2"), ("j_new", "fixed", "new_link", "5 5 5", ""),
        ("j2_renamed", "fixed", "l2_renamed", "0 1 0", ""),
        ("j_extra", "fixed", "extra", "0 0 3", "")])
    (tmp / "old.urdf").write_text(old)
    (tmp / "new.urdf").write_text(new)
    return tmp / "old.urdf", tmp / "new.urdf"


@pytest.fixture(scope="module")
def outputs(tmp_path_factory: pytest.TempPathFactory) -> dict[str, Any]:
    tmp = tmp_path_factory.mktemp("json")
    r2d2_args = ["r2d2.urdf", "--json"]
    runs = {
        "joints": ["joints", *r2d2_args],
        "links": ["links", *r2d2_args],
        "info": ["info", *r2d2_args],
        "tree": ["tree", *r2d2_args],
        "templates": ["templates", "--json"],
        "drive": ["drive", "--steps", "5", "--json"],
        "render": ["render", "r2d2.urdf", "--size", "64x48", "-o", str(tmp / "r.png"), "--json"],
        "sim": ["sim", str(EXAMPLES / "two_cars.json"), "--json"],
    }
    import pybullet_data

    r2d2 = Path(pybullet_data.getDataPath()) / "r2d2.urdf"
    runs["check"] = ["check", str(r2d2), "--json"]
    old, new = diff_pair(tmp)
    runs["diff"] = ["diff", str(old), str(new), "--json"]
    # The Franka's links touch at the zero pose, so `pairs` has entries to check.
    runs["collisions"] = ["collisions", "franka_panda/panda.urdf", "--json"]
    # The broken arm, with a capsule (no solid to derive inertia from: a finding left) and a
    # zero joint axis (an error fix does not repair), so no list is empty.
    broken = (ROOT / "tests" / "fixtures" / "robots" / "broken_arm.urdf").read_text()
    broken = broken.replace("<cylinder ", "<capsule ").replace(
        '<origin xyz="0 0 0.5"/><axis xyz="0 0 1"/>', '<origin xyz="0 0 0.5"/><axis xyz="0 0 0"/>')
    # Its visual mesh relative to it, written into another folder: a path moved for it.
    broken = broken.replace('<visual><geometry><mesh filename="package:///meshes/unit_cube.stl"',
                            '<visual><geometry><mesh filename="unit_cube.stl"')
    for folder in ("src", "out"):
        (tmp / folder).mkdir()
    (tmp / "src" / "broken.urdf").write_text(broken)
    shutil.copy(ROOT / "tests" / "fixtures" / "meshes" / "unit_cube.stl", tmp / "src")
    runs["fix"] = ["fix", str(tmp / "src" / "broken.urdf"), "-o", str(tmp / "out" / "fixed.urdf"),
                   "--json", "--allow-mass-change"]
    runs["sweep"] = ["sweep", "drive", "--steps", "5", "--vary", "steer=0.1,0.2", "--json"]
    # r2d2: fixed links (sites), meshes (paths), notes of every common kind
    runs["export"] = ["export", "mjcf", "r2d2.urdf", "-o", str(tmp / "r2d2.xml"), "--json"]
    runs["agree"] = ["agree", "r2d2.urdf", str(tmp / "r2d2.xml"), "--json", "--poses", "5"]
    out = {}
    for name, args in runs.items():
        result = CliRunner().invoke(app, args)
        assert result.exit_code in (0, 1), (name, result.stderr)
        out[name] = json.loads(result.stdout)
    return out


def test_every_json_command_is_documented() -> None:
    assert set(contracts()) == {"joints", "links", "info", "tree", "templates", "check",
                                "drive", "render", "sim", "diff", "collisions", "fix", "sweep",
                                "export", "agree"}


@pytest.mark.parametrize("command", sorted(contracts()))
def test_documented_keys_are_the_printed_keys(command: str, outputs: dict[str, Any]) -> None:
    doc = outputs[command]
    for path, keys in contracts()[command].items():
        node = at(doc, path)
        assert isinstance(node, dict), (command, path)
        assert set(node) == keys, (command, path, set(node) ^ keys)


def test_pybullet_fields_keep_pybullet_names(outputs: dict[str, Any]) -> None:
    # The naming rule: PyBullet's names for PyBullet's fields, snake_case for ours.
    joint = outputs["joints"]["joints"][0]
    assert {"jointIndex", "jointLowerLimit", "parentFramePos"} <= set(joint)
    ours = [k for k in outputs["info"] if not k.islower()]
    assert ours == []
