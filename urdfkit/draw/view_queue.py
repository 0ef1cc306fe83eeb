"""The page's actions on the robot, applied one at a time in the order the server got them.

viser runs a control's callback in a thread pool of 32 threads, one call per change: two
changes (a slider's value and a Reset button, or a slider's 40 values) race for the robot
in no set order, and a later value can be applied before an earlier one. An ``async``
callback runs on viser's event loop in the order messages arrive; it only queues the action
here, and one thread applies the queue in that order.
"""

from __future__ import annotations

import threading
from collections import deque
from collections.abc import Callable, Hashable
from typing import Any


class ActionQueue:
    """Actions applied by one thread, first in first out.

    An action may carry a key (a slider's name): while a later action with the same key is
    waiting, an earlier one is dropped, so a run of values a page sent is applied as its
    last value, and a slow robot never falls behind a fast hand.

    Args:
        name: The thread's name.
        failed: Called with an exception an action raised (the thread goes on).
    """

    def __init__(self, name: str, failed: Callable[[Exception], None]) -> None:
        self._items: deque[tuple[Hashable | None, Callable[[], Any]]] = deque()
        self._cv = threading.Condition()
        self._busy = False
        self._stopped = False
        self._failed = failed
        self._thread = threading.Thread(target=self._run, name=name, daemon=True)
        self._thread.start()

    def put(self, action: Callable[[], Any], key: Hashable | None = None) -> None:
        """Queue an action (after every one queued before it)."""
        with self._cv:
            self._items.append((key, action))
            self._cv.notify_all()

    def waiting(self, key: Hashable) -> bool:
        """Whether an action with this key is queued and not yet started."""
        with self._cv:
            return any(k == key for k, _ in self._items)

    def wait_idle(self, timeout: float | None = None) -> bool:
        """Block until nothing is queued or running (or ``timeout`` s); whether it is so."""
        with self._cv:
            return self._cv.wait_for(lambda: not self._items and not self._busy, timeout)

    def stop(self, timeout: float = 5.0) -> None:
        """Drop what is queued and end the thread."""
        with self._cv:
            self._stopped = True
            self._items.clear()
            self._cv.notify_all()
        self._thread.join(timeout)

    def _run(self) -> None:
        while True:
            with self._cv:
                self._cv.wait_for(lambda: self._items or self._stopped)
                if self._stopped:
                    return
                key, action = self._items.popleft()
                if key is not None and any(k == key for k, _ in self._items):
                    continue  # a later value of the same control is waiting
                self._busy = True
            try:
                action()
            except Exception as e:  # noqa: BLE001 - the page outlives an action that fails
                self._failed(e)
            finally:
                with self._cv:
                    self._busy = False
                    self._cv.notify_all()
