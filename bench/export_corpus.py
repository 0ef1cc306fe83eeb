"""export mjcf + agree over a corpus of real robot descriptions, floating and fixed (issue 48).

Usage:

    python bench/export_corpus.py MANIFEST [--out DIR] [--only NAME ...] [--timeout S] [--resume]
                                  [--table-only] [--poses N]

MANIFEST is bench/corpus.py's (same reader, same fields: name, path, packages, package_path,
ros_package_path, args, group, notes; see `python bench/corpus.py --help`).
bench/export-corpus-example.json runs it on pybullet_data's 19 robots (docs/export.md's).

For each entry, one command at a time, each a subprocess bounded by --timeout:

1. raw PyBullet: a plain `p.loadURDF` in DIRECT with URDF_USE_INERTIA_FROM_FILE |
   URDF_USE_IMPLICIT_CYLINDER (what the export mirrors), in its own process (a segfault is
   recorded, not suffered). A xacro is loaded through `urdfkit build`'s output, written beside the
   source (NAME.corpus-built.urdf) so that relative and package:// paths resolve from there.
2. `urdfkit export mjcf FILE -o DIR/NAME/float.xml --json`, then the same with `--fixed-base`
   (fixed.xml), with the entry's package options and xacro arguments.
3. MuJoCo's own loader on each written file (`mujoco.MjModel.from_xml_path`, a subprocess).
4. `urdfkit agree FILE MODEL --json` on each, with the same options (`--fixed-base` for fixed).

Recorded per step: the exit code, its kind (bench/corpus.py's: ok, findings, refusal, bug = exit
3 or a traceback, crash = a signal or another code, timeout), the first stderr line and the
run time; for export the notes count (by kind); for agree every failing row (check, value,
tolerance, detail) and the known rows. Results are stored per robot in DIR/results/NAME.json
(--resume skips those stored) and all together in DIR/summary.json. Prints a markdown table:
robot | raw PyBullet | export (float/fixed) | agree float | agree fixed | failing rows / refusal,
then the counts.

Exit status: 0 when every robot raw PyBullet loads exports both ways, MuJoCo loads both files and
agree passes every row both ways, with no exit 3, crash or timeout anywhere; else 1.
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import time
from collections import Counter
from pathlib import Path
from typing import Any

sys.path.insert(0, str(Path(__file__).resolve().parent))

from corpus import _common, _env, _urdfkit, each_robot, expand, raw_load, run  # noqa: E402

FLAGS = ["URDF_USE_INERTIA_FROM_FILE", "URDF_USE_IMPLICIT_CYLINDER"]
MODES = ("float", "fixed")
_BAD = ("bug", "crash", "timeout")

MUJOCO_SCRIPT = r"""
import json, sys
try:
    import mujoco
    m = mujoco.MjModel.from_xml_path(sys.argv[1])
    out = {"loaded": True, "nbody": m.nbody, "njnt": m.njnt}
except Exception as exc:
    text = str(exc).strip().splitlines()
    out = {"loaded": False, "error": (text[0] if text else type(exc).__name__)[:300]}
print(json.dumps(out))
"""


def _step(run_: Any) -> dict[str, Any]:
    return {
        "exit": run_.exit,
        "kind": run_.kind,
        "stderr": run_.stderr,
        "seconds": round(run_.seconds, 2),
    }


def _json(text: str) -> dict[str, Any]:
    try:
        data = json.loads(text)
    except json.JSONDecodeError:
        return {}
    return data if isinstance(data, dict) else {}


def mujoco_load(model: Path, timeout: float) -> dict[str, Any]:
    """MuJoCo's own loader on a written MJCF, in a subprocess."""
    start = time.perf_counter()
    try:
        proc = subprocess.run(
            [sys.executable, "-c", MUJOCO_SCRIPT, str(model)],
            capture_output=True,
            text=True,
            errors="replace",
            timeout=timeout,
        )
    except subprocess.TimeoutExpired:
        return {"loaded": False, "error": f"timeout after {timeout:.0f} s", "kind": "timeout"}
    seconds = round(time.perf_counter() - start, 2)
    last = proc.stdout.strip().splitlines()[-1:] or [""]
    out = _json(last[0])
    if not out:
        return {"loaded": False, "error": f"died (exit {proc.returncode})", "kind": "crash",
                "seconds": seconds}
    out["seconds"] = seconds
    return out


def survey(entry: dict[str, Any], out: Path, timeout: float, poses: int) -> dict[str, Any]:
    """Raw PyBullet, then export and agree floating and fixed, on one manifest entry."""
    name = entry["name"]
    path = os.path.abspath(expand(str(entry["path"])))
    opts, env, kit = _common(entry), _env(entry), _urdfkit()
    xargs = [a for arg in entry.get("args") or [] for a in ("-a", arg)]
    work = out / "files" / name
    work.mkdir(parents=True, exist_ok=True)
    result: dict[str, Any] = {
        "name": name,
        "path": path,
        "group": entry.get("group", ""),
        "notes": entry.get("notes", ""),
        "steps": {},
    }
    start = time.perf_counter()

    # 1. raw PyBullet (a xacro through build, written beside its source).
    loadable = path
    if path.endswith(".xacro"):
        parent = Path(path).parent
        beside = parent if os.access(parent, os.W_OK) else work
        built = beside / f"{Path(path).name.split('.')[0]}.corpus-built.urdf"
        built.unlink(missing_ok=True)
        b = run(kit + ["build", path, "-o", str(built), "--force", *opts, *xargs], env, timeout)
        result["steps"]["build"] = _step(b)
        loadable = str(built) if b.exit in (0, 1) and built.exists() else ""
    if loadable:
        t0 = time.perf_counter()
        raw = raw_load(loadable, FLAGS, timeout)
        result["raw"] = {
            "loaded": bool(raw.get("loaded")),
            "error": raw.get("error", ""),
            "joints": len(raw.get("joints", [])),
            "seconds": round(time.perf_counter() - t0, 2),
        }
    else:
        result["raw"] = {"loaded": False, "error": "build failed", "joints": 0}

    # 2-4. export, MuJoCo's loader, agree; floating then fixed.
    for mode in MODES:
        fixed = ["--fixed-base"] if mode == "fixed" else []
        model = work / f"{mode}.xml"
        e = run(
            kit + ["export", "mjcf", path, "-o", str(model), "--force", "--json", *fixed,
                   *opts, *xargs],
            env,
            timeout,
        )
        step = _step(e)
        notes = _json(e.stdout).get("notes") or []
        step["notes"] = len(notes)
        step["notes_by_kind"] = dict(
            Counter(str(n.get("kind", "?")) if isinstance(n, dict) else "?" for n in notes)
        )
        result["steps"][f"export_{mode}"] = step
        if e.exit != 0 or not model.exists():
            continue
        result["steps"][f"mujoco_{mode}"] = mujoco_load(model, timeout)
        a = run(
            kit + ["agree", path, str(model), "--json", "--poses", str(poses), *fixed, *opts,
                   *xargs],
            env,
            timeout,
        )
        step = _step(a)
        data = _json(a.stdout)
        rows = data.get("rows") or []
        step["rows"] = len(rows)
        step["failing"] = [
            {k: r.get(k) for k in ("check", "value", "tolerance", "unit", "detail")}
            for r in rows
            if r.get("status") == "fail"
        ]
        step["known"] = [r.get("check") for r in rows if r.get("status") == "known"]
        step["statuses"] = dict(Counter(str(r.get("status")) for r in rows))
        step["unmatched"] = {
            k: len(data.get(k) or []) for k in ("unmatched_links", "unmatched_joints",
                                                "extra_joints")
        }
        result["steps"][f"agree_{mode}"] = step
    result["seconds"] = round(time.perf_counter() - start, 2)
    return result


def _cell(step: dict[str, Any] | None) -> str:
    if step is None:
        return "-"
    kind = step["kind"]
    if kind == "ok":
        return "ok"
    return {"findings": "F", "refusal": "R", "bug": "**B**", "crash": "**X**",
            "timeout": "**T**"}[kind]


def _agree_cell(res: dict[str, Any], mode: str) -> str:
    step = res["steps"].get(f"agree_{mode}")
    mj = res["steps"].get(f"mujoco_{mode}")
    if mj is not None and not mj.get("loaded"):
        return "MuJoCo refuses"
    if step is None:
        return "-"
    if step["kind"] == "ok":
        known = len(step.get("known") or [])
        return "all pass" + (f" ({known} known)" if known else "")
    if step["kind"] == "findings":
        return f"FAIL {len(step['failing'])}"
    return _cell(step)


def _short(res: dict[str, Any], text: str, width: int = 200) -> str:
    """A stderr line without the robot's folder (the file's name is enough in the table)."""
    return text.replace(str(Path(res["path"]).parent) + os.sep, "")[:width]


def _why(res: dict[str, Any]) -> str:
    bits: list[str] = []
    if not res["raw"]["loaded"]:
        bits.append(f"raw: {res['raw']['error'][:80]}")
    build = res["steps"].get("build")
    if build and build["kind"] != "ok":
        bits.append(f"build: {_short(res, build['stderr'])}")
    for mode in MODES:
        e = res["steps"].get(f"export_{mode}")
        if e and e["kind"] != "ok":
            if mode == "fixed" and res["steps"].get("export_float", {}).get("stderr") == e[
                "stderr"
            ]:
                continue
            bits.append(f"export {mode}: {_short(res, e['stderr'])}")
        mj = res["steps"].get(f"mujoco_{mode}")
        if mj and not mj.get("loaded"):
            bits.append(f"MuJoCo {mode}: {mj.get('error', '')[:120]}")
        a = res["steps"].get(f"agree_{mode}")
        if a and a["kind"] not in ("ok", "findings"):
            bits.append(f"agree {mode}: {_short(res, a['stderr'])}")
        elif a and a["failing"]:
            rows = "; ".join(
                f"{r['check']} {_num(r['value'])} > {_num(r['tolerance'])}"
                + (f" ({str(r['detail'])[:60]})" if r.get("detail") else "")
                for r in a["failing"]
            )
            bits.append(f"{mode}: {rows}")
    return "; ".join(bits).replace("|", "\\|")


def _num(value: Any) -> str:
    return f"{value:.2g}" if isinstance(value, (int, float)) else str(value)


def table(results: list[dict[str, Any]]) -> str:
    """One markdown row per robot."""
    lines = [
        "| robot | raw PyBullet | export (float/fixed) | agree float | agree fixed "
        "| failing rows / refusal |",
        "|---|---|---|---|---|---|",
    ]
    for res in results:
        raw = "loads" if res["raw"]["loaded"] else "refuses"
        export = "/".join(_cell(res["steps"].get(f"export_{m}")) for m in MODES)
        lines.append(
            f"| {res['name']} | {raw} | {export} | {_agree_cell(res, 'float')} | "
            f"{_agree_cell(res, 'fixed')} | {_why(res)} |"
        )
    return "\n".join(lines)


def _passes(res: dict[str, Any], mode: str) -> bool:
    step = res["steps"].get(f"agree_{mode}")
    mj = res["steps"].get(f"mujoco_{mode}") or {}
    return bool(step and step["kind"] == "ok" and mj.get("loaded"))


def summarize(results: list[dict[str, Any]]) -> dict[str, Any]:
    """Counts over the corpus."""
    loaded = [r for r in results if r["raw"]["loaded"]]
    bad: dict[str, list[str]] = {}
    for res in results:
        for step_name, step in res["steps"].items():
            if step.get("kind") in _BAD:
                bad.setdefault(res["name"], []).append(f"{step_name}: {step['kind']}")
    return {
        "robots": len(results),
        "raw_loaded": len(loaded),
        "exported_float": sum(
            1 for r in loaded if r["steps"].get("export_float", {}).get("exit") == 0
        ),
        "exported_fixed": sum(
            1 for r in loaded if r["steps"].get("export_fixed", {}).get("exit") == 0
        ),
        "exported_both": sum(
            1 for r in loaded if all(r["steps"].get(f"export_{m}", {}).get("exit") == 0
                                     for m in MODES)
        ),
        "mujoco_refuses": [
            r["name"] for r in results
            if any(not (r["steps"].get(f"mujoco_{m}") or {"loaded": True}).get("loaded")
                   for m in MODES)
        ],
        "agree_pass_float": sum(1 for r in loaded if _passes(r, "float")),
        "agree_pass_fixed": sum(1 for r in loaded if _passes(r, "fixed")),
        "agree_pass_both": sum(1 for r in loaded if all(_passes(r, m) for m in MODES)),
        "not_passing": [r["name"] for r in loaded if not all(_passes(r, m) for m in MODES)],
        "bad": bad,
        "seconds_total": round(sum(r.get("seconds", 0) for r in results), 1),
        "seconds_max": max((r.get("seconds", 0) for r in results), default=0),
    }


def main(argv: list[str] | None = None) -> int:
    """Command line entry point."""
    parser = argparse.ArgumentParser(
        prog="bench/export_corpus.py",
        description=__doc__.split("\n\n", 1)[0] if __doc__ else None,
        epilog=(__doc__ or "").split("\n\n", 1)[-1],
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    parser.add_argument("manifest", type=Path, help="JSON or TOML manifest (bench/corpus.py's)")
    parser.add_argument("--out", type=Path, default=Path("/tmp/urdfkit-export-corpus"))
    parser.add_argument("--only", nargs="*", default=None, help="run only these names")
    parser.add_argument("--timeout", type=float, default=300.0, help="seconds per command")
    parser.add_argument("--poses", type=int, default=100, help="agree --poses")
    parser.add_argument("--resume", action="store_true", help="skip robots with a stored result")
    parser.add_argument("--table-only", action="store_true", help="table from stored results")
    args = parser.parse_args(argv)
    results = each_robot(args, lambda entry: survey(entry, args.out, args.timeout, args.poses))
    summary = summarize(results)
    (args.out / "summary.json").write_text(
        json.dumps({"summary": summary, "results": results}, indent=1)
    )
    print(table(results))
    print()
    print("```json\n" + json.dumps(summary, indent=1) + "\n```")
    return 1 if summary["bad"] or summary["not_passing"] else 0


if __name__ == "__main__":
    sys.exit(main())
