r"""``urdfkit tree --dot``: the kinematic graph as Graphviz DOT, and SVG/PNG/PDF through ``dot``.

Links are boxes, joints are edges from parent to child labelled with the joint's name, type,
axis and limits, and the index PyBullet will give it. The graph is built from the lxml
document by :func:`urdfkit.draw.tree.kinematic_tree`, so no PyBullet is loaded.

Names are written as quoted DOT strings, with ``"`` and ``\`` escaped. Graphviz expands escape
sequences in *labels* (``\N`` becomes the node name, ``\G`` the graph name, ``\n`` a line
break), so doubling backslashes makes a link called ``a\N`` show as ``a\N``. In node IDs the
doubled backslash stays doubled (DOT cannot end a quoted ID with a single one), which is why
every node carries an explicit label with the exact name.
"""

from __future__ import annotations

import shutil
import subprocess
from pathlib import Path

from lxml import etree

from urdfkit.core.errors import MissingDependencyError, OutputError
from urdfkit.core.output import atomic_write, check_output
from urdfkit.draw import style
from urdfkit.model.xmlio import fmt_float, fmt_vec

#: Output suffixes written as DOT text; the others are rendered by the ``dot`` program.
DOT_SUFFIXES = (".dot", ".gv")
RENDERED_SUFFIXES = (".svg", ".png", ".pdf")
#: Seconds ``dot`` may take; a 100-link graph takes well under one.
DOT_TIMEOUT = 30.0

GRAPHVIZ_HINT = ("install Graphviz for the `dot` program (Debian/Ubuntu: sudo apt-get install "
                 "graphviz; macOS: brew install graphviz; conda: conda install graphviz), or "
                 "write DOT text with -o graph.dot")


def quote(text: str) -> str:
    """A DOT quoted string that shows ``text`` literally, also when used as a label."""
    text = text.replace("\\", "\\\\").replace('"', '\\"')
    # A raw line break inside a quoted string is legal DOT but breaks line-based tools;
    # write it as the label escape for a line break instead.
    text = text.replace("\r\n", "\\n").replace("\n", "\\n").replace("\r", "\\n")
    return f'"{text}"'


def _limits(kind: str, limit: tuple[float, float] | None) -> str | None:
    if limit is None:
        return None
    unit = "m" if kind == "prismatic" else "rad"
    return f"[{fmt_float(limit[0], 4)}, {fmt_float(limit[1], 4)}] {unit}"


def dot_graph(root: etree._Element, name: str | None = None) -> str:
    """The kinematic graph of a guarded ``<robot>`` document as DOT text.

    Args:
        root: The ``<robot>`` element (after :func:`urdfkit.sources.guard.guard`, which rules out
            cycles and second parents).
        name: The graph's name; defaults to the robot's name attribute.
    """
    from urdfkit.draw.tree import kinematic_tree

    tree = kinematic_tree(root)
    title = name if name is not None else root.get("name", "robot")
    font = style.FONT_FAMILY
    lines = [
        f"digraph {quote(title)} {{",
        "  rankdir=TB;",
        f"  graph [fontname={quote(font)}, label={quote(title)}, labelloc=t];",
        f'  node [shape=box, style="rounded,filled", fontname={quote(font)}, '
        f'fillcolor="{style.hex_color(style.GROUND)}", color="{style.hex_color(style.TEXT)}"];',
        f'  edge [fontname={quote(font)}, fontsize=9, color="{style.hex_color(style.PRIMARY)}"];',
    ]
    for node in tree.walk():
        extra = ", penwidth=2" if node.joint is None else ""
        lines.append(f"  {quote(node.link)} [label={quote(node.link)}{extra}];")
    edges = sorted(((child.joint, parent.link, child.link) for parent in tree.walk()
                    for child in parent.children if child.joint is not None),
                   key=lambda e: e[0].index)
    for j, parent_link, child_link in edges:  # in PyBullet's joint-index order
        label = [f"[{j.index}] {j.name}", j.type]
        if j.axis is not None:
            label.append(f"axis {fmt_vec([fmt_clean(a) for a in j.axis])}")
        lim = _limits(j.type, j.limit)
        if lim:
            label.append(lim)
        attrs = f"label={quote(chr(10).join(label))}"
        if j.type == "fixed":
            # Fixed joints do not move: drawn dashed and grey, like a weld line.
            attrs += f', style=dashed, color="{style.hex_color(style.GRID)}"'
        lines.append(f"  {quote(parent_link)} -> {quote(child_link)} [{attrs}];")
    lines.append("}")
    return "\n".join(lines) + "\n"


def fmt_clean(x: float) -> float:
    """Round away float noise in an axis (0.7071067811865476 -> 0.7071) for a short label."""
    return round(x, 4) + 0.0


def render_dot(dot: str, fmt: str, timeout: float = DOT_TIMEOUT) -> bytes:
    """Run Graphviz ``dot -T<fmt>`` on DOT text; return the output bytes.

    Raises:
        MissingDependencyError: ``dot`` is not installed (the message says how to get it).
        OutputError: ``dot`` failed or took too long.
    """
    exe = shutil.which("dot")
    if exe is None:
        raise MissingDependencyError(f"-o .{fmt} needs Graphviz: {GRAPHVIZ_HINT}")
    try:
        proc = subprocess.run([exe, f"-T{fmt}"], input=dot.encode("utf-8"),
                              capture_output=True, timeout=timeout)
    except subprocess.TimeoutExpired:
        raise OutputError(f"Graphviz dot took longer than {timeout:g} s and was stopped") \
            from None
    if proc.returncode != 0:
        said = proc.stderr.decode("utf-8", "replace").strip().splitlines()
        raise OutputError(f"Graphviz dot failed: {said[0] if said else proc.returncode}")
    return proc.stdout


def check_graph_path(path: str | Path, *, force: bool = False) -> Path:
    """Refuse an output path early: unknown suffix, or an existing file without ``force``."""
    return check_output(path, force=force, suffixes=DOT_SUFFIXES + RENDERED_SUFFIXES,
                        what="the graph")


def write_graph(dot: str, path: str | Path, *, force: bool = False) -> Path:
    """Write DOT text (``.dot``/``.gv``) or a picture rendered by ``dot`` (``.svg`` ...)."""
    path = check_graph_path(path, force=force)
    suffix = path.suffix.lower()
    data = dot.encode("utf-8") if suffix in DOT_SUFFIXES else render_dot(dot, suffix[1:])
    return atomic_write(path, data, force=force)
