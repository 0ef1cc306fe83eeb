"""Bench section for issues 11 and 30: `urdfkit check` over pybullet_data, as programs.

Baselines (whole processes, start-up included, as users and CI run them):

- the parse loop (baselines/parse_loop.py): walk the folder and parse every .urdf/.xacro with
  lxml, nothing else;
- the floor (baselines/floor.py): the same, plus reading every mesh those files name with the
  fastest plain reader for its format (numpy for binary STL, floats split from OBJ and ASCII
  STL, lxml and float arrays for COLLADA), computing nothing: what a cold check must read.

Goals (issues 30 and 39, plain Python): the cold run (every cache off: URDFKIT_CACHE_DIR=) at
most 5x the floor; warm meshes with the result cache off (--no-cache) at most 3.5x the parse
loop (3x while check's path was compiled); a warm re-run (result cache on, nothing changed)
at most 1.5x the parse loop. The warm cases share a cache
folder that the first round fills, so their minimum is the warm figure. Issue 51: ``--target
ros,pinocchio,drake`` at most 1.5x the same check without it, warm (and, with no goal, its cost
with ``--no-cache``).
"""

from __future__ import annotations

from run import Case, Context


def cases(ctx: Context) -> list[Case]:
    import tempfile

    import pybullet_data

    data = pybullet_data.getDataPath()
    cache = {"URDFKIT_CACHE_DIR": tempfile.mkdtemp(prefix="urdfkit-bench-cache-")}
    base = "parse loop (python + lxml) over pybullet_data"
    floor = "floor: parse loop + every mesh read (python + lxml + numpy)"
    check = [*ctx.urdfkit, "check", data, "--json", "--jobs", "1"]
    warm = "urdfkit check pybullet_data --json --jobs 1, warm result cache"
    fresh = "urdfkit check pybullet_data --json --jobs 1 --no-cache, warm meshes"
    # issue 51: the targets' rules, warm (goal 1.5x check alone) and their cost unmasked
    targets = ["--target", "ros,pinocchio,drake"]
    return [
        Case(base, [ctx.python, str(ctx.baselines / "parse_loop.py"), data]),
        Case(floor, [ctx.python, str(ctx.baselines / "floor.py"), data]),
        Case(warm, check, [(base, 1.5)], ok=(0, 1), env=cache),
        Case(fresh, [*check, "--no-cache"], [(base, 3.5)], ok=(0, 1), env=cache),
        Case("urdfkit check pybullet_data --target ros,pinocchio,drake, warm result cache",
             [*check, *targets], [(warm, 1.5)], ok=(0, 1), env=cache),
        # no goal: what the rules cost a file that is checked afresh, for the record
        Case("urdfkit check pybullet_data --target ros,pinocchio,drake --no-cache, warm meshes",
             [*check, *targets, "--no-cache"], ok=(0, 1), env=cache),
        Case("urdfkit check pybullet_data --json --no-cache (every core), warm meshes",
             [*ctx.urdfkit, "check", data, "--json", "--no-cache"], [(base, 3.5)], ok=(0, 1),
             env=cache),
        Case("urdfkit check pybullet_data --json --jobs 1, cold (every cache off)", check,
             [(floor, 5.0)], ok=(0, 1), env={"URDFKIT_CACHE_DIR": ""}),
    ]
