"""Every file-reading command over the hostile corpus: no crash, no traceback, no leak."""

from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

import pytest

from urdfkit.cli import app

HERE = Path(__file__).parent / "hostile"
sys.path.insert(0, str(HERE))
from make_corpus import make_corpus  # noqa: E402

#: Command -> extra arguments ({file} is replaced by the corpus file; else it comes first).
COMMANDS: dict[str, list[str]] = {
    "check": [], "joints": [], "links": [], "tree": [], "info": [], "fix": ["{file}", "--diff"],
    "drive": ["--urdf", "{file}", "--steps", "5"],
    "render": ["{file}", "--size", "64x48", "--force", "-o", "{out}"],
    "export": ["mjcf", "{file}", "--force", "-o", "{xml}"],
}
PASSWD_MARK = "root:x:0:0"


@pytest.fixture(scope="module")
def corpus(tmp_path_factory: pytest.TempPathFactory) -> tuple[Path, dict[str, str]]:
    out = tmp_path_factory.mktemp("hostile")
    expected = make_corpus(out / "corpus")
    yield out / "corpus", expected
    (out / "corpus" / "unreadable.urdf").chmod(0o644)


def _registered() -> set[str]:
    return {c.name or c.callback.__name__ for c in app.registered_commands}  # type: ignore[union-attr]


@pytest.mark.parametrize("command", list(COMMANDS))
def test_command_survives_corpus(command: str, corpus: tuple[Path, dict[str, str]],
                                 tmp_path: Path) -> None:
    assert command in _registered(), f"`urdfkit {command}` is not registered"
    folder, expected = corpus
    files = [str(folder / name) for name in sorted(expected)]
    extra = [a.replace("{out}", str(tmp_path / "out.png"))
             .replace("{xml}", str(tmp_path / "out.xml")) for a in COMMANDS[command]]
    log = tmp_path / "log.jsonl"
    proc = subprocess.run(
        [sys.executable, str(HERE / "run_commands.py"), str(log), command, *files, "--", *extra],
        capture_output=True, timeout=300, cwd=tmp_path)
    records = [json.loads(ln) for ln in log.read_text().splitlines()]
    started = [r["start"] for r in records if "start" in r]
    assert proc.returncode == 0, (f"`urdfkit {command}` died (code {proc.returncode}) on "
                                  f"{started[-1] if started else '?'}: {proc.stderr[-2000:]!r}")
    results = [r for r in records if "exit" in r]
    assert len(results) == len(files)
    unnamed = []
    for r in results:
        name = Path(r["file"]).name
        said = r["stdout"] + r["stderr"]
        assert r["exception"] is None, f"{command} {name}: {r['exception']}"
        assert "Traceback" not in said, f"{command} {name}: {said[-1500:]}"
        assert r["exit"] in (0, 1, 2), f"{command} {name}: exit {r['exit']}"
        assert r["seconds"] < 15, f"{command} {name}: {r['seconds']:.1f} s"
        assert PASSWD_MARK not in said
        if r["exit"] != 0 and name not in said:
            unnamed.append(f"{name}: {said.strip()!r}")
    assert not unnamed, f"`urdfkit {command}` messages that do not name the file: {unnamed}"


def test_check_verdicts_over_corpus(corpus: tuple[Path, dict[str, str]]) -> None:
    folder, expected = corpus
    proc = subprocess.run([sys.executable, "-m", "urdfkit", "check", str(folder), "--json"],
                          capture_output=True, text=True, timeout=120)
    assert proc.returncode == 1, proc.stderr
    assert PASSWD_MARK not in proc.stdout + proc.stderr
    data = json.loads(proc.stdout)
    assert sorted(Path(f).name for f in data["files"]) == sorted(expected)
    with_errors = {Path(f["file"]).name for f in data["findings"] if f["level"] == "error"}
    verdicts = {name: ("error" if name in with_errors else "ok") for name in expected}
    assert verdicts == expected


@pytest.mark.parametrize("name", ["two_roots.urdf", "two_parents.urdf", "cycle_with_root.urdf",
                                  "duplicate_joints.urdf", "self_joint.urdf",
                                  "percent_link.urdf", "long_name.urdf", "x.urdf", "xxe.urdf"])
def test_real_cli_refuses_crash_cases(name: str, corpus: tuple[Path, dict[str, str]]) -> None:
    """The installed entry point, as a user runs it: exit 2, one line naming the file."""
    folder, _ = corpus
    proc = subprocess.run([sys.executable, "-m", "urdfkit", "joints", str(folder / name)],
                          capture_output=True, text=True, timeout=60,
                          env={**os.environ, "COLUMNS": "400"})
    assert proc.returncode == 2, proc.stderr
    assert proc.stdout == ""
    assert "Traceback" not in proc.stderr and name in proc.stderr
