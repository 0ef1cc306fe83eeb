"""Bench for issue 29: ``urdfkit view`` against ``urdfkit render`` on a 33-link robot with meshes.

Standalone: ``python bench/view_bench.py [-n ROUNDS] [--moves 200]``. Measures

- time to first draw: from starting ``urdfkit view FILE`` to robot pixels in a headless
  Chromium page (Debian's ``chromium``, software WebGL), against the wall time of
  ``urdfkit render FILE`` on the same file (goal: at most 1.5x). The browser is started before
  the clock, as a user's browser is already open;
- slider to scene on the server: :meth:`urdfkit.draw.view.Viewer.set_joints` (resetJointState, mimic
  followers, getLinkState of every link, every link node moved, the joint vector texts),
  median over ``--moves`` moves (goal: at most 20 ms);
- ``drive --view`` against ``drive``, both at ``--speed max`` (no pacing), simplecar for
  ``--drive-seconds`` simulated seconds: the run loop alone (the same opened scenario run
  with and without the stream as its sink; goal: at most 1.3x), and the whole command up to
  its summary (viser, the page's own load and check included), rounds interleaved.

The robot: four arms of eight links on a base, every link a KUKA iiwa STL from pybullet_data
(visual and collision), green so its pixels are found. Exit status 1 if a goal is missed.
"""

from __future__ import annotations

import argparse
import io
import os
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

#: The issue's goals.
FIRST_DRAW_RATIO = 1.5
MOVE_MS = 20.0
DRIVE_VIEW_RATIO = 1.3
CHROMIUM = os.environ.get("URDFKIT_CHROMIUM", "/usr/bin/chromium")


def robot(folder: Path) -> Path:
    """Write the 33-link bench robot into ``folder``."""
    import pybullet_data

    meshes = Path(pybullet_data.getDataPath()) / "kuka_iiwa" / "meshes"
    inertial = ('<inertial><mass value="1"/><inertia ixx="0.01" iyy="0.01" izz="0.01" '
                'ixy="0" ixz="0" iyz="0"/></inertial>')

    def link(name: str, mesh: str) -> str:
        shape = f'<geometry><mesh filename="{meshes / mesh}"/></geometry>'
        return (f'<link name="{name}">{inertial}<visual>{shape}<material name="g"/></visual>'
                f"<collision>{shape}</collision></link>")

    parts = ['<robot name="bench"><material name="g"><color rgba="0.1 0.8 0.2 1"/></material>',
             link("base", "link_0.stl")]
    for arm, (x, y) in enumerate([(0.4, 0.4), (-0.4, 0.4), (-0.4, -0.4), (0.4, -0.4)]):
        parent = "base"
        for k in range(8):
            name = f"a{arm}_l{k}"
            parts.append(link(name, f"link_{k % 7 + 1}.stl"))
            xyz = f"{x} {y} 0.15" if k == 0 else "0 0 0.2"
            parts.append(f'<joint name="a{arm}_j{k}" type="revolute"><parent link="{parent}"/>'
                         f'<child link="{name}"/><origin xyz="{xyz}"/>'
                         f'<axis xyz="{k % 2} {1 - k % 2} 0"/>'
                         '<limit lower="-2" upper="2" effort="10" velocity="1"/></joint>')
            parent = name
    parts.append("</robot>")
    path = folder / "bench33.urdf"
    path.write_text("\n".join(parts))
    return path


def _robot_pixels(page: object) -> int:
    import numpy as np
    from PIL import Image

    png = page.screenshot()  # type: ignore[attr-defined]
    rgb = np.asarray(Image.open(io.BytesIO(png)).convert("RGB")).astype(int)[160:620, :640]
    # Coloured pixels: the page is white and its grid grey; the links are green, or amber
    # where check warns about them (this robot's made-up inertia does).
    return int((rgb.max(axis=2) - rgb.min(axis=2) > 60).sum())


def first_draw(path: Path, browser: object) -> float:
    """Seconds from ``urdfkit view`` starting to robot pixels on the page."""
    t0 = time.perf_counter()
    proc = subprocess.Popen([sys.executable, "-m", "urdfkit", "view", str(path)],
                            stdout=subprocess.PIPE, stderr=subprocess.DEVNULL, text=True)
    try:
        assert proc.stdout is not None
        url = proc.stdout.readline().split()[2]
        page = browser.new_page(viewport={"width": 1000, "height": 700})  # type: ignore[attr-defined]
        page.goto(url)
        while _robot_pixels(page) < 2000:
            if time.perf_counter() - t0 > 120:
                raise RuntimeError("no robot pixels after 120 s")
        took = time.perf_counter() - t0
        page.close()
        return took
    finally:
        proc.terminate()
        proc.wait(timeout=30)


def render_time(path: Path, out: Path) -> float:
    """Wall seconds of ``urdfkit render FILE``."""
    t0 = time.perf_counter()
    subprocess.run([sys.executable, "-m", "urdfkit", "render", str(path), "-o", str(out),
                    "--force"], check=True, capture_output=True)
    return time.perf_counter() - t0


def slider_moves(path: Path, moves: int) -> list[float]:
    """Milliseconds of each of ``moves`` joint moves through the viewer's server API."""
    from urdfkit.draw.view import Viewer

    v = Viewer(str(path))
    try:
        names = [j.name for j in v.model.joints]
        out = []
        for k in range(moves):
            value = ((k * 37) % 200 - 100) / 60
            t0 = time.perf_counter()
            v.set_joints({names[k % len(names)]: value})
            out.append((time.perf_counter() - t0) * 1000)
        return out
    finally:
        v.close()


def drive_loops(seconds: float) -> tuple[float, float]:
    """Wall seconds of one simplecar run loop without, then with, the page's stream."""
    from urdfkit.draw.view import Viewer
    from urdfkit.draw.view_stream import RunStream
    from urdfkit.motion.drive import DriveConfig, Scenario

    config = DriveConfig(throttle=10, steer=0.2, seconds=seconds, keep_trajectory=False)
    with Scenario(config) as sc:
        t0 = time.perf_counter()
        sc.run()
        plain = time.perf_counter() - t0
    with Scenario(config) as sc:
        viewer = Viewer(sc.car_file, inertia_from_file=True, watch=False, ground=40.0)
        try:
            stream = RunStream(viewer, sc.link_poses, None, seconds)
            t0 = time.perf_counter()
            sc.run(sink=stream)
            streamed = time.perf_counter() - t0
        finally:
            viewer.close()
    return plain, streamed


def drive_commands(seconds: float) -> tuple[float, float]:
    """Wall seconds of ``urdfkit drive`` and of ``drive --view --speed max`` to its summary."""
    args = [sys.executable, "-m", "urdfkit", "drive", "--steer", "0.2", "--seconds",
            str(seconds), "--json"]
    t0 = time.perf_counter()
    subprocess.run(args, check=True, capture_output=True)
    plain = time.perf_counter() - t0
    t0 = time.perf_counter()
    # --no-wait: the run starts at once, and the command ends with it (its page closed).
    proc = subprocess.Popen([*args, "--view", "--speed", "max", "--no-wait"],
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                            stdin=subprocess.DEVNULL)
    assert proc.stderr is not None
    while "the run is over" not in proc.stderr.readline():
        if proc.poll() is not None:
            raise RuntimeError("drive --view ended before its summary")
    viewed = time.perf_counter() - t0
    proc.communicate(timeout=30)
    return plain, viewed


def main() -> int:
    """Run the bench and print its figures; 1 if a goal is missed."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("-n", "--rounds", type=int, default=3)
    parser.add_argument("--moves", type=int, default=200)
    parser.add_argument("--drive-seconds", type=float, default=30.0)
    args = parser.parse_args()
    loops = [drive_loops(args.drive_seconds) for _ in range(args.rounds)]
    commands = [drive_commands(args.drive_seconds) for _ in range(args.rounds)]
    loop_ratio = statistics.median(b / a for a, b in loops)
    command_ratio = statistics.median(b / a for a, b in commands)
    from playwright.sync_api import sync_playwright

    with tempfile.TemporaryDirectory() as tmp:
        path = robot(Path(tmp))
        moves = slider_moves(path, args.moves)
        renders = [render_time(path, Path(tmp) / "r.png") for _ in range(args.rounds)]
        with sync_playwright() as pw:
            browser = pw.chromium.launch(executable_path=CHROMIUM, args=[
                "--use-angle=swiftshader", "--enable-unsafe-swiftshader"])
            draws = [first_draw(path, browser) for _ in range(args.rounds)]
            browser.close()
    draw, rend = statistics.median(draws), statistics.median(renders)
    move = statistics.median(moves)
    p95 = sorted(moves)[int(len(moves) * 0.95) - 1]
    print(f"first draw in Chromium: median {draw:.2f} s over {args.rounds} "
          f"({', '.join(f'{d:.2f}' for d in draws)})")
    print(f"urdfkit render:         median {rend:.2f} s over {args.rounds} "
          f"({', '.join(f'{r:.2f}' for r in renders)})")
    print(f"ratio view/render: {draw / rend:.2f} (goal <= {FIRST_DRAW_RATIO})")
    print(f"slider -> scene: median {move:.2f} ms, p95 {p95:.2f} ms over {len(moves)} moves "
          f"(goal <= {MOVE_MS} ms)")
    print(f"drive --view run loop: median {loop_ratio:.2f}x the plain loop over "
          f"{args.rounds} ({', '.join(f'{a:.2f}/{b:.2f} s' for a, b in loops)}; goal <= "
          f"{DRIVE_VIEW_RATIO}x)")
    print(f"drive --view command to its summary: median {command_ratio:.2f}x drive "
          f"({', '.join(f'{a:.2f}/{b:.2f} s' for a, b in commands)})")
    return int(draw / rend > FIRST_DRAW_RATIO or move > MOVE_MS
               or loop_ratio > DRIVE_VIEW_RATIO)


if __name__ == "__main__":
    sys.exit(main())
