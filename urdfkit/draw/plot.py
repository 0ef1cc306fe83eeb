"""The ``drive --plot`` picture: the x-y path seen from above, and speed over time.

matplotlib is an optional extra (``pip install 'urdfkit[plot]'``) and costs ~0.3 s to import,
so it is imported here, inside the function, and only when a plot is asked for. The Agg
backend is selected explicitly: it needs no display and renders the same bytes everywhere.
Colours and fonts come from :mod:`urdfkit.draw.style`, the same look as ``urdfkit render``.
"""

from __future__ import annotations

import io
import math
from pathlib import Path
from typing import TYPE_CHECKING, Any

from urdfkit.core.errors import MissingDependencyError, ParameterError
from urdfkit.core.output import atomic_write, check_output
from urdfkit.draw import style

if TYPE_CHECKING:
    from collections.abc import Mapping, Sequence

    from urdfkit.motion.drive_result import DriveResult


def _pyplot() -> Any:
    try:
        import matplotlib
    except ImportError as e:
        raise MissingDependencyError(
            "`plot` needs matplotlib: pip install 'urdfkit[plot]'", param="plot") from e
    matplotlib.use("Agg", force=True)
    import matplotlib.pyplot as plt

    return plt


def check_plot_path(path: str | Path, *, force: bool = False) -> None:
    """Refuse, before the run starts, a bad plot path or a missing matplotlib.

    Bad: not a PNG, or not writable (see :func:`urdfkit.core.output.check_output`).
    """
    check_output(path, force=force, suffixes=(".png",), what="the plot")
    import importlib.util

    if importlib.util.find_spec("matplotlib") is None:
        raise MissingDependencyError(
            "`plot` needs matplotlib: pip install 'urdfkit[plot]'", param="plot")


def plot_bytes(result: DriveResult) -> bytes:
    """Draw the path and speed of a drive as PNG bytes."""
    plt = _pyplot()
    traj = result.trajectory
    if traj is None:
        raise ParameterError("a plot needs the drive's samples: run it with "
                             "`keep_trajectory=True`", param="keep_trajectory")
    t, xs, ys = traj.column("t"), traj.column("x"), traj.column("y")
    yaws = traj.column("yaw")
    speed = [math.hypot(vx, vy)
             for vx, vy in zip(traj.column("vx"), traj.column("vy"), strict=False)]
    hexc = style.hex_color
    with plt.rc_context({"font.family": style.FONT_FAMILY, "font.size": style.FONT_SIZE,
                         "text.color": hexc(style.TEXT), "axes.labelcolor": hexc(style.TEXT),
                         "xtick.color": hexc(style.TEXT), "ytick.color": hexc(style.TEXT),
                         "axes.edgecolor": hexc(style.GRID), "grid.color": hexc(style.GRID),
                         "svg.hashsalt": "urdfkit"}):
        fig, (ax, bx) = plt.subplots(1, 2, figsize=(10, 4.5), dpi=100,
                                     gridspec_kw={"width_ratios": [1.2, 1]})
        fig.patch.set_facecolor(hexc(style.BACKGROUND))
        ax.set_facecolor(hexc(style.GROUND))
        ax.plot(xs, ys, color=hexc(style.PRIMARY), linewidth=2, label="path")
        # Heading marks: an arrow along the yaw at the start and at the end.
        span = max(max(xs) - min(xs), max(ys) - min(ys), 0.5)
        arrow = 0.08 * span
        for i, colour, label in ((0, style.START, "start"), (-1, style.END, "end")):
            ax.plot(xs[i], ys[i], "o", color=hexc(colour), markersize=8, label=label, zorder=3)
            ax.annotate("", xy=(xs[i] + arrow * math.cos(yaws[i]),
                                ys[i] + arrow * math.sin(yaws[i])),
                        xytext=(xs[i], ys[i]), zorder=4,
                        arrowprops={"arrowstyle": "-|>", "color": hexc(colour), "lw": 2})
        if result.turn_center is not None and result.turning_radius is not None:
            cx, cy = result.turn_center
            ax.plot(cx, cy, "+", color=hexc(style.SECONDARY), markersize=10,
                    label=f"turn centre, R = {result.turning_radius:.2f} m")
        ax.set_aspect("equal", adjustable="datalim")
        ax.set_xlabel("x (m)")
        ax.set_ylabel("y (m)")
        ax.set_title(f"{result.model}: path from above")
        ax.grid(True, linewidth=0.5)
        ax.legend(loc="best", fontsize=style.FONT_SIZE - 1)
        bx.plot(t, speed, color=hexc(style.SECONDARY), linewidth=2)
        bx.set_xlabel("time (s)")
        bx.set_ylabel("speed (m/s)")
        bx.set_title(f"speed (mean {result.mean_speed:.2f} m/s)")
        bx.set_ylim(bottom=0)
        bx.grid(True, linewidth=0.5)
        fig.tight_layout()
        buf = io.BytesIO()
        # No timestamp/software metadata: the same run gives the same bytes.
        fig.savefig(buf, format="png", metadata={"Software": None})
        plt.close(fig)
    return buf.getvalue()


def write_plot(result: DriveResult, path: str | Path, *, force: bool = False) -> Path:
    """Draw the drive to a PNG file, atomically."""
    check_plot_path(path, force=force)
    return atomic_write(path, plot_bytes(result), force=force)


#: Line colours of a sweep plot, one per value of the second varied name.
SERIES = (style.PRIMARY, style.SECONDARY, style.START, style.END, style.AXIS_Z, style.AXIS_X)


#: Units of the drive's results and settings, for a sweep plot's axes (docs/drive.md). A
#: name not here (a scenario key, a template parameter) is labelled without one.
UNITS = {
    # drive rows (urdfkit.sweep.DRIVE_METRICS)
    "final_x": "m", "final_y": "m", "final_z": "m", "final_yaw": "rad",
    "heading_change": "rad", "yaw_rate": "rad/s", "distance": "m", "mean_speed": "m/s",
    "turning_radius": "m", "turn_center_x": "m", "turn_center_y": "m", "expected_radius": "m",
    "sim_time": "s", "steps": "steps", "samples": "samples", "steer_applied": "rad",
    # scenario rows (urdfkit.sweep.SIM_FIELDS; a joint's are its own unit: rad or m)
    "end_x": "m", "end_y": "m", "end_z": "m", "top_speed": "m/s", "heading_deg": "deg",
    # what a drive sweep varies
    "throttle": "rad/s", "steer": "rad, or rad/s when skid steered", "max_force": "N m",
    "seconds": "s", "time_step": "s", "gravity": "m/s²",
}


def axis_label(name: str) -> str:
    """``"turning_radius (m)"``: a sweep axis named with its unit, when known."""
    unit = UNITS.get(name.rpartition(".")[2])
    return f"{name} ({unit})" if unit else name


def sweep_plot_bytes(rows: Sequence[Mapping[str, Any]], names: Sequence[str],
                     metric: str) -> bytes:
    """A sweep's ``metric`` against its first varied value, one line per value of the others.

    Points that failed, or lack the metric (a drive that did not turn has no radius), are
    left out of the lines.
    """
    plt = _pyplot()
    x_name, others = names[0], list(names[1:])
    series: dict[tuple[Any, ...], list[tuple[float, float]]] = {}
    for r in rows:
        x, y = r.get(x_name), r.get(metric)
        if r.get("error") or not isinstance(x, (int, float)) or not isinstance(y, (int, float)):
            continue
        series.setdefault(tuple(r.get(n) for n in others), []).append((float(x), float(y)))
    hexc = style.hex_color
    with plt.rc_context({"font.family": style.FONT_FAMILY, "font.size": style.FONT_SIZE,
                         "text.color": hexc(style.TEXT), "axes.labelcolor": hexc(style.TEXT),
                         "xtick.color": hexc(style.TEXT), "ytick.color": hexc(style.TEXT),
                         "axes.edgecolor": hexc(style.GRID), "grid.color": hexc(style.GRID)}):
        fig, ax = plt.subplots(figsize=(7, 4.5), dpi=100)
        fig.patch.set_facecolor(hexc(style.BACKGROUND))
        ax.set_facecolor(hexc(style.GROUND))
        ordered = sorted(series.items(), key=lambda kv: [str(v) for v in kv[0]])
        for k, (label, pts) in enumerate(ordered):
            pts.sort()
            text = ", ".join(f"{n} = {v}" for n, v in zip(others, label, strict=True))
            ax.plot([p[0] for p in pts], [p[1] for p in pts], marker="o", linewidth=2,
                    color=hexc(SERIES[k % len(SERIES)]), label=text or None)
        ax.set_xlabel(axis_label(x_name))
        ax.set_ylabel(axis_label(metric))
        ax.set_title(f"{metric} against {x_name}")
        ax.grid(True, linewidth=0.5)
        if others and ordered:
            ax.legend(loc="best", fontsize=style.FONT_SIZE - 1)
        fig.tight_layout()
        buf = io.BytesIO()
        fig.savefig(buf, format="png", metadata={"Software": None})
        plt.close(fig)
    return buf.getvalue()


def write_sweep_plot(rows: Sequence[Mapping[str, Any]], names: Sequence[str], metric: str,
                     path: str | Path, *, force: bool = False) -> Path:
    """Draw a sweep's metric to a PNG file, atomically."""
    check_plot_path(path, force=force)
    return atomic_write(path, sweep_plot_bytes(rows, names, metric), force=force)
