"""Bench section for issue 11 (presentation): text output costs about what --json costs.

- `check` over pybullet_data, piped: text at most 1.2x `--json` (rich once made it 2x).
- `tree` on a 1000-link chain: `--json` at most 1.2x the text (indented nested JSON once took
  4 s and 58 MB; it is flat now).
"""

from __future__ import annotations

from run import Case, Context


def _chain(ctx: Context, n: int = 1000) -> str:
    path = ctx.tmp / "chain.urdf"
    links = "".join(f'<link name="l{i}"/>' for i in range(n))
    joints = "".join(
        f'<joint name="j{i}" type="revolute"><parent link="l{i - 1}"/><child link="l{i}"/>'
        f'<axis xyz="0 0 1"/><limit lower="-1" upper="1" effort="1" velocity="1"/></joint>'
        for i in range(1, n))
    path.write_text(f'<robot name="chain">{links}{joints}</robot>')
    return str(path)


def cases(ctx: Context) -> list[Case]:
    import pybullet_data

    data = pybullet_data.getDataPath()
    chain = _chain(ctx)
    check_json = "urdfkit check pybullet_data --json"
    tree_text = "urdfkit tree chain1000.urdf"
    return [
        Case(check_json, [*ctx.urdfkit, "check", data, "--json"], ok=(0, 1)),
        Case("urdfkit check pybullet_data", [*ctx.urdfkit, "check", data], [(check_json, 1.2)],
             ok=(0, 1)),
        Case(tree_text, [*ctx.urdfkit, "tree", chain]),
        Case("urdfkit tree chain1000.urdf --json", [*ctx.urdfkit, "tree", chain, "--json"],
             [(tree_text, 1.2)]),
    ]
