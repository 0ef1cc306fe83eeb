"""``urdfkit.resolve``, the documented import: the code lives in :mod:`urdfkit.sources.resolve`."""

from urdfkit.sources.resolve import (
    resolve as resolve,
)
