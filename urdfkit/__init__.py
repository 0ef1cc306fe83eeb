"""urdfkit: build, inspect and test-drive URDF robot descriptions with PyBullet.

The command-line tool is ``urdfkit``; the library's entry points live in
:mod:`urdfkit.builder` (the URDF model), :mod:`urdfkit.model.catalog` (templates),
:mod:`urdfkit.inspect` and :mod:`urdfkit.engine.body` (decoded PyBullet tables),
:mod:`urdfkit.draw.tree`
(the kinematic tree) and the simulation modules.
"""

__version__ = "0.1.0"

__all__ = ["__version__"]
