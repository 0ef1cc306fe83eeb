"""``urdfkit mcp``: urdfkit's commands as Model Context Protocol tools, over stdio.

Each tool (:mod:`urdfkit.serve.mcp_tools`) runs the command itself, as a user runs it, in a
process of its own (:mod:`urdfkit.serve.tool_runs`): its answer is the command's JSON, its
refusal the command's one line (a tool error), and a file that would crash PyBullet takes down
that process, never the server. Tools read only the files they are given and write only where
told, and a path outside the client's roots is refused.
"""

from collections.abc import Sequence
from pathlib import Path
from typing import Any

from urdfkit.serve.tool_runs import Roots


def build_mcp(roots: Sequence[str | Path] = ()) -> Any:
    """The MCP server with urdfkit's tools (start it with ``run("stdio")``).

    Raises:
        MissingDependencyError: the ``mcp`` SDK is not installed (``urdfkit[mcp]`` named).
    """
    from urdfkit.core.errors import import_optional

    import_optional("mcp.server.mcpserver", "the MCP SDK", "urdfkit mcp", "mcp")
    from mcp.server.mcpserver import MCPServer

    from urdfkit import __version__
    from urdfkit.serve.mcp_tools import register

    server = MCPServer(name="urdfkit", version=__version__, log_level="WARNING", instructions=(
        "Check, inspect, repair, build, render and compare URDF and xacro robot descriptions "
        "as PyBullet loads them. Paths must be inside the client's roots."))
    register(server, Roots(roots))
    return server
