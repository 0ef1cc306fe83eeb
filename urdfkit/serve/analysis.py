"""An editor's buffer checked as ``urdfkit check`` checks the file, and read as PyBullet loads it.

:func:`analyse` runs every rule (the guard's included, and ``--target``'s) on the text as it is
in the editor, saved or not: a xacro is expanded as if it held the text, its includes found
beside it, and each finding is placed at the file and line it was written at (an included
file's finding belongs to that file). The robot as PyBullet loads it (the joint and link
tables' facts: index, type, limits, mass, inertia) is kept for hovers.
"""

from __future__ import annotations

import os
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from urdfkit.core.finding import Finding


@dataclass(frozen=True)
class Placed:
    """A finding where it was written: the file (absolute), its 0-based line (-1: none)."""

    path: str
    line: int
    finding: Finding


@dataclass
class Analysis:
    """One version of a buffer, checked.

    Attributes:
        path: The buffer's file (absolute).
        findings: Every finding, placed.
        robot: The URDF as PyBullet loads it (:class:`~urdfkit.formats.robot.LoadedRobot`),
            None where it cannot be read.
        joint_index: PyBullet's index of each joint (depth-first from the root).
        link_index: PyBullet's index of each link (-1: the base).
        urdf: The URDF text checked (a xacro's expansion), for fixes.
        origins: A xacro's expansion's origins (``file:line`` per element, document order).
        written: Where each link and joint of a xacro's expansion was written, by kind and
            name: (file, 0-based line), for a name a macro makes (``${name}``).
    """

    path: str
    findings: list[Placed] = field(default_factory=list)
    robot: Any = None
    joint_index: dict[str, int] = field(default_factory=dict)
    link_index: dict[str, int] = field(default_factory=dict)
    urdf: bytes = b""
    origins: list[str | None] = field(default_factory=list)
    written: dict[tuple[str, str], tuple[str, int]] = field(default_factory=dict)


def is_xacro(path: str) -> bool:
    """Whether the file is xacro (``.xacro``, ``.urdf.xacro``)."""
    return path.endswith(".xacro")


def analyse(path: str, text: str, *, packages: Mapping[str, Path] | None = None,
            xacro_args: Mapping[str, str] | None = None,
            targets: Sequence[str] = (), timeout: float | None = None) -> Analysis:
    """Check ``text`` as the content of ``path``; never raises on bad input (findings say it).

    A xacro's expansion longer than ``timeout`` seconds is stopped and said (``U000``).
    """
    from urdfkit.checks.check import check_file
    from urdfkit.core.errors import InputError, ParameterError
    from urdfkit.sources.expand import Expanded, expand_xacro

    data = text.encode("utf-8")
    display = path
    out = Analysis(path)
    if is_xacro(path):
        try:
            expanded: bytes = expand_xacro(path, xacro_args, timeout=timeout, display=display,
                                           packages=packages, strict_args=False, text=data)
        except (InputError, ParameterError) as e:
            line = (e.line - 1) if e.line else -1
            out.findings.append(Placed(path, line, Finding("U000", "error", e.message, display,
                                                             e.line)))
            return out
        assert isinstance(expanded, Expanded)
        result = check_file(display, path, packages=packages, xacro_args=xacro_args,
                            targets=targets, expanded=expanded)
        out.urdf = bytes(expanded)
        out.origins = list(expanded.origins)
    else:
        result = check_file(display, path, packages=packages, targets=targets, data=data)
        out.urdf = data
    out.findings = [place(path, f) for f in result.findings]
    _read_robot(out)
    return out


def place(path: str, f: Finding) -> Placed:
    """Where a finding belongs: its ``origin`` (xacro's file:line), else its line, else none."""
    if f.origin:
        file, _, line = f.origin.rpartition(":")
        if file and line.isdigit():
            where = os.path.normpath(file if os.path.isabs(file) else
                                     os.path.join(os.getcwd(), file))
            if os.path.realpath(where) == os.path.realpath(path):
                where = path  # the document as the editor named it (xacro resolves links)
            return Placed(where, int(line) - 1, f)
    return Placed(path, (f.line - 1) if f.line else -1, f)


def _read_robot(out: Analysis) -> None:
    """The URDF as PyBullet loads it, and PyBullet's indices, if it can be read."""
    from urdfkit.core.errors import UrdfkitError
    from urdfkit.formats.robot import read_robot
    from urdfkit.model.spec import depth_first
    from urdfkit.model.xmlio import parse_xml

    try:
        root = parse_xml(out.urdf, out.path).getroot()
        robot = read_robot(root, out.path)
    except (UrdfkitError, ValueError, KeyError):
        return
    out.robot = robot
    if out.origins:
        from urdfkit.sources.guard import origin_map

        for el, at in (origin_map(root, out.origins) or {}).items():
            if el.tag in ("link", "joint") and el.getparent() is root:
                p = place(out.path, Finding("", "info", "", out.path, None, at))
                out.written[(str(el.tag), el.get("name") or "")] = (p.path, p.line)
    below: dict[str, list[Any]] = {}
    for j in robot.joints:
        below.setdefault(j.parent, []).append(j)
    order = depth_first(robot.root, below, lambda j: j.child)
    out.joint_index = {j.name: i for i, j in enumerate(order)}
    out.link_index = {robot.root: -1, **{j.child: i for i, j in enumerate(order)}}


def hover_text(analysis: Analysis | None, kind: str, name: str) -> str | None:
    """What PyBullet loads for a link or joint of this name (Markdown), if known."""
    if analysis is None or analysis.robot is None:
        return None
    robot = analysis.robot
    if kind == "joint":
        j = next((j for j in robot.joints if j.name == name), None)
        if j is None:
            return None
        index = analysis.joint_index.get(name)
        lines = [f"**joint `{name}`**: PyBullet index {index}, "
                 f"{j.declared_type or j.type}" + ("" if j.type == j.declared_type
                                                  or not j.declared_type
                                                  else f" (loaded as {j.type})"),
                 f"parent `{j.parent}` -> child `{j.child}`"]
        if j.moves:
            lines.append(f"limits {j.lower:g} .. {j.upper:g}" if j.limited
                         else "no position limit (PyBullet holds none)")
            lines.append(f"effort {j.effort:g}, velocity {j.velocity:g}, "
                         f"damping {j.damping:g}, friction {j.friction:g}")
        return "  \n".join(lines)
    if kind == "link":
        link = robot.links.get(name)
        if link is None:
            return None
        i = link.inertial
        index = analysis.link_index.get(name)
        t = i.tensor
        lines = [f"**link `{name}`**: PyBullet index {index}"
                 + (" (the base)" if index == -1 else ""),
                 f"mass {i.mass:g} kg" + ("" if i.given else
                                          " (no <inertial>: PyBullet's default)"),
                 f"centre of mass {' '.join(f'{c:g}' for c in i.com)}",
                 f"inertia ixx {t[0][0]:g} iyy {t[1][1]:g} izz {t[2][2]:g} "
                 f"ixy {t[0][1]:g} ixz {t[0][2]:g} iyz {t[1][2]:g}"]
        return "  \n".join(lines)
    return None
