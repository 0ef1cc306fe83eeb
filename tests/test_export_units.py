"""The formats modules on their own: forward kinematics against an independent URDF library
(yourdfpy), rotations against PyBullet's, fused mass properties against a closed form."""

from __future__ import annotations

import math

import numpy as np
import pytest

from urdfkit.formats.fk import link_frames
from urdfkit.formats.mjcf import combine, mat_to_quat
from urdfkit.formats.robot import LoadedInertial, read_robot
from urdfkit.sources.resolve import resolve


@pytest.mark.parametrize("name", ["kuka_iiwa/model.urdf", "r2d2.urdf", "racecar/racecar.urdf"])
def test_forward_kinematics_matches_yourdfpy(name: str) -> None:
    yourdfpy = pytest.importorskip("yourdfpy")  # in the test extra
    with resolve(name) as r:
        robot = read_robot(r.root, r.name)
        other = yourdfpy.URDF.load(str(r.load_path), load_meshes=False,
                                   build_collision_scene_graph=False, load_collision_meshes=False)
    rng = np.random.default_rng(3)
    for _ in range(8):
        q = {j.name: float(rng.uniform(-1, 1)) for j in robot.movable()}
        other.update_cfg({n: q[n] for n in other.actuated_joint_names})
        ours = link_frames(robot, q)
        for link in robot.links:
            theirs = other.get_transform(link, robot.root)
            assert ours[link] == pytest.approx(theirs, abs=1e-12), link


def test_quaternions_agree_with_pybullet() -> None:
    import pybullet as p

    rng = np.random.default_rng(1)
    for _ in range(200):
        rpy = rng.uniform(-math.pi, math.pi, 3)
        x, y, z, w = p.getQuaternionFromEuler(rpy)
        m = np.array(p.getMatrixFromQuaternion((x, y, z, w))).reshape(3, 3)
        q = mat_to_quat(m)
        sign = 1.0 if q[0] * w >= 0 else -1.0  # q and -q are one rotation
        assert np.array(q) * sign == pytest.approx([w, x, y, z], abs=1e-7)  # float32 inside


def test_two_point_masses_fuse_to_the_dumbbell_formula() -> None:
    # two 1 kg points 2 m apart on x: centre between them, I_yy = I_zz = 2 * 1 * 1^2
    point = LoadedInertial(1.0, (0.0, 0.0, 0.0), ((0.0, 0, 0), (0, 0.0, 0), (0, 0, 0.0)))
    left, right = np.eye(4), np.eye(4)
    left[0, 3], right[0, 3] = -1.0, 1.0
    m = combine([(point, left), (point, right)])
    assert m.mass == 2.0 and m.com.tolist() == [0, 0, 0]
    assert np.diag(m.tensor).tolist() == [0, 2, 2]


def test_geom_names_say_each_geoms_link() -> None:
    """With geom_names, every geom of the MJCF is named and Export.geom_links gives the link it
    was written for, fused links included (r2d2's fixed links share their parent's body);
    without it no geom is named (the goldens stay as they are)."""
    from lxml import etree

    from urdfkit.formats.fk import fused
    from urdfkit.formats.mjcf import ExportOptions, export_mjcf

    with resolve("r2d2.urdf") as r:
        robot = read_robot(r.root, r.name)
        named = export_mjcf(robot, ExportOptions(geom_names=True), "a")
        plain = export_mjcf(robot, ExportOptions(), "a")
    geoms = etree.fromstring(named.xml).iter("geom")
    where = fused(robot, split_world=True)
    seen, fused_in = 0, 0
    for g in geoms:
        body = g.getparent().get("name")
        link = named.geom_links[g.get("name")]
        assert where[link][0] == body  # the link's geoms are in the body it was fused into
        seen += 1
        fused_in += link != body
    shapes = sum(len(link.visuals) + len(link.collisions) for link in robot.links.values())
    assert seen == len(named.geom_links) == shapes
    assert fused_in  # r2d2's fixed links' geoms sit in their parents' bodies
    assert not [g for g in etree.fromstring(plain.xml).iter("geom") if g.get("name")]
