"""The engines urdfkit can run on, by name: one module each, imported when opened.

Each module named here has ``connect(gui=False)``, which returns a new
:class:`urdfkit.engine.api.Simulator`. A third engine is one module, one entry here and one
parameter of tests/test_engine_contract.py.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from urdfkit.engine.api import Simulator

#: Engine name -> the module that implements it.
ENGINES: dict[str, str] = {
    "mujoco": "urdfkit.engine.mujoco",
}


def open_engine(name: str, gui: bool = False) -> Simulator:
    """A new world on the engine ``name``.

    Raises:
        ParameterError: An engine urdfkit does not have (the closest names said).
        MissingDependencyError: Its package is not installed (the extra to install named).
    """
    import importlib

    from urdfkit.core.errors import ParameterError

    if name not in ENGINES:
        from urdfkit.core.suggest import hint

        raise ParameterError(f"`engine` {name!r} is not one of {', '.join(sorted(ENGINES))}"
                             f"{hint(name, ENGINES)}", param="engine")
    module = importlib.import_module(ENGINES[name])
    engine: Simulator = module.connect(gui=gui)
    return engine
