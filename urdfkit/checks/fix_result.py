"""What ``fix`` returns: each repair made or left (:class:`Repair`), and the file's result.

:class:`FixResult` holds the original and repaired bytes, the total mass before and after,
and the lists ``fix --json`` prints (docs/fix.md); :func:`urdfkit.checks.fix.fix_file`
returns it.
"""

from __future__ import annotations

import difflib
from dataclasses import dataclass, field
from typing import Any


@dataclass
class Repair:
    """One fix made, or one finding left as it was (with why).

    Attributes:
        code: The rule code of the finding.
        line: Its line in the original file.
        message: What was done, or why nothing was.
    """

    code: str
    line: int | None
    message: str
    #: The link a repair is to (for the re-check), not in the JSON.
    subject: str | None = field(default=None, compare=False)

    def to_dict(self) -> dict[str, Any]:
        """The JSON form."""
        return {"code": self.code, "line": self.line, "message": self.message}


@dataclass
class FixResult:
    """The repaired text of one file, and what was repaired.

    Attributes:
        file: The file as the user named it.
        original: Its bytes.
        fixed: The repaired bytes (equal to ``original`` when nothing was fixed).
        repairs: The fixes made, in file order.
        left: Findings of fixable codes that were left, each with the reason.
        other_errors: Error findings ``fix`` does not repair (a zero axis, a missing limit):
            ``check`` explains them.
        relative_paths: Mesh and texture paths relative to the file's folder: a copy
            written elsewhere no longer finds them as written.
        moved_paths: ``(old, new)`` of each ``filename`` rewritten for the folder the result
            is written to (``output``): only those attributes change.
    """

    file: str
    original: bytes
    fixed: bytes
    #: The file's total mass (the sum of its finite ``<mass>`` values), before and after.
    mass_before: float = 0.0
    mass_after: float = 0.0
    #: The total mass PyBullet loads, before and after: the file's plus 1 kg for every link
    #: without ``<inertial>`` but ``world`` (a frame given mass 0 loses that phantom kilogram).
    loaded_before: float = 0.0
    loaded_after: float = 0.0
    repairs: list[Repair] = field(default_factory=list)
    left: list[Repair] = field(default_factory=list)
    other_errors: list[Repair] = field(default_factory=list)
    relative_paths: list[str] = field(default_factory=list)
    moved_paths: list[tuple[str, str]] = field(default_factory=list)

    @property
    def changed(self) -> bool:
        """Whether anything was fixed."""
        return self.fixed != self.original

    def diff(self, new_name: str | None = None) -> str:
        """A unified diff from the original to the fixed text."""
        a = self.original.decode("utf-8", "replace").splitlines(keepends=True)
        b = self.fixed.decode("utf-8", "replace").splitlines(keepends=True)
        # git's a/ and b/ prefixes, before a relative path: an absolute one keeps one slash
        old, new = self.file, new_name or self.file
        return "".join(difflib.unified_diff(a, b, f"a/{old.lstrip('/')}",
                                            f"b/{new.lstrip('/')}"))

    def to_dict(self) -> dict[str, Any]:
        """The ``--json`` form (docs/fix.md)."""
        return {"file": self.file, "changed": self.changed,
                "mass": {"before": self.mass_before, "after": self.mass_after,
                         "loaded_before": self.loaded_before,
                         "loaded_after": self.loaded_after},
                "fixes": [x.to_dict() for x in self.repairs],
                "left": [x.to_dict() for x in self.left],
                "other_errors": [x.to_dict() for x in self.other_errors],
                "moved_paths": [{"from": a, "to": b} for a, b in self.moved_paths]}
