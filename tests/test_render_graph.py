"""urdfkit tree --dot: the kinematic graph as DOT text, and drawn by Graphviz when installed."""

from __future__ import annotations

import re
import shutil
import subprocess
from pathlib import Path

import pytest
from lxml import etree
from typer.testing import CliRunner

from urdfkit.cli import app
from urdfkit.core.errors import MissingDependencyError, OutputError
from urdfkit.draw.graph import dot_graph, quote, write_graph
from urdfkit.sources.resolve import open_input

runner = CliRunner()
needs_dot = pytest.mark.skipif(shutil.which("dot") is None,
                               reason="Graphviz `dot` is not installed")

# A DOT string: quotes, with backslash escapes inside.
_STRING = r'"(?:[^"\\]|\\.)*"'
_ATTRS = rf'\[(?:\s*\w+=(?:{_STRING}|[\w.#-]+),?)*\s*\]'
_NODE = re.compile(rf"^  ({_STRING}) {_ATTRS};$")
_EDGE = re.compile(rf"^  ({_STRING}) -> ({_STRING}) ({_ATTRS});$")


def _unquote(s: str) -> str:
    return re.sub(r"\\(.)", lambda m: "\n" if m.group(1) == "n" else m.group(1), s[1:-1])


def _parse(dot: str) -> tuple[list[str], list[tuple[str, str, str]]]:
    """Check the DOT text line by line; return node names and (parent, child, label) edges."""
    lines = dot.splitlines()
    assert re.match(rf"^digraph {_STRING} \{{$", lines[0]), lines[0]
    assert lines[-1] == "}"
    nodes, edges = [], []
    for line in lines[1:-1]:
        if line.startswith(("  rankdir=", "  graph [", "  node [", "  edge [")):
            continue
        if m := _EDGE.match(line):
            label = re.search(rf"label=({_STRING})", m.group(3))
            assert label is not None, line
            edges.append((_unquote(m.group(1)), _unquote(m.group(2)), _unquote(label.group(1))))
        elif m := _NODE.match(line):
            nodes.append(_unquote(m.group(1)))
        else:
            raise AssertionError(f"not a DOT statement: {line!r}")
    return nodes, edges


def _dot_of(path: str | Path) -> tuple[str, etree._Element]:
    with open_input(path) as r:
        return dot_graph(r.root), r.root


@pytest.mark.parametrize("robot", ["simplecar", "r2d2.urdf"])
def test_dot_names_every_link_and_joint(robot: str, simplecar_urdf: Path) -> None:
    dot, root = _dot_of(simplecar_urdf if robot == "simplecar" else robot)
    nodes, edges = _parse(dot)
    links = [el.get("name") for el in root.iter("link")]
    joints = {el.get("name"): el for el in root.iter("joint")}
    assert sorted(nodes) == sorted(links)
    assert len(edges) == len(joints)
    for parent, child, label in edges:
        name = label.splitlines()[0].split("] ", 1)[1]
        j = joints[name]
        assert j.find("parent").get("link") == parent
        assert j.find("child").get("link") == child
        assert label.splitlines()[1] == j.get("type")
    # Edges come in PyBullet's joint-index order.
    indices = [int(label.split("]")[0][1:]) for _, _, label in edges]
    assert indices == list(range(len(joints)))


def test_dot_labels_axis_and_limits(simplecar_urdf: Path) -> None:
    _, edges = _parse(_dot_of(simplecar_urdf)[0])
    labels = {lab.splitlines()[0].split("] ")[1]: lab.splitlines() for _, _, lab in edges}
    assert labels["base_to_left_hinge"] == ["[0] base_to_left_hinge", "revolute", "axis 0 0 1",
                                            "[-0.5, 0.5] rad"]
    assert labels["base_to_left_back_wheel"] == ["[4] base_to_left_back_wheel", "continuous",
                                                 "axis 0 1 0"]
    _, r2d2 = _parse(_dot_of("r2d2.urdf")[0])
    pole = next(lab for _, _, lab in r2d2 if "gripper_extension" in lab).splitlines()
    assert pole[1:] == ["prismatic", "axis 1 0 0", "[-0.38, 0] m"]
    fixed = next(lab for _, _, lab in r2d2 if "base_to_right_leg" in lab).splitlines()
    assert fixed[1:] == ["fixed"]  # no axis for a fixed joint


def test_quote_escapes_for_dot() -> None:
    assert quote('a"b') == r'"a\"b"'
    assert quote("a\\N") == r'"a\\N"'
    assert quote("two\nlines") == r'"two\nlines"'


HOSTILE = """<robot name='q"uote'>
  <link name='base "quoted"'/>
  <link name='back\\N slash'/>
  <link name='{brace} -> arrow; [x]'/>
  <joint name='j "1"' type='revolute'>
    <parent link='base "quoted"'/><child link='back\\N slash'/>
    <axis xyz='0 0 1'/><limit lower='-1' upper='1' effort='1' velocity='1'/>
  </joint>
  <joint name='j;2' type='fixed'>
    <parent link='base "quoted"'/><child link='{brace} -> arrow; [x]'/>
  </joint>
</robot>
"""


def test_awkward_names_survive(tmp_path: Path) -> None:
    path = tmp_path / "odd.urdf"
    path.write_text(HOSTILE)
    dot, _ = _dot_of(path)
    nodes, edges = _parse(dot)
    assert sorted(nodes) == sorted(['base "quoted"', "back\\N slash", "{brace} -> arrow; [x]"])
    assert {(p, c) for p, c, _ in edges} == {('base "quoted"', "back\\N slash"),
                                             ('base "quoted"', "{brace} -> arrow; [x]")}
    if shutil.which("dot"):
        # Graphviz itself reads it, and draws every label as the exact name (an ID keeps its
        # backslashes doubled: DOT has no other way to end a quoted ID with one).
        svg = subprocess.run(["dot", "-Tsvg"], input=dot.encode(), capture_output=True,
                             check=True).stdout
        texts = set(etree.fromstring(svg).itertext())
        for name in nodes + ['[0] j "1"', "[1] j;2"]:
            assert name in texts, name


@needs_dot
def test_tree_svg_with_graphviz(simplecar_urdf: Path, tmp_path: Path) -> None:
    out = tmp_path / "graph.svg"
    res = runner.invoke(app, ["tree", str(simplecar_urdf), "-o", str(out)])
    assert res.exit_code == 0, res.output
    svg = etree.parse(str(out)).getroot()
    assert svg.tag.endswith("svg")
    text = " ".join(t for t in svg.itertext())
    for name in ("base_link", "left_front_wheel", "base_to_left_hinge", "revolute"):
        assert name in text
    res = runner.invoke(app, ["tree", str(simplecar_urdf), "-o", str(out)])
    assert res.exit_code == 2 and "--force" in res.output


def test_svg_without_graphviz_says_how_to_install(simplecar_urdf: Path, tmp_path: Path,
                                                  monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setattr(shutil, "which", lambda name: None)
    with pytest.raises(MissingDependencyError, match="apt-get install graphviz"):
        write_graph(_dot_of(simplecar_urdf)[0], tmp_path / "g.svg")
    res = runner.invoke(app, ["tree", str(simplecar_urdf), "-o", str(tmp_path / "g.svg")])
    assert res.exit_code != 0
    assert "graphviz" in res.output.lower() and "-o graph.dot" in res.output
    assert not (tmp_path / "g.svg").exists()


def test_cli_tree_dot_stdout_and_file(simplecar_urdf: Path, tmp_path: Path) -> None:
    res = runner.invoke(app, ["tree", str(simplecar_urdf), "--dot"])
    assert res.exit_code == 0, res.output
    nodes, _ = _parse(res.stdout)
    assert "base_link" in nodes
    out = tmp_path / "g.dot"
    res = runner.invoke(app, ["tree", str(simplecar_urdf), "-o", str(out)])
    assert res.exit_code == 0
    assert out.read_text() == _dot_of(simplecar_urdf)[0]
    res = runner.invoke(app, ["tree", str(simplecar_urdf), "-o", str(out)])
    assert res.exit_code == 2 and "exists; pass --force" in res.output
    res = runner.invoke(app, ["tree", str(simplecar_urdf), "-o", str(out), "--force"])
    assert res.exit_code == 0


def test_cli_tree_dot_errors(simplecar_urdf: Path, tmp_path: Path) -> None:
    res = runner.invoke(app, ["tree", str(simplecar_urdf), "-o", str(tmp_path / "g.txt")])
    assert res.exit_code == 2 and "the graph must end in .dot or .gv" in res.output
    res = runner.invoke(app, ["tree", str(simplecar_urdf), "--dot", "--json"])
    assert res.exit_code == 2 and "choose one" in res.output
    bad = tmp_path / "bad.urdf"
    bad.write_text("<robot name='x'><link name='a'/><link name='b'/></robot>")
    res = runner.invoke(app, ["tree", str(bad), "--dot"])
    assert res.exit_code == 2 and "bad.urdf" in res.output and "root links" in res.output
    with pytest.raises(OutputError, match="the graph must end in"):
        write_graph("digraph {}", tmp_path / "g")
