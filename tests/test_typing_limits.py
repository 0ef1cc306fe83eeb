"""The simulation's types say something: few ``Any``, no ``self: Any``, typos caught by mypy.

``Simulation`` was once ~50 functions taking ``self: Any``, bound onto the class: a misspelt
attribute passed mypy. Its parts are classes now (docs/architecture.md); these tests hold it so.
"""

from __future__ import annotations

import ast
import shutil
from pathlib import Path

import pytest

import urdfkit

PACKAGE = Path(urdfkit.__file__).parent
#: The modules whose signatures are counted: motion/, and the public faces of sim and gym.
TYPED = sorted(PACKAGE.glob("motion/*.py")) + [PACKAGE / "sim.py", PACKAGE / "gym.py"]
#: ``Any`` is left only at the PyBullet, pydantic and JSON boundaries.
MAX_ANY = 30
#: The parts of a Simulation, and the class each planted typo must be caught in.
PARTS = ["motion/simulation.py", "motion/sim_world.py", "motion/sim_robot.py",
         "motion/sim_control.py", "motion/sim_sensors.py", "motion/sim_dynamics.py",
         "motion/sim_record.py", "motion/sim_episode.py"]


def _annotations(tree: ast.AST) -> list[tuple[ast.expr, int]]:
    """Every annotation of a function signature or an annotated assignment, with its line."""
    out: list[tuple[ast.expr, int]] = []
    for node in ast.walk(tree):
        if isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef)):
            a = node.args
            for arg in [*a.posonlyargs, *a.args, *a.kwonlyargs, a.vararg, a.kwarg]:
                if arg is not None and arg.annotation is not None:
                    out.append((arg.annotation, node.lineno))
            if node.returns is not None:
                out.append((node.returns, node.lineno))
        elif isinstance(node, ast.AnnAssign):
            out.append((node.annotation, node.lineno))
    return out


def _any_count(annotation: ast.expr) -> int:
    if isinstance(annotation, ast.Constant) and isinstance(annotation.value, str):
        annotation = ast.parse(annotation.value, mode="eval").body  # a quoted annotation
    return sum(1 for n in ast.walk(annotation)
               if (isinstance(n, ast.Name) and n.id == "Any")
               or (isinstance(n, ast.Attribute) and n.attr == "Any"))


def test_any_is_rare_in_the_simulation_signatures() -> None:
    found = [f"{path.relative_to(PACKAGE)}:{line}"
             for path in TYPED
             for annotation, line in _annotations(ast.parse(path.read_text("utf-8")))
             for _ in range(_any_count(annotation))]
    # A count that reads nothing would pass: the files are there and annotated.
    assert len(TYPED) > 10 and sum(len(_annotations(ast.parse(p.read_text("utf-8"))))
                                   for p in TYPED) > 500
    assert len(found) <= MAX_ANY, f"{len(found)} uses of Any (at most {MAX_ANY}): {found}"


def test_no_function_takes_self_any() -> None:
    wrong = []
    for path in PACKAGE.rglob("*.py"):
        for node in ast.walk(ast.parse(path.read_text("utf-8"))):
            if isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef)) and node.args.args:
                first = node.args.args[0]
                if first.arg == "self" and first.annotation is not None and \
                        _any_count(first.annotation):
                    wrong.append(f"{path.relative_to(PACKAGE)}:{node.lineno} {node.name}")
    assert not wrong, wrong


def _plant(source: str) -> tuple[str, int, str]:
    """``source`` with its first read of ``self.<attr>`` outside ``__init__`` misspelt.

    Returns the new source, the line, and the misspelt name. A module without methods
    (sim_episode's functions) gets its first read of an attribute of a typed parameter.
    """
    tree = ast.parse(source)
    for func in ast.walk(tree):
        if not isinstance(func, ast.FunctionDef) or func.name == "__init__":
            continue
        params = {a.arg for a in func.args.args if a.annotation is not None or a.arg == "self"}
        for node in ast.walk(func):
            if isinstance(node, ast.Attribute) and isinstance(node.ctx, ast.Load) and \
                    isinstance(node.value, ast.Name) and node.value.id in params and \
                    not node.attr.startswith("__"):
                lines = source.splitlines(keepends=True)
                line = lines[node.lineno - 1]
                start = node.value.end_col_offset + 1  # after "name."
                wrong = node.attr + "x"
                lines[node.lineno - 1] = line[:start] + wrong + line[start + len(node.attr):]
                return "".join(lines), node.lineno, wrong
    raise AssertionError("nothing to plant a typo in")


@pytest.mark.slow  # a whole mypy run per part (16 s): CI's slow step runs it
def test_mypy_catches_a_misspelt_attribute_in_every_part(tmp_path: Path) -> None:
    """One typo per part (``self.world`` read as ``self.worldx``...), one mypy run: all caught."""
    api = pytest.importorskip("mypy.api")
    copy = tmp_path / "urdfkit"
    shutil.copytree(PACKAGE, copy, ignore=shutil.ignore_patterns("__pycache__", "*.so"))
    planted = {}
    for part in PARTS:
        text, line, wrong = _plant((copy / part).read_text("utf-8"))
        (copy / part).write_text(text, "utf-8")
        planted[part] = (line, wrong)
    out, _err, status = api.run(["--ignore-missing-imports", "--disallow-untyped-defs",
                                 "--cache-dir", str(tmp_path / "cache"), str(copy)])
    assert status == 1, out
    rows = [row.replace("\\", "/") for row in out.splitlines()]
    for part, (line, wrong) in planted.items():
        hits = [row for row in rows
                if f"urdfkit/{part}:{line}: error:" in row and f'"{wrong}"' in row]
        assert hits, f"mypy missed {wrong} planted at {part}:{line}\n{out}"
