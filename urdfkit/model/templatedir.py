"""Where the built-in xacro templates live (kept tiny: ``drive`` imports it on every run)."""

from __future__ import annotations

from pathlib import Path


def template_dir() -> Path:
    """The folder of the built-in templates.

    Installed, it is the package ``urdfkit.templates``: pyproject.toml puts the top-level
    ``templates/`` folder there, and ``tests/test_packaging.py`` checks the wheel carries it.
    Run from a source checkout (``python -m urdfkit`` in the repository) that package does not
    exist, and the top-level folder beside the package is the same files.
    """
    from importlib.util import find_spec

    # Looked up by name, not imported: a static import type-checks differently in a source
    # checkout (no such module) and beside an installed wheel (a real one).
    spec = find_spec("urdfkit.templates")
    if spec is None or spec.origin is None:
        return Path(__file__).resolve().parents[2] / "templates"
    return Path(spec.origin).parent
