"""``urdfkit mcp``'s tools: each runs its command (:func:`urdfkit.serve.tool_runs.answer`).

Imported only once the ``mcp`` SDK is known to be there (:func:`urdfkit.serve.mcp.build_mcp`):
the SDK reads each tool's signature, ``Context`` included, to build its schema.
"""

import difflib
import os
import tempfile
from pathlib import Path
from typing import Any

from mcp.server.mcpserver import Context, Image
from mcp.server.mcpserver.exceptions import ToolError

from urdfkit.serve.tool_runs import Roots, ToolRefused, answer, common_options, run_command


def _last_line(err: str, what: str, code: int) -> str:
    return " ".join(err.strip().splitlines()[-1:]) or f"urdfkit {what} exited {code}"


class Tools:
    """The tools, over the folders they may use."""

    def __init__(self, allowed: Roots) -> None:
        self.allowed = allowed

    async def check(self, paths: list[str], ctx: Context, targets: list[str] | None = None,
                    packages: list[str] | None = None,
                    xacro_args: list[str] | None = None) -> dict[str, Any]:
        """Every check rule on URDF/xacro files or folders: findings with code, level, line.

        targets: also what ros, pinocchio, drake or mujoco refuse or change.
        packages: NAME=PATH for package://. xacro_args: NAME:=VALUE.
        """
        try:
            files = [str(await self.allowed.check(ctx, p)) for p in paths]
            args = ["check", *files, "--json", *common_options(packages, xacro_args)]
            if targets:
                args += ["--target", ",".join(targets)]
            return answer(args)
        except ToolRefused as e:
            raise ToolError(str(e)) from None

    async def inspect(self, command: str, file: str, ctx: Context,
                      packages: list[str] | None, xacro_args: list[str] | None
                      ) -> dict[str, Any]:
        """``urdfkit COMMAND FILE --json``."""
        try:
            path = await self.allowed.check(ctx, file)
            return answer([command, str(path), "--json", *common_options(packages, xacro_args)])
        except ToolRefused as e:
            raise ToolError(str(e)) from None

    async def joints(self, file: str, ctx: Context, packages: list[str] | None = None,
                     xacro_args: list[str] | None = None) -> dict[str, Any]:
        """PyBullet's joint table: every getJointInfo field by name, URDF type, limits, index."""
        return await self.inspect("joints", file, ctx, packages, xacro_args)

    async def links(self, file: str, ctx: Context, packages: list[str] | None = None,
                    xacro_args: list[str] | None = None) -> dict[str, Any]:
        """PyBullet's link table: index, mass, inertia, inertial frame, shapes."""
        return await self.inspect("links", file, ctx, packages, xacro_args)

    async def info(self, file: str, ctx: Context, packages: list[str] | None = None,
                   xacro_args: list[str] | None = None) -> dict[str, Any]:
        """A robot's summary as PyBullet loads it: links, joints, mass, DOF, bounding box."""
        return await self.inspect("info", file, ctx, packages, xacro_args)

    async def collisions(self, file: str, ctx: Context, packages: list[str] | None = None,
                         xacro_args: list[str] | None = None) -> dict[str, Any]:
        """Link pairs that touch at the zero pose and at sampled poses."""
        return await self.inspect("collisions", file, ctx, packages, xacro_args)

    async def fix(self, file: str, ctx: Context, write: bool = False,
                  output: str | None = None, balance: bool = False,
                  packages: list[str] | None = None) -> dict[str, Any]:
        """Fix's repairs of a URDF as a unified diff, written only with ``write``.

        Written to ``output``, or in place keeping the original as FILE.orig.
        """
        try:
            path = await self.allowed.check(ctx, file)
            extra = common_options(packages, None) + (["--balance"] if balance else [])
            diff = _fix_diff(path, extra)
            written = None
            if write and diff:
                target = path if output is None else \
                    await self.allowed.check(ctx, output, "write")
                args = ["fix", str(path), *extra]
                args += ["--in-place"] if output is None else ["-o", str(target)]
                code, _, err = run_command(args)
                if code not in (0, 1):
                    raise ToolRefused(_last_line(err, "fix", code))
                written = str(target)
            return {"file": str(path), "diff": diff, "changed": bool(diff), "written": written}
        except ToolRefused as e:
            raise ToolError(str(e)) from None

    async def build(self, target: str, output: str, ctx: Context,
                    params: list[str] | None = None, xacro_args: list[str] | None = None,
                    force: bool = False) -> dict[str, Any]:
        """Build a URDF from a template name (see `urdfkit templates`) or a xacro, to output.

        params: template KEY=VALUE. xacro_args: NAME:=VALUE. force: overwrite output.
        """
        try:
            out = await self.allowed.check(ctx, output, "write")
            source = target
            if os.sep in target or target.endswith(".xacro") or Path(target).exists():
                source = str(await self.allowed.check(ctx, target))
            args = ["build", source, "-o", str(out), *(["--force"] if force else [])]
            for p in params or []:
                args += ["--set", p]
            args += common_options(None, xacro_args)
            code, _, err = run_command(args)
            if code != 0:
                raise ToolRefused(_last_line(err, "build", code))
            return {"written": str(out), "said": err.strip().splitlines()[-3:]}
        except ToolRefused as e:
            raise ToolError(str(e)) from None

    async def render(self, file: str, ctx: Context, view: str = "iso",
                     size: str = "800x600", collision: bool = False,
                     packages: list[str] | None = None,
                     xacro_args: list[str] | None = None) -> Image:
        """A PNG of the robot as PyBullet loads it (view: iso, front, side, top)."""
        try:
            path = await self.allowed.check(ctx, file)
            with tempfile.TemporaryDirectory(prefix="urdfkit-mcp-") as tmp:
                png = Path(tmp) / "robot.png"
                args = ["render", str(path), "-o", str(png), "--view", view, "--size", size,
                        *common_options(packages, xacro_args),
                        *(["--collision"] if collision else [])]
                code, _, err = run_command(args)
                if code != 0 or not png.exists():
                    raise ToolRefused(_last_line(err, "render", code))
                return Image(data=png.read_bytes(), format="png")
        except ToolRefused as e:
            raise ToolError(str(e)) from None

    async def agree(self, file: str, ctx: Context, engine: str = "pinocchio",
                    model: str | None = None, poses: int = 20) -> dict[str, Any]:
        """Compare what another engine loads with PyBullet, row by row.

        engine: pinocchio, drake, mujoco-loader, or mujoco with model (an MJCF file).
        """
        try:
            if engine == "mujoco" and model is None:
                raise ToolRefused("engine mujoco compares an MJCF file: give `model`, or use "
                                  "engine mujoco-loader, pinocchio or drake")
            path = await self.allowed.check(ctx, file)
            args = ["agree", str(path)]
            if model is not None:
                args.append(str(await self.allowed.check(ctx, model)))
            return answer([*args, "--engine", engine, "--json", "--poses", str(poses)])
        except ToolRefused as e:
            raise ToolError(str(e)) from None


def _fix_diff(path: Path, extra: list[str]) -> str:
    """Fix's repairs of ``path`` as a unified diff, staged in a temporary folder."""
    with tempfile.TemporaryDirectory(prefix="urdfkit-mcp-") as tmp:
        staged = Path(tmp) / path.name
        code, _, err = run_command(["fix", str(path), "-o", str(staged), *extra])
        if code not in (0, 1):
            raise ToolRefused(_last_line(err, "fix", code))
        after = staged.read_text("utf-8") if staged.exists() else path.read_text("utf-8")
    before = path.read_text("utf-8")
    return "".join(difflib.unified_diff(before.splitlines(True), after.splitlines(True),
                                        str(path), str(path) + " (fixed)"))


def register(server: Any, allowed: Roots) -> None:
    """Every tool on ``server``."""
    tools = Tools(allowed)
    for name in ("check", "joints", "links", "info", "collisions", "fix", "build", "render",
                 "agree"):
        server.tool(name=name)(getattr(tools, name))
