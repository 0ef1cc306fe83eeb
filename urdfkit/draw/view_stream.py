"""A simulated run streamed to ``urdfkit view``'s page (``drive --view``, ``sim --view``)."""

from __future__ import annotations

import threading
from collections.abc import Sequence
from typing import Any

from urdfkit.core.errors import EngineError
from urdfkit.draw.view_model import Layer, Vec3, ViewedRobot


def wxyz(q: Sequence[float]) -> tuple[float, float, float, float]:
    """A PyBullet quaternion (x, y, z, w) as viser takes it (w, x, y, z)."""
    return (float(q[3]), float(q[0]), float(q[1]), float(q[2]))


#: Seconds the web server may take to start. viser waits on its server thread without a time
#: limit, and that thread dies silently on anything but a port in use: a hang, never a
#: message. Bounded here.


def add_shapes(scene: Any, root: str, link: Any, tint: tuple[int, int, int] | None
                ) -> list[tuple[Layer, Any]]:
    """A link's visual and collision meshes under its frame ``root``: (kind, handle) pairs."""
    out: list[tuple[Layer, Any]] = []
    layers: tuple[tuple[Layer, Any], ...] = (("visual", link.visuals),
                                             ("collision", link.collisions))
    for kind, shapes in layers:
        for k, sh in enumerate(shapes):
            out.append((kind, scene.add_mesh_simple(
                f"{root}/{kind}{k}", sh.vertices, sh.faces, color=tint or sh.rgb,
                opacity=None if sh.opacity >= 1 else sh.opacity,
                # No shadow pass: it doubles the first draw in software WebGL.
                cast_shadow=False, receive_shadow=False,
                position=sh.pos, wxyz=wxyz(sh.quat))))
    return out


class RunDisplay:
    """The part of the page a run drives: more robots, and poses given from outside.

    :class:`urdfkit.draw.view.Viewer` is one; :class:`RunStream` drives it. The attributes are the
    viewer's (set by its constructor).
    """

    server: Any
    model: ViewedRobot
    status: Any
    sliders: dict[str, Any]
    reset_button: Any
    #: The page shows poses given from outside (a run, :meth:`show_poses`): the model's
    #: own joints no longer move the scene, even from a late slider callback.
    external_poses: bool
    #: More robots on the page (sim --view): each model and its link frames.
    extra: list[tuple[ViewedRobot, list[Any]]]
    _lock: threading.RLock
    _nodes: dict[Layer, list[Any]]
    _frames: list[Any]

    def apply_toggles(self) -> None:
        """Show or hide each layer as the page's checkboxes say."""
        raise NotImplementedError

    def add_robot(self, file: str, *, inertia_from_file: bool = False) -> int:
        """Draw one more robot (its visual and collision shapes, no controls); its number.

        For a scenario of several robots (``sim --view``): robot 0 is :attr:`model`, the
        others come here, and :meth:`show_poses` places each.
        """
        m = ViewedRobot(file, inertia_from_file=inertia_from_file)
        k = len(self.extra) + 1
        scene, frames = self.server.scene, []
        with self._lock:
            for link, (pos, quat) in zip(m.links, m.link_poses(), strict=True):
                root = f"/robot{k}/link{link.index + 1}"
                frames.append(scene.add_frame(root, show_axes=False, position=pos,
                                              wxyz=wxyz(quat)))
                for kind, mesh in add_shapes(scene, root, link, None):
                    self._nodes[kind].append(mesh)
            self.extra.append((m, frames))
            self.apply_toggles()
        return k

    def show_poses(self, poses: Sequence[tuple[Sequence[float], Sequence[float]]],
                   robot: int = 0) -> None:
        """Put every link node of a robot at a world pose (``(xyz, xyzw)``, base first).

        For a run simulated elsewhere (``drive --view``, ``sim --view``): the poses come from
        that session, not from this viewer's models. ``robot`` 0 is :attr:`model`; others
        were added with :meth:`add_robot`.
        """
        self.external_poses = True
        frames = self._frames if robot == 0 else self.extra[robot - 1][1]
        if len(poses) != len(frames):
            raise EngineError(f"the run has {len(poses)} links, the view {len(frames)}")
        with self._lock, self.server.atomic():
            for frame, (pos, quat) in zip(frames, poses, strict=True):
                frame.position = tuple(float(x) for x in pos)
                frame.wxyz = wxyz(quat)

    def robot_pose(self, robot: int, link: int = 0) -> tuple[Vec3, tuple[float, ...]]:
        """A link node's pose in the scene, by robot number and link position (base 0)."""
        frame = (self._frames if robot == 0 else self.extra[robot - 1][1])[link]
        return (tuple(float(x) for x in frame.position),  # type: ignore[return-value]
                tuple(float(x) for x in frame.wxyz))


#: Frames pushed to the page per second of wall time, at most, while a run streams.
STREAM_FPS = 30.0


#: Points of a run's path kept on the page (halved by dropping every other one past this).
PATH_POINTS = 2000


class RunStream:
    """Stream a simulated run to a :class:`Viewer`: link poses, the path, then the summary.

    Use it as the run's ``sink`` (called with each trajectory sample): it paces the run to
    ``speed`` times real time (``None``: as fast as it goes), pushes the robot's link poses,
    read from the run's own PyBullet session, at most :data:`STREAM_FPS` times a second of
    wall time, and draws the base's path on the ground.

    Args:
        viewer: The page (loaded from the same file as the run; more robots added with
            :meth:`Viewer.add_robot`).
        poses: Returns every link's world pose in the run's session, base first: one list,
            or (``robots=True``) a list of them, one per robot in the viewer's order.
        speed: Simulated seconds per wall second; None for no pacing.
        total: The run's simulated duration (for the status line).
        robots: ``poses`` gives one list per robot.
    """

    def __init__(self, viewer: RunDisplay, poses: Any, speed: float | None,
                 total: float, robots: bool = False) -> None:
        import time

        self.viewer, self.speed, self.total = viewer, speed, total
        self.poses = poses if robots else (lambda: [poses()])
        self.path: list[tuple[float, float, float]] = []
        #: Each robot's base path, sampled as frames are pushed (:meth:`tick`).
        self.paths: list[list[tuple[float, float, float]]] = []
        self.frames = 0
        self._clock = time.perf_counter
        self._sleep = time.sleep
        self._start = self._clock()
        self._last = -1.0
        self._stride = 1
        self._seen = 0
        viewer.status.content = f"**Running**: 0.0 of {total:g} s simulated"
        # The page shows the run, not the model's own joints: its controls would fight it.
        for control in (*viewer.sliders.values(), viewer.reset_button):
            control.disabled = True

    def __call__(self, row: Sequence[float]) -> None:
        """Take one drive sample ``(t, x, y, z, ...)``: pace, record, maybe push."""
        t = float(row[0])
        self._seen += 1
        if self._seen % self._stride == 0:
            self.path.append((float(row[1]), float(row[2]), float(row[3])))
            if len(self.path) > PATH_POINTS:
                self.path = self.path[::2]
                self._stride *= 2
        self.tick(t)

    def tick(self, t: float) -> None:
        """The run is at simulated time ``t``: wait for the wall clock (paced), maybe push."""
        if self.speed is not None:
            ahead = self._start + t / self.speed - self._clock()
            if ahead > 0:
                self._sleep(ahead)
        now = self._clock()
        if now - self._last >= 1.0 / STREAM_FPS:
            self._last = now
            self.push(f"**Running**: {t:.1f} of {self.total:g} s simulated")

    def push(self, status: str | None = None) -> None:
        """Show the run's current pose and path now."""
        import numpy as np

        every = self.poses()
        for k, poses in enumerate(every):
            self.viewer.show_poses(poses, robot=k)
        self.frames += 1
        paths = [self.path]
        if not self._seen:  # not fed drive samples: each robot's path from its base poses
            while len(self.paths) < len(every):
                self.paths.append([])
            for path, poses in zip(self.paths, every, strict=False):
                path.append(tuple(float(x) for x in poses[0][0]))  # type: ignore[arg-type]
                if len(path) > PATH_POINTS:
                    path[:] = path[::2]
            paths = self.paths
        for k, path in enumerate(paths):
            if len(path) < 2:
                continue
            pts = np.asarray(path, dtype=np.float32)
            pts[:, 2] = 0.002  # on the ground, not at the base's height
            segments = np.stack([pts[:-1], pts[1:]], axis=1)
            self.viewer.server.scene.add_line_segments(
                f"/run/path{k or ''}", segments, (230, 97, 0), thickness=3.0,
                thickness_units="screen")
        if status is not None:
            self.viewer.status.content = status

    def finish(self, summary: str) -> None:
        """The final pose and path, and the run's summary in the page."""
        self.push(summary)
