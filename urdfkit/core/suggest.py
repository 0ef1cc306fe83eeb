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


def _entries(folder: Path, limit: int = 2000) -> tuple[list[str], list[str]]:
    """The robot-file names and the subfolder names in ``folder`` (not recursive; bounded)."""
    robots: list[str] = []
    folders: list[str] = []
    deps.note_listing(folder)
    try:
        with os.scandir(folder) as it:
            for entry in it:
                if entry.name.endswith(ROBOT_SUFFIXES):
                    robots.append(entry.name)
                else:
                    try:
                        if entry.is_dir():
                            folders.append(entry.name)
                    except OSError:
                        pass
                if len(robots) + len(folders) >= limit:
                    break
    except OSError:
        pass
    return robots, folders


def _stem(name: str) -> str:
    """A robot file's name without its suffix, which a typo is judged on.

    ``.urdf``, alike in every file, would make unrelated names look close.
    """
    for suffix in ROBOT_SUFFIXES[::-1]:  # .urdf.xacro before .xacro
        if name.endswith(suffix):
            return name[:-len(suffix)]
    return name


def _matches(word: str, robots: list[str]) -> list[str]:
    """The robot files in a listing that ``word`` (a file name, maybe without suffix) means."""
    stem = word.split(".")[0]
    exact = [f for f in robots if f.split(".")[0] == stem]
    if exact:
        return exact
    by_stem: dict[str, str] = {}
    for f in robots:
        by_stem.setdefault(_stem(f), f)
    return [by_stem[s] for s in close(_stem(word), by_stem)]


def _under(root: Path, parts: list[str]) -> list[tuple[Path, list[str]]]:
    """The folders ``parts`` may mean below ``root``, each with its parts as they exist.

    Each part that is a folder is kept as typed; one that is not is replaced by the closest
    subfolder names (``kuka_iwa`` -> ``kuka_iiwa``). At most three ways through.
    """
    ways: list[tuple[Path, list[str]]] = [(root, [])]
    for n, part in enumerate(parts):
        step: list[tuple[Path, list[str]]] = []
        for folder, typed in ways:
            if part in ("", ".", ".."):
                step.append((folder / part if part else folder, [*typed, part]))
            elif n == 0 and part == "~":
                step.append((Path.home(), [*typed, part]))
            elif (folder / part).is_dir():
                step.append((folder / part, [*typed, part]))
            else:
                step += [(folder / m, [*typed, m]) for m in close(part, _entries(folder)[1])]
        ways = step[:3]
    return ways


def files(name: str, data_dir: Path | None = None) -> list[str]:
    """Robot files close to ``name``, path component by component: here, then in pybullet_data.

    Each folder of the path that does not exist is matched against the folders that do
    (``kuka_iwa/model.urdf`` finds ``kuka_iiwa/model.urdf``), and the file against the robot
    files in the folder reached, by name without suffix, so ``my_robt.urdf`` finds
    ``my_robot.urdf`` and nothing that merely ends in ``.urdf``. ``name`` may lack its suffix
    (``r2d2`` finds ``r2d2.urdf``). Matches here come first, spelt as the user spelt the
    path (``./my_robot.urdf``); pybullet_data's are relative to it, as every loading command
    looks them up there.
    """
    parts = name.replace(os.sep, "/").split("/")
    *folders, last = parts
    roots = [Path("/") if os.path.isabs(name) else Path(".")]
    if data_dir is not None and not os.path.isabs(name) and folders[:1] != ["~"]:
        roots.append(data_dir)
    found: list[str] = []
    for root in roots:
        for folder, typed in _under(root, folders):
            for match in _matches(last, _entries(folder)[0]):
                shown = "/".join([*typed, match])
                if shown != name and shown not in found:
                    found.append(shown)
    return found[:3]
