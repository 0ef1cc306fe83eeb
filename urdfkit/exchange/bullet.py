"""What PyBullet computes for a URDF that the MJCF writer mirrors (its recomputed inertia)."""

from __future__ import annotations

from typing import Any

from urdfkit.exchange.robot import Inertial


def loaded_inertials(resolved: Any, *, inertia_from_file: bool) -> dict[str, Inertial]:
    """Each link's mass properties as PyBullet loads them, in the link frame.

    Without ``inertia_from_file`` PyBullet discards the file's ``<inertia>`` and computes one
    from the collision shapes' bounding boxes (a link without collision shapes gets a tiny
    sphere's, 6.7e-7 for 1 kg): ``export --inertia-from-shapes`` writes these.
    """
    import numpy as np

    from urdfkit.engine.session import LoadOptions, Session
    from urdfkit.model.spec import quat_to_matrix

    with Session() as s:
        body = s.load_urdf(resolved.load_path, LoadOptions(inertia_from_file=inertia_from_file),
                           resolved.name)
        b = s.bullet
        names = {-1: b.getBodyInfo(body)[0].decode("utf-8", "replace")}
        for i in range(b.getNumJoints(body)):
            names[i] = b.getJointInfo(body, i)[12].decode("utf-8", "replace")
        out = {}
        for i, name in names.items():
            d = b.getDynamicsInfo(body, i)
            r = np.array(quat_to_matrix(d[4]))
            t = r @ np.diag(d[2]) @ r.T
            out[name] = Inertial(float(d[0]), (d[3][0], d[3][1], d[3][2]),
                                 ((t[0, 0], t[0, 1], t[0, 2]), (t[1, 0], t[1, 1], t[1, 2]),
                                  (t[2, 0], t[2, 1], t[2, 2])))
    return out
