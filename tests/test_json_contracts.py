"""docs/json.md is a contract: every key it lists is what the command prints, no more, no less."""

from __future__ import annotations

import json
import re
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
    for line in DOC.read_text().splitlines():
        heading = re.match(r"## `urdfkit (\w+)", line)
        if heading:
            command = heading.group(1)
            out[command] = {}
            continue
        item = re.match(r"- `(\.[^`]*)`(?: \([^)]*\))?: (.*)", line)
        if item and command:
            out[command][item.group(1)] = set(re.findall(r"`(\w+)`", item.group(2)))
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
    out = {}
    for name, args in runs.items():
        result = CliRunner().invoke(app, args)
        assert result.exit_code in (0, 1), (name, result.stderr)
        out[name] = json.loads(result.stdout)
    return out


def test_every_json_command_is_documented() -> None:
    assert set(contracts()) == {"joints", "links", "info", "tree", "templates", "check",
                                "drive", "render", "sim"}


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
