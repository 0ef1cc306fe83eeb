"""Does an MJCF agree with the URDF PyBullet loads? Both engines loaded and compared.

The URDF goes into PyBullet (the flags ``export`` mirrors) through the engine seam
(:class:`~urdfkit.engine.pybullet.PyBulletEngine`), the MJCF file into MuJoCo by MuJoCo's own
loader (:class:`~urdfkit.engine.mujoco_file.MjcfFile`: the proof is of the file on disk); links
are matched to bodies or sites and joints to joints, and the two sides answer the same
questions as two :class:`~urdfkit.engine.api.Model` implementations in PyBullet's indices
(:mod:`urdfkit.exchange.agree_sides`). Each comparison is one
:class:`~urdfkit.exchange.agree_report.Row` with its worst figure and its tolerance beside it:

- structure (:mod:`~urdfkit.exchange.agree_structure`): joint names, order, kinds, limits,
  damping (1e-12); total and per-body mass (1e-12 relative) and inertia about the centre of
  mass (1e-9 relative), bodies welded together compared as one; the body tree
  (:mod:`~urdfkit.exchange.agree_tree`); forces MuJoCo alone applies;
- kinematics and dynamics (:mod:`~urdfkit.exchange.agree_poses`): every matched link frame at
  seeded poses, against PyBullet's ``getLinkState`` (float32 inside: 1e-6) and against
  :mod:`urdfkit.formats.fk` (1e-12); the joint-space mass matrix and inverse-dynamics torques
  (1e-9 relative), base fixed on both sides; self-contacts at the poses;
- contacts (:mod:`~urdfkit.exchange.agree_contact`): collision geometry and contact parameters;
- a free swing under gravity (:mod:`~urdfkit.exchange.agree_swing`), MuJoCo set to PyBullet's
  integration, base fixed, and floating where the base is free on both sides.

The MJCF need not be ours: anything matched by name is compared, and what cannot be matched
is listed.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

from urdfkit.exchange.agree_report import Agreement, AgreeOptions


def agree(resolved: Any, model_path: str | Path, options: AgreeOptions | None = None
          ) -> Agreement:
    """Compare ``model_path`` (MJCF) with the resolved URDF as PyBullet loads it.

    Raises:
        InputError: MuJoCo cannot load the MJCF.
        MissingDependencyError: MuJoCo is not installed.
    """
    import numpy as np

    from urdfkit.engine.mujoco_file import open_mjcf
    from urdfkit.engine.pybullet import PyBulletEngine
    from urdfkit.exchange.agree_contact import collisions
    from urdfkit.exchange.agree_poses import poses
    from urdfkit.exchange.agree_sides import sides
    from urdfkit.exchange.agree_structure import structure
    from urdfkit.exchange.agree_swing import swing
    from urdfkit.formats.robot import read_robot

    o = options or AgreeOptions()
    robot = read_robot(resolved.root, resolved.name)
    # a model that diverges says so in its rows (inf, NaN: null in JSON) and in MuJoCo's
    # warnings, not in numpy's or MuJoCo's lines on stderr
    with open_mjcf(model_path) as mjcf, np.errstate(all="ignore"):
        engine = PyBulletEngine()
        try:
            s = sides(robot, mjcf, engine, str(resolved.load_path), str(model_path), o)
            structure(s)
            poses(s)
            collisions(s)
            swing(s)
        finally:
            engine.close()
        s.result.warnings += [w for w in dict.fromkeys(mjcf.run_warnings)
                              if w not in s.result.warnings]
        return s.result
