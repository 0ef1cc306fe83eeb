"""The view's sidebar controls for the robot on show: a slider per joint, a button per finding.

Each function adds controls to the folder the caller has open and hands each one to ``wire``,
which connects it to what it does (:class:`urdfkit.draw.view.Viewer` routes a page's values
through its gate into its queue of actions). :func:`show_values` puts a run's joint positions
on the sliders and in the pose fields.
"""

from __future__ import annotations

import math
import os
from collections.abc import Callable, Mapping, Sequence
from typing import Any

from urdfkit.draw import view_page as page
from urdfkit.draw.view_model import TINTS, ViewedRobot


def add_sliders(gui: Any, model: ViewedRobot, wire: Callable[[str, Any], None]
                ) -> dict[str, Any]:
    """One slider per movable joint (mimic joints shown, not movable), by joint name."""
    now = model.positions()
    sliders: dict[str, Any] = {}
    for j in model.joints:
        step = (j.upper - j.lower) / 1000 if j.upper > j.lower else 0.001
        hint = f"{j.urdf_type}, PyBullet joint {j.index}"
        if j.mimic is not None:
            hint += f"; mimics {j.mimic[0]} x {j.mimic[1]:g} + {j.mimic[2]:g}"
        hi = max(j.upper, j.lower + step)
        s = gui.add_slider(j.name, min=j.lower, max=hi, step=step,
                           initial_value=min(max(now[j.name], j.lower), j.upper),
                           # A joint whose limits meet has nothing to slide.
                           disabled=j.mimic is not None or j.upper <= j.lower,
                           hint=hint)
        s.precision = page.box_digits(j.lower, hi, step)
        wire(j.name, s)
        sliders[j.name] = s
    return sliders


def add_findings(gui: Any, model: ViewedRobot, wire: Callable[[Any, str], None]) -> list[Any]:
    """Each finding once: a button for one about a link, the text of the others.

    The button (wired with the link it is about) selects the link, whose panel then shows the
    finding's text. Returns the controls added, the text first.
    """
    added = [gui.add_markdown(page.findings(model))]
    for f in (f for f in model.findings if f.level in TINTS):
        links = model.finding_links(f)
        if not links:
            continue
        where = f"line {f.line}" if f.line is not None else os.path.basename(f.file)
        button = gui.add_button(page.finding_button(f.code, where, links[0]),
                                hint=f"{links[0]}: {f.text}"[:300],
                                color="red" if f.level == "error" else "yellow")
        wire(button, links[0])
        added.append(button)
    return added


def show_values(sliders: Mapping[str, Any], vector_text: Any, joints_text: Any,
                values: Mapping[str, float], joints: Sequence[Any]) -> None:
    """Put joint positions (by name) on the sliders and in the pose fields, in ``joints``' order.

    A slider takes the value of the joint of its name, kept within its ends.
    """
    for name, value in values.items():  # the sliders are disabled: nothing follows
        s = sliders.get(name)
        if s is not None and math.isfinite(float(value)):
            s.value = min(max(float(value), float(s.min)), float(s.max))
    joints = [j for j in joints if j.name in values]
    vector_text.value = repr([round(float(values[j.name]), 6) for j in joints])
    text = ",".join(f"{j.name}={round(float(values[j.name]), 6):g}" for j in joints)
    joints_text.value = f"--joints {text}" if text else ""
