"""urdfkit's jsontext writes exactly what ``json.dumps(indent=2)`` writes (the standard library is
the reference), and raises where it raises."""

from __future__ import annotations

import json
import math

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from urdfkit.core.jsontext import dumps

# Strings with the characters the fast path relies on the encoder escaping.
TEXT = st.text(alphabet=st.sampled_from(list('ab,{}[]:" \\\x00\x01\n\tü€😀')), max_size=8)
SCALARS = st.none() | st.booleans() | st.integers() | TEXT | st.floats(allow_nan=False,
                                                                       allow_infinity=False)
FLAT_ROW = st.dictionaries(TEXT, SCALARS, min_size=1, max_size=5)
VALUES = st.recursive(
    SCALARS | st.lists(FLAT_ROW, max_size=4),
    lambda inner: st.lists(inner, max_size=4) | st.tuples(inner, inner)
    | st.dictionaries(TEXT, inner, max_size=4)
    | st.dictionaries(st.integers() | st.booleans() | st.none(), inner, max_size=3),
    max_leaves=30)


@settings(max_examples=400, deadline=None)
@given(VALUES)
def test_the_same_text_as_the_standard_library(value: object) -> None:
    assert dumps(value) == json.dumps(value, indent=2)


def test_a_check_report_shape() -> None:
    findings = [{"code": f"U{i:03d}", "level": "error", "message": 'a "quoted", {x}: y\n',
                 "file": "r.urdf", "line": i or None, "origin": None} for i in range(50)]
    data = {"files": ["r.urdf"], "findings": findings, "summary": {"files": 1, "error": 50},
            "empty": {}, "none": [], "nested": [[1, [2, {}]], {"k": [{"a": 1}]}]}
    assert dumps(data) == json.dumps(data, indent=2)


@pytest.mark.parametrize("bad", [math.nan, [math.inf], {"a": [{"b": -math.inf}]},
                                 [{"a": math.nan}], {"s": {1, 2}}])
def test_raises_where_the_standard_library_raises(bad: object) -> None:
    with pytest.raises((ValueError, TypeError)) as ours:
        dumps(bad)
    with pytest.raises(type(ours.value)):
        json.dumps(bad, indent=2, allow_nan=False)
