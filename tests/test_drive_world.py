"""A `world` root (issue 41, item 5): PyBullet gives a link named `world` without <inertial>
mass 0, so a robot built with its world frame is a static base; drive says so and why."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

from urdfkit.motion.drive import DriveConfig, drive

MIR = Path(__file__).parent / "fixtures" / "robots" / "mir_like.urdf"


def _world_rooted(tmp_path: Path) -> Path:
    text = MIR.read_text()
    assert text.count('<link name="base_footprint" />') == 1
    text = text.replace('<link name="base_footprint" />', '<link name="world" />')
    text = text.replace('<parent link="base_footprint" />', '<parent link="world" />')
    out = tmp_path / "world_mir.urdf"
    out.write_text(text)
    return out


def test_a_world_root_is_the_static_base_pybullet_makes_it(tmp_path: Path) -> None:
    urdf = _world_rooted(tmp_path)
    # Raw PyBullet: mass 0, and the base stays 1 m up under gravity.
    raw = ("import pybullet as p\np.connect(p.DIRECT)\np.setGravity(0, 0, -10)\n"
           f"b = p.loadURDF({str(urdf)!r}, [0, 0, 1])\n"
           "[p.stepSimulation() for _ in range(240)]\n"
           "print('END', p.getDynamicsInfo(b, -1)[0], p.getBasePositionAndOrientation(b)[0][2])\n")
    out = subprocess.run([sys.executable, "-c", raw], capture_output=True, text=True,
                         timeout=120).stdout.split("END")[-1].split()
    assert float(out[0]) == 0.0 and float(out[1]) == 1.0
    r = drive(DriveConfig(urdf=str(urdf), seconds=1.0, keep_trajectory=False))
    assert [p for p in r.problems if p.startswith("static base: the root link is named `world`")]
    assert abs(r.final_position[0]) < 1e-6  # it did not move


def test_the_same_robot_without_the_world_root_is_not_static() -> None:
    r = drive(DriveConfig(urdf=str(MIR), seconds=1.0, keep_trajectory=False))
    assert not [p for p in r.problems if p.startswith("static base")]
    assert r.final_position[0] > 0.3
