"""The builder model: checks on assignment, inertia, deterministic XML, and the round trip."""

from __future__ import annotations

import math
from typing import Any

import pytest

from urdfkit.builder import (
    Box,
    Calibration,
    Collision,
    Contact,
    Cylinder,
    Dynamics,
    Inertia,
    Inertial,
    Joint,
    Limit,
    Link,
    Material,
    Mesh,
    Mimic,
    Origin,
    Robot,
    SafetyController,
    Sphere,
    Visual,
    as_written,
)
from urdfkit.core.errors import ModelError


def full_robot() -> Robot:
    """A robot that uses every element the model holds."""
    r = Robot(name="everything")
    r.add_material(Material("red", color=(1, 0, 0, 1)))
    r.add_material(Material("tex", texture="wood.png"))
    r.add_link(Link(
        "base",
        inertial=Inertial(2.0, Inertia(0.1, 0.001, -0.002, 0.2, 0.003, 0.3),
                          Origin((0.01, 0, -0.02), (0.1, 0.2, 0.3))),
        visuals=[Visual(Box((1, 2, 3)), Origin((0, 0, 1)), "red", name="body"),
                 Visual(Mesh("meshes/a.stl", scale=(0.001, 0.001, 0.001)),
                        material=Material("inline", color=(0.1, 0.2, 0.3, 0.5)))],
        collisions=[Collision(Box((1, 2, 3)), name="hull"), Collision(Sphere(0.5))],
        contact=Contact(lateral_friction=0.8, rolling_friction=0.01, spinning_friction=0.02,
                        restitution=0.1, stiffness=3e4, damping=100, contact_cfm=0.001,
                        contact_erp=0.2, inertia_scaling=3, friction_anchor=True),
    ))
    r.add_link(Link("arm", inertial=Inertial(1.0, Inertia(0.01, 0, 0, 0.01, 0, 0.01)),
                    collisions=[Collision(Cylinder(0.05, 0.4), Origin(rpy=(math.pi / 2, 0, 0)))]))
    r.add_link(Link("finger"))
    r.add_link(Link("twin"))
    r.add_joint(Joint("base_to_arm", "revolute", "base", "arm", Origin((0, 0, 1.5)),
                      axis=(0, 1, 0), limit=Limit(10, 2, -1.5, 1.5),
                      dynamics=Dynamics(0.5, 0.1),
                      safety_controller=SafetyController(10, -1.4, 1.4, 100),
                      calibration=Calibration(rising=0.1, falling=-0.1)))
    r.add_joint(Joint("arm_to_finger", "prismatic", "arm", "finger", axis=(1, 0, 0),
                      limit=Limit(5, 0.1, 0, 0.05)))
    r.add_joint(Joint("arm_to_twin", "prismatic", "arm", "twin", axis=(-1, 0, 0),
                      limit=Limit(5, 0.1, 0, 0.05), mimic=Mimic("arm_to_finger", 1.0, 0.0)))
    return r


def test_round_trip_is_lossless_for_everything_the_model_holds() -> None:
    robot = full_robot()
    text = robot.to_bytes()
    again = Robot.from_string(text)
    assert again == robot
    assert again.to_bytes() == text
    # The pieces yourdfpy once dropped on save must be there.
    twin = again.joint("arm_to_twin")
    assert twin.mimic == Mimic("arm_to_finger", 1.0, 0.0)
    assert again.link("base").contact == robot.link("base").contact
    assert again.joint("base_to_arm").safety_controller.k_position == 100
    assert again.joint("base_to_arm").calibration.falling == -0.1


def test_unknown_top_level_elements_survive_the_round_trip() -> None:
    text = ('<robot name="r"><link name="a"/><gazebo reference="a"><mu1>0.5</mu1></gazebo>'
            '</robot>')
    robot = Robot.from_string(text)
    assert len(robot.extras) == 1
    assert b'<gazebo reference="a">' in robot.to_bytes()
    assert Robot.from_string(robot.to_bytes()) == robot


def test_writing_is_deterministic_and_formats_floats() -> None:
    r = Robot("fmt")
    r.add_link(Link("a", inertial=Inertial(0.1 * 3, Inertia(-0.0, 0, 0, 1e-7, 0, 2))))
    out = r.to_bytes()
    assert out == r.to_bytes()
    assert b'<mass value="0.3"/>' in out
    assert b'ixx="0"' in out  # -0.0 is written as 0
    assert b"1e-07" in out
    assert out.startswith(b'<?xml version="1.0" encoding="utf-8"?>\n')


def test_equality_tolerates_float_noise_but_not_real_differences() -> None:
    assert Origin((0.1 + 0.2, 0, 0)) == Origin((0.3, 0, 0))
    assert Origin((0.3001, 0, 0)) != Origin((0.3, 0, 0))


@pytest.mark.parametrize(
    ("make", "fragment"),
    [
        (lambda: Box((1, -2, 3)), "attribute 'size' of element <box>: must be > 0"),
        (lambda: Box((1, 2)), "attribute 'size' of element <box>: expected 3 numbers"),
        (lambda: Cylinder(0.1, float("nan")), "'length' of element <cylinder>: expected a finite"),
        (lambda: Sphere("big"), "'radius' of element <sphere>: expected a number"),
        (lambda: Inertial(-1.0), "'mass' of element <inertial>: must be >= 0"),
        (lambda: Material("m", color=(2, 0, 0, 1)), "colour components must lie in 0..1"),
        (lambda: Joint("j", "hinge", "a", "b"), "unknown joint type 'hinge'"),
        (lambda: Joint("j", "revolute", "a", "b"), "needs <limit effort=... velocity=...>"),
        (lambda: Joint("j", "fixed", "a", "a"), "joins link 'a' to itself"),
        (lambda: Joint("j", "continuous", "a", "b", axis=(0, 0, 0)), "axis must not be zero"),
        (lambda: Limit(1, 1, lower=1, upper=-1), "lower 1 is above upper -1"),
        (lambda: Link(""), "'name' of element <link>: expected a non-empty name"),
    ],
)
def test_bad_values_fail_where_they_are_set(make, fragment: str) -> None:
    with pytest.raises(ModelError, match=None) as info:
        make()
    assert fragment in str(info.value)


def test_assignment_after_construction_is_checked_too() -> None:
    box = Box((1, 1, 1))
    with pytest.raises(ModelError, match="must be > 0"):
        box.size = (0, 1, 1)
    assert box.size == (1.0, 1.0, 1.0)


def test_robot_refuses_bad_structure_as_it_is_composed() -> None:
    r = Robot("r")
    r.add_link(Link("a"))
    with pytest.raises(ModelError, match="already has a link named 'a'"):
        r.add_link(Link("a"))
    with pytest.raises(ModelError, match="child link 'b' does not exist"):
        r.add_joint(Joint("j", "fixed", "a", "b"))
    r.add_link(Link("b"))
    r.add_link(Link("c"))
    r.add_joint(Joint("j", "fixed", "a", "b"))
    with pytest.raises(ModelError, match="already has a joint named 'j'"):
        r.add_joint(Joint("j", "fixed", "a", "c"))
    with pytest.raises(ModelError, match="'b' already has a parent"):
        r.add_joint(Joint("k", "fixed", "c", "b"))


def test_parser_reports_file_and_line() -> None:
    text = '<robot name="r">\n<link name="a">\n<collision><geometry><box size="1 0 1"/>' \
           '</geometry></collision></link>\n</robot>'
    with pytest.raises(ModelError) as info:
        Robot.from_string(text, file="x.urdf")
    assert info.value.file == "x.urdf"
    assert info.value.line == 3
    assert str(info.value).startswith("x.urdf:3: ")


def test_parser_rejects_two_roots_and_cycles() -> None:
    two_roots = '<robot name="r"><link name="a"/><link name="b"/></robot>'
    with pytest.raises(ModelError, match="exactly one root link, found 2"):
        Robot.from_string(two_roots)
    cycle = ('<robot name="r"><link name="a"/><link name="b"/><link name="c"/>'
             '<joint name="j1" type="fixed"><parent link="a"/><child link="b"/></joint>'
             '<joint name="j2" type="fixed"><parent link="b"/><child link="c"/></joint>'
             '<joint name="j3" type="fixed"><parent link="c"/><child link="b"/></joint></robot>')
    with pytest.raises(ModelError, match="two parent joints"):
        Robot.from_string(cycle)


# --------------------------------------------------------------------------- lenient read


LENIENT = ('<robot name="r"><link name="a"><collision><geometry><sphere radius="0"/>'
           '<material name="grey"/></geometry></collision></link><link name="b"/>'
           '<joint name="j" type="revolute"><parent link="a"/><child link="b"/>'
           '<origin xyz="0.07, 0, -0.69" rpy="0 0 0 0"/><axis xyz="0 0 0"/>'
           '<limit lower="1" upper="-1.57." effort="inf"/></joint></robot>')


def test_strict_read_refuses_what_the_lenient_read_keeps_as_written() -> None:
    with pytest.raises(ModelError):
        Robot.from_string(LENIENT)
    robot = Robot.from_string(LENIENT, strict=False)
    joint = robot.joint("j")
    assert joint.origin.xyz == "0.07, 0, -0.69"  # no numbers: its text
    assert joint.origin.rpy == (0, 0, 0, 0)  # numbers, of the wrong count
    assert joint.axis == (0, 0, 0)
    lim = joint.limit
    assert lim is not None
    assert (lim.lower, lim.upper, lim.effort, lim.velocity) == (1.0, "-1.57.", "inf", None)
    sphere = robot.link("a").collisions[0].geometry
    assert isinstance(sphere, Sphere) and sphere.radius == 0.0
    # Building from those values stays refused: assignment is checked as before.
    with pytest.raises(ModelError, match="axis must not be zero"):
        joint.axis = (0, 0, 0)


def test_lenient_read_still_refuses_what_has_no_tree() -> None:
    for bad, message in [
            (LENIENT.replace('type="revolute"', 'type="hinge"'), "unknown joint type"),
            (LENIENT.replace('<link name="b"/>', ""), "does not exist"),
            (LENIENT.replace('<sphere radius="0"/>', '<ball/>'), "unknown shape <ball>"),
            (LENIENT.replace('<link name="a">', '<link>'), "missing attribute 'name'")]:
        with pytest.raises(ModelError, match=message):
            Robot.from_string(bad, strict=False)


@pytest.mark.parametrize(("value", "kept"), [
    ("0", 0.0), (" 1e-1 ", 0.1), ("1 2 3 4", (1.0, 2.0, 3.0, 4.0)), (0, 0.0),
    ("0.07, 0,\n -0.69", "0.07, 0, -0.69"), ("-1.57.", "-1.57."), ("+Infinity", "inf"),
    ("1 nan 0", "1 nan 0"), ("", ""), (None, None), ((1, 2), (1.0, 2.0)),
    ((1, "x"), "1.0 x")])
def test_as_written_keeps_numbers_where_there_are_numbers(value: Any, kept: Any) -> None:
    assert as_written(value) == kept
    assert as_written(as_written(value)) == kept  # idempotent: one broken value, one spelling


# --------------------------------------------------------------------------- inertia


def test_solid_shape_inertia_formulas() -> None:
    box = Box((0.5, 0.3, 0.1)).inertia(6)
    assert (box.ixx, box.iyy, box.izz) == pytest.approx((0.05, 0.13, 0.17))
    cyl = Cylinder(0.1, 0.05).inertia(0.3)
    assert (cyl.ixx, cyl.iyy, cyl.izz) == pytest.approx((0.0008125, 0.0008125, 0.0015))
    sph = Sphere(0.2).inertia(5)
    assert sph.ixx == pytest.approx(0.4 * 5 * 0.04)


def test_rotated_shapes_rotate_their_inertia() -> None:
    # A wheel: cylinder rolled by pi/2 lies along y, so its axial moment moves to iyy.
    wheel = Inertial.from_shapes(0.3, [(Cylinder(0.1, 0.05), Origin(rpy=(math.pi / 2, 0, 0)))])
    t = wheel.inertia
    assert (t.ixx, t.iyy, t.izz) == pytest.approx((0.0008125, 0.0015, 0.0008125))
    assert max(abs(t.ixy), abs(t.ixz), abs(t.iyz)) < 1e-15
    # A 45-degree yaw couples x and y.
    yawed = Inertial.from_shapes(1.0, [(Box((1, 0.1, 0.1)), Origin(rpy=(0, 0, math.pi / 4)))])
    assert yawed.inertia.ixy != pytest.approx(0)
    assert sorted(yawed.inertia.principal_moments) == pytest.approx(
        sorted((Box((1, 0.1, 0.1)).inertia(1).ixx, Box((1, 0.1, 0.1)).inertia(1).iyy,
                Box((1, 0.1, 0.1)).inertia(1).izz)))


def test_compound_shapes_use_parallel_axis_theorem() -> None:
    # Two unit-mass spheres 1 m apart: about the middle, ixx gets 2 * 1 * 0.5^2 from the offset.
    s = Sphere(0.1)
    both = Inertial.from_shapes(2.0, [(s, Origin((0, 0.5, 0))), (s, Origin((0, -0.5, 0)))])
    assert both.origin.xyz == pytest.approx((0, 0, 0))
    own = s.inertia(1).ixx
    assert both.inertia.ixx == pytest.approx(2 * own + 2 * 0.25)
    assert both.inertia.iyy == pytest.approx(2 * own)


def test_complete_inertia_fills_missing_tensors_from_collisions() -> None:
    r = Robot("r")
    r.add_link(Link("a", inertial=Inertial(2.0),
                    collisions=[Collision(Box((1, 1, 1)), Origin((0, 0, 0.5)))]))
    r.complete_inertia()
    i = r.link("a").inertial
    assert i.origin.xyz == pytest.approx((0, 0, 0.5))
    assert i.inertia.ixx == pytest.approx(2 / 6)
    # Writing derives it too, without the caller asking.
    lazy = Robot("r")
    lazy.add_link(Link("a", inertial=Inertial(3.0), collisions=[Collision(Sphere(0.1))]))
    written = Robot.from_string(lazy.to_bytes()).link("a").inertial
    assert written.inertia.ixx == pytest.approx(0.4 * 3 * 0.01)
    mesh_only = Robot("m")
    mesh_only.add_link(Link("a", inertial=Inertial(1.0), collisions=[Collision(Mesh("x.stl"))]))
    with pytest.raises(ModelError, match="cannot derive inertia from mesh"):
        mesh_only.complete_inertia()


def test_pybullet_joint_order_is_depth_first_in_file_order(pb) -> None:
    # Declare joints so that file order and depth-first order differ.
    r = Robot("order")
    for name in ("root", "a", "a1", "b", "b1", "a2"):
        r.add_link(Link(name, inertial=Inertial(0.1, Inertia(1e-3, 0, 0, 1e-3, 0, 1e-3)),
                        collisions=[Collision(Sphere(0.01))]))
    r.add_joint(Joint("root_a", "continuous", "root", "a", axis=(0, 0, 1)))
    r.add_joint(Joint("root_b", "continuous", "root", "b", axis=(0, 0, 1)))
    r.add_joint(Joint("a_a1", "continuous", "a", "a1", axis=(0, 0, 1)))
    r.add_joint(Joint("b_b1", "continuous", "b", "b1", axis=(0, 0, 1)))
    r.add_joint(Joint("a_a2", "continuous", "a", "a2", axis=(0, 0, 1)))
    predicted = [j.name for j in r.pybullet_joint_order()]
    assert predicted == ["root_a", "a_a1", "a_a2", "root_b", "b_b1"]
    p, client = pb
    import tempfile
    from pathlib import Path

    with tempfile.TemporaryDirectory() as d:
        path = Path(d) / "order.urdf"
        r.write(path)
        body = p.loadURDF(str(path), physicsClientId=client)
        actual = [p.getJointInfo(body, i, physicsClientId=client)[1].decode()
                  for i in range(p.getNumJoints(body, physicsClientId=client))]
    assert actual == predicted
