"""Build urdfkit: pure Python, with ``check``'s hot path compiled by mypyc where it can be.

Everything else is in pyproject.toml. The modules in :data:`COMPILED` are the ones every file
``check`` reads goes through (the one walk, the rules, the findings): compiled, a
``check --no-cache`` run over pybullet_data takes ~25% less time (bench/README.md, issue 30).
Beside them, ``urdfkit/model/_walk.c`` does the one walk itself over libxml2's nodes.

They stay plain Python, with the same behaviour, when:

- the build is editable (``pip install -e``): a compiled module would shadow the source you
  edit;
- ``URDFKIT_PURE=1`` is set;
- mypyc is not there (a build without isolation and without mypy), or the C compiler fails
  (no ``cc``, no Python headers): the build says so on stderr and ships the sources.

A compiled module's ``__file__`` ends in ``.so``; ``bench/run.py`` prints which kind it
measures, and tests/test_build.py fails in CI if the install is not the kind CI asked for.
"""

from __future__ import annotations

import os
import sys

from setuptools import setup
from setuptools.command.build_ext import build_ext

#: The check path, compiled by mypyc. Tests patch none of their functions (a compiled module
#: calls its own functions directly, so a patch would not reach them).
COMPILED = [
    "urdfkit/core/record.py",
    "urdfkit/core/finding.py",
    "urdfkit/model/spec.py",
    "urdfkit/model/index.py",
    "urdfkit/model/xmlio.py",
    "urdfkit/sources/guard.py",
    "urdfkit/sources/meshdata.py",
    "urdfkit/sources/meshstore.py",
    "urdfkit/checks/validate.py",
    "urdfkit/checks/check.py",
]


def _why_pure() -> str | None:
    if os.environ.get("URDFKIT_PURE"):
        return "URDFKIT_PURE is set"
    if any(arg.startswith("editable") or arg == "develop" for arg in sys.argv[1:]):
        return "an editable install"
    try:
        import mypyc.build  # noqa: F401
    except ImportError:
        return "mypyc is not installed in the build environment"
    return None


class OptionalBuildExt(build_ext):
    """Build the compiled modules, or, if the compiler fails, ship the plain sources."""

    def run(self) -> None:
        """Build them; on any failure remove what was built and go on without them."""
        try:
            super().run()
        except Exception as e:  # noqa: BLE001 - any compiler failure: fall back, say why
            for path in self.get_outputs():
                if os.path.exists(path):
                    os.remove(path)
            self.extensions = []
            sys.stderr.write(f"urdfkit: building the compiled check path failed ({e}); "
                             "installing plain Python (check is ~25% slower)\n")


def _walk_extension() -> list:
    """``urdfkit.model._walk``: the one walk of check in C, over lxml's public C API.

    Built against the lxml of the build environment (pyproject.toml's build requirements);
    at run time it refuses to load under another major version of lxml, and index.py then
    walks in Python.
    """
    try:
        import lxml
    except ImportError:
        sys.stderr.write("urdfkit: lxml is not in the build environment; the walk stays "
                         "in Python\n")
        return []
    from setuptools import Extension

    return [Extension("urdfkit.model._walk", ["urdfkit/model/_walk.c"],
                      include_dirs=lxml.get_include(), extra_compile_args=["-O2"])]


def _ext_modules() -> list:
    why = _why_pure()
    if why is not None:
        sys.stderr.write(f"urdfkit: plain Python build ({why})\n")
        return []
    from mypyc.build import mypycify

    try:
        compiled = mypycify(COMPILED, opt_level="3", debug_level="0")
    except BaseException as e:  # noqa: BLE001 - mypyc's own failure (a type error) exits
        sys.stderr.write(f"urdfkit: mypyc could not compile the check path ({e!r}); "
                         "installing plain Python\n")
        return []
    return [*compiled, *_walk_extension()]


setup(ext_modules=_ext_modules(), cmdclass={"build_ext": OptionalBuildExt})
