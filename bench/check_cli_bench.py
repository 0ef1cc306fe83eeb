"""Bench section for issue 11: `urdfkit check` over pybullet_data on one worker, as a program.

Goal: at most 3x a plain lxml parse loop over the same files (baselines/parse_loop.py: walk
the folder, parse every .urdf/.xacro, nothing else). Both are whole processes, start-up
included, as users and CI run them. The every-core run is shown beside it.

``check`` also reads the 1,155 meshes the files name (mesh-aware inertia, units, concavity),
whose integrals it caches on disk: the cases run with a cache of their own, filled by the
first round (so min is the warm figure), and once more with the cache off (every mesh read
and integrated on every run).
"""

from __future__ import annotations

from run import Case, Context


def cases(ctx: Context) -> list[Case]:
    import tempfile

    import pybullet_data

    data = pybullet_data.getDataPath()
    cache = {"URDFKIT_CACHE_DIR": tempfile.mkdtemp(prefix="urdfkit-bench-cache-")}
    base = "parse loop (python + lxml) over pybullet_data"
    return [
        Case(base, [ctx.python, str(ctx.baselines / "parse_loop.py"), data]),
        Case("urdfkit check pybullet_data --json --jobs 1",
             [*ctx.urdfkit, "check", data, "--json", "--jobs", "1"], [(base, 3.0)], ok=(0, 1),
             env=cache),
        Case("urdfkit check pybullet_data --json (every core)",
             [*ctx.urdfkit, "check", data, "--json"], [(base, 3.0)], ok=(0, 1), env=cache),
        Case("urdfkit check pybullet_data --json --jobs 1, mesh cache off",
             [*ctx.urdfkit, "check", data, "--json", "--jobs", "1"], ok=(0, 1),
             env={"URDFKIT_CACHE_DIR": ""}),
    ]
