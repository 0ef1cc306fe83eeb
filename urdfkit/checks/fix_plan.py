"""``fix``'s repairs, finding by finding: what each one writes, or why it is left.

:class:`_Plan` takes the elements :mod:`urdfkit.checks.fix` found wrong and decides each
repair: a link's inertia (derived from its collision solid, balanced, a small mass for a
massless moving link, mass 0 for a frame), Gazebo's contact parameters carried to
``<contact>``, an undefined material defined, a ``package:///`` path named, and relative
paths rewritten for another folder. It writes every repair through a
:class:`urdfkit.checks.fix_splice.Splice` and lists it (or why nothing was done) as a
:class:`urdfkit.checks.fix_result.Repair`.
"""

from __future__ import annotations

import os
from collections.abc import Mapping, Sequence
from pathlib import Path

from lxml import etree

from urdfkit.checks.fix_inertia import balanced, inertia_in_frame, inertia_xml, iso
from urdfkit.checks.fix_result import Repair
from urdfkit.checks.fix_splice import Splice, attr, prepend
from urdfkit.checks.rules_mass import STUB_SIZE, Solid, link_solid
from urdfkit.model.spec import attr_float as _num
from urdfkit.model.spec import attr_vec as _vec
from urdfkit.model.xmlio import fmt_float, fmt_vec
from urdfkit.sources.guard import RuleReport

#: Mass (kg) and principal moment (kg m^2) for a massless link that moves.
SMALL_MASS = 1e-3
SMALL_INERTIA = 1e-6
#: What PyBullet draws a visual with an undefined material in.
UNDEFINED_RGBA = "1 1 1 1"
INERTIA_ORDER = ("U606", "U602", "U601", "U609", "U610", "U603", "U604", "U605", "U608")


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
        #: The edits, on the text and the tree alike.
        self.splice = Splice(text, root, file)
        #: Where the result goes, when not beside the file (relative paths are for it).
        self.folder = folder
        #: ``(old, new)`` of each filename rewritten for ``folder``.
        self.moved: list[tuple[str, str]] = []
        self.renamed: set[etree._Element] = set()
        self.root = root
        self.balance = balance
        self.density = density
        self.report = report
        self.repairs: list[Repair] = []
        self.left: list[Repair] = []
        self.defined: set[str] = set()

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
            self.splice.insert_last_child(link, f"<contact>{xml}</contact>")
            contact = etree.SubElement(link, "contact")
        else:
            self.splice.insert_last_child(contact, xml)
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
        code = next(c for c in INERTIA_ORDER if c in by_code)
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
        self.splice.insert_first_child(job.link, [
            '<inertial><mass value="0"/><inertia ixx="0" ixy="0" ixz="0" iyy="0" iyz="0" '
            'izz="0"/></inertial>'])
        prepend(job.link, etree.fromstring(
            '<inertial><mass value="0"/><inertia ixx="0" ixy="0" ixz="0" iyy="0" iyz="0" '
            'izz="0"/></inertial>'))
        self.repairs.append(Repair(job.code, job.line, f"link {job.name!r} is a frame (no shapes, "
                                   "fixed to its parent, only frames below it): gave it "
                                   "mass 0, where PyBullet would add 1 kg"))

    def _small_mass(self, job: _LinkJob) -> None:
        """U602: a moving link without mass gets a small one, with its shapes' inertia."""
        solid = job.solid
        tensor = solid.inertia(SMALL_MASS) if solid else iso(SMALL_INERTIA)
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
                self.splice.replace(inertia, inertia_xml(iso(mean)))
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
        xml = f'<material name="{attr(name)}"><color rgba="{UNDEFINED_RGBA}"/></material>'
        self.splice.insert_first_child(self.root, [xml])
        new = etree.Element("material", name=name)
        etree.SubElement(new, "color", rgba=UNDEFINED_RGBA)
        prepend(self.root, new)
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
        self.splice.set_attribute(el, "filename", new)
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
            if old is None or el in self.renamed or el not in self.splice.tag_at:
                continue
            new = rebased(old, base, self.folder)
            if new is not None:
                self.splice.set_attribute(el, "filename", new)
                self.moved.append((old, new))

    # ---- the inertial, written on the text and the tree alike

    def _write_inertial(self, link: etree._Element, mass: float,
                        com: Sequence[float] | None, tensor: Sequence[Sequence[float]],
                        frame: Sequence[float], keep_mass: bool) -> None:
        """Write ``<inertial>``: a new one, or the old one with mass and inertia replaced.

        ``tensor`` is in link axes; it is written in the frame of the inertial's ``<origin
        rpy>``. An existing ``<origin>`` is kept; ``com`` gives a new one.
        """
        xml = inertia_in_frame(tensor, frame)[1]  # in the inertial's frame
        inertial = link.find("inertial")
        if inertial is None:
            lines = ["<inertial>"]
            if com is not None and any(abs(x) > 0 for x in com):
                lines.append(f'\t<origin xyz="{fmt_vec(tuple(com))}" rpy="0 0 0"/>')
            lines += [f'\t<mass value="{fmt_float(mass, 6)}"/>', f"\t{xml}",
                      "</inertial>"]
            self.splice.insert_first_child(link, lines)
            new = etree.fromstring("".join(x.strip() for x in lines))
            prepend(link, new)
            return
        mass_el = inertial.find("mass")
        if not keep_mass:
            if mass_el is not None:
                self.splice.set_attribute(mass_el, "value", fmt_float(mass, 6))
            else:
                self.splice.insert_first_child(inertial, [f'<mass value="{fmt_float(mass, 6)}"/>'])
                prepend(inertial, etree.Element("mass", value=fmt_float(mass, 6)))
        if com is not None and inertial.find("origin") is None and any(com):
            self.splice.insert_first_child(inertial, [f'<origin xyz="{fmt_vec(tuple(com))}" '
                                                      'rpy="0 0 0"/>'])
            prepend(inertial, etree.Element("origin", xyz=fmt_vec(tuple(com)), rpy="0 0 0"))
        old = inertial.find("inertia")
        if old is not None:
            self.splice.replace(old, xml)
        else:
            self.splice.insert_last_child(inertial, xml)
            inertial.append(etree.fromstring(xml))


    def finish(self) -> bytes:
        """The repaired text (:meth:`Splice.finish`)."""
        return self.splice.finish()
