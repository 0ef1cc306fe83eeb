"""Build the servo pendulum of ``pendulum_servo.json`` with the urdfkit builder API.

Run it to (re)write ``pendulum.urdf`` next to this file::

    python examples/pendulum.py

A fixed post with a hinge 1 m up, about y, and an arm that hangs down from it with a 1 kg bob
at its end. Only the bob collides, so the arm's mass sits at the bob and its inertia is the
solid sphere's, derived by the builder from the shape and the mass.
"""

from __future__ import annotations

import math
from pathlib import Path

from urdfkit.builder import (
    Box,
    Collision,
    Cylinder,
    Inertial,
    Joint,
    Limit,
    Link,
    Material,
    Origin,
    Robot,
    Sphere,
    Visual,
)

HERE = Path(__file__).resolve().parent


def build_pendulum(length: float = 0.5, mass: float = 1.0, effort: float = 20.0) -> Robot:
    """A hanging pendulum: joint ``hinge`` at angle 0 points the arm straight down."""
    robot = Robot("pendulum")
    robot.add_material(Material("grey", color=(0.6, 0.6, 0.6, 1)))
    robot.add_material(Material("orange", color=(1.0, 0.5, 0.1, 1)))
    robot.add_link(Link(
        "base_link",
        inertial=Inertial(5.0),
        visuals=[Visual(Box((0.1, 0.1, 1.0)), Origin((0, 0, 0.5)), "grey")],
        collisions=[Collision(Box((0.1, 0.1, 1.0)), Origin((0, 0, 0.5)))],
    ))
    robot.add_link(Link(
        "arm",
        inertial=Inertial(mass),
        visuals=[Visual(Cylinder(0.01, length), Origin((0, 0, -length / 2)), "grey"),
                 Visual(Sphere(0.05), Origin((0, 0, -length)), "orange")],
        collisions=[Collision(Sphere(0.05), Origin((0, 0, -length)))],
    ))
    robot.add_joint(Joint("hinge", "revolute", "base_link", "arm", Origin((0.15, 0, 1.0)),
                          axis=(0, 1, 0), limit=Limit(effort, 20.0, -math.pi, math.pi)))
    return robot


if __name__ == "__main__":
    path = build_pendulum().write(HERE / "pendulum.urdf", force=True)
    print(f"wrote {path}")
