"""A seeded sample of the fuzz campaign (tests/fuzz): mutants of real robots through every
file-reading command, with zero signals, hangs, tracebacks, bugs, multi-line or unnamed
refusals, or unparsable JSON. The full run is bench/fuzz.py."""

from __future__ import annotations

import pytest
from fuzz.runner import FAILURES, campaign, classify, commands


@pytest.mark.fuzz  # not in the default run: CI runs it (pytest -m fuzz)
def test_seeded_sample_has_no_failures() -> None:
    report = campaign(60, seed=20261122, jobs=2)
    assert report.runs == 60 * len(commands("r.urdf"))
    failures = [f"{f['class']}: {' '.join(map(str, f['command']))} <- {f['seed']} "
                f"{f['mutations']}: {str(f['stderr']).strip()[-300:]}" for f in report.failures]
    assert failures == []
    # The sample is not vacuous: it reaches refusals, findings and clean loads.
    classes = report.classes()
    assert classes["refusal"] > 0 and classes["findings"] > 0 and classes["ok"] > 0


@pytest.mark.parametrize(("run", "expected"), [
    ({"command": ["joints", "r.urdf"], "code": None, "signal": 11, "hang": False,
      "stdout": "", "stderr": ""}, "signal"),
    ({"command": ["joints", "r.urdf"], "code": None, "signal": None, "hang": True,
      "stdout": "", "stderr": ""}, "hang"),
    ({"command": ["joints", "r.urdf"], "code": 1, "signal": None, "hang": False,
      "stdout": "", "stderr": "Traceback (most recent call last):\n"}, "traceback"),
    ({"command": ["joints", "r.urdf"], "code": 3, "signal": None, "hang": False,
      "stdout": "", "stderr": "urdfkit: internal error"}, "bug"),
    ({"command": ["joints", "r.urdf"], "code": 2, "signal": None, "hang": False,
      "stdout": "", "stderr": "urdfkit: error: something\n"}, "unnamed refusal"),
    ({"command": ["joints", "r.urdf"], "code": 2, "signal": None, "hang": False,
      "stdout": "", "stderr": "urdfkit: error: r.urdf: a\nmore\n"}, "multi-line error"),
    ({"command": ["joints", "r.urdf"], "code": 2, "signal": None, "hang": False,
      "stdout": "", "stderr": "urdfkit: error: r.urdf: " + "x" * 3000 + "\n"},
     "unbounded error"),
    ({"command": ["joints", "r.urdf", "--json"], "code": 0, "signal": None, "hang": False,
      "stdout": "{not json", "stderr": ""}, "dirty json"),
    ({"command": ["joints", "r.urdf", "--json"], "code": 0, "signal": None, "hang": False,
      "stdout": "{}", "stderr": "urdfkit: warning: x\n"}, "ok"),
])
def test_the_classifier_tells_failures_apart(run: dict[str, object], expected: str) -> None:
    assert classify(run, "r.urdf") == expected
    assert (expected in FAILURES) == (expected not in ("ok", "findings", "refusal"))
