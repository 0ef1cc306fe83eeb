"""How the MJCF writer writes numbers and frames: every double round-trips.

:func:`num` writes a float with ``repr`` (``-0`` as ``0``), :func:`nums` several; a frame
is ``pos`` and a ``quat`` in MuJoCo's order (:func:`mat_to_quat`, :func:`place`).
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:
    from lxml import etree


def num(x: float) -> str:
    """A float that reads back to the same double (``-0`` written as ``0``)."""
    x = float(x)
    if x == 0:
        return "0"
    text = repr(x)
    return text[:-2] if text.endswith(".0") else text


def nums(v: Any) -> str:
    """Numbers separated by spaces."""
    return " ".join(num(x) for x in v)


def mat_to_quat(m: Any) -> tuple[float, float, float, float]:
    """A rotation matrix's quaternion (w, x, y, z), MuJoCo's order (Shepperd's method)."""
    tr = m[0][0] + m[1][1] + m[2][2]
    if tr > 0:
        s = math.sqrt(tr + 1.0) * 2
        q = (0.25 * s, (m[2][1] - m[1][2]) / s, (m[0][2] - m[2][0]) / s, (m[1][0] - m[0][1]) / s)
    elif m[0][0] > m[1][1] and m[0][0] > m[2][2]:
        s = math.sqrt(1.0 + m[0][0] - m[1][1] - m[2][2]) * 2
        q = ((m[2][1] - m[1][2]) / s, 0.25 * s, (m[0][1] + m[1][0]) / s, (m[0][2] + m[2][0]) / s)
    elif m[1][1] > m[2][2]:
        s = math.sqrt(1.0 + m[1][1] - m[0][0] - m[2][2]) * 2
        q = ((m[0][2] - m[2][0]) / s, (m[0][1] + m[1][0]) / s, 0.25 * s, (m[1][2] + m[2][1]) / s)
    else:
        s = math.sqrt(1.0 + m[2][2] - m[0][0] - m[1][1]) * 2
        q = ((m[1][0] - m[0][1]) / s, (m[0][2] + m[2][0]) / s, (m[1][2] + m[2][1]) / s, 0.25 * s)
    return (float(q[0]), float(q[1]), float(q[2]), float(q[3]))


def place(el: etree._Element, t: Any) -> None:
    """Set ``pos`` and ``quat`` of ``el`` from a 4x4 transform (left out when identity)."""
    if any(t[:3, 3]):
        el.set("pos", nums(t[:3, 3]))
    q = mat_to_quat(t[:3, :3])
    if q != (1.0, 0.0, 0.0, 0.0):
        el.set("quat", nums(q))
