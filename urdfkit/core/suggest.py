"""'Did you mean': close matches for names a user mistyped (pure, no I/O but a folder listing).

Every refusal of an unknown name (a template, a ``--set`` key, a xacro ``--arg``, a joint,
a file) ends with the closest known names, so the fix is one copy-paste away.
"""

from __future__ import annotations

import difflib
import os
from collections.abc import Iterable
from pathlib import Path

from urdfkit.core import deps

ROBOT_SUFFIXES = (".urdf", ".xacro", ".urdf.xacro")


def close(word: str, choices: Iterable[str], n: int = 3, cutoff: float = 0.6) -> list[str]:
    """The up to ``n`` choices closest to ``word``, best first (case-insensitive).

    Runners-up are kept only when nearly as close as the best, so a typo gets one answer
    and a real ambiguity gets a few.
    """
    by_lower: dict[str, str] = {}
    for c in choices:
        by_lower.setdefault(c.lower(), c)
    key = word.lower()
    scored = []
    for lower, original in by_lower.items():
        m = difflib.SequenceMatcher(None, key, lower)
        if m.real_quick_ratio() >= cutoff and m.quick_ratio() >= cutoff:
            ratio = m.ratio()
            if ratio >= cutoff:
                scored.append((ratio, original))
    scored.sort(key=lambda t: -t[0])
    if not scored:
        return []
    best = scored[0][0]
    return [name for ratio, name in scored[:n] if ratio >= best - 0.05]


def hint(word: str, choices: Iterable[str], n: int = 3) -> str:
    """``"; did you mean 'a' or 'b'?"``, or ``""`` when nothing is close."""
    found = close(word, choices, n=n)
    if not found:
        return ""
    quoted = [repr(f) for f in found]
    listed = quoted[0] if len(quoted) == 1 else ", ".join(quoted[:-1]) + f" or {quoted[-1]}"
    return f"; did you mean {listed}?"


def _robot_files(folder: Path, limit: int = 2000) -> list[str]:
    """The robot-file names in ``folder`` (not recursive; bounded for huge folders)."""
    out: list[str] = []
    deps.note_listing(folder)
    try:
        with os.scandir(folder) as it:
            for entry in it:
                if entry.name.endswith(ROBOT_SUFFIXES):
                    out.append(entry.name)
                    if len(out) >= limit:
                        break
    except OSError:
        pass
    return out


def files(name: str, data_dir: Path | None = None) -> list[str]:
    """Robot files whose names are close to ``name``: beside it, then in pybullet_data.

    ``name`` may lack its suffix (``r2d2`` finds ``r2d2.urdf``). Matches in the folder are
    returned as paths the user can pass back; pybullet_data matches as bare names, which
    every loading command looks up there.
    """
    path = Path(name)
    stem = path.name
    found: list[str] = []
    folder = path.parent
    local = _robot_files(folder)
    exact = [f for f in local if f.split(".")[0] == stem.split(".")[0]]
    for match in exact or close(stem, local):
        found.append(str(folder / match) if str(folder) != "." else match)
    if data_dir is not None and not path.is_absolute():
        base = data_dir / folder
        remote = _robot_files(base)
        exact = [f for f in remote if f.split(".")[0] == stem.split(".")[0]]
        for match in exact or close(stem, remote):
            rel = (folder / match).as_posix()
            if rel not in found:
                found.append(rel)
    return found[:3]
