"""The fuzz campaign: mutants of real robots through every file-reading command.

:func:`campaign` writes each mutant into a folder of its own (with the FIFO, device link or
folder its mutation points a mesh at), runs every command on it through ``driver.py`` (in
``jobs`` warm processes), and classifies each run. Failures are: a signal (segfault, abort),
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

from .mutate import Mutant, mutate, seeds

DRIVER = Path(__file__).with_name("driver.py")
FAILURES = ("signal", "hang", "traceback", "bug", "bad exit", "multi-line error",
            "unbounded error", "unnamed refusal", "dirty json")
#: The longest stderr line a run may print (present.py cuts every message to 2,000).
LONGEST_LINE = 2_500
LATIN1_NAME = os.fsdecode(b"caf\xe9.urdf")


def commands(file: str) -> list[list[str]]:
    """Every file-reading command, as a user would type it."""
    return [
        ["check", file], ["check", file, "--json"], ["joints", file, "--json"],
        ["links", file, "--json"], ["tree", file], ["tree", file, "--json"],
        ["info", file, "--json"], ["render", file, "-o", "out.png", "--size", "64x48", "--force"],
        ["drive", "--urdf", file, "--steps", "24", "--json"], ["sim", "scenario.json", "--json"],
        ["fix", file, "-o", "fixed.urdf", "--force", "--json"], ["fix", file, "--diff"],
        ["diff", file, "fixed.urdf", "--json"], ["collisions", file, "--samples", "4", "--json"],
        ["export", "mjcf", file, "-o", "out.xml", "--force", "--json"],
        ["sweep", "drive", "--urdf", file, "--steps", "12", "--vary", "throttle=1,2",
         "--jobs", "1", "--json"],
        ["sweep", "sim", "scenario.json", "--vary", "duration=0.02,0.04", "--jobs", "1",
         "-o", "rows.csv", "--force"],
    ]


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
        shown = (file, file.encode("utf-8", "backslashreplace").decode("utf-8"), "scenario.json",
                 "fixed.urdf")
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
    """Run ``n`` mutants (seeded) through every command over ``jobs`` driver processes.

    Args:
        out: Scratch folder (default: a temp folder, removed).
        keep: Where to save each failing mutant with its command and stderr.
    """
    rng = random.Random(seed)
    corpus = seeds()
    names = sorted(corpus)
    with tempfile.TemporaryDirectory(prefix="urdfkit-fuzz-") as tmp:
        root = Path(out or tmp)
        mutants: dict[str, tuple[Mutant, str]] = {}
        batches: list[list[dict[str, object]]] = [[] for _ in range(jobs)]
        for i in range(n):
            name = rng.choice(names)
            mutant = mutate(name, corpus[name], rng)
            file = LATIN1_NAME if rng.random() < 0.1 else "robot.urdf"
            if file == LATIN1_NAME:
                mutant.mutations.append("Latin-1 file name")
            workdir = root / f"m{i:05d}"
            _prepare(workdir, mutant, file)
            mutants[workdir.name] = (mutant, file)
            batches[i % jobs].append({"id": workdir.name, "dir": str(workdir),
                                      "commands": commands(file), "timeout": timeout})
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
                run = json.loads(line)
                mutant, file = mutants[run["id"]]
                cls = classify(run, file)
                command = " ".join(a if a != file else "F" for a in run["command"][:2])
                report.runs += 1
                report.counts[(cls, command)] += 1
                report.seconds[command] = report.seconds.get(command, 0.0) + run["seconds"]
                totals[command] += 1
                if cls in FAILURES:
                    failure = {"class": cls, "mutant": run["id"], "seed": mutant.seed_name,
                               "mutations": mutant.mutations, "command": run["command"],
                               "stderr": str(run["stderr"])[-2000:]}
                    report.failures.append(failure)
                    if keep is not None:
                        keep.mkdir(parents=True, exist_ok=True)
                        stem = f"{cls.replace(' ', '_')}-{run['id']}"
                        (keep / f"{stem}.urdf").write_bytes(mutant.data)
                        (keep / f"{stem}.json").write_text(json.dumps(failure, indent=2))
        for command, total in totals.items():
            report.seconds[command] /= total
        return report
