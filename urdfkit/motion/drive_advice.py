"""What ``drive`` says beside its numbers: what it found, and the advice it measures first.

Found at load: a static base or a start inside the ground (:func:`start_problems`), frames
PyBullet gives 1 kg (:func:`phantom_mass`), driven wheels on a swivel left free
(:func:`free_swivels`), the file's Gazebo friction where the engine uses another
(:func:`gazebo_differences`). Found after the run: a base that turns slower than commanded,
with advice tried by running the same drive again first (:func:`yaw_shortfall`).
"""

from __future__ import annotations

import math
from collections.abc import Callable
from typing import TYPE_CHECKING

from urdfkit.motion.vehicle import PYBULLET_DEFAULT_FORCE

if TYPE_CHECKING:
    from urdfkit.engine.api import Simulator
    from urdfkit.model.gazebo import GazeboContact
    from urdfkit.motion.vehicle import Drivetrain

#: PyBullet's linear and angular damping of every link (drive does not change it).
PYBULLET_LINK_DAMPING = 0.04
#: The longest run (simulated s) repeated at more force to test the advice to raise it.
PROBE_LIMIT = 60.0


def start_problems(engine: Simulator, body: int, ground: int, tutorial: bool
                   ) -> tuple[bool, list[str], list[str]]:
    """A static base, or a start inside the ground, make the run meaningless: say so.

    Whether the base is static, the problems, and the warnings (the tutorial's own start,
    reproduced, is a warning).
    """
    problems: list[str] = []
    warnings: list[str] = []
    static_base = engine.dynamics(body, -1).mass == 0
    root = engine.link_names(body)[0]
    if static_base and root == "world":
        # PyBullet gives a link named `world` without <inertial> mass 0, not 1 kg
        # (measured on 3.2.7: with a mass of its own it falls like any other).
        problems.append("static base: the root link is named `world`, and PyBullet gives a "
                        "`world` link without <inertial> mass 0, which fixes it where it is "
                        "loaded: the car cannot move; drop the `world` link and its joint "
                        "(build without the world frame) to drive it")
    elif static_base:
        problems.append("static base: the root link has mass 0, so PyBullet fixes it where it "
                        "is loaded and the car cannot move; give it a mass")
    points = engine.closest_points(body, ground, 0.0)
    depth = min((pt.distance for pt in points), default=0.0)
    if depth < -0.005:
        if tutorial:  # the tutorial's own start: reproduced, and said
            warnings.append(f"the tutorial's start is {-depth * 1000:.0f} mm inside the "
                            "ground (the contact pushes the car out at once)")
        else:
            problems.append(f"started inside the ground: {-depth * 1000:.0f} mm deep (the "
                            "contact pushes it out with a jolt); leave `base_position` unset "
                            "to rest it on the ground")
    return static_base, problems, warnings


def gazebo_differences(engine: Simulator, body: int, gazebo: dict[str, GazeboContact]
                       ) -> list[str]:
    """The file's Gazebo friction where the engine uses another, as a user reads it."""
    if not gazebo:
        return []
    from urdfkit.motion.gazebo_load import link_indices

    index = link_indices(engine, body)
    out = []
    for name, g in gazebo.items():
        mu = g.lateral_friction
        if mu is None or name not in index:
            continue
        used = engine.dynamics(body, index[name]).lateral_friction
        if abs(used - mu) > 1e-9 * max(1.0, mu):
            given = " ".join(f"{k} {v:g}" for k, v in g.given().items()
                             if k in ("mu1", "mu2"))
            out.append(f"{name} {given}, {engine.label} uses {used:g}")
    return out


def phantom_mass(engine: Simulator, body: int, frames: list[str] | None) -> str | None:
    """What to say when PyBullet's 1 kg for each link without <inertial> is much of the robot.

    Frames (camera, IMU, sensor links) usually have no <inertial>; PyBullet makes each a
    1 kg body. On a small robot that is most of its weight, high up: a TurtleBot-sized base
    with five such frames (5 of 8.55 kg) tips over in raw PyBullet with its motors off.
    """
    if not frames:
        return None
    total = sum(engine.dynamics(body, k).mass for k in range(-1, len(engine.joints(body))))
    made_up = float(len(frames))
    if total > 0 and made_up >= 0.1 * total:
        names = ", ".join(frames[:5]) + (", ..." if len(frames) > 5 else "")
        return (
            f"PyBullet gives the {len(frames)} link(s) without <inertial> 1 kg each "
            f"({names}): {made_up:g} of the {total:.4g} kg simulated; if they are frames, "
            "`urdfkit fix` gives them mass 0")
    return None


def free_swivels(engine: Simulator, body: int, train: Drivetrain) -> str | None:
    """What to say when driven wheels hang from a swivel left free (a caster's).

    Naming only the wheels of a base whose wheels all sit on swivels (youBot's, Toyota
    HSR's drive unit on ``base_roll_joint``) leaves the swivels rolling free: the unit
    turns under the body, and the body's path and yaw are not the wheels'. HSR at
    ``--steer 0.5`` yawed 0.13 rad while its drive unit turned, and the run blamed wheel
    slip.
    """
    joints = engine.joints(body)
    free = set(train.casters)
    swivels: dict[int, list[str]] = {}
    for w in train.wheels:
        k = joints[w].parent
        while k >= 0:
            if k in free and k not in train.wheels:
                swivels.setdefault(k, []).append(train.joint_names[w])
            k = joints[k].parent
    if swivels:
        named = ", ".join(train.joint_names[k] for k in swivels)
        wheels = ", ".join(w for ws in swivels.values() for w in ws)
        them = "it" if len(swivels) == 1 else "them"
        return (
            f"the driven wheels {wheels} hang from free swivel(s) {named}, which turn "
            "under the base as the wheels push: the base's path and yaw are not the "
            f"wheels'; give {named} to --hinges to hold {them}")
    return None


def unloaded_wheels(engine: Simulator, body: int, ground: int, train: Drivetrain) -> str | None:
    """Said when the wheels carry none of the weight on the ground now; else None.

    The body then rests on something else: ball casters as low as the wheels, a chassis.
    """
    contacts = engine.contacts(body, other=ground)
    total = sum(c.normal_force for c in contacts)
    wheels = set(train.wheels)
    on_wheels = sum(c.normal_force for c in contacts if c.link_a in wheels)
    if total <= 0 or on_wheels > 0.01 * total:
        return None
    bearers = sorted({train.link_names.get(c.link_a, str(c.link_a)) for c in contacts
                      if c.link_a not in wheels and c.normal_force > 0})
    return (f"the wheels carry {on_wheels:.3g} N of the {total:.3g} N on the ground: the "
            f"body rests on {', '.join(bearers)}, and the wheels spin without weight; lower "
            "the wheels or raise what it rests on (a ball caster as low as the wheels can "
            "take all of it)")


def yaw_shortfall(train: Drivetrain, steer: float, throttle: float, max_force: float | None,
                  rate: float, share: float, sim_time: float,
                  probe: Callable[..., float | None]) -> str:
    """Why the base turns slower than commanded, and advice that was tried before it is said.

    The same drive (same duration, so the same settled half) is run again over what a user
    would reach: ten and a hundred times the wheel force (capped at PyBullet's default), then,
    if no force helps, up to three times the yaw rate (capped where the inner wheels would
    stop: 2 v / track). Advice is given only when its run turns clearly faster (1.5x); it
    names the option as the command line spells it. More yaw rate is then searched for the
    command that turns within 10% of what was asked (:func:`_aim`). At most three re-runs and
    :data:`AIM_RUNS` more, only when this warning is printed; runs over :data:`PROBE_LIMIT` s
    are not repeated. ``probe(**changes)`` runs the same drive with some of its options
    changed (``max_force``, ``steer``) and gives its yaw rate (None: it failed).
    """
    kind = "skid steering" if train.steering == "skid" else "differential steering"
    # round first: a share of -3e-5 is said "0%", not "-0%"
    said = (f"{kind} turns at {rate:.3g} rad/s, {round(share, 2) + 0.0:.0%} of the "
            f"{steer:g} commanded")
    force = PYBULLET_DEFAULT_FORCE if max_force is None else max_force
    if not 0 < sim_time <= PROBE_LIMIT:
        return (f"{said}; not measured at more force (the run is over {PROBE_LIMIT:g} s): "
                "the wheels slip sideways, or the motors are too weak")

    def better(r: float | None) -> bool:
        return r is not None and abs(r) > 1.5 * abs(rate) and \
            abs(r - rate) > 0.05 * abs(steer)

    def shown(r: float | None) -> str:
        return "failed" if r is None else f"{r:.3g} rad/s"

    tried: list[str] = []
    for factor in (10.0, 100.0):
        higher = min(force * factor, PYBULLET_DEFAULT_FORCE) if force > 0 else factor
        if higher <= force or (tried and tried[-1].startswith(f"--max-force {higher:g}:")):
            break
        r = probe(max_force=higher)
        if better(r):
            assert r is not None
            return (f"{said}; with --max-force {higher:g} it turns at {r:.3g} rad/s "
                    f"({r / steer:.0%}): run with --max-force {higher:g}")
        tried.append(f"--max-force {higher:g}: {shown(r)}")
    widest = 2.0 * abs(throttle) * train.reference_radius / train.track \
        if train.track > 0 else math.inf
    more = math.copysign(min(3.0 * abs(steer), widest), steer)
    if abs(more) > 1.2 * abs(steer):
        r = probe(steer=more)
        if better(r):
            assert r is not None
            first = f"more wheel force does not help ({'; '.join(tried)})" if tried \
                else "at PyBullet's default wheel force"
            return f"{said}; {first}: the wheels slip sideways, and " + _aim(
                lambda x: probe(steer=x), steer, (steer, rate), (more, r), widest)
        tried.append(f"--steer {more:.3g}: {shown(r)}")
    return (f"{said}; neither more force nor more yaw rate turns it faster "
            f"({'; '.join(tried)}): the wheels slip sideways")


#: How close advice must land to the yaw rate asked for to be advised as reaching it.
AIM = 0.1
#: Re-runs the search for that command may take (beyond the first at more yaw rate).
AIM_RUNS = 4


def _aim(measure: Callable[[float], float | None], asked: float, start: tuple[float, float],
         more: tuple[float, float], widest: float) -> str:
    """The ``--steer`` to command for the yaw rate ``asked``, found by running it.

    A skid-steered base turns slower than commanded, and not in proportion: three times the
    command may turn it faster than asked (r2d2 at --throttle 5: --steer 0.9 turns at 0.5
    rad/s for 0.3 asked). From the two runs made (``start``, the user's, and ``more``), the
    secant method picks the next command, rounded to the three digits the advice prints,
    and runs it, up to :data:`AIM_RUNS` times, until one lands within :data:`AIM` of
    ``asked`` (capped at ``widest``, where the inner wheels stop). The advice names that
    command and what it measured; if none lands, the nearest, and says it missed.
    """
    runs = [start, more]
    for _ in range(AIM_RUNS):
        (s0, r0), (s1, r1) = runs[-2], runs[-1]
        if abs(r1 - asked) <= AIM * abs(asked) or r1 == r0:
            break
        s = s1 + (asked - r1) * (s1 - s0) / (r1 - r0)
        s = math.copysign(min(abs(s), widest), asked) if s * asked > 0 else s1 / 2
        s = float(f"{s:.3g}")
        if any(s == x for x, _ in runs):
            break
        r = measure(s)
        if r is None:
            break
        runs.append((s, r))
    s, r = min(runs[1:], key=lambda x: abs(x[1] - asked))
    if abs(r - asked) <= AIM * abs(asked):
        return (f"--steer {s:.3g} turns at {r:.3g} rad/s ({r / asked:.0%} of the {asked:g} "
                f"asked): command more yaw rate (--steer {s:.3g})")
    tried = "; ".join(f"--steer {x:.3g}: {y:.3g} rad/s" for x, y in runs[1:])
    return (f"no command tried turns within {AIM:.0%} of the {asked:g} asked ({tried}); "
            f"--steer {s:.3g} comes nearest, at {r:.3g} rad/s ({r / asked:.0%})")
