"""``agree``'s swing rows: both engines swing the robot from the same start, step by step.

A free swing under gravity, base fixed (a free-falling floating robot does not swing), MuJoCo
set to PyBullet's integration (:class:`~urdfkit.engine.mujoco_file_swing.Swing`) and
PyBullet's motors and link damping off, compared until a joint comes within 0.01 rad of a
limit: the engines' limit models differ (PyBullet's a hard constraint, MuJoCo's a soft one).
Where the base is free on both sides, a floating swing too: from rest at the origin, the
joints set moving, gravity off, the joints and the root link's frame compared.
"""

from __future__ import annotations

import math
from typing import Any

from urdfkit.exchange.agree_poses import sample_range
from urdfkit.exchange.agree_report import LIMIT_MARGIN, TOL_FLOATING_BASE, TOL_SWING
from urdfkit.exchange.agree_sides import Sides


def swing(s: Sides) -> None:
    """The free swing with the base fixed; where the base is free, floating too."""
    blocked = _swing_blocked(s)
    if blocked is not None:
        s.result.add("swing", "free swing", None, None, "", blocked[0], status=blocked[1])
        return
    _swing(s, floating=False)
    if s.root_free() is not None and not s.pybullet_static():
        _swing(s, floating=True)


def _swing_blocked(s: Sides) -> tuple[str, str | None] | None:
    """Why no swing can be compared (the row's detail and status), or None."""
    res = s.result
    if not s.pb.names and not res.extra_joints:
        return "no movable joints", "info"
    if not s.matched or res.unmatched_joints or res.extra_joints:
        return "not compared: the joints differ", None
    if s.pb.spherical:
        return "not compared: spherical joints", "info"
    from urdfkit.exchange.bullet_state import unreadable_state

    if unreadable_state(s.pb.joints):  # getJointStates would raise or misread
        return "not compared: " + unreadable_state(s.pb.joints), "known"
    if s.repaired:
        return (f"not compared: PyBullet simulates a singular inertia on "
                f"{', '.join(s.repaired[:3])} "
                "(see the structure rows)", "known")
    return None


def _locked(s: Sides) -> dict[str, float]:
    """Joints PyBullet locks (lower == upper) that the MJCF leaves unlimited: name -> q."""
    theirs = s.mj_joints()
    out = {}
    for j in s.robot.movable():
        if j.limited and j.lower == j.upper and j.name in s.jnt \
                and not theirs[j.name].limited:
            out[j.name] = j.lower
    return out


def _swing_start(s: Sides) -> tuple[dict[str, float], dict[str, float]]:
    """The seeded start: each limited joint in the middle half of its range.

    And joint speeds for the floating swing: a free robot falling from rest does not swing.
    """
    import numpy as np

    rng = np.random.default_rng(s.options.seed + 1)
    joints = {j.name: j for j in s.robot.joints}
    q0, v0 = {}, {}
    for n in s.pb.names:
        j = joints[n]
        lo, hi = sample_range(j) if j.limited else (-2.0, 2.0)
        mid = (lo + hi) / 2 if math.isfinite(lo + hi) else lo / 2 + hi / 2  # 1e308 and up
        half = (hi - lo) / 4
        q0[n] = float(rng.uniform(mid - half, mid + half))
    for n in s.pb.names:
        v0[n] = float(rng.uniform(-1.0, 1.0))
    return q0, v0


def _swing(s: Sides, floating: bool) -> None:
    from urdfkit.engine.mujoco_file_swing import Swing

    pb, res, o = s.pb, s.result, s.options
    locked = _locked(s)
    names = [n for n in pb.names if n not in locked]
    try:
        sw = Swing(s.mjcf, floating, {s.jnt[n]: q for n, q in locked.items()}, o.time_step,
                   s.body.get(s.robot.root), [s.jnt[n] for n in names])
    except (ValueError, RuntimeError) as e:
        res.add("swing", "free swing", None, None, "", "not compared: MuJoCo cannot weld "
                f"the locked joints ({str(e).strip().splitlines()[0][:120]})")
        return
    q0, v0 = _swing_start(s)
    sw.start({s.jnt[n]: q0[n] for n in names},
             {s.jnt[n]: v0[n] for n in names} if floating else {})
    unstable = _explicit_damping_unstable(s, q0)
    if unstable:
        kind = "floating swing" if floating else "free swing"
        res.add("swing", f"{kind}, dt {o.time_step:g}", None, None, "", unstable,
                status="known")
        return
    body = pb.swinger(floating, {n: q0.get(n, 0.0) for n in pb.names},
                      {n: v0[n] for n in names} if floating else {}, o.time_step)
    if floating:
        # uniform gravity moves a free robot's every body alike: off, the base's motion
        # is the joints' reaction alone, a few cm, where PyBullet's float32 base frame is
        # good to ~1e-9 m (with gravity, 4.9 m of fall leave 2.4e-7 of float32 rounding)
        sw.gravity_off()
        pb.engine.set_gravity((0.0, 0.0, 0.0))
    try:
        _swing_compare(s, sw, body, names, floating, locked)
    finally:
        if body != pb.body:
            pb.engine.remove_body(body)
        pb.engine.set_gravity(s.mjcf.gravity)


def _swing_compare(s: Sides, sw: Any, body: int, names: list[str], floating: bool,
                   locked: dict[str, float]) -> None:
    import numpy as np

    pb, o = s.pb, s.options
    e = pb.engine
    step_pb, rows = e.step, e.joint_rows
    joints = {j.name: j for j in s.robot.joints}
    index = [pb.movable[pb.names.index(n)] for n in names]
    # how near a limit the swing may come: LIMIT_MARGIN, or an eighth of a short range
    # (the start is a quarter of the range in from each limit), so that a gripper finger
    # of 11.5 mm (youBot's) does not stop the whole swing at its first step
    margin = {n: min(LIMIT_MARGIN, (joints[n].upper - joints[n].lower) / 8)
              for n in names if joints[n].limited}
    spun = 0.0  # the integral of the base's squared angular speed (rad^2/s)
    steps = round(o.seconds / o.time_step)
    worst, at, stop, why, base = 0.0, "", steps, "", 0.0
    for step in range(steps):
        sw.step()
        step_pb()
        qp = [r[0] for r in rows(body, index)] if index else []
        near = ""
        for n, m, v in zip(names, sw.positions(), qp, strict=True):
            j = joints[n]
            err = abs(m - v)
            if err > worst or err != err:
                worst, at = (err if err == err else math.inf), n
            if j.limited and min(v - j.lower, j.upper - v, m - j.lower,
                                 j.upper - m) < margin[n]:
                near = n
        if floating:  # the root's frame is its free joint's qpos (xpos lags a step)
            t, tm = pb.base_frame(body), sw.base_frame()
            off = max(float(np.abs(t[:3, 3] - tm[:3, 3]).max()),
                      float(np.abs(t[:3, :3] - tm[:3, :3]).max()))
            base = max(base, off if off == off else math.inf)
            spun += sw.spin() * o.time_step
        if near:
            unit = "m" if joints[near].type == "prismatic" else "rad"
            stop, why = step + 1, f"; stopped at {(step + 1) * o.time_step:g} s: " \
                f"{near} within {margin[near]:g} {unit} of a limit"
            break
    _swing_rows(s, floating, stop, worst, at, why, (base, spun), locked)


def _swing_rows(s: Sides, floating: bool, stop: int, worst: float, at: str, why: str,
                base: tuple[float, float], locked: dict[str, float]) -> None:
    res, dt = s.result, s.options.time_step
    mimic = [j.name for j in s.robot.movable() if j.mimic is not None]
    known = f"; mimic joints free on both sides ({', '.join(mimic)}): PyBullet ignores " \
        "<mimic>" if mimic else ""
    if locked:
        known += f"; locked joints welded at their value on both sides ({', '.join(locked)})"
    kind = "floating swing" if floating else "free swing"
    what = f"{kind} {stop * dt:g} s, dt {dt:g}"
    skew = _skewed_axes(s)
    status = None
    if skew and worst > TOL_SWING:
        status = "known"
        known += (f"; the axis of {skew[0][1]} is {skew[0][0]:.2g} off unit length in the "
                  "file: PyBullet's step uses it so (its own mass matrix normalises it), "
                  "MuJoCo normalises it, so the two step slightly different robots")
    res.add("swing", what, worst, TOL_SWING, "rad", f"{at}{why}{known}", status=status)
    if floating:
        # the engines turn a spinning base by different first-order steps (measured on
        # a1: 1.5e-10, 7.7e-11, 3.8e-11 at dt 1, 0.5, 0.25 ms while its joints agree to
        # 1e-16): they part by up to dt x the integral of the squared spin rate
        tol = TOL_FLOATING_BASE + dt * base[1]
        res.add("swing", f"{kind}: base frame", base[0], tol, "m|matrix",
                f"{s.robot.root} (free on both sides, from rest, joints set moving; "
                f"tolerance 1e-9 + dt x {base[1]:.3g} rad^2/s of spin)"
                + (f"; {known.lstrip('; ')}" if status else ""), status=status)


def _skewed_axes(s: Sides) -> list[tuple[float, str]]:
    """Joints whose axis PyBullet loaded off unit length (worst first)."""
    out = []
    for i, n in zip(s.pb.movable, s.pb.names, strict=True):
        off = abs(math.sqrt(sum(a * a for a in s.pb.joints[i].axis)) - 1.0)
        if off > 1e-12:
            out.append((off, n))
    return sorted(out, reverse=True)


def _explicit_damping_unstable(s: Sides, q0: dict[str, float]) -> str:
    """Why the swing cannot be compared when joint damping makes it unstable, else "".

    Both sides step joint damping explicitly (PyBullet does; MuJoCo is set so, its
    implicit ``eulerdamp`` off), so a joint's speed is multiplied by about
    ``1 - dt * damping / inertia`` each step: past 2 it flips sign and grows. PyBullet
    caps it at its 100 rad/s joint-speed limit, MuJoCo does not, so the two part by
    radians in a few steps (a Shadow hand's 0.1 N m s/rad on fingertips of ~1e-6 kg m^2
    at 1 ms: 100). The bound is the largest eigenvalue of ``dt M^-1 B`` at the start pose,
    the file's own mass matrix (base welded).
    """
    import numpy as np

    theirs = s.mj_joints()
    damping = np.array([theirs[n].damping for n in s.pb.names])
    if not damping.any():
        return ""
    mass = np.array(s.model.mass_matrix(0, [q0[n] for n in s.matched]))
    dt = s.options.time_step
    try:
        rate = float(np.linalg.eigvals(np.linalg.solve(mass, np.diag(damping))).real.max())
    except np.linalg.LinAlgError:  # a singular mass matrix: the dynamics rows say so
        return ""
    if rate * dt <= 2.0:
        return ""
    own = damping * dt / np.maximum(np.diag(mass), 1e-300)
    k = int(own.argmax())
    return (f"not compared: joint damping makes the swing unstable at this step: both "
            f"engines step it explicitly, and dt x damping / inertia reaches "
            f"{rate * dt:.3g} (stable under 2; {s.pb.names[k]}: damping "
            f"{damping[k]:.3g} N m s/rad on "
            f"{mass[k, k]:.3g} kg m^2), so joint speeds flip sign each "
            f"step and grow, PyBullet's to its 100 rad/s cap; PyBullet's own simulation "
            f"of this file is unstable at any step over {2.0 / rate:.3g} s")
