"""The text on ``urdfkit view``'s page: status, findings, joint table, selection (markdown)."""

from __future__ import annotations

import math
import re
from collections.abc import Sequence

from urdfkit.draw.view_model import COLLISION_RGB, SELECTED_RGB, TINTS, TOUCHING_RGB, ViewedRobot

#: Characters a slider's number box shows whole: viser's box is 3 rem wide ("-2.0944" fits,
#: "-0.09985" is cut; measured in Chromium with the page's fonts).
BOX_CHARS = 7


def box_digits(lo: float, hi: float, step: float) -> int:
    """Decimals a slider shows: two significant digits of its step, as many as its box shows.

    viser shows (and the page rounds a slider's values to) enough decimals for the slider's
    ends and step: 7 for a joint at +-2.0943951 rad, more than its box shows ("3.00000" of a
    replay whose last time is 3.0000000000000013 s).
    """
    whole = max(len(str(int(abs(x)))) + (x < 0) for x in (lo, hi))
    need = 1 - math.floor(math.log10(step)) if step > 0 else 0
    return max(0, min(BOX_CHARS - whole - 1, need))


#: Lets a long name break anywhere: a joint name longer than the panel is wide wraps, never cut.
WRAP = "overflow-wrap:anywhere"


def md(text: str) -> str:
    """Text safe inside markdown, wrapping anywhere (no table, emphasis or HTML made by names).

    viser renders raw HTML in markdown (scripts included), so ``<`` is escaped like the
    characters markdown uses; the span lets a name with no spaces wrap in the panel.
    """
    return f'<span style="{WRAP}">{_escape(text)}</span>'


def _escape(text: str) -> str:
    return re.sub(r"([\\`*_|<>\[\]&#!])", r"\\\1", text)


def code(text: str) -> str:
    r"""Text shown as code (a file, a command), escaped as :func:`md` and wrapping anywhere.

    A markdown code span shows its text as it is, backslashes included (a path's ``_``
    escaped for markdown showed as ``kuka\_iiwa``), and cannot wrap a long path: an HTML
    ``code`` element's text is markdown, escaped as any other.
    """
    return f'<code style="{WRAP}">{_escape(text)}</code>'


#: Characters a finding's button shows on its one line in the docked panel (measured in
#: Chromium: 40 of "U604 line 12: ..." fit).
BUTTON_CHARS = 38


def finding_button(code: str, where: str, link: str) -> str:
    """A finding button's label, ``U604 line 12: upper_arm``, on one line.

    A button does not wrap: a link name too long for it keeps its end (where names of one
    robot differ: ``left_arm_link_7``, ``right_arm_link_7``) after an ellipsis; the button's
    hint has it whole.
    """
    head = f"{code} {where}: "
    room = max(BUTTON_CHARS - len(head), 12)
    return head + (link if len(link) <= room else "\u2026" + link[-(room - 1):])


def status(m: ViewedRobot, error: str | None) -> str:
    """The head line: the robot, its size, and the last reload's error if any."""
    head = f"**{md(m.resolved.robot_name or m.file)}**: {len(m.links)} links, " \
           f"{len(m.joints)} movable joints"
    return head if error is None else \
        f"{head}\n\n**Reload failed**, showing the last good robot: {md(error)}"


def legend() -> str:
    """What each colour the page may paint means (the robot's own colours otherwise)."""
    def swatch(rgb: tuple[int, int, int], what: str) -> str:
        hexc = "#{:02x}{:02x}{:02x}".format(*rgb)
        return f'<span style="color:{hexc}">&#9632;</span> {what}'

    return "  \n".join((
        "Colours: PyBullet's own, except",
        swatch(TINTS["error"], "a link with an error (Tint findings)"),
        swatch(TINTS["warning"], "a link with a warning (Tint findings)"),
        swatch(TOUCHING_RGB, "links touching (Self-collisions)"),
        swatch(SELECTED_RGB, "the selected link"),
        swatch(COLLISION_RGB, "collision shapes; pink: the hull of a concave mesh")))


def findings(m: ViewedRobot) -> str:
    """Each finding once: the file's, and those on no link (a button stands for the others)."""
    shown = [f for f in m.findings if f.level in ("error", "warning")]
    lines = [f"In {code(m.file)}:"] if shown else []
    on_links = 0
    for f in shown:
        if m.finding_links(f):
            on_links += 1
            continue
        where = f.file if f.line is None else f"{f.file}:{f.line}"
        lines.append(f"- **{f.level} {f.code}** {code(where)}: {md(f.text)}")
    if on_links:
        lines.append(f"- {on_links} on links, below: a button selects its link and shows "
                     "the finding")
    hidden = len(m.findings) - len(shown)
    if hidden:
        lines.append(f"- and {hidden} note(s): {code('urdfkit check ' + m.file)}")
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
            lines.append(f"- **{f.level} {f.code}** {code(where)}: {md(f.text)}")
    return "\n\n".join(lines[:2]) + ("\n\n" + "\n".join(lines[2:]) if lines[2:] else "")


def touching(pairs: Sequence[tuple[str, str, float]]) -> str:
    """The links touching at this pose, and by how much."""
    return "\n".join(f"- touching: {md(a)} and {md(b)} "
                     f"({'by' if d < 0 else 'at'} {abs(d) * 1000:.3g} mm)" for a, b, d in pairs)
