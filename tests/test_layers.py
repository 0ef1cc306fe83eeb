"""The package's folders are its floors: imports flow one way, from the command line down.

Every import between urdfkit's modules counts, lazy ones inside functions included: a lazy import
that goes the wrong way is still a step living in the wrong room. docs/architecture.md draws the
same tree.
"""

from __future__ import annotations

import ast
from pathlib import Path

import pytest

import urdfkit

PACKAGE = Path(urdfkit.__file__).parent

#: The floors, lowest first, and the folders on each: a module may import from its own floor
#: or below, never above. The three capabilities (checks, motion, draw) share a floor: they
#: may use each other (a sweep checks its robot, a plot reads a drive's trajectory), without
#: cycles between modules. ``formats`` shares the engine's floor: an engine builds its model
#: from the MJCF export.
FLOOR_FOLDERS = [["core"], ["model"], ["sources"], ["engine", "formats"],
                 ["checks", "motion", "draw", "exchange"], ["commands", "serve"]]
FLOORS: dict[str, int] = {name: n for n, names in enumerate(FLOOR_FOLDERS) for name in names}
FOLDERS = [name for names in FLOOR_FOLDERS for name in names]
#: The public modules at the top of the package, each on the floor of what it fronts. The last
#: four only re-export what README and docs/ import from them (tests/test_public_api.py).
TOP: dict[str, str] = {"builder": "model", "inspect": "engine", "sim": "motion",
                       "gym": "motion", "sweep": "motion", "cli": "commands",
                       "__main__": "commands", "entry": "commands", "render": "draw",
                       "diff": "checks", "collisions": "checks", "resolve": "sources"}


def _module_names() -> list[str]:
    """Every module, dotted below urdfkit: ``cli``, ``model.spec``, ``commands.drive``."""
    names = [p.relative_to(PACKAGE).with_suffix("").as_posix().replace("/", ".")
             for p in PACKAGE.rglob("*.py")]
    return sorted(n for n in names if n != "__init__" and not n.endswith(".__init__"))


def _floor(module: str) -> int:
    folder = module.split(".")[0]
    return FLOORS[TOP.get(folder, folder)]


def _path(module: str) -> Path:
    return PACKAGE.joinpath(*module.split(".")).with_suffix(".py")


def _imports(name: str) -> set[str]:
    tree = ast.parse(_path(name).read_text("utf-8"))
    modules = set(_module_names())
    out: set[str] = set()

    def add(dotted: str) -> None:
        # `from urdfkit.model import spec` names a module; `from urdfkit.model.spec import X`
        # names one too. Keep the longest prefix that is a module.
        parts = dotted.split(".")
        for n in range(len(parts), 0, -1):
            if ".".join(parts[:n]) in modules:
                out.add(".".join(parts[:n]))
                return

    for node in ast.walk(tree):
        if isinstance(node, ast.ImportFrom):
            if node.level:
                package = name.split(".")[: -node.level]
                base = ".".join(package + ([node.module] if node.module else []))
            elif node.module and node.module.startswith("urdfkit"):
                base = node.module.removeprefix("urdfkit").lstrip(".")
            else:
                continue
            for a in node.names:
                add(f"{base}.{a.name}" if base else a.name)
        elif isinstance(node, ast.Import):
            for a in node.names:
                if a.name.startswith("urdfkit."):
                    add(a.name.removeprefix("urdfkit."))
    return out - {name}


def test_every_module_lives_in_a_floor() -> None:
    loose = [m for m in _module_names() if m.split(".")[0] not in FLOORS | TOP]
    assert not loose, f"put {loose} in one of {FOLDERS}, or name it in TOP"
    folders = {p.name for p in PACKAGE.iterdir() if p.is_dir() and (p / "__init__.py").exists()}
    assert folders - {"templates"} <= set(FOLDERS), folders


def test_package_init_files_import_nothing() -> None:
    for init in PACKAGE.rglob("__init__.py"):
        tree = ast.parse(init.read_text("utf-8"))
        imports = [n for n in ast.walk(tree) if isinstance(n, (ast.Import, ast.ImportFrom))]
        assert not imports, f"{init} imports; start-up pays for every import it makes"


def test_imports_never_go_up_a_floor() -> None:
    wrong = [f"{m} (floor {_floor(m)}) imports {i} (floor {_floor(i)})"
             for m in _module_names() for i in sorted(_imports(m)) if _floor(i) > _floor(m)]
    assert not wrong, "\n".join(wrong)


#: Lower modules that still import a public face; each is a step for its owner to move down.
LEANING_UP: set[tuple[str, str]] = set()


def test_the_floors_never_import_the_public_faces() -> None:
    """The top-level modules are faces over the floors: only the command line and other faces
    import them, so no room below leans on the API it serves (the model, the joint table and the
    rest live in their floors, and the faces re-export them)."""
    below = [m for m in _module_names()
             if m.split(".")[0] in FLOORS and FLOORS[m.split(".")[0]] < FLOORS["commands"]]
    wrong = [f"{m} imports the public face {i}" for m in below for i in sorted(_imports(m))
             if i.split(".")[0] in TOP and (m, i) not in LEANING_UP]
    assert not wrong, "\n".join(wrong)
    stale = [pair for pair in LEANING_UP if pair[1] not in _imports(pair[0])]
    assert not stale, f"no longer leaning up, drop from LEANING_UP: {stale}"


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
