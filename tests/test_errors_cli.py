"""The one error road: exit codes, one-line messages, flags for parameters, did-you-mean,
signals, help and completion."""

from __future__ import annotations

import json
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest
from typer.testing import CliRunner

from urdfkit.cli import app
from urdfkit.commands import present
from urdfkit.commands.flags import flag_message
from urdfkit.core.errors import ParameterError
from urdfkit.motion.drive import DriveConfig

runner = CliRunner()

COMMANDS = ["build", "templates", "joints", "links", "tree", "info", "check", "drive",
            "render", "sim", "export", "agree"]


def invoke(*args: str, env: dict[str, str] | None = None) -> tuple[int, str, str]:
    result = runner.invoke(app, list(args), env=env)
    return result.exit_code, result.stdout, result.stderr


def one_error_line(err: str) -> str:
    lines = [line for line in err.splitlines() if line.strip()]
    assert len(lines) == 1, err
    assert lines[0].startswith("urdfkit: "), err
    assert "Traceback" not in err
    return lines[0]


# --------------------------------------------------------------------------- exit codes


def test_a_bug_exits_3_with_one_line_and_a_debug_switch(monkeypatch: pytest.MonkeyPatch,
                                                        simplecar_urdf: Path) -> None:
    import urdfkit.engine.report

    def broken(*_a: object, **_k: object) -> None:
        raise RuntimeError("boom")

    monkeypatch.setattr(urdfkit.engine.report, "inspect_file", broken)
    code, out, err = invoke("joints", str(simplecar_urdf))
    assert code == 3 and out == ""
    line = one_error_line(err)
    assert "internal error (a bug in urdfkit)" in line and "RuntimeError: boom" in line
    assert "URDFKIT_DEBUG=1" in line
    code, _, err = invoke("joints", str(simplecar_urdf), env={"URDFKIT_DEBUG": "1"})
    assert code == 3 and "Traceback" in err and "RuntimeError: boom" in err


def test_a_crash_in_check_is_not_a_finding(monkeypatch: pytest.MonkeyPatch,
                                           simplecar_urdf: Path) -> None:
    # CI must tell "your URDF has errors" (1) from "urdfkit broke" (3).
    import urdfkit.checks.check

    monkeypatch.setattr(urdfkit.checks.check, "check_paths",
                        lambda *a, **k: (_ for _ in ()).throw(KeyError("rule")))
    code, _, err = invoke("check", str(simplecar_urdf))
    assert code == 3 and "a bug in urdfkit" in one_error_line(err)


@pytest.mark.parametrize(("args", "expected"), [
    (["drive", "--throttle", "abc"],
     "urdfkit: error: drive: Invalid value for '--throttle': 'abc'"),
    (["joints"], "urdfkit: error: joints: Missing argument 'FILE'"),
    (["joints", "r2d2.urdf", "--bogus"], "No such option: --bogus"),
    (["nosuch"], "No such command 'nosuch'"),
    (["check", "--fail-on", "warn", "x.urdf"], "--fail-on expects error, warning or info"),
])
def test_usage_errors_are_one_line_exit_2(args: list[str], expected: str) -> None:
    code, _, err = invoke(*args)
    assert code == 2
    line = one_error_line(err)
    assert line.startswith("urdfkit: error: ")
    assert expected.lower() in line.lower(), line


def test_unknown_option_suggests_the_close_one() -> None:
    _, _, err = invoke("drive", "--throtle", "3")
    assert "--throttle" in one_error_line(err)


# --------------------------------------------------------------------------- parameters


def test_library_names_parameters_and_the_cli_names_flags() -> None:
    with pytest.raises(ParameterError) as e:
        DriveConfig(time_step=0).check()
    assert "`time_step`" in str(e.value) and "--" not in str(e.value)
    assert e.value.param == "time_step"
    code, _, err = invoke("drive", "--time-step", "0")
    assert code == 2 and "--time-step must be in (0, 0.1]" in one_error_line(err)
    assert flag_message("`xacro_args` and `params`") == "--arg and --set"
    assert flag_message("pass `force=True` to overwrite") == "pass --force to overwrite"
    assert flag_message("`sample_every`") == "--sample-every"


def test_scenario_keys_are_not_turned_into_flags(tmp_path: Path) -> None:
    scenario = tmp_path / "s.json"
    scenario.write_text(json.dumps({"robots": [{"template": "simplecar",
                                                "vehicle": {"wheels": ["nope"]},
                                                "drive": [{"until": 1, "throttle": 1}]}]}))
    code, _, err = invoke("sim", str(scenario))
    line = one_error_line(err)
    assert code == 2 and "robots[0].vehicle: `wheels`: no joint named 'nope'" in line


# --------------------------------------------------------------------------- did you mean


@pytest.mark.parametrize(("args", "expected"), [
    (["joints", "r2d2"], "did you mean 'r2d2.urdf'?"),
    (["joints", "r2d3.urdf"], "did you mean 'r2d2.urdf'?"),
    (["build", "simplcar"], "did you mean 'simplecar'"),
    (["build", "simplecar", "--set", "wheel_radiu=0.1", "-o", "-"], "did you mean "
     "'wheel_radius'?"),
    (["joints", "r2d2.urdf", "--type", "revolut"], "did you mean 'revolute'?"),
    (["drive", "--steps", "5", "--wheels", "base_to_left_back_whel"],
     "did you mean 'base_to_left_back_wheel'?"),
    (["render", "r2d2.urdf", "--view", "isometric", "-o", "-"], "(choose from"),
])
def test_did_you_mean(args: list[str], expected: str) -> None:
    code, _, err = invoke(*args)
    assert code == 2
    assert expected in one_error_line(err)


def test_did_you_mean_looks_beside_the_file(tmp_path: Path, simplecar_urdf: Path) -> None:
    (tmp_path / "my_arm.urdf").write_bytes(simplecar_urdf.read_bytes())
    _, _, err = invoke("joints", str(tmp_path / "my_arm"))
    assert f"did you mean '{tmp_path / 'my_arm.urdf'}'?" in one_error_line(err)


def test_did_you_mean_goes_path_component_by_component(
        tmp_path: Path, simplecar_urdf: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    # Issue 49: `joints kuka_iwa/model.urdf` got nothing; `joints ./my_robt.urdf` suggested
    # pybullet_data's cube_rotate.urdf.
    monkeypatch.chdir(tmp_path)
    _, _, err = invoke("joints", "kuka_iwa/model.urdf")
    assert one_error_line(err).endswith("did you mean 'kuka_iiwa/model.urdf'?")
    _, _, err = invoke("joints", "kuka_iwa/modl.urdf")  # a folder and the file both misspelt
    assert one_error_line(err).endswith("did you mean 'kuka_iiwa/model.urdf'?")
    _, _, err = invoke("joints", "./my_robt.urdf")  # nothing close: nothing suggested
    assert "did you mean" not in one_error_line(err)
    (tmp_path / "my_robot.urdf").write_bytes(simplecar_urdf.read_bytes())
    _, _, err = invoke("joints", "./my_robt.urdf")  # the file here, spelt as the user spelt it
    assert one_error_line(err).endswith("did you mean './my_robot.urdf'?")
    (tmp_path / "robots" / "arm").mkdir(parents=True)
    (tmp_path / "robots" / "arm" / "arm.urdf").write_bytes(simplecar_urdf.read_bytes())
    _, _, err = invoke("joints", "robot/arms/arm.urdf")
    assert one_error_line(err).endswith("did you mean 'robots/arm/arm.urdf'?")


# --------------------------------------------------------------------------- JSON


def test_json_never_carries_nan(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    text = present.json_text({"a": [1.0, float("nan")], "b": {"c": float("inf")}})
    doc = json.loads(text)
    assert doc["a"] == [1.0, None] and doc["b"] == {"c": None}
    assert doc["diagnostics"] == ["2 non-finite number(s) written as null (first at a[1])"]
    assert "non-finite" in capsys.readouterr().err
    # Through a command: PyBullet reports an infinite effort limit as inf.
    urdf = tmp_path / "inf.urdf"
    urdf.write_text('<robot name="r"><link name="a"/><link name="b"/>'
                    '<joint name="j" type="revolute"><parent link="a"/><child link="b"/>'
                    '<limit lower="-1" upper="1" effort="inf" velocity="1"/></joint></robot>')
    code, out, err = invoke("joints", str(urdf), "--json")
    assert code == 0, err
    doc = json.loads(out)
    assert doc["joints"][0]["jointMaxForce"] is None
    assert any("non-finite" in d for d in doc["diagnostics"])


# --------------------------------------------------------------------------- help


@pytest.mark.parametrize("command", COMMANDS)
def test_every_help_ends_with_examples(command: str) -> None:
    code, out, _ = invoke(command, "--help", env={"COLUMNS": "120"})
    assert code == 0
    tail = out[out.index("Examples"):]
    assert 2 <= tail.count(f"$ urdfkit {command}") <= 4


def test_help_text_reflows_and_keeps_its_words() -> None:
    # A docstring's line breaks are not the help's: its paragraphs are wrapped anew, to the
    # terminal's width up to 100 columns (tests/test_help_words.py: no word is cut).
    _, out, _ = invoke("drive", "--help", env={"COLUMNS": "300"})
    lines = out.splitlines()
    at = next(n for n, line in enumerate(lines) if line.startswith("  Wheels (continuous"))
    assert lines[at] == "  Wheels (continuous joints about a horizontal axis) and steering " \
        "hinges (revolute joints about a"  # up to 100 columns, not the docstring's 92
    assert "Wheels (continuous joints about a horizontal axis) and steering hinges (revolute " \
        "joints about a vertical axis that carry wheels) are detected." in " ".join(out.split())
    _, out, _ = invoke("tree", "--help", env={"COLUMNS": "300"})
    assert "[n] is the index PyBullet will give the joint." in " ".join(out.split())


def test_help_keeps_brackets_and_shows_readable_defaults() -> None:
    _, out, _ = invoke("drive", "--help", env={"COLUMNS": "160"})
    assert "urdfkit[plot]" in out
    assert "1/240" in out and "0.0041666" not in out


def test_shell_completion() -> None:
    code, out, err = invoke("--show-completion", "bash")
    assert code == 0 and "_urdfkit_completion" in out and "complete" in out, (code, out, err)
    done = subprocess.run([sys.executable, "-m", "urdfkit"], capture_output=True, text=True,
                          env={**os.environ, "_URDFKIT_COMPLETE": "complete_bash",
                               "COMP_WORDS": "urdfkit joints --mov", "COMP_CWORD": "2"},
                          timeout=60)
    assert done.stdout.split() == ["--movable"]


# --------------------------------------------------------------------------- signals


def wait_for_rows(folder: Path, proc: subprocess.Popen[str], timeout: float = 60.0) -> None:
    """Wait until the run streams rows (its temp file grows), however slow the machine."""
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline:
        assert proc.poll() is None, "the run ended before it was signalled"
        if any(p.stat().st_size > 20_000 for p in folder.glob(".*.tmp")):
            return
        time.sleep(0.05)
    pytest.fail("the run wrote no rows in time")


@pytest.mark.parametrize("sig", [signal.SIGTERM, signal.SIGHUP])
def test_sigterm_and_sighup_stop_a_drive_like_ctrl_c(tmp_path: Path, sig: int) -> None:
    out = tmp_path / "run.csv"
    proc = subprocess.Popen([sys.executable, "-m", "urdfkit", "drive", "--seconds", "100000",
                             "--trajectory", str(out)], stdout=subprocess.PIPE,
                            stderr=subprocess.PIPE, text=True)
    wait_for_rows(tmp_path, proc)  # past the imports and the load: the run loop is going
    proc.send_signal(sig)
    stdout, stderr = proc.communicate(timeout=30)
    assert proc.returncode == 130, stderr
    assert "interrupted" in stderr and "Traceback" not in stderr
    rows = out.read_text().splitlines()
    assert rows[0].startswith("t,x,y") and len(rows) > 10  # every complete row kept
    assert all(len(r.split(",")) == len(rows[0].split(",")) for r in rows)
    assert "final position" in stdout


# --------------------------------------------------------------------------- file names


@pytest.mark.parametrize("command", [["joints", "--json"], ["links", "--json"],
                                     ["info", "--json"], ["tree", "--json"], ["info"],
                                     ["tree"]])
def test_file_names_that_are_not_utf8_load(tmp_path: Path, simplecar_urdf: Path,
                                           command: list[str]) -> None:
    # A name from another locale: Python keeps the byte 0xff as a surrogate, which PyBullet
    # cannot take; urdfkit loads a copy with a clean name and shows the name escaped.
    name = os.fsdecode(bytes(tmp_path) + b"/car\xff.urdf")
    Path(name).write_bytes(simplecar_urdf.read_bytes())
    proc = subprocess.run([sys.executable, "-m", "urdfkit", command[0], name, *command[1:]],
                          capture_output=True, timeout=60)
    assert proc.returncode == 0, proc.stderr
    if "--json" in command:
        doc = json.loads(proc.stdout)
        assert doc["robot"] == "simplecar"
    else:
        assert b"simplecar" in proc.stdout and b"Traceback" not in proc.stderr


@pytest.mark.parametrize("suffix", [".csv", ".jsonl"])
def test_sigterm_keeps_the_rows_a_sim_streamed(tmp_path: Path, suffix: str) -> None:
    scenario = tmp_path / "long.json"
    scenario.write_text(json.dumps({
        "duration": 100000.0, "record": {"every": 24},
        "robots": [{"name": "car", "template": "simplecar",
                    "drive": [{"until": 100000.0, "throttle": 5, "steer": 0.2}]}]}))
    out = tmp_path / f"rows{suffix}"
    proc = subprocess.Popen([sys.executable, "-m", "urdfkit", "sim", str(scenario), "-o",
                             str(out)], stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                            text=True)
    wait_for_rows(tmp_path, proc)
    proc.send_signal(signal.SIGTERM)
    _, stderr = proc.communicate(timeout=30)
    assert proc.returncode == 130, stderr
    assert "interrupted" in stderr and "Traceback" not in stderr
    lines = out.read_text().splitlines()
    assert len(lines) > 5
    if suffix == ".jsonl":
        rows = [json.loads(line) for line in lines]  # every line a complete row
        assert [r["step"] for r in rows] == [24 * i for i in range(len(rows))]
    else:
        width = len(lines[0].split(","))
        assert lines[0].startswith("t,step,robot") and all(
            len(line.split(",")) == width for line in lines)
    assert not list(tmp_path.glob(".rows*.tmp"))  # the temp file became the file


def test_a_mesh_path_component_over_255_characters_is_one_line(tmp_path: Path,
                                                               simplecar_urdf: Path) -> None:
    text = simplecar_urdf.read_text().replace(
        "<visual>", f'<visual><geometry><mesh filename="{"d" * 300}/m.stl"/></geometry>'
                    "</visual><visual>", 1)
    path = tmp_path / "long.urdf"
    path.write_text(text)
    code, _, err = invoke("joints", str(path))
    assert code == 2
    assert "longer than the file system allows" in one_error_line(err)
    result = runner.invoke(app, ["check", str(path), "--json"])
    assert result.exit_code == 1
    assert "U704" in [f["code"] for f in json.loads(result.stdout)["findings"]]


def test_a_path_through_a_folder_you_cannot_enter_is_one_line(simplecar_urdf: Path) -> None:
    import shutil
    import tempfile

    as_root = os.geteuid() == 0
    setpriv = shutil.which("setpriv")
    if as_root and setpriv is None:
        pytest.skip("running as root (which enters anything) and setpriv is not available")
    base = Path(tempfile.mkdtemp(dir="/tmp"))
    try:
        base.chmod(0o755)
        locked = base / "locked"
        locked.mkdir()
        shutil.copy(simplecar_urdf, locked / "car.urdf")
        (base / "car.urdf").write_text(simplecar_urdf.read_text().replace(
            "<visual>", '<visual><geometry><mesh filename="locked/m.stl"/></geometry>'
                        "</visual><visual>", 1))
        locked.chmod(0)
        prefix = [setpriv, "--reuid=65534", "--regid=65534", "--clear-groups"] if as_root else []
        for target, fragment in ((locked / "car.urdf", "permission denied"),
                                 (base / "car.urdf", "permission denied")):
            done = subprocess.run([*prefix, sys.executable, "-m", "urdfkit", "joints",
                                   str(target)], capture_output=True, text=True, timeout=60,
                                  env={**os.environ, "HOME": "/tmp"})
            assert done.returncode == 2, done.stderr
            assert fragment in one_error_line(done.stderr)
    finally:
        (base / "locked").chmod(0o755)
        shutil.rmtree(base)
