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


#: Typos planted outside motion/: (module, function, parameter). Each reads an attribute of a
#: typed parameter, so a misspelt one must fail mypy. Five of these passed it once, when their
#: parameters were ``Any`` (an lxml element, a Joint, an Export, a Session).
TARGETS: list[tuple[str, str, str]] = [
    ("checks/rules_joints.py", "_joint_inertia", "jv"),
    ("checks/fix_plan.py", "_Plan.carry_contacts", "link"),
    ("formats/mjcf.py", "_Writer.joint", "j"),
    ("formats/mjcf.py", "_Writer.fill", "body"),
    ("exchange/agree_sides.py", "PyBulletSide.__init__", "engine"),
    ("commands/exporting.py", "_export_dict", "e"),
    ("model/robot.py", "_parse_joint", "el"),
    ("sources/references.py", "label", "el"),
    ("draw/view_model.py", "ViewedRobot.set_positions", "self"),
    ("engine/session.py", "Session.load_urdf", "self"),
    ("core/finding.py", "Finding.to_dict", "self"),
    ("checks/build.py", "_unloadable", "root"),
    ("gym.py", "SimpleDrivingEnv.step", "self"),
    ("serve/analysis.py", "_read_robot", "out"),
]


def _plant_in(source: str, qualname: str, param: str) -> tuple[str, int, str]:
    """``source`` with the first read of ``<param>.<attr>`` in function ``qualname`` misspelt."""
    tree = ast.parse(source)
    scopes: list[ast.AST] = [tree]
    for part in qualname.split("."):
        found = [n for scope in scopes for n in ast.iter_child_nodes(scope)
                 if isinstance(n, (ast.ClassDef, ast.FunctionDef)) and n.name == part]
        assert found, f"no {qualname}"
        scopes = found[:1]
    func = scopes[0]
    for node in ast.walk(func):
        if isinstance(node, ast.Attribute) and isinstance(node.ctx, ast.Load) and \
                isinstance(node.value, ast.Name) and node.value.id == param and \
                not node.attr.startswith("__"):
            lines = source.splitlines(keepends=True)
            line = lines[node.lineno - 1]
            start = node.value.end_col_offset + 1
            wrong = node.attr + "x"
            lines[node.lineno - 1] = line[:start] + wrong + line[start + len(node.attr):]
            return "".join(lines), node.lineno, wrong
    raise AssertionError(f"{qualname} reads no attribute of {param}")


def test_every_folder_has_a_planted_typo() -> None:
    folders = {p.parent.name for p in PACKAGE.rglob("*.py")
               if "__pycache__" not in p.parts and p.parent != PACKAGE} - {"templates"}
    planted = {Path(m).parent.name for m, _, _ in TARGETS} | {"motion"}
    assert folders <= planted, folders - planted


def test_mypy_catches_a_misspelt_attribute_in_every_folder(tmp_path: Path) -> None:
    """One typo per target (``self.world`` read as ``self.worldx``...), one mypy run: all caught.

    In the default run: one mypy run over a copy of the package (about 10 s on one core).
    """
    api = pytest.importorskip("mypy.api")
    copy = tmp_path / "urdfkit"
    shutil.copytree(PACKAGE, copy, ignore=shutil.ignore_patterns("__pycache__", "*.so"))
    planted: list[tuple[str, int, str]] = []
    for part in PARTS:
        text, line, wrong = _plant((copy / part).read_text("utf-8"))
        (copy / part).write_text(text, "utf-8")
        planted.append((part, line, wrong))
    for module, qualname, param in TARGETS:
        source = (copy / module).read_text("utf-8")
        text, line, wrong = _plant_in(source, qualname, param)
        (copy / module).write_text(text, "utf-8")
        planted.append((module, line, wrong))
    out, _err, status = api.run(["--ignore-missing-imports", "--disallow-untyped-defs",
                                 "--cache-dir", str(tmp_path / "cache"), str(copy)])
    assert status == 1, out
    rows = [row.replace("\\", "/") for row in out.splitlines()]
    missed = [f"{part}:{line} {wrong}" for part, line, wrong in planted
              if not [row for row in rows
                      if f"urdfkit/{part}:{line}: error:" in row and f'"{wrong}"' in row]]
    assert not missed, f"mypy missed {missed}\n{out}"
