"""The engines urdfkit can run on, by name, each imported only when it is opened.

A third engine is one module of ``engine/`` implementing :class:`~urdfkit.engine.api.Simulator`
(and a module-level ``preload()`` that imports the engine's package) and one entry here.
"""

from __future__ import annotations

import importlib
from typing import TYPE_CHECKING

from urdfkit.core.errors import ParameterError

if TYPE_CHECKING:
    from urdfkit.engine.api import Simulator

#: Engine name to ``module:class``, the module imported on first use.
ENGINES: dict[str, str] = {"pybullet": "urdfkit.engine.pybullet:PyBulletEngine"}


def open_engine(name: str = "pybullet", gui: bool = False) -> Simulator:
    """A new world in engine ``name``: DIRECT, or a window of the engine's own with ``gui``.

    Raises:
        ParameterError: an engine urdfkit does not know.
        EngineError: the engine cannot start (no display for its GUI).
    """
    try:
        where = ENGINES[name]
    except KeyError:
        raise ParameterError(f"`engine`: no engine named {name!r}; engines: "
                             f"{', '.join(ENGINES)}", param="engine") from None
    module, cls = where.split(":")
    engine: Simulator = getattr(importlib.import_module(module), cls)(gui=gui)
    return engine


def preload(name: str = "pybullet") -> None:
    """Import engine ``name``'s package now: a process about to fork workers warms them once.

    Raises:
        ParameterError: an engine urdfkit does not know.
    """
    if name not in ENGINES:
        raise ParameterError(f"`engine`: no engine named {name!r}; engines: "
                             f"{', '.join(ENGINES)}", param="engine")
    importlib.import_module(ENGINES[name].split(":")[0]).preload()
