"""MuJoCo's own warnings, kept for the report instead of printed on stderr.

MuJoCo's C code warns through ``mju_user_warning``, which prints ``WARNING: ...`` and a blank
line on stderr when no handler is set: its XML parser on a NaN ("XML contains a 'NaN'"), the
simulation when it diverges ("Nan, Inf or huge value in QACC at DOF 0"). On a refusal that
made a one-line error three; on a run, lines outside urdfkit's own.
"""

from __future__ import annotations

from collections.abc import Iterator
from contextlib import contextmanager
from typing import Any


@contextmanager
def mujoco_warnings(mujoco: Any) -> Iterator[list[str]]:
    """Collect what MuJoCo warns inside the block (the previous handler restored after)."""
    said: list[str] = []

    def keep(message: str) -> None:
        said.append(one_line(message))

    previous = mujoco.get_mju_user_warning()
    mujoco.set_mju_user_warning(keep)
    try:
        yield said
    finally:
        mujoco.set_mju_user_warning(previous)


def one_line(message: str) -> str:
    """A MuJoCo warning as one line, as urdfkit's warnings are.

    A second line (``Element name 'f', id 0``) goes in brackets after the first.
    """
    first, *rest = message.strip().splitlines() or [""]
    return first + (f" ({'; '.join(r.strip() for r in rest)})" if rest else "")


#: What MuJoCo warned while a :func:`listen` is open, one line each (its users clear it).
_SAID: list[str] = []
#: How many listeners are open, and the handler before the first.
_LISTENERS: dict[str, Any] = {"open": 0, "previous": None}


def listen(mujoco: Any) -> list[str]:
    """Keep what MuJoCo warns from now until :func:`stop_listening`, in the list returned.

    For a loop that would pay :func:`mujoco_warnings` at every step (a MuJoCo engine's
    step): the handler is set once, while any listener is open, and the one before it put
    back when the last closes. The list is shared: a step clears it before it steps.
    """
    if _LISTENERS["open"] == 0:
        _LISTENERS["previous"] = mujoco.get_mju_user_warning()
        mujoco.set_mju_user_warning(lambda message: _SAID.append(one_line(message)))
    _LISTENERS["open"] += 1
    return _SAID


def stop_listening(mujoco: Any) -> None:
    """One :func:`listen` less; the last puts the handler before them back."""
    _LISTENERS["open"] -= 1
    if _LISTENERS["open"] == 0:
        mujoco.set_mju_user_warning(_LISTENERS["previous"])
        _LISTENERS["previous"] = None
