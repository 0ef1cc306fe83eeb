"""``drive --view`` (issue 29): the run streams to the page while it simulates headless, and
what the page ends on is the run ``drive --json`` reports."""

from __future__ import annotations

import json
import subprocess
import sys
import time
from pathlib import Path
from typing import Any

import pytest
from conftest import wait_until as _wait_for

#: One worker runs every page and server test (pytest-xdist --dist loadgroup): two Chromiums
#: drawing WebGL in software on 2 cores starve each other.
pytestmark = [pytest.mark.xdist_group("browser"), pytest.mark.usefixtures("plain_lighting")]

pytest.importorskip("viser", reason="urdfkit view needs viser (a core dependency)")

from urdfkit.draw.view import Viewer  # noqa: E402
from urdfkit.draw.view_stream import RunStream  # noqa: E402
from urdfkit.motion.drive import DriveConfig, Scenario, drive  # noqa: E402


def _streamed(config: DriveConfig, speed: float | None) -> tuple[object, RunStream, float]:
    with Scenario(config) as sc:
        viewer = Viewer(sc.car_file, inertia_from_file=True, watch=False, ground=20.0)
        try:
            start = time.perf_counter()  # before the stream's own clock starts
            stream = RunStream(viewer, sc.link_poses, speed, config.seconds or 0.0)
            times: list[float] = []

            def sink(row: Any) -> None:
                times.append(float(row[0]))
                stream(row)

            result = sc.run(sink=sink)
            wall = time.perf_counter() - start
            stream.finish("done")
            base = viewer.link_pose(viewer.model.links[0].name)
            wheel = viewer.link_pose("left_back_wheel")
            raw_wheel = sc.link_poses()[[lk.name for lk in viewer.model.links]
                                        .index("left_back_wheel")]
        finally:
            viewer.close()
    stream.final = (base, wheel, raw_wheel)  # type: ignore[attr-defined]
    stream.last_t = times[-1] if times else 0.0  # type: ignore[attr-defined]
    return result, stream, wall


@pytest.mark.parametrize("engine", ["pybullet", "mujoco"])
def test_the_page_ends_where_drive_json_ends(engine: str) -> None:
    if engine == "mujoco":
        pytest.importorskip("mujoco")
    config = DriveConfig(throttle=10, steer=0.2, seconds=3, engine=engine)
    result, stream, _ = _streamed(config, None)
    (base_pos, _), (wheel_pos, _), raw_wheel = stream.final  # type: ignore[attr-defined]
    plain = drive(DriveConfig(throttle=10, steer=0.2, seconds=3, engine=engine))
    # The same run (each engine is deterministic): streaming changes nothing it simulates...
    assert result.final_position == pytest.approx(plain.final_position, abs=1e-9)  # type: ignore[attr-defined]
    # ...and the page's base and wheel frames are where the run's session has them.
    assert base_pos == pytest.approx(plain.final_position, abs=1e-6)
    assert wheel_pos == pytest.approx(raw_wheel[0], abs=1e-6)
    assert stream.frames >= 2
    # The path on the ground: every sample, ending at the final position.
    assert len(stream.path) == result.samples  # type: ignore[attr-defined]
    assert stream.path[-1][:2] == pytest.approx(plain.final_position[:2], abs=1e-9)


def test_the_run_is_paced_to_its_speed() -> None:
    # At 4x real time, the last sample (at ~2 simulated seconds) is shown no earlier than a
    # quarter of its time after the stream started: the bound the pacing guarantees (an
    # unpaced run of simplecar takes ~0.1 s). The last sample is not at 2.0 exactly.
    _, stream, wall = _streamed(DriveConfig(throttle=10, seconds=2), 4.0)
    last = stream.last_t  # type: ignore[attr-defined]
    assert last > 1.9 and wall >= last / 4.0


def _urdfkit(*args: str, timeout: float = 120) -> subprocess.CompletedProcess[str]:
    """``urdfkit ARGS`` as a script runs it: no terminal on stdin, and a time limit."""
    return subprocess.run([sys.executable, "-m", "urdfkit", *args], capture_output=True,
                          text=True, timeout=timeout, stdin=subprocess.DEVNULL)


def test_cli_no_wait_runs_prints_json_and_exits() -> None:
    # --no-wait is for scripts: the run starts at once, and the command ends with it (it
    # used to print its JSON and then serve the page until Ctrl-C, never exiting).
    r = _urdfkit("drive", "--steer", "0.2", "--seconds", "3", "--view", "--no-wait",
                 "--speed", "max", "--json")
    assert r.returncode == 0, r.stderr
    assert "its page at http://" in r.stderr and "is closed" in r.stderr, r.stderr
    plain = _urdfkit("drive", "--steer", "0.2", "--seconds", "3", "--json")
    assert json.loads(r.stdout)["final_position"] == json.loads(plain.stdout)["final_position"]


@pytest.mark.slow  # 8 s of waiting by design: CI's slow step runs it
def test_cli_without_a_terminal_says_it_waits_and_wait_timeout_ends_the_wait() -> None:
    import re
    import signal

    # No page and no terminal: stderr says the wait has no end but a page, a signal or
    # --wait-timeout, and it waits (a 1 s unpaced drive would be over long before 3 s).
    proc = subprocess.Popen([sys.executable, "-m", "urdfkit", "drive", "--seconds", "1",
                             "--view", "--speed", "max", "--json"], stdin=subprocess.DEVNULL,
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    seen: list[str] = []
    try:
        assert _lines_until(proc, "waiting for a page", 120, seen), "".join(seen)
        assert re.search(r"to connect to http://\S+ before the run starts; with no terminal, "
                         r"only a page, a signal \(Ctrl-C\) or --wait-timeout ends the wait",
                         seen[-1]), seen[-1]
        time.sleep(3)
        assert proc.poll() is None
        proc.send_signal(signal.SIGINT)
        out, _ = proc.communicate(timeout=30)
        assert proc.returncode == 130 and out == ""
    finally:
        if proc.poll() is None:
            proc.kill()
            proc.communicate()
    # --wait-timeout 2: after 2 s without a page the run starts unwatched, prints its JSON
    # and the command ends (exit 0: the run is done and clean).
    start = time.monotonic()
    r = _urdfkit("drive", "--seconds", "1", "--view", "--speed", "max", "--json",
                 "--wait-timeout", "2")
    assert r.returncode == 0, r.stderr
    assert time.monotonic() - start >= 2.0
    assert "at most 2 s" in r.stderr and "no page connected in 2 s" in r.stderr, r.stderr
    assert json.loads(r.stdout)["sim_time"] == pytest.approx(1.0, abs=0.01)


@pytest.mark.parametrize(("args", "says"), [
    (["--view", "--gui"], "--view replaces --gui"),
    (["--view", "--speed", "0"], "--speed takes a positive factor or max"),
    (["--view", "--speed", "fast"], "--speed takes a positive factor or max"),
    (["--wait-timeout", "2"], "--wait-timeout bounds --view's wait for a page; add --view"),
    (["--view", "--no-wait", "--wait-timeout", "2"], "--no-wait waits for no page"),
    (["--view", "--wait-timeout", "nan"], "--wait-timeout takes a number of seconds, got nan"),
])
def test_cli_refuses_bad_view_options(args: list[str], says: str) -> None:
    r = subprocess.run([sys.executable, "-m", "urdfkit", "drive", *args], capture_output=True,
                       text=True, timeout=60)
    assert r.returncode == 2 and says in r.stderr and r.stderr.count("\n") == 1, r.stderr


# --------------------------------------------------------------------------- in a browser

# The ``chromium`` fixture (Debian's Chromium under Playwright) is tests/conftest.py's.


def _lines_until(proc: Any, text: str, seconds: float, seen: list[str]) -> bool:
    """Take the process's stderr lines into ``seen`` until one holds ``text``.

    Read by a thread into a queue (:func:`_reader`): a buffered pipe under select() can hold
    a line select() never reports.
    """
    import queue

    lines = _reader(proc)
    end = time.monotonic() + seconds
    while time.monotonic() < end:
        try:
            line = lines.get(timeout=0.2)
        except queue.Empty:
            continue
        if line is None:
            return False
        seen.append(line)
        if text in line:
            return True
    return False


def _reader(proc: Any) -> Any:
    """One queue of the process's stderr lines (None at its end), made on first use."""
    import queue
    import threading

    if not hasattr(proc, "lines"):
        proc.lines = queue.Queue()

        def pump() -> None:
            for line in iter(proc.stderr.readline, ""):
                proc.lines.put(line)
            proc.lines.put(None)

        threading.Thread(target=pump, daemon=True).start()
    return proc.lines


def _car_pixels(page: Any) -> int:
    """Pixels of the car in the canvas: its black tyres (the page is white, the grid grey)."""
    import io

    import numpy as np
    from PIL import Image

    box = page.locator("canvas").first.bounding_box()
    # Software WebGL on a loaded 2-core machine: a screenshot may take a while.
    png = page.screenshot(timeout=120000)
    rgb = np.asarray(Image.open(io.BytesIO(png)).convert("RGB")).astype(int)
    x0, y0 = int(box["x"]), int(box["y"])
    x1, y1 = int(box["x"] + box["width"]), int(box["y"] + box["height"])
    crop = rgb[y0 + 160:y1 - 90, x0:x1]  # below the WebGL notice, above the axes gizmo
    return int((crop.max(axis=2) < 50).sum())


@pytest.mark.slow  # a long browser test (10-30 s): CI's slow step runs it
def test_drive_view_waits_for_the_page_follows_the_car_and_replays(
        chromium: Any, tmp_path: Path) -> None:
    import csv
    import re
    import signal

    run_csv = tmp_path / "run.csv"
    proc = subprocess.Popen(
        [sys.executable, "-m", "urdfkit", "drive", "--view", "--speed", "4", "--seconds", "8",
         "--trajectory", str(run_csv)], stdout=subprocess.PIPE, stderr=subprocess.PIPE,
        text=True)
    seen: list[str] = []
    page = None
    try:
        assert _lines_until(proc, "waiting for a page", 120, seen), "".join(seen)
        url = re.search(r"(http://\S+)", seen[-1]).group(1)  # type: ignore[union-attr]
        # Unwatched, it waits: at 4x real time the 8 s run would take 2 s, and after 4 s
        # nothing has run (no line but the wait, the process alive).
        assert not _lines_until(proc, "until Ctrl-C", 4, seen), "".join(seen)
        assert proc.poll() is None
        page = chromium.new_page(viewport={"width": 1000, "height": 700})
        page.goto(url)
        assert _lines_until(proc, "a page connected", 60, seen), "".join(seen)
        page.get_by_text("Running").first.wait_for(timeout=30000)  # watched from the start
        assert _lines_until(proc, "until Ctrl-C", 120, seen), "".join(seen)
        page.get_by_text("Done").first.wait_for(timeout=30000)
        with run_csv.open() as f:
            rows = list(csv.DictReader(f))
        end = rows[-1]
        # The car, 8 m from where it started, is in the canvas at the end (the camera followed).
        assert float(end["x"]) ** 2 + float(end["y"]) ** 2 > 4.0
        assert _wait_for(lambda: _car_pixels(page) > 200, 20), _car_pixels(page)
        # Replay to the midpoint: the base is where the run's own sample at 4 s has it.
        slider = page.locator("[role=slider]").first
        slider.focus()
        page.keyboard.press("Home")
        for _ in range(50):  # 100 steps over the run: 50 to the middle
            page.keyboard.press("ArrowRight")
        page.get_by_text("Replay").first.wait_for(timeout=10000)
        status = page.get_by_text(re.compile(r"t = 4\.00 s")).first
        status.wait_for(timeout=20000)
        x, y, z = (float(v) for v in re.search(
            r"base at x (\S+), y (\S+), z (\S+) m", status.inner_text()).groups())  # type: ignore[union-attr]
        mid = next(r for r in rows if abs(float(r["t"]) - 4.0) < 1e-9)
        assert (x, y, z) == pytest.approx((float(mid["x"]), float(mid["y"]), float(mid["z"])),
                                          abs=2e-3)  # the status prints millimetres
        # The joint readouts show the run's values at that time, not the model's zero.
        wheel = "base_to_left_back_wheel"
        shown = next(v for v in (t.input_value() for t in page.locator("textarea").all())
                     if v.startswith("--joints"))
        value = float(re.search(rf"{wheel}=(\S+?)(,|$)", shown).group(1))  # type: ignore[union-attr]
        assert value == pytest.approx(float(mid[f"{wheel}_angle"]), rel=1e-5)  # 6 digits
        assert value > 10  # the wheel has turned many times by then
        assert _wait_for(lambda: _car_pixels(page) > 200, 20)  # the camera followed it back
        proc.send_signal(signal.SIGINT)
        proc.communicate(timeout=30)
        assert proc.returncode == 0
    finally:
        if page is not None:
            page.close()
        if proc.poll() is None:
            proc.kill()
            proc.communicate()




def test_the_page_names_the_template_not_its_cache_file() -> None:
    # The built car is a file in urdfkit's cache; the findings and notes name "simplecar".
    import re

    from urdfkit.commands.driving import _run_view
    from urdfkit.draw import view_page

    config = DriveConfig(seconds=0.1)
    with Scenario(config) as sc:
        assert "simplecar" in sc.car_file and sc.car_file != "simplecar"
        stream = _run_view(sc, config, None, None)
        try:
            m = stream.viewer.model
            assert m.file == "simplecar" and m.resolved.name == "simplecar"
            assert m.findings and all(f.file == "simplecar" for f in m.findings)
            shown = re.sub(r"\\(.)", r"\1", re.sub(r"<[^>]+>", "", view_page.findings(m)))
            assert sc.car_file not in shown
        finally:
            stream.viewer.close()
