"""`urdfkit sim` as users call it: both examples, outputs, and errors with exit code 2."""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

import pytest
from typer.testing import CliRunner

from urdfkit.cli import app

EXAMPLES = Path(__file__).parent.parent / "examples"


@pytest.fixture
def runner() -> CliRunner:
    return CliRunner()


@pytest.mark.parametrize("name", ["two_cars.json", "two_cars.toml", "pendulum_servo.json"])
def test_examples_run_and_print_a_summary(runner: CliRunner, name: str) -> None:
    result = runner.invoke(app, ["sim", str(EXAMPLES / name)])
    assert result.exit_code == 0, result.output
    robots = ["pendulum"] if name.startswith("pendulum") else ["parked", "north"]
    for robot in robots:
        assert robot in result.stdout
    assert "720 steps" in result.stdout


def test_json_is_one_object_with_the_rows(runner: CliRunner) -> None:
    result = runner.invoke(app, ["sim", str(EXAMPLES / "two_cars.json"), "--json"])
    assert result.exit_code == 0, result.output
    data = json.loads(result.stdout)
    assert data["steps"] == 720 and data["rows"] == 122 == len(data["observations"])
    assert [r["robot"] for r in data["robots"]] == ["parked", "north"]
    north = [o for o in data["observations"] if o["robot"] == "north"]
    assert north[-1]["t"] == pytest.approx(3.0)
    assert data["out"] is None


def test_out_writes_rows_and_refuses_to_overwrite(runner: CliRunner, tmp_path: Path) -> None:
    out = tmp_path / "rows.jsonl"
    scenario = str(EXAMPLES / "pendulum_servo.json")
    result = runner.invoke(app, ["sim", scenario, "--out", str(out), "--json"])
    assert result.exit_code == 0, result.output
    data = json.loads(result.stdout)
    assert data["out"] == str(out) and "observations" not in data
    lines = out.read_text().splitlines()
    assert len(lines) == data["rows"] == 181
    assert json.loads(lines[-1])["robot"] == "pendulum"
    before = out.read_bytes()
    again = runner.invoke(app, ["sim", scenario, "--out", str(out)])
    assert again.exit_code == 2
    assert "exists; pass --force" in again.stderr
    assert out.read_bytes() == before
    forced = runner.invoke(app, ["sim", scenario, "--out", str(out), "--force"])
    assert forced.exit_code == 0, forced.output
    assert "wrote" in forced.stderr


def test_csv_out(runner: CliRunner, tmp_path: Path) -> None:
    out = tmp_path / "rows.csv"
    result = runner.invoke(app, ["sim", str(EXAMPLES / "pendulum_servo.json"), "-o", str(out)])
    assert result.exit_code == 0, result.output
    header = out.read_text().splitlines()[0].split(",")
    assert header[:4] == ["t", "step", "robot", "motor_angles.hinge"]
    assert "joint_forces.hinge.fz" in header


def test_bad_output_format_fails_before_the_run(runner: CliRunner, tmp_path: Path) -> None:
    result = runner.invoke(app, ["sim", str(EXAMPLES / "two_cars.json"), "-o",
                                 str(tmp_path / "rows.xlsx")])
    assert result.exit_code == 2
    assert "rows.xlsx: the rows file must end in .jsonl" in result.stderr


def test_validation_error_names_the_path_and_exits_2(runner: CliRunner, tmp_path: Path) -> None:
    doc = json.loads((EXAMPLES / "two_cars.json").read_text())
    doc["robots"][1]["drive"][0]["until"] = "soon"
    path = tmp_path / "bad.json"
    path.write_text(json.dumps(doc))
    result = runner.invoke(app, ["sim", str(path)])
    assert result.exit_code == 2
    assert result.stderr.strip() == (f"urdfkit: error: {path}: robots[1].drive[0].until: "
                                     "expected a number")
    assert result.stdout == ""


def test_missing_scenario(runner: CliRunner, tmp_path: Path) -> None:
    result = runner.invoke(app, ["sim", str(tmp_path / "nope.toml"), "--json"])
    assert result.exit_code == 2
    assert "nope.toml: no such file" in result.stderr
    assert result.stdout == ""


def test_sim_command_imports_pydantic_only_when_run(tmp_path: Path) -> None:
    probe = ("import json, sys\nfrom urdfkit.cli import app\n"
             "try:\n    app(sys.argv[1:], standalone_mode=False)\nexcept SystemExit:\n    pass\n"
             "sys.stderr.write('\\nMODULES:' + json.dumps(sorted(sys.modules)))")

    def modules(*args: str) -> set[str]:
        proc = subprocess.run([sys.executable, "-c", probe, *args], capture_output=True,
                              text=True, timeout=60)
        return set(json.loads(proc.stderr[proc.stderr.rindex("MODULES:") + 8:]))

    assert "pydantic" not in modules("sim", "--help")
    loaded = modules("sim", str(EXAMPLES / "pendulum_servo.json"), "--json")
    assert {"pydantic", "urdfkit.sim"} <= loaded
    assert loaded.isdisjoint({"yourdfpy", "trimesh", "matplotlib"})
