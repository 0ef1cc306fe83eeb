"""simulation_and_control parity (issue 25): configs as users have them run, with warnings for
what SimInterface never reads or would stop on, and the same run as the complete config."""

from __future__ import annotations

import copy
import json
import shutil
from pathlib import Path

import pytest
from typer.testing import CliRunner

from urdfkit import sac
from urdfkit.cli import app
from urdfkit.sim import Simulation

FIXTURES = Path(__file__).parent / "fixtures" / "sac"
README_KEYS = FIXTURES / "configs" / "readme_keys.json"
#: Keys the README example carries that SimInterface's code never reads.
UNREAD = ["robot_pybullet.ros_urdf_path", "robot_pybullet.motor_friction",
          "robot_pybullet.motor_friction_coeff", "robot_pin.ros_urdf_path",
          "robot_pin.floating_base_name"]
#: Keys SimInterface indexes that the README example lacks, with the value meaning "off".
MISSING = {"motor_damping": [0], "motor_damping_coeff": [0.0], "motor_elastic_torque": [0],
           "motor_elastic_coeff": [0.0], "motor_inertia": [0], "motor_inertia_coeff": [0.0],
           "noise_flag": [0], "robot_noise": [{}], "delay_measure_flag": [0]}


def _setup(tmp_path: Path) -> Path:
    shutil.copytree(FIXTURES / "models", tmp_path / "models")
    (tmp_path / "configs").mkdir()
    target = tmp_path / "configs" / README_KEYS.name
    shutil.copy(README_KEYS, target)
    return target


def test_the_readme_example_keys_run_with_warnings_only(tmp_path: Path) -> None:
    config = _setup(tmp_path)
    result = CliRunner().invoke(app, ["sim", str(config), "-o", str(tmp_path / "rows.csv")])
    assert result.exit_code == 0, result.stderr
    warnings = [ln for ln in result.stderr.splitlines() if ln.startswith("urdfkit: warning:")]
    assert not [ln for ln in result.stderr.splitlines()
                if ln.strip() and not ln.startswith(("urdfkit: warning:", "wrote "))]
    for key in UNREAD:
        assert any(f"warning: {key}: not a key SimInterface reads" in w for w in warnings), key
    for key in MISSING:
        assert any(f"warning: robot_pybullet.{key}: missing; SimInterface stops with a "
                   "KeyError" in w for w in warnings), key


def test_unread_keys_change_nothing_and_missing_keys_run_as_off(tmp_path: Path) -> None:
    config = _setup(tmp_path)
    as_given = json.loads(config.read_text())
    complete = copy.deepcopy(as_given)
    for key in UNREAD:
        section, name = key.split(".")
        del complete[section][name]
    complete["robot_pybullet"].update(MISSING)
    complete_path = config.with_name("complete.json")
    complete_path.write_text(json.dumps(complete))
    quiet = sac.convert(complete, source=complete_path).notes
    assert not [n for n in quiet if "not a key" in n or "missing;" in n]

    def run(path: Path) -> list[list[float]]:
        sim = Simulation.from_file(path)
        try:
            out = []
            for _ in range(300):
                sim.step()
                o = sim.observe(sim.robot_names()[0])
                out.append([*o.motor_angles.values(), *o.motor_velocities.values()])
            return out
        finally:
            sim.close()

    a, b = run(config), run(complete_path)
    assert a == b  # bit for bit
    assert a[-1] != a[0]  # not vacuous: the arm moved under its servo and gravity


@pytest.mark.parametrize("where", ["robot_pybullet", "sim", "top"])
def test_an_unknown_key_is_a_warning_never_a_refusal(tmp_path: Path, where: str) -> None:
    config = _setup(tmp_path)
    conf = json.loads(config.read_text())
    (conf if where == "top" else conf[where])["made_up_key"] = 1
    notes = sac.convert(conf, source=config).notes
    name = "made_up_key" if where == "top" else f"{where}.made_up_key"
    assert any(n.startswith(f"{name}: not a") and "no effect" in n for n in notes)
