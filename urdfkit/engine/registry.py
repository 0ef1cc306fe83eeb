"""The engines urdfkit can run on, by name, each imported only when it is opened.

A third engine is one module of ``engine/`` implementing :class:`~urdfkit.engine.api.Simulator`
(its class taking ``gui``, and a module-level ``preload()`` that imports the engine's package),
one entry here and one parameter of tests/test_engine_contract.py.
"""

from __future__ import annotations

import importlib
from typing import TYPE_CHECKING

from urdfkit.core.errors import ParameterError

if TYPE_CHECKING:
    from urdfkit.engine.api import Simulator

#: Engine name to ``module:class``, the module imported on first use.
ENGINES: dict[str, str] = {"pybullet": "urdfkit.engine.pybullet:PyBulletEngine",
                           "mujoco": "urdfkit.engine.mujoco:MuJoCoEngine"}


def open_engine(name: str = "pybullet", gui: bool = False) -> Simulator:
    """A new world in engine ``name``.

    Raises:
        ParameterError: An engine urdfkit does not have (the closest names said), or ``gui``
            where the engine has none.
        MissingDependencyError: Its package is not installed (the extra to install named).
    """
    module, cls = _where(name).split(":")
    engine: Simulator = getattr(importlib.import_module(module), cls)(gui=gui)
    return engine


def check(name: str) -> None:
    """Refuse an engine urdfkit does not have, before anything is opened.

    Raises:
        ParameterError: No engine of that name (the closest names said).
    """
    _where(name)


def preload(name: str = "pybullet") -> None:
    """Import engine ``name``'s package now: a process about to fork workers warms them once.

    Raises:
        ParameterError: An engine urdfkit does not have.
        MissingDependencyError: Its package is not installed.
    """
    importlib.import_module(_where(name).split(":")[0]).preload()


def _where(name: str) -> str:
    if name not in ENGINES:
        from urdfkit.core.suggest import hint

        raise ParameterError(f"`engine`: no engine named {name!r}; engines: "
                             f"{', '.join(ENGINES)}{hint(name, ENGINES)}", param="engine")
    return ENGINES[name]
