"""The one exception hierarchy of urdfkit.

Library code raises these; only ``cli.py`` catches them, once, and turns each into a
single line on stderr plus an exit code. Every error that concerns a file carries the
file and, where known, the line, so the message reads like a compiler's: ``car.urdf:12: ...``.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any


class UrdfkitError(Exception):
    """Base of every error urdfkit raises on purpose.

    Attributes:
        message: What went wrong and, where possible, how to fix it.
        file: The file concerned, if any.
        line: The 1-based line in ``file``, if known.
        param: The Python parameter the error is about (``time_step``), if any. Messages
            name parameters the way Python code passes them; the CLI, which knows which flag
            feeds which parameter, shows the flag (``--time-step``) instead.
        exit_code: What the CLI exits with.
    """

    exit_code = 2

    def __init__(self, message: str, *, file: str | Path | None = None, line: int | None = None,
                 param: str | None = None):
        super().__init__(message)
        self.message = message
        self.file = str(file) if file is not None else None
        self.line = line
        self.param = param

    def __str__(self) -> str:
        if self.file is None:
            return self.message
        where = self.file if self.line is None else f"{self.file}:{self.line}"
        return f"{where}: {self.message}"


class InputError(UrdfkitError):
    """An input file is missing, unreadable, malformed or unsafe to load."""


class XacroNotExpanded(InputError):
    """xacro was not expanded because executing it is disabled (``--no-exec``)."""


class Oversized(InputError):
    """A body over MAX_LOADABLE_LINKS links, refused before parsing (finding U209)."""

    code = "U209"


class ModelError(UrdfkitError, ValueError):
    """A value given to the builder model is invalid (raised where it is set)."""


class ParameterError(UrdfkitError, ValueError):
    """A template parameter or a function argument is unknown or invalid."""


class OutputError(UrdfkitError):
    """An output file cannot be written, or exists and ``--force`` was not given."""


class EngineError(UrdfkitError):
    """PyBullet refused a file or a request."""


class MissingDependencyError(UrdfkitError):
    """An optional dependency is needed; the message says what to install."""


def import_optional(module: str, label: str, needed_by: str, extra: str) -> Any:
    """``module`` imported, or :class:`MissingDependencyError` naming the extra to install.

    ``label`` is the package as people call it ("Pinocchio"), ``needed_by`` what needs it
    ("agree --engine pinocchio").
    """
    import importlib

    try:
        return importlib.import_module(module)
    except ImportError as e:
        raise MissingDependencyError(f"{needed_by} needs {label}: pip install "
                                     f"'urdfkit[{extra}]'") from e

