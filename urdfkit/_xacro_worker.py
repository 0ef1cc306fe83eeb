"""Expand one xacro file and print the URDF: run in a subprocess by :mod:`urdfkit.expand`.

xacro's ``${}`` expressions evaluate Python, so a user's xacro file is code. It runs here, in
a child process with a timeout, never inside urdfkit itself.

Usage: ``python -m urdfkit._xacro_worker FILE [name:=value ...]``
"""

from __future__ import annotations

import sys


def main(argv: list[str]) -> int:
    """Expand ``argv[0]`` with ``name:=value`` mappings; write URDF to stdout."""
    if not argv:
        print("usage: python -m urdfkit._xacro_worker FILE [name:=value ...]", file=sys.stderr)
        return 2
    mappings = {}
    for item in argv[1:]:
        key, sep, value = item.partition(":=")
        if not sep:
            print(f"bad argument {item!r}: expected name:=value", file=sys.stderr)
            return 2
        mappings[key] = value
    import xacro

    try:
        doc = xacro.process_file(argv[0], mappings=mappings)
    except BaseException as e:  # xacro raises bare Exceptions and SystemExit
        msg = str(e).strip().splitlines()
        print(msg[0] if msg else type(e).__name__, file=sys.stderr)
        return 1
    sys.stdout.buffer.write(doc.toxml(encoding="utf-8"))
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
