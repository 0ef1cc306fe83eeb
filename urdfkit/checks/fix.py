"""``urdfkit fix``: repair what ``check`` finds and a machine can repair, and touch nothing else.

The rules of :mod:`urdfkit.checks.validate` decide what is wrong (one road: ``fix`` keeps no rules
of
its own); this module decides the repair, element by element:

- **Inertia.** Where it is missing (U606, U609, U610), impossible (U603 not positive definite,
  U604 triangle inequality), singular (U608) or far from the shapes (U605), the tensor is
  derived from the link's collision solid (:func:`urdfkit.checks.rules_mass.link_solid`:
  primitives in closed form, meshes integrated) at the link's mass, and written in the
  ``<inertial>``'s own frame, which is kept. A link with no ``<inertial>`` gets the mass of
  its solid at ``density`` (water, 1000 kg/m^3, unless told). ``balance=True`` keeps the
  file's values where it can: a triangle-inequality violation is balanced as MuJoCo's
  ``balanceinertia`` does (every principal moment set to their mean, the trace kept), and
  U605/U608 are left.
- **Massless moving links** (U602) get 1 g and 1e-6 kg m^2 about each axis (or their solid's
  inertia at 1 g): enough for the solver, too little to change the robot's dynamics.
- **Materials** used but never defined (U706) are defined at the top, white: the colour
  PyBullet draws for them today, so nothing changes on screen until the user picks one.
- **``package:///path``** (U708, which ROS tools refuse) becomes ``package://NAME/path`` when
  the file lies in a folder with a ``package.xml``, else a path relative to the URDF.
- **Gazebo contacts** (U803), only when asked (``gazebo_contacts=True``): a link's
  ``<gazebo>`` mu1/mu2 and kp/kd become its ``<contact>`` lateral_friction, stiffness and
  damping (:mod:`urdfkit.model.gazebo` says what maps and what cannot); values the link's
  ``<contact>`` already has are kept.

Edits are spliced into the original text: comments, element order, indentation, quotes and
number formatting elsewhere stay byte for byte. The result is parsed again and compared,
element by element, with the same edits made on the parsed tree; a mismatch is a bug in
urdfkit, raised rather than written. Joints are never edited.

This module is the road: the file read and checked, the repairs planned, the result
re-checked. The repairs themselves are :mod:`urdfkit.checks.fix_plan`'s, written through
:mod:`urdfkit.checks.fix_splice` with the tensors of :mod:`urdfkit.checks.fix_inertia`; what
fix returns is :mod:`urdfkit.checks.fix_result`'s.
"""

from __future__ import annotations

import math
import os
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path

from lxml import etree

from urdfkit.checks.fix_inertia import balanced, triangle_repair
from urdfkit.checks.fix_plan import INERTIA_ORDER, _Plan
from urdfkit.checks.fix_result import FixResult, Repair
from urdfkit.checks.rules_mass import Solid
from urdfkit.checks.validate import ALL_RULES
from urdfkit.core.errors import InputError, ParameterError
from urdfkit.model.spec import attr_float as _num
from urdfkit.model.spec import default_mass
from urdfkit.model.xmlio import parse_xml, read_bytes
from urdfkit.sources.guard import RuleReport, refuse_oversized

#: Density (kg/m^3) that gives a link with no ``<inertial>`` its mass: water.
DEFAULT_DENSITY = 1000.0
#: The codes ``fix`` repairs.
FIXABLE = ("U601", "U602", "U603", "U604", "U605", "U606", "U608", "U609", "U610", "U706", "U708",
           "U803")


def fix_file(path: str | Path, *, balance: bool = False, density: float | None = None,
             packages: Mapping[str, Path] | None = None,
             select: Sequence[str] = (), gazebo_contacts: bool = False,
             output: str | Path | None = None, buffer: bytes | None = None) -> FixResult:
    """Repair a URDF file's fixable findings; return the new text (nothing is written).

    Args:
        path: The URDF (xacro is refused: its inertia comes from macros; fix the macro or
            the expanded file).
        balance: Keep the file's inertia values where possible: balance triangle-inequality
            violations (MuJoCo's ``balanceinertia``) instead of deriving from the shapes, and
            leave U605 and U608.
        density: kg/m^3, to give a link that has no mass (no ``<inertial>``, or mass <= 0)
            the mass of its collision shapes. None (the default): fix invents no mass; such
            links are left and said (a ROS ``base_link`` whose robot's mass sits in a fixed
            ``inertial_link`` must stay massless).
        packages: ``package://`` mappings, to find meshes.
        select: Only these codes (or prefixes); empty for all of :data:`FIXABLE`.
        gazebo_contacts: Carry Gazebo's contact parameters over to ``<contact>`` (U803);
            without it they are left as they are, and not counted as left.
        output: Where the result will be written. In another folder than ``path``, each
            relative mesh and texture path is rewritten to name the same file from there
            (:func:`urdfkit.sources.uris.rebased`), so the written file loads as the
            original does; only those ``filename`` attributes change.
        buffer: The file's bytes as an editor holds them (unsaved): repaired as if the file
            held them.

    Raises:
        InputError: the file cannot be read or parsed, or is xacro.
        ParameterError: a bad ``density``.
    """
    display, source, data, text = _read_source(path, density, buffer)
    root = parse_xml(data, display).getroot()
    report = RuleReport(display, source.absolute().parent, packages)
    for rule in ALL_RULES:
        rule(root, report)
    run = _Fixing(data, text, display, root, report, balance, density, packages,
                  tuple(c.upper() for c in select), gazebo_contacts).run
    plan, fixed = run({})
    # A fix counts only if check then passes its rule: re-check the repaired links, and redo
    # without those still flagged (a mass of 1e308 has no inertia a float can hold).
    still = _unfixed(fixed, display, source, packages, plan.repairs)
    # The paths are moved last: the re-check above reads the meshes from the file's folder.
    folder = _elsewhere(source, output)
    if still or folder is not None:
        plan, fixed = run(still, folder)
    others = [Repair(f.code, f.line, f.message) for f in report.findings
              if f.level == "error" and f.code not in FIXABLE]
    from urdfkit.model.spec import FILE_TAGS

    relative = sorted({fn for el in root.iter(*FILE_TAGS) if (fn := (el.get("filename") or "")
                       .strip()) and "://" not in fn and not Path(fn).is_absolute()})
    new_root = parse_xml(fixed, display).getroot() if fixed != data else root
    return FixResult(display, data, fixed, mass_before=_total_mass(root),
                     mass_after=_total_mass(new_root),
                     loaded_before=_total_mass(root, loaded=True),
                     loaded_after=_total_mass(new_root, loaded=True),
                     repairs=sorted(plan.repairs, key=_by_line),
                     left=sorted(plan.left, key=_by_line), other_errors=others,
                     relative_paths=relative, moved_paths=plan.moved)


def _elsewhere(source: Path, output: str | Path | None) -> Path | None:
    """The folder ``output`` is in, when it is not ``source``'s; else None."""
    if output is None:
        return None
    folder = Path(output).expanduser().absolute().parent
    same = os.path.realpath(folder) == os.path.realpath(source.absolute().parent)
    return None if same else folder


def _read_source(path: str | Path, density: float | None, given: bytes | None = None
                 ) -> tuple[str, Path, bytes, str]:
    """The file's name as shown, its path, bytes and text; refusals before any work."""
    from urdfkit.sources.resolve import locate

    display = str(path)
    # a bare name is found in pybullet_data, as every command finds it; an editor's buffer
    # names where it is, saved or not
    source = locate(path) if given is None else Path(path)
    if density is not None and not (math.isfinite(density) and density > 0):
        raise ParameterError(f"`density` must be a positive number of kg/m^3, got {density!r}",
                             param="density")
    if source.suffix == ".xacro":
        raise InputError("fix edits URDF files, and a xacro file's values come from its macros "
                         "and arguments: fix the macro, or expand the file first (urdfkit build "
                         "or xacro) and fix that", file=display)
    data = read_bytes(source) if given is None else given
    refuse_oversized(data, display)
    try:
        text = data.decode("utf-8")
    except UnicodeDecodeError as e:
        raise InputError(f"not UTF-8 text (byte {e.start}); fix rewrites only UTF-8 files",
                         file=display) from None
    return display, source, data, text


@dataclass
class _Fixing:
    """One file's findings, and how to plan their repairs (:meth:`run`, maybe twice)."""

    data: bytes
    text: str
    display: str
    root: etree._Element
    report: RuleReport
    balance: bool
    density: float | None
    packages: Mapping[str, Path] | None
    wanted: tuple[str, ...]
    gazebo_contacts: bool = False

    def run(self, skip: Mapping[str, str], folder: Path | None = None) -> tuple[_Plan, bytes]:
        """Plan every repair (but those of the links in ``skip``, said why) and apply them.

        ``folder``: where the result goes, when not beside the file; relative paths are
        rewritten for it.
        """
        # A fresh tree each time (the plan edits the tree it is given); the findings' elements
        # are the pristine ``root``'s, mapped to it by position.
        tree = parse_xml(self.data, self.display).getroot()
        plan = _Plan(self.text, tree, self.display, self.balance, self.density, self.report,
                     folder)
        for el, codes in self._targets(_same_elements(self.root, tree)).items():
            name = el.get("name", "")
            if el.tag == "link" and name in skip:
                plan.left.append(Repair(codes[0][0], codes[0][1], f"link {name!r}: {skip[name]}"))
            elif el.tag == "link" and codes[0][0] == "U803":
                plan.carry_contacts(el, codes[0][1])
            elif el.tag == "link":
                plan.fix_link(el, codes)
            elif codes[0][0] == "U706":
                plan.define_material(el, codes[0][1])
            else:
                plan.normalise_uri(el, codes[0][1], self.packages)
        if folder is not None:
            plan.move_paths()
        return plan, plan.finish()

    def _targets(self, elements: Mapping[etree._Element, etree._Element]
                 ) -> dict[etree._Element, list[tuple[str, int | None]]]:
        """The elements to repair (in the fresh tree), each with its codes and lines."""
        found: dict[etree._Element, list[tuple[str, int | None]]] = {}
        for f, el in zip(self.report.findings, self.report.elements, strict=True):
            if f.code not in FIXABLE or el is None:
                continue
            if self.wanted and not any(f.code.startswith(w) for w in self.wanted):
                continue
            if f.code == "U803":
                if self.gazebo_contacts:  # the link the <gazebo> block refers to
                    link = _link_named(self.root, el.get("reference") or _parent_name(el))
                    if link is not None:
                        found.setdefault(elements[link], []).insert(0, (f.code, f.line))
                continue
            target = el if f.code in ("U706", "U708") else _link_of(el)
            if target is not None:
                found.setdefault(elements[target], []).append((f.code, f.line))
        return found


def _total_mass(root: etree._Element, loaded: bool = False) -> float:
    """The sum of a robot's finite link masses, as written.

    ``loaded``: as PyBullet loads it, which gives a link with no ``<inertial>`` 1 kg (0 if it
    is named ``world``).
    """
    total = 0.0
    for link in root.iterchildren("link"):
        if loaded and link.find("inertial") is None:
            total += default_mass(link.get("name"))
            continue
        mass = _num(link.find("inertial/mass"), "value")
        if mass is not None and math.isfinite(mass):
            total += mass
    return total if math.isfinite(total) else math.inf


def _same_elements(a: etree._Element, b: etree._Element) -> dict[etree._Element, etree._Element]:
    """Each element of tree ``a`` mapped to the one at the same place in ``b`` (a re-parse)."""
    return dict(zip(a.iter(), b.iter(), strict=True))


def _unfixed(fixed: bytes, display: str, source: Path, packages: Mapping[str, Path] | None,
             repairs: Sequence[Repair]) -> dict[str, str]:
    """Links whose inertia repair ``check`` would still flag, each with the finding."""
    subjects = {r.subject for r in repairs if r.subject is not None and r.code in INERTIA_ORDER}
    if not subjects:
        return {}
    report = RuleReport(display, source.absolute().parent, packages)
    tree = parse_xml(fixed, display).getroot()
    for rule in ALL_RULES:
        rule(tree, report)
    out: dict[str, str] = {}
    for f, el in zip(report.findings, report.elements, strict=True):
        link = _link_of(el) if el is not None else None
        name = link.get("name", "") if link is not None else None
        if name in subjects and f.code in INERTIA_ORDER and name not in out:
            out[name] = (f"not fixed: the derived inertial still fails {f.code} "
                         f"({f.message}); set a mass a float can carry, then run fix again")
    return out


def _link_named(root: etree._Element, name: str | None) -> etree._Element | None:
    return next((link for link in root.iterchildren("link") if link.get("name") == name), None)


def _parent_name(el: etree._Element) -> str | None:
    parent = el.getparent()
    return parent.get("name") if parent is not None else None


def _by_line(x: Repair) -> tuple[int, str]:
    return (x.line or 0, x.code)


def _link_of(el: etree._Element) -> etree._Element | None:
    if el.tag == "link":
        return el
    return next((a for a in el.iterancestors("link")), None)


__all__ = ["DEFAULT_DENSITY", "FIXABLE", "FixResult", "Repair", "Solid", "balanced", "fix_file",
           "triangle_repair"]
