"""``fix``'s repairs carried back into the xacro they came from, for an editor's code action.

``fix`` edits URDF and refuses xacro, whose values may come from macros and properties. Where
they do not, the repair can be written where the value is: ``fix`` runs on the xacro's
expansion, each element it changed is found where xacro says it was written (its origin), and
each changed attribute whose value is written there as a plain number is replaced by ``fix``'s
new value. A change that cannot be carried back so (a value from ``${}``, an element ``fix``
added or one written in another file) means no action: a partial repair would leave a file
``check`` still flags.
"""

from __future__ import annotations

import os
import re
from collections.abc import Mapping
from pathlib import Path
from typing import Any

from urdfkit.serve.document import read

_NUMBER = re.compile(r"\s*[-+0-9.eE ]+\s*")


def xacro_fix(path: str, text: str, codes: set[str], analysis: Any,
              packages: Mapping[str, Path]) -> tuple[str, str] | None:
    """The xacro text with ``fix``'s repairs of its expansion written in, and what they were.

    None when no asked-for code is one fix repairs, the expansion is not the text's (a newer
    text is being checked), or a repair cannot be carried back.
    """
    from lxml import etree

    from urdfkit.checks.fix import FIXABLE, fix_file
    from urdfkit.core.errors import UrdfkitError
    from urdfkit.sources.guard import origin_map

    if analysis is None or not analysis.urdf or not codes & set(FIXABLE):
        return None
    stand_in = os.path.join(os.path.dirname(path), ".urdfkit-expanded.urdf")
    try:  # (the stand-in names the folder meshes are found from; it is never written)
        result = fix_file(stand_in, packages=packages, buffer=analysis.urdf)
    except (UrdfkitError, ValueError):
        return None
    if not result.changed:
        return None
    before = etree.fromstring(analysis.urdf)
    after = etree.fromstring(result.fixed)
    old, new = list(before.iter(etree.Element)), list(after.iter(etree.Element))
    origins = origin_map(before, analysis.origins)
    if len(old) != len(new) or origins is None:
        return None
    edits = _edits(path, text, old, new, origins)
    if edits is None:
        return None
    out = text
    for start, end, value in sorted(edits, reverse=True):
        out = out[:start] + value + out[end:]
    done = sorted({r.code for r in result.repairs})
    return out, f"{len(result.repairs)} repair(s) ({', '.join(done)}) in the xacro"


def _edits(path: str, text: str, old: list[Any], new: list[Any],
           origins: Mapping[Any, str]) -> list[tuple[int, int, str]] | None:
    """(start, end, new value) per changed attribute, or None if one cannot be carried back."""
    doc = read(text)
    out: list[tuple[int, int, str]] = []
    for a, b in zip(old, new, strict=True):
        if a.tag != b.tag:
            return None
        changed = {k: v for k, v in b.attrib.items() if a.get(k) != v}
        if not changed and set(a.attrib) == set(b.attrib):
            continue
        if set(a.attrib) != set(b.attrib):
            return None  # fix added or removed an attribute: not carried back
        at = origins.get(a)
        if at is None:
            return None
        file, _, line = at.rpartition(":")
        where = file if os.path.isabs(file) else os.path.join(os.getcwd(), file)
        if os.path.normpath(where) != os.path.normpath(path) or not line.isdigit():
            return None  # written in another file
        tag = next((t for t in doc.tags if t.name == a.tag
                    and doc.position(t.start)[0] == int(line) - 1), None)
        if tag is None:
            return None
        for key, value in changed.items():
            written = tag.attrs.get(key)
            if written is None or not _NUMBER.fullmatch(written[2]):
                return None  # from ${} or a macro parameter: the number is not here
            out.append((written[0], written[1], value))
    return out
