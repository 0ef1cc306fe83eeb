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
from urdfkit.sources.meshstore import Integrals

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


def test_records_pickle_compare_and_hash() -> None:
    # check's worker processes hand findings and mesh entries back by pickle (a pool whose
    # results cannot be read hangs). The records are plain classes (compiled, a frozen
    # dataclass is built through Python: 1.5 us against 0.03), compared and hashed by value.
    f = Finding("U605", "warning", "m", "a.urdf", 3, "b.xacro:4")
    assert pickle.loads(pickle.dumps(f)) == f
    assert hash(pickle.loads(pickle.dumps(f))) == hash(f) and len({f, Finding(*_fields(f))}) == 1
    assert f != Finding("U605", "warning", "m", "a.urdf", 4, "b.xacro:4") and f != _fields(f)
    assert repr(f) == ("Finding(code='U605', level='warning', message='m', file='a.urdf', "
                       "line=3, origin='b.xacro:4')")
    entry = Integrals(1.0, (0.1, 0.2, 0.3), (1.0, 2.0, 3.0, 0.0, 0.0, 0.0), (0.0, 0.0, 0.0),
                      (1.0, 1.0, 1.0), True, 12, 0.5, 2)
    assert pickle.loads(pickle.dumps(entry)) == entry == Integrals.unpack(entry.pack())
    props = entry.scaled((2.0, 2.0, 2.0))
    assert props is not None and pickle.loads(pickle.dumps(props)) == props
    st = os.stat(__file__)
    ref = Reference("x.stl", "/m/x.stl", "U703", "warning", "msg", st)
    back = pickle.loads(pickle.dumps(ref))
    assert back == ref and back.stat == st
    solid = Solid(1.0, (0.0, 0.0, 0.5), ((1.0, 0.0, 0.0), (0.0, 2.0, 0.0), (0.0, 0.0, 3.0)), 2.0)
    assert pickle.loads(pickle.dumps(solid)) == solid


def _fields(f: Finding) -> tuple[object, ...]:
    return (f.code, f.level, f.message, f.file, f.line, f.origin)
