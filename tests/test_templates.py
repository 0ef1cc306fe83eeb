"""The built-in templates: golden files, PyBullet facts, physics-correct inertia, parameters."""

from __future__ import annotations

import math
from pathlib import Path

import pytest

from urdfkit.builder import Inertial, Robot
from urdfkit.core.errors import ParameterError
from urdfkit.model.catalog import TEMPLATES, build_template, get_template

GOLDEN = Path(__file__).parent / "golden"

SIMPLECAR_JOINTS = [
    # (index, name, pybullet type (0 = REVOLUTE), child link, axis)
    (0, "base_to_left_hinge", 0, "left_hinge", (0, 0, 1)),
    (1, "left_hinge_to_left_front_wheel", 0, "left_front_wheel", (0, 1, 0)),
    (2, "base_to_right_hinge", 0, "right_hinge", (0, 0, 1)),
    (3, "right_hinge_to_right_front_wheel", 0, "right_front_wheel", (0, 1, 0)),
    (4, "base_to_left_back_wheel", 0, "left_back_wheel", (0, 1, 0)),
    (5, "base_to_right_back_wheel", 0, "right_back_wheel", (0, 1, 0)),
]


@pytest.mark.parametrize("name", sorted(TEMPLATES))
def test_templates_match_their_golden_files(name: str) -> None:
    assert build_template(name).to_bytes() == (GOLDEN / f"{name}.urdf").read_bytes()


@pytest.mark.parametrize("name", sorted(TEMPLATES))
def test_templates_ship_as_package_data(name: str) -> None:
    text = get_template(name).source()
    assert "xacro:arg" in text


@pytest.mark.parametrize("name", sorted(TEMPLATES))
def test_python_defaults_match_the_xacro_defaults(name: str) -> None:
    # Plain `xacro file.urdf.xacro` must give the same robot as `urdfkit build name`.
    import xacro

    from urdfkit.model.templatedir import template_dir

    t = get_template(name)
    # The installed package's folder, or the checkout's templates/ (an editable install).
    plain = xacro.process_file(str(template_dir() / t.file)).toxml()
    robot = Robot.from_string(plain)
    robot.complete_inertia()
    assert robot == build_template(name)


def test_simplecar_loads_in_pybullet_with_the_tutorial_indices(pb, simplecar_urdf: Path) -> None:
    p, client = pb
    body = p.loadURDF(str(simplecar_urdf), flags=p.URDF_USE_INERTIA_FROM_FILE,
                      physicsClientId=client)
    assert p.getNumJoints(body, physicsClientId=client) == 6
    for index, name, jtype, child, axis in SIMPLECAR_JOINTS:
        info = p.getJointInfo(body, index, physicsClientId=client)
        assert info[1].decode() == name
        assert info[2] == jtype
        assert info[12].decode() == child
        assert info[13] == pytest.approx(axis)
    # Hinges: revolute about z at 0.2 0 0, limits -0.5..0.5, effort 100, velocity 100.
    for hinge in (0, 2):
        info = p.getJointInfo(body, hinge, physicsClientId=client)
        assert (info[8], info[9], info[10], info[11]) == pytest.approx((-0.5, 0.5, 100, 100))
        assert info[14] == pytest.approx((0.2, 0, 0))
    # Continuous wheels come back as REVOLUTE with lower=0, upper=-1.
    for wheel in (1, 3, 4, 5):
        info = p.getJointInfo(body, wheel, physicsClientId=client)
        assert (info[8], info[9]) == (0.0, -1.0)
    # Front wheels 0 +-0.2 0 from the hinges; rear wheels at -0.2 +-0.175 0. PyBullet reports
    # parentFramePos relative to the parent's centre of mass, and the hinge's centre of mass
    # sits 0.11 m out along its arm (which starts 0.02 m out from the pivot, clear of the other
    # hinge), so the front wheels read 0 +-0.09 0.
    assert p.getJointInfo(body, 1, physicsClientId=client)[14] == pytest.approx((0, 0.09, 0))
    assert p.getJointInfo(body, 3, physicsClientId=client)[14] == pytest.approx((0, -0.09, 0))
    assert p.getJointInfo(body, 4, physicsClientId=client)[14] == pytest.approx((-0.2, 0.175, 0))
    assert p.getJointInfo(body, 5, physicsClientId=client)[14] == pytest.approx((-0.2, -0.175, 0))
    # In the world, at rest, the wheel centres are where the tutorial puts them.
    centres = [p.getLinkState(body, i, physicsClientId=client)[4] for i in (1, 3, 4, 5)]
    assert centres == [pytest.approx(c) for c in
                       [(0.2, 0.2, 0), (0.2, -0.2, 0), (-0.2, 0.175, 0), (-0.2, -0.175, 0)]]
    # Masses as the tutorial states.
    masses = [p.getDynamicsInfo(body, i, physicsClientId=client)[0] for i in range(-1, 6)]
    assert masses == pytest.approx([6, 0.01, 0.3, 0.01, 0.3, 0.3, 0.3])


def _check_inertia_is_physical(inertial: Inertial) -> None:
    a, b, c = inertial.inertia.principal_moments
    assert a > 0
    assert a + b >= c and b + c >= a and a + c >= b


def test_simplecar_inertia_is_that_of_its_solid_shapes() -> None:
    robot = build_template("simplecar")
    for link in robot.links:
        shapes = [(col.geometry, col.origin) for col in link.collisions]
        expected = Inertial.from_shapes(link.inertial.mass, shapes)
        assert link.inertial.inertia == expected.inertia, link.name
        assert link.inertial.origin.xyz == pytest.approx(expected.origin.xyz)
        _check_inertia_is_physical(link.inertial)
    wheel = robot.link("left_back_wheel").inertial.inertia
    # The tutorial's ixx=0.4 for a 0.3 kg, 0.1 m wheel was ~500x too large.
    assert 0.4 / wheel.ixx > 400
    assert wheel.iyy == pytest.approx(0.5 * 0.3 * 0.1**2)


def test_pybullet_agrees_with_the_file_inertia(pb, simplecar_urdf: Path) -> None:
    # Without URDF_USE_INERTIA_FROM_FILE PyBullet recomputes inertia from the collision
    # shapes; for simplecar's solid shapes the two must agree (box body exactly).
    p, client = pb
    body = p.loadURDF(str(simplecar_urdf), physicsClientId=client)
    engine = p.getDynamicsInfo(body, -1, physicsClientId=client)[2]
    assert engine == pytest.approx((0.05, 0.13, 0.17))


def test_simpleplane_is_static_with_high_friction(pb, simpleplane_urdf: Path) -> None:
    p, client = pb
    body = p.loadURDF(str(simpleplane_urdf), physicsClientId=client)
    mass, lateral = p.getDynamicsInfo(body, -1, physicsClientId=client)[:2]
    assert mass == 0
    assert lateral == pytest.approx(4)
    robot = build_template("simpleplane")
    assert robot.links[0].visuals[0].geometry.size == (20, 20, 0.01)
    assert robot.links[0].visuals[0].material.color == (0.91, 0.925, 0.945, 1)


def test_parameters_change_the_robot() -> None:
    robot = build_template("simplecar", {"wheel_radius": "0.12", "wheelbase": 0.6,
                                         "body_size": "0.6,0.4,0.12", "steer_limit": 0.3,
                                         "lateral_friction": 2})
    wheel = robot.link("left_back_wheel")
    assert wheel.collisions[0].geometry.radius == pytest.approx(0.12)
    assert wheel.contact.lateral_friction == 2
    assert robot.joint("base_to_left_hinge").origin.xyz == pytest.approx((0.3, 0, 0))
    assert robot.joint("base_to_left_back_wheel").origin.xyz[0] == pytest.approx(-0.3)
    assert robot.joint("base_to_left_hinge").limit.upper == pytest.approx(0.3)
    assert robot.link("base_link").collisions[0].geometry.size == pytest.approx((0.6, 0.4, 0.12))


@pytest.mark.parametrize(
    ("values", "message"),
    [
        ({"wheel_radius": "-0.1"}, "parameter 'wheel_radius' must be > 0"),
        ({"wheel_radius": "fast"}, "parameter 'wheel_radius' expects a number"),
        ({"body_mass": "nan"}, "parameter 'body_mass' must be finite"),
        ({"body_size": "1 2"}, "parameter 'body_size' expects three numbers, got 2"),
        ({"steer_limit": "2"}, "parameter 'steer_limit' must be <= 1.5708"),
        ({"colour": "red"}, "template 'simplecar' has no parameter 'colour'"),
    ],
)
def test_bad_parameters_name_the_parameter(values: dict, message: str) -> None:
    with pytest.raises(ParameterError) as info:
        build_template("simplecar", values)
    assert message in str(info.value)


def test_unknown_template_lists_the_known_ones() -> None:
    with pytest.raises(ParameterError, match=r"no template named 'truck' \(known: simplecar"):
        get_template("truck")


def test_steer_limit_parameter_reaches_pybullet(pb, tmp_path: Path) -> None:
    p, client = pb
    path = tmp_path / "car.urdf"
    build_template("simplecar", {"steer_limit": math.pi / 4}).write(path)
    body = p.loadURDF(str(path), physicsClientId=client)
    info = p.getJointInfo(body, 0, physicsClientId=client)
    assert (info[8], info[9]) == pytest.approx((-math.pi / 4, math.pi / 4))


@pytest.mark.parametrize("sets", [[], ["track=0.5", "front_track=0.5", "wheel_radius=0.12",
                                      "body_size=0.6,0.4,0.1"]])
def test_a_template_built_clear_of_self_contact_passes_collisions(
        sets: list[str], tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    # The README's examples: build, then `urdfkit collisions` exits 0 (no pair in contact at
    # the start pose) and build said nothing about contacts.
    from typer.testing import CliRunner

    from urdfkit.cli import app

    monkeypatch.chdir(tmp_path)
    runner = CliRunner()
    args = [a for s in sets for a in ("--set", s)]
    result = runner.invoke(app, ["build", "simplecar", *args, "-o", "car.urdf"])
    assert result.exit_code == 0 and "start pose" not in result.stderr, result.stderr
    result = runner.invoke(app, ["collisions", "car.urdf", "--json"])
    assert result.exit_code == 0, result.stdout


def test_build_names_the_pair_its_set_values_put_in_contact(
        tmp_path: Path, monkeypatch: pytest.MonkeyPatch, pb: tuple) -> None:
    from typer.testing import CliRunner

    from urdfkit.cli import app

    monkeypatch.chdir(tmp_path)
    result = CliRunner().invoke(app, ["build", "simplecar", "--set", "wheel_radius=0.12",
                                      "--set", "body_size=0.6,0.4,0.1", "-o", "car.urdf"])
    assert result.exit_code == 0  # written (PyBullet loads it), and said
    said = [ln for ln in result.stderr.splitlines() if "start pose" in ln]
    assert len(said) == 2 and all("'base_link'" in ln and "25 mm" in ln for ln in said), said
    # The depth is PyBullet's own: the body (0.4 m wide) over the front wheels, whose inner
    # faces stand 0.2 - 0.025 = 0.175 m from the centre line: 25 mm in.
    p, client = pb
    body = p.loadURDF(str(tmp_path / "car.urdf"), flags=p.URDF_USE_IMPLICIT_CYLINDER,
                      physicsClientId=client)
    points = p.getClosestPoints(body, body, 0.0, -1, 1, physicsClientId=client)
    assert min(pt[8] for pt in points) == pytest.approx(-0.025, abs=1e-3)
