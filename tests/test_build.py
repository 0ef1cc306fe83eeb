"""The build is plain Python (a py3-none-any wheel), and the records check's workers hand
back by pickle keep their value.
"""

from __future__ import annotations

import os
import pickle
from pathlib import Path

import urdfkit
from urdfkit.checks.rules_mass import Solid
from urdfkit.core.finding import Finding
from urdfkit.sources.meshstore import Integrals
from urdfkit.sources.references import Reference


def test_the_package_is_plain_python() -> None:
    # No C source and no compiled module in what is imported (the installed package in CI):
    # the wheel is py3-none-any, and every module is the source a reader sees.
    package = Path(urdfkit.__file__).parent
    native = [p for p in package.rglob("*") if p.suffix in (".c", ".so", ".pyd", ".pyx")]
    assert not native, native


def test_records_pickle_compare_and_hash() -> None:
    # check's worker processes hand findings and mesh entries back by pickle (a pool whose
    # results cannot be read hangs); the records are compared and hashed by value.
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


def test_check_results_and_targets_pickle_by_value() -> None:
    # A worker hands back a FileResult with its findings, cache entry and mesh entries; the
    # value is the file and its findings (what two runs must agree on), not the bookkeeping.
    from urdfkit.checks.check import FileResult
    from urdfkit.sources.uris import Target

    f = Finding("U605", "warning", "m", "a.urdf", 3)
    fr = FileResult("a.urdf", [f], entry=((1, 2, 3, 4), {}, [f.to_dict()]), meshes={"k": b"v"})
    back = pickle.loads(pickle.dumps(fr))
    assert back == fr and back.entry == fr.entry and back.meshes == fr.meshes
    assert fr == FileResult("a.urdf", [f], cached=True) != FileResult("a.urdf", [])
    target = Target(Path("/m/x.stl"), "pkg")
    assert pickle.loads(pickle.dumps(target)) == target and hash(target) == hash(
        Target(Path("/m/x.stl"), "pkg")) and target != Target(None, "pkg", "not found")
