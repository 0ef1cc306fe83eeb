"""``drive --view`` (issue 29): the run streams to the page while it simulates headless, and
what the page ends on is the run ``drive --json`` reports."""

from __future__ import annotations

import json
import subprocess
import sys
import time
from typing import Any

import pytest

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


def test_the_page_ends_where_drive_json_ends() -> None:
    config = DriveConfig(throttle=10, steer=0.2, seconds=3)
    result, stream, _ = _streamed(config, None)
    (base_pos, _), (wheel_pos, _), raw_wheel = stream.final  # type: ignore[attr-defined]
    plain = drive(DriveConfig(throttle=10, steer=0.2, seconds=3))
    # The same run (PyBullet is deterministic): streaming changes nothing it simulates...
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


def test_cli_streams_prints_json_and_serves_until_ctrl_c(served_run: Any) -> None:
    code, out, err = served_run("drive", "--steer", "0.2", "--seconds", "3", "--view",
                                "--speed", "max", "--json")
    assert code == 0, err  # the run finished clean: Ctrl-C only closed the page
    plain = subprocess.run([sys.executable, "-m", "urdfkit", "drive", "--steer", "0.2",
                            "--seconds", "3", "--json"], capture_output=True, text=True,
                           timeout=120)
    assert json.loads(out)["final_position"] == json.loads(plain.stdout)["final_position"]


@pytest.mark.parametrize(("args", "says"), [
    (["--view", "--gui"], "--view replaces --gui"),
    (["--view", "--speed", "0"], "--speed takes a positive factor or max"),
    (["--view", "--speed", "fast"], "--speed takes a positive factor or max"),
])
def test_cli_refuses_bad_view_options(args: list[str], says: str) -> None:
    r = subprocess.run([sys.executable, "-m", "urdfkit", "drive", *args], capture_output=True,
                       text=True, timeout=60)
    assert r.returncode == 2 and says in r.stderr and r.stderr.count("\n") == 1, r.stderr
