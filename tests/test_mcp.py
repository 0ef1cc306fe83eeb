"""`urdfkit mcp`, driven by the MCP SDK's own client over stdio.

Every tool is called and its answer held to the command's own (`urdfkit ... --json`) or to the
file it says it wrote; a path outside the client's roots is refused; and every file of the
hostile corpus goes through every tool that reads a robot without taking the server down.
"""

from __future__ import annotations

import json
import subprocess
import sys
from collections.abc import AsyncIterator
from contextlib import asynccontextmanager
from pathlib import Path

import anyio
from mcp import types
from mcp.client.session import ClientSession
from mcp.client.stdio import StdioServerParameters, stdio_client

sys.path.insert(0, str(Path(__file__).parent / "hostile"))
from make_corpus import make_corpus  # noqa: E402

BAD = """<?xml version="1.0"?>
<robot name="bad">
  <link name="base">
    <inertial><mass value="2"/>
      <inertia ixx="1" ixy="0" ixz="0" iyy="0.1" iyz="0" izz="0.1"/></inertial>
    <collision><geometry><box size="0.2 0.2 0.2"/></geometry></collision>
  </link>
  <link name="arm">
    <inertial><mass value="0.5"/>
      <inertia ixx="0.01" ixy="0" ixz="0" iyy="0.01" iyz="0" izz="0.01"/></inertial>
    <collision><geometry><box size="0.1 0.1 0.3"/></geometry></collision>
  </link>
  <joint name="elbow" type="revolute"><parent link="base"/><child link="arm"/>
    <origin xyz="0 0 0.3"/><axis xyz="0 0 1"/>
    <limit lower="-1.5" upper="1.5" effort="7" velocity="2"/></joint>
</robot>
"""


@asynccontextmanager
async def session(root: Path, roots: list[Path] | None = None) -> AsyncIterator[ClientSession]:
    """A client session with `urdfkit mcp` started in ``root`` (``roots``: the client's)."""
    params = StdioServerParameters(command=sys.executable, args=["-m", "urdfkit", "mcp"],
                                   cwd=str(root))

    async def list_roots(_ctx: object) -> types.ListRootsResult:
        return types.ListRootsResult(roots=[types.Root(uri=r.as_uri()) for r in roots or []])

    async with stdio_client(params) as (read, write), ClientSession(
            read, write, list_roots_callback=list_roots if roots is not None else None) as s:
        await s.initialize()
        yield s


def _json(result: types.CallToolResult) -> dict:
    assert not result.is_error, result.content
    return json.loads(result.content[0].text)


def _cli(*args: str) -> dict:
    done = subprocess.run([sys.executable, "-m", "urdfkit", *args], capture_output=True,
                          text=True, check=False)
    return json.loads(done.stdout)


def test_every_tool_answers_as_its_command(tmp_path: Path) -> None:
    robot = tmp_path / "bad.urdf"
    robot.write_text(BAD)

    async def main() -> None:
        async with session(tmp_path) as s:
            names = {t.name for t in (await s.list_tools()).tools}
            assert names == {"check", "joints", "links", "info", "collisions", "fix", "build",
                             "render", "agree"}
            got = _json(await s.call_tool("check", {"paths": ["bad.urdf"]}))
            want = _cli("check", str(robot), "--json")
            assert got["findings"] == want["findings"] and got["exit_code"] == 1
            for tool in ("joints", "links", "info", "collisions"):
                got = _json(await s.call_tool(tool, {"file": str(robot)}))
                got.pop("exit_code")
                assert got == _cli(tool, str(robot), "--json"), tool
            fixed = _json(await s.call_tool("fix", {"file": "bad.urdf"}))
            assert fixed["changed"] and fixed["written"] is None
            assert robot.read_text() == BAD  # not written unless asked
            fixed = _json(await s.call_tool("fix", {"file": "bad.urdf", "write": True,
                                                    "output": "fixed.urdf"}))
            out = tmp_path / "fixed.urdf"
            subprocess.run([sys.executable, "-m", "urdfkit", "fix", str(robot), "-o",
                            str(tmp_path / "cli.urdf")], capture_output=True, check=False)
            assert fixed["written"] == str(out)
            assert out.read_bytes() == (tmp_path / "cli.urdf").read_bytes()
            built = _json(await s.call_tool("build", {"target": "simplecar",
                                                      "output": "car.urdf"}))
            assert Path(built["written"]).is_file()
            picture = await s.call_tool("render", {"file": "bad.urdf", "size": "160x120"})
            assert not picture.is_error and picture.content[0].type == "image"
            import base64
            import io

            from PIL import Image

            image = Image.open(io.BytesIO(base64.b64decode(picture.content[0].data)))
            assert image.size == (160, 120)
            rows = _json(await s.call_tool("agree", {"file": "bad.urdf",
                                                     "engine": "pinocchio", "poses": 3}))
            # Bullet zeroes base's tensor (ixx > iyy + izz): Pinocchio keeps it
            assert rows["engine"] == "Pinocchio" and rows["exit_code"] == 1
            assert {r["check"] for r in rows["rows"] if r["status"] == "fail"} >= \
                {"inertia tensors"}

    anyio.run(main)


def test_paths_outside_the_roots_are_refused(tmp_path: Path) -> None:
    inside, outside = tmp_path / "in", tmp_path / "out"
    inside.mkdir()
    outside.mkdir()
    (outside / "r.urdf").write_text(BAD)
    (inside / "r.urdf").write_text(BAD)

    async def main() -> None:
        async with session(inside, roots=[inside]) as s:
            for tool, args in (("joints", {"file": str(outside / "r.urdf")}),
                               ("check", {"paths": ["../out/r.urdf"]}),
                               ("fix", {"file": "r.urdf", "write": True,
                                        "output": str(outside / "w.urdf")}),
                               ("build", {"target": "simplecar",
                                          "output": str(outside / "car.urdf")})):
                result = await s.call_tool(tool, args)
                assert result.is_error and "outside the client's roots" in \
                    result.content[0].text, (tool, result.content)
            assert sorted(p.name for p in outside.iterdir()) == ["r.urdf"]
            result = await s.call_tool("agree", {"file": "r.urdf", "engine": "mujoco"})
            assert result.is_error and "give `model`" in result.content[0].text
            assert not _json(await s.call_tool("joints", {"file": "r.urdf"}))["exit_code"]

    anyio.run(main)


#: Hostile files of each kind (crashers, XML attacks, broken numbers, no file): the default run.
SAMPLE = ["two_roots.urdf", "cycle_with_root.urdf", "percent_link.urdf", "xxe.urdf",
          "billion_laughs.urdf", "nan_mass.urdf", "x.urdf", "non_utf8.urdf"]
#: Every tool that reads a robot, with its arguments for a file.
READERS = [("check", lambda f: {"paths": [f]}), ("joints", lambda f: {"file": f}),
           ("links", lambda f: {"file": f}), ("info", lambda f: {"file": f}),
           ("collisions", lambda f: {"file": f}), ("fix", lambda f: {"file": f}),
           ("render", lambda f: {"file": f, "size": "80x60"}),
           ("agree", lambda f: {"file": f, "engine": "pinocchio", "poses": 2})]


def test_the_hostile_corpus_never_takes_the_server_down(tmp_path: Path) -> None:
    """Every tool on hostile files: the command's one line as a tool error, or its answer.

    A sample of each kind: the commands themselves go through the whole corpus in
    tests/test_hostile.py (all 48 files through every tool took 55 s, measured).
    """
    corpus = tmp_path / "hostile"
    expected = make_corpus(corpus)
    names = [n for n in SAMPLE if n in expected]
    assert len(names) >= len(SAMPLE) - 1

    async def main() -> None:
        async with session(tmp_path) as s:
            for name in names:
                for tool, args in READERS:
                    result = await s.call_tool(tool, args(str(corpus / name)))
                    text = getattr(result.content[0], "text", "") if result.content else ""
                    assert "Traceback" not in text and "internal error" not in text, \
                        (name, tool, text)
                    if result.is_error:
                        assert len(text) < 2000 and "\n" not in text.strip(), (name, tool)
            assert (await s.list_tools()).tools  # still serving

    anyio.run(main)
