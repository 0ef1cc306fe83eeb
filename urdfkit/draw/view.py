"""``urdfkit view``: the robot in a browser, as PyBullet loaded it, with ``check``'s findings on it.

Three parts:

- :class:`~urdfkit.draw.view_model.ViewedRobot` (view_model.py) reads a loaded body into plain
  data: shapes, inertial frames, movable joints, findings mapped to links. It never computes
  kinematics.
- :class:`Viewer` (here) shows a :class:`ViewedRobot` with viser (a web server whose client
  ships in its wheel, so it works offline), and reloads it when the file or anything it read
  changes; the page's text is written by view_page.py, its cameras and lights are placed by
  view_camera.py.
- :class:`~urdfkit.draw.view_stream.RunStream` (view_stream.py) streams a simulated run to the page.

The server is guarded (view_guard.py: only its own page, only sane values, no camera move from
a slider's keys), and what pages do to the robot is applied in the order it arrives by one
thread (view_queue.py).
"""

from __future__ import annotations

import contextlib
import functools
import math
import os
import threading
from collections.abc import Mapping, Sequence
from typing import Any

from urdfkit.core.errors import EngineError, MissingDependencyError, UrdfkitError
from urdfkit.draw import view_page as page
from urdfkit.draw.view_camera import ASPECT, FIT, FOV_DEG, PageCameras, environment, fit, light
from urdfkit.draw.view_guard import Gate, GuardError, guarded_serve, keep_keys_off_camera
from urdfkit.draw.view_model import SELECTED_RGB, TINTS, TOUCHING_RGB, Layer, Vec3, ViewedRobot
from urdfkit.draw.view_queue import ActionQueue
from urdfkit.draw.view_stream import RunDisplay, add_shapes, wxyz

#: The selection dropdown's entry for no link.
NO_LINK = "(none)"
__all__ = ["ASPECT", "FIT", "FOV_DEG", "TINTS", "TOUCHING_RGB", "Viewer", "free_port"]

#: How often the watcher looks at the files the robot was read from (s).
POLL_SECONDS = 0.25


def _viser() -> Any:
    try:
        import viser
    except ImportError as e:
        raise MissingDependencyError("urdfkit view needs viser: pip install viser") from e
    return viser


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
        self._load_args: dict[str, Any] = {
            "packages": packages, "package_paths": package_paths, "xacro_args": xacro_args,
            "inertia_from_file": inertia_from_file, "display": display}
        self.file = file
        self.model = ViewedRobot(file, **self._load_args)  # a bad file fails here, before serving
        self.error: str | None = None
        self.reloads = 0
        self._failed: dict[str, Any] | None = None
        self._lock = threading.RLock()
        self._nodes: dict[Layer, list[Any]] = {}
        self._frames: list[Any] = []
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
            self.server, self.gate = _start_server(viser, host, self.port)
        except OSError as e:
            self.model.close()
            raise EngineError(f"cannot serve on {host}:{self.port}: {e.strerror or e}",
                              param="port") from None
        except TimeoutError:
            self.model.close()
            raise EngineError(f"the server on {host}:{self.port} did not start within "
                              f"{SERVER_START_TIMEOUT:g} s", param="port") from None
        except GuardError:
            self.model.close()
            raise
        self.port = int(self.server.get_port())
        self.url = f"http://{'localhost' if host in ('127.0.0.1', '::1') else host}:{self.port}"
        self.server.scene.set_up_direction("+z")
        light(self.server, self.lighting)
        #: Where each page's camera is, as urdfkit put it (view_camera.py).
        self.cameras = PageCameras(self.server)
        # A sidebar beside the canvas, not a panel floating over the scene; wide enough that
        # joint names and the pose fields are not cut.
        self.server.gui.configure_theme(control_width="large")
        self.server.gui.main_panel.dock_right()
        # The robot stands where `render` stands it: its lowest point on the grid (a run's
        # ground is its own plane at z = 0).
        floor = self.model.bounds()[0][2] if stand_on_grid else 0.0
        self.grid = self.server.scene.add_grid("/ground", width=ground, height=ground,
                                               cell_size=0.1 if ground <= 4.0 else 0.5,
                                               section_size=1.0, position=(0.0, 0.0, floor))
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
        self._aim_camera()
        self._stop = threading.Event()
        # A run on show (drive --view) is not reloaded under it: no watcher then.
        self._watcher = threading.Thread(target=self._watch if watch else lambda: None,
                                         name="urdfkit-view-watch", daemon=True)
        self._watcher.start()

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
        for h in self._frames + self._gui:  # a link's frame takes its shapes with it
            h.remove()
        self._nodes = {"visual": [], "collision": [], "frames": [], "inertia": []}
        self._frames, self._gui, self.sliders = [], [], {}
        self._draw_links()
        self.apply_toggles()
        listed, flags = self.model.joint_vector()
        self.vector_text.value, self.joints_text.value = listed, flags
        self._add_sliders()
        self._add_findings()
        names = [lk.name for lk in self.model.links]
        self.select_link.options = [NO_LINK, *names]
        if self.selected not in names:
            self.selected = None
        self.select(self.selected)
        with self.table_folder:
            self._gui.append(self.server.gui.add_markdown(page.joint_table(self.model)))
        self._refresh_status()

    def _draw_links(self) -> None:
        """Each link's frame, shapes, axes, joint axis, centre of mass and inertia box."""
        import numpy as np

        from urdfkit.model.spec import quat_to_matrix, rotate

        scene, m = self.server.scene, self.model
        size = max(max(hi - lo for lo, hi in zip(*m.bounds(), strict=True)), 0.05)
        self.frame_size = size * 0.15  # the axes a link frame is drawn with: the robot's scale
        by_index = {j.link: j for j in m.joints}
        for link, (pos, quat) in zip(m.links, m.link_poses(), strict=True):
            root = f"/robot/link{link.index + 1}"
            self._frames.append(scene.add_frame(root, show_axes=False, position=pos,
                                                wxyz=wxyz(quat)))
            for kind, mesh in add_shapes(scene, root, link, None):
                # Clicking a link in the scene selects it (and its joint's row).
                mesh.on_click(self._clicked(link.name))
                self._nodes[kind].append(mesh)
            self._nodes["frames"].append(scene.add_frame(
                f"{root}/axes", axes_length=self.frame_size, axes_radius=size * 0.006))
            joint = by_index.get(link.index)
            if joint is not None:  # PyBullet's axis is in the inertial frame: into the link's
                axis = np.asarray(rotate(quat_to_matrix(link.inertial_quat), joint.axis),
                                  dtype=float)
                points = np.array([[-axis, axis]], dtype=np.float32) * size * 0.2
                self._nodes["frames"].append(scene.add_line_segments(
                    f"{root}/joint_axis", points, (204, 121, 167), thickness=size * 0.006))
            self._nodes["inertia"].append(scene.add_frame(
                f"{root}/com", show_axes=False, position=link.inertial_pos,
                wxyz=wxyz(link.inertial_quat)))
            self._nodes["inertia"].append(scene.add_icosphere(
                f"{root}/com/dot", radius=size * 0.012, color=(20, 20, 20)))
            if link.inertia_box is not None:
                self._nodes["inertia"].append(scene.add_box(
                    f"{root}/com/box", dimensions=link.inertia_box, color=(0, 114, 178),
                    opacity=0.35))

    def _add_sliders(self) -> None:
        """One slider per movable joint (mimic joints shown, not movable)."""
        gui, now = self.server.gui, self.model.positions()
        with self.joints_folder:
            for j in self.model.joints:
                step = (j.upper - j.lower) / 1000 if j.upper > j.lower else 0.001
                hint = f"{j.urdf_type}, PyBullet joint {j.index}"
                if j.mimic is not None:
                    hint += f"; mimics {j.mimic[0]} x {j.mimic[1]:g} + {j.mimic[2]:g}"
                hi = max(j.upper, j.lower + step)
                s = gui.add_slider(j.name, min=j.lower, max=hi, step=step,
                                   initial_value=min(max(now[j.name], j.lower), j.upper),
                                   # A joint whose limits meet has nothing to slide.
                                   disabled=j.mimic is not None or j.upper <= j.lower,
                                   hint=hint)
                s.precision = page.box_digits(j.lower, hi, step)
                self.gate.on_value(s, functools.partial(self._slid, j.name, s))
                self.sliders[j.name] = s
                self._gui.append(s)

    def _add_findings(self) -> None:
        """Each finding once: a button for one about a link, the text of the others.

        The button selects the link, whose panel then shows the finding's text.
        """
        gui, m = self.server.gui, self.model
        with self.findings_folder:
            self._gui.append(gui.add_markdown(page.findings(m)))
            for f in (f for f in m.findings if f.level in TINTS):
                links = m.finding_links(f)
                if not links:
                    continue
                where = f"line {f.line}" if f.line is not None else os.path.basename(f.file)
                button = gui.add_button(page.finding_button(f.code, where, links[0]),
                                        hint=f"{links[0]}: {f.text}"[:300],
                                        color="red" if f.level == "error" else "yellow")
                self.gate.on_value(button, self._selects(links[0]))
                self._gui.append(button)

    def _refresh_status(self) -> None:
        self.status.content = page.status(self.model, self.error)

    def refit(self, client: Any) -> None:
        """Frame one page's camera again, as when it connected (the Reset view button)."""
        if client is None:
            return
        with contextlib.suppress(AssertionError):  # a page that has not said its camera yet
            if self.aim_page is not None:
                self.aim_page(client)
            else:
                self.cameras.aim(client, lambda: self.model.bounds())

    def _aim_camera(self) -> None:
        """Fit the robot's bounds in the view of pages to come, and of viser's "Reset View"."""
        eye, target, _ = fit(self.model.bounds(), ASPECT)
        cam = self.server.initial_camera
        cam.fov = math.radians(FOV_DEG)
        cam.look_at, cam.position, cam.up = target, eye, (0.0, 0.0, 1.0)

    def _client_connected(self, client: Any) -> None:
        """A page connected: fit the camera to its own canvas, and release :meth:`wait_for_page`.

        Fitted again when its canvas changes size (the panel docking beside it narrows it
        just after it connects), until its user moves the camera.
        """
        import time

        try:
            # The page reports its camera (and so its canvas's aspect) just after connecting.
            end = time.monotonic() + 5.0
            while not client.camera.update_timestamp and time.monotonic() < end:
                time.sleep(0.02)
            if client.camera.update_timestamp:
                self.cameras.watch(client)
                if self.aim_page is not None:
                    self.aim_page(client)
                else:
                    self.cameras.aim(client, lambda: self.model.bounds())
        finally:
            self._connected.set()

    def wait_for_page(self, timeout: float | None = None) -> bool:
        """Block until a page has connected (or ``timeout`` seconds); whether one has."""
        return self._connected.wait(timeout)

    def apply_toggles(self) -> None:
        """Show or hide each layer as the Show checkboxes say."""
        with self._lock:
            want = {"visual": self.show_visual.value, "collision": self.show_collision.value,
                    "frames": self.show_frames.value, "inertia": self.show_inertia.value}
            for kind, handles in self._nodes.items():
                for h in handles:
                    h.visible = bool(want[kind])

    def visible(self, kind: Layer) -> bool:
        """Whether a layer (visual, collision, frames, inertia) is shown."""
        handles = self._nodes.get(kind, [])
        return bool(handles) and all(h.visible for h in handles)

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
        self.error = f"internal error (a bug in urdfkit): {type(e).__name__}: {e}"
        self._refresh_status()

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
            for name, value in values.items():  # the sliders are disabled: nothing follows
                s = self.sliders.get(name)
                if s is not None and math.isfinite(float(value)):
                    s.value = min(max(float(value), float(s.min)), float(s.max))
            joints = [j for j in (self.model.joints if joints is None else joints)
                      if j.name in values]
            self.vector_text.value = repr([round(float(values[j.name]), 6) for j in joints])
            text = ",".join(f"{j.name}={round(float(values[j.name]), 6):g}" for j in joints)
            self.joints_text.value = f"--joints {text}" if text else ""

    def update_poses(self) -> None:
        """Move every link node to the pose PyBullet reports (not while a run is shown)."""
        if self.external_poses:
            return
        with self._lock, self.server.atomic():
            for frame, (pos, quat) in zip(self._frames, self.model.link_poses(), strict=True):
                frame.position = pos
                frame.wxyz = wxyz(quat)

    def recolour(self) -> None:
        """Each link's colour: selected, touching, its findings' tint (asked), or its own."""
        with self._lock:
            hit = {name for a, b, _ in self.touching for name in (a, b)}
            tint = bool(self.tint_findings.value)
            for link, k in zip(self.model.links, range(len(self.model.links)), strict=True):
                base = TINTS.get(link.level or "") if tint else None
                layers: tuple[tuple[Layer, Any], ...] = (("visual", link.visuals),
                                                         ("collision", link.collisions))
                for kind, shapes in layers:
                    handles = [h for h in self._nodes.get(kind, [])
                               if h.name.startswith(f"/robot/link{k}/")]
                    for h, sh in zip(handles, shapes, strict=True):
                        want = SELECTED_RGB if link.name == self.selected else \
                            TOUCHING_RGB if link.name in hit else (base or sh.rgb)
                        if tuple(h.color) != tuple(want):
                            h.color = want

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
        for link, frame in zip(self.model.links, self._frames, strict=True):
            if link.name == name:
                return (tuple(float(x) for x in frame.position),  # type: ignore[return-value]
                        tuple(float(x) for x in frame.wxyz))
        raise KeyError(name)

    def nodes(self, kind: Layer, link: str) -> list[Any]:
        """The scene handles of one layer of one link (for tests and tools)."""
        index = next(i for i, lk in enumerate(self.model.links) if lk.name == link)
        prefix = f"/robot/link{index}/"
        return [h for h in self._nodes.get(kind, []) if h.name.startswith(prefix)]

    # ------------------------------------------------------------------ reloading

    def _watch(self) -> None:
        from urdfkit.core import deps

        try:
            self.update_touching()
        except Exception as e:  # noqa: BLE001 - the server outlives a probe that fails
            self.error = f"self-collisions not measured: {e}"
            self._refresh_status()
        while not self._stop.wait(POLL_SECONDS):
            recorded = self._failed if self._failed is not None else self.model.depends
            try:
                if deps.unchanged(recorded):
                    continue
                self.reload()
            except Exception as e:  # noqa: BLE001 - the server outlives any bad file
                self.error = f"{type(e).__name__}: {e}"
                self._refresh_status()

    def reload(self) -> bool:
        """Load the file again; on success show it, keeping joint values by name.

        Returns whether the new robot is on show. A failure keeps the old one and sets
        :attr:`error`; the next change of any file tried is retried. Pages whose camera is
        where urdfkit put it are framed on the new robot; a camera its user moved stays.
        """
        from urdfkit.core import deps

        kept = self.model.positions()
        try:
            model = ViewedRobot(self.file, **self._load_args)
        except Exception as e:  # noqa: BLE001 - any failure keeps the last good robot
            self.error = str(e) if isinstance(e, UrdfkitError) else \
                f"internal error (a bug in urdfkit): {type(e).__name__}: {e}"
            # Not retried until a file changes again: a bad file is not loaded 4 times a second.
            with deps.record() as recorded:  # what the failed attempt depends on
                deps.note(self.file)
                for path in self.model.depends:
                    deps.note(path)
            self._failed = recorded
            self._refresh_status()
            return False
        names = {j.name for j in model.joints}
        keep = {k: v for k, v in kept.items() if k in names}
        # The joints are set before the new robot is published: a reader that sees the new
        # model (or the new count) never sees it at zero.
        model.set_positions(keep)
        with self._lock:
            old, self.model = self.model, model
            self._failed = None
            self.error = None
            self._show_model()
            old.close()
            self.set_joints(keep)
            # A robot that grew (or shrank) is framed again where no one moved the camera.
            self._aim_camera()
            self.cameras.refit(self.server.get_clients().values())
            self.reloads += 1  # last: the count says the reload is complete
        return True

    def close(self) -> None:
        """Stop watching and serving, and disconnect PyBullet."""
        self._stop.set()
        self._watcher.join(timeout=5)
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
