"""The text on ``urdfkit view``'s page: status, findings, joint table, selection (markdown)."""

from __future__ import annotations

import re
from collections.abc import Sequence

from urdfkit.draw.view_model import TINTS, ViewedRobot


def md(text: str) -> str:
    """Text safe inside markdown (no tables or emphasis broken by names)."""
    return re.sub(r"([\\`*_|<>\[\]])", r"\\\1", text)


def status(m: ViewedRobot, error: str | None) -> str:
    """The head line: the robot, its size, and the last reload's error if any."""
    head = f"**{md(m.resolved.robot_name or m.file)}**: {len(m.links)} links, " \
           f"{len(m.joints)} movable joints"
    return head if error is None else \
        f"{head}\n\n**Reload failed**, showing the last good robot: {md(error)}"


def findings(m: ViewedRobot) -> str:
    """Errors and warnings with the links they are about; notes counted."""
    shown = [f for f in m.findings if f.level in ("error", "warning")]
    lines = []
    for f in shown:
        where = f.file if f.line is None else f"{f.file}:{f.line}"
        links = ", ".join(m.finding_links(f))
        lines.append(f"- **{f.level} {f.code}** `{where}`{' (' + links + ')' if links else ''}"
                     f": {md(f.text)}")
    hidden = len(m.findings) - len(shown)
    if hidden:
        lines.append(f"- and {hidden} note(s): `urdfkit check {m.file}`")
    lines += [f"- note: {md(n)}" for n in m.notes]
    return "\n".join(lines) or "No errors or warnings."


def joint_table(m: ViewedRobot) -> str:
    """PyBullet's joint table: index, name, type, child link, limits."""
    rows = ["| # | joint | type | child | limits |", "|---|---|---|---|---|"]
    for j in m.table:
        limits = f"{j.joint_lower_limit:g} .. {j.joint_upper_limit:g}" if j.limited else ""
        rows.append(f"| {j.joint_index} | {md(j.joint_name)} | {j.type_label} | "
                    f"{md(j.link_name)} | {limits} |")
    return "\n".join(rows)


def selection(m: ViewedRobot, link: str) -> str:
    """A selected link: its joint's row, its mass, and the findings about it."""
    row = next((j for j in m.table if j.link_name == link), None)
    lines = [f"**{md(link)}**: " + (
        "the base" if row is None else
        f"child of joint {row.joint_index} **{md(row.joint_name)}** "
        f"({row.type_label}"
        + (f", {row.joint_lower_limit:g} .. {row.joint_upper_limit:g}"
           if row.limited else "") + f"), parent {md(row.parent_link_name)}")]
    view = next(lk for lk in m.links if lk.name == link)
    lines.append(f"mass {view.mass:g} kg")
    for f in m.findings:
        if f.level in TINTS and link in m.finding_links(f):
            where = f.file if f.line is None else f"{f.file}:{f.line}"
            lines.append(f"- **{f.level} {f.code}** `{where}`: {md(f.text)}")
    return "\n\n".join(lines[:2]) + ("\n\n" + "\n".join(lines[2:]) if lines[2:] else "")


def touching(pairs: Sequence[tuple[str, str, float]]) -> str:
    """The links touching at this pose, and by how much."""
    return "\n".join(f"- touching: {md(a)} and {md(b)} "
                     f"({'by' if d < 0 else 'at'} {abs(d) * 1000:.3g} mm)" for a, b, d in pairs)
