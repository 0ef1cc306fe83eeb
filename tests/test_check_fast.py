"""``urdfkit check``'s fast start (urdfkit/entry.py) against the typer command line.

The console script reads plain ``check`` command lines itself, without typer; every other
command line goes to typer. Each case here runs both roads as separate processes, the fast
one through ``python -m urdfkit`` (what the console script runs) and the typer one through
``urdfkit.cli.main``, and compares stdout, stderr and the exit code byte for byte.
"""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import pytest

from urdfkit.commands.check_run import parse_argv

ROBOTS = Path(__file__).parent / "fixtures" / "robots"
PACKAGES = Path(__file__).parent / "fixtures" / "packages"
TYPER = "import sys\nfrom urdfkit.cli import main\nsys.argv = ['urdfkit', *sys.argv[1:]]\nmain()\n"
PROBE = ("import sys\nfrom urdfkit.entry import main\nsys.argv = ['urdfkit', *sys.argv[1:]]\n"
         "try:\n    main()\nexcept SystemExit as e:\n    code = e.code\n"
         "print('typer' in sys.modules, file=sys.stderr)\nsys.exit(code)\n")


def _run(argv: list[str], cwd: Path, fast: bool) -> tuple[int, str, str]:
    env = {**os.environ, "URDFKIT_CACHE_DIR": "", "COLUMNS": "100"}
    cmd = [sys.executable, "-m", "urdfkit", *argv] if fast else \
        [sys.executable, "-c", TYPER, *argv]
    p = subprocess.run(cmd, capture_output=True, text=True, cwd=cwd, env=env, timeout=120)
    return p.returncode, p.stdout, p.stderr


CASES = [
    ["check", "panda_like.urdf"],
    ["check", "panda_like.urdf", "--json"],
    ["check", ".", "--json", "--jobs", "1"],
    ["check", ".", "--format", "sarif", "-j", "1"],
    ["check", ".", "--format=junit", "--fail-on", "warning"],
    ["check", "broken_arm.urdf", "--format", "github", "--fail-on=info"],
    ["check", ".", "--select", "U6", "--select", "U2", "--ignore=U607", "--all"],
    ["check", "ur_like.urdf", "quadruped_like.urdf", "--no-cache", "--no-exec"],
    ["check", "missing.urdf"],  # exit 2, one line from the library
    ["check", ".", "--fail-on", "bogus"],  # a bad value the command judges
    ["check", ".", "--format", "yaml"],
    ["check", ".", "--json", "--format", "sarif"],
    ["check", ".", "--select", "Z9"],
    ["check", ".", "--arg", "nocolon"],
    ["check", ".", "-p", "nope=/nonexistent", "--json"],
]


@pytest.mark.parametrize("argv", CASES, ids=lambda a: " ".join(a[1:]))
def test_fast_start_says_what_typer_says(argv: list[str]) -> None:
    assert parse_argv(argv[1:]) is not None, "this case should take the fast road"
    fast = _run(argv, ROBOTS, fast=True)
    slow = _run(argv, ROBOTS, fast=False)
    assert fast == slow


UNPLAIN = [
    ["check", "--help"], ["check", ".", "-h"], ["check"], ["check", ".", "--jobs", "0"],
    ["check", ".", "--jobs", "two"], ["check", ".", "-j4"], ["check", ".", "--json=yes"],
    ["check", ".", "--format", "json", "--format", "sarif"], ["check", ".", "--jsn"],
    ["check", ".", "--select"], ["check", "--", "."], ["check", ".", "--select", "-U6"],
]


@pytest.mark.parametrize("argv", UNPLAIN, ids=lambda a: " ".join(a[1:]) or "bare")
def test_anything_else_is_typers(argv: list[str]) -> None:
    """Help and usage errors come from typer, the same through either entry point."""
    assert parse_argv(argv[1:]) is None
    assert _run(argv, ROBOTS, fast=True) == _run(argv, ROBOTS, fast=False)


def test_the_fast_road_never_imports_typer() -> None:
    env = {**os.environ, "URDFKIT_CACHE_DIR": ""}
    fast = subprocess.run([sys.executable, "-c", PROBE, "check", ".", "--json"],
                          capture_output=True, text=True, cwd=ROBOTS, env=env, timeout=120)
    assert fast.stderr.strip().splitlines()[-1] == "False", fast.stderr
    typer_road = subprocess.run([sys.executable, "-c", PROBE, "check", "--help"],
                                capture_output=True, text=True, cwd=ROBOTS, env=env,
                                timeout=120)
    assert typer_road.stderr.strip().splitlines()[-1] == "True"


def test_parse_reads_each_form() -> None:
    assert parse_argv(["a", "--jobs=3", "-p", "x=y", "--package-path", "d", "-a", "k:=v",
                       "b"]) == {"paths": ["a", "b"], "jobs": 3, "package": ["x=y"],
                                 "package_path": ["d"], "arg": ["k:=v"]}
    assert parse_argv(["a", "--json", "--json"]) is None  # typer decides what twice means
    assert parse_argv(["a", "--jobs", "1٣"]) is None  # not ASCII digits


def test_fast_start_with_packages(tmp_path: Path) -> None:
    argv = ["check", str(PACKAGES), "--package-path", str(PACKAGES), "--json", "-j", "1"]
    assert _run(argv, tmp_path, fast=True) == _run(argv, tmp_path, fast=False)
