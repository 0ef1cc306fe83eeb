"""Expand one xacro file into a file: run, contained, by :mod:`urdfkit.expand`.

xacro's ``${}`` expressions evaluate Python, so a user's xacro file is code. It runs here, in
a child process that limits itself (memory, CPU, core dumps), adopts any descendant that tries
to daemonize (child subreaper), and kills all its descendants before it exits or when told to
stop (SIGTERM).

Usage: ``python -m urdfkit._xacro_worker OUT ERR TIMEOUT MEMORY FILE [name:=value ...]``
"""

from __future__ import annotations

import math
import os
import signal
import sys

PR_SET_CHILD_SUBREAPER = 36


def _limits(timeout: float, memory: int) -> None:
    import resource

    cpu = max(1, math.ceil(timeout)) + 1
    for what, value in ((resource.RLIMIT_AS, memory), (resource.RLIMIT_CPU, cpu),
                        (resource.RLIMIT_CORE, 0)):
        try:
            resource.setrlimit(what, (value, value))
        except (ValueError, OSError):  # a lower hard limit is already in place
            pass


def _subreaper() -> None:
    if not sys.platform.startswith("linux"):
        return
    import ctypes

    try:
        ctypes.CDLL(None, use_errno=True).prctl(PR_SET_CHILD_SUBREAPER, 1, 0, 0, 0)
    except (OSError, AttributeError):  # pragma: no cover
        pass


def _descendants(root: int) -> list[int]:
    """Every process below ``root`` (from /proc), nearest first."""
    children: dict[int, list[int]] = {}
    try:
        pids = [int(p) for p in os.listdir("/proc") if p.isdigit()]
    except OSError:  # pragma: no cover - no /proc
        return []
    for pid in pids:
        try:
            with open(f"/proc/{pid}/stat", "rb") as f:
                stat = f.read()
        except OSError:
            continue
        fields = stat.rsplit(b")", 1)[-1].split()
        if len(fields) > 1:
            children.setdefault(int(fields[1]), []).append(pid)
    out, queue = [], list(children.get(root, []))
    while queue:
        pid = queue.pop(0)
        out.append(pid)
        queue.extend(children.get(pid, []))
    return out


def _kill_descendants() -> None:
    for _ in range(20):  # a fork bomb may keep forking while we kill: a few rounds
        pids = _descendants(os.getpid())
        if not pids:
            return
        for pid in pids:
            try:
                os.kill(pid, signal.SIGKILL)
            except OSError:
                pass
        while True:  # reap what was re-parented to us, so nothing lingers as a zombie
            try:
                if os.waitpid(-1, os.WNOHANG)[0] == 0:
                    break
            except ChildProcessError:
                break


def _stop(signum: int, _frame: object) -> None:
    _kill_descendants()
    os._exit(128 + signum)


def main(argv: list[str]) -> int:
    """Expand FILE with ``name:=value`` mappings into OUT; errors go to ERR (last line)."""
    if len(argv) < 5:
        print(__doc__, file=sys.stderr)
        return 2
    out, _err, timeout, memory, source, *items = argv
    _limits(float(timeout), int(memory))
    _subreaper()
    signal.signal(signal.SIGTERM, _stop)
    mappings = {}
    for item in items:
        key, sep, value = item.partition(":=")
        if not sep:
            print(f"bad argument {item!r}: expected name:=value", file=sys.stderr)
            return 2
        mappings[key] = value
    try:
        import xacro

        doc = xacro.process_file(source, mappings=mappings)
        data = doc.toxml(encoding="utf-8")
    except MemoryError:
        print("MemoryError: the expansion needed more memory than its limit", file=sys.stderr)
        return 1
    except BaseException as e:  # xacro raises bare Exceptions and SystemExit
        msg = str(e).strip().splitlines()
        print(msg[0] if msg else type(e).__name__, file=sys.stderr)
        return 1
    finally:
        _kill_descendants()
    with open(out, "wb") as f:
        f.write(data)
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
