"""Property: on random trees built with urdfkit.builder and then broken, check and the guard
agree, and whatever the guard lets through loads in PyBullet without crashing."""

from __future__ import annotations

import copy

from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from lxml import etree

from urdfkit.builder import Box, Collision, Inertial, Joint, Limit, Link, Robot
from urdfkit.checks.validate import ALL_RULES
from urdfkit.core.errors import InputError
from urdfkit.sources.guard import guard, guard_findings, run_rules

MUTATIONS = ("none", "drop_link", "duplicate_link", "duplicate_joint", "cycle", "corrupt_number")


@st.composite
def robots(draw: st.DrawFn) -> Robot:
    n = draw(st.integers(min_value=1, max_value=8))
    robot = Robot(name="prop")
    for i in range(n):
        size = tuple(draw(st.floats(0.05, 2.0)) for _ in range(3))
        robot.add_link(Link(name=f"l{i}", inertial=Inertial(mass=draw(st.floats(0.1, 10.0))),
                            collisions=[Collision(geometry=Box(size=size))]))
    for i in range(1, n):
        parent = draw(st.integers(0, i - 1))
        jtype = draw(st.sampled_from(["fixed", "continuous", "revolute", "prismatic"]))
        limit = Limit(lower=-1, upper=1, effort=5, velocity=1) \
            if jtype in ("revolute", "prismatic") else None
        robot.add_joint(Joint(name=f"j{i}", type=jtype, parent=f"l{parent}", child=f"l{i}",
                              axis=(0, 0, 1) if jtype != "fixed" else None, limit=limit))
    robot.complete_inertia()
    return robot


def mutate(root: etree._Element, how: str, pick: int) -> bool:
    """Break ``root`` in place; False if this robot is too small for the mutation."""
    links, joints = root.findall("link"), root.findall("joint")
    if how in ("duplicate_joint", "cycle", "drop_link") and not joints:
        return False
    if how == "drop_link" and len(links) > 1:
        root.remove(links[pick % len(links)])
    elif how == "duplicate_link":
        root.append(copy.deepcopy(links[pick % len(links)]))
    elif how == "duplicate_joint" and joints:
        root.append(copy.deepcopy(joints[pick % len(joints)]))
    elif how == "cycle" and joints:
        j = copy.deepcopy(joints[pick % len(joints)])
        j.set("name", "back")
        p, c = j.find("parent"), j.find("child")
        p.set("link", c.get("link")), c.set("link", root.findall("link")[0].get("name"))
        root.append(j)
    elif how == "corrupt_number":
        el = root.findall(".//mass")[pick % len(links)]
        el.set("value", ["nan", "-inf", "heavy", "1 2"][pick % 4])
    return how != "none"


@settings(max_examples=50, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(robot=robots(), how=st.sampled_from(MUTATIONS), pick=st.integers(0, 100))
def test_check_and_guard_agree(robot: Robot, how: str, pick: int, tmp_path_factory) -> None:
    root = robot.to_element()
    broken = mutate(root, how, pick)
    root = etree.fromstring(etree.tostring(root))  # fresh line numbers
    guard_codes = {f.code for f in guard_findings(root, "p.urdf")}
    check_codes = {f.code for f in run_rules(root, "p.urdf", ALL_RULES) if f.level == "error"}
    try:
        guard(root, "p.urdf")
        refused = False
    except InputError:
        refused = True
    assert refused == bool(guard_codes)
    assert guard_codes <= check_codes
    if not broken:
        assert check_codes == set()
    elif how in ("duplicate_link", "duplicate_joint", "cycle", "drop_link"):
        assert refused
    if how == "corrupt_number":
        assert "U401" in check_codes or "U402" in check_codes
    if not refused:
        # What the guard lets through must not crash PyBullet (it may refuse it politely).
        from urdfkit.engine.session import Session

        path = tmp_path_factory.mktemp("prop") / "p.urdf"
        path.write_bytes(etree.tostring(root))
        with Session() as s:
            try:
                body = s.load_urdf(path)
            except Exception as e:  # EngineError: a clean refusal is fine
                assert type(e).__name__ == "EngineError"
            else:
                assert s.call("getNumJoints", body) == len(root.findall("joint"))
