"""``urdfkit.render``, the documented import: the code lives in :mod:`urdfkit.draw.render`."""

from urdfkit.draw.render import (
    RenderOptions as RenderOptions,
)
from urdfkit.draw.render import (
    render_file as render_file,
)
from urdfkit.draw.render import (
    write_png as write_png,
)
