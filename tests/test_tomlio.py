"""The TOML writer: what it writes, tomllib reads back the same."""

from __future__ import annotations

import math
import sys

import pytest

from urdfkit.model.tomlio import dumps

if sys.version_info >= (3, 11):
    import tomllib
else:  # pragma: no cover
    import tomli as tomllib


def test_round_trip_of_a_scenario_shaped_document() -> None:
    doc = {
        "duration": 2.0, "time_step": 1 / 240, "seed": 7, "gui": False,
        "physics": {"gravity": [0.0, 0.0, -9.81], "solver_iterations": 30},
        "robots": [
            {"name": "dog", "urdf": "models/a b.urdf", "joints": {"hip": 0.1, "knee.1": -0.2},
             "motor": {"kp": {"hip": 80.0, "knee.1": 80.0}, "max_torque": "unlimited",
                       "deep": {"a": {"b": 1}}},
             "feet": {"FL": "foot_fl", "FR": "foot_fr"}},
            {"name": "plane", "urdf": "plane.urdf", "fixed": True},
        ],
        "segments": [{"duration": 1.0, "mode": "position", "targets": {"hip": 0.3}}],
        "limits": {"upper": math.inf, "lower": -math.inf},
        "text": 'quote " backslash \\ newline \n unicode é',
        "empty": {}, "empty_list": [],
    }
    text = dumps(doc, header=["made by a test", ""])
    assert text.startswith("# made by a test\n#\n")
    assert tomllib.loads(text) == doc


def test_nan_and_unknown_types_are_refused() -> None:
    with pytest.raises(ValueError, match="NaN"):
        dumps({"x": math.nan})
    with pytest.raises(ValueError, match="cannot write"):
        dumps({"x": object()})
