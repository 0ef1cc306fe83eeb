"""The wheel carries the templates: a plain (non-editable) install must find them."""

from __future__ import annotations

import shutil
import subprocess
import sys
import zipfile
from pathlib import Path

ROOT = Path(__file__).parent.parent


def test_wheel_ships_templates_as_package_data(tmp_path: Path) -> None:
    # Built from a copy of what the wheel is made of: a build/ folder left in the checkout
    # would otherwise lend the wheel files its own configuration leaves out.
    source = tmp_path / "src"
    source.mkdir()
    for name in ("pyproject.toml", "README.md", "LICENSE"):
        if (ROOT / name).exists():
            shutil.copy2(ROOT / name, source / name)
    for folder in ("urdfkit", "templates"):
        shutil.copytree(ROOT / folder, source / folder,
                        ignore=shutil.ignore_patterns("__pycache__"))
    out = subprocess.run(
        [sys.executable, "-m", "pip", "wheel", "--no-deps", "-q", "-w", str(tmp_path),
         str(source)],
        capture_output=True, text=True, timeout=300,
    )
    assert out.returncode == 0, out.stderr
    (wheel,) = tmp_path.glob("urdfkit-*.whl")
    names = set(zipfile.ZipFile(wheel).namelist())
    for template in (ROOT / "templates").glob("*.xacro"):
        assert f"urdfkit/templates/{template.name}" in names
    assert "urdfkit/py.typed" in names
    assert "urdfkit/cli.py" in names
    # Every module of every folder: a folder missing from pyproject's packages list would
    # leave a plain install unable to import urdfkit.cli at all.
    package = ROOT / "urdfkit"
    modules = {p.relative_to(ROOT).as_posix() for p in package.rglob("*.py")}
    assert modules <= names, sorted(modules - names)
    # Every command on a plain install: sim (pydantic) and render (Pillow) need no extra;
    # yourdfpy (trimesh, scipy, ...) is a test tool, not a runtime dependency.
    with zipfile.ZipFile(wheel) as zf:
        meta = next(n for n in zf.namelist() if n.endswith(".dist-info/METADATA"))
        requires = [line.split(":", 1)[1].strip() for line in
                    zf.read(meta).decode().splitlines() if line.startswith("Requires-Dist:")]
    core = {r.split(";")[0].split(">")[0].split("<")[0].split("=")[0].strip().lower()
            for r in requires if "extra ==" not in r}
    assert {"pybullet", "numpy", "lxml", "typer", "pydantic", "pillow", "xacro"} <= core
    assert "yourdfpy" not in core and "matplotlib" not in core
