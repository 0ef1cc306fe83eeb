"""Load URDF files in the real consumers ``check --target`` predicts: urdfdom (ROS), Pinocchio,
Drake and MuJoCo's own URDF reader.

Each engine runs in a worker process of its own, kept for the test process (:func:`load`),
which reads file paths on stdin and answers a JSON line for each: whether the engine refused
the file and why, and what it loaded (masses, joints). A file that kills the worker (a crash in
the engine) is answered ``crashed`` and the worker restarted, so one file cannot stop a sweep.
Used by tests/test_check_targets.py, and by bench/target_agreement.py for the corpora.
"""

from __future__ import annotations

import atexit
import contextlib
import json
import os
import subprocess
import sys
import sysconfig
from dataclasses import dataclass, field
from pathlib import Path

ENGINES = ("ros", "pinocchio", "drake", "mujoco")


def cmeel_prefix() -> Path | None:
    """Where ``pip install pin`` put urdfdom's ``check_urdf`` and its libraries."""
    prefix = Path(sysconfig.get_paths()["purelib"]) / "cmeel.prefix"
    return prefix if (prefix / "bin" / "check_urdf").is_file() else None


def available(engine: str) -> bool:
    """Whether ``engine`` can be loaded here."""
    if engine == "ros":
        return cmeel_prefix() is not None
    module = {"pinocchio": "pinocchio", "drake": "pydrake", "mujoco": "mujoco"}[engine]
    import importlib.util

    return importlib.util.find_spec(module) is not None


@dataclass
class Outcome:
    """What one engine did with one file."""

    refused: bool
    message: str = ""
    crashed: bool = False
    #: What was loaded: per engine, e.g. {"masses": {link: kg}, "joints": [...], "nq": n}.
    model: dict[str, object] = field(default_factory=dict)


_WORKER = r'''
import json, os, sys, io, contextlib
engine = sys.argv[1]

def ros(path):
    import subprocess
    env = dict(os.environ, LD_LIBRARY_PATH=os.path.join(PREFIX, "lib"))
    try:
        p = subprocess.run([os.path.join(PREFIX, "bin", "check_urdf"), path],
                           capture_output=True, text=True, errors="replace", env=env, timeout=20)
    except subprocess.TimeoutExpired:  # its tree printer loops on a joint that is its own
        return {"refused": False, "message": "check_urdf did not end (it parsed the file)"}
    text = (p.stderr + p.stdout).strip()
    if p.returncode != 0:
        first = text.splitlines()[0] if text else f"exit {p.returncode}"
        return {"refused": True, "message": first}
    return {"refused": False, "message": ""}

def pinocchio(path):
    import pinocchio as pin
    try:
        m = pin.buildModelFromUrdf(path)
    except Exception as e:
        return {"refused": True, "message": f"{type(e).__name__}: {e}".splitlines()[0]}
    masses = {}
    for i in range(1, m.njoints):
        masses[m.names[i]] = float(m.inertias[i].mass)
    frames = {f.name: str(f.type) for f in m.frames}
    return {"refused": False, "model": {"nq": m.nq, "nv": m.nv,
            "joints": [m.names[i] for i in range(1, m.njoints)],
            "joint_masses": masses, "frames": frames}}

def drake(path):
    # as a simulation loads it: a plant with a SceneGraph (which reads visuals and
    # collisions), its package_map holding the packages the file names that can be found
    import re
    from pydrake.multibody.parsing import Parser
    from pydrake.multibody.plant import AddMultibodyPlantSceneGraph
    from pydrake.systems.framework import DiagramBuilder
    from pathlib import Path
    from urdfkit.sources.uris import find_package
    builder = DiagramBuilder()
    plant, _ = AddMultibodyPlantSceneGraph(builder, 0.0)
    parser = Parser(plant)
    try:
        text = Path(path).read_text("utf-8", "replace")
    except OSError:
        text = ""
    for name in set(re.findall(r"(?:package|model)://([^/\"']+)/", text)):
        root = find_package(name, Path(path).parent)
        if root is not None and not parser.package_map().Contains(name):
            parser.package_map().Add(name, str(root))
    try:
        parser.AddModels(path)
        plant.Finalize()
    except BaseException as e:  # Drake's failed conditions raise SystemExit
        return {"refused": True, "message": f"{type(e).__name__}: {e}".splitlines()[0]}
    bodies = {}
    for i in range(plant.num_bodies()):
        b = plant.get_body(__import__("pydrake").multibody.tree.BodyIndex(i))
        if b.name() != "world":
            bodies[b.name()] = float(b.default_mass())
    return {"refused": False, "model": {"nq": plant.num_positions(),
            "nv": plant.num_velocities(), "masses": bodies}}

def mujoco(path):
    import mujoco as mj
    try:
        m = mj.MjModel.from_xml_path(path)
    except Exception as e:
        return {"refused": True, "message": f"{type(e).__name__}: {e}".strip().splitlines()[0]}
    names = [mj.mj_id2name(m, mj.mjtObj.mjOBJ_BODY, i) for i in range(m.nbody)]
    return {"refused": False, "model": {"nq": int(m.nq), "nv": int(m.nv), "bodies": names,
            "masses": {n: float(m.body_mass[i]) for i, n in enumerate(names)},
            "limited": [bool(x) for x in m.jnt_limited],
            "nvisual": int(sum(1 for g in range(m.ngeom) if m.geom_contype[g] == 0
                               and m.geom_conaffinity[g] == 0))}}

PREFIX = sys.argv[2]
load = {"ros": ros, "pinocchio": pinocchio, "drake": drake, "mujoco": mujoco}[engine]
if engine == "drake":
    import logging
    logging.getLogger("drake").setLevel(logging.ERROR)
for line in sys.stdin:
    path = line.rstrip("\n")
    out = io.StringIO()
    with contextlib.redirect_stdout(out):
        try:
            answer = load(path)
        except UnicodeDecodeError:  # loaded; its names are no UTF-8 for the bindings
            answer = {"refused": False, "model": {}}
    print(json.dumps(answer), flush=True)
'''


class _Worker:
    def __init__(self, engine: str) -> None:
        prefix = cmeel_prefix()
        self.engine = engine
        self.proc = subprocess.Popen(
            [sys.executable, "-c", _WORKER, engine, str(prefix or "")],
            stdin=subprocess.PIPE, stdout=subprocess.PIPE, stderr=subprocess.DEVNULL,
            text=True, env=dict(os.environ, MUJOCO_GL="egl"))

    def ask(self, path: str) -> Outcome:
        assert self.proc.stdin is not None and self.proc.stdout is not None
        try:
            self.proc.stdin.write(path + "\n")
            self.proc.stdin.flush()
            line = self.proc.stdout.readline()
        except BrokenPipeError:
            line = ""
        if not line:
            self.proc.wait()
            return Outcome(True, f"crashed (exit {self.proc.returncode})", crashed=True)
        d = json.loads(line)
        return Outcome(d["refused"], d.get("message", ""), model=d.get("model", {}))

    def close(self) -> None:
        assert self.proc.stdin is not None and self.proc.stdout is not None
        if self.proc.poll() is None:
            self.proc.stdin.close()
            self.proc.wait(timeout=30)
        for pipe in (self.proc.stdin, self.proc.stdout):
            with contextlib.suppress(BrokenPipeError):  # the worker died with input unread
                pipe.close()


#: One worker per engine, kept for the process (an engine's import costs 0.15-0.5 s).
_WORKERS: dict[str, _Worker] = {}


def _close_all() -> None:
    for worker in _WORKERS.values():
        worker.close()
    _WORKERS.clear()


atexit.register(_close_all)


def load(engine: str, paths: list[str]) -> dict[str, Outcome]:
    """Each file loaded in ``engine``, in its worker process (restarted after a crash)."""
    found: dict[str, Outcome] = {}
    for path in paths:
        worker = _WORKERS.get(engine)
        if worker is None or worker.proc.poll() is not None:
            worker = _WORKERS[engine] = _Worker(engine)
        found[path] = worker.ask(os.path.abspath(path))
        if found[path].crashed:
            worker.close()
            del _WORKERS[engine]
    return found
