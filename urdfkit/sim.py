"""Config-driven simulation: a scenario in, per-step observations out.

:class:`Simulation` sets up one PyBullet client of its own (a
:class:`~urdfkit.engine.session.Session`, so several simulations in one process never share a
world), loads the ground and the robots of a scenario, and steps them under their
controllers. It is the library behind ``urdfkit sim`` and is meant to be driven from a notebook
or an RL environment too::

    with Simulation.from_file("examples/two_cars.json") as sim:
        sim.step(10)
        obs = sim.observe("north")        # what a sensor reports (noise, delay)
        true = sim.observe("north", ideal=True)
        result = sim.run()                # to the scenario's duration, recording rows

Observations are measured through each robot's motor offsets and directions; the *reported*
ones then go through delay and noise. Neither touches the physics: the controllers and the
servo model read the true joint state.

The implementation lives in :mod:`urdfkit.motion` (:mod:`urdfkit.motion.simulation` and its
parts); this module is its public face.
"""

from __future__ import annotations

from urdfkit.motion.scenario import OBSERVATION_FIELDS, load_scenario, parse_scenario
from urdfkit.motion.sim_robot import SimRobot
from urdfkit.motion.sim_state import JointSpec, Observation, RobotSummary, SimResult
from urdfkit.motion.sim_writers import (
    OUTPUT_FORMATS,
    RowText,
    check_rows_output,
    flatten,
    rows_to_bytes,
    write_rows,
)
from urdfkit.motion.simulation import PARQUET_ROWS, Simulation, run_to_file, summarize

__all__ = [
    "OBSERVATION_FIELDS", "OUTPUT_FORMATS", "PARQUET_ROWS", "JointSpec", "Observation",
    "RobotSummary", "RowText", "SimResult", "SimRobot", "Simulation", "check_rows_output",
    "flatten", "load_scenario", "parse_scenario", "rows_to_bytes", "run_to_file",
    "summarize", "write_rows",
]
