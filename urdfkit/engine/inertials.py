"""Each link's mass properties and contact parameters as PyBullet loads a URDF.

What another engine must be given to simulate the robot PyBullet simulates: PyBullet
diagonalises a tensor with products of inertia (its Jacobi sweeps), gives a link without
``<inertial>`` 1 kg and unit inertia, zeroes a tensor that breaks the triangle inequality, and
without ``URDF_USE_INERTIA_FROM_FILE`` discards ``<inertia>`` for one it computes from the
collision shapes' bounding boxes. ``urdfkit export`` writes these (through
:func:`urdfkit.exchange.bullet.loaded_inertials`), and the MuJoCo engine builds its model from
them (:mod:`urdfkit.engine.mujoco`).
"""

from __future__ import annotations

from pathlib import Path

from urdfkit.engine.api import LinkDynamics

Matrix = tuple[tuple[float, float, float], tuple[float, float, float],
               tuple[float, float, float]]


def loaded_dynamics(path: str | Path, *, inertia_from_file: bool,
                    display: str | None = None) -> dict[str, LinkDynamics]:
    """Every link's ``getDynamicsInfo`` by name, from a floating load of a guarded URDF."""
    from urdfkit.engine.session import LoadOptions, Session

    with Session() as s:
        body = s.load_urdf(path, LoadOptions(inertia_from_file=inertia_from_file), display)
        b = s.bullet
        names = {-1: b.getBodyInfo(body)[0].decode("utf-8", "replace")}
        for i in range(b.getNumJoints(body)):
            names[i] = b.getJointInfo(body, i)[12].decode("utf-8", "replace")
        out = {}
        for i, name in names.items():
            d = b.getDynamicsInfo(body, i)
            out[name] = LinkDynamics(
                mass=float(d[0]), inertia=_vec(d[2]), inertial_position=_vec(d[3]),
                inertial_orientation=(float(d[4][0]), float(d[4][1]), float(d[4][2]),
                                      float(d[4][3])),
                lateral_friction=float(d[1]), rolling_friction=float(d[6]),
                spinning_friction=float(d[7]), restitution=float(d[5]),
                contact_stiffness=float(d[9]), contact_damping=float(d[8]))
    return out


def link_tensor(d: LinkDynamics) -> Matrix:
    """The inertia tensor about the centre of mass in the link frame's axes: R diag(I) R^T."""
    import numpy as np

    from urdfkit.model.spec import quat_to_matrix

    r = np.array(quat_to_matrix(d.inertial_orientation))
    t = r @ np.diag(d.inertia) @ r.T
    return ((float(t[0, 0]), float(t[0, 1]), float(t[0, 2])),
            (float(t[1, 0]), float(t[1, 1]), float(t[1, 2])),
            (float(t[2, 0]), float(t[2, 1]), float(t[2, 2])))


def _vec(v: tuple[float, ...]) -> tuple[float, float, float]:
    return (float(v[0]), float(v[1]), float(v[2]))
