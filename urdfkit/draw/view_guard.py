"""What ``urdfkit view``'s server lets in: other sites' pages, hostile values, camera keys.

viser 1.1 serves its page and its websocket to any page that asks, applies whatever a client
sends to a control, and moves the camera on arrow keys pressed on a slider. Three guards:

- :func:`guarded_serve`: the websocket server answers only the page's own origin, under a
  Host name that is this machine's (a page of another site, or a DNS-rebinding name, gets a
  403 and no data);
- :class:`Gate`: a value a client sends to a control is checked before viser applies it
  (a number finite and within the slider, a menu choice among its options, nothing to a
  disabled control, nothing but ``value``); what is refused is ignored quietly;
- :func:`keep_keys_off_camera`: arrow keys pressed on a slider or menu move that control only.

viser has no option for any of them, so each reaches into viser where noted; each checks
that what it relies on is there and raises :class:`GuardError` otherwise, so a viser that
changed fails to start rather than serving unguarded.
"""

from __future__ import annotations

import asyncio
import contextlib
import http
import ipaddress
import math
import socket
import threading
from collections.abc import Callable, Iterator
from typing import Any

from urdfkit.core.errors import EngineError


class GuardError(EngineError):
    """This viser cannot be guarded as the viewer needs (it changed under us)."""


#: Host names that reach this machine's loopback interface.
LOOPBACK = ("localhost", "127.0.0.1", "[::1]")
#: Bind addresses that listen on every interface.
WILDCARD = ("0.0.0.0", "::", "")


def _split_host(header: str) -> tuple[str, int | None]:
    """A Host header's name (IPv6 in brackets, lower case) and port (None if absent or bad)."""
    header = header.strip().lower()
    if header.startswith("["):
        name, _, rest = header.partition("]")
        name += "]"
        port_text = rest[1:] if rest.startswith(":") else ""
        if rest and not rest.startswith(":"):
            return header, None
    else:
        name, _, port_text = header.partition(":")
    if not port_text:
        return name, 80
    return (name, int(port_text)) if port_text.isdigit() else (name, None)


def _is_ip(name: str) -> bool:
    try:
        ipaddress.ip_address(name.strip("[]"))
    except ValueError:
        return False
    return True


def _own_names() -> set[str]:
    """This machine's own names (for a server bound to every interface)."""
    names = set(LOOPBACK)
    for name in (socket.gethostname(), socket.getfqdn()):
        if name:
            names.add(name.lower())
            names.add(f"{name.lower()}.local")
    return names


def allowed(host: str | None, origin: str | None, bound: str, port: int) -> bool:
    """Whether a request's Host and Origin headers are the viewer's own page's.

    ``Host`` must name this machine on ``port``: a loopback name for a server bound to
    loopback, the bound address (or a loopback name) for one bound to an address, and an IP
    address or this machine's own name for one bound to every interface. A DNS-rebinding page
    comes under its own domain name and is refused. ``Origin``, when a browser sends one (it
    always does on a websocket), must be ``http://`` + that Host: the page the server served.
    A request with no Origin is no other site's page (a script, a link opened from a
    terminal), so its Host alone decides.
    """
    if not host:
        return False
    name, at = _split_host(host)
    if at != port:
        return False
    bound = bound.strip().lower()
    bound_name = f"[{bound}]" if ":" in bound else bound
    if bound in WILDCARD:
        ok = _is_ip(name) or name in _own_names()
    elif bound_name in LOOPBACK:
        ok = name in LOOPBACK
    else:
        ok = name == bound_name or name in LOOPBACK
    if not ok:
        return False
    return origin is None or origin.strip().lower() == f"http://{host.strip().lower()}"


def _gate(bound: str, inner: Any) -> Any:
    """The server's ``process_request`` wrapped: a 403 unless :func:`allowed` says yes."""

    def process_request(connection: Any, request: Any) -> Any:
        hosts = request.headers.get_all("Host")
        origins = request.headers.get_all("Origin")
        port = int(connection.local_address[1])
        if len(hosts) != 1 or len(origins) > 1 or \
                not allowed(hosts[0], origins[0] if origins else None, bound, port):
            return connection.respond(http.HTTPStatus.FORBIDDEN,
                                      "urdfkit view answers only its own page\n")
        return None if inner is None else inner(connection, request)

    return process_request


_SERVE_LOCK = threading.Lock()


@contextlib.contextmanager
def guarded_serve(bound: str) -> Iterator[list[bool]]:
    """Within it, a viser server that starts answers only its own page (:func:`allowed`).

    viser starts websockets' ``serve`` itself and takes no ``process_request`` or
    ``origins`` of ours, so ``websockets.asyncio.server.serve`` is wrapped while the server
    starts (viser looks it up when it binds, before its constructor returns), one start at a
    time. The list it yields gets an entry when the wrapper was used; the caller checks it,
    so a viser that binds some other way is refused rather than left unguarded.
    """
    import websockets.asyncio.server as ws_server

    original = ws_server.serve
    used: list[bool] = []

    def serve(*args: Any, **kwargs: Any) -> Any:
        kwargs["process_request"] = _gate(bound, kwargs.get("process_request"))
        used.append(True)
        return original(*args, **kwargs)

    with _SERVE_LOCK:
        ws_server.serve = serve  # type: ignore[assignment,misc]
        try:
            yield used
        finally:
            ws_server.serve = original  # type: ignore[misc]


# --------------------------------------------------------------------------- values


def clean_value(handle: Any, value: Any) -> tuple[bool, Any]:
    """Whether a value a client sent may reach a control, and the value to apply.

    A slider or number takes a finite number, clamped to its bounds; a checkbox or button a
    bool; a menu one of its options; a text a string; a disabled control nothing. Any other
    control takes a value of its current value's type (tuples element by element).
    """
    import viser

    if getattr(handle, "disabled", False):
        return False, None
    current = handle.value
    if isinstance(handle, (viser.GuiSliderHandle, viser.GuiNumberHandle)):
        if isinstance(value, bool) or not isinstance(value, (int, float)) or \
                not math.isfinite(value):
            return False, None
        lo, hi = getattr(handle, "min", None), getattr(handle, "max", None)
        if lo is not None:
            value = max(value, lo)
        if hi is not None:
            value = min(value, hi)
        return True, type(current)(value)
    if isinstance(handle, (viser.GuiDropdownHandle, viser.GuiButtonGroupHandle)):
        return (True, value) if isinstance(value, str) and value in handle.options else \
            (False, None)
    if isinstance(current, bool):
        return (True, value) if isinstance(value, bool) else (False, None)
    if isinstance(current, tuple):
        if not isinstance(value, (list, tuple)) or len(value) != len(current):
            return False, None
        out = []
        for old, new in zip(current, value, strict=True):
            ok, v = _same_kind(old, new)
            if not ok:
                return False, None
            out.append(v)
        return True, tuple(out)
    return _same_kind(current, value)


def _same_kind(old: Any, new: Any) -> tuple[bool, Any]:
    if isinstance(old, (int, float)) and not isinstance(old, bool):
        if isinstance(new, bool) or not isinstance(new, (int, float)) or \
                not math.isfinite(new):
            return False, None
        return True, type(old)(new)
    return (True, new) if type(new) is type(old) else (False, None)


#: How long a control several pages changed is left alone before every page is sent its
#: value (:meth:`Gate._settle`), and how recent a change counts.
SETTLE_SECONDS = 0.3
CONTENDED_SECONDS = 3.0
#: The longest :meth:`Gate.set` waits for viser's event loop before setting the value itself.
SET_TIMEOUT = 10.0


class Gate:
    """The one way in for the values pages send to controls: checked, then told in order.

    viser casts what a client sends to the control's type (a string sent to a slider raised
    in its handler: a traceback per message), applies NaN, values out of range and values
    for disabled controls, and lets ``updates`` set any attribute of a control's state (its
    callbacks among them). Its handler is wrapped: a value :func:`clean_value` refuses is
    dropped quietly, a clamped one applied clamped and then sent to every page, the
    sender's included (viser sends a change to the other pages only, so the sender would
    keep showing its own value).

    :meth:`on_value` hears a control's values as the page sent them, on viser's event loop,
    in the order they arrived. A viser callback reads the control's value instead, which
    another thread may have written over in between: a page's value was lost so.

    Reaches into viser: the server's websocket interface, the GUI's handler and its table of
    inputs by id (there is no public hook for incoming values).
    """

    def __init__(self, server: Any) -> None:
        try:
            import viser
            from viser import _messages

            self._button = viser.GuiButtonHandle
            self._update = _messages.GuiUpdateMessage
            self._loop = server._event_loop
            self._ws = server._websock_server
            self._inputs = server.gui._gui_input_handle_from_uuid
            self._viser = server.gui._handle_gui_updates
            self._ws.unregister_handler(self._update, self._viser)
        except (ImportError, AttributeError, AssertionError, ValueError) as e:
            raise GuardError(f"this viser cannot be guarded against hostile values ({e}); "
                             "urdfkit view is tested with viser 1.1") from None
        self._heard: dict[int, tuple[Any, Callable[[Any], None]]] = {}
        #: Per control (by id): changes pages sent, and when each page last sent one.
        self._busy: dict[str, tuple[int, dict[Any, float]]] = {}
        self._ws.register_handler(self._update, self._checked)

    def set(self, handle: Any, value: Any, unless: Callable[[], bool] | None = None) -> None:
        """Set a control's value from the server, on viser's event loop (waited for).

        A page's value is applied there (the control's state set, then :meth:`on_value`
        told) in one step: a value set from another thread could land in between, be sent to
        the page after its own newer value, and stay on it (viser sends a page's change to
        the other pages only): the page showed 0.0084, the robot held 0.168. Set on the loop,
        it comes before or after a page's value, whole. ``unless()``, checked there, skips it.
        """
        import concurrent.futures

        def write() -> None:
            if (unless is None or not unless()) and handle.value != value:
                handle.value = value
                self._written(handle)

        try:
            on_loop = asyncio.get_running_loop() is self._loop
        except RuntimeError:
            on_loop = False
        if on_loop or self._loop.is_closed():
            write()
            return
        done: concurrent.futures.Future[None] = concurrent.futures.Future()

        def run() -> None:
            try:
                write()
                done.set_result(None)
            except BaseException as e:  # noqa: BLE001 - handed to the waiting thread
                done.set_exception(e)

        try:
            self._loop.call_soon_threadsafe(run)
            done.result(timeout=SET_TIMEOUT)
        except (RuntimeError, concurrent.futures.TimeoutError):  # the server has stopped
            if not done.done():
                write()

    def _written(self, handle: Any) -> None:
        """The server set a control (on the loop): a page's value after it gets settled."""
        uuid = next((k for k, h in self._inputs.items() if h is handle), None)
        if uuid is not None:
            count, pages = self._busy.get(uuid, (0, {}))
            pages[None] = self._loop.time()  # None: the server, as a page of its own
            self._busy[uuid] = count, pages

    def on_value(self, handle: Any, heard: Callable[[Any], None]) -> None:
        """Call ``heard(value)`` with each value a page sends ``handle`` that gets in.

        Called on viser's event loop after viser applied the value (a button: ``True`` per
        click): it must only queue work. Controls since removed are forgotten here.
        """
        alive = {id(h) for h in self._inputs.values()}
        self._heard = {k: v for k, v in self._heard.items() if k in alive}
        self._heard[id(handle)] = (handle, heard)

    async def _checked(self, client_id: Any, message: Any) -> None:
        updates = message.updates
        handle = self._inputs.get(message.uuid)
        if handle is None or not isinstance(updates, dict) or list(updates) != ["value"]:
            return
        ok, value = clean_value(handle, updates["value"])
        if not ok:
            return
        message.updates = {"value": value}
        await self._viser(client_id, message)
        if value != updates["value"]:  # clamped: the sender is told too
            self._ws.queue_message(self._update(message.uuid, {"value": value}))
        if not isinstance(handle, self._button):  # a click has no value to show
            loop = asyncio.get_running_loop()
            count, pages = self._busy.get(message.uuid, (0, {}))
            pages[client_id] = loop.time()
            self._busy[message.uuid] = count + 1, pages
            loop.call_later(SETTLE_SECONDS, self._settle, message.uuid, count + 1)
        heard = self._heard.get(id(handle))
        if heard is not None and heard[0] is handle:
            heard[1](value)

    def _settle(self, uuid: str, count: int) -> None:
        """Once a control several writers changed is quiet, send every page its value.

        The writers are pages, and the server (:meth:`set`). viser sends a page's change to
        the other pages only, and a page may apply a value it got after its own newer change:
        it sends its changes at most every 50 ms, the last one late, and applies what it gets
        at its next frame (8 a second in software WebGL). Such a page kept showing another's
        value, or the server's, over its own: two pages on one slider (one showed 0.015, the
        robot held -0.033); keys pressed just after *Reset to zero* (the page showed 0, the
        robot -0.126). Sent when the control has been quiet :data:`SETTLE_SECONDS` and more
        than one writer changed it in the last :data:`CONTENDED_SECONDS` (a late value may
        come after a quiet spell). Not sent when one page alone changed it: that page shows
        what it sent, and a value sent back while it still moves the slider (its next keys
        not yet in) moved it back.
        """
        busy = self._busy.get(uuid)
        if busy is None or busy[0] != count:
            return  # not quiet yet: a later change set its own time
        now = asyncio.get_running_loop().time()
        pages = {k: t for k, t in busy[1].items() if now - t < CONTENDED_SECONDS}
        self._busy[uuid] = count, pages
        handle = self._inputs.get(uuid)
        if handle is not None and len(pages) > 1:
            self._ws.queue_message(self._update(uuid, {"value": handle.value}))


# --------------------------------------------------------------------------- keys

#: Run once in each page. viser's camera controls turn the camera on arrow keys (and move it
#: on WASD, Q and E) pressed anywhere in the document except in an INPUT, TEXTAREA or SELECT;
#: a slider's thumb is a ``role=slider`` element, so its arrow keys moved the slider and the
#: camera at once. React handles a key at its root element (or a portal's), below <body>:
#: stopping an arrow key at <body> when it was pressed on a control that uses arrows leaves
#: the control its key and keeps it from the document's camera listener. Keys on the canvas,
#: and keys a control does not use, still reach the camera.
KEYS_JS = """
if (!window.__urdfkitKeys) {
  window.__urdfkitKeys = true;
  const usesArrows = '[role="slider"], [role="listbox"], [role="option"], [role="combobox"],'
    + ' [role="tab"], [role="radio"]';
  document.body.addEventListener("keydown", (event) => {
    const target = event.target;
    if (event.code.startsWith("Arrow") && target instanceof Element
        && target.closest(usesArrows)) {
      event.stopPropagation();
    }
  });
}
"""


def keep_keys_off_camera(server: Any) -> None:
    """Have every page (those to come too) keep control keys from the camera (:data:`KEYS_JS`).

    viser has no setting for its keyboard camera, and runs JavaScript only through its
    RunJavascriptMessage (the way it loads plotly.js); queued once on the broadcast buffer,
    it is never culled, so each page that connects runs it (once: it marks the window).
    """
    try:
        from viser import _messages

        server._websock_server.queue_message(_messages.RunJavascriptMessage(source=KEYS_JS))
    except (ImportError, AttributeError) as e:
        raise GuardError(f"this viser cannot keep slider keys from its camera ({e}); "
                         "urdfkit view is tested with viser 1.1") from None
