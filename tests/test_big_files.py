"""Files past line 65,535, where lxml's ``sourceline`` stops counting.

The expected lines come from the text itself (where each ``<link name=...`` is written), not
from urdfkit: a finding must name the line a user's editor shows.
"""

from __future__ import annotations

import json
from pathlib import Path

import pytest
from typer.testing import CliRunner

from urdfkit.cli import app
from urdfkit.model.xmlio import line_of, parse_xml, start_tags

BAD = ('<link name="late{k}"><inertial><mass value="-1"/><inertia ixx="1" iyy="1" izz="1" '
       'ixy="0" ixz="0" iyz="0"/></inertial><collision><geometry><box size="0.1 0.1 0.1"/>'
       '</geometry></collision></link>')


@pytest.fixture(scope="module")
def big(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """70,000 comment lines that quote a ``<link`` tag, then three links with a bad mass."""
    lines = ['<robot name="r">', '<link name="base"><inertial><mass value="1"/><inertia '
             'ixx="1" iyy="1" izz="1" ixy="0" ixz="0" iyz="0"/></inertial></link>']
    lines += ['<!-- <link name="quoted"> -->'] * 70_000
    for k in range(3):
        lines.append(BAD.format(k=k))
        lines.append(f'<joint name="j{k}" type="fixed"><parent link="base"/>'
                     f'<child link="late{k}"/></joint>')
    lines.append("</robot>")
    path = tmp_path_factory.mktemp("big") / "big.urdf"
    path.write_text("\n".join(lines) + "\n")
    return path


def _written_lines(path: Path, needle: str) -> list[int]:
    return [n for n, line in enumerate(path.read_text().splitlines(), 1) if needle in line]


def test_every_element_keeps_its_true_line(big: Path) -> None:
    data = big.read_bytes()
    root = parse_xml(data, big).getroot()
    links = [el for el in root.iter("link")]
    want = [2] + _written_lines(big, '<link name="late')
    assert [line_of(el) for el in links] == want
    assert want[-1] > 70_000
    assert max(el.sourceline or 0 for el in links) <= 65_535  # lxml alone cannot say it
    # start_tags skips the tags quoted in comments: one offset per element.
    assert len(start_tags(data)) == sum(1 for el in root.iter() if isinstance(el.tag, str))


@pytest.mark.parametrize("fmt", ["text", "json", "sarif", "github"])
def test_check_names_lines_past_the_cap(big: Path, fmt: str) -> None:
    result = CliRunner().invoke(app, ["check", str(big), "--format", fmt, "--select", "U601"])
    assert result.exit_code == 1, result.stderr
    want = _written_lines(big, '<link name="late')
    out = result.stdout
    if fmt == "json":
        lines = [f["line"] for f in json.loads(out)["findings"]]
    elif fmt == "sarif":
        lines = [r["locations"][0]["physicalLocation"]["region"]["startLine"]
                 for r in json.loads(out)["runs"][0]["results"]]
    elif fmt == "github":
        lines = [int(x.split("line=")[1].split(",")[0]) for x in out.splitlines() if "U601" in x]
    else:
        lines = [int(x.split()[0]) for x in out.splitlines() if "U601" in x]
    assert sorted(lines) == want


def test_fix_splices_at_the_right_place_past_the_cap(big: Path, tmp_path: Path) -> None:
    out = tmp_path / "fixed.urdf"
    result = CliRunner().invoke(app, ["fix", str(big), "-o", str(out), "--select", "U601",
                                       "--density", "1000", "--allow-mass-change"])
    assert result.exit_code == 0, result.stderr
    before, after = big.read_text().splitlines(), out.read_text().splitlines()
    assert len(before) == len(after)
    changed = [n for n, (a, b) in enumerate(zip(before, after, strict=True), 1) if a != b]
    assert changed == _written_lines(big, '<link name="late')  # the three links, nothing else
    assert all('mass value="-1"' not in after[n - 1] for n in changed)
    check = CliRunner().invoke(app, ["check", str(out), "--select", "U601", "--format", "json"])
    assert check.exit_code == 0 and json.loads(check.stdout)["findings"] == []
