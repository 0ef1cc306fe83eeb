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
"""

from __future__ import annotations

import difflib
import math
import os
import re
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from lxml import etree

from urdfkit.checks.rules_mass import STUB_SIZE, Solid, link_solid
from urdfkit.checks.validate import ALL_RULES
from urdfkit.core.errors import InputError, ParameterError
from urdfkit.model.spec import attr_float as _num
from urdfkit.model.spec import attr_vec as _vec
from urdfkit.model.spec import default_mass, rpy_to_matrix, sym_eigenvalues, transpose
from urdfkit.model.xmlio import fmt_float, fmt_vec, parse_xml, read_bytes, start_tags
from urdfkit.sources.guard import RuleReport, refuse_oversized

#: Density (kg/m^3) that gives a link with no ``<inertial>`` its mass: water.
DEFAULT_DENSITY = 1000.0
#: Mass (kg) and principal moment (kg m^2) for a massless link that moves.
SMALL_MASS = 1e-3
SMALL_INERTIA = 1e-6
#: What PyBullet draws a visual with an undefined material in.
UNDEFINED_RGBA = "1 1 1 1"
#: The codes ``fix`` repairs.
FIXABLE = ("U601", "U602", "U603", "U604", "U605", "U606", "U608", "U609", "U610", "U706", "U708",
           "U803")
#: The inertia codes, most serious first: a link gets one inertial repair, for its worst.
_INERTIA_ORDER = ("U606", "U602", "U601", "U609", "U610", "U603", "U604", "U605", "U608")


@dataclass
class Repair:
    """One fix made, or one finding left as it was (with why).

    Attributes:
        code: The rule code of the finding.
        line: Its line in the original file.
        message: What was done, or why nothing was.
    """

    code: str
    line: int | None
    message: str
    #: The link a repair is to (for the re-check), not in the JSON.
    subject: str | None = field(default=None, compare=False)

    def to_dict(self) -> dict[str, Any]:
        """The JSON form."""
        return {"code": self.code, "line": self.line, "message": self.message}


@dataclass
class FixResult:
    """The repaired text of one file, and what was repaired.

    Attributes:
        file: The file as the user named it.
        original: Its bytes.
        fixed: The repaired bytes (equal to ``original`` when nothing was fixed).
        repairs: The fixes made, in file order.
        left: Findings of fixable codes that were left, each with the reason.
        other_errors: Error findings ``fix`` does not repair (a zero axis, a missing limit):
            ``check`` explains them.
        relative_paths: Mesh and texture paths relative to the file's folder: a copy
            written elsewhere no longer finds them as written.
        moved_paths: ``(old, new)`` of each ``filename`` rewritten for the folder the result
            is written to (``output``): only those attributes change.
    """

    file: str
    original: bytes
    fixed: bytes
    #: The file's total mass (the sum of its finite ``<mass>`` values), before and after.
    mass_before: float = 0.0
    mass_after: float = 0.0
    #: The total mass PyBullet loads, before and after: the file's plus 1 kg for every link
    #: without ``<inertial>`` but ``world`` (a frame given mass 0 loses that phantom kilogram).
    loaded_before: float = 0.0
    loaded_after: float = 0.0
    repairs: list[Repair] = field(default_factory=list)
    left: list[Repair] = field(default_factory=list)
    other_errors: list[Repair] = field(default_factory=list)
    relative_paths: list[str] = field(default_factory=list)
    moved_paths: list[tuple[str, str]] = field(default_factory=list)

    @property
    def changed(self) -> bool:
        """Whether anything was fixed."""
        return self.fixed != self.original

    def diff(self, new_name: str | None = None) -> str:
        """A unified diff from the original to the fixed text."""
        a = self.original.decode("utf-8", "replace").splitlines(keepends=True)
        b = self.fixed.decode("utf-8", "replace").splitlines(keepends=True)
        # git's a/ and b/ prefixes, before a relative path: an absolute one keeps one slash
        old, new = self.file, new_name or self.file
        return "".join(difflib.unified_diff(a, b, f"a/{old.lstrip('/')}",
                                            f"b/{new.lstrip('/')}"))

    def to_dict(self) -> dict[str, Any]:
        """The ``--json`` form (docs/fix.md)."""
        return {"file": self.file, "changed": self.changed,
                "mass": {"before": self.mass_before, "after": self.mass_after,
                         "loaded_before": self.loaded_before,
                         "loaded_after": self.loaded_after},
                "fixes": [x.to_dict() for x in self.repairs],
                "left": [x.to_dict() for x in self.left],
                "other_errors": [x.to_dict() for x in self.other_errors],
                "moved_paths": [{"from": a, "to": b} for a, b in self.moved_paths]}


def fix_file(path: str | Path, *, balance: bool = False, density: float | None = None,
             packages: Mapping[str, Path] | None = None,
             select: Sequence[str] = (), gazebo_contacts: bool = False,
             output: str | Path | None = None) -> FixResult:
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

    Raises:
        InputError: the file cannot be read or parsed, or is xacro.
        ParameterError: a bad ``density``.
    """
    display, source, data, text = _read_source(path, density)
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


def _read_source(path: str | Path, density: float | None) -> tuple[str, Path, bytes, str]:
    """The file's name as shown, its path, bytes and text; refusals before any work."""
    from urdfkit.sources.resolve import locate

    display = str(path)
    source = locate(path)  # a bare name is found in pybullet_data, as every command finds it
    if density is not None and not (math.isfinite(density) and density > 0):
        raise ParameterError(f"`density` must be a positive number of kg/m^3, got {density!r}",
                             param="density")
    if source.suffix == ".xacro":
        raise InputError("fix edits URDF files, and a xacro file's values come from its macros "
                         "and arguments: fix the macro, or expand the file first (urdfkit build "
                         "or xacro) and fix that", file=display)
    data = read_bytes(source)
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
    subjects = {r.subject for r in repairs if r.subject is not None and r.code in _INERTIA_ORDER}
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
        if name in subjects and f.code in _INERTIA_ORDER and name not in out:
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


def balanced(tensor: Sequence[Sequence[float]]) -> float | None:
    """MuJoCo's ``balanceinertia``: one principal moment (their mean) for all three.

    None when the triangle inequality holds, or the tensor is not positive definite.
    """
    a, b, c = sym_eigenvalues(tensor)
    if a <= 0 or a + b >= c:
        return None
    return (a + b + c) / 3


#: What may follow an element's start tag up to its end tag: end tags, start tags (``<``
#: then a name), and comments, CDATA and processing instructions, whose ``<`` start nothing.
_TOKEN = re.compile(r"<!--.*?-->|<!\[CDATA\[.*?\]\]>|<\?.*?\?>|</[^>]*>|<(?=[^!?/])", re.DOTALL)



#: Why a link's inertia was left: nothing to derive it from.
_NO_SOLID = ("no collision solid to derive inertia from (no <collision>, a capsule, plane or "
             "SDF, or a mesh that is unreadable or not closed); write <inertial> by hand")
#: Why a link's inertia was derived, by the code that found it wrong.
_WHY = {"U609": "had no <inertia>", "U610": "had an incomplete <inertia>",
        "U603": "had an inertia that is not positive definite",
        "U604": "had an inertia that violates the triangle inequality",
        "U605": "had an inertia far from what its shapes imply",
        "U608": "had a singular inertia"}


class _LinkJob:
    """One link to repair: its first code by :data:`_INERTIA_ORDER`, and what it holds."""

    def __init__(self, link: etree._Element, code: str, line: int | None,
                 solid: Solid | None) -> None:
        self.link, self.code, self.line, self.solid = link, code, line, solid
        self.name = link.get("name", "")
        self.inertial = link.find("inertial")
        mass_el = self.inertial.find("mass") if self.inertial is not None else None
        self.mass = _num(mass_el, "value")
        self.origin = self.inertial.find("origin") if self.inertial is not None else None
        self.frame = _vec(self.origin, "rpy", 3, (0.0, 0.0, 0.0)) or (0.0, 0.0, 0.0)

    def skip(self, why: str) -> Repair:
        """The repair left undone, and why."""
        return Repair(self.code, self.line, f"link {self.name!r}: {why}")


class _Plan:
    """The edits to one file: spliced into its text and made on its tree, side by side."""

    def __init__(self, text: str, root: etree._Element, file: str, balance: bool,
                 density: float | None, report: RuleReport, folder: Path | None = None):
        self.text = text
        #: Where the result goes, when not beside the file (relative paths are for it).
        self.folder = folder
        #: ``(old, new)`` of each filename rewritten for ``folder``.
        self.moved: list[tuple[str, str]] = []
        self.renamed: set[etree._Element] = set()
        self.root = root
        self.file = file
        self.balance = balance
        self.density = density
        self.report = report
        self.edits: list[tuple[int, int, str]] = []
        self.repairs: list[Repair] = []
        self.left: list[Repair] = []
        self.defined: set[str] = set()
        starts = [0]
        starts += [m.end() for m in re.finditer("\n", text)]
        self.line_starts = starts
        # Every element's start tag by its path: exact past line 65,535 (where lxml's
        # sourceline stops), for prefixed tags, and with tags quoted in comments.
        # Keyed by the element itself (the map keeps each proxy alive, so lxml hands back the
        # same one): an element a repair inserted has no start tag in the text, and is skipped.
        elements = (el for el in root.iter() if isinstance(el.tag, str))
        self.tag_at: dict[etree._Element, int] = dict(
            zip(elements, start_tags(text), strict=False))

    # ---- repairs

    def carry_contacts(self, link: etree._Element, line: int | None) -> None:
        """U803: write the link's Gazebo contact parameters as PyBullet's ``<contact>``."""
        from urdfkit.model.gazebo import gazebo_contacts

        name = link.get("name", "")
        gz = gazebo_contacts(self.root).get(name)
        if gz is None:  # pragma: no cover - the rule found them in this tree
            return
        contact = link.find("contact")
        have = {c.tag for c in contact} if contact is not None else set()
        new = {k: v for k, v in gz.pybullet().items() if k not in have}
        kept = sorted(set(gz.pybullet()) - set(new))
        if not new:
            self.left.append(Repair("U803", line, f"link {name!r}: its <contact> already sets "
                                    f"{', '.join(kept)}; left as written" if kept else
                                    f"link {name!r}: Gazebo's contact is not carried: "
                                    + "; ".join(f"{k} {fmt_float(gz.given()[k])} is {why}"
                                                for k, why in gz.refused.items())))
            return
        xml = "".join(f'<{k} value="{fmt_float(v)}"/>' for k, v in new.items())
        if contact is None:
            self._insert_last_child(link, f"<contact>{xml}</contact>")
            contact = etree.SubElement(link, "contact")
        else:
            self._insert_last_child(contact, xml)
        for k, v in new.items():
            etree.SubElement(contact, k, value=fmt_float(v))
        said = ", ".join(f"{k} {fmt_float(v)}" for k, v in new.items())
        mu1, mu2 = (None if "mu1" in gz.refused else gz.mu1,
                    None if "mu2" in gz.refused else gz.mu2)
        source = [] if "lateral_friction" not in new else [
            "lateral_friction from " + (
                "the larger of mu1 and mu2 (the other is 0, which would leave no grip)"
                if gz.grip_only_one_way else "the smaller of mu1 and mu2"
                if mu1 is not None and mu2 is not None and mu1 != mu2
                else "mu1" if mu1 is not None else "mu2")]
        if "stiffness" in new:
            source.append("stiffness and damping from kp and kd")
        refused = [f"{k} {fmt_float(gz.given()[k])} ({why})" for k, why in gz.refused.items()]
        self.repairs.append(Repair(
            "U803", line, f"link {name!r}: wrote Gazebo's contact into <contact>: {said} "
            f"({', '.join(source)})"
            + (f"; kept its own {', '.join(kept)}" if kept else "")
            + (f"; not carried: {', '.join(gz.not_carried)}" if gz.not_carried else "")
            + (f"; refused: {'; '.join(refused)}" if refused else "")))

    def fix_link(self, link: etree._Element, codes: list[tuple[str, int | None]]) -> None:
        before = len(self.repairs)
        try:
            self._fix_link(link, codes)
        finally:
            for r in self.repairs[before:]:
                r.subject = link.get("name", "")

    def _fix_link(self, link: etree._Element, codes: list[tuple[str, int | None]]) -> None:
        by_code = dict(codes)
        code = next(c for c in _INERTIA_ORDER if c in by_code)
        job = _LinkJob(link, code, by_code[code], link_solid(link, self.report))
        if code == "U606" and job.solid is None and self._fixed_leaf(link):
            self._massless_frame(job)
        elif code == "U602":
            self._small_mass(job)
        elif job.solid is None and not (self.balance and code == "U604"):
            self.left.append(job.skip(_NO_SOLID))
        elif code in ("U606", "U601"):
            assert job.solid is not None
            self._missing_mass(job, job.solid)
        else:  # --balance balances a U604 tensor without a solid: it needs none
            self._inertia(job, job.solid)

    def _massless_frame(self, job: _LinkJob) -> None:
        """U606 on a frame: mass 0, so that PyBullet does not add 1 kg."""
        self._insert_first_child(job.link, [
            '<inertial><mass value="0"/><inertia ixx="0" ixy="0" ixz="0" iyy="0" iyz="0" '
            'izz="0"/></inertial>'])
        _prepend(job.link, etree.fromstring(
            '<inertial><mass value="0"/><inertia ixx="0" ixy="0" ixz="0" iyy="0" iyz="0" '
            'izz="0"/></inertial>'))
        self.repairs.append(Repair(job.code, job.line, f"link {job.name!r} is a frame (no shapes, "
                                   "fixed to its parent, only frames below it): gave it "
                                   "mass 0, where PyBullet would add 1 kg"))

    def _small_mass(self, job: _LinkJob) -> None:
        """U602: a moving link without mass gets a small one, with its shapes' inertia."""
        solid = job.solid
        tensor = solid.inertia(SMALL_MASS) if solid else _iso(SMALL_INERTIA)
        self._write_inertial(job.link, SMALL_MASS, solid.com if solid and job.inertial is None
                             else None, tensor, job.frame, keep_mass=False)
        given = "the inertia of its shapes at that mass" if solid else "inertia 1e-06"
        self.repairs.append(Repair(job.code, job.line, f"link {job.name!r} moves but had no "
                                   f"mass: gave it {fmt_float(SMALL_MASS)} kg and {given}"))

    def _missing_mass(self, job: _LinkJob, solid: Solid) -> None:
        """U606 or U601: the mass of the shapes at ``--density``, or said why not."""
        code = job.code
        root = job.name not in {c.get("link") for c in self.root.iter("child")}
        if solid.size < STUB_SIZE:
            self.left.append(job.skip(
                "its collision shapes are stubs (under 1 cm): no mass to derive from them; "
                "write <inertial> by hand" + ("" if root else " (mass 0 for a frame)")))
            return
        if self.density is None:
            advice = ("it is the root link: mass 0 would make PyBullet fix the robot in place, "
                      "so give it its real <inertial>" if root else
                      "give it its real <inertial> (mass 0 if it is a frame)")
            self.left.append(job.skip(
                f"{'no <inertial>' if code == 'U606' else 'no valid mass'} and fix invents no "
                f"mass: {advice}, or pass --density to give it the mass of its collision "
                "shapes at that density"))
            return
        new_mass = self.density * solid.volume
        self._write_inertial(job.link, new_mass, solid.com if job.inertial is None or
                             job.origin is None else None, solid.inertia(new_mass), job.frame,
                             keep_mass=False)
        what = "had no <inertial>" if code == "U606" else "had no valid mass"
        self.repairs.append(Repair(code, job.line, f"link {job.name!r} {what}: "
                                   f"{fmt_float(new_mass, 4)} kg ({fmt_float(solid.volume, 4)}"
                                   f" m^3 at {fmt_float(self.density)} kg/m^3) and the "
                                   "inertia of its collision shapes"))

    def _inertia(self, job: _LinkJob, solid: Solid | None) -> None:
        """U603-U605, U608-U610: the inertia derived from the shapes (or balanced)."""
        code, mass = job.code, job.mass
        if mass is None or mass <= 0:
            self.left.append(job.skip(
                "mass 0: no inertia to derive (a frame); give it a mass if it moves"))
            return
        inertia = job.inertial.find("inertia") if job.inertial is not None else None
        if self.balance and code in ("U605", "U608"):
            self.left.append(job.skip(f"{code} left as it is: --balance keeps the file's values"))
            return
        if self.balance and code == "U604" and inertia is not None:
            from urdfkit.checks.rules_mass import inertia_tensor

            file_tensor = inertia_tensor(inertia)
            mean = balanced(file_tensor) if file_tensor is not None else None
            if mean is not None:
                self._replace_inertia(inertia, _iso(mean))
                self.repairs.append(Repair(code, job.line, f"link {job.name!r}: balanced its "
                                           "inertia as MuJoCo's balanceinertia does (every "
                                           "principal moment set to their mean, "
                                           f"{fmt_float(mean, 4)})"))
                return
        if solid is None:
            self.left.append(job.skip(_NO_SOLID))
            return
        if code == "U605" and solid.size < STUB_SIZE:
            self.left.append(job.skip(
                "its collision shapes are stubs (under 1 cm), nothing to derive inertia from"))
            return
        self._write_inertial(job.link, mass, None, solid.inertia(mass), job.frame,
                             keep_mass=True)
        self.repairs.append(Repair(code, job.line, f"link {job.name!r} {_WHY[code]}: derived it "
                                   f"from its collision shapes at its mass {fmt_float(mass, 6)} "
                                   "kg"))

    def _fixed_leaf(self, link: etree._Element) -> bool:
        """Whether ``link`` is a frame (a ``tool0``, a lidar mount with its optical frame).

        A frame hangs from a fixed joint, has no shapes, and has only frames fixed below it.
        """
        by_name = {x.get("name"): x for x in self.root.iterchildren("link")}
        below: dict[str | None, list[tuple[str | None, bool]]] = {}
        parent_fixed: dict[str | None, bool] = {}
        for j in self.root.iterchildren("joint"):
            parent, child = j.find("parent"), j.find("child")
            if parent is None or child is None:
                continue
            fixed = j.get("type") == "fixed"
            below.setdefault(parent.get("link"), []).append((child.get("link"), fixed))
            parent_fixed[child.get("link")] = fixed

        def frame(name: str | None, seen: frozenset[str | None]) -> bool:
            el = by_name.get(name)
            if el is None or name in seen or el.find("collision") is not None \
                    or el.find("visual") is not None:
                return False
            return all(fixed and frame(child, seen | {name})
                       for child, fixed in below.get(name, []))

        name = link.get("name")
        return parent_fixed.get(name, False) and frame(name, frozenset())

    def define_material(self, el: etree._Element, line: int | None) -> None:
        name = el.get("name", "")
        if name in self.defined:
            return
        self.defined.add(name)
        xml = f'<material name="{_attr(name)}"><color rgba="{UNDEFINED_RGBA}"/></material>'
        self._insert_first_child(self.root, [xml])
        new = etree.Element("material", name=name)
        etree.SubElement(new, "color", rgba=UNDEFINED_RGBA)
        _prepend(self.root, new)
        self.repairs.append(Repair("U706", line, f"material {name!r} was used but never "
                                   f"defined: defined it white ({UNDEFINED_RGBA}), the colour "
                                   "PyBullet draws it in; set the colour you meant"))

    def normalise_uri(self, el: etree._Element, line: int | None,
                      packages: Mapping[str, Path] | None) -> None:
        from urdfkit.sources.uris import package_xml_name, resolve_uri

        old = el.get("filename", "")
        base = self.report.base
        assert base is not None
        target = resolve_uri(old, base, packages).path
        if target is None or not target.is_file():
            self.left.append(Repair("U708", line, f"{old!r}: no file found to point to"))
            return
        new = None
        for folder in [target.parent, *target.parent.parents]:
            name = package_xml_name(str(folder))
            if name:
                new = f"package://{name}/{target.relative_to(folder).as_posix()}"
                break
        if new is None:
            new = Path(os.path.relpath(target, base)).as_posix()
            if self.folder is not None:  # written elsewhere: named from there
                from urdfkit.sources.uris import rebased

                new = rebased(new, base, self.folder) or new
        self._set_attribute(el, "filename", new)
        self.renamed.add(el)
        self.repairs.append(Repair("U708", line, f"{old!r} -> {new!r} (package:/// has no "
                                   "package name; ROS tools refuse it)"))

    def move_paths(self) -> None:
        """Rewrite each relative mesh and texture path for :attr:`folder` (nothing else)."""
        from urdfkit.model.spec import FILE_TAGS
        from urdfkit.sources.uris import rebased

        base = self.report.base
        assert base is not None and self.folder is not None
        for el in self.root.iter(*FILE_TAGS):
            old = el.get("filename")
            if old is None or el in self.renamed or el not in self.tag_at:
                continue
            new = rebased(old, base, self.folder)
            if new is not None:
                self._set_attribute(el, "filename", new)
                self.moved.append((old, new))

    # ---- edits, on the text and the tree alike

    def _write_inertial(self, link: etree._Element, mass: float,
                        com: Sequence[float] | None, tensor: Sequence[Sequence[float]],
                        frame: Sequence[float], keep_mass: bool) -> None:
        """Write ``<inertial>``: a new one, or the old one with mass and inertia replaced.

        ``tensor`` is in link axes; it is written in the frame of the inertial's ``<origin
        rpy>``. An existing ``<origin>`` is kept; ``com`` gives a new one.
        """
        local, inertia_xml = inertia_in_frame(tensor, frame)
        inertial = link.find("inertial")
        if inertial is None:
            lines = ["<inertial>"]
            if com is not None and any(abs(x) > 0 for x in com):
                lines.append(f'\t<origin xyz="{fmt_vec(tuple(com))}" rpy="0 0 0"/>')
            lines += [f'\t<mass value="{fmt_float(mass, 6)}"/>', f"\t{inertia_xml}",
                      "</inertial>"]
            self._insert_first_child(link, lines)
            new = etree.fromstring("".join(x.strip() for x in lines))
            _prepend(link, new)
            return
        mass_el = inertial.find("mass")
        if not keep_mass:
            if mass_el is not None:
                self._set_attribute(mass_el, "value", fmt_float(mass, 6))
            else:
                self._insert_first_child(inertial, [f'<mass value="{fmt_float(mass, 6)}"/>'])
                _prepend(inertial, etree.Element("mass", value=fmt_float(mass, 6)))
        if com is not None and inertial.find("origin") is None and any(com):
            self._insert_first_child(inertial, [f'<origin xyz="{fmt_vec(tuple(com))}" '
                                                'rpy="0 0 0"/>'])
            _prepend(inertial, etree.Element("origin", xyz=fmt_vec(tuple(com)), rpy="0 0 0"))
        old = inertial.find("inertia")
        if old is not None:
            self._replace_inertia(old, local)
        else:
            self._insert_last_child(inertial, inertia_xml)
            inertial.append(etree.fromstring(inertia_xml))

    def _replace_inertia(self, el: etree._Element, tensor: Sequence[Sequence[float]]) -> None:
        start, end = self._span(el)
        xml = _inertia_xml(tensor)
        self.edits.append((start, end, xml))
        new = etree.fromstring(xml)
        new.tail = el.tail
        parent = el.getparent()
        assert parent is not None
        parent.replace(el, new)

    def _set_attribute(self, el: etree._Element, name: str, value: str) -> None:
        start, tag_end, _ = self._start_tag(el)
        tag = self.text[start:tag_end]
        m = re.search(rf"(\s{re.escape(name)}\s*=\s*)([\"'])(.*?)\2", tag, re.S)
        if m is None:  # pragma: no cover - the rules found the attribute in this element
            raise AssertionError(f"attribute {name} not found in {tag!r}")
        quote = m.group(2)
        escaped = _attr(value) if quote == '"' else _attr(value).replace("'", "&apos;")
        self.edits.append((start + m.start(3), start + m.end(3), escaped))
        el.set(name, value)

    def _insert_first_child(self, parent: etree._Element, lines: list[str]) -> None:
        """Insert lines as the first child; a leading tab in a line is one more indent."""
        start, tag_end, closed = self._start_tag(parent)
        indent = self._indent(start)
        # The first child written in the text (not one an earlier repair inserted).
        first = next((c for c in parent if not isinstance(c.tag, str) or c in self.tag_at),
                     None)
        if first is not None and not closed:
            inner = self._indent(self._start_tag(first)[0]) if isinstance(first.tag, str) \
                else None
            child = inner if inner is not None and inner.startswith(indent) and inner != indent \
                else indent + self._unit()
        else:
            child = indent + self._unit()
        unit = self._unit()
        body = "\n".join(child + unit * (len(x) - len(x.lstrip("\t"))) + x.lstrip("\t")
                         for x in lines)
        if closed:  # <link name="x"/> becomes <link name="x"> ... </link>
            head = self.text[start:tag_end].rstrip(">").rstrip().rstrip("/").rstrip()
            self.edits.append((start, tag_end, f"{head}>\n{body}\n{indent}</{parent.tag!s}>"))
        else:
            self.edits.append((tag_end, tag_end, "\n" + body))

    def _insert_last_child(self, parent: etree._Element, xml: str) -> None:
        start, end = self._span(parent)
        if self.text[end - 2:end] == "/>":  # <inertial/>: open it
            self._insert_first_child(parent, [xml])
            return
        close = self.text.rindex("</", start, end)
        own_line = self.text[self.text.rfind("\n", 0, close) + 1:close]
        if own_line.strip() == "":  # the end tag on a line of its own: a child line above it
            self.edits.append((close, close, f"{self._unit()}{xml}\n{own_line}"))
        else:  # all on one line: stay on it
            self.edits.append((close, close, xml))

    # ---- finding elements in the text

    def _start_tag(self, el: etree._Element) -> tuple[int, int, bool]:
        """(start, end, self-closing) of the element's start tag in the text."""
        start = self.tag_at[el]
        end, closed = self._tag_end(start)
        return start, end, closed

    def _tag_end(self, start: int) -> tuple[int, bool]:
        """The end of the start tag at ``start`` (past its ``>``, quotes minded), self-closing."""
        i, quote = start + 1, ""
        while True:
            ch = self.text[i]
            if quote:
                quote = "" if ch == quote else quote
            elif ch in "\"'":
                quote = ch
            elif ch == ">":
                return i + 1, self.text[i - 1] == "/"
            i += 1

    def _span(self, el: etree._Element) -> tuple[int, int]:
        start, tag_end, closed = self._start_tag(el)
        if closed:
            return start, tag_end
        depth, pos = 1, tag_end
        while True:
            m = _TOKEN.search(self.text, pos)
            if m is None:  # pragma: no cover - the document is well formed
                raise AssertionError(f"no end of <{el.tag!s}>")
            if m.group().startswith("</"):
                depth -= 1
                if depth == 0:
                    return start, m.end()
                pos = m.end()
            elif m.group() == "<":
                pos, closed = self._tag_end(m.start())
                depth += not closed
            else:  # a comment, CDATA or processing instruction: no tags in it
                pos = m.end()

    def _indent(self, pos: int) -> str:
        line_start = self.text.rfind("\n", 0, pos) + 1
        lead = self.text[line_start:pos]
        return lead if lead.strip() == "" else ""

    def _unit(self) -> str:
        first = next((x for x in self.root if isinstance(x.tag, str) and x in self.tag_at),
                     None)
        if first is not None:
            unit = self._indent(self._start_tag(first)[0])
            if unit:
                return unit
        return "  "

    # ---- the result

    def finish(self) -> bytes:
        if not self.edits:
            return self.text.encode("utf-8")
        out = self.text
        for start, end, new in sorted(self.edits, key=lambda e: (e[0], e[1]), reverse=True):
            out = out[:start] + new + out[end:]
        data = out.encode("utf-8")
        got = _shape(parse_xml(data, self.file).getroot())
        if got != _shape(self.root):  # pragma: no cover - a bug in the splicing above
            raise AssertionError(f"{self.file}: the edited text does not parse to the edited "
                                 "tree; nothing written")
        return data


def _prepend(parent: etree._Element, new: etree._Element) -> None:
    """Make ``new`` the tree's first child of ``parent``, where the text edit puts it.

    :meth:`_Plan._insert_first_child` writes it right after the start tag, so any text the
    parent held before its first child (a stray ``>`` of ``<robot name="r">>``, as youBot's
    xacro writes) now follows ``new``.
    """
    parent.insert(0, new)
    new.tail, parent.text = parent.text, None


def triangle_repair(link: etree._Element, report: RuleReport | None, mass: float,
                    fallback: Sequence[Sequence[float]] | None = None) -> tuple[str, str] | None:
    """The ``<inertia>`` fix writes for a link whose inertia breaks the triangle inequality.

    U604's repair, as :meth:`_Plan._inertia` makes it: the tensor of the link's collision
    solid at its mass, in the frame of the inertial's ``<origin rpy>`` (kept), written with
    9 significant digits; for a link without a solid, every principal moment set to their
    mean (MuJoCo's ``balanceinertia``, what ``fix --balance`` writes); for a tensor that cannot
    be balanced either (not positive definite), ``fallback`` when given: the tensor (link axes)
    PyBullet computes from the collision shapes' box without URDF_USE_INERTIA_FROM_FILE,
    which export passes so that no robot PyBullet loads is a dead end. Returns the element's
    XML and how it was made, or None when fix has nothing to write. ``urdfkit export`` writes
    it where PyBullet zeroes such a tensor and MuJoCo would refuse the body it leaves.
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
    return (_inertia_xml(_iso(mean)), "every principal moment set to their mean (MuJoCo's "
            "balanceinertia; it has no collision solid), as `urdfkit fix --balance` writes it")


def inertia_in_frame(tensor: Sequence[Sequence[float]], frame: Sequence[float]
              ) -> tuple[tuple[tuple[float, float, float], ...], str]:
    """A tensor in link axes, turned into the inertial's ``rpy`` frame, and its ``<inertia>``."""
    local = _rotate_tensor(transpose(rpy_to_matrix(frame)), tensor)
    return local, _inertia_xml(local)


def _iso(moment: float) -> tuple[tuple[float, float, float], ...]:
    return ((moment, 0.0, 0.0), (0.0, moment, 0.0), (0.0, 0.0, moment))


def _rotate_tensor(rot: Sequence[Sequence[float]], t: Sequence[Sequence[float]]
                   ) -> tuple[tuple[float, float, float], ...]:
    """``rot @ t @ rot.T``."""
    rt = [[sum(rot[i][k] * t[k][j] for k in range(3)) for j in range(3)] for i in range(3)]
    out = [[sum(rt[i][k] * rot[j][k] for k in range(3)) for j in range(3)] for i in range(3)]
    return tuple((r[0], r[1], r[2]) for r in out)


def _inertia_xml(t: Sequence[Sequence[float]]) -> str:
    def f(x: float) -> str:
        return fmt_float(x, 9) if abs(x) > 1e-12 * max(abs(t[0][0]), abs(t[1][1]),
                                                        abs(t[2][2]), 1e-300) else "0"

    return (f'<inertia ixx="{f(t[0][0])}" ixy="{f(t[0][1])}" ixz="{f(t[0][2])}" '
            f'iyy="{f(t[1][1])}" iyz="{f(t[1][2])}" izz="{f(t[2][2])}"/>')


def _attr(text: str) -> str:
    """``text`` as a double-quoted attribute value that parses back to ``text``.

    Tabs and line breaks are written as character references: XML turns a literal one in an
    attribute into a space (a material named ``"a&#9;b"`` would come back ``"a b"``).
    """
    return (text.replace("&", "&amp;").replace('"', "&quot;").replace("<", "&lt;")
            .replace("\t", "&#9;").replace("\n", "&#10;").replace("\r", "&#13;"))


def _shape(el: etree._Element) -> Any:
    """An element as nested tuples: tag, attributes, stripped text, children (comments too)."""
    return (str(el.tag), tuple(sorted(el.attrib.items())), (el.text or "").strip(),
            tuple(_shape(c) for c in el))


__all__ = ["DEFAULT_DENSITY", "FIXABLE", "FixResult", "Repair", "Solid", "balanced", "fix_file"]
