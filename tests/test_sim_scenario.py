"""Scenario files: the issue's example as written, TOML, and errors that name their path."""
# ruff: noqa: E501 - ISSUE_EXAMPLE is kept byte for byte as the issue wrote it.

from __future__ import annotations

import copy
import json
import sys
from pathlib import Path
from typing import Any

import pytest

from urdfkit.core.errors import InputError, MissingDependencyError
from urdfkit.motion import scenario as sc
from urdfkit.sim import Simulation

EXAMPLES = Path(__file__).parent.parent / "examples"
TWO_CARS = EXAMPLES / "two_cars.json"

# The scenario of issue 6, verbatim: it must be accepted as written.
ISSUE_EXAMPLE = """
{
  "physics": {"time_step": 0.0041666667, "gravity": [0, 0, -9.81], "solver_iterations": 30},
  "ground": "simpleplane",
  "duration": 3.0,
  "record": {"every": 12},
  "robots": [
    {"name": "parked", "template": "simplecar", "position": [0, -2, 0.1],
     "drive": [{"until": 3.0, "throttle": 0, "steer": 0}]},
    {"name": "north", "template": "simplecar", "params": {"wheel_radius": 0.1},
     "position": [0, 2, 0.1], "orientation_rpy": [0, 0, 1.5708],
     "drive": [{"until": 1.0, "throttle": 10, "steer": 0}, {"until": 3.0, "throttle": 10, "steer": 0.3}]}
  ]
}
"""


def example() -> dict[str, Any]:
    return json.loads(ISSUE_EXAMPLE)


def test_the_example_file_is_the_issue_example_and_is_accepted() -> None:
    assert json.loads(TWO_CARS.read_text()) == example()
    s = sc.load_scenario(TWO_CARS)
    assert s.physics.solver_iterations == 30
    assert s.ground.template == "simpleplane"
    assert [r.name for r in s.robots] == ["parked", "north"]
    assert s.robots[1].drive[1].steer == pytest.approx(0.3)
    assert s.record.every == 12


def test_toml_version_is_the_same_scenario() -> None:
    a = sc.load_scenario(TWO_CARS)
    b = sc.load_scenario(EXAMPLES / "two_cars.toml")
    assert a.model_dump() == b.model_dump()


def test_defaults_fill_a_minimal_scenario() -> None:
    s = sc.parse_scenario({"robots": [{"template": "simplecar"}]})
    assert s.physics.time_step == pytest.approx(1 / 240)
    assert s.physics.cone_friction is True
    assert s.ground is None
    assert s.robots[0].name == "robot0"
    assert s.robots[0].base == "floating"


def mutate(path: str, value: Any) -> dict[str, Any]:
    """The issue example with the value at a dotted path (``robots.1.drive.0.until``) set."""
    doc = example()
    *parents, last = path.split(".")
    node: Any = doc
    for part in parents:
        node = node[int(part)] if part.isdigit() else node[part]
    if value is KeyError:
        del node[last]
    elif isinstance(node, list):
        node[int(last)] = value
    else:
        node[last] = value
    return doc


@pytest.mark.parametrize(("path", "value", "message"), [
    ("robots.1.drive.0.until", "1.0", "robots[1].drive[0].until: expected a number"),
    ("robots.1.drive.0.until", True, "robots[1].drive[0].until: expected a number"),
    ("robots.1.drive.0.until", KeyError, "robots[1].drive[0].until: required key is missing"),
    ("robots.1.drive.0.until", -1, "robots[1].drive[0].until: must be > 0"),
    ("robots.1.drive.1.until", 0.5,
     "robots[1].drive[1].until: must be later than the previous segment's (1 s)"),
    ("robots.0.position", [0, 1], "robots[0].position: expected 3 numbers, got 2"),
    ("robots.1.orientation_quat", [0, 0, 1],
     "robots[1].orientation_quat: expected 4 numbers, got 3"),
    ("robots.0.base", "welded", "robots[0].base: expected 'floating', 'fixed' or 'on_rack'"),
    ("physics.solver_iterations", 2.5, "physics.solver_iterations: expected an integer"),
    ("physics.cone_friction", "yes", "physics.cone_friction: expected true or false"),
    ("record.every", 0, "record.every: must be >= 1"),
    ("robots", [], "robots: expected at least 1 item, got 0"),
    ("robots.0.drive", "fast", "robots[0].drive: expected a list"),
    ("physics", 3, "physics: expected an object (a table in TOML)"),
    ("robots.0.template", "bicycle",
     "robots[0].template: no template named 'bicycle' (known: simplecar, simpleplane)"),
    ("robots.1.params.wheel_radius", -0.1,
     "robots[1].params: parameter 'wheel_radius' must be > 0, got -0.1"),
    ("robots.1.params.wheels", 4, "robots[1].params: template 'simplecar' has no parameter"),
    ("robots.0.urdf", "car.urdf", "robots[0]: give either 'template' or 'urdf'"),
    ("robots.1.name", "parked", "robots[1].name: 'parked' is already the name of robots[0]"),
    ("robots.0.motor", {"kp": 10}, "robots[0].motor: the servo model drives 'joints' targets"),
    ("robots.0.joints", [{"until": 1, "targets": {"a": 0}}],
     "robots[0]: give one controller: 'drive' or 'joints', not both"),
    ("robots.0.initial_joints", {"hinge": "up"},
     "robots[0].initial_joints.hinge: expected a number, or an object with position"),
    ("robots.0.motor_directions", {"hinge": 2},
     "robots[0].motor_directions.hinge: expected 1 or -1"),
    ("ground", "no_such_plane.urdf",
     "ground.urdf: no such file: no_such_plane.urdf (looked next to the scenario and in "
     "pybullet_data)"),
])
def test_errors_name_the_path(path: str, value: Any, message: str) -> None:
    with pytest.raises(InputError) as e:
        sc.parse_scenario(mutate(path, value), source="cars.json")
    assert str(e.value).startswith(f"cars.json: {message}"), str(e.value)
    assert e.value.exit_code == 2


def test_unknown_keys_are_errors_that_list_the_known_ones() -> None:
    doc = example()
    doc["robots"][1]["drive"][0]["trottle"] = 10
    with pytest.raises(InputError, match=r"robots\[1\]\.drive\[0\]\.trottle: unknown key "
                                         r"'trottle'; known keys: until, throttle, steer"):
        sc.parse_scenario(doc)
    doc = example()
    doc["physic"] = {}
    with pytest.raises(InputError, match="physic: unknown key 'physic'; known keys: physics,"):
        sc.parse_scenario(doc)


def test_several_problems_report_the_first_and_count_the_rest() -> None:
    doc = mutate("robots.1.drive.0.until", "x")
    doc["robots"][0]["position"] = "here"
    with pytest.raises(InputError, match=r"\(and 1 more problem\)$"):
        sc.parse_scenario(doc)


def test_missing_urdf_is_reported_with_its_path(tmp_path: Path) -> None:
    doc = {"robots": [{"name": "a", "template": "simplecar"},
                      {"name": "b", "urdf": "meshes/robot.urdf"}]}
    path = tmp_path / "s.json"
    path.write_text(json.dumps(doc))
    with pytest.raises(InputError) as e:
        sc.load_scenario(path)
    assert str(e.value) == (f"{path}: robots[1].urdf: no such file: meshes/robot.urdf "
                            "(looked next to the scenario and in pybullet_data)")


def test_urdf_paths_are_relative_to_the_scenario_or_pybullet_data(tmp_path: Path,
                                                                  simplecar_urdf: Path) -> None:
    (tmp_path / "sub").mkdir()
    (tmp_path / "sub" / "car.urdf").write_bytes(simplecar_urdf.read_bytes())
    doc = {"ground": "plane.urdf", "robots": [{"urdf": "car.urdf"}]}
    (tmp_path / "sub" / "s.json").write_text(json.dumps(doc))
    s = sc.load_scenario(tmp_path / "sub" / "s.json")
    assert s.path_of("car.urdf") == str(tmp_path / "sub" / "car.urdf")
    assert s.path_of("plane.urdf") == "plane.urdf"  # found later in pybullet_data


@pytest.mark.parametrize(("text", "suffix", "message"), [
    ('{"robots": [\n  {"template": "simplecar",}\n]}', ".json", ":2: invalid JSON"),
    ('{"duration": 1, "duration": 2, "robots": []}', ".json", "duplicate key 'duration'"),
    ("[1, 2]", ".json", "the top level must be an object"),
    ("duration = \n", ".toml", "invalid TOML"),
    ("duration = 1", ".yaml", "a scenario is a .json or .toml file"),
])
def test_unparseable_files(tmp_path: Path, text: str, suffix: str, message: str) -> None:
    path = tmp_path / f"s{suffix}"
    path.write_text(text)
    with pytest.raises(InputError, match=message.replace("(", r"\(")):
        sc.load_scenario(path)


def test_missing_file_and_folder(tmp_path: Path) -> None:
    with pytest.raises(InputError, match="no such file"):
        sc.load_scenario(tmp_path / "nope.json")
    with pytest.raises(InputError, match="is a directory"):
        sc.load_scenario(tmp_path)


def test_toml_types_are_checked_too(tmp_path: Path) -> None:
    path = tmp_path / "s.toml"
    path.write_text('[record]\nevery = "12"\n[[robots]]\ntemplate = "simplecar"\n')
    with pytest.raises(InputError, match=r"record\.every: expected an integer"):
        sc.load_scenario(path)


def test_joint_names_are_checked_against_the_loaded_body() -> None:
    doc = {"robots": [{"name": "car", "template": "simplecar",
                       "initial_joints": {"base_to_left_hinge": 0.1, "steering": 0.2}}]}
    with pytest.raises(InputError, match=r"robots\[0\]\.initial_joints\.steering: no joint "
                                         r"named 'steering' in car; active joints: "
                                         r"base_to_left_hinge,"):
        Simulation(doc)
    doc = {"robots": [{"template": "simplecar",
                       "joints": [{"until": 1, "targets": {"base_to_left_hinge": 0.1}},
                                  {"until": 2, "targets": {"nope": 0}}]}]}
    with pytest.raises(InputError, match=r"robots\[0\]\.joints\[1\]\.targets\.nope: no joint"):
        Simulation(doc)
    doc = {"record": {"contact_links": ["base_link", "tyre"]},
           "robots": [{"template": "simplecar"}]}
    with pytest.raises(InputError, match=r"record\.contact_links\[1\]: no robot has a link "
                                         r"named 'tyre'"):
        Simulation(doc)


def test_vehicle_without_wheels_names_the_path(tmp_path: Path) -> None:
    doc = {"robots": [{"template": "simplecar", "vehicle": {"wheels": ["nope"]},
                       "drive": [{"until": 1, "throttle": 1}]}]}
    with pytest.raises(InputError, match=r"robots\[0\]\.vehicle: `wheels`: no joint named"):
        Simulation(doc)


def test_missing_pydantic_says_what_to_install(monkeypatch: pytest.MonkeyPatch) -> None:
    sc.schema.cache_clear()
    monkeypatch.setitem(sys.modules, "pydantic", None)  # makes `import pydantic` fail
    try:
        with pytest.raises(MissingDependencyError,
                           match=r"reinstall it: pip install --force-reinstall pydantic"):
            sc.parse_scenario(copy.deepcopy(example()))
    finally:
        sc.schema.cache_clear()


def test_up_stands_a_y_up_robot_before_its_orientation(tmp_path: Path) -> None:
    from urdfkit.engine.session import import_pybullet
    from urdfkit.model.spec import UP_AXES, quat_mul

    p = import_pybullet()
    # quat_mul agrees with PyBullet's own composition.
    a, b = p.getQuaternionFromEuler((0.1, -0.4, 2.0)), UP_AXES["y"]
    _, composed = p.multiplyTransforms((0, 0, 0), a, (0, 0, 0), b)
    assert quat_mul(a, b) == pytest.approx(composed, abs=1e-6)  # PyBullet computes in float32
    urdf = tmp_path / "tower.urdf"
    urdf.write_text('<robot name="tower"><link name="a"><inertial><mass value="1"/><inertia '
                    'ixx="0.1" ixy="0" ixz="0" iyy="0.1" iyz="0" izz="0.1"/></inertial>'
                    '<collision><geometry><box size="0.1 1 0.1"/></geometry></collision>'
                    '</link></robot>')
    doc = {"duration": 0.01, "robots": [{"urdf": str(urdf), "base": "fixed", "up": "y",
                                         "orientation_rpy": [0, 0, 0.5]}]}
    with Simulation(doc) as s:
        row = s.run().rows[0]
    expected = quat_mul(p.getQuaternionFromEuler((0, 0, 0.5)), UP_AXES["y"])
    assert row.base_orientation == pytest.approx(expected, abs=1e-6)


def test_errors_name_document_keys_not_pydantic_union_members() -> None:
    from urdfkit.core.errors import InputError
    from urdfkit.motion.scenario import parse_scenario

    doc = {"robots": [{"name": "a", "template": "simplecar", "motor": {"kp": "abc"}}]}
    with pytest.raises(InputError) as e:
        parse_scenario(doc)
    assert e.value.message == "robots[0].motor.kp: expected a number"  # kp is float | dict
