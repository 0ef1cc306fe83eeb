"""`agree --engine ENGINE` over a manifest of robots: exit codes and the rows that disagree.

    python bench/agree_engines_corpus.py --engine pinocchio --manifest /work/corpus/manifest.json

Each robot runs as a user runs it (the CLI, 20 poses); the table of exit codes is docs/engines.md
"What another engine loads". Writes ENGINE.json (per robot: exit code, failing rows, last
stderr line) beside --out.
"""

from __future__ import annotations

import argparse
import collections
import json
import subprocess
from pathlib import Path


def main() -> None:
    """Run the corpus and print one line per robot, then the exit-code counts."""
    import pybullet_data

    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--engine", required=True)
    ap.add_argument("--manifest", required=True)
    ap.add_argument("--out", default=".")
    ap.add_argument("--poses", default="20")
    a = ap.parse_args()
    robots = json.loads(Path(a.manifest).read_text())["robots"]
    out = {}
    for r in robots:
        path = r["path"].replace("{pybullet_data}", pybullet_data.getDataPath())
        cmd = ["urdfkit", "agree", path, "--engine", a.engine, "--json", "--poses", a.poses]
        for arg in r.get("args", []):
            cmd += ["--arg", arg]
        for pp in r.get("package_path", []):
            cmd += ["--package-path", pp]
        try:
            p = subprocess.run(cmd, capture_output=True, text=True, timeout=300, check=False)
            rc: int | str = p.returncode
            stdout, stderr = p.stdout, p.stderr
        except subprocess.TimeoutExpired:
            rc, stdout, stderr = "timeout", "", ""
        fails = []
        if stdout.strip():
            data = json.loads(stdout)
            fails = [(x["check"], x["value"], x["detail"][:150]) for x in data["rows"]
                     if x["status"] == "fail"]
        last = stderr.strip().splitlines()[-1][:300] if stderr.strip() else ""
        out[r["name"]] = {"rc": rc, "fails": fails, "err": last}
        print(r["name"], rc, fails[:3], last[:200], flush=True)
    Path(a.out, f"{a.engine}.json").write_text(json.dumps(out, indent=1))
    print(dict(collections.Counter(str(v["rc"]) for v in out.values())))


if __name__ == "__main__":
    main()
