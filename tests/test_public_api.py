"""Every import the README and docs/ show works, and so does the public API the layout keeps.

The names are read from the documents themselves, so a page that documents a new import is
tested by adding it, and a move that breaks one fails here.
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
