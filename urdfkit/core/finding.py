"""One finding of ``check``: small and import-free, so a cached run never loads the rules."""

from __future__ import annotations

from typing import Literal

from urdfkit.core.record import Record

#: A finding's level; ``check --fail-on`` takes one too.
Level = Literal["info", "warning", "error"]
#: Finding levels, lowest first.
LEVELS: tuple[Level, ...] = ("info", "warning", "error")


class Finding(Record):
    """One problem found in a file.

    Attributes:
        code: A stable identifier such as ``U201``, for ``--select`` and ``--ignore``.
        level: ``error``, ``warning`` or ``info``.
        message: What is wrong with which element, and how to fix it.
        file: The file, as the user named it.
        line: The 1-based line, where known.
        origin: Where the element was written when that is another file (xacro), else None.
    """

    __slots__ = ("code", "level", "message", "file", "line", "origin")
    _FIELDS = ("code", "level", "message", "file", "line", "origin")

    code: str
    level: str
    message: str
    file: str
    line: int | None
    origin: str | None

    def __init__(
            self,
            code: str,
            level: str,
            message: str,
            file: str,
            line: int | None = None,
            origin: str | None = None,
    ) -> None:
        self.code = code
        self.level = level
        self.message = message
        self.file = file
        self.line = line
        self.origin = origin

    def to_dict(self) -> dict[str, object]:
        """The JSON form."""
        return {"code": self.code, "level": self.level, "message": self.message,
                "file": self.file, "line": self.line, "origin": self.origin}

    def __str__(self) -> str:
        where = self.file if self.line is None else f"{self.file}:{self.line}"
        return f"{where}: {self.level} {self.code}: {self.text}"

    @property
    def text(self) -> str:
        """The message, with where the element was written when that is another file."""
        return f"{self.message} (written at {self.origin})" if self.origin else self.message
