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

from collections.abc import Mapping, Sequence
from pathlib import Path

from lxml import etree

from urdfkit.checks.targets_drake import CODES as DRAKE_CODES
from urdfkit.checks.targets_drake import rule_drake
from urdfkit.checks.targets_mujoco import CODES as MUJOCO_CODES
from urdfkit.checks.targets_mujoco import rule_mujoco
from urdfkit.checks.targets_pinocchio import CODES as PINOCCHIO_CODES
from urdfkit.checks.targets_pinocchio import rule_pinocchio
from urdfkit.checks.targets_ros import CODES as ROS_CODES
from urdfkit.checks.targets_ros import rule_ros
from urdfkit.core.errors import ParameterError
from urdfkit.core.finding import Finding
from urdfkit.sources.guard import Rule

#: Every target, by name: who reads the file there.
TARGETS: dict[str, str] = {
    "pybullet": "PyBullet 3.2.7 (check's own rules; always on)",
    "ros": "urdfdom, the parser of robot_state_publisher, RViz and MoveIt",
    "pinocchio": "Pinocchio 4 (through urdfdom)",
    "drake": "Drake's URDF parser into a MultibodyPlant (its kinematics and dynamics)",
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
    if not asked:
        raise ParameterError(f"`target` names no target; targets: {', '.join(TARGETS)}",
                             param="target")
    return tuple(t for t in TARGETS if t in asked and t != "pybullet")


#: Each target's code family.
FAMILIES = {"T1": "ros", "T2": "pinocchio", "T3": "drake", "T4": "mujoco"}


def check_selection(select: Sequence[str], targets: Sequence[str]) -> None:
    """Refuse a ``--select`` of target codes whose target is not asked for.

    It would select nothing, and a CI run would pass on nothing.

    Raises:
        ParameterError: naming the ``--target`` the codes need.
    """
    for code in select:
        if not code.startswith("T"):
            continue
        needs = [t for family, t in FAMILIES.items()
                 if family.startswith(code[:2]) or code.startswith(family)]
        if not any(t in targets for t in needs):
            raise ParameterError(f"`select` {code}: {'those are' if len(code) < 4 else 'it is'} "
                                 f"the codes of --target {','.join(needs)}, which is not "
                                 "given: nothing would be selected", param="select")


#: The deepest element urdfdom's XML parser (tinyxml2 11) reads, the root at depth 1: one
#: level more is XML_ELEMENT_DEPTH_EXCEEDED (measured with check_urdf).
TINYXML2_DEPTH = 498


def unparsed(display: str, data: bytes | None, targets: Sequence[str], *,
             base: str | None = None,
             packages: Mapping[str, Path] | None = None) -> list[Finding]:
    """The targets' findings for a file check's own parser refused (its ``U000``).

    urdfdom's XML parser is tinyxml2, which reads what lxml refuses in two ways: bytes that are
    no UTF-8 (kept as they are) and elements nested deeper than lxml's 256 levels (to
    :data:`TINYXML2_DEPTH`). Such a file is parsed again as tinyxml2 would take it and judged
    by the targets' rules; anything else not well-formed, or not readable, they refuse.
    """
    from urdfkit.sources.guard import run_rules

    root = _tinyxml2_tree(data) if data is not None else None
    if root is None or _depth(root) > TINYXML2_DEPTH:
        why = "cannot be read" if data is None else "is not XML its parser (tinyxml2) reads" \
            if root is None else f"nests elements deeper than tinyxml2's {TINYXML2_DEPTH} " \
            "levels (XML_ELEMENT_DEPTH_EXCEEDED)"
        return [Finding(code, "error", f"{who} refuses the file: it {why}", display)
                for target, (code, who) in _UNREADABLE.items() if target in targets]
    return run_rules(root, display, target_rules(targets), base=base, packages=packages)


#: Who refuses a file its XML parser cannot read, by target, and with what code.
_UNREADABLE = {"ros": ("T101", "urdfdom"), "pinocchio": ("T200", "Pinocchio (its urdfdom)"),
               "drake": ("T301", "Drake"), "mujoco": ("T401", "MuJoCo")}


def _tinyxml2_tree(data: bytes) -> etree._Element | None:
    parser = etree.XMLParser(huge_tree=True, resolve_entities=False, no_network=True,
                             load_dtd=False)
    for text in (data, data.decode("utf-8", "replace").encode("utf-8")):
        try:
            return etree.fromstring(text, parser)
        except (etree.XMLSyntaxError, ValueError):
            continue
    return None


def _depth(root: etree._Element) -> int:
    deepest = depth = 0
    for event, _el in etree.iterwalk(root, events=("start", "end")):
        depth += 1 if event == "start" else -1
        deepest = max(deepest, depth)
    return deepest


def target_rules(targets: Sequence[str]) -> tuple[Rule, ...]:
    """The rules of ``targets`` (names :func:`parse_targets` gave), in the targets' order."""
    return tuple(rule for t in targets for rule in RULES.get(t, ()))


# --------------------------------------------------------------------------- the rules

#: Each target's rules.
RULES: dict[str, tuple[Rule, ...]] = {"ros": (rule_ros,), "pinocchio": (rule_pinocchio,),
                                      "drake": (rule_drake,), "mujoco": (rule_mujoco,)}

#: Every target code with a one-line summary (merged into check's codes).
TARGET_CODES: dict[str, str] = {**ROS_CODES, **PINOCCHIO_CODES, **DRAKE_CODES,
                                **MUJOCO_CODES}
