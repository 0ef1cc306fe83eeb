"""One look for every picture urdfkit draws (render, drive plots): colours and fonts.

Colours are RGB in 0..1. The robot colours follow simplecar's materials; the accents are the
Okabe-Ito palette, which stays distinguishable for colour-blind readers.
"""

from __future__ import annotations

BACKGROUND = (1.0, 1.0, 1.0)
GROUND = (0.91, 0.925, 0.945)
GRID = (0.78, 0.80, 0.83)
TEXT = (0.15, 0.17, 0.20)
#: Path / primary data series.
PRIMARY = (0.0, 0.447, 0.698)
#: Secondary series (speed, second robot).
SECONDARY = (0.835, 0.369, 0.0)
START = (0.0, 0.62, 0.451)
END = (0.8, 0.475, 0.655)
#: Link-frame and joint-axis colours: x red, y green, z blue, as in every robotics viewer.
AXIS_X = (0.85, 0.15, 0.15)
AXIS_Y = (0.15, 0.65, 0.2)
AXIS_Z = (0.15, 0.3, 0.85)
FONT_FAMILY = "DejaVu Sans"
FONT_SIZE = 10


def rgb255(color: tuple[float, float, float]) -> tuple[int, int, int]:
    """A 0..1 colour as 0..255 integers (for Pillow)."""
    return tuple(round(c * 255) for c in color)  # type: ignore[return-value]


def hex_color(color: tuple[float, float, float]) -> str:
    """A 0..1 colour as ``#rrggbb`` (for matplotlib)."""
    r, g, b = rgb255(color)
    return f"#{r:02x}{g:02x}{b:02x}"
