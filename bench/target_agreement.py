"""Issue 51's agreement table: does ``check --target X`` report an error exactly where engine X
refuses the file?

Corpora: pybullet_data's URDFs; the robots of a corpus manifest (robot_descriptions' and the
ROS packages of docs/robots.md; xacro expanded once by urdfkit, both sides then read the same
URDF); and seeded fuzz mutants of real robots (tests/fuzz/mutate.py). Each file is checked by
urdfkit (``check_paths(targets=...)``, no cache) and loaded by the engine itself
(tests/engine_loaders.py: urdfdom's ``check_urdf``, ``pinocchio.buildModelFromUrdf``, ...).
"Predicted refused" is an error of the target's codes.

Usage::

    python bench/target_agreement.py --targets ros,pinocchio --mutants 500 \\
        [--manifest /work/corpus/manifest.json] [--seed 1] [--show 10]
"""

from __future__ import annotations

import argparse
import json
import random
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT / "tests"))

from engine_loaders import load  # noqa: E402
from fuzz.mutate import mutate, seeds  # noqa: E402

PREFIX = {"ros": "T1", "pinocchio": "T2", "drake": "T3", "mujoco": "T4"}


def pybullet_data() -> list[str]:
    import pybullet_data as pd

    return sorted(str(p) for p in Path(pd.getDataPath()).rglob("*.urdf"))


def manifest_files(manifest: Path, out: Path) -> list[str]:
    """Each robot of the manifest as a URDF (xacro expanded once, into ``out``)."""
    import pybullet_data as pd

    from urdfkit.sources.resolve import open_input

    files = []
    for entry in json.loads(manifest.read_text("utf-8"))["robots"]:
        path = entry["path"].replace("{pybullet_data}", pd.getDataPath())
        if path.endswith((".xacro",)) or "xacro" in Path(path).name:
            try:
                with open_input(path, xacro_args=entry.get("args", []),
                                package_paths=entry.get("package_path", [])) as res:
                    target = out / f"{entry['name']}.urdf"
                    target.write_bytes(Path(res.load_path).read_bytes())
                    path = str(target)
            except Exception as e:  # noqa: BLE001 - a robot we cannot expand is reported
                print(f"  skipped {entry['name']}: {e}", file=sys.stderr)
                continue
        files.append(path)
    return files


def mutants(n: int, seed: int, out: Path) -> list[str]:
    rng = random.Random(seed)
    pool = seeds()
    names = sorted(pool)
    files = []
    for k in range(n):
        name = names[rng.randrange(len(names))]
        m = mutate(name, pool[name], rng)
        path = out / f"m{k:05d}.urdf"
        path.write_bytes(m.data)
        files.append(str(path))
    return files


def agreement(paths: list[str], target: str) -> dict[str, object]:
    from urdfkit.checks.check import check_paths

    result = check_paths(paths, targets=(target,), cache=False)
    prefix = PREFIX[target]
    predicted = {fr.file: any(f.level == "error" and f.code.startswith(prefix)
                              for f in fr.findings) for fr in result.files}
    actual = load(target, paths)
    false_refusals = [p for p in paths if predicted[p] and not actual[p].refused]
    misses = [(p, actual[p].message) for p in paths if actual[p].refused and not predicted[p]]
    return {"files": len(paths), "refused": sum(a.refused for a in actual.values()),
            "crashed": sum(a.crashed for a in actual.values()),
            "predicted": sum(predicted.values()), "false_refusals": false_refusals,
            "misses": misses,
            "agree": 1 - (len(false_refusals) + len(misses)) / max(1, len(paths))}


def main() -> int:
    ap = argparse.ArgumentParser()
    ap.add_argument("--targets", default="ros,pinocchio")
    ap.add_argument("--manifest", type=Path, default=None)
    ap.add_argument("--mutants", type=int, default=500)
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--show", type=int, default=10)
    ap.add_argument("--keep", type=Path, default=None, help="write the files here, kept")
    a = ap.parse_args()
    with tempfile.TemporaryDirectory() as scratch:
        tmp = str(a.keep) if a.keep is not None else scratch
        Path(tmp).mkdir(parents=True, exist_ok=True)
        corpora = {"pybullet_data": pybullet_data()}
        if a.manifest is not None:
            (Path(tmp) / "robots").mkdir(exist_ok=True)
            corpora["manifest robots"] = manifest_files(a.manifest, Path(tmp) / "robots")
        if a.mutants:
            (Path(tmp) / "mutants").mkdir(exist_ok=True)
            corpora[f"mutants (seed {a.seed})"] = mutants(a.mutants, a.seed,
                                                          Path(tmp) / "mutants")
        print("| corpus | target | files | engine refuses | check predicts | false refusals "
              "| misses | agreement |")
        print("|---|---|---:|---:|---:|---:|---:|---:|")
        details = []
        for corpus, paths in corpora.items():
            for target in a.targets.split(","):
                start = time.perf_counter()
                r = agreement(paths, target)
                fr, ms = r["false_refusals"], r["misses"]
                assert isinstance(fr, list) and isinstance(ms, list)
                took = time.perf_counter() - start
                print(f"| {corpus} | {target} | {r['files']} | {r['refused']} "
                      f"({r['crashed']} crashed) | {r['predicted']} | {len(fr)} | {len(ms)} "
                      f"| {100 * float(r['agree']):.1f}% |  <!-- {took:.0f} s -->")
                details += [f"{corpus} {target} false refusal: {p}" for p in fr[:a.show]]
                details += [f"{corpus} {target} miss: {p}: {m}" for p, m in ms[:a.show]]
        for line in details:
            print(line)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
