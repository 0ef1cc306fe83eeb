"""One finding of ``check``: small and import-free, so a cached run never loads the rules."""

from __future__ import annotations

#: Finding levels, lowest first.
LEVELS = ("info", "warning", "error")


class Finding:
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

    def _key(self) -> tuple[object, ...]:
        return (self.code, self.level, self.message, self.file, self.line, self.origin)

    def __eq__(self, other: object) -> bool:
        if type(other) is not Finding:
            return NotImplemented
        return self._key() == other._key()

    def __hash__(self) -> int:
        return hash(self._key())

    def __repr__(self) -> str:
        return (f"Finding(code={self.code!r}, "
                f"level={self.level!r}, "
                f"message={self.message!r}, "
                f"file={self.file!r}, "
                f"line={self.line!r}, "
                f"origin={self.origin!r})")

    def __reduce__(self) -> tuple[object, ...]:  # for pickle (check's workers hand these back)
        return (Finding, (self.code, self.level, self.message, self.file, self.line, self.origin))

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
