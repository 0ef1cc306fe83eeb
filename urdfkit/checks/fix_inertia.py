"""Inertia tensors as ``fix`` writes them: balanced, turned into a frame, written as XML.

:func:`balanced` is MuJoCo's ``balanceinertia``; :func:`inertia_in_frame` turns a tensor in
link axes into the ``<inertial>``'s ``rpy`` frame and writes its ``<inertia>``;
:func:`triangle_repair` is U604's repair as :mod:`urdfkit.checks.fix_plan` makes it, which
``urdfkit export`` also writes (:mod:`urdfkit.exchange.bullet`).
"""

from __future__ import annotations

from collections.abc import Sequence

from lxml import etree

from urdfkit.checks.rules_mass import link_solid
from urdfkit.model.spec import attr_vec as _vec
from urdfkit.model.spec import rpy_to_matrix, sym_eigenvalues, transpose
from urdfkit.model.xmlio import fmt_float
from urdfkit.sources.guard import RuleReport


def balanced(tensor: Sequence[Sequence[float]]) -> float | None:
    """MuJoCo's ``balanceinertia``: one principal moment (their mean) for all three.

    None when the triangle inequality holds, or the tensor is not positive definite.
    """
    a, b, c = sym_eigenvalues(tensor)
    if a <= 0 or a + b >= c:
        return None
    return (a + b + c) / 3


def triangle_repair(link: etree._Element, report: RuleReport | None, mass: float,
                    fallback: Sequence[Sequence[float]] | None = None) -> tuple[str, str] | None:
    """The ``<inertia>`` fix writes for a link whose inertia breaks the triangle inequality.

    U604's repair, as :meth:`urdfkit.checks.fix_plan._Plan._inertia` makes it: the tensor of
    the link's collision solid at its mass, in the frame of the inertial's ``<origin rpy>``
    (kept), written with 9 significant digits; for a link without a solid, every principal
    moment set to their mean (MuJoCo's ``balanceinertia``, what ``fix --balance`` writes); for
    a tensor that cannot be balanced either (not positive definite), ``fallback`` when given:
    the tensor (link axes) PyBullet computes from the collision shapes' box without
    URDF_USE_INERTIA_FROM_FILE, which export passes so that no robot PyBullet loads is a dead
    end. Returns the element's XML and how it was made, or None when fix has nothing to write.
    ``urdfkit export`` writes it where PyBullet zeroes such a tensor and MuJoCo would refuse
    the body it leaves.
    """
    if not mass > 0:
        return None
    inertial = link.find("inertial")
    origin = inertial.find("origin") if inertial is not None else None
    frame = _vec(origin, "rpy", 3, (0.0, 0.0, 0.0)) or (0.0, 0.0, 0.0)
    solid = link_solid(link, report)
    if solid is not None:
        return (inertia_in_frame(solid.inertia(mass), frame)[1], "the inertia of its collision "
                f"shapes at its mass {fmt_float(mass, 6)} kg, as `urdfkit fix` writes it")
    from urdfkit.checks.rules_mass import inertia_tensor

    inertia = inertial.find("inertia") if inertial is not None else None
    file_tensor = inertia_tensor(inertia) if inertia is not None else None
    mean = balanced(file_tensor) if file_tensor is not None else None
    if mean is None and fallback is not None:
        return (inertia_in_frame(fallback, frame)[1], "the inertia PyBullet computes from the "
                "box around its collision shapes when URDF_USE_INERTIA_FROM_FILE is off (fix "
                "has no solid to derive one from, and the file's tensor cannot be balanced)")
    if mean is None:
        return None
    return (inertia_xml(iso(mean)), "every principal moment set to their mean (MuJoCo's "
            "balanceinertia; it has no collision solid), as `urdfkit fix --balance` writes it")


def inertia_in_frame(tensor: Sequence[Sequence[float]], frame: Sequence[float]
              ) -> tuple[tuple[tuple[float, float, float], ...], str]:
    """A tensor in link axes, turned into the inertial's ``rpy`` frame, and its ``<inertia>``."""
    local = _rotate_tensor(transpose(rpy_to_matrix(frame)), tensor)
    return local, inertia_xml(local)


def iso(moment: float) -> tuple[tuple[float, float, float], ...]:
    """The tensor with ``moment`` about every axis."""
    return ((moment, 0.0, 0.0), (0.0, moment, 0.0), (0.0, 0.0, moment))


def _rotate_tensor(rot: Sequence[Sequence[float]], t: Sequence[Sequence[float]]
                   ) -> tuple[tuple[float, float, float], ...]:
    """``rot @ t @ rot.T``."""
    rt = [[sum(rot[i][k] * t[k][j] for k in range(3)) for j in range(3)] for i in range(3)]
    out = [[sum(rt[i][k] * rot[j][k] for k in range(3)) for j in range(3)] for i in range(3)]
    return tuple((r[0], r[1], r[2]) for r in out)


def inertia_xml(t: Sequence[Sequence[float]]) -> str:
    """``<inertia>`` with 9 significant digits.

    A component at most 1e-12 times the largest diagonal one is written 0.
    """

    def f(x: float) -> str:
        return fmt_float(x, 9) if abs(x) > 1e-12 * max(abs(t[0][0]), abs(t[1][1]),
                                                        abs(t[2][2]), 1e-300) else "0"

    return (f'<inertia ixx="{f(t[0][0])}" ixy="{f(t[0][1])}" ixz="{f(t[0][2])}" '
            f'iyy="{f(t[1][1])}" iyz="{f(t[1][2])}" izz="{f(t[2][2])}"/>')
