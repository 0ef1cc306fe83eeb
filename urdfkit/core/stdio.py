"""The one lock over the process's standard output (file descriptor 1).

PyBullet's C code writes to fd 1, so :func:`urdfkit.engine.session.quiet_stdout` points fd 1 at a
temporary file while it runs. Another thread's print in that window would go there too, and
be lost: ``urdfkit view`` printed its URL into a background self-collision probe's capture
now and then, and the URL never appeared. Every redirection of fd 1 holds :data:`LOCK` for
its whole block, and every line urdfkit prints holds it while writing, so neither meets the
other. Re-entrant: the thread inside a redirection may print (into it).
"""

from __future__ import annotations

# The lock threading.RLock() makes, without importing threading (~0.5 ms of every run).
from _thread import RLock

LOCK = RLock()
