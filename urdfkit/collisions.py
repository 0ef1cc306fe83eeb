"""The documented ``urdfkit.collisions``: the code is in :mod:`urdfkit.checks.collisions`."""

from urdfkit.checks.collisions import (
    self_collisions as self_collisions,
)
