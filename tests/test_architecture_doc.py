"""docs/architecture.md names every module of the package, and only modules that exist."""

from __future__ import annotations

import re
from pathlib import Path

import urdfkit

PACKAGE = Path(urdfkit.__file__).parent
#: In the checkout: the tests' own folder's parent, wherever urdfkit is installed.
DOC = Path(__file__).resolve().parent.parent / "docs" / "architecture.md"


def _listed() -> set[str]:
    """The modules the tree block names: ``cli``, ``model.spec``, ``engine.api`` ..."""
    text = DOC.read_text("utf-8")
    block = text[text.index("```\nurdfkit/\n") + 4:]
    block = block[:block.index("```")]
    listed: set[str] = set()
    folder = ""
    for line in block.splitlines()[1:]:
        head = re.match(r"\s{2}(\w+)/\s+floor \d+\s+(.*)", line)
        if head:
            folder, names = head.group(1), head.group(2)
        elif line.startswith("  ") and not line.startswith("   "):  # the top-level modules
            folder, names = "", re.split(r"\s{6,}", line.strip())[0]
            listed.update(n[:-3] for n in names.split() if n.endswith(".py"))
            continue
        else:
            names = line.strip()
        listed.update(f"{folder}.{n}" for n in re.findall(r"[a-z_]\w*", names))
    return listed


def _modules() -> set[str]:
    return {p.relative_to(PACKAGE).with_suffix("").as_posix().replace("/", ".")
            for p in PACKAGE.rglob("*.py")
            if p.name != "__init__.py" and "__pycache__" not in p.parts}


def test_every_module_is_listed_and_every_listed_one_exists() -> None:
    listed, modules = _listed(), _modules()
    assert len(modules) > 100  # the package was read
    assert not modules - listed, f"missing from docs/architecture.md: {sorted(modules - listed)}"
    assert not listed - modules, f"listed but gone: {sorted(listed - modules)}"
