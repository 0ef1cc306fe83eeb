"""`urdfkit agree` on joint limits as large as a double holds (issue 48: +-1e308 overflowed
the pose sampler and the swing start, exit 3): poses are drawn from a bounded part of each
range, which is all of any real range, and every row stays a real comparison."""

from __future__ import annotations

import json
import math
from pathlib import Path

import pytest
from typer.testing import CliRunner

from urdfkit.cli import app
from urdfkit.exchange.agree_poses import pybullet_frame_tolerances, sample_range

mujoco = pytest.importorskip("mujoco")  # in the test extra: CI never skips it
runner = CliRunner()
HUGE = Path(__file__).parent / "fixtures" / "robots" / "huge_limits.urdf"
BIG = 1.7976931348623157e308


class _Joint:
    def __init__(self, kind: str, lower: float, upper: float) -> None:
        self.type, self.lower, self.upper = kind, lower, upper


@pytest.mark.parametrize(("kind", "lower", "upper", "expected"), [
    # real ranges are sampled whole, to the bit: UR's +-2 pi, go2's calf, a gripper finger
    ("revolute", -2 * math.pi, 2 * math.pi, (-2 * math.pi, 2 * math.pi)),
    ("revolute", -2.72, -0.84, (-2.72, -0.84)),
    ("prismatic", 0.0, 0.0115, (0.0, 0.0115)),
    # a double's reach: a turn or a metre from the point of the range nearest zero
    ("revolute", -1e308, 1e308, (-2 * math.pi, 2 * math.pi)),
    ("revolute", -BIG, 0.5, (-2 * math.pi, 0.5)),
    ("prismatic", 0.0, BIG, (0.0, 1.0)),
    ("revolute", 100.0, 1e308, (100.0, 100.0 + 2 * math.pi)),
    ("prismatic", -BIG, -5.0, (-6.0, -5.0)),
])
def test_the_sampled_part_of_a_range(kind: str, lower: float, upper: float,
                                     expected: tuple[float, float]) -> None:
    assert sample_range(_Joint(kind, lower, upper)) == expected


def test_agree_on_limits_of_1e308_compares_every_row(tmp_path: Path) -> None:
    out = tmp_path / "huge.xml"
    r = runner.invoke(app, ["export", "mjcf", str(HUGE), "-o", str(out)])
    assert r.exit_code == 0, r.output
    assert 'range="-1e+308 1e+308"' in out.read_text()  # written as the file says
    r = runner.invoke(app, ["agree", str(HUGE), str(out), "--json"])
    assert r.exit_code == 0, r.output  # exit 3 (OverflowError) before
    rows = {row["check"]: row for row in json.loads(r.stdout)["rows"]}
    assert [row for row in rows.values() if row["status"] == "fail"] == []
    # the frames were compared with a tolerance of the sampled reach, not of 1e308
    frames = rows["frames vs PyBullet: position"]
    assert frames["tolerance"] < 1e-5 and "(4 frames x 100 poses)" in frames["detail"]
    assert rows["joint limits"]["value"] == 0.0
    swing = next(row for check, row in rows.items() if check.startswith("free swing"))
    assert swing["status"] == "pass" and swing["check"].startswith("free swing 1 s")


def test_the_frame_tolerances_stay_float32_sized() -> None:
    from urdfkit.formats.robot import read_robot
    from urdfkit.model.xmlio import load_xml

    robot = read_robot(load_xml(HUGE).getroot(), str(HUGE))
    tolerances = pybullet_frame_tolerances(robot)
    assert max(tolerances.values()) == pytest.approx(2.0 ** -22 * (3 + 4 * math.pi + 1))


def _agree_in_a_process(tmp_path: Path, edit: tuple[str, str]) -> tuple[int, list[str]]:
    """Export the huge-limits robot, edit the MJCF, run agree as a user: code, stderr lines
    (MuJoCo's C code prints on the process's own stderr, which CliRunner does not see)."""
    import subprocess
    import sys

    out = tmp_path / "model.xml"
    r = runner.invoke(app, ["export", "mjcf", str(HUGE), "-o", str(out)])
    assert r.exit_code == 0, r.output
    text = out.read_text()
    assert edit[0] in text
    out.write_text(text.replace(edit[0], edit[1], 1))
    r2 = subprocess.run([sys.executable, "-m", "urdfkit", "agree", str(HUGE), str(out),
                         "--poses", "2"], capture_output=True, text=True, timeout=120)
    return r2.returncode, [ln for ln in r2.stderr.splitlines() if ln.strip()]


def test_a_nan_mujoco_refuses_is_one_line(tmp_path: Path) -> None:
    code, lines = _agree_in_a_process(tmp_path, ('ctrlrange="-1 1"',
                                                 'ctrlrange="NaN inf 0"'))
    assert code == 2
    # MuJoCo's parser also said "WARNING: XML contains a 'NaN'" and a blank line on stderr
    assert len(lines) == 1 and "model.xml: MuJoCo cannot load it: " in lines[0], lines


def test_a_diverging_model_fails_its_rows_and_prints_only_urdfkits_lines(tmp_path: Path
                                                                        ) -> None:
    code, lines = _agree_in_a_process(tmp_path, ('<option integrator="implicitfast"/>',
                                                 '<option gravity="0 0 -1e300"/>'))
    assert code == 1
    # MuJoCo's "WARNING: Nan, Inf or huge value in QACC" and numpy's overflow warnings before
    assert lines and all(ln.startswith("urdfkit: warning: ") for ln in lines), lines
    assert any("MuJoCo: Nan, Inf or huge value in QACC" in ln for ln in lines), lines
