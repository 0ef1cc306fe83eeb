"""The view's cameras and lights: each page fitted to its own canvas, lit from every side.

A page reports its canvas's size in its first camera message, and again whenever the canvas
changes. The first report is often the whole window's: the control panel docks beside the
canvas a moment later and narrows it (a 1000 x 700 window: 1000 x 700, then 612 x 700). A
camera fitted once, at connect, for the first width then cut the robot at the sides: whether
it did depended on which came first. :class:`PageCameras` fits each page for the size it
reports now, and fits it again when the size changes, as long as the page's user has not
moved the camera urdfkit set.
"""

from __future__ import annotations

import math
import os
import threading
from collections import deque
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any

from urdfkit.core.errors import ParameterError

#: The page's vertical field of view (degrees), set so the camera's fit is computed for it.
FOV_DEG = 45.0
#: Share of the canvas the framed box's projection may fill.
FIT = 0.85
#: The canvas's width over its height assumed before a page says its own (reset view).
ASPECT = 1.4
#: The direction the page opens from: ``urdfkit render``'s iso view.
ISO = (math.cos(math.radians(30)) * math.cos(math.radians(-40)),
       math.cos(math.radians(30)) * math.sin(math.radians(-40)), math.sin(math.radians(30)))
#: viser's environment maps (``URDFKIT_VIEW_ENVIRONMENT``); ``city`` is its page's own.
ENVIRONMENTS = ("apartment", "city", "dawn", "forest", "lobby", "night", "park", "studio",
                "sunset", "warehouse")
#: The sky light that stands in for the environment map: white from above, grey from below.
SKY_INTENSITY, SKY_GROUND = 2.5, (128, 128, 128)
#: A camera is where urdfkit put it when it is within this share of its distance.
SAME_PLACE = 1e-4
#: Positions remembered per page (30 a second while a run streams: 10 s of them).
SENT_KEPT = 300

Box = tuple[Any, Any]


def environment() -> str:
    """The lighting ``URDFKIT_VIEW_ENVIRONMENT`` asks for: ``none`` or one of viser's maps.

    By default (``none``) there is no environment map: :func:`light` adds a sky light instead.
    With a GPU an environment map costs little, but without one (software WebGL) viser's page
    prefilters it for seconds, and shows the canvas faded out meanwhile: the washed-out grey
    robot of a page's first 6 to 15 s. One of viser's maps (``city``, its page's own,
    ``studio``, ...) brings it back.
    """
    name = os.environ.get("URDFKIT_VIEW_ENVIRONMENT", "none").strip().lower() or "none"
    if name in ("0", "off"):
        name = "none"
    if name not in ("none", *ENVIRONMENTS):
        raise ParameterError("URDFKIT_VIEW_ENVIRONMENT takes none or one of viser's maps ("
                             f"{', '.join(ENVIRONMENTS)}); got {name[:40]!r}")
    return name


def light(server: Any, name: str) -> None:
    """Light the scene: viser's environment map ``name``, or (``none``) a sky light.

    The sky light, white from above and grey from below, is added to viser's two directional
    lights and lights every side of a robot. Without it a side facing away from the main light
    drew black (a white cylinder seen from behind the light: its pixels' median 8 of 255).
    """
    if name == "none":
        server.scene.configure_environment_map(hdri=None)
        # Its direction is its position: the world's up (the scene's up is +z).
        server.scene.add_light_hemisphere("/lights/sky", sky_color=(255, 255, 255),
                                          ground_color=SKY_GROUND, intensity=SKY_INTENSITY,
                                          position=(0.0, 0.0, 1.0))
    elif name != "city":  # the page's own map needs no bytes sent
        server.scene.configure_environment_map(hdri=name)


def fit(box: Box, aspect: float, direction: Any = ISO, at: Any = None) -> tuple[Any, Any, Any]:
    """Camera (eye, target, up) looking back along ``direction`` that frames ``box``.

    ``urdfkit render``'s fit (every corner inside :data:`FIT` of the view at
    :data:`FOV_DEG`), so the page opens on the robot as the PNG shows it; looking ``at`` a
    point (a followed robot's base) when given.
    """
    from urdfkit.draw.framing import basis, fit_box

    return fit_box(basis(direction, (0.0, 0.0, 1.0)), box[0], box[1], aspect, FOV_DEG, FIT,
                   at=at)


def aspect_of(client: Any) -> float:
    """A page's canvas width over height (:data:`ASPECT` until it has said)."""
    try:
        value = float(client.camera.aspect)
    except (AttributeError, AssertionError, ZeroDivisionError):
        return ASPECT
    return value if math.isfinite(value) and value > 0 else ASPECT


@dataclass
class _Aimed:
    """Where urdfkit last put one page's camera, and how to put it there again."""

    #: The positions set lately: a page reports its camera late (by seconds, when software
    #: WebGL takes that long a frame), and between the position and the look-at it was sent.
    sent: deque[Any] = field(default_factory=lambda: deque(maxlen=SENT_KEPT))
    #: The last direction set (from the target to the camera).
    direction: Any = ISO
    aspect: float = ASPECT
    #: Aims the page again for its new canvas (None: nothing to redo).
    again: Callable[[Any], None] | None = None
    #: How much farther than the fit the page's user has zoomed a followed robot (1: not).
    zoom: float = 1.0


class PageCameras:
    """Each page's camera, as urdfkit last set it: fitted, followed, refitted.

    A page's camera is *moved* when its position is none urdfkit set lately (within
    :data:`SAME_PLACE` of its distance): its user orbited, panned or zoomed. Its look-at is not
    compared: a page reports the camera between the position and the look-at it was sent. A
    moved camera is never refitted behind its user's back; a followed robot keeps the direction
    the user turned it to, and a distance they zoomed out to.
    """

    def __init__(self, server: Any) -> None:
        self.server = server
        self._lock = threading.RLock()
        self._aimed: dict[int, _Aimed] = {}

    def initial(self, box: Box) -> None:
        """Fit ``box`` in the view of pages to come, and of viser's "Reset View"."""
        eye, target, _ = fit(box, ASPECT)
        cam = self.server.initial_camera
        cam.fov = math.radians(FOV_DEG)
        cam.look_at, cam.position, cam.up = target, eye, (0.0, 0.0, 1.0)

    def connected(self, client: Any, aim: Callable[[Any], None]) -> None:
        """A page connected: once it reports its camera, watch it and ``aim(client)``.

        The page reports its camera (and so its canvas's aspect) just after connecting: waited
        for at most 5 s; a page that says nothing by then is left as it is.
        """
        import time

        end = time.monotonic() + 5.0
        while not client.camera.update_timestamp and time.monotonic() < end:
            time.sleep(0.02)
        if client.camera.update_timestamp:
            self.watch(client)
            aim(client)

    def watch(self, client: Any) -> None:
        """Refit a page when its canvas changes size (its user not having moved it)."""
        client.camera.on_update(lambda camera: self._reported(camera.client))

    def forget(self, client: Any) -> None:
        """A page that has gone."""
        with self._lock:
            self._aimed.pop(client.client_id, None)

    def release(self, client: Any) -> None:
        """Leave a page's camera be from now on, whatever its canvas does (free camera)."""
        with self._lock:
            aimed = self._aimed.get(client.client_id)
            if aimed is not None:
                aimed.again = None

    def moved(self, client: Any) -> bool:
        """Whether a page's camera is not where urdfkit lately put it."""
        import numpy as np

        with self._lock:
            aimed = self._aimed.get(client.client_id)
            if aimed is None or not aimed.sent:
                return False
            try:
                pos = np.asarray(client.camera.position, dtype=float)
                at = np.asarray(client.camera.look_at, dtype=float)
            except AssertionError:  # not reported yet: nobody has moved it
                return False
            reach = SAME_PLACE * max(float(np.linalg.norm(pos - at)), 1e-3)
            off = np.abs(np.asarray(aimed.sent, dtype=float) - pos).max(axis=1)
            return not bool((off <= reach).any())

    def aim(self, client: Any, box: Callable[[], Box]) -> None:
        """Frame a box on one page from the iso direction, for its canvas as reported now.

        ``box`` is called again (the canvas changed, the robot was reloaded) while the page's
        camera stays where this put it.
        """
        eye, target, _ = fit(box(), aspect_of(client))
        self._set(client, eye, target, again=lambda c: self.aim(c, box))

    def follow(self, client: Any, box: Callable[[], Box], at: Callable[[], Any]) -> None:
        """Frame a moving box on one page, looking at ``at()``, from its user's direction.

        The direction is the one the page's user turned the camera to (the iso view until
        then). The distance is the fit's for the box and the page's canvas now, so the box is
        whole whatever the canvas's shape; a user who zoomed out stays that much farther
        (never closer: the box stays whole).
        """
        import numpy as np

        with self._lock:
            aimed = self._aimed.get(client.client_id)
            direction: Any = ISO if aimed is None else aimed.direction
            zoom = 1.0 if aimed is None else aimed.zoom
            # A new page's first report is the page's default camera, not one a user chose
            # (nor always the initial one this server set): it opens on the iso view.
            reach = 0.0
            if aimed is not None and self.moved(client):
                offset = np.asarray(client.camera.position) - np.asarray(client.camera.look_at)
                reach = float(np.linalg.norm(offset))
                if reach > 1e-9:
                    direction = offset
            eye, target, _ = fit(box(), aspect_of(client), direction, at())
            distance = float(np.linalg.norm(np.asarray(eye) - np.asarray(target)))
            if reach > 1e-9:  # the user's own distance, never nearer than the fit
                zoom = max(1.0, reach / distance)
            back = (np.asarray(eye) - np.asarray(target)) / distance
            eye = np.asarray(target) + back * distance * zoom
            self._set(client, eye, target, again=lambda c: self.follow(c, box, at), zoom=zoom)

    def refit(self, clients: Any) -> None:
        """Aim again every page whose camera is where urdfkit put it (a reloaded robot)."""
        for client in clients:
            with self._lock:
                aimed = self._aimed.get(client.client_id)
                if aimed is not None and aimed.again is not None and not self.moved(client):
                    aimed.again(client)

    def _reported(self, client: Any) -> None:
        """A page reported its camera: refit it if its canvas changed and it is unmoved."""
        with self._lock:
            aimed = self._aimed.get(client.client_id)
            if aimed is None or aimed.again is None:
                return
            if abs(aspect_of(client) - aimed.aspect) <= 1e-3 * aimed.aspect:
                return
            if not self.moved(client):
                aimed.again(client)

    def _set(self, client: Any, eye: Any, target: Any, *,
             again: Callable[[Any], None] | None, zoom: float = 1.0) -> None:
        import numpy as np

        eye = tuple(float(x) for x in eye)
        target = tuple(float(x) for x in target)
        with self._lock:
            aimed = self._aimed.setdefault(client.client_id, _Aimed())
            aimed.aspect, aimed.again, aimed.zoom = aspect_of(client), again, zoom
            aimed.direction = np.asarray(eye) - np.asarray(target)
            aimed.sent.append(eye)
            cam = client.camera
            with self.server.atomic():  # position first: setting it moves look_at along
                cam.fov = math.radians(FOV_DEG)
                cam.up_direction = (0.0, 0.0, 1.0)  # the orbit's axis: the world's up
                cam.position = eye
                cam.look_at = target
