"""A long drive shows its progress on a terminal, and nothing of it in a pipe (issue 49,
item 6: `drive --steps 100000000` ran for over an hour without a word).

The run is started with stderr on a pseudo-terminal (stdout piped, as `| tee` leaves it) and
again with stderr piped, each stopped with SIGINT once it is under way.
"""

from __future__ import annotations

import os
import pty
import re
import select
import signal
import subprocess
import sys
import time

LONG = ["drive", "--steps", "100000000"]
#: rich's time-left column, h:mm:ss
TIME_LEFT = re.compile(r"\d+:\d\d:\d\d")


def _start(stderr: int) -> subprocess.Popen[bytes]:
    env = {**os.environ, "COLUMNS": "120", "NO_COLOR": "1"}
    return subprocess.Popen([sys.executable, "-m", "urdfkit", *LONG], stdout=subprocess.PIPE,
                            stderr=stderr, env=env)


def _stop(proc: subprocess.Popen[bytes]) -> bytes:
    proc.send_signal(signal.SIGINT)
    out, _ = proc.communicate(timeout=60)
    assert proc.returncode == 130  # interrupted: the summary covers the steps simulated
    return out


def test_a_long_run_on_a_terminal_shows_progress_with_the_time_left() -> None:
    leader, follower = pty.openpty()
    proc = _start(follower)
    os.close(follower)
    seen = b""
    try:
        deadline = time.monotonic() + 60
        while time.monotonic() < deadline and not (
                b"/100,000,000 steps" in seen and TIME_LEFT.search(seen.decode(errors="replace"))):
            ready, _, _ = select.select([leader], [], [], 1.0)
            if ready:
                try:
                    seen += os.read(leader, 65536)
                except OSError:
                    break
        out = _stop(proc)
    finally:
        if proc.poll() is None:
            proc.kill()
            proc.wait()
        os.close(leader)
    text = seen.decode(errors="replace")
    assert "driving" in text and "/100,000,000 steps" in text, text[-2000:]
    assert TIME_LEFT.search(text), text[-2000:]
    assert b"steps" not in out.split(b"simulated")[0]  # stdout: the summary only, no bar
    assert b"final position" in out


def test_a_long_run_piped_shows_none() -> None:
    proc = _start(subprocess.PIPE)
    try:
        time.sleep(3)  # the bar would be up after 0.25 s
        assert proc.stderr is not None
        proc.send_signal(signal.SIGINT)
        out, err = proc.communicate(timeout=60)
    finally:
        if proc.poll() is None:
            proc.kill()
            proc.wait()
    assert proc.returncode == 130
    assert b"driving" not in err and b"100,000,000 steps" not in err and b"\r" not in err, err
    assert b"final position" in out
