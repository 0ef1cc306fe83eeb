"""Human text rounds; JSON keeps exact values (issue 49, item 5).

`agree` printed "PyBullet 65.24999999999999 kg" and the masses in `info --json` are sums
such as 5.9999999999999964: float noise a reader cannot use. Every human printer of these
commands is run on robots whose masses sum to such values and must show no number of 13 or
more significant digits; the JSON keeps the exact values.
"""

from __future__ import annotations

import json
import re
from pathlib import Path

import pytest
from typer.testing import CliRunner

from urdfkit.cli import app

runner = CliRunner()
#: A decimal number with 13 or more significant digits.
NOISE = re.compile(r"(?<![\w.])-?(?=(?:\d\.?){13})\d+\.\d+")
#: Their masses sum to float noise: 65.24999999999999, 5.9999999999999964, 25.166999999999998.
ROBOTS = ["r2d2.urdf", "quadruped/minitaur.urdf", "laikago/laikago.urdf"]


@pytest.mark.parametrize("robot", ROBOTS)
def test_human_text_has_no_float_noise_and_json_keeps_it_exact(robot: str,
                                                               tmp_path: Path) -> None:
    xml = tmp_path / "robot.xml"
    assert runner.invoke(app, ["export", "mjcf", robot, "-o", str(xml)]).exit_code == 0
    for args in (["info", robot], ["joints", robot, "--all"], ["links", robot, "--all"],
                 ["tree", robot], ["collisions", robot],
                 ["agree", robot, str(xml), "--poses", "3", "--all"]):
        result = runner.invoke(app, args)
        assert result.exit_code in (0, 1), (args, result.stderr)
        assert not NOISE.findall(result.stdout + result.stderr), (args, result.stdout)
    # JSON: the exact values, not rounded.
    info = json.loads(runner.invoke(app, ["info", robot, "--json"]).stdout)
    assert info["total_mass"] == {"r2d2.urdf": 65.24999999999999,
                                  "quadruped/minitaur.urdf": 5.9999999999999964,
                                  "laikago/laikago.urdf": 25.166999999999998}[robot]


def test_agree_says_the_masses_as_a_reader_reads_them(tmp_path: Path) -> None:
    xml = tmp_path / "r2d2.xml"
    assert runner.invoke(app, ["export", "mjcf", "r2d2.urdf", "-o", str(xml)]).exit_code == 0
    out = runner.invoke(app, ["agree", "r2d2.urdf", str(xml), "--poses", "3"]).stdout
    assert "PyBullet 65.25 kg, MuJoCo 65.25 kg" in out
    data = json.loads(runner.invoke(app, ["agree", "r2d2.urdf", str(xml), "--poses", "3",
                                          "--json"]).stdout)
    total = next(r for r in data["rows"] if r["check"] == "total mass")
    assert "PyBullet 65.24999999999999 kg" in total["detail"]  # the exact value, in JSON
