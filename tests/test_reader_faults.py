"""Every reader of every command, given what is not a regular file: a FIFO (which would block
forever), a symlink to /dev/zero (which never ends), a folder, and a symlink to nothing. Each
must give one line naming the file and exit 2 (check: a finding, exit 1), at once (issue 26,
class 1; the fuzzer covers the same for meshes)."""

from __future__ import annotations

import os
import shutil
import signal
from collections.abc import Iterator
from pathlib import Path

import pytest
from typer.testing import CliRunner

from urdfkit.cli import app

runner = CliRunner()
EXAMPLES = Path(__file__).resolve().parents[1] / "examples"
KINDS = ("fifo", "zero", "folder", "dangling")
#: How long a refusal may take: it is a stat, not a read (a hang is what is tested for).
LIMIT_S = 30

URDF_COMMANDS = [
    ["joints", "{F}"], ["links", "{F}", "--json"], ["tree", "{F}"], ["info", "{F}"],
    ["render", "{F}", "-o", "{D}/out.png"], ["collisions", "{F}"],
    ["fix", "{F}", "-o", "{D}/fixed.urdf"], ["diff", "{F}", "{GOOD}"], ["diff", "{GOOD}", "{F}"],
    ["drive", "--urdf", "{F}", "--steps", "5"],
    ["export", "mjcf", "{F}", "-o", "{D}/out.xml"], ["agree", "{F}", "{D}/none.xml"],
    ["agree", "{GOOD}", "{F}"],
    ["sweep", "drive", "--urdf", "{F}", "--steps", "5", "--vary", "throttle=1,2", "--jobs", "1"],
]
SCENARIO_COMMANDS = [
    ["sim", "{F}", "-o", "{D}/rows.csv"],
    ["sim", "convert", "{F}", "-o", "{D}/scenario.toml"],
    ["sweep", "sim", "{F}", "--vary", "duration=0.1,0.2", "--jobs", "1"],
]


def _make(kind: str, path: Path) -> None:
    if kind == "fifo":
        os.mkfifo(path)
    elif kind == "zero":
        path.symlink_to("/dev/zero")
    elif kind == "folder":
        path.mkdir()
    else:
        path.symlink_to(path.with_name("nothing-here"))


@pytest.fixture
def alarm() -> Iterator[None]:
    def hang(*_: object) -> None:
        raise TimeoutError(f"the command did not return within {LIMIT_S} s (it hangs)")

    old = signal.signal(signal.SIGALRM, hang)
    signal.alarm(LIMIT_S)
    try:
        yield
    finally:
        signal.alarm(0)
        signal.signal(signal.SIGALRM, old)


def _run(args: list[str], bad: Path, tmp: Path, good: Path) -> tuple[int, str]:
    argv = [a.replace("{F}", str(bad)).replace("{D}", str(tmp)).replace("{GOOD}", str(good))
            for a in args]
    result = runner.invoke(app, argv)
    return result.exit_code, result.stderr


def _one_line_naming(err: str, name: str) -> str:
    lines = [ln for ln in err.splitlines() if ln.strip() and "warning:" not in ln]
    assert len(lines) == 1, err[:2000]
    assert "Traceback" not in err and name in lines[0], lines[0]
    return lines[0]


@pytest.mark.parametrize("kind", KINDS)
@pytest.mark.parametrize("args", URDF_COMMANDS, ids=lambda a: " ".join(a[:2]))
def test_a_urdf_that_is_not_a_regular_file(kind: str, args: list[str], tmp_path: Path,
                                           simplecar_urdf: Path, alarm: None) -> None:
    bad = tmp_path / "bad.urdf"
    _make(kind, bad)
    code, err = _run(args, bad, tmp_path, simplecar_urdf)
    assert code == 2
    _one_line_naming(err, "bad.urdf")


@pytest.mark.parametrize("kind", KINDS)
def test_check_reports_a_urdf_that_is_not_a_regular_file_as_an_error(
        kind: str, tmp_path: Path, alarm: None) -> None:
    bad = tmp_path / "bad.urdf"
    _make(kind, bad)
    result = runner.invoke(app, ["check", str(bad), "--format", "json"])
    assert result.exit_code in (1, 2), result.output
    assert "bad.urdf" in result.stdout + result.stderr and "Traceback" not in result.stderr


@pytest.mark.parametrize("kind", KINDS)
@pytest.mark.parametrize("args", SCENARIO_COMMANDS, ids=lambda a: " ".join(a[:2]))
def test_a_scenario_that_is_not_a_regular_file(kind: str, args: list[str], tmp_path: Path,
                                               simplecar_urdf: Path, alarm: None) -> None:
    bad = tmp_path / "bad.json"
    _make(kind, bad)
    code, err = _run(args, bad, tmp_path, simplecar_urdf)
    assert code == 2
    _one_line_naming(err, "bad.json")


@pytest.mark.parametrize("kind", ("fifo", "zero"))
def test_a_xacro_include_that_is_not_a_regular_file(kind: str, tmp_path: Path,
                                                    alarm: None) -> None:
    _make(kind, tmp_path / "inc.xacro")
    top = tmp_path / "top.urdf.xacro"
    top.write_text('<?xml version="1.0"?>\n<robot name="r" '
                   'xmlns:xacro="http://www.ros.org/wiki/xacro">\n'
                   '  <xacro:include filename="inc.xacro"/>\n  <link name="a"/>\n</robot>\n')
    for args in (["build", str(top), "-o", str(tmp_path / "top.urdf")], ["joints", str(top)]):
        code, err = _run(args, top, tmp_path, top)
        assert code == 2
        line = _one_line_naming(err, "inc.xacro")
        assert "not a regular file" in line


@pytest.mark.parametrize("kind", ("fifo", "zero"))
def test_a_sweep_journal_that_is_not_a_regular_file(kind: str, tmp_path: Path,
                                                    alarm: None) -> None:
    out = tmp_path / "rows.csv"
    _make(kind, tmp_path / "rows.csv.partial")
    code, err = _run(["sweep", "drive", "--steps", "5", "--vary", "throttle=1,2", "--jobs", "1",
                      "-o", str(out), "--resume"], out, tmp_path, out)
    assert code == 2
    _one_line_naming(err, "rows.csv.partial")


@pytest.mark.parametrize("kind", KINDS)
def test_scenario_env_refuses_a_scenario_that_is_not_a_regular_file(
        kind: str, tmp_path: Path, alarm: None) -> None:
    pytest.importorskip("gymnasium", reason="urdfkit.gym needs the gym extra")
    from urdfkit.core.errors import InputError
    from urdfkit.gym import ScenarioEnv

    bad = tmp_path / "bad.json"
    _make(kind, bad)
    with pytest.raises(InputError, match="bad.json"):
        ScenarioEnv(bad)


def test_the_readers_still_read_regular_files(tmp_path: Path, simplecar_urdf: Path,
                                              alarm: None) -> None:
    # The same commands on real files succeed: the refusals above are about the file type.
    shutil.copy(EXAMPLES / "pendulum.urdf", tmp_path / "pendulum.urdf")
    shutil.copy(EXAMPLES / "pendulum_servo.json", tmp_path / "s.json")
    for args in (["joints", "{F}"], ["diff", "{F}", "{GOOD}"]):
        code, err = _run(args, simplecar_urdf, tmp_path, simplecar_urdf)
        assert code == 0, err
    code, err = _run(["sim", "{F}", "-o", "{D}/rows.csv"], tmp_path / "s.json", tmp_path,
                     simplecar_urdf)
    assert code == 0, err


SAC = Path(__file__).parent / "fixtures" / "sac"


@pytest.mark.parametrize("kind", ("fifo", "zero", "folder", "long"))
def test_a_simulation_and_control_urdf_path_that_is_not_a_file(kind: str, tmp_path: Path,
                                                                alarm: None) -> None:
    import json

    shutil.copytree(SAC / "models", tmp_path / "models")
    (tmp_path / "configs").mkdir()
    conf = json.loads((SAC / "configs" / "pendulum.json").read_text())
    name = "a/" * 2500 + "x.urdf" if kind == "long" else "bad.urdf"
    if kind != "long":
        _make(kind, tmp_path / "models" / name)
    conf["robot_pybullet"]["urdf_path"] = [name]
    config = tmp_path / "configs" / "pendulum.json"
    config.write_text(json.dumps(conf))
    code, err = _run(["sim", "{F}", "-o", "{D}/rows.csv"], config, tmp_path, config)
    assert code == 2
    line = _one_line_naming(err, "urdf_path[0]")
    assert "no such file" not in line  # it is there, or too long a name: said as such
    assert len(line) < 1000
