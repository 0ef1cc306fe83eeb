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
        # one line each ("flex 'f' is not rigid ...\nElement name 'f', id 0": the element in
        # brackets), as urdfkit's warnings are
        first, *rest = message.strip().splitlines() or [""]
        said.append(first + (f" ({'; '.join(r.strip() for r in rest)})" if rest else ""))

    previous = mujoco.get_mju_user_warning()
    mujoco.set_mju_user_warning(keep)
    try:
        yield said
    finally:
        mujoco.set_mju_user_warning(previous)
