"""Nothing is lost, nothing is clobbered: every writer goes through urdfkit/core/output.py."""

from __future__ import annotations

import errno
import os
import shutil
import subprocess
import time
from pathlib import Path

import pytest
from typer.testing import CliRunner

from urdfkit.cli import app
from urdfkit.core import output
from urdfkit.core.errors import OutputError
from urdfkit.core.output import StreamingFile, atomic_write, check_output

runner = CliRunner()


def one_line(err: str) -> str:
    lines = err.strip().splitlines()
    assert len(lines) == 1 and "Traceback" not in err, err
    return lines[0]


def test_special_files_are_never_replaced_even_with_force(tmp_path: Path) -> None:
    fifo = tmp_path / "pipe.urdf"
    os.mkfifo(fifo)
    for args in (["build", "simplecar", "-o", str(fifo), "--force"],
                 ["render", "r2d2.urdf", "-o", str(tmp_path / "sock.png"), "--force"]):
        if "sock.png" in args[3]:
            import socket

            s = socket.socket(socket.AF_UNIX)
            s.bind(args[3])
            s.close()
        result = runner.invoke(app, args)
        assert result.exit_code == 2
        assert "not a regular file" in one_line(result.stderr)
    assert fifo.is_fifo()
    with pytest.raises(OutputError, match="not a regular file"):
        check_output("/dev/null", force=True)


def test_a_dangling_symlink_is_an_existing_path(tmp_path: Path) -> None:
    link = tmp_path / "car.urdf"
    link.symlink_to(tmp_path / "nowhere.urdf")
    result = runner.invoke(app, ["build", "simplecar", "-o", str(link)])
    assert result.exit_code == 2 and "exists; pass --force" in one_line(result.stderr)
    assert link.is_symlink()
    result = runner.invoke(app, ["build", "simplecar", "-o", str(link), "--force"])
    assert result.exit_code == 0
    assert not link.is_symlink() and b"<robot" in link.read_bytes()  # the link, replaced
    assert not (tmp_path / "nowhere.urdf").exists()


def test_a_full_disk_is_one_line_and_leaves_no_temp_file(tmp_path: Path,
                                                          monkeypatch: pytest.MonkeyPatch) -> None:
    target = tmp_path / "car.urdf"
    target.write_text("keep me")

    def full(fd: int, data: bytes) -> int:
        raise OSError(errno.ENOSPC, "No space left on device")

    monkeypatch.setattr(output.os, "write", full)
    result = runner.invoke(app, ["build", "simplecar", "-o", str(target), "--force"])
    assert result.exit_code == 2
    assert one_line(result.stderr).endswith(f"{target}: cannot write: the disk is full")
    assert target.read_text() == "keep me"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["car.urdf"]


def test_a_real_full_disk(tmp_path: Path) -> None:
    mount = tmp_path / "small"
    mount.mkdir()
    done = subprocess.run(["mount", "-t", "tmpfs", "-o", "size=64k", "tmpfs", str(mount)],
                          capture_output=True)
    if done.returncode != 0:
        pytest.skip(f"cannot mount a tmpfs here: {done.stderr.decode().strip()}")
    try:
        with pytest.raises(OutputError, match="the disk is full"):
            atomic_write(mount / "big.bin", b"x" * 200_000)
        assert list(mount.iterdir()) == []
        result = runner.invoke(app, ["drive", "--seconds", "200", "--sample-every", "1",
                                     "--trajectory", str(mount / "run.csv")])
        assert result.exit_code == 2 and "the disk is full" in result.stderr
        assert "Traceback" not in result.stderr
        assert list(mount.iterdir()) == []
    finally:
        subprocess.run(["umount", str(mount)], capture_output=True)


def test_stale_temp_files_of_ours_are_cleaned(tmp_path: Path) -> None:
    stale = tmp_path / ".car.urdf.abcd1234.tmp"
    fresh = tmp_path / ".car.urdf.efgh5678.tmp"
    other = tmp_path / ".notes.txt.abcd1234.tmp"
    for p in (stale, fresh, other):
        p.write_text("partial")
    old = time.time() - 3600
    os.utime(stale, (old, old))
    os.utime(other, (old, old))
    atomic_write(tmp_path / "car.urdf", b"<robot/>")
    assert not stale.exists()
    assert fresh.exists()  # maybe another run's, still writing
    assert other.exists()  # not ours to judge


def test_streaming_keeps_complete_rows_on_interrupt_only(tmp_path: Path) -> None:
    path = tmp_path / "rows.jsonl"
    with pytest.raises(KeyboardInterrupt), StreamingFile(path, keep_on_interrupt=True) as out:
        out.write(b'{"a": 1}\n')
        raise KeyboardInterrupt
    assert path.read_bytes() == b'{"a": 1}\n'
    other = tmp_path / "other.jsonl"
    with pytest.raises(RuntimeError), StreamingFile(other, keep_on_interrupt=True) as out:
        out.write(b'{"a": 1}\n')
        raise RuntimeError("a bug")
    assert not other.exists()
    with pytest.raises(KeyboardInterrupt), StreamingFile(other) as out:  # atomic by default
        out.write(b"half")
        raise KeyboardInterrupt
    assert not other.exists()
    assert sorted(p.name for p in tmp_path.iterdir()) == ["rows.jsonl"]


def test_unwritable_folders_are_one_line(tmp_path: Path) -> None:
    result = runner.invoke(app, ["build", "simplecar", "-o", str(tmp_path / "no" / "car.urdf")])
    assert result.exit_code == 2 and "does not exist" in one_line(result.stderr)
    long = tmp_path / ("x" * 300 + ".urdf")
    result = runner.invoke(app, ["build", "simplecar", "-o", str(long)])
    assert result.exit_code == 2 and "too long" in one_line(result.stderr)
    if os.geteuid() != 0 and shutil.which("true"):
        ro = tmp_path / "ro"
        ro.mkdir()
        ro.chmod(0o555)
        result = runner.invoke(app, ["build", "simplecar", "-o", str(ro / "car.urdf")])
        assert result.exit_code == 2 and "permission denied" in one_line(result.stderr)


BROKEN_ARM = Path(__file__).parent / "fixtures" / "robots" / "broken_arm.urdf"


def _arm_package(tmp_path: Path) -> Path:
    """broken_arm.urdf (which fix changes) in a package, its mesh beside it."""
    pkg = tmp_path / "arm_description"
    (pkg / "meshes").mkdir(parents=True)
    (pkg / "urdf").mkdir()
    (pkg / "package.xml").write_text("<package><name>arm_description</name></package>")
    shutil.copy(Path(__file__).parent / "fixtures" / "meshes" / "unit_cube.stl",
                pkg / "meshes" / "unit_cube.stl")
    path = pkg / "urdf" / "arm.urdf"
    shutil.copy(BROKEN_ARM, path)
    return path


def test_a_replaced_file_keeps_its_mode_and_its_backup_too(tmp_path: Path) -> None:
    path = _arm_package(tmp_path)
    path.chmod(0o600)
    result = runner.invoke(app, ["fix", str(path), "--in-place", "--allow-mass-change"])
    assert result.exit_code in (0, 1), result.stderr
    assert path.read_bytes() != BROKEN_ARM.read_bytes()  # it was rewritten
    assert oct(path.stat().st_mode & 0o7777) == oct(0o600)
    backup = Path(f"{path}.orig")
    assert backup.read_bytes() == BROKEN_ARM.read_bytes()
    assert oct(backup.stat().st_mode & 0o7777) == oct(0o600)
    out = tmp_path / "out.urdf"
    out.write_text("old")
    out.chmod(0o751)
    result = runner.invoke(app, ["fix", str(path), "-o", str(out), "--force",
                                 "--allow-mass-change"])
    assert result.exit_code in (0, 1), result.stderr
    assert oct(out.stat().st_mode & 0o7777) == oct(0o751)
    # A new file gets open()'s mode under the umask, not mkstemp's 0600.
    umask = os.umask(0o022)
    try:
        atomic_write(tmp_path / "new.txt", b"x")
    finally:
        os.umask(umask)
    assert oct((tmp_path / "new.txt").stat().st_mode & 0o777) == oct(0o644)


@pytest.mark.skipif(os.geteuid() != 0, reason="changing a file's owner needs root")
def test_a_replaced_file_keeps_its_owner(tmp_path: Path) -> None:
    path = _arm_package(tmp_path)
    os.chown(path, 4321, 4322)
    path.chmod(0o755)
    result = runner.invoke(app, ["fix", str(path), "--in-place", "--allow-mass-change"])
    assert result.exit_code in (0, 1), result.stderr
    st = path.stat()
    assert (st.st_uid, st.st_gid, st.st_mode & 0o7777) == (4321, 4322, 0o755)
    st = Path(f"{path}.orig").stat()
    assert (st.st_uid, st.st_gid, st.st_mode & 0o7777) == (4321, 4322, 0o755)


def test_fix_in_place_on_a_symlink_fixes_the_target(tmp_path: Path) -> None:
    target = _arm_package(tmp_path)
    link = target.parent / "linked.urdf"
    link.symlink_to(target.name)
    result = runner.invoke(app, ["fix", str(link), "--in-place", "--allow-mass-change"])
    assert result.exit_code in (0, 1), result.stderr
    assert link.is_symlink() and os.readlink(link) == target.name
    assert target.read_bytes() != BROKEN_ARM.read_bytes()
    assert Path(f"{link}.orig").read_bytes() == BROKEN_ARM.read_bytes()
    # No temp file of ours is left beside the link or the target.
    assert not [p for p in target.parent.iterdir() if p.name.endswith(".tmp")]
