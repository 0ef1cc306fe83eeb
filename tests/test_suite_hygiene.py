"""The suite keeps itself honest (issue 27): every test asserts something, and every skip says
why. Read from the test modules' syntax trees, so a new module is covered without a list."""

from __future__ import annotations

import ast
from pathlib import Path

TESTS = Path(__file__).parent
#: Calls that fail a test by raising, as an assert would (gymnasium's environment checker).
CHECKERS = {"check_env"}
#: pytest helpers that assert: pytest.raises, pytest.warns, pytest.fail.
PYTEST_ASSERTS = {"raises", "warns", "fail", "deprecated_call"}


def _modules() -> list[Path]:
    return sorted(TESTS.glob("test_*.py"))


def _called(node: ast.AST) -> set[str]:
    out = set()
    for sub in ast.walk(node):
        if isinstance(sub, ast.Call):
            if isinstance(sub.func, ast.Name):
                out.add(sub.func.id)
            elif isinstance(sub.func, ast.Attribute):
                out.add(sub.func.attr)
    return out


def _asserts_directly(node: ast.AST) -> bool:
    for sub in ast.walk(node):
        if isinstance(sub, ast.Assert):
            return True
        if isinstance(sub, ast.Call) and isinstance(sub.func, ast.Attribute) and \
                sub.func.attr in PYTEST_ASSERTS and isinstance(sub.func.value, ast.Name) and \
                sub.func.value.id == "pytest":
            return True
    return False


def _tests_without_assertion(path: Path) -> list[str]:
    tree = ast.parse(path.read_text("utf-8"))
    functions = {n.name: n for n in ast.walk(tree)
                 if isinstance(n, (ast.FunctionDef, ast.AsyncFunctionDef))}
    # A helper asserts if it asserts itself or calls one that does (to a fixed point).
    asserting = {name for name, fn in functions.items() if _asserts_directly(fn)} | CHECKERS
    changed = True
    while changed:
        changed = False
        for name, fn in functions.items():
            if name not in asserting and _called(fn) & asserting:
                asserting.add(name)
                changed = True
    return [name for name, fn in functions.items()
            if name.startswith("test_") and name not in asserting]


def test_every_test_asserts_something() -> None:
    silent = {f"{path.name}::{name}" for path in _modules()
              for name in _tests_without_assertion(path)}
    assert silent == set(), "tests that cannot fail: " + ", ".join(sorted(silent))


def test_the_checker_sees_a_test_that_cannot_fail(tmp_path: Path) -> None:
    probe = tmp_path / "test_probe.py"
    probe.write_text("def _helper(x):\n    assert x\n\n"
                     "def test_fine():\n    _helper(1)\n\n"
                     "def test_silent():\n    x = 1 + 1\n")
    assert _tests_without_assertion(probe) == ["test_silent"]


def _skips_without_reason(path: Path) -> list[int]:
    out = []
    for node in ast.walk(ast.parse(path.read_text("utf-8"))):
        if not isinstance(node, ast.Call) or not isinstance(node.func, ast.Attribute):
            continue
        name = node.func.attr
        keywords = {k.arg for k in node.keywords}
        if name == "skip" and not node.args and "reason" not in keywords:
            out.append(node.lineno)  # pytest.skip() / pytest.mark.skip()
        elif name == "skipif" and "reason" not in keywords:
            out.append(node.lineno)
    return out


def test_every_skip_says_why() -> None:
    silent = [f"{path.name}:{line}" for path in _modules()
              for line in _skips_without_reason(path)]
    assert silent == [], "skips without a reason: " + ", ".join(silent)


def test_the_skip_checker_sees_a_reasonless_skip(tmp_path: Path) -> None:
    probe = tmp_path / "test_probe.py"
    # The probe's test bodies are never run: only the decorators and calls are read.
    probe.write_text("import pytest\n\n@pytest.mark.skipif(True)\ndef test_a():\n    pass\n\n"
                     "@pytest.mark.skipif(True, reason='why')\ndef test_b():\n    pass\n\n"
                     "def test_c():\n    pytest.skip()\n")
    assert _skips_without_reason(probe) == [3, 12]


def test_the_readme_counts_the_browser_tests(tmp_path: Path) -> None:
    # Issue 49: the README's test command did not say that most skips are the browser tests,
    # which need Chromium. Its count is the tests that take the `chromium` fixtures (directly
    # or through another fixture), as pytest collects them.
    import os
    import re
    import subprocess
    import sys

    (tmp_path / "browser_count.py").write_text(
        "def pytest_collection_finish(session):\n"
        "    n = sum(bool({'chromium', 'module_chromium'} & set(getattr(i, 'fixturenames', ())))"
        " for i in session.items)\n"
        "    print(f'BROWSER TESTS {n}')\n")
    files = [str(p) for p in _modules() if "chromium" in p.read_text("utf-8")]
    done = subprocess.run([sys.executable, "-m", "pytest", "--co", "-q", "-n", "0", "-p",
                           "browser_count", *files], capture_output=True, text=True,
                          timeout=300, cwd=TESTS.parent,
                          env={**os.environ, "PYTHONPATH": os.pathsep.join(
                              [str(tmp_path), os.environ.get("PYTHONPATH", "")])})
    counted = re.search(r"BROWSER TESTS (\d+)", done.stdout)
    assert counted is not None, done.stdout + done.stderr
    said = re.search(r"^- (\d+) are the browser tests", (TESTS.parent / "README.md").read_text(),
                     re.M)
    assert said is not None and int(said[1]) == int(counted[1]) > 0
