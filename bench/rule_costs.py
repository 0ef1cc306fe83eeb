"""What each of check's rules costs, per file, over pybullet_data (issue 30's per-rule table).

In process, mesh cache warm, no result cache: every URDF is read and parsed once, then each
round runs ``check``'s rules on every file in their real order with a fresh report, timing
each rule; the minimum over rounds is kept. The first rule to need the document's one walk
(``urdfkit.model.index.Doc``) pays for it, and the first to need a file reference resolves
it, as in a real run; the walk is also timed on its own. Read and parse are timed as
``check`` does them, beside a bare ``lxml.etree.parse`` of the same files.

The cyclic garbage collector is off while timing, as in ``urdfkit check`` (its run makes no
reference cycles): on, its scans of the 1,095 trees held here land on whichever rule
allocates when a collection is due (rule_inertia, mostly), not on the rule's own work.

Usage: python bench/rule_costs.py [-n 7] [--only random|other]

Not a unit test: the table goes in bench/README.md.
"""

from __future__ import annotations

import argparse
import gc
import time
from collections import defaultdict
from pathlib import Path

import pybullet_data
from lxml import etree

from urdfkit.checks.check import discover
from urdfkit.checks.validate import ALL_RULES
from urdfkit.model.xmlio import parse_xml, read_bytes, tolerate_quirks
from urdfkit.sources.guard import RuleReport


def main() -> int:
    ap = argparse.ArgumentParser()
    ap.add_argument("-n", type=int, default=7)
    ap.add_argument("--only", choices=("random", "other"))
    a = ap.parse_args()
    data = Path(pybullet_data.getDataPath())
    files = [Path(p) for _, p, problem in discover([data])
             if problem is None and p.endswith(".urdf")]
    if a.only:
        files = [f for f in files if ("random_urdfs" in f.parts) == (a.only == "random")]
    roots = [(f, parse_xml(read_bytes(f), f).getroot(), f.parent.absolute()) for f in files]
    for f, root, base in roots:  # warm the mesh memo, as a warm mesh cache would
        r = RuleReport(str(f), base, {})
        for rule in ALL_RULES:
            rule(root, r)

    best: dict[str, float] = defaultdict(lambda: float("inf"))

    def keep(name: str, seconds: float) -> None:
        best[name] = min(best[name], seconds)

    parser = etree.XMLParser(resolve_entities=False, no_network=True)
    gc.disable()  # as check runs (commands/check_run.py)
    for _ in range(a.n):
        t = time.perf_counter()
        for f in files:
            try:
                etree.parse(str(f), parser)
            except etree.XMLSyntaxError:
                pass
        keep("(baseline) lxml.etree.parse, read included", time.perf_counter() - t)
        t = time.perf_counter()
        for f in files:
            fixed, _ = tolerate_quirks(read_bytes(f))
            parse_xml(fixed, f, tolerated=True)
        keep("read + quirks + parse, as check does", time.perf_counter() - t)
        t = time.perf_counter()
        from urdfkit.model.index import Doc

        for _, root, _ in roots:
            Doc(root)
        keep("the one walk (Doc) alone", time.perf_counter() - t)
        spent: dict[str, float] = defaultdict(float)
        for f, root, base in roots:
            r = RuleReport(str(f), base, {})
            for rule in ALL_RULES:
                t = time.perf_counter()
                rule(root, r)
                spent[rule.__name__] += time.perf_counter() - t
        for name, seconds in spent.items():
            keep(name, seconds)
        keep("every rule", sum(spent.values()))

    n = len(files)
    print(f"{n} URDFs{f' ({a.only})' if a.only else ''} in pybullet_data, min of {a.n} rounds")
    print(f"{'':46s} {'ms':>8s} {'us/file':>8s}")
    rules = {rule.__name__ for rule in ALL_RULES}
    order = [k for k in best if k not in rules and k != "every rule"] + \
        sorted((k for k in best if k in rules), key=lambda k: -best[k]) + ["every rule"]
    for name in order:
        print(f"{name:46s} {best[name] * 1e3:8.2f} {best[name] / n * 1e6:8.1f}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
