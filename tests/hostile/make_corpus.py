"""Generate the hostile URDF corpus into a folder (used by tests/test_hostile.py).

Every case is a file (or, for ``x.urdf``, a directory) that urdfkit must survive: broken XML,
broken trees, broken numbers and physics, missing files, XML attacks. ``make_corpus`` returns
what ``urdfkit check`` must say about each: ``"error"`` (at least one error finding) or
``"ok"`` (no error finding).

Usage: ``python tests/hostile/make_corpus.py OUTDIR``
"""

from __future__ import annotations

import os
import sys
from pathlib import Path

SECRET = "/etc/passwd"

_INERTIAL = ('<inertial><mass value="1"/>'
             '<inertia ixx="0.1" ixy="0" ixz="0" iyy="0.1" iyz="0" izz="0.1"/></inertial>')


def link(name: str, inertial: str = _INERTIAL, extra: str = "") -> str:
    """A link with a valid inertial and a box collision."""
    return (f'<link name="{name}">{inertial}<collision><geometry><box size="0.5 0.5 0.5"/>'
            f'</geometry></collision>{extra}</link>\n')


def joint(name: str, parent: str, child: str, jtype: str = "revolute",
          limit: str = '<limit lower="-1" upper="1" effort="10" velocity="1"/>',
          axis: str = '<axis xyz="0 0 1"/>', extra: str = "") -> str:
    """A joint; the default is a valid revolute joint."""
    return (f'<joint name="{name}" type="{jtype}"><parent link="{parent}"/>'
            f'<child link="{child}"/>{axis}{limit}{extra}</joint>\n')


def robot(body: str, name: str = "r", head: str = "") -> str:
    """A <robot> document."""
    return f'<?xml version="1.0"?>\n{head}<robot name="{name}">\n{body}</robot>\n'


def chain(n: int) -> str:
    """A valid serial chain of ``n`` links."""
    return robot("".join(link(f"l{i}") for i in range(n)) +
                 "".join(joint(f"j{i}", f"l{i}", f"l{i + 1}") for i in range(n - 1)))


TWO = link("a") + link("b")
VALID = robot(TWO + joint("j", "a", "b"))


def cases() -> dict[str, tuple[str | bytes, str]]:
    """File name -> (content, expected check verdict)."""
    laughs = "".join(f'<!ENTITY l{i} "&l{i - 1};&l{i - 1};&l{i - 1};&l{i - 1};&l{i - 1};">'
                     for i in range(1, 10))
    return {
        # --- not a URDF at all
        "empty.urdf": (b"", "error"),
        "whitespace.urdf": (b"  \n\t \n", "error"),
        "binary.urdf": (bytes(range(256)) * 8, "error"),
        "not_xml.urdf": (b"this is not XML {}\n", "error"),
        "truncated.urdf": (VALID[: len(VALID) // 2], "error"),
        "non_utf8.urdf": ('<robot name="r\xe9">'.encode("latin-1") + link("a").encode() +
                          b"</robot>", "error"),
        "root_not_robot.urdf": ('<model name="m">' + link("a") + "</model>", "error"),
        "no_links.urdf": (robot(""), "error"),
        "no_robot_name.urdf": ("<robot>" + link("a") + "</robot>", "error"),
        # --- tree shape
        "missing_parent.urdf": (robot(TWO + '<joint name="j" type="fixed"><child link="b"/>'
                                      "</joint>"), "error"),
        "missing_child_link.urdf": (robot(TWO + joint("j", "a", "ghost")), "error"),
        "two_roots.urdf": (robot(TWO), "error"),
        "cycle_with_root.urdf": (robot(TWO + link("c") + joint("j1", "b", "c") +
                                       joint("j2", "c", "b")), "error"),
        "cycle_without_root.urdf": (robot(TWO + joint("j1", "a", "b") + joint("j2", "b", "a")),
                                    "error"),
        "two_parents.urdf": (robot(TWO + link("c") + joint("j1", "a", "c") +
                                   joint("j2", "b", "c") + joint("j3", "a", "b")), "error"),
        "self_joint.urdf": (robot(TWO + joint("j", "a", "b") + joint("k", "b", "b")), "error"),
        "duplicate_links.urdf": (robot(TWO + link("b") + joint("j", "a", "b")), "error"),
        "duplicate_joints.urdf": (robot(TWO + link("c") + joint("j", "a", "b") +
                                        joint("j", "b", "c")), "error"),
        # --- names
        "percent_link.urdf": (robot(link("a") + link("b%s%n") + joint("j", "a", "b%s%n")),
                              "error"),
        "percent_joint.urdf": (robot(TWO + joint("j%n%n%n", "a", "b")), "error"),
        # PyBullet segfaults on a 5000-character link name (from 2288) or joint name (1264).
        "long_name.urdf": (robot(link("a") + link("b" * 5000) + joint("j", "a", "b" * 5000)),
                           "error"),
        "long_joint_name.urdf": (robot(TWO + joint("j" * 5000, "a", "b")), "error"),
        "name_1000.urdf": (robot(link("a") + link("b" * 1000) + joint("j" * 1000, "a",
                                                                      "b" * 1000)), "ok"),
        # Whitespace inside names, as character references (a literal tab or newline in an
        # attribute is read as a space): fix once exited 3 defining such a material.
        "tab_material.urdf": (robot(link("a", extra='<visual><geometry><box size="1 1 1"/>'
                                         '</geometry><material name="or&#9;ange"/></visual>')),
                              "ok"),
        "newline_material.urdf": (robot(
            '<material name="a&#10;b"><color rgba="1 0 0 1"/></material>'
            + link("a", extra='<visual><geometry><box size="1 1 1"/></geometry>'
                              '<material name="a&#10;b"/></visual>')), "ok"),
        "tab_names.urdf": (robot(link("a&#9;b") + link(" c ") + joint("j&#13;k", "a&#9;b",
                                                                      " c ")), "ok"),
        # --- size
        "chain_127.urdf": (chain(127), "ok"),
        "chain_200.urdf": (chain(200), "error"),
        "chain_5000.urdf": (chain(5000), "error"),
        # --- joints
        "missing_limit.urdf": (robot(TWO + joint("j", "a", "b", limit="")), "error"),
        "unknown_joint_type.urdf": (robot(TWO + joint("j", "a", "b", jtype="wobbly")), "error"),
        "lower_above_upper.urdf": (robot(TWO + joint(
            "j", "a", "b", limit='<limit lower="1" upper="-1" effort="1" velocity="1"/>')),
            "error"),
        "zero_axis.urdf": (robot(TWO + joint("j", "a", "b", axis='<axis xyz="0 0 0"/>')),
                           "error"),
        # --- numbers
        "nan_mass.urdf": (robot(link("a", _INERTIAL.replace('value="1"', 'value="nan"'))),
                          "error"),
        "inf_origin.urdf": (robot(TWO + joint("j", "a", "b", extra='<origin xyz="inf 0 0"/>')),
                            "error"),
        "word_number.urdf": (robot(TWO + joint(
            "j", "a", "b", limit='<limit lower="minus one" upper="1" effort="1" velocity="1"/>')),
            "error"),
        # --- mass and inertia
        "negative_mass.urdf": (robot(link("a", _INERTIAL.replace('value="1"', 'value="-2"'))),
                               "error"),
        "negative_inertia.urdf": (robot(link("a", _INERTIAL.replace('ixx="0.1"', 'ixx="-0.1"'))),
                                  "error"),
        "non_pd_inertia.urdf": (robot(link("a", _INERTIAL.replace('ixy="0"', 'ixy="0.5"'))),
                                "error"),
        "triangle_inertia.urdf": (robot(link("a", _INERTIAL.replace('izz="0.1"', 'izz="0.5"'))),
                                  "error"),
        # --- geometry
        "negative_size.urdf": (robot(link("a").replace('size="0.5 0.5 0.5"', 'size="1 -1 1"')),
                               "error"),
        "two_number_size.urdf": (robot(link("a").replace('size="0.5 0.5 0.5"', 'size="1 1"')),
                                 "error"),
        # --- files
        "missing_mesh.urdf": (robot(link("a", extra='<visual><geometry><mesh filename="nowhere.'
                                             'stl"/></geometry></visual>')), "error"),
        "missing_package_mesh.urdf": (robot(link("a", extra='<visual><geometry><mesh filename='
                                                     '"package://no_such_pkg/m.stl"/></geometry>'
                                                     '</visual>')), "error"),
        # --- XML attacks
        "xxe.urdf": (f'<?xml version="1.0"?>\n<!DOCTYPE robot [<!ENTITY xxe SYSTEM '
                     f'"file://{SECRET}">]>\n<robot name="&xxe;">{link("a")}</robot>\n', "error"),
        "billion_laughs.urdf": (f'<?xml version="1.0"?>\n<!DOCTYPE robot [<!ENTITY l0 "lol">'
                                f'{laughs}]>\n<robot name="&l9;">{link("a")}</robot>\n', "error"),
        # --- valid files
        "valid.urdf": (VALID, "ok"),
        "valid_version00.urdf": (VALID.replace('version="1.0"', 'version="0.0"'), "ok"),
    }


def make_corpus(out: str | Path) -> dict[str, str]:
    """Write every case into ``out``; return file name -> expected verdict."""
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    expected: dict[str, str] = {}
    for name, (content, verdict) in cases().items():
        data = content.encode("utf-8") if isinstance(content, str) else content
        (out / name).write_bytes(data)
        expected[name] = verdict
    # A folder whose name claims to be a URDF file.
    (out / "x.urdf").mkdir(exist_ok=True)
    expected["x.urdf"] = "error"
    # An unreadable file (root reads everything, so it is only an error for other users).
    unreadable = out / "unreadable.urdf"
    unreadable.write_text(VALID)
    unreadable.chmod(0)
    expected["unreadable.urdf"] = "ok" if os.geteuid() == 0 else "error"
    return expected


if __name__ == "__main__":
    if len(sys.argv) != 2:
        sys.exit("usage: make_corpus.py OUTDIR")
    for name, verdict in make_corpus(sys.argv[1]).items():
        print(f"{verdict:5} {name}")
