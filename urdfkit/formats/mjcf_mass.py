"""The mass properties the MJCF writer gives each body, and what MuJoCo refuses of them.

:func:`combine` adds the links fused into one body exactly; :class:`Masses` takes each link's
mass properties (the file's, PyBullet's own, or what ``urdfkit fix`` writes where PyBullet
zeroed a tensor and the moving body would be refused), combines a body's, and refuses what
MuJoCo refuses with check's code and the line.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

from urdfkit.core.errors import InputError
from urdfkit.formats.robot import LoadedInertial, LoadedLink, LoadedRobot


@dataclass
class Mass:
    """A body's mass properties: mass, centre of mass and tensor, in the body's frame."""

    mass: float
    com: Any
    tensor: Any


def combine(parts: list[tuple[LoadedInertial, Any]]) -> Mass:
    """Mass properties of rigidly joined links: (inertial, link frame in the body) each.

    Each link's centre and tensor are placed in the body's axes, then joined by
    :func:`urdfkit.model.massprops.combine` (the parallel-axis theorem).
    """
    import numpy as np

    from urdfkit.model.massprops import combine as join

    with np.errstate(all="ignore"):  # huge values overflow: check_mass refuses the result
        placed = []
        for i, t in parts:
            r = t[:3, :3]
            com = r @ np.array(i.com) + t[:3, 3]
            tensor = r @ np.array(i.tensor) @ r.T
            placed.append((i.mass, com.tolist(), tensor.tolist()))
    total = join(placed)
    return Mass(float(total.mass), np.array(total.com), np.array(total.tensor))


class Masses:
    """Each body's mass properties, checked as MuJoCo checks them; see :func:`combine`."""

    def __init__(self, robot: LoadedRobot, inertials: dict[str, LoadedInertial] | None,
                 repairs: dict[str, tuple[LoadedInertial, str, str, str]] | None,
                 inertia_from_shapes: bool, note: Callable[[str, str, int | None], None]
                 ) -> None:
        self.robot = robot
        #: Link mass properties to write instead of the file's, and fix's tensor for each
        #: link PyBullet simulates singular (:class:`urdfkit.formats.mjcf.ExportOptions`).
        self.inertials = inertials
        self.repairs = repairs
        self.inertia_from_shapes = inertia_from_shapes
        self.note = note
        #: The links fused into each body, by body: set by the writer before the first body.
        self.members: dict[str, list[str]] = {}
        #: The links given fix's tensor.
        self.repaired: list[str] = []

    def inertial(self, link: LoadedLink) -> LoadedInertial:
        """The mass properties written for a link: fix's, the options', else the file's."""
        if link.name in self.repaired and self.repairs:
            return self.repairs[link.name][0]
        if self.inertials is not None and link.name in self.inertials:
            return self.inertials[link.name]
        return link.inertial

    def body_mass(self, name: str, links: list[str], where: dict[str, Any],
                  moving: bool) -> Mass:
        """A body's mass properties, from the links fused into it.

        Where PyBullet zeroed a link's tensor (the triangle inequality) and that leaves a
        moving body with a zero principal moment, which MuJoCo refuses, the tensor
        ``urdfkit fix`` writes for the link is written instead: a way through, said per link.
        """
        import numpy as np

        def mass() -> Mass:
            return combine([(self.inertial(self.robot.links[n]), where[n][1]) for n in links])

        m = mass()
        fixable = [n for n in links if n in (self.repairs or {})]
        if not moving or not fixable or not np.isfinite(m.tensor).all() \
                or np.linalg.eigvalsh(m.tensor)[0] > 1e-15:  # mjMINVAL, as check_mass
            return m
        assert self.repairs is not None
        for n in fixable:
            inertial, xml, how, why = self.repairs[n]
            self.repaired.append(n)
            self.note("repaired", f"link {n!r}: PyBullet simulates it with {why}, which "
                      f"leaves the moving body {name!r} without the inertia MuJoCo "
                      f"requires, so written instead: {xml}, {how}. agree lists this link's "
                      "rows as a known difference", inertial.line)
        return mass()

    def check_mass(self, name: str, m: Mass, moving: bool) -> None:
        """Refuse what MuJoCo refuses, with check's code (U602-U604, U608) and the line."""
        import numpy as np

        link = self.robot.links[name]
        line = link.inertial.line or link.line
        if not (math.isfinite(m.mass) and np.isfinite(m.com).all()
                and np.isfinite(m.tensor).all()):
            nan = math.isnan(m.mass) or np.isnan(m.com).any() or np.isnan(m.tensor).any()
            what = ("are not numbers (NaN) as PyBullet loads them: a mass, origin or inertia "
                    "written nan, or infinities that cancel (urdfkit check names it, U401)"
                    if nan else "overflow a double")
            raise InputError(f"the mass properties of link {name!r} (with the links fused into "
                             f"it) {what}; MuJoCo cannot use them",
                             file=self.robot.file, line=line)
        if not moving:
            return
        if m.mass <= 1e-15:  # mjMINVAL: MuJoCo's floor for a moving body's mass
            what = "0" if m.mass <= 0 else f"{m.mass:.3g} kg, under MuJoCo's floor of 1e-15"
            raise InputError(f"U602: link {name!r} moves but has mass {what} (with the links "
                             "fused into it); MuJoCo refuses a massless moving body",
                             file=self.robot.file, line=line)
        with np.errstate(all="ignore"):
            eig = np.linalg.eigvalsh(m.tensor)
        scale = max(abs(eig).max(), 1e-300)
        if not np.isfinite(eig).all() or not math.isfinite(scale):
            raise InputError(f"the inertia of link {name!r} overflows a double; MuJoCo cannot "
                             "use it", file=self.robot.file, line=line)
        a, b, c = sorted(eig)
        if a <= 1e-15:  # mjMINVAL: MuJoCo's floor for a moving body's principal moments
            # the cause check names: a link's own tensor PyBullet zeroed (U604)
            for n in self.members.get(name, [name]) if not self.inertia_from_shapes else ():
                given = self.robot.links[n].inertial
                if given.given and given.mass > 0:
                    self.triangle(n, np.array(given.tensor), given.line)
            raise InputError(f"U608: inertia of link {name!r} (with the links fused into it) "
                             f"has a zero principal moment ({a:.6g}, {b:.6g}, {c:.6g}); "
                             "MuJoCo refuses it for a moving body", file=self.robot.file,
                             line=line)
        if a < -1e-12 * scale:
            raise InputError(f"U603: inertia of link {name!r} is not positive definite (principal "
                             f"moments {a:.6g}, {b:.6g}, {c:.6g}); MuJoCo refuses it",
                             file=self.robot.file, line=line)
        if a + b < c - 1e-9 * scale:
            raise InputError(f"U604: inertia of link {name!r} violates the triangle inequality "
                             f"({a:.6g} + {b:.6g} < {c:.6g}); MuJoCo refuses it",
                             file=self.robot.file, line=line)

    def triangle(self, name: str, tensor: Any, line: int | None) -> None:
        """U604 on a link's own tensor from the file (PyBullet zeroes such a tensor)."""
        import numpy as np

        with np.errstate(all="ignore"):
            eig = np.linalg.eigvalsh(tensor) if np.isfinite(tensor).all() else None
        if eig is None or not np.isfinite(eig).all():
            return
        a, b, c = sorted(eig)
        if a + b < c - 1e-9 * max(abs(c), 1e-300):
            what = (f"U603: inertia of link {name!r} is not positive definite (principal "
                    f"moments {a:.6g}, {b:.6g}, {c:.6g})" if a < 0 else
                    f"U604: inertia of link {name!r} violates the triangle inequality "
                    f"({a:.6g} + {b:.6g} < {c:.6g})")
            # export writes what fix writes where there is one (see body_mass)
            hint = ("`urdfkit fix` can derive one from the shapes" if self.repairs is None
                    else "`urdfkit fix` cannot repair it either: it has no collision solid to "
                    "derive one from, and such a tensor cannot be balanced; write its "
                    "<inertial> by hand")
            raise InputError(f"{what}: PyBullet zeroes it and MuJoCo refuses the body it "
                             f"leaves ({hint})", file=self.robot.file, line=line)
