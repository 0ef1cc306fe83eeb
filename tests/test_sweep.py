"""``urdfkit sweep``: grids, zips, ranges, validation, resume, failures, determinism and both
backends; each row is checked against the single run it stands for."""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

import pytest
from typer.testing import CliRunner

from urdfkit.cli import app
from urdfkit.core.errors import InputError, MissingDependencyError, ParameterError
from urdfkit.motion import sweep_plan as sweep
from urdfkit.motion.drive import DriveConfig, drive
from urdfkit.sim import Simulation

EXAMPLES = Path(__file__).resolve().parent.parent / "examples"
#: Short drives: a sweep test is about the sweep, not about 10 s of driving.
BASE = {"seconds": 2.0, "throttle": 10.0}


def _cli(*args: str) -> tuple[int, str, str]:
    result = CliRunner().invoke(app, list(args))
    return result.exit_code, result.stdout, result.stderr


def _by_point(rows: list[dict[str, Any]]) -> list[dict[str, Any]]:
    return sorted(rows, key=lambda r: r["point"])


# ---- values, grids and zips


def test_values_ranges_and_types() -> None:
    assert sweep.parse_vary("steer=0.1,0.2,0.3").values == (0.1, 0.2, 0.3)
    assert sweep.parse_vary("wheel_radius=0.08:0.14:4").values == (0.08, 0.1, 0.12, 0.14)
    assert sweep.parse_vary("steps=100,200").values == (100, 200)
    assert sweep.parse_vary("drivetrain=locked,differential").values == ("locked",
                                                                          "differential")
    assert sweep.parse_vary("x=2:2:1").values == (2.0,)
    for bad in ("steer", "steer=", "=1", "steer=0:1", "steer=0:1:0", "steer=0:1:2.5",
                "steer=1,,2", "steer=a:b:3"):
        with pytest.raises(ParameterError):
            sweep.parse_vary(bad)


def test_grid_varies_the_first_name_slowest_and_zip_pairs() -> None:
    a, b = sweep.parse_vary("a=1,2"), sweep.parse_vary("b=x,y,z")
    assert list(sweep.points([a, b])) == [
        {"a": 1, "b": "x"}, {"a": 1, "b": "y"}, {"a": 1, "b": "z"},
        {"a": 2, "b": "x"}, {"a": 2, "b": "y"}, {"a": 2, "b": "z"}]
    c = sweep.parse_vary("c=3,4")
    assert list(sweep.points([a, c], zip_=True)) == [{"a": 1, "c": 3}, {"a": 2, "c": 4}]
    with pytest.raises(ParameterError, match="as many"):
        sweep.points([a, b], zip_=True)
    with pytest.raises(ParameterError, match="twice"):
        sweep.points([a, a])


def test_key_paths() -> None:
    assert sweep.parse_path("robots[0].motor.kp") == ["robots", 0, "motor", "kp"]
    assert sweep.parse_path("physics.time_step") == ["physics", "time_step"]
    doc: dict[str, Any] = {"robots": [{"name": "a"}]}
    sweep.set_path(doc, "robots[0].motor.kp", 50)  # a missing table is created
    assert doc["robots"][0]["motor"] == {"kp": 50}
    with pytest.raises(ParameterError, match="out of range"):
        sweep.set_path(doc, "robots[3].motor.kp", 1)
    with pytest.raises(ParameterError, match="not a list"):
        sweep.set_path(doc, "robots[0].name[1]", 1)
    for bad in ("[0].x", "robots..x", "robots[x]", "9lives"):
        with pytest.raises(ParameterError):
            sweep.parse_path(bad)


# ---- every point is checked before any runs


def test_bad_names_and_values_name_the_point() -> None:
    with pytest.raises(ParameterError, match="did you mean 'steer'"):
        sweep.plan("drive", BASE, ["stear=0.1"])
    with pytest.raises(ParameterError, match=r"point 1 \(wheel_radius=-0.1\)"):
        sweep.plan("drive", BASE, ["wheel_radius=0.1,-0.1"])
    with pytest.raises(ParameterError, match=r"point 2 \(time_step=0.5\)"):
        sweep.plan("drive", BASE, ["time_step=0.01,0.02,0.5"])
    with pytest.raises(ParameterError, match="built-in simplecar"):
        sweep.plan("drive", {**BASE, "urdf": "racecar/racecar.urdf"}, ["wheel_radius=0.1"])
    with pytest.raises(ParameterError, match="drive or sim"):
        sweep.plan("drivee", BASE, ["steer=1"])
    scenario = EXAMPLES / "pendulum_servo.json"
    with pytest.raises(InputError, match=r"point 0 .*physics"):
        sweep.plan("sim", scenario, ["physics.time_stepp=0.01"])
    with pytest.raises(InputError, match=r"point 1 \(robots\[0\]\.motor\.kp=-5\)"):
        sweep.plan("sim", scenario, ["robots[0].motor.kp=5,-5"])
    with pytest.raises(ParameterError, match="out of range"):
        sweep.plan("sim", scenario, ["robots[1].motor.kp=5"])


def test_nothing_runs_when_a_late_point_is_bad(tmp_path: Path) -> None:
    out = tmp_path / "rows.csv"
    code, _, err = _cli("sweep", "drive", "--vary", "steer=0.1,0.2", "--vary",
                        "wheel_radius=0.1,0", "--out", str(out))
    assert code == 2 and "point 1 (steer=0.1, wheel_radius=0)" in err
    assert list(tmp_path.iterdir()) == []  # not even a journal


# ---- each row is the single run it stands for


def test_drive_rows_equal_single_runs_number_for_number() -> None:
    rows = _by_point(list(sweep.run("drive", BASE, ["steer=0.1,0.3",
                                                    "wheel_radius=0.08,0.12"], jobs=1)))
    assert [(r["steer"], r["wheel_radius"]) for r in rows] == [
        (0.1, 0.08), (0.1, 0.12), (0.3, 0.08), (0.3, 0.12)]
    for r in rows:
        single = drive(DriveConfig(seconds=2.0, steer=r["steer"], keep_trajectory=False,
                                   template_params={"wheel_radius": str(r["wheel_radius"])}))
        d = single.to_dict()
        assert r["error"] is None
        assert [r["final_x"], r["final_y"], r["final_z"]] == d["final_position"]
        for key in ("distance", "heading_change", "turning_radius", "expected_radius",
                    "mean_speed", "yaw_rate", "steps"):
            assert r[key] == d[key], key


def test_cli_row_equals_urdfkit_drive_json() -> None:
    code, out, _ = _cli("sweep", "drive", "--seconds", "2", "--vary", "steer=0.25", "--json")
    row = json.loads(out)["rows"][0]
    code2, out2, _ = _cli("drive", "--seconds", "2", "--steer", "0.25", "--json")
    single = json.loads(out2)
    assert code == code2 == 0
    assert [row["final_x"], row["final_y"], row["final_z"]] == single["final_position"]
    assert row["turning_radius"] == single["turning_radius"] and row["distance"] == \
        single["distance"]


def test_two_workers_give_the_rows_of_one() -> None:
    vary = ["steer=0.05,0.15,0.25", "max_force=5,20"]
    one = _by_point(list(sweep.run("drive", BASE, vary, jobs=1)))
    two = _by_point(list(sweep.run("drive", BASE, vary, jobs=2)))
    assert one == two and len(one) == 6


def test_sim_rows_equal_single_scenario_runs() -> None:
    scenario = EXAMPLES / "pendulum_servo.json"
    rows = _by_point(list(sweep.run("sim", scenario, ["robots[0].motor.kp=100,400",
                                                      "duration=1.0"], jobs=2)))
    for r in rows:
        doc = json.loads(scenario.read_text())
        doc["robots"][0]["motor"]["kp"] = r["robots[0].motor.kp"]
        doc["duration"] = 1.0
        with Simulation(doc, base_dir=EXAMPLES) as s:
            result = s.run(keep=False)
        x = result.summaries[0]
        assert r["pendulum.joint.hinge"] == round(x.final_joints["hinge"], 6)
        assert r["pendulum.joint_max.hinge"] == round(x.joint_max["hinge"], 6)
        assert r["steps"] == result.steps == 240
    # With kd fixed at 8, kp 400 is underdamped: it overshoots the 0.5 rad target within the
    # second, where kp 100 has not reached it yet.
    soft, stiff = rows
    assert soft["pendulum.joint_max.hinge"] < 0.5 < stiff["pendulum.joint_max.hinge"]


# ---- failing points, files, resume, interruption


def test_a_failing_point_records_its_error_and_the_sweep_goes_on(tmp_path: Path) -> None:
    car = tmp_path / "car.urdf"
    code, _, _ = _cli("build", "simplecar", "-o", str(car))
    missing = tmp_path / "broken.urdf"  # there, but not a robot: fails when its point loads
    missing.write_text("<robot name='r'><link name='a'/><link name='b'/></robot>")
    rows = _by_point(list(sweep.run("drive", BASE, [f"urdf={car},{missing}"], jobs=1)))
    assert rows[0]["error"] is None and rows[0]["distance"] > 0
    assert "broken.urdf" in rows[1]["error"] and "distance" not in rows[1]
    # A file that is not there at all is bad input: refused before any point runs.
    with pytest.raises(InputError, match="gone.urdf: no such file"):
        sweep.plan("drive", BASE, [f"urdf={car},{tmp_path / 'gone.urdf'}"])
    out = tmp_path / "rows.jsonl"
    code, stdout, _ = _cli("sweep", "drive", "--seconds", "1", "--vary",
                           f"urdf={car},{missing}", "--out", str(out))
    assert code == 1 and "1 failed" in stdout
    lines = [json.loads(x) for x in out.read_text().splitlines()]
    assert sorted(bool(x["error"]) for x in lines) == [False, True]


@pytest.mark.parametrize("suffix", [".csv", ".jsonl", ".parquet"])
def test_rows_file_in_each_format(tmp_path: Path, suffix: str) -> None:
    if suffix == ".parquet":
        pytest.importorskip("pyarrow.parquet")  # the parquet extra
    out = tmp_path / f"rows{suffix}"
    code, _, err = _cli("sweep", "drive", "--seconds", "1", "--vary", "steer=0.1,0.2",
                        "--out", str(out), "-j", "1")
    assert code == 0, err
    rows = _by_point(sweep.read_rows(out))
    assert [r["steer"] for r in rows] == [0.1, 0.2] and rows[1]["distance"] > 0
    assert not out.with_name(out.name + ".partial").exists()
    code, _, err = _cli("sweep", "drive", "--seconds", "1", "--vary", "steer=0.1",
                        "--out", str(out))
    assert code == 2 and "exists" in err  # never overwritten without --force


def test_resume_runs_only_the_missing_and_failed_points(tmp_path: Path) -> None:
    out = tmp_path / "rows.csv"
    vary = ["steer=0.1,0.2,0.3", "seconds=1"]
    done = [r for r in sweep.run("drive", BASE, vary, jobs=1) if r["steer"] != 0.2]
    done[0]["error"] = "it broke"  # a failed point is run again
    partial = out.with_name("rows.csv.partial")
    partial.write_text("".join(json.dumps(r) + "\n" for r in done) + '{"point": 1, "ste')
    code, _, err = _cli("sweep", "drive", "--vary", vary[0], "--vary", vary[1], "--out",
                        str(out))
    assert code == 2 and "--resume" in err  # a journal is never overwritten silently
    code, stdout, _ = _cli("sweep", "drive", "--vary", vary[0], "--vary", vary[1], "--out",
                           str(out), "--resume")
    assert code == 0 and "2 point(s) ran" in stdout and "1 skipped" in stdout
    rows = sweep.read_rows(out)
    assert sorted((r["point"], r["steer"]) for r in rows) == [(0, 0.1), (1, 0.2), (2, 0.3)]
    assert not any(r["error"] for r in rows)  # the failed row was replaced, not kept beside
    code, stdout, _ = _cli("sweep", "drive", "--vary", vary[0], "--vary", vary[1], "--out",
                           str(out), "--resume")
    assert code == 0 and "0 point(s) ran" in stdout and "3 skipped" in stdout


def test_ctrl_c_keeps_the_rows_so_far(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    real = sweep.execute

    def interrupted(*args: Any, **kwargs: Any) -> Any:
        for k, row in enumerate(real(*args, **kwargs)):
            if k == 2:
                raise KeyboardInterrupt
            yield row

    monkeypatch.setattr(sweep, "execute", interrupted)
    out = tmp_path / "rows.jsonl"
    code, _, _ = _cli("sweep", "drive", "--seconds", "0.5", "--vary", "steer=0.1,0.2,0.3,0.4",
                      "--out", str(out), "-j", "1")
    assert code == 130
    assert [r["point"] for r in sweep.read_rows(out)] == [0, 1]


def test_plot_draws_the_metric(tmp_path: Path) -> None:
    picture = tmp_path / "radius.png"
    code, _, err = _cli("sweep", "drive", "--seconds", "4", "--vary", "steer=0.2,0.3",
                        "--vary", "drivetrain=differential,locked", "--plot", "turning_radius",
                        "--plot-file", str(picture))
    assert code == 0, err
    assert picture.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    code, _, err = _cli("sweep", "drive", "--seconds", "1", "--vary", "steer=0.2",
                        "--plot", "turning_radios", "--plot-file", str(tmp_path / "x.png"))
    assert code == 2 and "did you mean 'turning_radius'" in err
    assert not (tmp_path / "x.png").exists()


def test_usage_errors() -> None:
    for args, words in [(("drive",), "--vary"), (("sim",), "scenario file"),
                        (("sim", str(EXAMPLES / "pendulum_servo.json"), "--throttle", "3",
                          "--vary", "duration=1"), "drive options"),
                        (("drive", "--vary", "steer=1", "--resume"), "--out"),
                        (("drive", "--vary", "steer=1", "--backend", "dask"), "local or ray"),
                        (("drive", "--vary", "steer=1", "--address", "auto"), "ray")]:
        code, _, err = _cli("sweep", *args)
        assert code == 2 and words in err and "Traceback" not in err, (args, err)


# ---- Ray


def test_ray_backend_gives_the_local_rows() -> None:
    pytest.importorskip("ray")
    vary = ["steer=0.1,0.3", "seconds=1"]
    local = _by_point(list(sweep.run("drive", BASE, vary, jobs=1)))
    ray_rows = _by_point(list(sweep.run("drive", BASE, vary, backend="ray", jobs=2)))
    assert ray_rows == local


def test_ray_missing_is_an_install_hint(monkeypatch: pytest.MonkeyPatch) -> None:
    import builtins

    real = builtins.__import__

    def no_ray(name: str, *args: Any, **kwargs: Any) -> Any:
        if name == "ray":
            raise ImportError("no ray here")
        return real(name, *args, **kwargs)

    monkeypatch.setattr(builtins, "__import__", no_ray)
    with pytest.raises(MissingDependencyError, match=r"pip install 'urdfkit\[ray\]'"):
        list(sweep.run("drive", BASE, ["steer=0.1"], backend="ray"))


def test_ctrl_c_inside_a_drive_stops_the_sweep(tmp_path: Path,
                                                monkeypatch: pytest.MonkeyPatch) -> None:
    # drive() catches Ctrl-C itself and returns an interrupted result: the sweep must stop
    # there, not record half a drive and go on to the next point.
    import urdfkit.motion.drive as driving

    real, calls = driving.drive, []

    def drive_once_then_ctrl_c(config: DriveConfig, progress: Any = None) -> Any:
        result = real(config, progress)
        calls.append(config.steer)
        result.interrupted = len(calls) == 2
        return result

    monkeypatch.setattr(driving, "drive", drive_once_then_ctrl_c)
    out = tmp_path / "rows.jsonl"
    code, _, _ = _cli("sweep", "drive", "--steps", "10", "--vary", "steer=0.1,0.2,0.3",
                      "--out", str(out), "-j", "1")
    assert code == 130 and calls == [0.1, 0.2]
    assert [r["steer"] for r in sweep.read_rows(out)] == [0.1]


def test_resume_refuses_the_rows_of_another_sweep(tmp_path: Path) -> None:
    out = tmp_path / "rows.csv"
    assert _cli("sweep", "drive", "--steps", "5", "--vary", "steer=0.1,0.2", "--out",
                str(out))[0] == 0
    before = out.read_bytes()
    for other in (["--vary", "steer=0.1,0.3"], ["--vary", "throttle=1,2"],
                  ["--vary", "steer=0.1,0.2", "--vary", "throttle=1,2"]):
        code, _, err = _cli("sweep", "drive", "--steps", "5", *other, "--out", str(out),
                            "--resume")
        assert code == 2 and "another sweep" in err, (other, err)
        assert out.read_bytes() == before and not Path(f"{out}.partial").exists()


def test_a_value_given_twice_and_a_lone_plot_file_are_refused(tmp_path: Path) -> None:
    for args, words in [(("--steer", "0.3", "--vary", "steer=0.1"), "--steer and by --vary"),
                        (("--set", "wheel_radius=0.2", "--vary", "wheel_radius=0.1"),
                         "--set and by --vary"),
                        (("--vary", "steer=0.1", "--plot-file", "x.png"), "--plot METRIC")]:
        code, _, err = _cli("sweep", "drive", *args)
        assert code == 2 and words in err, (args, err)


def test_a_scenario_plot_metric_is_checked_before_the_run(tmp_path: Path) -> None:
    scenario = str(EXAMPLES / "pendulum_servo.json")
    out = tmp_path / "rows.csv"
    code, _, err = _cli("sweep", "sim", scenario, "--vary", "duration=0.2,0.3", "--plot",
                        "pendulm.distance", "--out", str(out))
    assert code == 2 and "did you mean 'pendulum.distance'" in err and not out.exists()
    # A joint's name is the robot file's: a typo there is known only after the run, which
    # keeps its rows, draws nothing and says why.
    picture = tmp_path / "p.png"
    code, _, err = _cli("sweep", "sim", scenario, "--vary", "duration=0.2,0.3", "--plot",
                        "pendulum.joint_max.hnge", "--plot-file", str(picture), "--out",
                        str(out))
    assert code == 1 and "did you mean 'pendulum.joint_max.hinge'" in err
    assert out.exists() and not picture.exists()
