"""Run every urdfkit command over a corpus of real robot descriptions and compare with raw PyBullet.

Usage:

    python bench/corpus.py MANIFEST [--out DIR] [--only NAME ...] [--timeout S] [--resume]

MANIFEST is a JSON or TOML file with a list of entries (JSON: a list, or {"robots": [...]};
TOML: [[robots]] tables). Each entry:

    name             short name, unique (required)
    path             the .urdf or .xacro file (required; {pybullet_data}, ~ and $VARS expand)
    packages         {"pkg_name": "/path/to/pkg", ...}  -> urdfkit -p pkg_name=/path/to/pkg
    package_path     ["/dir", ...]                        -> urdfkit --package-path /dir
    ros_package_path "/a:/b"                              -> ROS_PACKAGE_PATH in the environment
    args             ["name:=value", ...]                 -> xacro arguments (-a)
    wheeled          true/false: also run `drive`
    group            free text shown in the table (e.g. "arm", "mobile")
    notes            free text carried to the table (e.g. "stand-in mesh for base_link.STL")

For each entry every command runs as its own subprocess with a timeout (one at a time, to keep
the load modest): check --json, joints --json, links --json, tree, info --json, render -o (small),
collisions --json, fix -o + diff, build -o (xacro input only), drive --json (wheeled only). For
each it records the exit code, the first stderr line and the run time. The file is also loaded
by a raw `p.loadURDF` in PyBullet DIRECT (a subprocess) with the flags urdfkit says it used
(`load_flags` in joints --json); joint count, names, types and limits, and each link's mass,
inertia diagonal and inertial position (getDynamicsInfo) are compared with urdfkit's joints/links
JSON. A xacro input is compared through `build`'s output.

`fix` and `build` write NAME.corpus-fixed.urdf / NAME.corpus-built.urdf next to each source, so that
relative and package:// mesh paths resolve from the written file: run it on a scratch copy of the
packages, or pass --no-beside to write under --out instead (diff is then not run).
bench/corpus-example.json runs on pybullet_data's robots.

Each non-zero exit is classified: `findings` (1), `refusal` (2; a *false refusal* when raw
PyBullet loaded the file, unless the message names a PyBullet limit (128-link state); drive's
refusals are about wheels and are judged by hand), `bug` (3, a traceback on stderr, or --json output
that does not parse), `crash` (killed by a signal or another code) or `timeout`.

Output: a markdown table on stdout (robot, each command's result, equal to PyBullet, notes)
and a JSON summary in DIR/summary.json (also per robot in DIR/results/NAME.json, so --resume
can skip robots already run). Cell legend: `ok` exit 0, `F` findings (exit 1), `R` refusal
(exit 2, raw PyBullet refused too), `R!` false refusal, `B` exit 3, `X` crash, `T` timeout,
`-` not run.

Exit status: 0 when there is no false refusal, bug, crash, timeout or mismatch; else 1.
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import time
from collections.abc import Callable
from dataclasses import asdict, dataclass, field
from pathlib import Path
from typing import Any

COMMANDS = (
    "check",
    "joints",
    "links",
    "tree",
    "info",
    "render",
    "collisions",
    "fix",
    "diff",
    "build",
    "drive",
)
# drive's refusals are about wheels, not loading ("no wheels found"): judged by hand, not here.
LOADERS = ("joints", "links", "info", "render", "collisions", "tree")
_SYMBOL = {
    "ok": "ok",
    "findings": "F",
    "refusal": "R",
    "false_refusal": "R!",
    "bug": "B",
    "crash": "X",
    "timeout": "T",
}
# Refusals that name something PyBullet loads but cannot then do (not false refusals).
PYBULLET_LIMITS = ("PyBullet cannot report the state",)
_BAD = ("false_refusal", "bug", "crash", "timeout")

RAW_SCRIPT = r"""
import json, os, sys
path, flags_names, fixed = sys.argv[1], sys.argv[2], sys.argv[3] == "1"
saved = os.dup(1)
devnull = os.open(os.devnull, os.O_WRONLY)
os.dup2(devnull, 1)
out = {}
try:
    import pybullet as p
    cid = p.connect(p.DIRECT)
    flags = 0
    for name in filter(None, flags_names.split(",")):
        flags |= getattr(p, name if name.startswith("URDF_") else "URDF_" + name)
    try:
        body = p.loadURDF(path, flags=flags, useFixedBase=fixed, physicsClientId=cid)
    except Exception as exc:
        text = str(exc).splitlines()[0] if str(exc) else type(exc).__name__
        out = {"loaded": False, "error": text}
    else:
        joints = []
        for i in range(p.getNumJoints(body, physicsClientId=cid)):
            info = p.getJointInfo(body, i, physicsClientId=cid)
            joints.append({"name": info[1].decode("utf-8", "replace"), "type": info[2],
                           "lower": info[8], "upper": info[9],
                           "mass": p.getDynamicsInfo(body, i, physicsClientId=cid)[0]})
        dyn = [p.getDynamicsInfo(body, i, physicsClientId=cid) for i in range(-1, len(joints))]
        out = {"loaded": True, "joints": joints, "base_mass": dyn[0][0],
               "inertia": [list(d[2]) for d in dyn], "inertial_pos": [list(d[3]) for d in dyn]}
    p.disconnect(cid)
finally:
    os.dup2(saved, 1)
print(json.dumps(out))
"""

_TYPE_CODES = {
    "REVOLUTE": 0,
    "PRISMATIC": 1,
    "SPHERICAL": 2,
    "PLANAR": 3,
    "FIXED": 4,
    "POINT2POINT": 5,
    "GEAR": 6,
}


@dataclass
class Run:
    """One command's outcome."""

    exit: int | None
    seconds: float
    stderr: str
    kind: str = "ok"
    stdout: str = field(default="", repr=False)


@dataclass
class Result:
    """Everything measured on one robot."""

    name: str
    path: str
    group: str = ""
    runs: dict[str, dict[str, Any]] = field(default_factory=dict)
    raw_loaded: bool | None = None
    raw_error: str = ""
    equal: bool | None = None
    mismatches: list[str] = field(default_factory=list)
    notes: list[str] = field(default_factory=list)


def load_manifest(path: Path) -> list[dict[str, Any]]:
    """Read the manifest's entries from a JSON or TOML file."""
    text = path.read_text(encoding="utf-8")
    if path.suffix == ".toml":
        import tomllib

        data: Any = tomllib.loads(text)
    else:
        data = json.loads(text)
    entries = data["robots"] if isinstance(data, dict) else data
    for entry in entries:
        if "name" not in entry or "path" not in entry:
            raise SystemExit(f"{path}: every entry needs a name and a path: {entry!r}")
    return list(entries)


def expand(path: str) -> str:
    """Expand ``{pybullet_data}``, ``~`` and environment variables in a manifest path."""
    if "{pybullet_data}" in path:
        import pybullet_data

        path = path.replace("{pybullet_data}", pybullet_data.getDataPath())
    return os.path.expandvars(os.path.expanduser(path))


def _urdfkit() -> list[str]:
    return [sys.executable, "-m", "urdfkit"]


def _common(entry: dict[str, Any]) -> list[str]:
    opts: list[str] = []
    for name, where in (entry.get("packages") or {}).items():
        opts += ["-p", f"{name}={where}"]
    for folder in entry.get("package_path") or []:
        opts += ["--package-path", folder]
    return opts


def _env(entry: dict[str, Any]) -> dict[str, str]:
    env = dict(os.environ)
    if entry.get("ros_package_path"):
        env["ROS_PACKAGE_PATH"] = entry["ros_package_path"]
    env.setdefault("COLUMNS", "200")
    return env


def run(cmd: list[str], env: dict[str, str], timeout: float) -> Run:
    """Run one command, bounded by timeout, and classify its exit code."""
    start = time.perf_counter()
    try:
        proc = subprocess.run(
            cmd, capture_output=True, text=True, errors="replace", env=env, timeout=timeout
        )
    except subprocess.TimeoutExpired:
        return Run(None, time.perf_counter() - start, f"timeout after {timeout:.0f} s", "timeout")
    seconds = time.perf_counter() - start
    lines = [line.strip() for line in proc.stderr.splitlines() if line.strip()]
    first = lines[0] if lines else ""
    if any(line.startswith("Traceback") for line in lines):
        first = next((line for line in reversed(lines) if not line.startswith("File ")), first)
    kinds = {0: "ok", 1: "findings", 2: "refusal", 3: "bug"}
    kind = kinds.get(proc.returncode, "crash")
    if kind in ("findings", "refusal") and any(line.startswith("Traceback") for line in lines):
        kind = "bug"  # bad input gets one line, never a traceback
    elif kind == "refusal" and len(lines) > 1 and not lines[-1].startswith("urdfkit: error"):
        first = f"{first} (+{len(lines) - 1} more stderr lines)"
    elif kind == "refusal" and not first.startswith("urdfkit: error"):
        # Warnings come first; the refusal's reason is its one error line.
        first = next((line for line in lines if line.startswith("urdfkit: error")), first)
    if kind in ("ok", "findings") and "--json" in cmd:
        try:
            json.loads(proc.stdout)
        except json.JSONDecodeError:
            kind, first = "bug", f"--json printed no JSON: {proc.stdout[:120]!r}"
    return Run(proc.returncode, seconds, first[:300], kind, proc.stdout)


def raw_load(path: str, flags: list[str], timeout: float) -> dict[str, Any]:
    """Load the file with a plain p.loadURDF in a subprocess: what a user's own script gets."""
    try:
        proc = subprocess.run(
            [sys.executable, "-c", RAW_SCRIPT, path, ",".join(flags), "0"],
            capture_output=True,
            text=True,
            errors="replace",
            timeout=timeout,
            cwd=os.path.dirname(path) or ".",
        )
    except subprocess.TimeoutExpired:
        return {"loaded": False, "error": f"raw PyBullet timed out after {timeout:.0f} s"}
    last = proc.stdout.strip().splitlines()[-1:] or [""]
    try:
        out: dict[str, Any] = json.loads(last[0])
    except json.JSONDecodeError:
        return {"loaded": False, "error": f"raw PyBullet died (exit {proc.returncode})"}
    return out


def compare(raw: dict[str, Any], joints: dict[str, Any], links: dict[str, Any]) -> list[str]:
    """Differences between raw PyBullet and urdfkit's joints/links JSON (empty when equal)."""
    diffs: list[str] = []
    ours = joints.get("joints", [])
    theirs = raw.get("joints", [])
    if len(ours) != len(theirs):
        return [f"joint count {len(ours)} vs raw {len(theirs)}"]
    for mine, other in zip(ours, theirs, strict=True):
        if mine["jointName"] != other["name"]:
            diffs.append(
                f"joint {mine['jointIndex']} name {mine['jointName']!r} vs raw {other['name']!r}"
            )
        if _TYPE_CODES.get(mine["jointType"], -1) != other["type"]:
            diffs.append(
                f"joint {mine['jointName']} type {mine['jointType']} vs raw code {other['type']}"
            )
        for key, rkey in (("jointLowerLimit", "lower"), ("jointUpperLimit", "upper")):
            if not _close(mine[key], other[rkey]):
                diffs.append(f"joint {mine['jointName']} {rkey} {mine[key]} vs raw {other[rkey]}")
    masses = {link["linkIndex"]: link["mass"] for link in links.get("links", [])}
    raw_masses = {-1: raw.get("base_mass")} | {i: j["mass"] for i, j in enumerate(theirs)}
    for index, mass in raw_masses.items():
        if index in masses and not _close(masses[index], mass):
            diffs.append(f"link {index} mass {masses[index]} vs raw {mass}")
        if index not in masses and links:
            diffs.append(f"link {index} missing from links --json")
    by_index = {link["linkIndex"]: link for link in links.get("links", [])}
    for key, rkey in (
        ("local_inertia_diagonal", "inertia"),
        ("local_inertial_pos", "inertial_pos"),
    ):
        for index, value in enumerate(raw.get(rkey, []), -1):
            mine = by_index.get(index, {}).get(key)
            if mine is not None and not all(map(_close, mine, value)):
                diffs.append(f"link {index} {key} {mine} vs raw {value}")
    return diffs


def _close(a: Any, b: Any) -> bool:
    if a is None or b is None:
        return a is b
    return bool(abs(float(a) - float(b)) <= 1e-9 * max(1.0, abs(float(a)), abs(float(b))))


def _json(run_: Run) -> dict[str, Any]:
    try:
        data = json.loads(run_.stdout)
    except json.JSONDecodeError:
        return {}
    return data if isinstance(data, dict) else {}


def survey(
    entry: dict[str, Any], out: Path, timeout: float, size: str, write_beside: bool = True
) -> Result:
    """Run every command on one entry and compare with raw PyBullet."""
    name, path = entry["name"], os.path.abspath(expand(str(entry["path"])))
    result = Result(name, path, entry.get("group", ""))
    if entry.get("notes"):
        result.notes.append(str(entry["notes"]))
    opts, env, kit = _common(entry), _env(entry), _urdfkit()
    xargs = [a for arg in entry.get("args") or [] for a in ("-a", arg)]
    work = out / "files"
    work.mkdir(parents=True, exist_ok=True)
    is_xacro = path.endswith(".xacro")
    runs: dict[str, Run] = {}

    def go(command: str, argv: list[str], limit: float = timeout) -> Run:
        runs[command] = run(kit + argv, env, limit)
        return runs[command]

    go("check", ["check", path, "--json", "--no-cache", *opts, *xargs])
    joints = go("joints", ["joints", path, "--json", *opts, *xargs])
    links = go("links", ["links", path, "--json", *opts, *xargs])
    go("tree", ["tree", path, *opts, *xargs])
    go("info", ["info", path, "--json", *opts, *xargs])
    go(
        "render",
        ["render", path, "-o", str(work / f"{name}.png"), "--size", size, "--force", *opts, *xargs],
    )
    go("collisions", ["collisions", path, "--json", *opts, *xargs])
    loadable = path
    # With beside, build and fix write next to the source (a scratch copy of the corpus), so that
    # relative and package:// mesh paths resolve from the written file as from the original.
    beside = Path(path).parent if write_beside and os.access(Path(path).parent, os.W_OK) else work
    if is_xacro:
        built = beside / f"{Path(path).name.split('.')[0]}.corpus-built.urdf"
        if (
            go("build", ["build", path, "-o", str(built), "--force", *opts, *xargs]).exit in (0, 1)
            and built.exists()
        ):
            loadable = str(built)
        else:
            loadable = ""
    if loadable:
        fixed = beside / f"{Path(loadable).name.split('.')[0]}.corpus-fixed.urdf"
        fixed.unlink(missing_ok=True)
        go("fix", ["fix", loadable, "-o", str(fixed), "--force", *opts])
        if fixed.exists() and beside != work:
            go("diff", ["diff", loadable, str(fixed), *opts])
        elif fixed.exists():
            result.notes.append(
                "diff not run: the fixed copy is not beside its meshes (--no-beside)"
            )
    if entry.get("wheeled"):
        go(
            "drive",
            ["drive", "--urdf", path, "--json", "--seconds", "3", *opts, *xargs],
            2 * timeout,
        )

    flags = _json(joints).get("load_flags") or ["URDF_USE_IMPLICIT_CYLINDER"]
    raw: dict[str, Any] = {"loaded": None, "error": "not built"}
    if loadable:
        raw = raw_load(loadable, flags, timeout)
    result.raw_loaded = raw.get("loaded")
    result.raw_error = raw.get("error", "")
    for command, run_ in runs.items():
        if (
            run_.kind == "refusal"
            and command in LOADERS + ("check", "build", "fix", "diff")
            and result.raw_loaded
            and not any(limit in run_.stderr for limit in PYBULLET_LIMITS)
        ):
            run_.kind = "false_refusal"
    if result.raw_loaded and joints.exit == 0 and links.exit == 0:
        result.mismatches = compare(raw, _json(joints), _json(links))
        result.equal = not result.mismatches
    elif result.raw_loaded is False and joints.exit == 2:
        result.equal = None
        result.notes.append(f"both refuse (raw: {result.raw_error})")
    elif result.raw_loaded is False and joints.exit == 0:
        result.equal = False
        result.mismatches.append(f"urdfkit loads, raw PyBullet refuses: {result.raw_error}")
    result.runs = {
        c: {k: v for k, v in asdict(r).items() if k != "stdout"} for c, r in runs.items()
    }
    return result


def cell(result: dict[str, Any], command: str) -> str:
    """The table cell of one command: a symbol from the legend."""
    run_ = result["runs"].get(command)
    return "-" if run_ is None else _SYMBOL[run_["kind"]]


def table(results: list[dict[str, Any]]) -> str:
    """The markdown table of all results."""
    head = ["robot", *COMMANDS, "= PyBullet", "notes"]
    lines = ["| " + " | ".join(head) + " |", "|" + "---|" * len(head)]
    for res in results:
        equal = {True: "yes", False: "**no**", None: "-"}[res["equal"]]
        notes = list(res["notes"]) + res["mismatches"][:2]
        for command in COMMANDS:
            run_ = res["runs"].get(command)
            if run_ and run_["kind"] in _BAD + ("refusal",):
                notes.append(f"{command}: {run_['stderr'][:140]}")
        text = "; ".join(notes).replace("|", "\\|")
        lines.append(
            "| " + " | ".join([res["name"], *(cell(res, c) for c in COMMANDS), equal, text]) + " |"
        )
    return "\n".join(lines)


def summarize(results: list[dict[str, Any]]) -> dict[str, Any]:
    """Counts over the corpus."""
    counts: dict[str, int] = {k: 0 for k in _SYMBOL}
    for res in results:
        for run_ in res["runs"].values():
            counts[run_["kind"]] += 1
    return {
        "robots": len(results),
        "raw_loaded": sum(1 for r in results if r["raw_loaded"]),
        "both_loaded": sum(
            1 for r in results if r["raw_loaded"] and r["runs"].get("joints", {}).get("exit") == 0
        ),
        "equal": sum(1 for r in results if r["equal"] is True),
        "mismatched": [r["name"] for r in results if r["equal"] is False],
        "runs_by_kind": counts,
        "bad": {
            r["name"]: [c for c, v in r["runs"].items() if v["kind"] in _BAD]
            for r in results
            if any(v["kind"] in _BAD for v in r["runs"].values())
        },
    }


def each_robot(args: argparse.Namespace,
               survey_one: Callable[[dict[str, Any]], dict[str, Any]]) -> list[dict[str, Any]]:
    """Each manifest entry's result (``--only``, ``--resume``, ``--table-only``), kept as
    ``OUT/results/NAME.json`` as soon as it is made, so an interrupted run resumes."""
    entries = load_manifest(args.manifest)
    if args.only:
        entries = [e for e in entries if e["name"] in set(args.only)]
    store = args.out / "results"
    store.mkdir(parents=True, exist_ok=True)
    results: list[dict[str, Any]] = []
    for entry in entries:
        stored = store / f"{entry['name']}.json"
        if (args.resume or args.table_only) and stored.exists():
            results.append(json.loads(stored.read_text()))
            continue
        if args.table_only:
            continue
        print(f"... {entry['name']}", file=sys.stderr, flush=True)
        started = time.monotonic()
        res = survey_one(entry)
        print(f"    {time.monotonic() - started:.1f} s", file=sys.stderr, flush=True)
        stored.write_text(json.dumps(res, indent=1))
        results.append(res)
    return results


def main(argv: list[str] | None = None) -> int:
    """Command line entry point."""
    parser = argparse.ArgumentParser(
        prog="bench/corpus.py",
        description=__doc__.split("\n\n", 1)[0] if __doc__ else None,
        epilog=(__doc__ or "").split("\n\n", 1)[-1],
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    parser.add_argument("manifest", type=Path, help="JSON or TOML manifest of robots")
    parser.add_argument(
        "--out", type=Path, default=Path("/tmp/urdfkit-corpus"), help="work and result folder"
    )
    parser.add_argument("--only", nargs="*", default=None, help="run only these names")
    parser.add_argument(
        "--timeout", type=float, default=180.0, help="seconds per command (drive: twice)"
    )
    parser.add_argument("--size", default="160x120", help="render size")
    parser.add_argument(
        "--no-beside",
        action="store_true",
        help="write fix/build output under --out, not next to each source",
    )
    parser.add_argument("--resume", action="store_true", help="skip robots with a stored result")
    parser.add_argument(
        "--table-only", action="store_true", help="print the table from stored results"
    )
    args = parser.parse_args(argv)
    results = each_robot(args, lambda entry: asdict(
        survey(entry, args.out, args.timeout, args.size, not args.no_beside)))
    summary = summarize(results)
    (args.out / "summary.json").write_text(
        json.dumps({"summary": summary, "results": results}, indent=1)
    )
    print(table(results))
    print()
    print("```json\n" + json.dumps(summary, indent=1) + "\n```")
    bad = summary["bad"] or summary["mismatched"]
    return 1 if bad else 0


if __name__ == "__main__":
    sys.exit(main())
