"""The one mass combination (urdfkit.model.massprops) against closed forms of physics: two point
masses are the two-body problem's reduced mass at their distance, and a solid cut into pieces,
joined again, is the solid (a box's m (b^2 + c^2) / 12, a cube's m s^2 / 6), turned and moved
anywhere. The builder, check's collision solid and the MJCF writer each get the same answer
through it."""

from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np
import pytest
from lxml import etree
from typer.testing import CliRunner

from urdfkit.builder import Box, Inertial, Origin
from urdfkit.checks.rules_mass import link_solid
from urdfkit.cli import app
from urdfkit.formats.fk import origin_matrix
from urdfkit.formats.mjcf import combine as fuse
from urdfkit.formats.robot import LoadedInertial
from urdfkit.model.massprops import combine
from urdfkit.model.spec import rpy_to_matrix

ZERO = ((0.0, 0.0, 0.0), (0.0, 0.0, 0.0), (0.0, 0.0, 0.0))


def _box(mass: float, size: tuple[float, float, float]) -> np.ndarray:
    """A solid box's inertia about its centre, in its axes: m (b^2 + c^2) / 12 and so on."""
    a, b, c = size
    return mass / 12 * np.diag([b * b + c * c, a * a + c * c, a * a + b * b])


def _close(got: object, want: np.ndarray, scale: float) -> None:
    assert np.abs(np.array(got) - want).max() <= 1e-14 * scale, (got, want)


def test_two_point_masses_are_the_reduced_mass_at_their_distance() -> None:
    # Two bodies: about their centre of mass I = mu (|r|^2 E - r r^T), mu = m1 m2 / (m1 + m2)
    m1, m2 = 1.5, 0.5
    p1, p2 = np.array([0.3, -1.2, 0.7]), np.array([-0.9, 0.4, 2.1])
    got = combine([(m1, p1.tolist(), ZERO), (m2, p2.tolist(), ZERO)])
    r = p2 - p1
    mu = m1 * m2 / (m1 + m2)
    assert got.mass == 2.0
    assert np.array(got.com) == pytest.approx((m1 * p1 + m2 * p2) / 2.0, abs=1e-15)
    _close(got.tensor, mu * (r @ r * np.eye(3) - np.outer(r, r)), 1.0)


@pytest.mark.parametrize("rpy", [(0.0, 0.0, 0.0), (0.3, -1.1, 2.4), (math.pi / 2, 0.0, 0.7)])
def test_two_halves_of_a_box_are_the_box_turned_and_moved_anywhere(rpy: tuple) -> None:
    mass, (a, b, c) = 3.0, (0.8, 0.5, 0.2)   # the whole box is 2a x b x c
    rot, at = np.array(rpy_to_matrix(rpy)), np.array([0.4, -0.2, 1.3])
    half = _box(mass / 2, (a, b, c))
    parts = [(mass / 2, (at + rot @ np.array([s * a / 2, 0.0, 0.0])).tolist(),
              (rot @ half @ rot.T).tolist()) for s in (-1.0, 1.0)]
    got = combine(parts)
    assert got.mass == mass
    assert np.array(got.com) == pytest.approx(at, abs=1e-15)
    whole = rot @ _box(mass, (2 * a, b, c)) @ rot.T
    _close(got.tensor, whole, float(np.abs(whole).max()))
    assert got.tensor[0][1] == got.tensor[1][0] and got.tensor[1][2] == got.tensor[2][1]


def test_eight_cubes_are_the_cube_of_twice_the_side() -> None:
    s, m = 0.25, 0.125   # eight cubes of side s and mass m: one of side 2s and mass 8m
    parts = [(m, (x * s / 2, y * s / 2, z * s / 2), _box(m, (s, s, s)).tolist())
             for x in (-1, 1) for y in (-1, 1) for z in (-1, 1)]
    got = combine(parts)
    assert got.mass == 8 * m and got.com == (0.0, 0.0, 0.0)
    _close(got.tensor, 8 * m * (2 * s) ** 2 / 6 * np.eye(3), 1.0)


def test_a_total_mass_of_zero_keeps_the_first_centre() -> None:
    got = combine([(0.0, (1.0, 2.0, 3.0), ZERO), (0.0, (4.0, 5.0, 6.0), ZERO)])
    assert got == (0.0, (1.0, 2.0, 3.0), ZERO)


# The three callers: each joins two halves of a 2a x b x c box, turned by RPY and moved to AT.
RPY, AT = (0.3, -1.1, 2.4), (0.4, -0.2, 1.3)
A, B, C, MASS = 0.8, 0.5, 0.2, 3.0


def _halves() -> list[tuple[tuple[float, float, float], tuple[float, float, float]]]:
    """Each half's centre (in the frame the box is turned in) and the box's rpy."""
    rot = np.array(rpy_to_matrix(RPY))
    return [(tuple((np.array(AT) + rot @ np.array([s * A / 2, 0, 0])).tolist()), RPY)
            for s in (-1.0, 1.0)]


def _whole(mass: float) -> np.ndarray:
    rot = np.array(rpy_to_matrix(RPY))
    return rot @ _box(mass, (2 * A, B, C)) @ rot.T


def test_checks_collision_solid_of_two_halves_is_the_box() -> None:
    collisions = "".join(
        f'<collision><origin xyz="{" ".join(map(repr, xyz))}" rpy="{" ".join(map(repr, rpy))}"/>'
        f'<geometry><box size="{A} {B} {C}"/></geometry></collision>' for xyz, rpy in _halves())
    solid = link_solid(etree.fromstring(f'<link name="l">{collisions}</link>'))
    assert solid is not None
    volume = 2 * A * B * C
    assert solid.volume == pytest.approx(volume, rel=1e-15)
    assert np.array(solid.com) == pytest.approx(AT, abs=1e-15)
    whole = _whole(volume)   # per unit density: the volume is the mass
    _close(solid.tensor, whole, float(np.abs(whole).max()))


def test_check_measures_a_link_of_two_halves_against_the_whole_box(tmp_path: Path) -> None:
    # The whole 1.6 x 0.5 x 0.2 box of 3 kg has the trace 3 (2.56 + 0.25 + 0.04) / 6; the file
    # says a twentieth of each moment, and check says so (U605), through the one combination.
    whole = [float(x) / 20 for x in np.diag(_box(MASS, (2 * A, B, C)))]
    path = tmp_path / "halves.urdf"
    path.write_text(
        f'<robot name="r"><link name="base"><inertial><mass value="{MASS}"/><inertia '
        f'ixx="{whole[0]!r}" iyy="{whole[1]!r}" izz="{whole[2]!r}" ixy="0" ixz="0" iyz="0"/>'
        '</inertial>' + "".join(
            f'<collision><origin xyz="{s * A / 2} 0 0"/><geometry><box size="{A} {B} {C}"/>'
            '</geometry></collision>' for s in (-1, 1)) + '</link></robot>')
    r = CliRunner().invoke(app, ["check", str(path), "--json", "--no-cache"])
    said = [f["message"] for f in json.loads(r.stdout)["findings"] if f["code"] == "U605"]
    assert len(said) == 1 and "is 0.05 times what its collision shapes and mass 3 kg imply" \
        in said[0], said


def test_the_builders_inertia_from_two_halves_is_the_box() -> None:
    got = Inertial.from_shapes(MASS, [(Box((A, B, C)), Origin(xyz, rpy)) for xyz, rpy in _halves()])
    assert got.origin.xyz == pytest.approx(AT, abs=1e-15)
    whole = _whole(MASS)
    _close(got.inertia.matrix, whole, float(np.abs(whole).max()))


def test_the_mjcf_writers_body_of_two_fused_halves_is_the_box() -> None:
    # Two links fused into one body, each half's centre of mass at its link's origin.
    half = LoadedInertial(MASS / 2, (0.0, 0.0, 0.0), tuple(map(tuple, _box(MASS / 2, (A, B, C)))))
    got = fuse([(half, origin_matrix(xyz, rpy)) for xyz, rpy in _halves()])
    assert got.mass == MASS
    assert got.com == pytest.approx(AT, abs=1e-15)
    whole = _whole(MASS)
    _close(got.tensor, whole, float(np.abs(whole).max()))
