"""A seeded sample of the fuzz campaigns (tests/fuzz): mutants of real robots through every
file-reading command (export and agree on the mutant's own export included), and mutants of
real MJCF exports through agree, with zero signals, hangs, tracebacks, bugs, multi-line or
unnamed refusals, or unparsable JSON. The full runs are bench/fuzz.py."""

from __future__ import annotations

import pytest
from fuzz.runner import (
    FAILURES,
    VERIFY_EVERY,
    campaign,
    classify,
    commands,
    mjcf_campaign,
    mjcf_commands,
)


@pytest.mark.fuzz  # not in the default run: CI runs it (pytest -m fuzz)
def test_seeded_sample_has_no_failures() -> None:
    report = campaign(60, seed=20261122, jobs=2)
    assert report.runs == sum(len(commands("r.urdf", verify=i % VERIFY_EVERY == 0))
                              for i in range(60))
    failures = [f"{f['class']}: {' '.join(map(str, f['command']))} <- {f['seed']} "
                f"{f['mutations']}: {str(f['stderr']).strip()[-300:]}" for f in report.failures]
    assert failures == []
    # The sample is not vacuous: it reaches refusals, findings and clean loads.
    classes = report.classes()
    assert classes["refusal"] > 0 and classes["findings"] > 0 and classes["ok"] > 0
    # agree ran on what export wrote, and compared it (every row held: the export is exact)
    assert report.counts[("ok", "agree F")] > 0


@pytest.mark.fuzz
def test_seeded_mjcf_sample_has_no_failures() -> None:
    report = mjcf_campaign(80, seed=20261123, jobs=2)
    assert report.runs == 80 * len(mjcf_commands("r.urdf"))
    failures = [f"{f['class']}: {' '.join(map(str, f['command']))} <- {f['seed']} "
                f"{f['mutations']}: {str(f['stderr']).strip()[-300:]}" for f in report.failures]
    assert failures == []
    # MuJoCo refused some, urdfkit's walk others, and the rest were compared
    classes = report.classes()
    assert classes["refusal"] > 0 and classes["ok"] > 0 and classes["findings"] > 0


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
    # agree's refusal of the export it was to read names that file
    ({"command": ["agree", "r.urdf", "out.xml"], "code": 2, "signal": None, "hang": False,
      "stdout": "", "stderr": "urdfkit: error: out.xml: no such file\n"}, "refusal"),
])
def test_the_classifier_tells_failures_apart(run: dict[str, object], expected: str) -> None:
    assert classify(run, "r.urdf") == expected
    assert (expected in FAILURES) == (expected not in ("ok", "findings", "refusal"))
