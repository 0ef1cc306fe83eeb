"""Expanding xacro: a user's xacro file is code, so it runs in a child process.

xacro's ``${}`` expressions evaluate Python. :func:`expand_xacro` runs
:mod:`urdfkit._xacro_worker` in a subprocess with a timeout and returns the URDF bytes; no
xacro code ever runs inside urdfkit itself.
"""

from __future__ import annotations

import os
import subprocess
import sys
from collections.abc import Mapping
from pathlib import Path

from .errors import InputError

#: Seconds a xacro expansion may take before it is killed.
XACRO_TIMEOUT = float(os.environ.get("URDFKIT_XACRO_TIMEOUT", "20"))


def expand_xacro(path: str | Path, args: Mapping[str, str] | None = None,
                 timeout: float | None = None, display: str | None = None) -> bytes:
    """Expand a xacro file in a subprocess; return the URDF bytes.

    Raises:
        InputError: xacro failed, or ran longer than ``timeout`` seconds.
    """
    name = display or str(path)
    # Absolute, because the worker runs in the file's folder (for its relative includes).
    cmd = [sys.executable, "-m", "urdfkit._xacro_worker", str(Path(path).resolve())]
    cmd += [f"{k}:={v}" for k, v in (args or {}).items()]
    limit = XACRO_TIMEOUT if timeout is None else timeout
    try:
        proc = subprocess.run(cmd, capture_output=True, timeout=limit, stdin=subprocess.DEVNULL,
                              cwd=str(Path(path).resolve().parent))
    except subprocess.TimeoutExpired:
        raise InputError(f"xacro expansion took longer than {limit:g} s and was stopped",
                         file=name) from None
    if proc.returncode != 0:
        lines = [ln for ln in proc.stderr.decode("utf-8", "replace").splitlines() if ln.strip()]
        msg = lines[0] if lines else f"exited with code {proc.returncode}"
        raise InputError(f"xacro failed: {msg}", file=name)
    return proc.stdout
