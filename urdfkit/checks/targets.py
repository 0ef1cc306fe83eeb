"""``check --target``: what each consumer the file goes to refuses, or silently changes.

A URDF rarely stays in PyBullet: ROS (robot_state_publisher, RViz and MoveIt parse it with
urdfdom), Pinocchio, Drake and MuJoCo's own URDF reader each read it their own way. For each
target asked for, the rules here predict, from the file alone and with none of those engines
installed:

- an **error** where the consumer refuses the file, with the consumer's own reason;
- a **warning** where it loads the file but holds something PyBullet does not (a link without
  ``<inertial>``: 1 kg in PyBullet, 0 kg in Pinocchio);
- **info** where only the structure differs (a fixed link fused away, a continuous joint's
  two coordinates).

Codes: ``T1xx`` ROS (urdfdom), ``T2xx`` Pinocchio, ``T3xx`` Drake, ``T4xx`` MuJoCo's reader.
PyBullet is always a target: check's own rules are its. Every rule was read in the
consumer's source and is proven against the consumer itself by
``tests/test_check_targets.py``, which loads each rule's fixture in the real engine.
"""

from __future__ import annotations

from collections.abc import Sequence

from urdfkit.checks.targets_pinocchio import CODES as PINOCCHIO_CODES
from urdfkit.checks.targets_pinocchio import rule_pinocchio
from urdfkit.checks.targets_ros import CODES as ROS_CODES
from urdfkit.checks.targets_ros import rule_ros
from urdfkit.core.errors import ParameterError
from urdfkit.sources.guard import Rule

#: Every target, by name: who reads the file there.
TARGETS: dict[str, str] = {
    "pybullet": "PyBullet 3.2.7 (check's own rules; always on)",
    "ros": "urdfdom, the parser of robot_state_publisher, RViz and MoveIt",
    "pinocchio": "Pinocchio 4 (through urdfdom)",
    "drake": "Drake's URDF parser",
    "mujoco": "MuJoCo's own URDF reader (not urdfkit's export)",
}


def parse_targets(items: Sequence[str] | None) -> tuple[str, ...]:
    """``--target`` values, comma-separated: the targets beyond PyBullet, in a fixed order.

    Raises:
        ParameterError: a name that is no target (with the nearest one).
    """
    if not items:
        return ()
    from urdfkit.core.suggest import hint

    asked: set[str] = set()
    for item in items:
        for name in (n.strip().lower() for n in item.split(",")):
            if not name:
                continue
            if name not in TARGETS:
                raise ParameterError(f"`target` {name!r}: no such target; targets: "
                                     f"{', '.join(TARGETS)}{hint(name, TARGETS)}",
                                     param="target")
            asked.add(name)
    return tuple(t for t in TARGETS if t in asked and t != "pybullet")


def target_rules(targets: Sequence[str]) -> tuple[Rule, ...]:
    """The rules of ``targets`` (names :func:`parse_targets` gave), in the targets' order."""
    return tuple(rule for t in targets for rule in RULES.get(t, ()))


# --------------------------------------------------------------------------- the rules

#: Each target's rules.
RULES: dict[str, tuple[Rule, ...]] = {"ros": (rule_ros,), "pinocchio": (rule_pinocchio,)}

#: Every target code with a one-line summary (merged into check's codes).
TARGET_CODES: dict[str, str] = {**ROS_CODES, **PINOCCHIO_CODES}
