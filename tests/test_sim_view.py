"""``sim --view`` (issue 29): every robot of a scenario streams to one page, which ends where
the same scenario run without a page ends."""

from __future__ import annotations

import json
import math
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
from urdfkit.sim import Simulation  # noqa: E402

TWO_CARS = Path(__file__).parent.parent / "examples" / "two_cars.toml"


def test_every_robot_ends_on_the_page_where_the_run_ends() -> None:
    with Simulation.from_file(str(TWO_CARS)) as s:
        bodies = list(s.bodies.values())
        viewer = Viewer(bodies[0].loaded[0], inertia_from_file=True, watch=False)
        try:
            viewer.add_robot(bodies[1].loaded[0], inertia_from_file=True)
            stream = RunStream(viewer, s.link_poses, None, 3.0, robots=True)
            result = s.run(sink=lambda _batch: stream.tick(s.t))
            stream.finish("done")
            end = s.link_poses()
            shown = [[viewer.robot_pose(k, link)[0] for link in range(len(end[k]))]
                     for k in range(2)]
        finally:
            viewer.close()
    with Simulation.from_file(str(TWO_CARS)) as s:
        s.run()
        plain = s.link_poses()
    assert result.steps == 720 and not result.interrupted
    for k in range(2):  # every link of both cars, on the page as in the run and in a plain one
        for page, run, alone in zip(shown[k], end[k], plain[k], strict=True):
            # viser skips a move that np.allclose calls no move (rel 1e-5, abs 1e-8), so a
            # parked car's last microns of settling may not reach the page.
            assert list(page) == pytest.approx(list(run[0]), rel=1e-5, abs=1e-8)
            assert list(run[0]) == pytest.approx(list(alone[0]), abs=1e-9)
    # The driving car moved, the parked one did not: the page shows two different paths.
    assert abs(end[1][0][0][1] - 2.0) > 0.5 and abs(end[0][0][0][1] + 2.0) < 0.01
    assert len(stream.paths) == 2 and all(len(path) >= 2 for path in stream.paths)


def test_cli_sim_view_no_wait_prints_json_and_exits(tmp_path: Path) -> None:
    out = tmp_path / "rows.jsonl"
    r = subprocess.run([sys.executable, "-m", "urdfkit", "sim", str(TWO_CARS), "--view",
                        "--no-wait", "--speed", "max", "--json", "-o", str(out)],
                       capture_output=True, text=True, timeout=120, stdin=subprocess.DEVNULL)
    assert r.returncode == 0, r.stderr
    assert "is closed" in r.stderr
    data = json.loads(r.stdout)
    assert data["steps"] == 720 and data["rows"] == 122
    assert len(out.read_text().splitlines()) == 122  # the rows file as without --view


def test_cli_sim_view_wait_timeout_runs_unwatched_and_exits() -> None:
    start = time.monotonic()
    r = subprocess.run([sys.executable, "-m", "urdfkit", "sim", str(TWO_CARS), "--view",
                        "--speed", "max", "--json", "--wait-timeout", "1.5"],
                       capture_output=True, text=True, timeout=120, stdin=subprocess.DEVNULL)
    assert r.returncode == 0, r.stderr
    assert time.monotonic() - start >= 1.5
    assert "waiting for a page to connect to http://" in r.stderr
    assert "no page connected in 1.5 s; the run starts unwatched" in r.stderr
    assert json.loads(r.stdout)["steps"] == 720


def test_cli_sim_view_refuses_gui_and_real_time() -> None:
    for extra in (["--gui"], ["--real-time"]):
        r = subprocess.run([sys.executable, "-m", "urdfkit", "sim", str(TWO_CARS), "--view",
                            *extra], capture_output=True, text=True, timeout=60)
        assert r.returncode == 2 and "--view paces the run itself" in r.stderr, r.stderr


def test_cli_sim_view_waits_for_a_page_before_the_run(tmp_path: Path) -> None:
    # Unwatched, the run does not start: the rows file is not written while it waits (an
    # unpaced 3 s scenario takes well under the 3 s waited here), and it says why on stderr.
    import signal
    import time

    out = tmp_path / "rows.jsonl"
    proc = subprocess.Popen([sys.executable, "-m", "urdfkit", "sim", str(TWO_CARS), "--view",
                             "--speed", "max", "-o", str(out)],
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    try:
        err = ""
        deadline = time.monotonic() + 120
        while "waiting for a page" not in err and time.monotonic() < deadline \
                and proc.poll() is None:
            err += proc.stderr.readline()  # type: ignore[union-attr]
        assert "waiting for a page to connect" in err and "--no-wait" in err, err
        time.sleep(3)
        assert proc.poll() is None and not out.exists()
        proc.send_signal(signal.SIGINT)
        proc.communicate(timeout=30)
        assert proc.returncode == 130 and not out.exists()
    finally:
        if proc.poll() is None:
            proc.kill()
            proc.communicate()


def test_sim_view_readouts_show_the_first_robots_joints_as_the_run_leaves_them() -> None:
    """sim --view's sliders read the run's joints (the first robot's), held to raw PyBullet."""
    from urdfkit.commands.simulating import _sim_view

    doc = {"physics": {"time_step": 1 / 240}, "ground": "simpleplane", "duration": 1.0,
           "robots": [{"name": "north", "template": "simplecar",
                       "drive": [{"until": 1.0, "throttle": 10, "steer": 0.3}]}]}
    with Simulation(doc) as s:
        stream = _sim_view(s, None, None)
        viewer = stream.viewer
        try:
            s.run(sink=lambda _batch: stream.tick(s.t))
            stream.finish("done")
            body = next(iter(s.bodies.values())).body
            bullet = s.bullet
            raw = {bullet.getJointInfo(body, j)[1].decode(): bullet.getJointState(body, j)[0]
                   for j in range(bullet.getNumJoints(body))}
            shown = {name: float(sl.value) for name, sl in viewer.sliders.items()}
        finally:
            viewer.close()
    # The car's wheels turned (10 rad/s for 1 s): the readouts are not the load pose.
    assert any(abs(v) > 1.0 for v in shown.values())
    for name, value in shown.items():
        lo, hi = float(viewer.sliders[name].min), float(viewer.sliders[name].max)
        assert value == pytest.approx(min(max(raw[name], lo), hi), abs=1e-6), name


def test_sim_view_readouts_are_the_followed_robots_joints() -> None:
    """two_cars, following north: the sliders and the pose fields hold north's joints as raw
    PyBullet has them at the end, not the parked car's (they did whichever car was followed);
    following parked again, parked's, in the replay too."""
    import re

    from urdfkit.commands.simulating import _sim_view

    with Simulation.from_file(str(TWO_CARS)) as s:
        stream = _sim_view(s, None, None)
        viewer = stream.viewer
        try:
            stream.camera.value = "follow north"
            s.run(sink=lambda _batch: stream.tick(s.t))
            stream.finish("**Done**")
            bullet = s.bullet
            raw = {name: {bullet.getJointInfo(b.body, j)[1].decode():
                          bullet.getJointState(b.body, j)[0]
                          for j in range(bullet.getNumJoints(b.body))}
                   for name, b in s.bodies.items()}

            def shown() -> tuple[dict[str, float], dict[str, float]]:
                sliders = {name: float(sl.value) for name, sl in viewer.sliders.items()}
                flags = viewer.joints_text.value.removeprefix("--joints ")
                return sliders, {k: float(v) for k, v in
                                 (pair.split("=") for pair in flags.split(","))}

            north_sliders, north_flags = shown()
            status = viewer.status.content
            stream.camera.value = "follow parked"
            stream.show_time(3.0)  # the replay's last frame, parked followed
            parked_sliders, parked_flags = shown()
        finally:
            viewer.close()
    wheel = "base_to_left_back_wheel"
    # North drove 3 s at 10 rad/s; the parked car's wheels barely turned.
    assert abs(raw["north"][wheel]) > 10 and abs(raw["parked"][wheel]) < 0.1
    for robot, sliders, flags in (("north", north_sliders, north_flags),
                                  ("parked", parked_sliders, parked_flags)):
        # (the field prints six significant digits)
        assert flags == pytest.approx({k: raw[robot][k] for k in flags}, rel=1e-5,
                                      abs=1e-5), robot
        for name, value in sliders.items():
            lo, hi = float(viewer.sliders[name].min), float(viewer.sliders[name].max)
            assert value == pytest.approx(min(max(raw[robot][name], lo), hi), abs=1e-6), \
                (robot, name)
    assert re.search(r"Joint readouts: north's", status), status


def test_a_run_that_waited_for_a_page_is_paced_from_its_start() -> None:
    """The pace counts from the run's first step, not from when the page was set up.

    The page is up before the wait for a browser; paced from then, a run that waited longer
    than it lasts ran unpaced once a page came (measured: a 3 s scenario at real time over in
    0.7 s after the page connected, having waited 6 s).
    """
    import time

    doc = {"physics": {"time_step": 1 / 240}, "ground": "simpleplane", "duration": 1.0,
           "robots": [{"name": "north", "template": "simplecar",
                       "drive": [{"until": 1.0, "throttle": 10, "steer": 0}]}]}
    with Simulation(doc) as s:
        stream = _sim_view_of(s, pace=2.0)
        try:
            time.sleep(1.0)  # the wait for a page: longer than the run at 2x (0.5 s)
            start = time.perf_counter()
            s.run(sink=lambda _batch: stream.tick(s.t))
            wall = time.perf_counter() - start
        finally:
            stream.viewer.close()
    # 1 simulated second at twice real time takes half a second of wall time, at least.
    assert wall >= 0.5, wall


def _sim_view_of(s: Simulation, pace: float | None) -> RunStream:
    """``sim --view``'s page for a simulation, not waiting for a browser."""
    from urdfkit.commands.simulating import _sim_view

    stream: RunStream = _sim_view(s, pace, None)
    return stream


# --------------------------------------------------------------------------- in a browser

@pytest.mark.slow  # a long browser test (10-30 s): CI's slow step runs it
def test_sim_view_in_a_browser_waits_follows_the_chosen_robot_and_replays(
        chromium: Any) -> None:
    """two_cars on the page in headless Chromium (tests/conftest.py's ``chromium``).

    The run waits for the page; the page's Camera dropdown picks the driving car; the camera
    the browser reports (viser's camera messages come from the page, never from the server)
    looks at that car where the run's own rows have it: at the end, and replayed to the start,
    the middle and the end again; the replay's status line gives the same place. Following
    the other car moves the camera and the status line to it, and a page reloaded after the
    run opens on it.
    """
    import re
    import socket
    import threading
    import time

    with socket.socket() as sock:  # a free port, so the page's URL is known here
        sock.bind(("127.0.0.1", 0))
        port = sock.getsockname()[1]
    with Simulation.from_file(str(TWO_CARS)) as s:
        started: list[RunStream] = []
        # sim --view's own page, waiting for a browser as the command does.
        from urdfkit.commands.shared import wait_for_page
        from urdfkit.commands.simulating import _sim_view

        def serve() -> None:
            stream = _sim_view(s, 2.0, port)
            started.append(stream)
            wait_for_page("sim", stream.viewer, True)
            started.append(stream)  # twice: a page came

        waiter = threading.Thread(target=serve, daemon=True)
        waiter.start()
        time.sleep(1.0)
        assert waiter.is_alive() and s.step_count == 0  # unwatched: nothing has run
        page = chromium.new_page(viewport={"width": 1000, "height": 700})
        try:
            page.goto(f"http://127.0.0.1:{port}")
            waiter.join(60)
            assert not waiter.is_alive() and len(started) == 2, \
                "the page's connection did not start it"
            stream = started[0]
            viewer = stream.viewer
            (client,) = viewer.server.get_clients().values()
            seen: list[Any] = []  # look_at as the browser reports it
            views: list[Any] = []  # and the whole camera
            client.camera.on_update(lambda cam: (seen.append(tuple(cam.look_at)), views.append(
                (cam.position, cam.look_at, cam.up_direction, cam.fov, cam.aspect))))

            def camera_at(where: Any) -> bool:
                return _wait_for(lambda: bool(seen) and seen[-1] == pytest.approx(
                    where, abs=1e-3), 30)

            # The default follows the first robot (parked); the user picks the other.
            page.locator("input[role=combobox][value='follow parked']").click()
            page.get_by_role("option", name="follow north").click()
            assert _wait_for(lambda: stream.camera.value == "follow north", 20)
            start = time.perf_counter()
            result = s.run(sink=lambda _batch: stream.tick(s.t))
            wall = time.perf_counter() - start
            stream.finish("**Done**")
            north = [r for r in result.to_dicts() if r["robot"] == "north"]
            parked_end = [r for r in result.to_dicts() if r["robot"] == "parked"][-1]
            end = north[-1]["base_position"]
            assert wall >= 1.5  # 3 simulated s at 2x, paced from the start, not the wait
            assert abs(end[1] - north[0]["base_position"][1]) > 2.0  # north drove off
            # The browser's camera ended on north's last row, 6 m from the parked car.
            assert camera_at(end), (seen[-3:], end)
            assert math.dist(seen[-1], parked_end["base_position"]) > 5.0

            page.get_by_text("Time (s)").first.wait_for(timeout=30000)  # the replay slider
            slider = page.locator("[role=slider]").first
            slider.focus()
            page.keyboard.press("Home")
            assert camera_at(north[0]["base_position"]), (seen[-3:], north[0])
            for _ in range(50):  # 100 steps over the run: 50 to the middle
                page.keyboard.press("ArrowRight")
            status = page.get_by_text(re.compile(r"t = 1\.50 s")).first
            status.wait_for(timeout=30000)
            mid = next(r for r in north if abs(r["t"] - 1.5) < 1e-6)["base_position"]
            shown = re.search(r"north's base at x (\S+), y (\S+), z (\S+) m",
                              status.inner_text())
            assert shown is not None, status.inner_text()
            assert [float(v) for v in shown.groups()] == pytest.approx(mid, abs=2e-3)
            assert camera_at(mid), (seen[-3:], mid)
            page.keyboard.press("End")  # the replay ends where the run ended
            page.get_by_text(re.compile(r"t = 3\.00 s")).first.wait_for(timeout=30000)
            assert camera_at(end), (seen[-3:], end)
            assert viewer.robot_pose(1)[0] == pytest.approx(end, abs=1e-6)
            # Following the other car now: the status line and the camera go to it.
            page.locator("input[role=combobox][value='follow north']").click()
            page.get_by_role("option", name="follow parked").click()
            status = page.get_by_text(re.compile(r"parked's base at")).first
            status.wait_for(timeout=30000)
            shown = re.search(r"t = 3\.00 s .* base at x (\S+), y (\S+), z (\S+) m",
                              status.inner_text())
            assert shown is not None, status.inner_text()
            parked = parked_end["base_position"]
            assert [float(v) for v in shown.groups()] == pytest.approx(parked, abs=2e-3)
            # simplecar is 0.4 m long: the camera looks at the car (its box's middle).
            assert _wait_for(lambda: math.dist(seen[-1], parked) < 0.3, 30), (seen[-3:], parked)
            # Framing every path: each row of both cars is inside the browser's camera view.
            page.locator("input[role=combobox][value='follow parked']").click()
            page.get_by_role("option", name="frame the whole path").click()
            points = [r["base_position"] for r in result.to_dicts()]
            assert _wait_for(lambda: _all_in_view(views[-1], points), 30), views[-1]
            assert not _all_in_view(views[0], points)  # (the first view did not hold them)
            # Free: the replay no longer moves the camera.
            page.locator("input[role=combobox][value='frame the whole path']").click()
            page.get_by_role("option", name="free").click()
            assert _wait_for(lambda: stream.camera.value == "free", 20)
            before = tuple(client.camera.look_at)
            page.locator("[role=slider]").first.focus()
            page.keyboard.press("Home")
            page.get_by_text(re.compile(r"t = 0\.00 s")).first.wait_for(timeout=30000)
            time.sleep(0.5)  # (show_time aims after it writes the status)
            assert tuple(client.camera.look_at) == before
            # A page opened after the run (here, reloaded) frames the first car where the run
            # left it (free: the first), not the origin (2 m away) where the file puts a car.
            late: list[Any] = []  # look_at as the new page reports it

            def watch(new: Any) -> None:  # (viser also calls this for the pages already in)
                if new.client_id != client.client_id:
                    new.camera.on_update(lambda cam: late.append(tuple(cam.look_at)))

            viewer.server.on_client_connect(watch)
            page.reload()
            assert _wait_for(lambda: bool(late) and math.dist(late[-1], parked) < 0.3, 30), \
                (late[-3:], parked)
        finally:
            page.close()
            if started:
                started[0].viewer.close()


def _all_in_view(view: Any, points: list[Any]) -> bool:
    """Whether every point projects inside a pinhole camera's frame.

    ``view``: (position, look_at, up, vertical field of view in radians, width / height), as
    the page reported its camera.
    """
    import numpy as np

    eye, target, up, fov, aspect = (np.asarray(v, dtype=float) for v in view)
    forward = (target - eye) / np.linalg.norm(target - eye)
    right = np.cross(forward, up)
    right /= np.linalg.norm(right)
    true_up = np.cross(right, forward)
    half = math.tan(float(fov) / 2)
    for point in points:
        d = np.asarray(point, dtype=float) - eye
        depth = float(d @ forward)
        if depth <= 0 or abs(d @ true_up) > half * depth or \
                abs(d @ right) > half * float(aspect) * depth:
            return False
    return True


