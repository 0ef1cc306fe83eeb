"""Expanding xacro: a user's xacro file is code, so it runs in a contained child process.

xacro's ``${}`` expressions evaluate Python, and xacro's own restrictions are bypassed with a
generator-frame walk that reaches ``os.system``. :func:`expand_xacro` therefore never runs
xacro inside urdfkit. It runs :mod:`urdfkit.sources._xacro_worker`:

- in a session and process group of its own, killed as a group on timeout, and after it
  finishes (its background children with it);
- as a child subreaper, so a grandchild that daemonizes (``setsid``, double fork) is
  re-parented to the worker, which kills every descendant before it exits;
- under resource limits: address space (:data:`XACRO_MEMORY`), CPU seconds (the timeout), no
  core dumps;
- with its output written to temp files, never to a pipe a background grandchild could hold
  open (which would make urdfkit wait the full timeout);
- and its error messages are scrubbed of the values of ``$(env VAR)`` variables.

It is containment of runaway and accidental harm, not a security sandbox: xacro code still
runs as the user, with the user's files and network. ``URDFKIT_NO_EXEC=1`` (or ``check
--no-exec``) refuses to run it at all; see docs/security.md.
"""

from __future__ import annotations

import os
import re
import signal
import subprocess
import sys
import tempfile
from collections.abc import Mapping
from pathlib import Path

from urdfkit.core.errors import InputError, XacroNotExpanded

#: Seconds a xacro expansion may take before it is killed.
XACRO_TIMEOUT = float(os.environ.get("URDFKIT_XACRO_TIMEOUT", "20"))
#: Address space a xacro worker may map (bytes).
XACRO_MEMORY = 2 * 1024**3
#: The worker's exit status for an argument no file declares (xacro would ignore it silently).
BAD_ARGS = 3
#: Set to 1 (true, yes) to refuse executing xacro anywhere (CI over untrusted repositories).
NO_EXEC_ENV = "URDFKIT_NO_EXEC"


def execution_allowed(no_exec: bool = False) -> bool:
    """Whether xacro may run: not with ``no_exec``, nor with URDFKIT_NO_EXEC set."""
    return not no_exec and os.environ.get(NO_EXEC_ENV, "").strip().lower() not in (
        "1", "true", "yes", "on")


_ENV_REF = re.compile(rb"\$\((?:opt)?env\s+([A-Za-z_][A-Za-z0-9_]*)")
_XACRO_NS = ("http://www.ros.org/wiki/xacro", "http://ros.org/wiki/xacro")


def _secrets(source: bytes) -> dict[str, str]:
    """Environment values an error message must not show.

    Those the file reads with ``$(env VAR)``/``$(optenv VAR)``, and any long value without a
    slash or a space (a token, a key).
    """
    names = {m.decode() for m in _ENV_REF.findall(source)}
    out = {n: os.environ[n] for n in names if os.environ.get(n)}
    out.update({k: v for k, v in os.environ.items() if len(v) >= 12 and "/" not in v
                and " " not in v})
    return out


def redact(message: str, secrets: Mapping[str, str]) -> str:
    """``message`` with every secret value replaced by ``$NAME``."""
    for name, value in sorted(secrets.items(), key=lambda kv: -len(kv[1])):
        if value and value in message:
            message = message.replace(value, f"${name}")
    return message


def expand_xacro(path: str | Path, args: Mapping[str, str] | None = None,
                 timeout: float | None = None, display: str | None = None,
                 no_exec: bool = False, packages: Mapping[str, Path] | None = None,
                 strict_args: bool = True, text: bytes | None = None) -> Expanded:
    """Expand a xacro file in a contained subprocess; return the URDF bytes (with origins).

    ``text`` stands for the file's bytes (an editor's unsaved buffer): the file is expanded
    as if it held them, its includes found from where it lies.

    ``$(find NAME)`` resolves without ROS through ``packages`` (a
    :class:`~urdfkit.sources.uris.PackageIndex`, or plain ``NAME: PATH`` pairs), then the
    environment's
    ROS_PACKAGE_PATH and AMENT_PREFIX_PATH, then by walking up from the file.

    Raises:
        XacroNotExpanded: executing xacro is disabled (``no_exec`` or URDFKIT_NO_EXEC).
        ParameterError: an argument neither the file nor its includes declare (unless not
            ``strict_args``: check passes one set of args to every file of a tree).
        InputError: xacro failed, or ran longer than ``timeout`` seconds.
    """
    name = display or str(path)
    if not execution_allowed(no_exec):
        raise XacroNotExpanded(f"not expanded: executing xacro is disabled ({NO_EXEC_ENV} or "
                               "--no-exec); xacro files run Python code", file=name)
    source_path = Path(path).resolve()
    from urdfkit.model.xmlio import read_bytes

    source = read_bytes(source_path) if text is None else text
    limit = XACRO_TIMEOUT if timeout is None else timeout
    secrets = _secrets(source)
    with tempfile.TemporaryDirectory(prefix="urdfkit-xacro-") as tmp:
        out, err = Path(tmp) / "out.urdf", Path(tmp) / "err.txt"
        # Absolute, because the worker runs in the file's folder (for its relative includes).
        import json

        from urdfkit.sources.uris import PackageIndex

        index = packages if isinstance(packages, PackageIndex) else PackageIndex(packages)
        cmd = [sys.executable, "-m", "urdfkit.sources._xacro_worker", str(out), str(err),
               f"{limit:g}", str(XACRO_MEMORY), json.dumps(index.to_json()), str(source_path)]
        # As xacro's command line: ``name:=`` with nothing after it keeps the file's default
        # (xacro 2.1.1 `xacro f.xacro namespace:=` gives the default, not ""), so an empty
        # value is not passed.
        cmd += [f"{k}:={v}" for k, v in (args or {}).items() if v != ""]
        if not strict_args:
            cmd.append("--lenient-args")
        if text is not None:
            (Path(tmp) / "buffer.xacro").write_bytes(text)
            cmd.append(f"--overlay={Path(tmp) / 'buffer.xacro'}")
        with open(os.devnull, "rb") as stdin, open(err, "ab") as log:
            proc = subprocess.Popen(cmd, stdin=stdin, stdout=log, stderr=log,
                                    cwd=str(source_path.parent), start_new_session=True)
            try:
                code = proc.wait(timeout=limit)
            except subprocess.TimeoutExpired:
                _stop(proc)
                raise InputError(f"xacro expansion took longer than {limit:g} s and was "
                                 "stopped", file=name) from None
            except BaseException:  # Ctrl-C, SIGTERM: take the worker down with us
                _stop(proc)
                raise
            finally:
                _kill_group(proc.pid)  # background children left in its group
                _note_reads(Path(str(out) + ".deps"))
        if code == BAD_ARGS:
            from urdfkit.core.errors import ParameterError

            lines = err.read_text("utf-8", "replace").strip().splitlines()
            raise ParameterError(lines[-1] if lines else "unknown xacro argument", file=name,
                                 param="xacro_args")
        if code != 0:
            lines = [ln for ln in err.read_text("utf-8", "replace").splitlines() if ln.strip()]
            if code < 0:
                why = {int(signal.SIGKILL): "was killed (out of memory, or its CPU limit)",
                       int(signal.SIGXCPU): "ran out of CPU time",
                       int(signal.SIGSEGV): "crashed"}.get(-code, f"died of signal {-code}")
                msg = f"the xacro worker {why}"
            else:
                msg = lines[-1] if lines else f"exited with code {code}"
            if "MemoryError" in msg or "Cannot allocate memory" in msg:
                msg = f"ran out of memory (limit {XACRO_MEMORY // 1024**2} MiB): {msg}"
            named = re.search(r"`(\w+)`", msg)  # a parameter the message names, for the CLI
            raise InputError(f"xacro failed: {redact(msg, secrets)}", file=name,
                             param=named.group(1) if named else None)
        return Expanded(out.read_bytes(), _origins(Path(str(out) + ".origins")))


def _note_reads(path: Path) -> None:
    """Tell :mod:`urdfkit.core.deps` every file the worker read (when a result is recorded)."""
    from urdfkit.core import deps

    if not deps._active:
        return
    import json

    try:
        read = json.loads(path.read_text("utf-8", "surrogateescape"))
    except (OSError, ValueError):
        return
    for name in read if isinstance(read, list) else []:
        if isinstance(name, str):
            deps.note(name)


class Expanded(bytes):
    """xacro's output, and where each of its elements was written.

    Attributes:
        origins: For each element in document order, ``"file:line"`` of the source text it
            came from (the macro body for an element a macro made; the path relative to the
            current folder when below it), or None.
    """

    origins: list[str | None]

    def __new__(cls, data: bytes, origins: list[str | None]) -> Expanded:  # noqa: D102
        self = super().__new__(cls, data)
        self.origins = origins
        return self


def _origins(path: Path) -> list[str | None]:
    import json

    try:
        found = json.loads(path.read_text("utf-8"))
        files = [_shown(f) for f in found["files"]]
        out: list[str | None] = []
        for at in found["origins"]:
            index, _, line = (at or "").partition(":")
            out.append(f"{files[int(index)]}:{int(line)}" if at else None)
        return out
    except (OSError, ValueError, KeyError, IndexError, TypeError):
        return []


def _shown(path: str) -> str:
    """A path as a user would type it: relative to the current folder when below it."""
    rel = os.path.relpath(path)
    return path if rel.startswith("..") else rel


def _kill_group(pgid: int) -> None:
    try:
        os.killpg(pgid, signal.SIGKILL)
    except (ProcessLookupError, PermissionError):
        pass


def _stop(proc: subprocess.Popen[bytes]) -> None:
    """SIGTERM first (the worker then kills its descendants), SIGKILL the group after 1 s."""
    try:
        os.killpg(proc.pid, signal.SIGTERM)
    except (ProcessLookupError, PermissionError):
        return
    try:
        proc.wait(timeout=1.0)
    except subprocess.TimeoutExpired:
        _kill_group(proc.pid)
        proc.wait()
