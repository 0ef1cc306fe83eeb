"""Bench section for issue 11: `urdfkit build` start-up against `urdfkit joints --json`.

`build simplecar` once took 2.7 s against 0.56 s for `joints`, because it imported yourdfpy and
trimesh to re-validate what the guard had already checked. Goal: at most 1.5x.
"""

from __future__ import annotations

from run import Case, Context

from urdfkit.model.catalog import build_template


def cases(ctx: Context) -> list[Case]:
    car = ctx.tmp / "car.urdf"
    build_template("simplecar").write(car, force=True)  # inspect_bench may have written it
    joints = "urdfkit joints car.urdf --json"
    return [
        Case(joints, [*ctx.urdfkit, "joints", str(car), "--json"]),
        Case("urdfkit build simplecar -o -", [*ctx.urdfkit, "build", "simplecar", "-o", "-"],
             [(joints, 1.5)]),
    ]
