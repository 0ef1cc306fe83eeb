"""What ``urdfkit view``'s server lets in (view_guard.py): only its own page, only sane values,
and no camera move from a slider's keys.

The server tests talk to it as a hostile page would: a raw websocket client (the
``websockets`` package viser itself uses) with its own Origin and Host headers, speaking
viser's wire format (zstd-compressed msgpack, decoded here).
"""

from __future__ import annotations

import asyncio
import gc
import math
import time
from pathlib import Path
from typing import Any

import pytest

pytestmark = [pytest.mark.xdist_group("browser"), pytest.mark.usefixtures("plain_lighting")]

pytest.importorskip("viser", reason="urdfkit view needs viser (a core dependency)")

from test_view import ARM  # noqa: E402


@pytest.fixture
def arm(tmp_path: Path) -> Path:
    path = tmp_path / "arm.urdf"
    path.write_text(ARM)
    return path


def _decode(frame: bytes) -> list[dict[str, Any]]:
    """viser's frame: msgpack length, zstd length (8 bytes each, little-endian), the zstd
    msgpack of ``{"messages": [...]}``, then binary buffers (left alone)."""
    import msgspec
    import zstandard

    size = int.from_bytes(frame[:8], "little")
    packed = int.from_bytes(frame[8:16], "little")
    inner = zstandard.ZstdDecompressor().decompress(frame[16:16 + packed], max_output_size=size)
    return list(msgspec.msgpack.decode(inner)["messages"])


def _encode(message: dict[str, Any]) -> bytes:
    import msgspec

    return msgspec.msgpack.encode(message)


#: A page's first report of its camera: viser runs no control callback for a page before it.
CAMERA = {"type": "ViewerCameraMessage", "wxyz": [1.0, 0.0, 0.0, 0.0],
          "position": [2.0, 2.0, 2.0], "fov": 0.8, "near": 0.01, "far": 100.0,
          "image_height": 700, "image_width": 1000, "look_at": [0.0, 0.0, 0.0],
          "up_direction": [0.0, 0.0, 1.0]}


async def _session(port: int, origin: str | None, host: str = "localhost",
                   send: list[dict[str, Any]] | None = None, listen: float = 1.5
                   ) -> tuple[int | None, list[dict[str, Any]]]:
    """Connect as a page of ``origin`` under the Host name ``host``, send ``send`` (after a
    camera report), and gather what the server sends: (HTTP status if refused, messages)."""
    import viser
    import websockets
    import websockets.exceptions

    got: list[dict[str, Any]] = []
    try:
        async with websockets.connect(
                f"ws://{host}:{port}", host="127.0.0.1", port=port, origin=origin,  # type: ignore[arg-type]
                subprotocols=[f"viser-v{viser.__version__}"], max_size=None) as ws:  # type: ignore[list-item]
            async def gather(seconds: float) -> None:
                end = time.monotonic() + seconds
                while (left := end - time.monotonic()) > 0:
                    try:
                        frame = await asyncio.wait_for(ws.recv(), left)
                    except asyncio.TimeoutError:
                        return
                    got.extend(_decode(frame))  # type: ignore[arg-type]

            await gather(listen)
            if send is not None:
                await ws.send(_encode(CAMERA))
                await gather(0.5)
                for message in send:
                    await ws.send(_encode(message))
                await gather(listen)
    except websockets.exceptions.InvalidStatus as e:
        return e.response.status_code, got
    return None, got


def _labelled(messages: list[dict[str, Any]]) -> dict[str, str]:
    """Control label -> its id, from the messages that add controls."""
    return {m["props"]["label"]: m["uuid"] for m in messages
            if isinstance(m.get("props"), dict) and "label" in m["props"] and "uuid" in m}


# --------------------------------------------------------------------------- origins


@pytest.mark.parametrize(("host", "origin", "bound", "ok"), [
    ("localhost:8080", "http://localhost:8080", "127.0.0.1", True),
    ("127.0.0.1:8080", "http://127.0.0.1:8080", "127.0.0.1", True),
    ("[::1]:8080", "http://[::1]:8080", "::1", True),
    ("localhost:8080", None, "127.0.0.1", True),  # a script: no Origin, a loopback Host
    ("localhost:8080", "http://evil.example", "127.0.0.1", False),  # another site's page
    ("localhost:8080", "null", "127.0.0.1", False),  # a sandboxed frame, a file:// page
    ("localhost:8080", "http://localhost:9999", "127.0.0.1", False),  # another local server
    ("localhost:8080", "https://localhost:8080", "127.0.0.1", False),
    ("evil.example:8080", "http://evil.example:8080", "127.0.0.1", False),  # DNS rebinding
    ("evil.example:8080", None, "127.0.0.1", False),
    ("localhost:9999", "http://localhost:9999", "127.0.0.1", False),  # another port
    ("", None, "127.0.0.1", False),
    ("192.168.1.5:8080", "http://192.168.1.5:8080", "0.0.0.0", True),  # --host 0.0.0.0
    ("evil.example:8080", "http://evil.example:8080", "0.0.0.0", False),
    ("192.168.1.5:8080", "http://192.168.1.5:8080", "192.168.1.5", True),
    ("10.0.0.9:8080", "http://10.0.0.9:8080", "192.168.1.5", False),
])
def test_allowed_is_the_page_own_origin_on_this_machine(host: str, origin: str | None,
                                                        bound: str, ok: bool) -> None:
    from urdfkit.draw.view_guard import allowed

    assert allowed(host, origin, bound, 8080) is ok


def test_another_sites_page_and_a_rebinding_host_are_refused_with_no_data(
        arm: Path, viewers: Any, capfd: pytest.CaptureFixture[str]) -> None:
    import urllib.error
    import urllib.request

    v = viewers(arm)
    port = v.port
    # The page's own origin gets the robot: its joint names among the first messages.
    status, got = asyncio.run(_session(port, f"http://localhost:{port}"))
    assert status is None and {"shoulder", "spin", "Link"} <= set(_labelled(got))
    status, got = asyncio.run(_session(port, None, host="127.0.0.1"))  # a script on this host
    assert status is None and "shoulder" in _labelled(got)
    # Another site's page, in this browser: refused at the handshake, not one message.
    for origin, host in (("http://evil.example", "localhost"),
                         (f"http://evil.example:{port}", "evil.example"),  # DNS rebinding
                         (None, "evil.example"), ("null", "localhost")):
        status, got = asyncio.run(_session(port, origin, host=host))
        assert (status, got) == (403, []), (origin, host)
    # The page itself is not served under another site's name either.
    request = urllib.request.Request(v.url, headers={"Host": f"evil.example:{port}"})
    with pytest.raises(urllib.error.HTTPError) as e:
        urllib.request.urlopen(request, timeout=10)
    e.value.close()  # its socket
    assert e.value.code == 403
    with urllib.request.urlopen(v.url, timeout=10) as r:
        assert r.status == 200
    assert "Traceback" not in capfd.readouterr().err


# --------------------------------------------------------------------------- values

#: What a hostile page sends to every control: none of it is a value any control takes.
HOSTILE: list[Any] = [math.nan, math.inf, -math.inf, 1e308, -1e308, "abc", "1.5", None,
                      [1, 2], {"a": 1}, 1, "x" * 10000]


@pytest.mark.slow  # a long browser test (10-30 s): CI's slow step runs it
def test_hostile_values_are_ignored_quietly(arm: Path, viewers: Any,
                                            capfd: pytest.CaptureFixture[str]) -> None:
    v = viewers(arm)
    port = v.port
    _, got = asyncio.run(_session(port, f"http://localhost:{port}"))
    ids = _labelled(got)
    before = {"link": v.select_link.value, "listed": v.vector_text.value,
              "flags": v.joints_text.value, "collision": v.show_collision.value}
    send = [{"type": "GuiUpdateMessage", "uuid": ids[label], "updates": {"value": bad}}
            for label in ("shoulder", "slide", "spin", "Link", "Collision", "Python list",
                          "--joints", "Reset to zero", "Reset view") for bad in HOSTILE]
    # Not a value: any attribute of a control's state (its callbacks among them).
    send += [{"type": "GuiUpdateMessage", "uuid": ids["Link"], "updates": {"update_cb": []}},
             {"type": "GuiUpdateMessage", "uuid": ids["shoulder"],
              "updates": {"disabled": True}},
             {"type": "GuiUpdateMessage", "uuid": ids["spin"], "updates": {"value": 0.5,
                                                                          "removed": True}}]
    # Then a value past the limit, and a sane one: clamped and applied.
    send += [{"type": "GuiUpdateMessage", "uuid": ids["shoulder"], "updates": {"value": 7.0}},
             {"type": "GuiUpdateMessage", "uuid": ids["spin"], "updates": {"value": 0.25}}]
    _, answer = asyncio.run(_session(port, f"http://localhost:{port}", send=send))
    # A page reporting a camera of no size, nowhere (its aspect is 1000 / 0): framed anyway.
    bad_camera = {**CAMERA, "image_height": 0, "position": [math.nan] * 3, "fov": math.inf}
    asyncio.run(_session(port, f"http://localhost:{port}", send=[bad_camera], listen=1.0))
    deadline = time.monotonic() + 10
    while v.model.positions()["spin"] != pytest.approx(0.25) and time.monotonic() < deadline:
        time.sleep(0.05)
    time.sleep(0.5)
    gc.collect()  # an asyncio task's unretrieved exception is printed when it is collected
    time.sleep(0.2)
    err = capfd.readouterr().err
    assert "Traceback" not in err and "Error" not in err, err[-3000:]
    now = v.model.positions()
    # The robot: finite, within its limits, at the clamped and the sane value.
    assert all(math.isfinite(x) for x in now.values())
    assert now == {"shoulder": pytest.approx(1.5), "slide": pytest.approx(1.5 * 0.05 + 0.01),
                   "spin": pytest.approx(0.25)}
    assert {k: s.value for k, s in v.sliders.items()} == pytest.approx(now)
    # The sender too was told the clamped value (viser tells only the others).
    told = [m["updates"]["value"] for m in answer if m.get("type") == "GuiUpdateMessage"
            and m.get("uuid") == ids["shoulder"] and "value" in m.get("updates", {})]
    assert told and told[-1] == pytest.approx(1.5)
    # The menus, checkboxes and read-only texts kept their values; the controls still work.
    assert v.select_link.value == before["link"] and v.show_collision.value is False
    assert not v.sliders["shoulder"].disabled
    assert v.vector_text.value == "[1.5, 0.085, 0.25]" != before["listed"]
    assert v.joints_text.value == "--joints shoulder=1.5,slide=0.085,spin=0.25"


# --------------------------------------------------------------------------- bursts


@pytest.mark.slow  # a long browser test (10-30 s): CI's slow step runs it
def test_a_burst_of_values_ends_on_the_last_one_everywhere(arm: Path, viewers: Any) -> None:
    # A page's values as fast as a socket takes them (a page sends one per 50 ms; a busy
    # server gets them in bunches): 60 to one slider, then 60 to another at once.
    v = viewers(arm)
    v.show_touching.value = True  # a move costs the self-collision pairs too
    port = v.port
    _, got = asyncio.run(_session(port, f"http://localhost:{port}"))
    ids = _labelled(got)
    shoulder = [round(0.02 * k, 4) for k in range(1, 61)]  # up to 1.2 rad
    spin = [round(-0.05 * k, 4) for k in range(1, 61)]  # down to -3 rad
    send = [{"type": "GuiUpdateMessage", "uuid": ids[name], "updates": {"value": x}}
            for name, values in (("shoulder", shoulder), ("spin", spin)) for x in values]
    _, answer = asyncio.run(_session(port, f"http://localhost:{port}", send=send, listen=3.0))
    last = {"shoulder": shoulder[-1], "spin": spin[-1]}
    deadline = time.monotonic() + 20
    while time.monotonic() < deadline and (
            v.model.positions()["spin"] != pytest.approx(last["spin"])
            or v.joints_text.value.split(",")[-1] != f"spin={last['spin']:g}"):
        time.sleep(0.05)
    time.sleep(0.5)
    now = v.model.positions()
    assert (now["shoulder"], now["spin"]) == pytest.approx((last["shoulder"], last["spin"]))
    assert {k: s.value for k, s in v.sliders.items()} == pytest.approx(now)
    assert v.joints_text.value == \
        f"--joints shoulder={last['shoulder']:g},slide={now['slide']:g},spin={last['spin']:g}"
    # And the page was never sent an older value of its own after its last one: it shows
    # the last value it sent.
    for name in ("shoulder", "spin"):
        told = [m["updates"]["value"] for m in answer if m.get("type") == "GuiUpdateMessage"
                and m.get("uuid") == ids[name] and "value" in m.get("updates", {})]
        assert not told or told[-1] == pytest.approx(last[name]), (name, told[-5:])
