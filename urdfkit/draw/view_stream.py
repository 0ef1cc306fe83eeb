"""A simulated run streamed to ``urdfkit view``'s page (``drive --view``, ``sim --view``)."""

from __future__ import annotations

import threading
from collections.abc import Callable, Sequence
from typing import TYPE_CHECKING, Any

from urdfkit.core.errors import EngineError
from urdfkit.draw.view_model import Vec3, ViewedRobot
from urdfkit.draw.view_page import box_digits
from urdfkit.draw.view_scene import RobotScene, add_shapes, wxyz

if TYPE_CHECKING:
    from urdfkit.engine.api import Simulator


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
    #: Aims a page that connects (``aim_page(client)``); None: at the model's bounds.
    aim_page: Any
    #: Each page's camera (:class:`~urdfkit.draw.view_camera.PageCameras`).
    cameras: Any
    #: The robot's nodes in the scene (the shapes of the robots added here join its layers).
    scene: RobotScene
    _lock: threading.RLock

    def apply_toggles(self) -> None:
        """Show or hide each layer as the page's checkboxes say."""
        raise NotImplementedError

    def show_joint_values(self, values: Any, joints: Any = None) -> None:
        """Show a run's joint positions (by name) on the page's readouts, in ``joints``' order."""
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
                    self.scene.nodes[kind].append(mesh)
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
        frames = self.scene.frames if robot == 0 else self.extra[robot - 1][1]
        if len(poses) != len(frames):
            raise EngineError(f"the run has {len(poses)} links, the view {len(frames)}")
        with self._lock, self.server.atomic():
            for frame, (pos, quat) in zip(frames, poses, strict=True):
                frame.position = tuple(float(x) for x in pos)
                frame.wxyz = wxyz(quat)

    def robot_pose(self, robot: int, link: int = 0) -> tuple[Vec3, tuple[float, ...]]:
        """A link node's pose in the scene, by robot number and link position (base 0)."""
        frame = (self.scene.frames if robot == 0 else self.extra[robot - 1][1])[link]
        return (tuple(float(x) for x in frame.position),  # type: ignore[return-value]
                tuple(float(x) for x in frame.wxyz))


#: Frames pushed to the page per second of wall time, at most, while a run streams.
STREAM_FPS = 30.0


#: Points of a run's path kept on the page (halved by dropping every other one past this).
PATH_POINTS = 2000
#: Frames of a run kept for its replay (halved the same way past this).
REPLAY_FRAMES = 4000
#: The page's camera modes during and after a run.
FOLLOW, WHOLE_PATH, FREE = "follow the robot", "frame the whole path", "free"
#: Ground a followed robot is framed with on every side, in robot sizes (its largest side):
#: the robot whole with its path around it, on a canvas of any shape.
FOLLOW_MARGIN = 0.5


def joint_reader(engine: Simulator, body: int, joints: Sequence[Any]
                 ) -> Callable[[], dict[str, float]]:
    """A function returning a run's joint positions by name (``joints``: the viewer's).

    ``engine`` is the run's world (any engine: indices are PyBullet's on every one).
    """
    indices = [j.index for j in joints]
    names = [j.name for j in joints]

    def read() -> dict[str, float]:
        rows = engine.joint_rows(body, indices) if indices else ()
        return {name: float(row[0]) for name, row in zip(names, rows, strict=True)}
    return read


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
        joints: Returns a robot's joint positions by name (the page's readouts), or None;
            with several robots, a list of them in the viewer's order: the readouts are the
            followed robot's.
        names: The robots' names, in the viewer's order (``sim --view``): with more than one,
            the camera can follow any of them.

    Each sample's poses are kept (:attr:`frames_kept`), so once the run is over the page can
    replay it: a time slider puts the robot where the run had it at that time. The camera
    follows the robot (with several, the one chosen), frames every path, or is left alone
    (a dropdown): followed, the robot is framed with :data:`FOLLOW_MARGIN` of ground around it,
    at the distance that fits the page's canvas as it is now, from the direction the page's
    user turned the camera to. The pacing starts with the run's first sample, not with the
    stream: a run that waited for a page is paced from when it starts.
    """

    def __init__(self, viewer: RunDisplay, poses: Any, speed: float | None,
                 total: float, robots: bool = False, joints: Any = None,
                 names: Sequence[str] | None = None) -> None:
        import time

        self.viewer, self.speed, self.total = viewer, speed, total
        #: The robots the camera can follow by name (empty: one robot, "follow the robot").
        self.names = list(names) if names is not None and len(names) > 1 else []
        self.poses = poses if robots else (lambda: [poses()])
        #: Each robot's joint reader (None: no readouts for it).
        self.joints: list[Any] = list(joints) if isinstance(joints, (list, tuple)) else [joints]
        #: (t, every robot's link poses, every robot's joint positions) per sample, for the
        #: replay.
        self.frames_kept: list[tuple[float, list[Any], list[dict[str, float]]]] = []
        self._keep_stride = 1
        self._kept_seen = 0
        self.replay: Any = None
        self._aimed_at: tuple[float, float, float] | None = None
        self._sizes: dict[int, float] = {}
        gui = viewer.server.gui
        follow = tuple(f"follow {n}" for n in self.names) or (FOLLOW,)
        with gui.add_folder("Run", order=0.5):
            self.camera = gui.add_dropdown(
                "Camera", (*follow, WHOLE_PATH, FREE), initial_value=follow[0],
                hint="Follow the robot, keep its whole path in view, or leave the camera be")
        self.camera.on_update(lambda _event: self._camera_changed())
        #: The simulated time the replay shows (None: the run's own end, no replay yet).
        self._shown: float | None = None
        # A page opened (or reloaded) during or after the run looks at the robot where the
        # run has it, not where the file puts it.
        viewer.aim_page = self._aim_page
        self.path: list[tuple[float, float, float]] = []
        #: Each robot's base path, sampled as frames are pushed (:meth:`tick`).
        self.paths: list[list[tuple[float, float, float]]] = []
        self.frames = 0
        self.summary = ""
        self._clock = time.perf_counter
        self._sleep = time.sleep
        #: Wall and simulated time of the run's first sample (the pacing's origin).
        self._start: tuple[float, float] | None = None
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
        self.keep(t)
        self.tick(t)

    def keep(self, t: float, every: list[Any] | None = None) -> None:
        """Keep the poses at simulated time ``t`` for the replay (thinned past REPLAY_FRAMES)."""
        self._kept_seen += 1
        if self._kept_seen % self._keep_stride:
            return
        every = self.poses() if every is None else every
        self.frames_kept.append((t, every, [read() if read else {} for read in self.joints]))
        if len(self.frames_kept) > REPLAY_FRAMES:
            self.frames_kept = self.frames_kept[::2]
            self._keep_stride *= 2

    def tick(self, t: float) -> None:
        """The run is at simulated time ``t``: wait for the wall clock (paced), maybe push."""
        if self.speed is not None:
            now = self._clock()
            if self._start is None:  # the run starts here (after any wait for a page)
                self._start = (now, t)
            ahead = self._start[0] + (t - self._start[1]) / self.speed - now
            if ahead > 0:
                self._sleep(ahead)
        if not self._seen:  # a scenario run (no drive samples): keep what each tick shows
            self.keep(t)
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
        k = self.followed()
        read = self.joints[k] if k < len(self.joints) else None
        if read is not None:
            self.viewer.show_joint_values(read(), self._model(k).joints)
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
            self.viewer.status.content = status + self._whose_joints()
        self._aim_all()

    def followed(self) -> int:
        """The robot the camera follows or frames (its number; 0 unless another is chosen)."""
        mode = self.camera.value
        return next((k for k, n in enumerate(self.names) if mode == f"follow {n}"), 0)

    def _model(self, robot: int) -> ViewedRobot:
        return self.viewer.model if robot == 0 else self.viewer.extra[robot - 1][0]

    def _whose_joints(self) -> str:
        """With several robots, whose joints the readouts show."""
        k = self.followed()
        if not self.names or k >= len(self.joints) or self.joints[k] is None:
            return ""
        return f"\n\nJoint readouts: {self.names[k]}'s"

    def _aim_all(self, force: bool = False) -> None:
        """Move every page's camera as the Camera dropdown says (nothing when free)."""
        mode = self.camera.value
        if mode == FREE:
            self._aimed_at = None
            return
        base = tuple(float(x) for x in self.viewer.robot_pose(self.followed())[0])
        if mode != WHOLE_PATH and base == self._aimed_at and not force:
            return  # a still robot: the camera stays as its user turned it
        for client in list(self.viewer.server.get_clients().values()):
            try:
                self._aim_page(client)
            except AssertionError:  # a page that has not reported its camera yet
                continue
        self._aimed_at = base  # type: ignore[assignment]

    def _camera_changed(self) -> None:
        """The Camera dropdown changed: aim now; in a replay, the status names the robot."""
        if self.camera.value == FREE:
            for client in list(self.viewer.server.get_clients().values()):
                self.viewer.cameras.release(client)
        self._aim_all(force=True)
        if self._shown is not None:
            self.show_time(self._shown)

    def _box(self) -> tuple[Any, Any]:
        """What the camera frames now: the followed robot with ground around it, or every path."""
        import numpy as np

        k = self.followed()
        pts = np.asarray([p[0] for p in self._frames_now()[k]], dtype=float)
        size = self._size(k)
        if self.camera.value != WHOLE_PATH:  # the shapes about the link frames, and a margin
            pad = size / 2 + FOLLOW_MARGIN * size
            return pts.min(axis=0) - pad, pts.max(axis=0) + pad
        lo, hi = pts.min(axis=0) - size / 2, pts.max(axis=0) + size / 2
        for path in (self.path, *self.paths):
            if path:
                got = np.asarray(path, dtype=float)
                lo, hi = np.minimum(lo, got.min(axis=0)), np.maximum(hi, got.max(axis=0))
        return lo, hi

    def _size(self, robot: int) -> float:
        """A robot's largest side (at least 10 cm), as loaded: measured once."""
        if robot not in self._sizes:
            lo, hi = self._model(robot).bounds()
            self._sizes[robot] = max(max(b - a for a, b in zip(lo, hi, strict=True)), 0.1)
        return self._sizes[robot]

    def _base(self) -> Vec3:
        """Where the followed robot's base is on the page now."""
        return self.viewer.robot_pose(self.followed())[0]

    def _aim_page(self, client: Any) -> None:
        """Frame one page as the Camera says (a page just connected: free frames the robot)."""
        if self.camera.value == WHOLE_PATH:
            self.viewer.cameras.aim(client, self._box)
        else:
            self.viewer.cameras.follow(client, self._box, self._base)

    def _frames_now(self) -> list[Any]:
        """Every robot's link poses as the page shows them now."""
        out = []
        n = 1 + len(self.viewer.extra)
        for k in range(n):
            frames = self.viewer.scene.frames if k == 0 else self.viewer.extra[k - 1][1]
            out.append([(tuple(float(x) for x in f.position), None) for f in frames])
        return out

    def finish(self, summary: str) -> None:
        """The final pose and path, the run's summary, and the replay slider in the page."""
        if not self._seen:  # a scenario run: keep its last frame for the replay too
            self.keep(self.total)
        self.push(summary)
        self.summary = summary
        kept = self.frames_kept
        if len(kept) < 2:
            return
        end = kept[-1][0]
        with self.viewer.server.gui.add_folder("Replay", order=0.6):
            self.replay = self.viewer.server.gui.add_slider(
                "Time (s)", min=0.0, max=end, step=end / 100, initial_value=end,
                hint="Put the robot where the run had it at this simulated time")
            # A run's last time is a sum of steps (3.0000000000000013 s): viser would show it
            # to 7 decimals, in a box that shows 5 characters of them.
            self.replay.precision = box_digits(0.0, end, end / 100)
        self.replay.on_update(lambda _event: self.show_time(float(self.replay.value)))

    def show_time(self, t: float) -> tuple[float, list[Any]]:
        """Show the kept frame nearest simulated time ``t``; its time and poses."""
        import bisect

        times = [f[0] for f in self.frames_kept]
        k = bisect.bisect_left(times, t)
        if k == len(times) or (k > 0 and t - times[k - 1] <= times[k] - t):
            k -= 1
        at, every, joints = self.frames_kept[k]
        self._shown = at
        for r, poses in enumerate(every):
            self.viewer.show_poses(poses, robot=r)
        k = self.followed()
        if k < len(joints) and joints[k]:
            self.viewer.show_joint_values(joints[k], self._model(k).joints)
        x, y, z = self.viewer.robot_pose(k)[0]
        whose = f"{self.names[k]}'s base" if self.names else "base"
        self.viewer.status.content = (f"**Replay**: t = {at:.2f} s of {times[-1]:.2f}; {whose} "
                                      f"at x {x:.3f}, y {y:.3f}, z {z:.3f} m\n\n{self.summary}"
                                      f"{self._whose_joints()}")
        self._aim_all()
        return at, every
