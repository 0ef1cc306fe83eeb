"""The crash classes the guard stands between a file and PyBullet, with PyBullet's raw outcome.

Each row is measured against raw PyBullet (``loadURDF`` in a subprocess): a new PyBullet
release that moves a limit fails ``test_raw_pybullet_still_behaves_as_recorded``. The guard
must refuse every row whose raw outcome is a crash or a hang, with and without ``--no-guard``,
and may refuse a row PyBullet loads only with a refusal that says so and that ``--no-guard``
lifts.
"""

from __future__ import annotations

import json
import os
import subprocess
import sys
import textwrap
from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass
from pathlib import Path

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from typer.testing import CliRunner

from urdfkit.cli import app
from urdfkit.model.spec import CRASH_NAME_BYTES, MAX_NAME_BYTES


def robot(link: str = "b", joint: str = "j", name: str = "r", jtype: str = "fixed",
          mesh: str | None = None, child_inertial: bool = True) -> str:
    visual = (f'<visual><geometry><mesh filename="{mesh}"/></geometry></visual>'
              if mesh else "")
    inertial = '<inertial><mass value="1"/><inertia ixx="1" ixy="0" ixz="0" iyy="1" iyz="0" ' \
               'izz="1"/></inertial>'
    return (f'<robot name="{name}"><link name="a">{inertial}{visual}</link>'
            f'<link name="{link}">{inertial if child_inertial else ""}</link>'
            f'<joint name="{joint}" type="{jtype}">'
            f'<parent link="a"/><child link="{link}"/></joint></robot>')


TWO_LINKS = '<link name="a"/><link name="b"/>'


@dataclass(frozen=True)
class Case:
    """One crash class: its fixture, PyBullet 3.2.7's raw outcome, what the guard says."""

    name: str
    urdf: str
    raw: str  # "crash" (a signal), "hang" (still running after the timeout), "loads", "error"
    refusal: str  # a fragment of the guard's one-line refusal
    liftable: bool = False  # --no-guard lets it through (the guard is stricter than PyBullet)
    query: str = ""  # a call after loading: some names load, then crash a query


CASES = [
    Case("two roots", f'<robot name="r">{TWO_LINKS}</robot>', "crash", "root"),
    Case("child with two parents",
         '<robot name="r"><link name="a"/><link name="b"/><link name="c"/>'
         '<joint name="j1" type="fixed"><parent link="a"/><child link="c"/></joint>'
         '<joint name="j2" type="fixed"><parent link="b"/><child link="c"/></joint>'
         '<joint name="j3" type="fixed"><parent link="a"/><child link="b"/></joint></robot>',
         "crash", "parent"),
    Case("cycle below the root",
         '<robot name="r"><link name="a"/><link name="b"/><link name="c"/>'
         '<joint name="j1" type="fixed"><parent link="a"/><child link="b"/></joint>'
         '<joint name="j2" type="fixed"><parent link="b"/><child link="c"/></joint>'
         '<joint name="j3" type="fixed"><parent link="c"/><child link="b"/></joint></robot>',
         "crash", "parent"),
    Case("duplicate joint names",
         '<robot name="r"><link name="a"/><link name="b"/><link name="c"/>'
         '<joint name="j" type="fixed"><parent link="a"/><child link="b"/></joint>'
         '<joint name="j" type="fixed"><parent link="b"/><child link="c"/></joint></robot>',
         "crash", "duplicate joint name"),
    # PyBullet quotes a link's name in the warning for a link without <inertial>: as printf's
    # format string. (With an <inertial>, that warning and the crash do not happen.)
    Case("% in a link name (no <inertial>)", robot(link="b%s%n", child_inertial=False),
         "crash", "contains '%'"),
    Case("% in a joint type", robot(jtype="fi%sxed"), "crash", "has type 'fi%sxed'"),
    Case("% in a joint name", robot(joint="j%s%n"), "loads", "contains '%'", liftable=True),
    Case("% in the robot name", robot(name="r%s%n"), "loads", "contains '%'", liftable=True),
    # Names well past the crash lengths: right at a boundary the overflow does not crash
    # every time (a CI run once loaded a 1264-byte joint name), and the table must not flake.
    Case("joint name of 700 x 'é' (1400 bytes)", robot(joint="é" * 700), "crash",
         "1400 bytes long"),
    Case("ASCII joint name of 1500 bytes", robot(joint="j" * 1500), "crash", "1500 bytes long"),
    Case("link name of 1000 x 'ロ' (3000 bytes)", robot(link="ロ" * 1000), "crash",
         "3000 bytes long"),
    Case("link name of 700 x 'é' (1400 bytes, under the link crash length)",
         robot(link="é" * 700), "loads", "1400 bytes long", liftable=True),
    Case("ASCII joint name of 1100 bytes", robot(joint="j" * 1100), "loads", "1100 bytes long",
         liftable=True),
    Case("robot name of 1500 bytes: loads, then getBodyInfo crashes", robot(name="r" * 1500),
         "crash", "1500 bytes long", query="p.getBodyInfo(b)"),
    Case("mesh that is a directory", robot(mesh="meshdir.stl"), "crash", "is a directory"),
    Case("mesh that is a FIFO", robot(mesh="pipe.stl"), "hang", "is a FIFO"),
]


@pytest.fixture
def workdir(tmp_path: Path) -> Path:
    (tmp_path / "meshdir.stl").mkdir()
    os.mkfifo(tmp_path / "pipe.stl")
    return tmp_path


def write(workdir: Path, case: Case) -> Path:
    path = workdir / "robot.urdf"
    path.write_text(case.urdf, encoding="utf-8")
    return path


def raw_outcome(path: Path, query: str = "", timeout: float = 4.0) -> str:
    """What raw PyBullet does with the file, in a subprocess (a crash must not kill pytest)."""
    code = textwrap.dedent(f"""
        import pybullet as p
        p.connect(p.DIRECT)
        try:
            b = p.loadURDF({str(path)!r})
        except p.error:
            raise SystemExit(3)
        {query}
        print("LOADED")
    """)
    try:
        done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                              timeout=timeout, cwd=path.parent)
    except subprocess.TimeoutExpired:
        return "hang"
    if done.returncode < 0:
        return "crash"
    if done.returncode == 3:
        return "error"
    return "loads" if "LOADED" in done.stdout else f"exit {done.returncode}"


@pytest.mark.parametrize("case", CASES, ids=[c.name for c in CASES])
def test_the_guard_refuses_every_class_with_one_named_line(workdir: Path, case: Case) -> None:
    path = write(workdir, case)
    for command in (["joints"], ["links", "--json"], ["info"], ["render", "-o", "-"]):
        result = CliRunner().invoke(app, [command[0], str(path), *command[1:]])
        assert result.exit_code == 2, (command, result.stderr)
        lines = result.stderr.strip().splitlines()
        assert len(lines) == 1 and lines[0].startswith(f"urdfkit: error: {path}:"), lines
        assert case.refusal in lines[0]
        assert ("--no-guard lifts it" in lines[0]) == case.liftable, lines[0]


@pytest.mark.parametrize("case", CASES, ids=[c.name for c in CASES])
def test_no_guard_lifts_only_what_pybullet_survives(workdir: Path, case: Case) -> None:
    path = write(workdir, case)
    result = CliRunner().invoke(app, ["joints", str(path), "--json", "--no-guard"])
    if case.liftable:
        assert result.exit_code == 0, result.stderr
        assert "let through without the guard" in result.stderr  # never silent
    else:
        assert result.exit_code == 2 and case.refusal in result.stderr


def test_every_crash_class_is_in_the_table() -> None:
    # A class the guard handles must be measured here; raw outcomes other than loads must be
    # refused without a way around.
    assert {c.raw for c in CASES} == {"crash", "hang", "loads"}
    assert all(c.liftable == (c.raw == "loads") for c in CASES)
    assert MAX_NAME_BYTES < min(CRASH_NAME_BYTES.values())


def test_raw_pybullet_still_behaves_as_recorded(workdir: Path) -> None:
    # Re-measured every run (in parallel, ~3 s): a PyBullet that moves a limit shows up here.
    files = []
    for i, case in enumerate(CASES):
        path = workdir / f"case{i}.urdf"
        path.write_text(case.urdf, encoding="utf-8")
        files.append((path, case))
    with ThreadPoolExecutor(max_workers=4) as pool:
        outcomes = list(pool.map(lambda pc: raw_outcome(pc[0], pc[1].query), files))
    mismatched = [(c.name, c.raw, got) for (_, c), got in zip(files, outcomes, strict=True)
                  if got != c.raw]
    assert mismatched == []


@pytest.mark.slow
def test_an_oversized_body_is_refused_before_the_tree_is_built(tmp_path: Path) -> None:
    # 280,000 links took 10 s and 720 MB to parse before the refusal; now it is a streaming
    # count with constant memory. Peak memory is the check (time is too noisy here).
    n = 280_000
    path = tmp_path / "chain.urdf"
    with path.open("w") as f:
        f.write('<robot name="chain">')
        f.writelines(f'<link name="l{i}"/>' for i in range(n))
        f.writelines(f'<joint name="j{i}" type="fixed"><parent link="l{i - 1}"/>'
                     f'<child link="l{i}"/></joint>' for i in range(1, n))
        f.write("</robot>")
    code = ("import sys\n"
            "from urdfkit.cli import main\n"
            "sys.argv = ['urdfkit', *sys.argv[1:]]\n"
            "try:\n    main()\nexcept SystemExit as e:\n"
            f"    print({PEAK_KIB}, e.code)\n")
    for command in (["tree"], ["joints", "--json"], ["check", "--json"]):
        done = subprocess.run([sys.executable, "-c", code, command[0], str(path), *command[1:]],
                              capture_output=True, text=True, timeout=120)
        peak_kb, exit_code = done.stdout.split()[-2:]
        assert exit_code == ("1" if command[0] == "check" else "2"), done.stderr
        assert "280000 links" in (done.stderr + done.stdout)
        assert int(peak_kb) < 250_000, (command, peak_kb)  # was 720 MB


#: A child's own peak memory in KiB (VmHWM). Not ru_maxrss: Linux carries the parent's
#: resident size across fork and exec into it, so after a test that grew pytest it lies.
PEAK_KIB = ("next(int(line.split()[1]) for line in open('/proc/self/status') "
            "if line.startswith('VmHWM:'))")


def one_line_robot(cut: int) -> str:
    """One line where ``<inertial>`` of link b straddles byte ``cut`` (a comment pads it)."""
    head = ('<robot name="r"><link name="a"><visual><geometry><box size="1 1 1"/></geometry>'
            '</visual></link>')
    tail = ('<link name="b"><inertial><mass value="1"/><inertia ixx="1" ixy="0" ixz="0" '
            'iyy="1" iyz="0" izz="1"/></inertial></link><joint name="j" type="fixed">'
            '<parent link="a"/><child link="b"/></joint></robot>')
    pad = cut - len(head) - len('<link name="b"><ine') - len("<!---->")
    return head + "<!--" + "x" * pad + "-->" + tail


@pytest.mark.parametrize("cut", [8191, 16382])  # PyBullet breaks lines every 8191 bytes
def test_a_line_pybullet_breaks_is_loaded_from_a_formatted_copy(tmp_path: Path,
                                                                 cut: int) -> None:
    broken, control = tmp_path / "broken.urdf", tmp_path / "control.urdf"
    broken.write_text(one_line_robot(cut))
    control.write_text(one_line_robot(600))  # the same robot, no break in a name
    assert raw_outcome(broken) == "error" and raw_outcome(control) == "loads"
    ours = CliRunner().invoke(app, ["joints", str(broken), "--json"])
    assert ours.exit_code == 0, ours.stderr
    theirs = CliRunner().invoke(app, ["joints", str(control), "--json"])
    assert json.loads(ours.stdout)["joints"] == json.loads(theirs.stdout)["joints"]
    found = json.loads(CliRunner().invoke(app, ["check", str(broken), "--json"]).stdout)
    assert [f["line"] for f in found["findings"] if f["code"] == "U008"] == [1]
    assert not [f for f in json.loads(CliRunner().invoke(
        app, ["check", str(control), "--json"]).stdout)["findings"] if f["code"] == "U008"]


@settings(max_examples=500, deadline=None)
@given(st.text(alphabet="ab./\\OoBbJjSsTtLlDdAaEe", max_size=12))
def test_mesh_suffix_reads_as_splitext(fn: str) -> None:
    # reference()'s fast path and the mesh lookup tell a mesh format without os.path.splitext.
    from urdfkit.model.spec import MESH_FORMATS, mesh_suffix

    suffix = os.path.splitext(fn)[1].lower()
    assert mesh_suffix(fn) == (suffix if suffix in MESH_FORMATS else "")
