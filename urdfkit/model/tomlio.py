"""Writing TOML: the one writer behind ``sim convert`` (reading is tomllib's).

A small, exact subset: tables, arrays of tables, inline tables, strings, numbers, booleans and
arrays. ``tomllib.loads(dumps(d)) == d`` for every document it accepts; NaN is refused.
"""

from __future__ import annotations

import json
import math
import re
from collections.abc import Mapping, Sequence
from typing import Any

_BARE_KEY = re.compile(r"^[A-Za-z0-9_-]+$")


def _toml_key(key: str) -> str:
    return key if _BARE_KEY.match(key) else json.dumps(key, ensure_ascii=False)


def _toml_value(value: Any) -> str:
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, int):
        return str(value)
    if isinstance(value, float):
        if math.isnan(value):
            raise ValueError("NaN has no place in a scenario")
        return ("inf" if value > 0 else "-inf") if math.isinf(value) else repr(value)
    if isinstance(value, str):
        # A JSON string is a TOML basic string (the same escapes).
        return json.dumps(value, ensure_ascii=False)
    if isinstance(value, (list, tuple)):
        return "[" + ", ".join(_toml_value(v) for v in value) + "]"
    if isinstance(value, Mapping):
        return "{" + ", ".join(f"{_toml_key(k)} = {_toml_value(v)}"
                               for k, v in value.items()) + "}"
    raise ValueError(f"cannot write {type(value).__name__} to TOML")


def _is_table(value: Any) -> bool:
    return isinstance(value, Mapping) and bool(value) and \
        any(isinstance(v, Mapping) for v in value.values()) or \
        isinstance(value, Mapping) and len(value) > 4


def dumps(document: Mapping[str, Any], header: Sequence[str] = ()) -> str:
    """A document (a scenario) as TOML text (``tomllib.loads`` gives the document back).

    Sub-tables get their own ``[section]`` when they nest or are long; small flat ones stay
    inline. ``header`` lines become comments at the top.
    """
    lines = [f"# {h}" if h else "#" for h in header]

    def emit(path: list[str], table: Mapping[str, Any], array: bool) -> None:
        def section(v: Any) -> bool:  # the top level's tables always get a [section]
            return _is_table(v) or not path and isinstance(v, Mapping) and bool(v)

        plain = [(k, v) for k, v in table.items()
                 if not section(v) and not (isinstance(v, list) and v
                                            and all(isinstance(x, Mapping) for x in v))]
        tables = [(k, v) for k, v in table.items() if section(v)]
        arrays = [(k, v) for k, v in table.items() if isinstance(v, list) and v
                  and all(isinstance(x, Mapping) for x in v)]
        if path:
            name = ".".join(_toml_key(p) for p in path)
            lines.append("")
            lines.append(f"[[{name}]]" if array else f"[{name}]")
        for k, v in plain:
            lines.append(f"{_toml_key(k)} = {_toml_value(v)}")
        for k, v in tables:
            emit([*path, k], v, False)
        for k, items in arrays:
            for item in items:
                emit([*path, k], item, True)

    emit([], document, False)
    return "\n".join(lines).lstrip("\n") + "\n"
