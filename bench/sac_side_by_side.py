"""urdfkit's simulation_and_control import, run side by side with the real SimInterface.

Standalone, and not in CI (simulation_and_control is not on PyPI, and CI reaches no git host):

    pip install pin                      # pinocchio, which SimInterface imports
    python bench/sac_side_by_side.py --sac /path/to/simulation_and_control-checkout

For a two-joint arm plain (no offsets, directions 1, no delay, no motor terms) and with
everything on (offsets, directions -1 and 1, a 3-step measurement delay, motor damping and
spring through the mass matrix), and a 12-motor quadruped on a floating base standing on the
ground (damping through the mass matrix, a 3-step delay, noise off), under three commands
(free: zero torque; the servo at a position target; a constant torque), it steps both for
``--steps`` steps and compares, at every step, what each reports: motor angles, velocities
and torques (``GetMotorAngles``, ``GetMotorVelocities``, ``GetMotorTorques`` against urdfkit's
``observe`` and ``motor_torques``) and the base position. It prints, per case, the largest
difference of each and how many steps agree bit for bit; exit 1 if any differs by more than
``--tolerance``. (A one-joint robot cannot be run: SimInterface's ``ComputeMassMatrix`` hands
``calculateMassMatrix`` a 0-d array for it, ``q.squeeze()`` of one angle, which PyBullet
refuses; urdfkit's own tests cover the pendulum against SimInterface's semantics.)
"""

from __future__ import annotations

import argparse
import contextlib
import io
import json
import shutil
import sys
import tempfile
from pathlib import Path

import numpy as np

FIXTURES = Path(__file__).resolve().parent.parent / "tests" / "fixtures" / "sac"


def configs(folder: Path) -> dict[str, Path]:
    """The two robots' configs, written into ``folder/configs`` beside ``folder/models``."""
    shutil.copytree(FIXTURES / "models", folder / "models")
    (folder / "configs").mkdir()
    plain = json.loads((FIXTURES / "configs" / "pendulum.json").read_text())
    plain["robot_pybullet"].update({
        "urdf_path": ["arm2.urdf"], "init_link_base_position": [[0.0, 0.0, 0.0]],
        "init_motor_angles": [[0.4, -0.7]], "init_motor_vel": [[0.0, 0.0]],
        "servo_pos_gains": [60.0], "servo_vel_gains": [4.0], "motor_damping": [0],
        "motor_damping_coeff": [0.0]})
    plain["robot_pin"]["urdf_path"] = ["arm2.urdf"]
    arm = json.loads((FIXTURES / "configs" / "pendulum.json").read_text())
    arm["robot_pybullet"].update({
        "urdf_path": ["arm2.urdf"], "init_link_base_position": [[0.0, 0.0, 0.0]],
        "init_motor_angles": [[0.4, -0.7]], "init_motor_vel": [[0.0, 0.0]],
        "motor_offset": [[0.2, -0.1]], "motor_direction": [[-1, 1]],
        "servo_pos_gains": [60.0], "servo_vel_gains": [4.0],
        "motor_damping": [1], "motor_damping_coeff": [0.8],
        "motor_elastic_torque": [1], "motor_elastic_coeff": [2.0],
        "delay_measure_flag": [1], "delay_measure_steps": [3]})
    arm["robot_pin"]["urdf_path"] = ["arm2.urdf"]
    quadruped = json.loads((FIXTURES / "configs" / "quadruped.json").read_text())
    quadruped["robot_pybullet"]["noise_flag"] = [0]  # two random generators never agree
    out = {}
    for name, conf in (("arm", plain), ("arm_full", arm), ("quadruped", quadruped)):
        path = folder / "configs" / f"{name}.json"
        path.write_text(json.dumps(conf))
        out[name] = path
    return out


def run_siminterface(sac_root: Path, config: Path, mode: str, value: list[float],
                     steps: int) -> list[np.ndarray]:
    """Per step: angles, velocities, torques, base position, from the real SimInterface."""
    sys.path.insert(0, str(sac_root))
    from simulation_and_control import MotorCommands
    from simulation_and_control.sim import pybullet_robot_interface as pb

    with contextlib.redirect_stdout(io.StringIO()):
        sim = pb.SimInterface(config.name, conf_file_path_ext=str(config.parent.parent),
                              use_gui=False)
    n = len(value)
    if mode == "position":
        cmd = MotorCommands(np.array([[v, 0.0] for v in value]), ["position"] * n)
    else:
        cmd = MotorCommands(np.array(value, dtype=float), ["torque"] * n)
    rows = []
    with contextlib.redirect_stdout(io.StringIO()):
        for _ in range(steps):
            sim.Step(cmd, "torque")
            rows.append(np.concatenate([np.asarray(sim.GetMotorAngles(0), dtype=float),
                                        np.asarray(sim.GetMotorVelocities(0), dtype=float),
                                        np.asarray(sim.GetMotorTorques(0), dtype=float),
                                        np.asarray(sim.GetBasePosition(0), dtype=float)]))
        sim.pybullet_client.disconnect()
    return rows


def run_urdfkit(config: Path, mode: str, value: list[float], steps: int) -> list[np.ndarray]:
    """The same, from urdfkit's Simulation on the same config."""
    from urdfkit.sim import Simulation

    rows = []
    with Simulation.from_file(config) as s:
        robot = s.robot_names()[0]
        names = list(s.joint_positions(robot))
        s.set_joint_targets(robot, dict(zip(names, value, strict=True)), mode=mode)
        for _ in range(steps):
            s.step()
            o = s.observe(robot)
            torques = s.motor_torques(robot)
            rows.append(np.array([*(o.motor_angles[k] for k in names),
                                  *(o.motor_velocities[k] for k in names),
                                  *(torques[k] for k in names), *o.base_position]))
    return rows


def main() -> int:
    """Run every case and print the differences; 1 if any is over the tolerance."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--sac", type=Path, required=True,
                        help="A simulation_and_control checkout (holding the package folder).")
    parser.add_argument("--steps", type=int, default=1000)
    parser.add_argument("--tolerance", type=float, default=1e-9)
    args = parser.parse_args()
    commands = {"free": ("torque", [0.0, 0.0]), "servo": ("position", [0.3, 0.5]),
                "torque": ("torque", [2.0, -1.5])}
    stand = [0.0, 0.8, -1.5] * 4
    cases = {"arm": commands, "arm_full": commands,
             "quadruped": {"free": ("torque", [0.0] * 12), "servo": ("position", stand),
                           "torque": ("torque", [0.5, -0.5, 1.0] * 4)}}
    worst = 0.0
    with tempfile.TemporaryDirectory() as tmp:
        paths = configs(Path(tmp))
        for robot, runs in cases.items():
            for case, (mode, value) in runs.items():
                ref = run_siminterface(args.sac, paths[robot], mode, value, args.steps)
                ours = run_urdfkit(paths[robot], mode, value, args.steps)
                n = len(value)
                parts = {"angles": slice(0, n), "velocities": slice(n, 2 * n),
                         "torques": slice(2 * n, 3 * n), "base": slice(3 * n, 3 * n + 3)}
                same = sum(bool(np.array_equal(a, b)) for a, b in zip(ref, ours, strict=True))
                diffs = {k: max(float(np.max(np.abs(a[s] - b[s])))
                                for a, b in zip(ref, ours, strict=True))
                         for k, s in parts.items()}
                moved = float(np.max(np.abs(ref[-1][:n] - ref[0][:n])))
                worst = max(worst, *diffs.values())
                print(f"{robot:9} {case:6} {args.steps} steps: bit for bit at {same} steps; "
                      "largest difference " + ", ".join(f"{k} {v:.3g}" for k, v in diffs.items())
                      + f" (the motors moved {moved:.3g} rad)")
    print(f"worst difference {worst:.3g} (tolerance {args.tolerance:g})")
    return int(worst > args.tolerance)


if __name__ == "__main__":
    sys.exit(main())
