"""A perspective camera placed so a box fills its view: ``render``'s pictures and the view's pages.

One fit for both, so the page opens on a robot as the PNG shows it, and a page that follows a
run frames the robot the same way from whatever direction its user has turned it to.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from typing import Any


def basis(direction: Sequence[float], up: Sequence[float]) -> tuple[Any, Any, Any]:
    """(towards the camera, right, up) unit vectors for a camera looking back along ``direction``.

    ``direction`` points from the target to the camera; ``up`` is the world's up. A camera
    looking straight along ``up`` takes the world's x (or y) as its up instead.
    """
    import numpy as np

    back = np.asarray(direction, dtype=float)
    back = back / max(float(np.linalg.norm(back)), 1e-12)
    for candidate in (up, (1.0, 0.0, 0.0), (0.0, 1.0, 0.0)):
        right = np.cross(-back, np.asarray(candidate, dtype=float))
        norm = float(np.linalg.norm(right))
        if norm > 1e-6:
            right = right / norm
            return back, right, np.cross(right, -back)
    raise ValueError("no camera basis")  # pragma: no cover - x and y are never both parallel


def corners(lo: Any, hi: Any) -> Any:
    """The eight corners of the box lo..hi."""
    import numpy as np

    return np.array([[x, y, z] for x in (lo[0], hi[0]) for y in (lo[1], hi[1])
                     for z in (lo[2], hi[2])], dtype=float)


def fit_box(frame: tuple[Any, Any, Any], lo: Sequence[float], hi: Sequence[float],
            aspect: float, fov_deg: float, fill: float,
            at: Sequence[float] | None = None) -> tuple[Any, Any, Any]:
    """Place a camera of basis ``frame`` (:func:`basis`) so the box lo..hi fills ``fill`` of it.

    Returns (eye, target, up). For a corner at camera-space offset (x, y, z) from the target
    (z towards the camera), a camera at distance d sees it at x / (d - z) on the image plane.
    Fitting needs ``|x| <= (d - z) * tan(half fov) * fill``, so d = max over corners of
    z + |x| / (tan * fill), and likewise for y. Two centring passes then move the target so the
    projected box sits in the middle rather than wherever perspective pushed it; a camera
    looking ``at`` a given point keeps it as its target (the box then sits about it).
    """
    import numpy as np

    back, right, up = frame
    lo_a, hi_a = np.asarray(lo, dtype=float), np.asarray(hi, dtype=float)
    # A flat or point-like robot still needs a finite box to frame.
    size = max(float(np.max(hi_a - lo_a)), 1e-3)
    pad = np.maximum(hi_a - lo_a, size * 0.02) / 2
    mid = (lo_a + hi_a) / 2
    points = corners(mid - pad, mid + pad)
    tan_v = math.tan(math.radians(fov_deg) / 2) * fill
    tan_h = tan_v * aspect
    target = mid.copy() if at is None else np.asarray(at, dtype=float)
    dist = 0.0
    for _ in range(3 if at is None else 1):
        rel = points - target
        x, y, z = rel @ right, rel @ up, rel @ back
        dist = float(np.max(np.maximum(z + np.abs(x) / tan_h, z + np.abs(y) / tan_v)))
        depth = dist - z
        u, v = x / depth, y / depth
        # Shift the target so the projected extremes are symmetric about the centre.
        du = (u.max() + u.min()) / 2
        dv = (v.max() + v.min()) / 2
        if at is not None or (abs(du) < 1e-6 and abs(dv) < 1e-6):
            break
        target = target + right * du * dist + up * dv * dist
    return target + back * dist, target, up
