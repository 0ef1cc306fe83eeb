"""bench/corpus.py, the corpus runner: its exit classes and its comparison with raw PyBullet."""

from __future__ import annotations

import importlib.util
import json
import sys
from pathlib import Path
from types import ModuleType

import pytest
from typer.testing import CliRunner

from urdfkit.cli import app

R2D2 = "r2d2.urdf"


def _corpus() -> ModuleType:
    path = Path(__file__).parent.parent / "bench" / "corpus.py"
    spec = importlib.util.spec_from_file_location("corpus_bench", path)
    assert spec is not None and spec.loader is not None
    module = importlib.util.module_from_spec(spec)
    sys.modules[spec.name] = module  # its dataclasses look themselves up there
    spec.loader.exec_module(module)
    return module


@pytest.mark.parametrize(("code", "kind"), [
    ("pass", "ok"), ("raise SystemExit(1)", "findings"), ("raise SystemExit(2)", "refusal"),
    ("raise SystemExit(3)", "bug"), ("import os; os.abort()", "crash"),
    ("import time; time.sleep(30)", "timeout"),
])
def test_each_exit_is_classified(code: str, kind: str) -> None:
    run = _corpus().run([sys.executable, "-c", code], {}, timeout=3.0)
    assert run.kind == kind


def test_a_traceback_or_json_that_does_not_parse_is_a_bug() -> None:
    corpus = _corpus()
    traceback = "import sys; sys.stderr.write('Traceback (most recent call last):\\n'); sys.exit(2)"
    assert corpus.run([sys.executable, "-c", traceback], {}, timeout=10.0).kind == "bug"
    not_json = [sys.executable, "-c", "print('{half')", "--json"]
    assert corpus.run(not_json, {}, timeout=10.0).kind == "bug"
    json_ok = [sys.executable, "-c", "print('{}')", "--json"]
    assert corpus.run(json_ok, {}, timeout=10.0).kind == "ok"


def test_urdfkit_equals_raw_pybullet_and_a_change_is_caught() -> None:
    corpus = _corpus()
    joints = json.loads(CliRunner().invoke(app, ["joints", R2D2, "--json"]).stdout)
    links = json.loads(CliRunner().invoke(app, ["links", R2D2, "--json"]).stdout)
    raw = corpus.raw_load(joints["path"], joints["load_flags"], timeout=60.0)
    assert raw["loaded"] and len(raw["joints"]) == len(joints["joints"]) == 15
    assert corpus.compare(raw, joints, links) == []
    prismatic = next(i for i, j in enumerate(raw["joints"]) if j["type"] == 1)
    raw["joints"][prismatic]["upper"] += 0.01
    raw["base_mass"] += 1.0
    raw["inertia"][3][1] *= 1.001
    diffs = corpus.compare(raw, joints, links)
    assert len(diffs) == 3 and "upper" in diffs[0] and "link -1 mass" in diffs[1]
    assert "link 2 local_inertia_diagonal" in diffs[2]
