"""Values no run can take, refused before anything runs; error lines bounded whatever they quote;
a million-point sweep planned in flat memory (issue 26, classes 5 to 7)."""

from __future__ import annotations

import itertools
import json
import shutil
import tracemalloc
from pathlib import Path

import pytest
from typer.testing import CliRunner

from urdfkit import sweep
from urdfkit.cli import app
from urdfkit.core.errors import ParameterError
from urdfkit.model.spec import MAX_STEPS
from urdfkit.motion.drive import DriveConfig

runner = CliRunner()
EXAMPLES = Path(__file__).resolve().parents[1] / "examples"


def invoke(*args: str) -> tuple[int, str, str]:
    result = runner.invoke(app, list(args))
    return result.exit_code, result.stdout, result.stderr


def one_line(err: str) -> str:
    lines = [line for line in err.splitlines() if line.strip()]
    assert len(lines) == 1, err[:2000]
    assert lines[0].startswith("urdfkit: error: ") and "Traceback" not in err
    return lines[0]


# --------------------------------------------------------------------------- steps


@pytest.mark.parametrize("args", [
    ("--seconds", "1e308"),                      # 1e308 / (1/240) overflows to inf steps
    ("--time-step", "1e-300", "--seconds", "1"),  # 1e300 steps: would run until memory is gone
    ("--steps", "1000000000000"),
])
def test_drive_refuses_a_run_past_the_step_limit_before_it_starts(
        args: tuple[str, ...]) -> None:
    code, out, err = invoke("drive", *args)
    line = one_line(err)
    assert code == 2 and out == ""
    assert f"{MAX_STEPS:,}" in line and "steps" in line


def test_the_step_limit_is_the_product_of_time_and_rate() -> None:
    # Exactly at the limit is allowed (the check is <=), one step past it is not.
    DriveConfig(seconds=MAX_STEPS * 0.01, time_step=0.01).check()
    with pytest.raises(ParameterError, match="at most"):
        DriveConfig(seconds=(MAX_STEPS + 1) * 0.01, time_step=0.01).check()


def _scenario(tmp_path: Path, **changes: object) -> Path:
    document = json.loads((EXAMPLES / "pendulum_servo.json").read_text())
    shutil.copy(EXAMPLES / "pendulum.urdf", tmp_path / "pendulum.urdf")
    for key, value in changes.items():
        if key == "time_step":
            document.setdefault("physics", {})["time_step"] = value
        elif key == "urdf":
            document["robots"][0]["urdf"] = value
        else:
            document[key] = value
    path = tmp_path / "s.json"
    path.write_text(json.dumps(document))
    return path


@pytest.mark.parametrize("changes", [{"duration": 1e308},
                                     {"duration": 1.0, "time_step": 1e-300}])
def test_sim_refuses_a_run_past_the_step_limit(tmp_path: Path,
                                               changes: dict[str, float]) -> None:
    code, _, err = invoke("sim", str(_scenario(tmp_path, **changes)), "-o",
                          str(tmp_path / "rows.csv"))
    line = one_line(err)
    assert code == 2 and "s.json: duration:" in line and f"{MAX_STEPS:,}" in line
    assert not (tmp_path / "rows.csv").exists()


def test_sweep_refuses_a_value_no_point_can_run_before_any_point_runs(tmp_path: Path) -> None:
    out = tmp_path / "rows.csv"
    code, _, err = invoke("sweep", "drive", "--vary", "seconds=0.01,1e308", "-o", str(out))
    line = one_line(err)
    assert code == 2 and "point 1 (seconds=1e+308)" in line and f"{MAX_STEPS:,}" in line
    assert not out.exists() and not Path(str(out) + ".partial").exists()


def test_a_combination_that_only_fails_together_becomes_that_points_failed_row() -> None:
    # seconds 1e6 with time_step 0.01 is 1e8 steps (allowed), and 0.01 s at 1e-4 is 100;
    # only 1e6 s at 1e-4 s (1e10 steps) is too many. Planning tries each value once, so it
    # passes; running that point (the only one not skipped here) gives its error as a row.
    plan = sweep.plan("drive", {}, ["seconds=0.01,1e6,0.02", "time_step=0.01,1e-4"])
    bad = {"seconds": 1e6, "time_step": 1e-4}
    rows = list(sweep.execute(plan, jobs=1, skip=lambda values: values != bad))
    assert len(rows) == 1 and rows[0]["point"] == 3
    assert rows[0]["seconds"] == 1e6 and "at most" in rows[0]["error"]


# --------------------------------------------------------------------------- big sweeps


def test_points_are_the_grid_itertools_product_gives() -> None:
    vary = [sweep.Vary("a", (1, 2, 3)), sweep.Vary("b", ("x", "y")), sweep.Vary("c", (0.5,)),
            sweep.Vary("d", (7, 8, 9, 10))]
    grid = sweep.points(vary)
    expected = [dict(zip("abcd", combo, strict=True))
                for combo in itertools.product(*(v.values for v in vary))]
    assert len(grid) == len(expected) == 24
    assert list(grid) == expected
    assert grid[-1] == expected[-1] and grid[5:9] == expected[5:9]
    # The probes try every value of every name at least once.
    tried = [grid[i] for i in grid.probes()]
    for v in vary:
        assert {p[v.name] for p in tried} == set(v.values)
    assert len(grid.probes()) <= sum(len(v.values) for v in vary) + 2


def test_a_million_point_grid_plans_in_flat_memory() -> None:
    tracemalloc.start()
    try:
        plan = sweep.plan("drive", {"seconds": 0.01},
                          ["throttle=0:10:1000", "steer=-0.5:0.5:1000"])
        first = plan.jobs[0][1]
        last_values = plan.assignments[len(plan.assignments) - 1]
        _, peak = tracemalloc.get_traced_memory()
    finally:
        tracemalloc.stop()
    assert len(plan.assignments) == 1_000_000
    assert first["throttle"] == 0 and first["steer"] == -0.5
    assert last_values == {"throttle": 10.0, "steer": 0.5}
    # A list of a million point dicts alone takes over 200 MB; planning holds ~2,000 checks.
    assert peak < 20_000_000, peak


# --------------------------------------------------------------------------- bounded lines


def test_an_error_quoting_a_huge_value_stays_short_and_says_its_length() -> None:
    code, _, err = invoke("drive", "--steer", "x" * 10_000)
    line = one_line(err)
    assert code == 2 and len(line) < 600 and "(10,002 characters)" in line


def test_a_huge_path_is_cut_in_every_error_line(tmp_path: Path) -> None:
    name = "a/" * 2500 + "x.urdf"
    code, _, err = invoke("joints", name)
    line = one_line(err)
    assert code == 2 and len(line) < 600 and "longer than the file system allows" in line
    code, _, err = invoke("sim", str(_scenario(tmp_path, urdf=name)))
    line = one_line(err)
    assert code == 2 and len(line) < 600 and "robots[0].urdf" in line


def test_a_config_nested_100000_deep_is_refused_in_one_line(tmp_path: Path) -> None:
    deep = tmp_path / "deep.json"
    deep.write_text('{"a": ' + "[" * 100_000 + "]" * 100_000 + "}")
    code, _, err = invoke("sim", str(deep))
    assert code == 2 and "nested deeper" in one_line(err)


def test_a_20_mb_string_in_a_config_comes_back_short(tmp_path: Path) -> None:
    path = _scenario(tmp_path)
    document = json.loads(path.read_text())
    document["robots"][0]["urdf"] = "n" * 20_000_000 + ".urdf"
    path.write_text(json.dumps(document))
    code, _, err = invoke("sim", str(path))
    line = one_line(err)
    assert code == 2 and len(line) < 1000 and "(20,000,005 characters)" in line


# --------------------------------------------------------------------------- fuzz finds


NAN_ARM = """<?xml version="1.0"?>
<robot name="r">
  <link name="base"><inertial><mass value="1"/>
    <inertia ixx="0.01" iyy="0.01" izz="0.01" ixy="0" ixz="0" iyz="0"/></inertial></link>
  <link name="tip"><inertial><mass value="1"/>
    <inertia ixx="0.01" iyy="nan" izz="0.01" ixy="0" ixz="0" iyz="0"/></inertial>
    <collision><geometry><cylinder radius="0.05" length="{length}"/></geometry></collision>
  </link>
  <joint name="j" type="revolute"><parent link="base"/><child link="tip"/>
    <axis xyz="0 1 0"/><limit lower="-1" upper="1" effort="1" velocity="1"/></joint>
</robot>
"""


@pytest.mark.parametrize("suffix", [".csv", ".jsonl"])
def test_a_sweep_whose_simulation_blows_up_writes_null_not_exit_3(tmp_path: Path,
                                                                  suffix: str) -> None:
    (tmp_path / "r.urdf").write_text(NAN_ARM.format(length="0.1"))
    scenario = tmp_path / "s.json"
    scenario.write_text(json.dumps({"duration": 0.05, "robots": [
        {"name": "r", "urdf": "r.urdf", "base": "fixed"}]}))
    out = tmp_path / f"rows{suffix}"
    code, _, err = invoke("sweep", "sim", str(scenario), "--vary", "duration=0.02,0.04",
                          "--jobs", "1", "-o", str(out))
    assert code == 0, err
    assert "not finite" in err and "written as null" in err
    rows = sweep.read_rows(out)
    assert len(rows) == 2 and any(v is None or v == "" for v in rows[0].values())


def test_a_subnormal_cylinder_is_checked_and_fixed_without_a_bug(tmp_path: Path) -> None:
    robot = tmp_path / "r.urdf"
    robot.write_text(NAN_ARM.format(length="1e-320").replace('iyy="nan"', 'iyy="0.01"'))
    for args in (["check", str(robot)], ["fix", str(robot), "--diff"]):
        code, _, err = invoke(*args)
        assert code in (0, 1), err
        assert "internal error" not in err


RING = """<?xml version="1.0"?>
<robot name="r">
  <link name="a"/><link name="b"/><link name="c"/><link name="d"/>
  <joint name="j1" type="revolute"><parent link="a"/><child link="b"/><axis xyz="0 0 1"/>
    <limit lower="-1" upper="1" effort="1" velocity="1"/><mimic joint="j2"/></joint>
  <joint name="j2" type="revolute"><parent link="b"/><child link="c"/><axis xyz="0 0 1"/>
    <limit lower="-1" upper="1" effort="1" velocity="1"/><mimic joint="{lead}"/></joint>
  <joint name="j3" type="revolute"><parent link="c"/><child link="d"/><axis xyz="0 0 1"/>
    <limit lower="-1" upper="1" effort="1" velocity="1"/></joint>
</robot>
"""


def test_check_flags_a_ring_of_mimic_joints_once_and_a_chain_not_at_all(tmp_path: Path) -> None:
    from urdfkit.checks.check import check_paths

    ring, chain = tmp_path / "ring.urdf", tmp_path / "chain.urdf"
    ring.write_text(RING.format(lead="j1"))
    chain.write_text(RING.format(lead="j3"))  # j1 -> j2 -> j3: a chain with a leader
    found = check_paths([ring, chain], jobs=1, cache=False)
    by_file = {Path(fr.file).name: [f for f in fr.findings if f.code == "U309"]
               for fr in found.files}
    assert len(by_file["ring.urdf"]) == 1 and by_file["chain.urdf"] == []
    f = by_file["ring.urdf"][0]
    assert f.level == "error" and "'j1' -> 'j2' -> 'j1'" in f.message and f.line == 5
    # collisions refuses the same file, and agrees with check on the chain
    code, _, err = invoke("collisions", str(ring))
    assert code == 2 and "ring" in err
    code, _, err = invoke("collisions", str(chain), "--samples", "2")
    assert code in (0, 1), err


def test_drive_survives_an_infinite_wheel(tmp_path: Path, simplecar_urdf: Path) -> None:
    # A cylinder of radius 1e309 (infinite) once made wheel detection take int(NaN): exit 3.
    import re

    text = simplecar_urdf.read_text()
    car = tmp_path / "car.urdf"
    car.write_text(re.sub(r'(<cylinder[^>]*radius=")[^"]+', r"\g<1>1e309", text))
    assert car.read_text() != text
    code, out, err = invoke("drive", "--urdf", str(car), "--steps", "24", "--json")
    assert code in (0, 1, 2), err
    assert "internal error" not in err
    if code == 0:
        json.loads(out)
