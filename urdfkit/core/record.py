"""Value records: classes compared, hashed, shown and pickled by their fields.

check makes one per element, mesh or finding of every file (findings, references, mesh
properties, solids). Compiled by mypyc, a frozen dataclass is built through Python's
generated ``__init__`` (1.5 us against 0.03 us for a plain class), so these are plain
classes with their own ``__init__``; what a dataclass would add comes from here, worked out
from two class attributes.
"""

from __future__ import annotations

from typing import ClassVar


class Record:
    """A value record: equal, hashed and shown by ``_COMPARED``, pickled by ``_FIELDS``.

    A subclass names its fields in ``__slots__`` and in ``_FIELDS`` (its constructor's order:
    pickle calls the constructor with them, as check's worker processes hand records back),
    and, when not all of them make its value, those that do in ``_COMPARED``. A mutable one
    sets ``__hash__ = None``.
    Treat a record as read-only: nothing stops an assignment, but the hash of one in a set
    would then be stale. Compiled (setup.py), it can be the base only of compiled classes.
    """

    __slots__ = ()
    _FIELDS: ClassVar[tuple[str, ...]] = ()
    _COMPARED: ClassVar[tuple[str, ...]] = ()

    def _compared(self) -> tuple[str, ...]:
        return self._COMPARED or self._FIELDS

    def _key(self) -> tuple[object, ...]:
        return tuple([getattr(self, name) for name in self._compared()])

    def __eq__(self, other: object) -> bool:
        if type(other) is not type(self):
            return NotImplemented
        assert isinstance(other, Record)
        return self._key() == other._key()

    def __hash__(self) -> int:
        return hash(self._key())

    def __repr__(self) -> str:
        shown = ", ".join([f"{name}={getattr(self, name)!r}" for name in self._compared()])
        return f"{type(self).__name__}({shown})"

    def __reduce__(self) -> tuple[object, ...]:
        return (type(self), tuple([getattr(self, name) for name in self._FIELDS]))
