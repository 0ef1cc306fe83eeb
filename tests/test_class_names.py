"""A class name means one thing: the robot model's names are the builder's, and no other public
class name is defined in two modules but those pyproject's [tool.urdfkit.names] lists.

formats/robot.py once defined its own Robot, Link, Joint and Inertial (the URDF as PyBullet
loads it, for the MJCF writer and agree) beside the builder's; a reader of ``robot: Robot`` in
the export could not tell which. Those are LoadedRobot, LoadedLink, LoadedJoint, LoadedInertial.
"""

from __future__ import annotations

import ast
from collections import defaultdict
from pathlib import Path

import urdfkit
import urdfkit.builder
import urdfkit.formats.robot
import urdfkit.model.builder_elements
import urdfkit.model.robot

PACKAGE = Path(urdfkit.__file__).parent
ROOT = Path(__file__).resolve().parent.parent
#: The typed model's names and the module that defines each.
MODEL = {"Robot": "urdfkit/model/robot.py", "Link": "urdfkit/model/builder_elements.py",
         "Joint": "urdfkit/model/builder_elements.py",
         "Inertial": "urdfkit/model/builder_elements.py"}


def _classes() -> dict[str, list[str]]:
    """Every public class name in the package and the modules that define one of that name."""
    where: dict[str, list[str]] = defaultdict(list)
    for path in sorted(PACKAGE.rglob("*.py")):
        module = "urdfkit/" + path.relative_to(PACKAGE).as_posix()
        for node in ast.walk(ast.parse(path.read_text("utf-8"))):
            if isinstance(node, ast.ClassDef) and not node.name.startswith("_"):
                where[node.name].append(module)
    return where


def _shared() -> set[str]:
    try:
        import tomllib
    except ImportError:  # Python 3.10
        import tomli as tomllib
    config = tomllib.loads((ROOT / "pyproject.toml").read_text("utf-8"))
    return set(config["tool"]["urdfkit"]["names"]["shared"])


def test_the_robot_models_names_are_defined_in_the_model_only() -> None:
    where = _classes()
    for name, module in MODEL.items():
        assert where[name] == [module], (name, where[name])
        # one class, wherever it is imported from
        assert getattr(urdfkit.builder, name) is getattr(urdfkit.model.robot, name)
    assert urdfkit.model.robot.Link is urdfkit.model.builder_elements.Link
    loaded = {"LoadedRobot", "LoadedLink", "LoadedJoint", "LoadedInertial", "LoadedShape"}
    assert all(where[n] == ["urdfkit/formats/robot.py"] for n in loaded)
    assert not set(MODEL) & set(vars(urdfkit.formats.robot))


def test_no_two_modules_define_a_class_of_one_name_but_the_listed() -> None:
    where = _classes()
    shared = {name for name, modules in where.items() if len(modules) > 1}
    listed = _shared()
    assert not listed & set(MODEL), "the model's names are never shared"
    new = {name: where[name] for name in shared - listed}
    assert not new, f"a class name in two modules: name what each is: {new}"
    gone = listed - shared
    assert not gone, f"no longer shared: take these off [tool.urdfkit.names]: {sorted(gone)}"


def test_the_scan_reads_the_package() -> None:
    # A scan that found nothing would pass: it finds the model's classes and many others.
    where = _classes()
    assert len(where) > 150 and set(MODEL) <= set(where)
