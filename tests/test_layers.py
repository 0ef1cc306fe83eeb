"""Imports flow one way: spec and model, then sources, then the engine, then run/draw, then CLI.

Every import between urdfkit's modules counts, lazy ones inside functions included: a lazy import
that goes the wrong way is still a step living in the wrong room.
"""

from __future__ import annotations

import ast
from pathlib import Path

import pytest

import urdfkit

PACKAGE = Path(urdfkit.__file__).parent

#: The house's floors, lowest first. A module may import from its own floor or below.
LAYERS: dict[str, int] = {}
for floor, names in enumerate([
    # spec and model
    "errors deps finding spec style templatedir suggest output cache xmlio tomlio builder catalog"
    " displaymesh stdio jsontext builder_elements",
    # sources: files, packages, xacro, and the guard every loader calls
    "uris meshes resultcache _xacro_worker expand guard resolve",
    # the engine session
    "session",
    # run and draw
    "inspect body tree report graph vehicle drive sac scenario sim gym render plot check build"
    " validate diff collisions fix sweep_journal sweep sweep_run view view_model view_page"
    " view_stream vehicle_shapes drive_result scenario_models sim_writers sim_dynamics"
    " sim_state sim_control sim_sensors sim_episode sim_setters sim_world sim_record",
    # presentation and the command line
    "present ci cli __main__ commands.shared commands.build commands.inspecting commands.checking"
    " commands.driving commands.drawing commands.simulating",
]):
    LAYERS.update(dict.fromkeys(names.split(), floor))


#: Folders of modules (named "folder.module" here), besides the flat ones.
FOLDERS = ("commands",)


def _module_names() -> list[str]:
    names = [p.stem for p in PACKAGE.glob("*.py") if p.stem != "__init__"]
    names += [f"{d}.{p.stem}" for d in FOLDERS for p in (PACKAGE / d).glob("*.py")
              if p.stem != "__init__"]
    return sorted(names)


def _path(name: str) -> Path:
    return PACKAGE / (name.replace(".", "/") + ".py")


def _dotted(module: str) -> str:
    """``commands.shared.x`` -> ``commands.shared``; ``present`` -> ``present``."""
    parts = module.split(".")
    return ".".join(parts[:2]) if parts[0] in FOLDERS else parts[0]


def _imports(name: str) -> set[str]:
    tree = ast.parse(_path(name).read_text("utf-8"))
    package = name.rpartition(".")[0]  # "" for a flat module
    out: set[str] = set()
    for node in ast.walk(tree):
        if isinstance(node, ast.ImportFrom):
            if node.level:
                base = ".".join(package.split(".")[:len(package.split(".")) - node.level + 1]
                                if package else [])
                prefix = f"{base}." if base else ""
                if node.module:
                    out.add(_dotted(prefix + node.module))
                else:
                    out.update(_dotted(prefix + a.name) for a in node.names)
            elif node.module == "urdfkit":
                out.update(_dotted(a.name) for a in node.names)
            elif node.module and node.module.startswith("urdfkit."):
                module = node.module.split(".", 1)[1]
                if module in FOLDERS:
                    out.update(_dotted(f"{module}.{a.name}") for a in node.names)
                else:
                    out.add(_dotted(module))
        elif isinstance(node, ast.Import):
            out.update(_dotted(a.name.split(".", 1)[1]) for a in node.names
                       if a.name.startswith("urdfkit."))
    return out & set(_module_names()) - {name}


def test_every_module_has_a_floor() -> None:
    missing = [m for m in _module_names() if m not in LAYERS]
    assert not missing, f"add {missing} to LAYERS in tests/test_layers.py"


def test_imports_never_go_up_a_floor() -> None:
    wrong = [f"{m} (floor {LAYERS[m]}) imports {i} (floor {LAYERS[i]})"
             for m in _module_names() for i in sorted(_imports(m))
             if m in LAYERS and i in LAYERS and LAYERS[i] > LAYERS[m]]
    assert not wrong, "\n".join(wrong)


def test_no_import_cycles() -> None:
    graph = {m: _imports(m) for m in _module_names()}
    # Tarjan's strongly connected components, iteratively.
    index: dict[str, int] = {}
    low: dict[str, int] = {}
    on_stack: set[str] = set()
    stack: list[str] = []
    cycles: list[list[str]] = []
    counter = 0
    for start in graph:
        if start in index:
            continue
        work = [(start, iter(sorted(graph[start])))]
        index[start] = low[start] = counter
        counter += 1
        stack.append(start)
        on_stack.add(start)
        while work:
            node, it = work[-1]
            nxt = next(it, None)
            if nxt is not None:
                if nxt not in index:
                    index[nxt] = low[nxt] = counter
                    counter += 1
                    stack.append(nxt)
                    on_stack.add(nxt)
                    work.append((nxt, iter(sorted(graph[nxt]))))
                elif nxt in on_stack:
                    low[node] = min(low[node], index[nxt])
                continue
            work.pop()
            if work:
                low[work[-1][0]] = min(low[work[-1][0]], low[node])
            if low[node] == index[node]:
                comp = []
                while True:
                    w = stack.pop()
                    on_stack.discard(w)
                    comp.append(w)
                    if w == node:
                        break
                if len(comp) > 1:
                    cycles.append(sorted(comp))
    assert not cycles, f"import cycles: {cycles}"


@pytest.mark.parametrize("module", ["cli"] + [m for m in _module_names()
                                    if m.startswith("commands.")])
def test_the_cli_is_in_its_own_room(module: str) -> None:
    """cli.py and the command modules parse options and present: no lxml or PyBullet."""
    tree = ast.parse(_path(module).read_text("utf-8"))
    names = {a.name.split(".")[0] for n in ast.walk(tree) if isinstance(n, ast.Import)
             for a in n.names}
    names |= {(n.module or "").split(".")[0] for n in ast.walk(tree)
              if isinstance(n, ast.ImportFrom) and n.level == 0}
    assert not names & {"lxml", "pybullet", "pybullet_data", "numpy"}, names
    engine_calls = {"getJointInfo", "loadURDF", "stepSimulation", "getDynamicsInfo",
                    "setJointMotorControl2", "getBasePositionAndOrientation"}
    used = {n.attr for n in ast.walk(tree) if isinstance(n, ast.Attribute)}
    assert not used & engine_calls, used & engine_calls
