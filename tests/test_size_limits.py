"""No module over the line limit and no class over its own (pyproject's [tool.urdfkit.limits]).

A module or class past its limit is split by what its parts do. The ones not split yet are
listed in pyproject.toml; the list may only shrink: a listed one that is back under its limit
must leave the list, and any other past its limit fails.
"""

from __future__ import annotations

import ast
from pathlib import Path

import urdfkit

PACKAGE = Path(urdfkit.__file__).parent
#: The checkout (pyproject.toml): the tests' own folder's parent, wherever urdfkit is installed.
ROOT = Path(__file__).resolve().parent.parent


def _limits() -> dict[str, object]:
    try:
        import tomllib
    except ImportError:  # Python 3.10
        import tomli as tomllib
    config = tomllib.loads((ROOT / "pyproject.toml").read_text("utf-8"))
    limits: dict[str, object] = config["tool"]["urdfkit"]["limits"]
    return limits


def _over() -> dict[str, int]:
    """Every module and class past its limit: ``path`` or ``path:Class`` -> its lines."""
    limits = _limits()
    module_lines, class_lines = int(limits["module_lines"]), int(limits["class_lines"])  # type: ignore[call-overload]
    over: dict[str, int] = {}
    for path in sorted(PACKAGE.rglob("*.py")):
        name = "urdfkit/" + path.relative_to(PACKAGE).as_posix()
        text = path.read_text("utf-8")
        if (n := len(text.splitlines())) > module_lines:
            over[name] = n
        for node in ast.walk(ast.parse(text)):
            if isinstance(node, ast.ClassDef) and node.end_lineno is not None and \
                    (n := node.end_lineno - node.lineno + 1) > class_lines:
                over[f"{name}:{node.name}"] = n
    return over


def test_no_module_or_class_past_its_limit_but_the_listed_ones() -> None:
    over = _over()
    listed = set(_limits()["oversize"])  # type: ignore[arg-type]
    new = {k: v for k, v in over.items() if k not in listed}
    assert not new, f"past the limit, split by what the parts do: {new}"
    split = listed - set(over)
    assert not split, f"no longer past the limit: take these off the list: {sorted(split)}"


def test_the_limits_are_read() -> None:
    # A limit that read nothing would pass: the package's largest module is counted.
    limits = _limits()
    assert limits["module_lines"] == 800 and limits["class_lines"] == 400
    assert max(len(p.read_text("utf-8").splitlines()) for p in PACKAGE.rglob("*.py")) > 500
