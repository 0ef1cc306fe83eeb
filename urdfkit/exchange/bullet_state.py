"""Whether PyBullet can report a loaded body's state (its 128-coordinate state queries).

``agree`` compares link frames against ``getLinkState`` and swings against
``getJointStates``; on a body past PyBullet's limits those raise (icub, 212 joints: exit 3
before) or silently answer wrong, so the rows say why they compared nothing instead, while
the exact forward-kinematics row and the dynamics rows still cover every joint and frame.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import TYPE_CHECKING

from urdfkit.model.spec import MAX_STATE_COORDINATES

if TYPE_CHECKING:
    from urdfkit.engine.api import JointInfo


def unreadable_state(joints: Sequence[JointInfo]) -> str:
    """Why PyBullet cannot report this body's state, from its joints, or "".

    ``joints`` are the body's, as :meth:`urdfkit.engine.api.Model.joints` gives them. See
    :data:`urdfkit.model.spec.MAX_STATE_COORDINATES` for what was measured.
    """
    limit = MAX_STATE_COORDINATES
    if len(joints) >= limit:
        return (f"PyBullet's state queries stop at {limit} links: getLinkState, getJointState "
                f"and getBasePositionAndOrientation raise on this body of {len(joints) + 1}")
    past = next((j for j in joints if j.q_index >= limit or j.v_index >= limit), None)
    if past is None:
        return ""
    return (f"PyBullet's state queries hold {limit} coordinates, the base's 7 first: from "
            f"joint {past.name} on this body's joints lie past them (getJointState reads them "
            "as 0; resetting any joint sets them back to 0)")


def unreliable_dynamics(dofs: int) -> str:
    """Why PyBullet's mass matrix and inverse dynamics of ``dofs`` joints are wrong, or "".

    For a fixed base, as agree loads it for the dynamics rows.
    """
    limit = MAX_STATE_COORDINATES
    if dofs <= limit:
        return ""
    return (f"calculateMassMatrix and calculateInverseDynamics answer wrong past {limit} "
            f"degrees of freedom, without an error (this body has {dofs})")
