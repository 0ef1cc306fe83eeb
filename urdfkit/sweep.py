"""``urdfkit sweep``: many drives or scenario runs, one row each, on a process pool or on Ray.

The implementation lives in :mod:`urdfkit.motion.sweep_plan` (and the rows file in
:mod:`urdfkit.motion.sweep_journal`); this module is its public face.
"""

from __future__ import annotations

from urdfkit.motion.sweep_plan import (
    BACKENDS,
    DRIVE_METRICS,
    DRIVE_OPTIONS,
    KINDS,
    MAX_POINTS,
    MAX_ROWS_BYTES,
    SIM_FIELDS,
    SIM_JOINT_FIELDS,
    Jobs,
    Journal,
    Plan,
    Points,
    Vary,
    check_metric,
    check_sim_metric,
    clip,
    default_jobs,
    execute,
    metric_names,
    parse_path,
    parse_value,
    parse_vary,
    plan,
    points,
    read_rows,
    run,
    run_point,
    set_path,
)

__all__ = [
    "BACKENDS", "check_metric", "check_sim_metric", "clip", "default_jobs", "DRIVE_METRICS",
    "DRIVE_OPTIONS", "execute", "Jobs", "Journal", "KINDS", "MAX_POINTS", "MAX_ROWS_BYTES",
    "metric_names", "parse_path", "parse_value", "parse_vary", "Plan", "plan", "points",
    "Points", "read_rows", "run", "run_point", "set_path", "SIM_FIELDS", "SIM_JOINT_FIELDS",
    "Vary",
]
