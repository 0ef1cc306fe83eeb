"""``urdfkit view``: the robot in a browser, as PyBullet loaded it, with ``check``'s findings on it.

Three parts:

- :class:`~urdfkit.draw.view_model.ViewedRobot` (view_model.py) reads a loaded body into plain
  data: shapes, inertial frames, movable joints, findings mapped to links. It never computes
  kinematics.
- :class:`Viewer` (here) shows a :class:`ViewedRobot` with viser (a web server whose client
  ships in its wheel, so it works offline), and reloads it when the file or anything it read
  changes (view_watch.py watches the files); the robot's scene nodes are drawn by
  view_scene.py, its sidebar controls added by view_panel.py, the page's text written by
  view_page.py, its cameras and lights placed by view_camera.py.
- :class:`~urdfkit.draw.view_stream.RunStream` (view_stream.py) streams a simulated run to the page.

The server is guarded (view_guard.py: only its own page, only sane values, no camera move from
a slider's keys), and what pages do to the robot is applied in the order it arrives by one
thread (view_queue.py).
"""

from __future__ import annotations

import contextlib
import functools
import math
import threading
from collections.abc import Mapping, Sequence
from typing import Any

from urdfkit.core.errors import EngineError, MissingDependencyError
from urdfkit.draw import view_page as page
from urdfkit.draw import view_panel as panel
from urdfkit.draw.view_camera import ASPECT, FIT, FOV_DEG, PageCameras, environment, light
from urdfkit.draw.view_guard import Gate, GuardError, guarded_serve, keep_keys_off_camera
from urdfkit.draw.view_model import SELECTED_RGB, TINTS, TOUCHING_RGB, Layer, Vec3, ViewedRobot
from urdfkit.draw.view_queue import ActionQueue
from urdfkit.draw.view_scene import RobotScene
from urdfkit.draw.view_stream import RunDisplay
from urdfkit.draw.view_watch import POLL_SECONDS, WatchedFile

#: The selection dropdown's entry for no link.
NO_LINK = "(none)"
__all__ = ["ASPECT", "FIT", "FOV_DEG", "NO_LINK", "POLL_SECONDS", "SELECTED_RGB", "TINTS",
           "TOUCHING_RGB", "Viewer", "free_port"]


def _viser() -> Any:
    try:
        import viser
    except ImportError as e:
        raise MissingDependencyError("urdfkit view needs viser: pip install viser") from e
    return viser


#: Seconds the web server may take to start. viser waits on its server thread without a time
#: limit, and that thread dies silently on anything but a port in use: a hang, never a
#: message. Bounded here.
SERVER_START_TIMEOUT = 60.0


def _start_server(viser: Any, host: str, port: int) -> tuple[Any, Gate]:
    """``viser.ViserServer``, started in a thread of its own, guarded (view_guard.py).

    It answers only its own page (other origins and Host names get a 403), checks every
    value a page sends before applying it, and keeps a slider's arrow keys from the camera.
    Waited for at most :data:`SERVER_START_TIMEOUT` seconds (TimeoutError past it); its
    errors are re-raised here.
    """
    box: dict[str, Any] = {}

    def start() -> None:
        try:
            # viser prints a banner with rich whatever `verbose` says.
            with _quiet(), guarded_serve(host) as guarded:
                server = viser.ViserServer(host=host, port=port, verbose=False)
            try:
                if not guarded:  # bound some other way: never serve unguarded
                    raise GuardError("this viser's server cannot be kept to its own page; "
                                     "urdfkit view is tested with viser 1.1")
                gate = Gate(server)
                keep_keys_off_camera(server)
            except GuardError:
                with _quiet():
                    server.stop()
                raise
            box["server"] = server, gate
        except BaseException as e:  # handed to the caller's thread
            box["error"] = e

    thread = threading.Thread(target=start, name="urdfkit-view-start", daemon=True)
    thread.start()
    thread.join(SERVER_START_TIMEOUT)
    if thread.is_alive():
        raise TimeoutError
    if "error" in box:
        raise box["error"]
    return box["server"]


def _serve(viser: Any, host: str, port: int) -> tuple[Any, Gate]:
    """:func:`_start_server`, its failure to listen said as an EngineError about ``port``."""
    try:
        return _start_server(viser, host, port)
    except OSError as e:
        raise EngineError(f"cannot serve on {host}:{port}: {e.strerror or e}",
                          param="port") from None
    except TimeoutError:
        raise EngineError(f"the server on {host}:{port} did not start within "
                          f"{SERVER_START_TIMEOUT:g} s", param="port") from None


def _page(server: Any, lighting: str, ground: float, floor: float) -> Any:
    """Set up the page: z up, its lights, the sidebar, and the grid (returned) at ``floor``."""
    server.scene.set_up_direction("+z")
    light(server, lighting)
    # A sidebar beside the canvas, not a panel floating over the scene; wide enough that
    # joint names and the pose fields are not cut.
    server.gui.configure_theme(control_width="large")
    server.gui.main_panel.dock_right()
    return server.scene.add_grid("/ground", width=ground, height=ground,
                                 cell_size=0.1 if ground <= 4.0 else 0.5, section_size=1.0,
                                 position=(0.0, 0.0, floor))


def free_port(host: str) -> int:
    """A TCP port nothing listens on now."""
    import socket

    family = socket.AF_INET6 if ":" in host else socket.AF_INET
    with socket.socket(family, socket.SOCK_STREAM) as sock:
        sock.bind((host, 0))
        return int(sock.getsockname()[1])


class Viewer(RunDisplay):
    """A viser server showing a :class:`ViewedRobot`, reloaded when its files change.

    The server never dies on a bad file: a load that fails keeps the last good robot and shows
    the error in the page (:attr:`error`).

    Attributes:
        model: The robot on show (the last one that loaded).
        error: The last reload's error message, or None.
        url: Where the page is.
        reloads: How many times the robot was reloaded.
    """

    def __init__(self, file: str, *, packages: Sequence[str] | None = None,
                 package_paths: Sequence[str] | None = None,
                 xacro_args: Sequence[str] | None = None, inertia_from_file: bool = False,
                 host: str = "127.0.0.1", port: int | None = None, watch: bool = True,
                 ground: float = 4.0, display: str | None = None,
                 stand_on_grid: bool = True) -> None:
        #: The scene's lighting: ``none`` (a sky light) or viser's environment map's name.
        self.lighting = environment()  # a bad URDFKIT_VIEW_ENVIRONMENT fails before anything
        #: The file on show, loaded again when it changes.
        self.source = WatchedFile(file, {
            "packages": packages, "package_paths": package_paths, "xacro_args": xacro_args,
            "inertia_from_file": inertia_from_file, "display": display})
        self.file = file
        self.model = self.source.load()  # a bad file fails here, before serving
        self.error: str | None = None
        self.reloads = 0
        self._lock = threading.RLock()
        #: The page shows poses given from outside (a run, :meth:`show_poses`): the model's
        #: own joints no longer move the scene, even from a late slider callback.
        self.external_poses = False
        #: More robots on the page (sim --view): each model and its link frames.
        self.extra: list[tuple[ViewedRobot, list[Any]]] = []
        #: Aims a page that connects (a run sets it: at the robot where the run has it);
        #: None: at the model's bounds.
        self.aim_page: Any = None
        self._gui: list[Any] = []
        self.sliders: dict[str, Any] = {}
        viser = _viser()
        self.host = host
        self.port = free_port(host) if not port else port
        try:
            self.server, self.gate = _serve(viser, host, self.port)
        except (EngineError, GuardError):
            self.model.close()
            raise
        self.port = int(self.server.get_port())
        self.url = f"http://{'localhost' if host in ('127.0.0.1', '::1') else host}:{self.port}"
        #: Where each page's camera is, as urdfkit put it (view_camera.py).
        self.cameras = PageCameras(self.server)
        # The robot stands where `render` stands it: its lowest point on the grid (a run's
        # ground is its own plane at z = 0).
        floor = self.model.bounds()[0][2] if stand_on_grid else 0.0
        self.grid = _page(self.server, self.lighting, ground, floor)
        #: The robot's nodes in the scene.
        self.scene = RobotScene(self.server.scene)
        self._connected = threading.Event()
        self.server.on_client_connect(self._client_connected)
        self.server.on_client_disconnect(self.cameras.forget)
        #: What pages do to the robot, applied in the order the server got it.
        self.actions = ActionQueue("urdfkit-view-actions", self._action_failed)
        self._static_gui()
        self._show_model()
        # Mimic joints to their leaders' zero pose (offsets included). Self-collisions are
        # first measured by the watcher, so their second load does not delay the first draw.
        self.set_joints(self.zero(), touching=False)
        self.cameras.initial(self.model.bounds())
        # A run on show (drive --view) is not reloaded under it: no watcher then.
        self.source.watch(watch, self._measure_touching, lambda: self.model.depends,
                          self.reload, self._report)

    # ------------------------------------------------------------------ the page

    def _static_gui(self) -> None:
        gui = self.server.gui
        self.status = gui.add_markdown("", order=0)
        # viser's own "Reset View" is in its settings menu; this one is where users look.
        self.reset_view = gui.add_button("Reset view", order=0.1, hint=(
            "Frame the robot again in this page's camera (a run: as the Camera menu says)"))
        self.reset_view.on_click(lambda event: self.refit(event.client))
        with gui.add_folder("Show", order=1):
            self.show_visual = gui.add_checkbox("Visual", True)
            self.show_collision = gui.add_checkbox("Collision", False)
            self.show_frames = gui.add_checkbox("Frames and axes", False)
            self.show_inertia = gui.add_checkbox("COM and inertia boxes", False)
            self.tint_findings = gui.add_checkbox(
                "Tint findings", False, hint="Links with a check error in red, with a warning "
                "in amber (else each link keeps PyBullet's own colours)")
            self.show_touching = gui.add_checkbox(
                "Self-collisions", False, hint="Measure the links touching at this pose, as "
                "urdfkit collisions does, list them and tint them magenta")
            self.legend = gui.add_markdown(page.legend())
            self.touching_text = gui.add_markdown("")
        for box in (self.show_visual, self.show_collision, self.show_frames, self.show_inertia):
            box.on_update(lambda _event: self.apply_toggles())
        self.tint_findings.on_update(lambda _event: self.recolour())
        self.show_touching.on_update(lambda _event: self.update_touching())
        self.touching: list[tuple[str, str, float]] = []
        self.selected: str | None = None
        with gui.add_folder("Selection", order=1.5):
            self.select_link = gui.add_dropdown(
                "Link", [NO_LINK], initial_value=NO_LINK,
                hint="Or click a link in the scene, or a finding")
            self.selected_text = gui.add_markdown("")
        self.gate.on_value(self.select_link, lambda value: self.actions.put(
            functools.partial(self._dropdown_moved, str(value)), key="select"))
        self.joints_folder = gui.add_folder("Joints", order=2)
        with self.joints_folder:
            self.reset_button = gui.add_button("Reset to zero")
            self.gate.on_value(self.reset_button, lambda _value: self.actions.put(self.reset))
            # Multiline: a long pose wraps instead of being cut at the field's edge.
            self.vector_text = gui.add_text("Python list", "[]", disabled=True, multiline=True)
            self.joints_text = gui.add_text("--joints", "", disabled=True, multiline=True)
        self.findings_folder = gui.add_folder("Findings", order=3)
        self.table_folder = gui.add_folder("Joint table", order=4, expand_by_default=False)

    def _show_model(self) -> None:
        """Put the model's shapes and controls on the page (replacing the previous ones)."""
        self.scene.clear()
        for h in self._gui:
            h.remove()
        self._gui = []
        self.scene.draw(self.model, self._clicked)
        self.apply_toggles()
        listed, flags = self.model.joint_vector()
        self.vector_text.value, self.joints_text.value = listed, flags
        gui = self.server.gui
        with self.joints_folder:
            self.sliders = panel.add_sliders(gui, self.model, lambda name, s: self.gate.on_value(
                s, functools.partial(self._slid, name, s)))
        self._gui += self.sliders.values()
        with self.findings_folder:
            self._gui += panel.add_findings(gui, self.model, lambda button, link:
                                            self.gate.on_value(button, self._selects(link)))
        names = [lk.name for lk in self.model.links]
        self.select_link.options = [NO_LINK, *names]
        if self.selected not in names:
            self.selected = None
        self.select(self.selected)
        with self.table_folder:
            self._gui.append(gui.add_markdown(page.joint_table(self.model)))
        self._refresh_status()

    def _refresh_status(self) -> None:
        self.status.content = page.status(self.model, self.error)

    def refit(self, client: Any) -> None:
        """Frame one page's camera again, as when it connected (the Reset view button)."""
        if client is None:
            return
        with contextlib.suppress(AssertionError):  # a page that has not said its camera yet
            self._aim(client)

    def _aim(self, client: Any) -> None:
        """Frame one page: as a run on show says, else on the model's bounds."""
        if self.aim_page is not None:
            self.aim_page(client)
        else:
            self.cameras.aim(client, lambda: self.model.bounds())

    def _client_connected(self, client: Any) -> None:
        """A page connected: fit the camera to its own canvas, and release :meth:`wait_for_page`.

        Fitted again when its canvas changes size (the panel docking beside it narrows it
        just after it connects), until its user moves the camera.
        """
        try:
            self.cameras.connected(client, self._aim)
        finally:
            self._connected.set()

    def wait_for_page(self, timeout: float | None = None) -> bool:
        """Block until a page has connected (or ``timeout`` seconds); whether one has."""
        return self._connected.wait(timeout)

    def apply_toggles(self) -> None:
        """Show or hide each layer as the Show checkboxes say."""
        with self._lock:
            self.scene.show({"visual": self.show_visual.value,
                             "collision": self.show_collision.value,
                             "frames": self.show_frames.value, "inertia": self.show_inertia.value})

    def visible(self, kind: Layer) -> bool:
        """Whether a layer (visual, collision, frames, inertia) is shown."""
        return self.scene.visible(kind)

    # ------------------------------------------------------------------ moving

    # What a page does to the robot goes through the gate (the value it sent, as it arrived)
    # into the queue of actions (applied in that order, view_queue.py).

    def _slid(self, name: str, handle: Any, value: Any) -> None:
        self.actions.put(functools.partial(self._slider_moved, name, handle, float(value)),
                         key=("slider", name))

    def _selects(self, link: str) -> Any:
        """What a finding's button does when a page clicks it: select its link."""
        return lambda _value: self.actions.put(functools.partial(self.select, link),
                                               key="select")

    def _clicked(self, link: str) -> Any:
        """A link's click callback (scene clicks come from pages only): select it."""
        async def clicked(_event: Any) -> None:
            self.actions.put(functools.partial(self.select, link), key="select")

        return clicked

    def _action_failed(self, e: Exception) -> None:
        self._report(f"internal error (a bug in urdfkit): {type(e).__name__}: {e}")

    def _slider_moved(self, name: str, handle: Any, value: float) -> None:
        """A page set a joint's slider to ``value``: move the joint there.

        The slider is not written back while a newer value of the page's is queued: a move
        applied late once put an old value back over a newer one (the page showed one value,
        the robot another). It is written when something else (Reset to zero) wrote over it
        after the page's value arrived.
        """
        with self._lock:
            slider = self.sliders.get(name)
            if slider is None or slider is not handle or slider.disabled or \
                    self.external_poses or not math.isfinite(value):
                return  # a slider of a robot since reloaded, a mimic joint, or a run on show
            if abs(self.model.positions()[name] - value) > 1e-12:
                self.set_joints({name: value}, moved=name)
            # Written over (Reset to zero) after the page's value came: put it back, unless a
            # newer value of the page's is waiting (checked on the loop, with no gap).
            self.gate.set(slider, self.model.positions()[name],
                          unless=functools.partial(self.actions.waiting, ("slider", name)))

    def set_joints(self, values: Mapping[str, float], touching: bool = True,
                   moved: str | None = None) -> dict[str, float]:
        """Move joints (by name) in PyBullet and update the scene; return the new positions.

        Values are kept within each joint's limits (a value that is not finite is ignored).
        ``touching=False`` leaves the self-collision highlight as it was; ``moved`` names the
        slider the value came from, which is left as it is.
        """
        with self._lock:
            limits = {j.name: (j.lower, j.upper) for j in self.model.joints}
            values = {k: min(max(float(v), limits[k][0]), limits[k][1])
                      for k, v in values.items() if k in limits and math.isfinite(float(v))}
            now = self.model.set_positions(values)
            followers = {j.name for j in self.model.joints if j.mimic is not None}
            for name, value in now.items():
                s = self.sliders.get(name)
                # Only the joints set here and their mimics: another slider may hold a value
                # a page just sent, its own call still to come. A slider's callback runs here,
                # in this thread, and finds its joint already there.
                if s is not None and name != moved and (name in values or name in followers) \
                        and abs(float(s.value) - value) > 1e-12:
                    self.gate.set(s, value)
            self.update_poses()
            if touching:
                self.update_touching()
            listed, flags = self.model.joint_vector()
            self.vector_text.value = listed
            self.joints_text.value = flags
            return now

    def show_joint_values(self, values: Mapping[str, float], joints: Any = None) -> None:
        """Show a run's joint positions (by name) on the sliders and in the pose fields.

        The robot on the page is posed by the run (:meth:`show_poses`); this keeps the
        readouts on the same values, without moving this viewer's own PyBullet body.
        ``joints`` orders the pose fields (another robot's: ``sim --view`` following it);
        the sliders, the first robot's, take the values of the joints of their names.
        """
        with self._lock:
            panel.show_values(self.sliders, self.vector_text, self.joints_text, values,
                              self.model.joints if joints is None else joints)

    def update_poses(self) -> None:
        """Move every link node to the pose PyBullet reports (not while a run is shown)."""
        if self.external_poses:
            return
        with self._lock, self.server.atomic():
            self.scene.move(self.model.link_poses())

    def recolour(self) -> None:
        """Each link's colour: selected, touching, its findings' tint (asked), or its own."""
        with self._lock:
            hit = {name for a, b, _ in self.touching for name in (a, b)}
            self.scene.recolour(self.model, self.selected, hit, bool(self.tint_findings.value))

    def _dropdown_moved(self, value: str) -> None:
        """A page chose ``value`` in the Selection menu: select it."""
        link = None if value == NO_LINK else value
        with self._lock:
            if link is None or link in {lk.name for lk in self.model.links}:
                self.select(link)

    def select(self, link: str | None) -> None:
        """Select a link (None: none): highlight it, show its joint's row and its findings.

        Clicking the link in the scene, choosing it in the Selection dropdown, or clicking a
        finding about it all come here.
        """
        with self._lock:
            m = self.model
            if link is not None and link not in {lk.name for lk in m.links}:
                raise KeyError(link)
            self.selected = link  # first: the menu's callback, run here, finds it selected
            want = NO_LINK if link is None else link
            self.gate.set(self.select_link, want)
            self.recolour()
            if link is None:
                self.selected_text.content = ""
                return
            self.selected_text.content = page.selection(m, link)

    def update_touching(self) -> None:
        """Measure the touching pairs (when shown) and colour their links magenta."""
        with self._lock:
            self.touching = self.model.touching() if self.show_touching.value else []
            self.recolour()
            self.touching_text.content = page.touching(self.touching)

    def zero(self) -> dict[str, float]:
        """Every joint at zero, or at its nearest limit when zero is outside them."""
        return {j.name: min(max(0.0, j.lower), j.upper) for j in self.model.joints}

    def reset(self) -> None:
        """Every joint to :meth:`zero`."""
        self.set_joints(self.zero())

    def link_pose(self, name: str) -> tuple[Vec3, tuple[float, float, float, float]]:
        """A link node's pose in the scene: (position, wxyz)."""
        return self.scene.link_pose(self.model, name)

    def nodes(self, kind: Layer, link: str) -> list[Any]:
        """The scene handles of one layer of one link (for tests and tools)."""
        return self.scene.of(self.model, kind, link)

    # ------------------------------------------------------------------ reloading

    def _measure_touching(self) -> None:
        """The first measure of self-collisions (on the watcher's thread): its failure said."""
        try:
            self.update_touching()
        except Exception as e:  # noqa: BLE001 - the server outlives a probe that fails
            self._report(f"self-collisions not measured: {e}")

    def _report(self, error: str) -> None:
        """Show an error in the page's status (:attr:`error`)."""
        self.error = error
        self._refresh_status()

    def reload(self) -> bool:
        """Load the file again; on success show it, keeping joint values by name.

        Returns whether the new robot is on show. A failure keeps the old one and sets
        :attr:`error`; the next change of any file tried is retried. Pages whose camera is
        where urdfkit put it are framed on the new robot; a camera its user moved stays.
        """
        loaded = self.source.reload(self.model)
        if isinstance(loaded, str):
            self._report(loaded)
            return False
        model, keep = loaded
        with self._lock:
            old, self.model = self.model, model
            self.source.failed = None
            self.error = None
            self._show_model()
            old.close()
            self.set_joints(keep)
            # A robot that grew (or shrank) is framed again where no one moved the camera.
            self.cameras.initial(self.model.bounds())
            self.cameras.refit(self.server.get_clients().values())
            self.reloads += 1  # last: the count says the reload is complete
        return True

    def close(self) -> None:
        """Stop watching and serving, and disconnect PyBullet."""
        self.source.stop()
        self.actions.stop()
        with _quiet():
            self.server.stop()
        self.model.close()
        for m, _ in self.extra:
            m.close()


def _quiet() -> Any:
    """Keep what viser prints on sys.stdout (its banner, "Server stopped") off ours."""
    import contextlib
    import io

    return contextlib.redirect_stdout(io.StringIO())
