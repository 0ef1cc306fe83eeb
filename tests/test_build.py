"""The build: check's hot path compiled by mypyc and its walk in C (setup.py), and what
compiling must not break.

CI runs the suite twice: against a regular install (compiled, URDFKIT_CI=1) and, in its second
environment, against a plain-Python one (URDFKIT_PURE=1). Each asserts it got what it asked for,
so neither can silently test the other.
"""

from __future__ import annotations

import ast
import importlib
import os
import pickle
from pathlib import Path

import pytest

from urdfkit.checks.validate import Solid
from urdfkit.core.finding import Finding
from urdfkit.sources.guard import Reference

ROOT = Path(__file__).resolve().parents[1]


def _compiled_modules() -> list[str]:
    """setup.py's COMPILED list, as module names (read, not imported: importing runs setup)."""
    tree = ast.parse((ROOT / "setup.py").read_text())
    for node in tree.body:
        if isinstance(node, ast.Assign) and getattr(node.targets[0], "id", None) == "COMPILED":
            paths = ast.literal_eval(node.value)
            return [p.removesuffix(".py").replace("/", ".") for p in paths]
    raise AssertionError("setup.py has no COMPILED list")


def _is_extension(module: str) -> bool:
    return not str(importlib.import_module(module).__file__).endswith(".py")


def test_the_compiled_list_names_real_modules() -> None:
    modules = _compiled_modules()
    assert "urdfkit.model.index" in modules and "urdfkit.checks.validate" in modules
    for m in modules:
        assert (ROOT / (m.replace(".", "/") + ".py")).is_file(), m


@pytest.mark.skipif(not os.environ.get("URDFKIT_CI"), reason="what CI installed")
def test_ci_tests_the_build_it_asked_for() -> None:
    from urdfkit.model import index

    modules = _compiled_modules()
    if os.environ.get("URDFKIT_PURE"):
        assert not any(_is_extension(m) for m in modules)
        assert not index.NATIVE_WALK
    else:
        assert all(_is_extension(m) for m in modules), \
            [m for m in modules if not _is_extension(m)]
        assert index.NATIVE_WALK  # the walk in C (urdfkit/model/_walk.c) was built and loads


def test_frozen_records_pickle() -> None:
    # check's worker processes hand findings back by pickle; mypyc's frozen dataclasses
    # cannot be unpickled field by field (a pool whose results cannot be read hangs).
    f = Finding("U605", "warning", "m", "a.urdf", 3, "b.xacro:4")
    assert pickle.loads(pickle.dumps(f)) == f
    st = os.stat(__file__)
    ref = Reference("x.stl", "/m/x.stl", "U703", "warning", "msg", st)
    back = pickle.loads(pickle.dumps(ref))
    assert back == ref and back.stat == st
    solid = Solid(1.0, (0.0, 0.0, 0.5), ((1.0, 0.0, 0.0), (0.0, 2.0, 0.0), (0.0, 0.0, 3.0)), 2.0)
    assert pickle.loads(pickle.dumps(solid)) == solid
