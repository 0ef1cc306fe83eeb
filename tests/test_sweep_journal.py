"""The sweep journal and rows under fault (issue 26, class 6; issue 27.14): a last row cut
short runs again, a damaged row elsewhere is refused with its line, a dangling --out link is
never replaced, a second sweep on the same output is refused while the first writes, and a
full disk is one line."""

from __future__ import annotations

import csv
import json
import subprocess
import sys
import time
from pathlib import Path

import pytest
from typer.testing import CliRunner

from urdfkit import sweep
from urdfkit.cli import app
from urdfkit.core.errors import InputError, OutputError

VARY = ["--vary", "steer=0.1,0.2", "--seconds", "0.2", "--jobs", "1"]


def _cli(*args: str) -> tuple[int, str, str]:
    result = CliRunner().invoke(app, list(args))
    return result.exit_code, result.stdout, result.stderr


def _finished(tmp_path: Path, suffix: str) -> Path:
    out = tmp_path / f"rows{suffix}"
    code, _, err = _cli("sweep", "drive", *VARY, "--out", str(out))
    assert code == 0, err
    return out


def test_a_finished_csv_cut_in_its_last_row_resumes_that_point(tmp_path: Path) -> None:
    out = _finished(tmp_path, ".csv")
    whole = out.read_text()
    out.write_text(whole[: whole.rindex("\n", 0, len(whole) - 1) + 10])  # row 2 cut short
    notes: list[str] = []
    rows = sweep.read_rows(out, notes=notes)
    assert [r["point"] for r in rows] == [0] and "cut short" in notes[0]
    code, stdout, err = _cli("sweep", "drive", *VARY, "--out", str(out), "--resume")
    assert code == 0, err
    assert "1 point(s) ran" in stdout and "cut short" in err
    assert out.read_text() == whole  # the same rows as the uncut run: deterministic


def test_a_damaged_jsonl_row_in_the_middle_is_refused_with_its_line(tmp_path: Path) -> None:
    out = _finished(tmp_path, ".jsonl")
    lines = out.read_text().splitlines(keepends=True)
    out.write_text(lines[0][:20] + "\n" + "".join(lines[1:]))  # row 1 damaged, row 2 whole
    with pytest.raises(InputError, match="row 1 is not a JSON object") as e:
        sweep.read_rows(out)
    assert e.value.line == 1
    code, _, err = _cli("sweep", "drive", *VARY, "--out", str(out), "--resume")
    assert code == 2 and f"{out}:1:" in err and "damaged" in err


def test_a_csv_row_with_missing_values_is_damage(tmp_path: Path) -> None:
    out = _finished(tmp_path, ".csv")
    rows = list(csv.reader(out.read_text().splitlines()))
    out.write_text("\n".join(",".join(r[:3]) if k == 1 else ",".join(r)
                             for k, r in enumerate(rows)) + "\n")
    with pytest.raises(InputError, match="row 2 has 3 values"):
        sweep.read_rows(out)


def test_a_dangling_out_link_is_never_replaced(tmp_path: Path) -> None:
    out = tmp_path / "rows.csv"
    out.symlink_to(tmp_path / "nowhere" / "rows.csv")
    code, _, err = _cli("sweep", "drive", *VARY, "--out", str(out))
    assert code == 2 and "exists" in err
    assert out.is_symlink() and not (tmp_path / "rows.csv.partial").exists()


def test_a_second_sweep_on_the_same_output_is_refused_while_the_first_writes(
        tmp_path: Path) -> None:
    out = tmp_path / "rows.csv"
    first = subprocess.Popen(
        [sys.executable, "-m", "urdfkit", "sweep", "drive", "--vary", "steer=0.1,0.2,0.3",
         "--seconds", "4", "--jobs", "1", "--out", str(out)],
        stdout=subprocess.DEVNULL, stderr=subprocess.PIPE)
    try:
        partial = tmp_path / "rows.csv.partial"
        deadline = time.monotonic() + 60
        while not partial.exists() and time.monotonic() < deadline:
            time.sleep(0.05)
        assert partial.exists(), "the first sweep never started its journal"
        code, _, err = _cli("sweep", "drive", "--vary", "steer=0.1,0.2,0.3", "--seconds", "4",
                            "--jobs", "1", "--out", str(out), "--resume")
        assert code == 2 and "another sweep is writing this output now" in err
    finally:
        _, first_err = first.communicate(timeout=300)
    assert first.returncode == 0, first_err.decode()[-2000:]
    assert len(sweep.read_rows(out)) == 3  # the first sweep's rows, untouched


def test_a_full_disk_while_writing_rows_is_one_line(tmp_path: Path) -> None:
    journal = sweep.Journal(tmp_path / "rows.csv", ["steer"], assignments=[{"steer": 0.1}])
    journal.open()
    try:
        import os

        full = os.open("/dev/full", os.O_WRONLY)  # every write: ENOSPC
        os.close(journal._fd)  # type: ignore[arg-type]
        journal._fd = full
        with pytest.raises(OutputError) as e:
            journal.add({"point": 0, "steer": 0.1, "error": None})
        assert "rows.csv.partial" in str(e.value) and "\n" not in str(e.value)
        assert "the disk is full" in str(e.value) and "--resume" in str(e.value)
    finally:
        journal._unlock()


def test_the_journal_rows_are_json_even_for_odd_values(tmp_path: Path) -> None:
    journal = sweep.Journal(tmp_path / "rows.jsonl", ["steer"], assignments=[{"steer": 0.1}])
    journal.open()
    journal.add({"point": 0, "steer": 0.1, "end": float("nan"), "error": None})
    journal._unlock()
    row = json.loads((tmp_path / "rows.jsonl.partial").read_text())
    assert row["end"] is None and any("not finite" in n for n in journal.notes)
