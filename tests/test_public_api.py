"""Every import the README and docs/ show works, and so does the public API the layout keeps.

The names are read from the documents themselves, so a page that documents a new import is
tested by adding it, and a move that breaks one fails here. So are the options of every
``urdfkit COMMAND ...`` line they show: a renamed or removed option fails here too.
"""

from __future__ import annotations

import importlib
import re
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
DOCUMENTS = [ROOT / "README.md", *sorted((ROOT / "docs").glob("*.md"))]
FROM = re.compile(r"^\s*from (urdfkit(?:\.\w+)*) import \(?([\w, ]+)\)?", re.M)
PLAIN = re.compile(r"^\s*import (urdfkit(?:\.\w+)*)", re.M)


def _documented() -> list[tuple[str, str, str | None]]:
    found: set[tuple[str, str, str | None]] = set()
    for doc in DOCUMENTS:
        text = doc.read_text("utf-8")
        for module, names in FROM.findall(text):
            for name in names.split(","):
                name = name.split(" as ")[0].strip()
                if name:
                    found.add((doc.name, module, name))
        for module in PLAIN.findall(text):
            found.add((doc.name, module, None))
    return sorted(found, key=lambda t: (t[0], t[1], t[2] or ""))


DOCUMENTED = _documented()


def test_the_documents_show_imports() -> None:
    # The reader below finds them at all: README and docs/ show at least these modules.
    modules = {module for _doc, module, _name in DOCUMENTED}
    assert {"urdfkit.builder", "urdfkit.sim", "urdfkit.gym"} <= modules, modules


@pytest.mark.parametrize(("doc", "module", "name"), DOCUMENTED,
                         ids=[f"{d}:{m}:{n}" for d, m, n in DOCUMENTED])
def test_documented_import_works(doc: str, module: str, name: str | None) -> None:
    imported = importlib.import_module(module)
    if name is not None:
        assert hasattr(imported, name) or importlib.util.find_spec(f"{module}.{name}"), \
            f"{doc}: from {module} import {name}"


@pytest.mark.parametrize(("module", "name"), [
    ("urdfkit.builder", "Robot"), ("urdfkit.inspect", "joint_table"), ("urdfkit.sim", "Simulation"),
    ("urdfkit.gym", "SimpleDrivingEnv"), ("urdfkit.gym", "ScenarioEnv"), ("urdfkit.sweep", "run"),
    ("urdfkit.cli", "main"), ("urdfkit.cli", "app"),
])
def test_public_api(module: str, name: str) -> None:
    assert callable(getattr(importlib.import_module(module), name))


# `urdfkit CMD rest` on one line of a document (a `\` continuation joined first); the rest
# stops at a comment, a pipe or the end of an inline code span.
COMMAND = re.compile(r"urdfkit (\w+)([^`#\n|]*)")
OPTION = re.compile(r"(?<![\w-])(--?[A-Za-z][\w-]*)")


def _documented_options() -> list[tuple[str, str, str]]:
    found: set[tuple[str, str, str]] = set()
    for doc in DOCUMENTS:
        if doc.name == "robots.md":  # a results log: its lines are what was run then
            continue
        text = re.sub(r"\\\n\s*", " ", doc.read_text("utf-8"))
        for command, rest in COMMAND.findall(text):
            for option in OPTION.findall(rest):
                found.add((doc.name, command, option))
    return sorted(found)


def test_documented_options_exist() -> None:
    import typer.main

    from urdfkit.cli import COMMANDS, app

    group = typer.main.get_command(app)
    known = {name: {o for p in group.commands[name].params
                    for o in (*p.opts, *p.secondary_opts)} | {"--help", "-h"}
             for name in COMMANDS}
    shown = [(doc, command, option) for doc, command, option in _documented_options()
             if command in known]
    # The reader finds them at all: the documents show well over a hundred.
    assert len(shown) > 100, len(shown)
    missing = [f"{doc}: urdfkit {command} {option}" for doc, command, option in shown
               if option not in known[command]]
    assert not missing, missing
