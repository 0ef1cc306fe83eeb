"""`urdfkit check` over a hostile tree: one broken file never stops the sweep, nothing hangs,
nothing is skipped silently, and pool workers never outlive the command."""

from __future__ import annotations

import json
import os
import shutil
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest

from urdfkit.checks.check import check_paths

GOOD = Path(__file__).parent / "golden" / "simplecar.urdf"


@pytest.fixture
def hostile(tmp_path: Path) -> Path:
    root = tmp_path / "repo"
    (root / "sub").mkdir(parents=True)
    shutil.copy(GOOD, root / "good.urdf")
    shutil.copy(GOOD, root / "sub" / "also_good.urdf")
    os.mkfifo(root / "pipe.urdf")  # open() would block forever waiting for a writer
    (root / "zero.urdf").symlink_to("/dev/zero")  # st_size 0, endless bytes
    (root / "folder.urdf").mkdir()
    (root / "dangling.urdf").symlink_to(root / "gone")
    name = os.fsdecode(bytes(root) + b"/caf\xe9.urdf")  # Latin-1 name, not UTF-8
    shutil.copy(GOOD, name)
    (root / "huge.urdf").write_text(GOOD.read_text().replace('<mass value="', '<mass value="1e308'))
    (root / "loop").symlink_to(root)  # a symlinked folder must not trap the walk
    return root


def test_one_broken_file_never_stops_the_sweep(hostile: Path) -> None:
    result = check_paths([hostile], jobs=1)
    by_name = {Path(fr.file).name: fr for fr in result.files}
    assert {"good.urdf", "also_good.urdf", "pipe.urdf", "zero.urdf", "folder.urdf",
            "dangling.urdf", "caf\udce9.urdf", "huge.urdf"} <= set(by_name)

    def u000(name: str) -> str:
        (f,) = [f for f in by_name[name].findings if f.code == "U000"]
        assert f.level == "error"
        return f.message

    assert "FIFO" in u000("pipe.urdf")
    assert "device" in u000("zero.urdf")
    assert "directory" in u000("folder.urdf")
    assert "no such file" in u000("dangling.urdf")
    for good in ("good.urdf", "also_good.urdf", "caf\udce9.urdf"):
        assert not [f for f in by_name[good].findings if f.level == "error"]
    assert any(f.code == "U601" or f.code.startswith("U4") for f in by_name["huge.urdf"].findings)


@pytest.mark.parametrize("as_json", [True, False])
def test_the_cli_reports_every_file_in_text_and_json(hostile: Path, as_json: bool) -> None:
    args = [sys.executable, "-m", "urdfkit", "check", str(hostile), "--jobs", "2"]
    done = subprocess.run(args + (["--json"] if as_json else []), capture_output=True,
                          timeout=60)
    assert done.returncode == 1, done.stderr  # findings, not a crash (3) or usage (2)
    assert b"Traceback" not in done.stderr
    if as_json:
        doc = json.loads(done.stdout)
        assert doc["summary"]["files"] == len(doc["files"]) >= 8
    else:
        # The name comes out as the bytes it has on disk (or escaped), never as a crash.
        assert b"caf\xe9.urdf" in done.stdout or b"caf\\udce9.urdf" in done.stdout
        assert b"file(s) checked" in done.stdout.splitlines()[-1]


def test_an_unreadable_folder_is_reported_not_skipped(tmp_path: Path) -> None:
    import tempfile

    as_root = os.geteuid() == 0
    setpriv = shutil.which("setpriv")
    if as_root and setpriv is None:
        pytest.skip("running as root (which reads anything) and setpriv is not available")
    # Root reads anything, so the check runs as nobody, in a folder nobody can reach.
    base = Path(tempfile.mkdtemp(dir="/tmp" if as_root else tmp_path))
    try:
        base.chmod(0o755)
        locked = base / "locked"
        locked.mkdir()
        shutil.copy(GOOD, locked / "r.urdf")
        shutil.copy(GOOD, base / "ok.urdf")
        locked.chmod(0)
        cmd = [sys.executable, "-m", "urdfkit", "check", str(base), "--json"]
        if as_root:
            cmd = [str(setpriv), "--reuid=65534", "--regid=65534", "--clear-groups", *cmd]
        done = subprocess.run(cmd, capture_output=True, timeout=60,
                              env={**os.environ, "HOME": "/tmp"})
        assert done.returncode == 1, done.stderr
        doc = json.loads(done.stdout)
    finally:
        (base / "locked").chmod(0o755)
        shutil.rmtree(base)
    problems = [f for f in doc["findings"] if f["file"] == str(locked)]
    assert problems and problems[0]["code"] == "U000" and "cannot list" in problems[0]["message"]
    assert str(base / "ok.urdf") in doc["files"]


def test_pool_workers_die_with_the_parent(tmp_path: Path) -> None:
    # Enough files that the sweep is still running when the parent is killed.
    tree = tmp_path / "many"
    tree.mkdir()
    text = GOOD.read_text()
    for i in range(8000):
        (tree / f"r{i}.urdf").write_text(text)
    reader_r, reader_w = os.pipe()
    proc = subprocess.Popen([sys.executable, "-m", "urdfkit", "check", str(tree), "--jobs", "2"],
                            stdout=reader_w, stderr=subprocess.DEVNULL)
    os.close(reader_w)

    def workers() -> list[int]:
        found = []
        for pid in os.listdir("/proc"):
            if not pid.isdigit() or int(pid) == proc.pid:
                continue
            try:
                cmdline = Path(f"/proc/{pid}/cmdline").read_bytes()
            except OSError:
                continue
            if str(tree).encode() in cmdline:
                found.append(int(pid))
        return found

    deadline = time.monotonic() + 60
    while not workers():  # imports done, workers forked and busy, however slow the machine
        assert proc.poll() is None and time.monotonic() < deadline, "no pool was seen running"
        time.sleep(0.02)
    proc.send_signal(signal.SIGKILL)  # no chance to clean up: only PR_SET_PDEATHSIG helps
    proc.wait(timeout=10)
    deadline = time.monotonic() + 5
    while workers() and time.monotonic() < deadline:
        time.sleep(0.05)
    assert workers() == []
    # Nobody else holds the pipe: the reader sees EOF at once instead of minutes later.
    os.set_blocking(reader_r, False)
    try:
        drained = b""
        while chunk := os.read(reader_r, 65536):
            drained += chunk
        assert b"Traceback" not in drained
    except BlockingIOError:
        pytest.fail("a worker still holds the caller's stdout")
    finally:
        os.close(reader_r)


def test_a_worker_dies_with_its_parent_even_when_idle(tmp_path: Path) -> None:
    # The end-to-end test above also passes when workers die of SIGPIPE on their next result;
    # this one pins the mechanism: an idle worker (as when a chunk is a slow xacro) must go
    # when its parent is SIGKILLed, and must not hold the caller's stdout.
    pidfile = tmp_path / "worker.pid"
    code = f"""
import os, time
from urdfkit.checks.check import worker_init
if os.fork() == 0:
    worker_init()
    with open({str(pidfile)!r}, "w") as f:
        f.write(str(os.getpid()))
    time.sleep(60)
    os._exit(0)
time.sleep(60)
"""
    parent = subprocess.Popen([sys.executable, "-c", code], stdout=subprocess.PIPE)
    deadline = time.monotonic() + 20
    while not pidfile.exists() or not pidfile.read_text():
        assert time.monotonic() < deadline
        time.sleep(0.05)
    worker = int(pidfile.read_text())
    assert os.readlink(f"/proc/{worker}/fd/1") == os.devnull
    parent.kill()
    parent.wait(timeout=10)
    deadline = time.monotonic() + 5
    while Path(f"/proc/{worker}").exists() and time.monotonic() < deadline:
        status = Path(f"/proc/{worker}/status").read_text() if Path(
            f"/proc/{worker}/status").exists() else ""
        if "State:\tZ" in status:
            break  # dead, waiting to be reaped by init
        time.sleep(0.05)
    alive = Path(f"/proc/{worker}").exists() and "State:\tZ" not in Path(
        f"/proc/{worker}/status").read_text()
    assert not alive
    assert parent.stdout is not None
    with parent.stdout:
        assert parent.stdout.read() == b""  # EOF at once: nobody else holds the pipe
