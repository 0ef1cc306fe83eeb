"""How ``urdfkit mcp``'s tools run their commands, and where they may read and write.

Each tool runs the command itself, as a user runs it, in a process of its own
(``python -m urdfkit COMMAND ... --json``): its answer is the command's JSON, its refusal the
command's one line (a tool error), and a file that would crash PyBullet takes down that process,
never the server. Tools read only the files they are given and write only where told
(``fix`` returns its diff and writes only with ``write``; ``build`` writes only ``output``),
and a path outside the client's roots (``roots/list``; without them the folders the server was
started with, by default its working folder) is refused.
"""


import json
import subprocess
import sys
from collections.abc import Sequence
from pathlib import Path
from typing import Any

#: Seconds a tool's command may run before it is stopped (a tool error says so).
TOOL_TIMEOUT = 300.0


class ToolRefused(Exception):
    """A tool's input refused (outside the roots, a command's exit 2): said to the client."""


def _inside(path: Path, roots: Sequence[Path]) -> bool:
    return any(path == r or r in path.parents for r in roots)


class Roots:
    """Where tools may read and write: the client's roots, else the server's own."""

    def __init__(self, fallback: Sequence[str | Path]) -> None:
        self.fallback = [Path(p).resolve() for p in fallback] or [Path.cwd().resolve()]

    async def of(self, ctx: Any) -> list[Path]:
        """The client's roots (file:// URIs) if it has any, else the fallback folders."""
        import warnings
        from urllib.parse import unquote, urlparse

        with warnings.catch_warnings():  # (the SDK 2.3 calls roots deprecated; clients send
            warnings.simplefilter("ignore")  # them, and the issue asks them kept)
            caps = getattr(ctx.session, "client_params", None)
            has = caps is not None and getattr(caps.capabilities, "roots", None) is not None
            if not has:
                return self.fallback
            try:
                listed = await ctx.session.list_roots()
            except Exception:  # noqa: BLE001 - a client that says it has roots and fails
                return self.fallback
        out = []
        for root in listed.roots:
            url = urlparse(str(root.uri))
            if url.scheme == "file":
                out.append(Path(unquote(url.path)).resolve())
        return out

    async def check(self, ctx: Any, path: str, what: str = "file") -> Path:
        """``path`` resolved, if it is inside a root.

        Raises:
            ToolRefused: It is not.
        """
        roots = await self.of(ctx)
        p = Path(path).expanduser()
        if not p.is_absolute():
            p = roots[0] / p if roots else p
        p = p.resolve()
        if not _inside(p, roots):
            raise ToolRefused(f"{path}: outside the client's roots "
                              f"({', '.join(str(r) for r in roots) or 'none'}); urdfkit "
                              f"{'reads' if what == 'file' else 'writes'} only inside them")
        return p


def run_command(args: Sequence[str], cwd: Path | None = None) -> tuple[int, str, str]:
    """``python -m urdfkit ARGS`` in a process of its own: exit code, stdout, stderr."""
    try:
        done = subprocess.run([sys.executable, "-m", "urdfkit", *args], capture_output=True,
                              text=True, timeout=TOOL_TIMEOUT, cwd=cwd,
                              stdin=subprocess.DEVNULL, check=False)
    except subprocess.TimeoutExpired:
        raise ToolRefused(f"urdfkit {args[0]} ran longer than {TOOL_TIMEOUT:g} s and was "
                          "stopped") from None
    return done.returncode, done.stdout, done.stderr


def answer(args: Sequence[str], cwd: Path | None = None) -> dict[str, Any]:
    """A command's JSON, its exit code beside it; a refusal or a bug as :class:`ToolRefused`."""
    code, out, err = run_command(args, cwd)
    if code in (0, 1) and out.strip():
        try:
            data = json.loads(out)
        except ValueError:
            data = {"output": out}
        return {"exit_code": code, **(data if isinstance(data, dict) else {"result": data})}
    said = " ".join(err.strip().splitlines()[-1:]) or f"urdfkit {args[0]} exited {code}"
    if code < 0:
        said = f"urdfkit {args[0]} crashed (signal {-code}) on this input"
    raise ToolRefused(said)


def common_options(packages: Sequence[str] | None, xacro_args: Sequence[str] | None
                   ) -> list[str]:
    """``--package`` and ``--arg`` options, as the command line takes them."""
    out: list[str] = []
    for p in packages or []:
        out += ["--package", p]
    for a in xacro_args or []:
        out += ["--arg", a]
    return out
