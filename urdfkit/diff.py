"""``urdfkit.diff``, the documented import: the code lives in :mod:`urdfkit.checks.diff`."""

from urdfkit.checks.diff import (
    diff_files as diff_files,
)
from urdfkit.checks.diff import (
    diff_robots as diff_robots,
)
