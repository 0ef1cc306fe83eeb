"""The file on show, watched: loaded again when it, or anything it was read from, changes.

:class:`WatchedFile` loads the robot (a :class:`~urdfkit.draw.view_model.ViewedRobot`), and
on a thread of its own looks every :data:`POLL_SECONDS` at the files the robot was read from
(:mod:`urdfkit.core.deps`): when one changed, the viewer reloads. A load that fails records
what it read, so a bad file is not loaded again until one of those files changes.
"""

from __future__ import annotations

import threading
from collections.abc import Callable, Iterable, Mapping
from typing import Any

from urdfkit.core.errors import UrdfkitError
from urdfkit.draw.view_model import ViewedRobot

#: How often the watcher looks at the files the robot was read from (s).
POLL_SECONDS = 0.25


class WatchedFile:
    """A robot file, its load options, and the thread that watches what it was read from."""

    def __init__(self, file: str, load_args: Mapping[str, Any]) -> None:
        self.file = file
        self.load_args = dict(load_args)
        #: What the last load read when it failed (None: it loaded): watched instead of the
        #: robot's own files until it loads.
        self.failed: dict[str, Any] | None = None
        self._stop = threading.Event()
        self._thread: threading.Thread | None = None

    def load(self) -> ViewedRobot:
        """The robot, loaded from the file now (raises what loading raises)."""
        return ViewedRobot(self.file, **self.load_args)

    def reload(self, now: ViewedRobot) -> tuple[ViewedRobot, dict[str, float]] | str:
        """The robot loaded again, at ``now``'s joint values (by name), and those values.

        A load that fails returns its message (:meth:`failure`): ``now`` stays on show.
        """
        kept = now.positions()
        try:
            model = self.load()
        except Exception as e:  # noqa: BLE001 - any failure keeps the last good robot
            return self.failure(e, now.depends)
        names = {j.name for j in model.joints}
        keep = {k: v for k, v in kept.items() if k in names}
        # The joints are set before the new robot is published: a reader that sees the new
        # model (or the new count) never sees it at zero.
        model.set_positions(keep)
        return model, keep

    def failure(self, e: Exception, depends: Iterable[str]) -> str:
        """The message for a load that raised ``e``; what it read is recorded in :attr:`failed`.

        ``depends``: the files the robot on show was read from; a change to any of them, or to
        the file, is tried again.
        """
        from urdfkit.core import deps

        error = str(e) if isinstance(e, UrdfkitError) else \
            f"internal error (a bug in urdfkit): {type(e).__name__}: {e}"
        # Not retried until a file changes again: a bad file is not loaded 4 times a second.
        with deps.record() as recorded:  # what the failed attempt depends on
            deps.note(self.file)
            for path in depends:
                deps.note(path)
        self.failed = recorded
        return error

    def watch(self, on: bool, first: Callable[[], None], depends: Callable[[], Mapping[str, Any]],
              reload: Callable[[], object], report: Callable[[str], None]) -> None:
        """Start the watching thread (``on`` False: one that does nothing).

        It calls ``first()``, then, every :data:`POLL_SECONDS`, ``reload()`` when a file the
        last load read (``depends()``, or :attr:`failed`) changed; whatever that raises is
        handed to ``report`` as one line: the server outlives any bad file.
        """

        def run() -> None:
            from urdfkit.core import deps

            first()
            while not self._stop.wait(POLL_SECONDS):
                recorded = self.failed if self.failed is not None else depends()
                try:
                    if deps.unchanged(recorded):
                        continue
                    reload()
                except Exception as e:  # noqa: BLE001 - the server outlives any bad file
                    report(f"{type(e).__name__}: {e}")

        self._thread = threading.Thread(target=run if on else lambda: None,
                                        name="urdfkit-view-watch", daemon=True)
        self._thread.start()

    def stop(self) -> None:
        """Stop watching (waited for at most 5 s)."""
        self._stop.set()
        if self._thread is not None:
            self._thread.join(timeout=5)
