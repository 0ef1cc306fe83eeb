"""One file loaded and read into a :class:`Report`: what ``joints``, ``links`` and ``info`` show.

Sits above :mod:`urdfkit.engine.joints` (the joint table) and :mod:`urdfkit.engine.body`
(links and summary): both are plain readers of a loaded body, and this module is the one that
loads it. ``body`` is imported only when links or the summary are asked for.
"""

from __future__ import annotations

import re
from collections.abc import Iterator, Sequence
from contextlib import contextmanager
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any

from urdfkit.engine.joints import JointInfo, base_link_name, joint_table
from urdfkit.engine.session import LoadOptions, Session, quiet_stdout
from urdfkit.sources.resolve import Resolved

if TYPE_CHECKING:
    from urdfkit.engine.body import LinkDynamics, Summary


@dataclass
class Report:
    """What a command shows about one file: its data plus what PyBullet said on the way.

    Attributes:
        file: The file as the user named it.
        path: The file found on disk (for example inside pybullet_data).
        robot: The ``<robot name>``.
        base_link: PyBullet's root link.
        joints: The joint table.
        links: The link table (``urdfkit links`` only).
        summary: The summary (``urdfkit info`` only).
        diagnostics: PyBullet's own output (warnings), captured off stdout.
        load_flags: The ``loadURDF`` flags the robot was loaded with, by name.
    """

    file: str
    path: str
    robot: str
    base_link: str
    joints: list[JointInfo] = field(default_factory=list)
    links: list[LinkDynamics] = field(default_factory=list)
    summary: Summary | None = None
    diagnostics: list[str] = field(default_factory=list)
    load_flags: list[str] = field(default_factory=list)

    def header(self) -> dict[str, Any]:
        """The keys every ``--json`` output starts with."""
        return {"file": self.file, "path": self.path, "robot": self.robot,
                "base_link": self.base_link, "load_flags": list(self.load_flags)}


@contextmanager
def loaded(resolved: Resolved, options: LoadOptions | None = None) -> Iterator[tuple[Session, int]]:
    """A fresh DIRECT session with the resolved file loaded; disconnected on exit."""
    with Session() as s:
        body = s.load_urdf(resolved.load_path, options, display=resolved.name)
        yield s, body


def inspect_file(resolved: Resolved, options: LoadOptions | None = None, *,
                 links: bool = False, info: bool = False) -> Report:
    """Load a resolved file and read its joint table, and optionally links and summary."""
    options = options or LoadOptions()
    with loaded(resolved, options) as (s, body):
        # One capture around all the queries instead of a temp file per PyBullet call (the
        # inner quiet_stdout blocks are re-entrant no-ops). Loading stays outside it, so a
        # refused file's error message can quote what PyBullet said.
        with quiet_stdout() as out:
            joints = joint_table(s, body, resolved.root)
            report = Report(resolved.name, str(resolved.source), resolved.robot_name,
                            base_link_name(s, body), joints)
            if links or info:
                from urdfkit.engine.body import link_table, summary

            if links:
                report.links = link_table(s, body, resolved.root, joints)
            if info:
                report.summary = summary(s, body, resolved.root, options.fixed_base)
    # After close(), so disconnect's own chatter is included too.
    report.diagnostics = tidy_diagnostics([*s.diagnostics, *out.lines])
    return report


#: The location prefix of PyBullet's b3Warning/b3Error/b3Printf output: source file and line.
_B3_PREFIX = re.compile(r"b3(?:Warning|Error)\[[^\]]*\]:\s*|b3Printf:\s*")


def tidy_diagnostics(lines: Sequence[str]) -> list[str]:
    """PyBullet's captured output as readable, de-duplicated messages.

    PyBullet writes each warning as ``b3Warning[file.cpp,126]:``, a newline, then text with no
    newline after it, so messages run into the next prefix; and it reports the link a warning
    is about as a separate warning of its own. Drop the prefixes, and fold the link name back into
    the "No inertial data for link" message it belongs to.
    """
    parts = [p.strip() for p in _B3_PREFIX.split("\n".join(lines))]
    parts = [p for chunk in parts for p in chunk.splitlines() if p.strip()]
    out: list[str] = []
    i = 0
    while i < len(parts):
        msg = parts[i]
        if msg.startswith("No inertial data for link") and i + 1 < len(parts) and \
                " " not in parts[i + 1]:
            msg = msg.replace("for link,", f"for link {parts[i + 1]!r},", 1)
            i += 1
        out.append(msg)
        i += 1
    return list(dict.fromkeys(out))
