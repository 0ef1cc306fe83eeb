"""Bench section for issue 17: ``urdfkit collisions`` on a 30-link mesh robot.

Goal from the issue: the zero pose plus 100 random poses cost under 5x one ``urdfkit joints``
run of the same robot. Both are timed as fresh subprocesses (imports, loading and mesh
reading included) in the same run::

    python bench/run.py -n 20 collisions_bench

The robot is generated here, not copied from anywhere: a humanoid-like tree of 30 links
(torso, pelvis, a two-joint neck, two 6-joint arms with bolted hands, two 6-joint legs), every link
a convex OBJ mesh of 160 triangles (a faceted capsule), with limits on every joint.
"""

from __future__ import annotations

import math
import sys
from pathlib import Path

BENCH = Path(__file__).resolve().parent
sys.path.insert(0, str(BENCH))

from run import Case, Context  # noqa: E402

#: Highest acceptable ratio of ``collisions --samples 100`` to ``joints`` (the issue's).
RATIO_GOAL = 5.0


def capsule_obj(radius: float, length: float, segments: int = 16, rings: int = 4) -> str:
    """A closed convex faceted capsule along z, from z=0 to z=length, as OBJ text."""
    verts: list[tuple[float, float, float]] = [(0.0, 0.0, -radius)]
    for k in range(1, rings + 1):  # bottom cap, then top cap, ring by ring
        phi = -math.pi / 2 + k * math.pi / (2 * rings)
        verts += [(radius * math.cos(phi) * math.cos(2 * math.pi * i / segments),
                   radius * math.cos(phi) * math.sin(2 * math.pi * i / segments),
                   radius * math.sin(phi)) for i in range(segments)]
    for k in range(rings):
        phi = k * math.pi / (2 * rings)
        verts += [(radius * math.cos(phi) * math.cos(2 * math.pi * i / segments),
                   radius * math.cos(phi) * math.sin(2 * math.pi * i / segments),
                   length + radius * math.sin(phi)) for i in range(segments)]
    verts.append((0.0, 0.0, length + radius))
    faces = []
    top = len(verts)
    for i in range(segments):  # bottom fan (1-based indices)
        faces.append((1, 2 + (i + 1) % segments, 2 + i))
    for ring in range(2 * rings - 1):
        a, b = 2 + ring * segments, 2 + (ring + 1) * segments
        for i in range(segments):
            j = (i + 1) % segments
            faces += [(a + i, a + j, b + j), (a + i, b + j, b + i)]
    last = 2 + (2 * rings - 1) * segments
    for i in range(segments):
        faces.append((last + i, last + (i + 1) % segments, top))
    lines = [f"v {x:.6f} {y:.6f} {z:.6f}" for x, y, z in verts]
    lines += [f"f {a} {b} {c}" for a, b, c in faces]
    return "\n".join(lines) + "\n"


def humanoid(folder: Path) -> Path:
    """Write the 30-link robot and its meshes into ``folder``; return the URDF."""
    folder.mkdir(parents=True, exist_ok=True)
    links: list[str] = []
    joints: list[str] = []

    def link(name: str, radius: float, length: float) -> None:
        mesh = folder / f"{name}.obj"
        mesh.write_text(capsule_obj(radius, length))
        mass = 1000 * math.pi * radius * radius * length
        i = mass * (3 * radius * radius + length * length) / 12
        links.append(
            f'  <link name="{name}">\n    <inertial><origin xyz="0 0 {length / 2:.4f}"/>'
            f'<mass value="{mass:.4f}"/><inertia ixx="{i:.6f}" ixy="0" ixz="0" iyy="{i:.6f}" '
            f'iyz="0" izz="{mass * radius * radius / 2:.6f}"/></inertial>\n'
            f'    <visual><geometry><mesh filename="{mesh.name}"/></geometry></visual>\n'
            f'    <collision><geometry><mesh filename="{mesh.name}"/></geometry></collision>\n'
            "  </link>")

    def joint(name: str, parent: str, child: str, xyz: str, axis: str, rpy: str = "0 0 0",
              lower: float = -1.5, upper: float = 1.5) -> None:
        joints.append(
            f'  <joint name="{name}" type="revolute"><parent link="{parent}"/>'
            f'<child link="{child}"/><origin xyz="{xyz}" rpy="{rpy}"/><axis xyz="{axis}"/>'
            f'<limit lower="{lower}" upper="{upper}" effort="50" velocity="3"/></joint>')

    link("torso", 0.12, 0.35)
    link("pelvis", 0.11, 0.1)
    joint("waist", "torso", "pelvis", "0 0 -0.15", "0 0 1", "3.14159 0 0", -0.8, 0.8)
    link("neck", 0.04, 0.06)
    joint("neck_yaw", "torso", "neck", "0 0 0.5", "0 0 1")
    link("head", 0.09, 0.08)
    joint("neck_pitch", "neck", "head", "0 0 0.1", "0 1 0", lower=-0.6, upper=0.6)
    for side, y in (("left", 1), ("right", -1)):
        parent = "torso"
        chain = [("shoulder_pitch", 0.06, 0.04, f"0 {0.2 * y} 0.42", "0 1 0", f"{-1.57 * y} 0 0"),
                 ("shoulder_roll", 0.05, 0.04, "0 0 0.08", "1 0 0", "0 0 0"),
                 ("upper_arm", 0.045, 0.22, "0 0 0.06", "0 0 1", "0 0 0"),
                 ("elbow", 0.04, 0.04, "0 0 0.26", "0 1 0", "0 0 0"),
                 ("forearm", 0.035, 0.2, "0 0 0.06", "0 0 1", "0 0 0"),
                 ("wrist_pitch", 0.03, 0.03, "0 0 0.24", "0 1 0", "0 0 0"),
                 ("hand", 0.035, 0.08, "0 0 0.05", "0 0 1", "0 0 0")]
        for k, (part, radius, length, xyz, axis, rpy) in enumerate(chain):
            name = f"{side}_{part}"
            link(name, radius, length)
            if k < 6:
                joint(f"{name}_joint", parent, name, xyz, axis, rpy)
            else:  # the hand is bolted to the wrist: a fixed joint, as on real arms
                joints.append(f'  <joint name="{name}_joint" type="fixed"><parent link="{parent}"'
                              f'/><child link="{name}"/><origin xyz="{xyz}"/></joint>')
            parent = name
        parent = "pelvis"
        for k, (part, radius, length, xyz, axis) in enumerate([
                ("hip_yaw", 0.06, 0.04, f"0 {0.1 * y} 0.08", "0 0 1"),
                ("hip_roll", 0.06, 0.04, "0 0 0.08", "1 0 0"),
                ("thigh", 0.06, 0.3, "0 0 0.06", "0 1 0"),
                ("shin", 0.05, 0.3, "0 0 0.38", "0 1 0"),
                ("ankle", 0.04, 0.04, "0 0 0.36", "0 1 0"),
                ("foot", 0.04, 0.1, "0 0 0.06", "1 0 0")]):
            name = f"{side}_{part}"
            link(name, radius, length)
            joint(f"{name}_joint", parent, name, xyz, axis, lower=-1.0 if k else -0.5,
                  upper=1.0 if k else 0.5)
            parent = name
    assert len(links) == 30, len(links)
    path = folder / "humanoid30.urdf"
    path.write_text('<?xml version="1.0"?>\n<robot name="humanoid30">\n'
                    + "\n".join(links + joints) + "\n</robot>\n")
    return path


def cases(ctx: Context) -> list[Case]:
    robot = str(humanoid(ctx.tmp / "humanoid30"))
    return [
        Case("urdfkit joints humanoid30", [*ctx.urdfkit, "joints", robot]),
        Case("urdfkit collisions humanoid30", [*ctx.urdfkit, "collisions", robot],
             [("urdfkit joints humanoid30", RATIO_GOAL)], ok=(0, 1)),
        Case("urdfkit collisions humanoid30 --samples 100",
             [*ctx.urdfkit, "collisions", robot, "--samples", "100"],
             [("urdfkit joints humanoid30", RATIO_GOAL)], ok=(0, 1)),
    ]


if __name__ == "__main__":
    import tempfile

    from urdfkit.checks.collisions import self_collisions
    from urdfkit.sources.resolve import resolve

    with tempfile.TemporaryDirectory() as tmp, resolve(humanoid(Path(tmp))) as r:
        found = self_collisions(r, samples=100)
        print(f"{found.tested} pairs tested over {found.poses} poses; "
              f"{len(found.pairs)} in contact, {len(found.always())} always")
        for x in found.pairs[:10]:
            print(f"  {x.link_a:>22} {x.link_b:<22} {x.distance * 1000:8.1f} mm "
                  f"{x.poses_in_contact:4d}")
