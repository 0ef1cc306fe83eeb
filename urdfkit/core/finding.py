"""One finding of ``check``: small and import-free, so a cached run never loads the rules."""

from __future__ import annotations

from typing import Literal

#: A finding's level; ``check --fail-on`` takes one too.
Level = Literal["info", "warning", "error"]
#: Finding levels, lowest first.
LEVELS: tuple[Level, ...] = ("info", "warning", "error")


class Finding:
    """One problem found in a file: a value (compared and hashed by its fields), read-only.

    Attributes:
        code: A stable identifier such as ``U201``, for ``--select`` and ``--ignore``.
        level: ``error``, ``warning`` or ``info``.
        message: What is wrong with which element, and how to fix it.
        file: The file, as the user named it.
        line: The 1-based line, where known.
        origin: Where the element was written when that is another file (xacro), else None.

    A plain class, not a dataclass: ``check`` loads this on every run, and making a frozen
    dataclass at import costs ~0.7 ms (measured: ~4.5M instructions, a plain class ~0.1M).
    """

    __slots__ = ("code", "level", "message", "file", "line", "origin")
    code: str
    level: str
    message: str
    file: str
    line: int | None
    origin: str | None

    def __init__(self, code: str, level: str, message: str, file: str,
                 line: int | None = None, origin: str | None = None) -> None:
        # Each slot's own setter (bound below the class): check makes thousands of findings,
        # and object.__setattr__ looks the name up on every call (~1.2k instructions a
        # field, the setter ~0.7k).
        _set_code(self, code)
        _set_level(self, level)
        _set_message(self, message)
        _set_file(self, file)
        _set_line(self, line)
        _set_origin(self, origin)

    def _key(self) -> tuple[str, str, str, str, int | None, str | None]:
        return (self.code, self.level, self.message, self.file, self.line, self.origin)

    def __eq__(self, other: object) -> bool:
        if other.__class__ is not Finding:
            return NotImplemented
        assert isinstance(other, Finding)
        return self._key() == other._key()

    def __hash__(self) -> int:
        return hash(self._key())

    def __setattr__(self, name: str, value: object) -> None:
        raise AttributeError(f"cannot assign to field {name!r}: a Finding is read-only")

    def __delattr__(self, name: str) -> None:
        raise AttributeError(f"cannot delete field {name!r}: a Finding is read-only")

    def __reduce__(self) -> tuple[type[Finding], tuple[object, ...]]:
        return (Finding, self._key())

    def __repr__(self) -> str:
        return (f"Finding(code={self.code!r}, level={self.level!r}, message={self.message!r}, "
                f"file={self.file!r}, line={self.line!r}, origin={self.origin!r})")

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


#: The slots' own setters (member descriptors), for Finding.__init__.
_set_code, _set_level, _set_message, _set_file, _set_line, _set_origin = (
    Finding.__dict__[name].__set__ for name in Finding.__slots__)
