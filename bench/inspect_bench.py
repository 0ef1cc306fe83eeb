"""Bench section for issue 3: `urdfkit joints`, `--help`, against the tutorial script and a
bare typer app doing the same PyBullet work."""

from __future__ import annotations

from run import Case, Context

from urdfkit.model.catalog import build_template


def cases(ctx: Context) -> list[Case]:
    car = ctx.tmp / "car.urdf"
    build_template("simplecar").write(car, force=True)  # another section may have written it
    script = str(ctx.baselines / "tutorial_inspect.py")
    bare = [ctx.python, str(ctx.baselines / "bare_typer.py")]
    return [
        Case("tutorial script", [ctx.python, script, str(car)]),
        Case("bare typer joints --json", [*bare, "joints", str(car), "--json"]),
        Case("bare typer --help", [*bare, "--help"]),
        Case("urdfkit joints --json", [*ctx.urdfkit, "joints", str(car), "--json"],
             [("tutorial script", 1.4), ("bare typer joints --json", 1.1)]),
        Case("urdfkit joints (table, piped)", [*ctx.urdfkit, "joints", str(car)],
             [("tutorial script", 1.6)]),
        # On a terminal: the rich table (imports rich), against the tutorial printing its
        # tuples to the same terminal.
        Case("tutorial script (terminal)", [ctx.python, script, str(car)], terminal=True),
        Case("urdfkit joints (table, terminal)", [*ctx.urdfkit, "joints", str(car)],
             [("tutorial script (terminal)", 1.6)], terminal=True),
        Case("urdfkit --help", [*ctx.urdfkit, "--help"], [("bare typer --help", 1.1)]),
    ]
