"""PyBullet's ``changeDynamics`` on the MuJoCo engine: what it carries, and what it names.

A link's mass, inertia and friction, a joint's damping and limits are carried (the fused
MuJoCo body's mass properties recombined, the contact pairs' friction recombined); what MuJoCo
has no counterpart for is refused with why (:data:`NOT_CARRIED`).
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import replace
from typing import Any

from urdfkit.core.errors import ParameterError
from urdfkit.engine.mujoco_world import World

#: The changeDynamics names this engine carries, and those it cannot (each with why).
CARRIED = ("mass", "localInertiaDiagonal", "lateralFriction", "spinningFriction",
           "rollingFriction", "jointDamping", "jointLowerLimit", "jointUpperLimit",
           "linearDamping", "angularDamping", "restitution")
NOT_CARRIED = {
    "contactStiffness": "MuJoCo's contacts are soft by its own solref/solimp, not a spring",
    "contactDamping": "MuJoCo's contacts are soft by its own solref/solimp, not a spring",
    "maxJointVelocity": "MuJoCo has no joint velocity cap (PyBullet's is 100 rad/s)",
    "anisotropicFriction": "MuJoCo's friction is the same in every direction of a contact",
    "frictionAnchor": "MuJoCo's friction has no anchor",
    "ccdSweptSphereRadius": "MuJoCo has no continuous collision detection by swept spheres",
    "contactProcessingThreshold": "MuJoCo makes a contact at a geom's margin (0), no sooner",
    "activationState": "MuJoCo's bodies do not sleep",
    "jointLimitForce": "MuJoCo's joint limits are soft constraints without a force cap",
    "collisionMargin": "MuJoCo's geom margins are fixed when the world is compiled",
}


def change_dynamics(w: World, body: int, link: int,
                    values: dict[str, float | Sequence[float]]) -> None:
    """Change a link's dynamics by PyBullet's ``changeDynamics`` names (see :data:`CARRIED`).

    Raises:
        ParameterError: A name MuJoCo cannot carry (:data:`NOT_CARRIED` says why), or not
            one of PyBullet's, or a value that leaves a moving body without mass.
    """
    w.compiled()
    r, ids = w.body(body)
    target = r.link(link)
    for key, value in values.items():
        check_dynamics(key, value)
        if key.startswith("joint") and link < 0:
            raise ParameterError(f"`{key}`: link -1 is the root, which has no joint",
                                 param=key)
    d = target.dynamics
    changes: dict[str, Any] = {}
    for key, value in values.items():
        if key == "mass":
            changes["mass"] = float(value)  # type: ignore[arg-type]
        elif key == "localInertiaDiagonal":
            v = list(value)  # type: ignore[arg-type]
            changes["inertia"] = (float(v[0]), float(v[1]), float(v[2]))
        elif key in ("lateralFriction", "spinningFriction", "rollingFriction"):
            field = {"lateralFriction": "lateral_friction",
                     "spinningFriction": "spinning_friction",
                     "rollingFriction": "rolling_friction"}[key]
            changes[field] = float(value)  # type: ignore[arg-type]
        elif key == "jointDamping":
            w.damping[(body, link)] = float(value)  # type: ignore[arg-type]
        elif key in ("jointLowerLimit", "jointUpperLimit"):
            lo, hi = w.limits.get((body, link), (ids.joints[link].lower,
                                                     ids.joints[link].upper))
            new = float(value)  # type: ignore[arg-type]
            w.limits[(body, link)] = (new, hi) if key == "jointLowerLimit" else (lo, new)
    old = d
    target.dynamics = replace(d, **changes)
    if "mass" in changes or "inertia" in changes:
        try:
            w.changed.add((body, target.body))
            w.apply_mass(body, target.body)
        except ParameterError:
            target.dynamics = old
            w.apply_mass(body, target.body)
            raise
    w.apply_joints()
    w.apply_pairs()


def check_dynamics(key: str, value: float | Sequence[float]) -> None:
    """Refuse a name MuJoCo cannot carry, or a value it cannot take, naming it."""
    if key in NOT_CARRIED:
        raise ParameterError(f"`{key}`: {NOT_CARRIED[key]}", param=key)
    if key not in CARRIED:
        from urdfkit.core.suggest import hint

        raise ParameterError(f"`{key}` is not a changeDynamics name"
                             f"{hint(key, (*CARRIED, *NOT_CARRIED))}", param=key)
    if key in ("linearDamping", "angularDamping") and value != 0:
        raise ParameterError(f"`{key}` {value!r}: MuJoCo has no per-body velocity damping "
                             "(0 is what it does; PyBullet's default is 0.04)", param=key)
    if key == "restitution" and value != 0:
        raise ParameterError(f"`restitution` {value!r}: MuJoCo's contacts do not bounce by "
                             "a coefficient (0 is what it does)", param=key)
    if key == "localInertiaDiagonal":
        if isinstance(value, (int, float)) or len(value) != 3:
            raise ParameterError("`localInertiaDiagonal` needs 3 values", param=key)
        if not all(math.isfinite(x) and x >= 0 for x in value):
            raise ParameterError(f"`localInertiaDiagonal` must be >= 0, got {value!r}",
                                 param=key)
    elif not isinstance(value, (int, float)) or not math.isfinite(value):
        raise ParameterError(f"`{key}` must be a number, got {value!r}", param=key)
    elif key in ("mass", "lateralFriction", "spinningFriction", "rollingFriction",
                 "jointDamping") and value < 0:
        raise ParameterError(f"`{key}` must be >= 0, got {value!r}", param=key)
