"""The fuzz campaigns: mutants of real robots through every file-reading command.

:func:`campaign` writes each URDF mutant into a folder of its own (with the FIFO, device link
or folder its mutation points a mesh at), runs every command on it through ``driver.py`` (in
``jobs`` warm processes), export and agree on its own export included, and classifies each
run. :func:`mjcf_campaign` does the same with mutants of real MJCF exports
(:mod:`.mjcf_mutate`) through ``urdfkit agree``. Failures are: a signal (segfault, abort),
a hang, a traceback, a bug (exit 3), an exit code that is not 0/1/2, an error that is not one
line, a refusal that does not name the file, and ``--json`` output that does not parse.
"""

from __future__ import annotations

import json
import os
import random
import subprocess
import sys
import tempfile
from collections import Counter
from dataclasses import dataclass, field
from pathlib import Path

from .mjcf_mutate import SPECIAL_TEXT, MjcfMutant, mutate_mjcf
from .mutate import Mutant, mutate, seeds

DRIVER = Path(__file__).with_name("driver.py")
FAILURES = ("signal", "hang", "traceback", "bug", "bad exit", "multi-line error",
            "unbounded error", "unnamed refusal", "dirty json")
#: The longest stderr line a run may print (present.py cuts every message to 2,000).
LONGEST_LINE = 2_500
LATIN1_NAME = os.fsdecode(b"caf\xe9.urdf")
#: Files a command's refusal may name besides the mutant: the scenario, fix's output, the
#: export agree reads, the model an MJCF mutant is.
NAMED = ("scenario.json", "fixed.urdf", "out.xml", "verified.xml", "model.xml")
#: One URDF mutant in this many also runs ``export --verify`` (100 poses and a swing: slow).
VERIFY_EVERY = 6
#: pybullet_data robots whose exports seed the MJCF campaign (small: agree runs per mutant).
MJCF_SEEDS = ("r2d2.urdf", "kuka_iiwa/model.urdf", "racecar/racecar.urdf")


def commands(file: str, verify: bool = False) -> list[list[str]]:
    """Every file-reading command, as a user would type it (``verify``: export --verify too)."""
    return [
        ["check", file], ["check", file, "--json"],
        ["check", file, "--json", "--target", "ros,pinocchio,drake,mujoco"],
        ["joints", file, "--json"],
        ["links", file, "--json"], ["tree", file], ["tree", file, "--json"],
        ["info", file, "--json"], ["render", file, "-o", "out.png", "--size", "64x48", "--force"],
        ["drive", "--urdf", file, "--steps", "24", "--json"], ["sim", "scenario.json", "--json"],
        ["fix", file, "-o", "fixed.urdf", "--force", "--json"], ["fix", file, "--diff"],
        ["diff", file, "fixed.urdf", "--json"], ["collisions", file, "--samples", "4", "--json"],
        ["export", "mjcf", file, "-o", "out.xml", "--force", "--json"],
        # the mutant against its own export (written just before, in the same folder)
        ["agree", file, "out.xml", "--json", "--poses", "4"],
        *([["export", "mjcf", file, "-o", "verified.xml", "--force", "--verify"]]
          if verify else []),
        ["sweep", "drive", "--urdf", file, "--steps", "12", "--vary", "throttle=1,2",
         "--jobs", "1", "--json"],
        ["sweep", "sim", "scenario.json", "--vary", "duration=0.02,0.04", "--jobs", "1",
         "-o", "rows.csv", "--force"],
    ]


def mjcf_commands(urdf: str) -> list[list[str]]:
    """What an MJCF mutant runs through: agree, as JSON and as the table."""
    return [["agree", urdf, "model.xml", "--json", "--poses", "4"],
            ["agree", urdf, "model.xml", "--poses", "2"]]


def classify(run: dict[str, object], file: str) -> str:
    """ok, findings, refusal, or one of :data:`FAILURES`."""
    command = run["command"]
    assert isinstance(command, list)
    err = str(run["stderr"])
    if run["hang"]:
        return "hang"
    if run["signal"] is not None:
        return "signal"
    if "Traceback" in err:
        return "traceback"
    code = run["code"]
    if code == 3:
        return "bug"
    if any(len(ln) > LONGEST_LINE for ln in err.splitlines()):
        return "unbounded error"
    if code not in (0, 1, 2):
        return "bad exit"
    if code == 2:
        errors = [ln for ln in err.splitlines() if ln.strip()
                  and not ln.startswith("urdfkit: warning:")]
        if len(errors) != 1:
            return "multi-line error"
        shown = (file, file.encode("utf-8", "backslashreplace").decode("utf-8"), *NAMED)
        if not any(name in errors[0] for name in shown):
            return "unnamed refusal"
        return "refusal"
    if "--json" in command:
        try:
            json.loads(str(run["stdout"]))
        except ValueError:
            return "dirty json"
    return "ok" if code == 0 else "findings"


@dataclass
class Report:
    """What a campaign found."""

    runs: int = 0
    mutants: int = 0
    counts: Counter[tuple[str, str]] = field(default_factory=Counter)
    failures: list[dict[str, object]] = field(default_factory=list)
    seconds: dict[str, float] = field(default_factory=dict)

    def classes(self) -> Counter[str]:
        """Runs per class."""
        out: Counter[str] = Counter()
        for (cls, _), n in self.counts.items():
            out[cls] += n
        return out

    def table(self) -> str:
        """A summary table: class by command."""
        commands_seen = sorted({c for _, c in self.counts})
        classes = sorted({k for k, _ in self.counts})
        width = max(len(c) for c in commands_seen) if commands_seen else 8
        lines = [f"{'command':<{width}}  " + "  ".join(f"{k:>10}" for k in classes) +
                 "   mean s"]
        for c in commands_seen:
            cells = "  ".join(f"{self.counts.get((k, c), 0):>10}" for k in classes)
            lines.append(f"{c:<{width}}  {cells}   {self.seconds.get(c, 0.0):.3f}")
        return "\n".join(lines)


def _prepare(workdir: Path, mutant: Mutant, file: str) -> None:
    workdir.mkdir(parents=True)
    (workdir / file).write_bytes(mutant.data)
    (workdir / "scenario.json").write_text(json.dumps(
        {"duration": 0.05, "robots": [{"name": "r", "urdf": file, "base": "fixed"}]}))
    if mutant.mesh == "dir":
        (workdir / "meshdir.stl").mkdir()
    elif mutant.mesh == "fifo":
        os.mkfifo(workdir / "pipe.stl")
    elif mutant.mesh == "devzero":
        (workdir / "zero.stl").symlink_to("/dev/zero")


def campaign(n: int, seed: int, jobs: int = 2, timeout: float = 30.0,
             out: Path | None = None, keep: Path | None = None) -> Report:
    """Run ``n`` URDF mutants (seeded) through every command over ``jobs`` driver processes.

    Args:
        out: Scratch folder (default: a temp folder, removed).
        keep: Where to save each failing mutant with its command and stderr.
    """
    rng = random.Random(seed)
    corpus = seeds()
    names = sorted(corpus)
    with tempfile.TemporaryDirectory(prefix="urdfkit-fuzz-") as tmp:
        root = Path(out or tmp)
        runs: list[_Run] = []
        for i in range(n):
            name = rng.choice(names)
            mutant = mutate(name, corpus[name], rng)
            file = LATIN1_NAME if rng.random() < 0.1 else "robot.urdf"
            if file == LATIN1_NAME:
                mutant.mutations.append("Latin-1 file name")
            workdir = root / f"m{i:05d}"
            _prepare(workdir, mutant, file)
            runs.append(_Run(workdir, mutant.seed_name, mutant.mutations, mutant.data, file,
                             commands(file, verify=i % VERIFY_EVERY == 0)))
        return _drive(root, runs, n, jobs, timeout, keep)


def mjcf_campaign(n: int, seed: int, jobs: int = 2, timeout: float = 30.0,
                  out: Path | None = None, keep: Path | None = None) -> Report:
    """Run ``n`` mutants of real MJCF exports (seeded) through ``urdfkit agree``.

    Each mutant is ``model.xml`` in a folder of its own, beside a copy (hard links) of its
    export's meshes and the special files its mutation names; the URDF is the seed robot in
    pybullet_data, read where it is.
    """
    from urdfkit.sources.uris import pybullet_data_path

    data = pybullet_data_path()
    assert data is not None, "pybullet_data ships with pybullet"
    rng = random.Random(seed)
    with tempfile.TemporaryDirectory(prefix="urdfkit-fuzz-mjcf-") as tmp:
        root = Path(out or tmp)
        exports = {name: _export_seed(root / "seeds" / f"s{k}", data / name)
                   for k, name in enumerate(MJCF_SEEDS)}
        runs: list[_Run] = []
        for i in range(n):
            name = rng.choice(MJCF_SEEDS)
            model = exports[name]
            mutant = mutate_mjcf(name, model.read_bytes(), rng)
            workdir = root / f"x{i:05d}"
            _prepare_mjcf(workdir, mutant, model.parent / "model_assets")
            runs.append(_Run(workdir, name, mutant.mutations, mutant.data, "model.xml",
                             mjcf_commands(str(data / name))))
        return _drive(root, runs, n, jobs, timeout, keep)


@dataclass
class _Run:
    """One mutant's folder, what made it, its file's name and its commands."""

    workdir: Path
    seed_name: str
    mutations: list[str]
    data: bytes
    file: str
    commands: list[list[str]]


def _export_seed(folder: Path, urdf: Path) -> Path:
    folder.mkdir(parents=True)
    model = folder / "model.xml"
    subprocess.run([sys.executable, "-m", "urdfkit", "export", "mjcf", str(urdf), "-o",
                    str(model)], check=True, capture_output=True)
    return model


def _prepare_mjcf(workdir: Path, mutant: MjcfMutant, assets: Path) -> None:
    (workdir / "model_assets").mkdir(parents=True)
    for f in assets.iterdir():
        try:
            os.link(f, workdir / "model_assets" / f.name)
        except OSError:  # another file system: a copy
            (workdir / "model_assets" / f.name).write_bytes(f.read_bytes())
    (workdir / "model.xml").write_bytes(mutant.data)
    for rel, kind in mutant.specials:
        path = workdir / rel
        if path.exists() or path.is_symlink():
            continue
        path.parent.mkdir(parents=True, exist_ok=True)
        if kind == "fifo":
            os.mkfifo(path)
        elif kind == "dir":
            path.mkdir()
        elif kind == "devzero":
            path.symlink_to("/dev/zero")
        else:
            path.write_text(SPECIAL_TEXT[kind])


def _drive(root: Path, runs: list[_Run], n: int, jobs: int, timeout: float,
           keep: Path | None) -> Report:
    """Every run's commands over ``jobs`` driver processes, each run classified."""
    batches: list[list[dict[str, object]]] = [[] for _ in range(jobs)]
    by_id = {}
    for i, run in enumerate(runs):
        by_id[run.workdir.name] = run
        batches[i % jobs].append({"id": run.workdir.name, "dir": str(run.workdir),
                                  "commands": run.commands, "timeout": timeout})
    procs = []
    for k, batch in enumerate(batches):
        job_file, result_file = root / f"jobs{k}.json", root / f"results{k}.jsonl"
        job_file.write_text(json.dumps(batch))
        procs.append((subprocess.Popen([sys.executable, str(DRIVER), str(job_file),
                                        str(result_file)]), result_file))
    report = Report(mutants=n)
    totals: Counter[str] = Counter()
    for proc, result_file in procs:
        proc.wait()
        for line in result_file.read_text().splitlines():
            result = json.loads(line)
            run = by_id[result["id"]]
            cls = classify(result, run.file)
            command = " ".join("F" if a == run.file else "U" if os.path.isabs(a) else a
                               for a in result["command"][:2])
            report.runs += 1
            report.counts[(cls, command)] += 1
            report.seconds[command] = report.seconds.get(command, 0.0) + result["seconds"]
            totals[command] += 1
            if cls in FAILURES:
                _record(report, keep, cls, result, run)
    for command, total in totals.items():
        report.seconds[command] /= total
    return report


def _record(report: Report, keep: Path | None, cls: str, result: dict[str, object],
            run: _Run) -> None:
    failure = {"class": cls, "mutant": result["id"], "seed": run.seed_name,
               "mutations": run.mutations, "command": result["command"],
               "stderr": str(result["stderr"])[-2000:]}
    report.failures.append(failure)
    if keep is not None:
        keep.mkdir(parents=True, exist_ok=True)
        stem = f"{cls.replace(' ', '_')}-{result['id']}"
        (keep / f"{stem}{Path(run.file).suffix}").write_bytes(run.data)
        (keep / f"{stem}.json").write_text(json.dumps(failure, indent=2))
