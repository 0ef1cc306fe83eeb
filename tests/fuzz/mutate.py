"""Mutants of real robot descriptions, for the fuzzer (pure Python + lxml, seeded).

Each mutation targets one class of hostile input found in the wild or by earlier fuzz runs:
numbers that are NaN, infinite, huge, empty or text; names that are long (in characters and
in UTF-8 bytes), multi-byte or full of printf formats; '%' in a joint type; elements deleted,
duplicated or moved; deep nesting; meshes that point at a folder, a FIFO, a device, an
over-long path; random truncation and byte flips.
"""

from __future__ import annotations

import random
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path

from lxml import etree

NUMERIC_VALUES = ["nan", "inf", "-inf", "1e308", "-1e308", "", "abc", "1e-320", "0", "-1",
                  "1 2", "NaN inf 0", "1e309"]
NAME_VALUES = ["a" * 1001, "b" * 1300, "c" * 2500, "é" * 700, "ロ" * 800, "%s%n", "%x%x%x%n",
               "name with spaces", "ü" * 300, "\u202e", "x" * 50000,
               # whitespace XML reads back only through character references (fix once
               # exited 3 writing a tab into a material name)
               "tab\there", "line\nbreak", "cr\rhere", " lead and trail ", "\t"]
#: Whitespace-bearing names for materials.
WHITESPACE_NAMES = ["or\tange", "a\nb", "c\rd", " e ", "\t\n"]


@dataclass
class Mutant:
    """A mutated file: its bytes, the mutations that made it, side files it needs."""

    seed_name: str
    data: bytes
    mutations: list[str] = field(default_factory=list)
    mesh: str | None = None  # a special mesh target to create beside the file


def _numeric_attrs(root: etree._Element) -> list[tuple[etree._Element, str]]:
    out = []
    for el in root.iter(etree.Element):
        for attr, value in el.items():
            if attr in ("name", "link", "joint", "type", "filename", "reference"):
                continue
            try:
                [float(x) for x in value.split()]
            except ValueError:
                continue
            out.append((el, attr))
    return out


def _rename(root: etree._Element, tag: str, rng: random.Random) -> str:
    """Rename a link or joint (and every reference to it): the name path, not a dangling one."""
    targets = [el for el in root if isinstance(el.tag, str) and el.tag == tag and el.get("name")]
    if not targets:
        return "no target"
    el = rng.choice(targets)
    old, new = el.get("name"), rng.choice(NAME_VALUES)
    el.set("name", new)
    attr = "link" if tag == "link" else "joint"
    for ref in root.iter(etree.Element):
        if ref.get(attr) == old:
            ref.set(attr, new)
    return f"{tag} {old!r} renamed to {new[:12]!r}... ({len(new)} chars)"


def m_number(root: etree._Element, rng: random.Random) -> str:
    """Set a numeric attribute to NaN, inf, 1e308, empty, text or a wrong count."""
    attrs = _numeric_attrs(root)
    if not attrs:
        return "no numbers"
    el, attr = rng.choice(attrs)
    value = rng.choice(NUMERIC_VALUES)
    el.set(attr, value)
    return f"<{el.tag} {attr}={value!r}>"


def m_link_name(root: etree._Element, rng: random.Random) -> str:
    """A long, multi-byte or printf-format link name."""
    return _rename(root, "link", rng)


def m_joint_name(root: etree._Element, rng: random.Random) -> str:
    """A long, multi-byte or printf-format joint name."""
    return _rename(root, "joint", rng)


def m_robot_name(root: etree._Element, rng: random.Random) -> str:
    """A long, multi-byte or printf-format robot name."""
    value = rng.choice(NAME_VALUES)
    root.set("name", value)
    return f"robot name ({len(value)} chars)"


def m_material_name(root: etree._Element, rng: random.Random) -> str:
    """A material name holding a tab, a line break or edge spaces (every use renamed, or a
    visual's material renamed alone: then it is used but never defined)."""
    materials = [el for el in root.iter("material") if el.get("name")]
    if not materials:
        return "no material to rename"
    old, new = rng.choice(materials).get("name"), rng.choice(WHITESPACE_NAMES)
    every = rng.random() < 0.5
    for el in materials:
        if el.get("name") == old and (every or el.getparent() is not root):
            el.set("name", new)
    return f"material {old!r} renamed to {new!r}" + ("" if every else " in its uses only")


def m_joint_type(root: etree._Element, rng: random.Random) -> str:
    """'%' in a joint type, or an unknown type."""
    joints = [j for j in root.iter("joint") if j.get("type")]
    if not joints:
        return "no joints"
    j = rng.choice(joints)
    value = rng.choice(["fi%sxed", "%n", "hinge", "REVOLUTE", ""])
    j.set("type", value)
    return f"joint type {value!r}"


def m_delete(root: etree._Element, rng: random.Random) -> str:
    """Delete a random element."""
    els = [el for el in root.iter(etree.Element) if el is not root]
    if not els:
        return "nothing"
    el = rng.choice(els)
    el.getparent().remove(el)
    return f"deleted <{el.tag}>"


def m_duplicate(root: etree._Element, rng: random.Random) -> str:
    """Duplicate a random element in place (duplicate names, two shapes, two parents...)."""
    import copy

    els = [el for el in root.iter(etree.Element) if el is not root]
    if not els:
        return "nothing"
    el = rng.choice(els)
    el.addnext(copy.deepcopy(el))
    return f"duplicated <{el.tag}>"


def m_move(root: etree._Element, rng: random.Random) -> str:
    """Move a random element under another parent."""
    els = [el for el in root.iter(etree.Element) if el is not root]
    if len(els) < 2:
        return "nothing"
    el, target = rng.sample(els, 2)
    if el in list(target.iterancestors()) or el is target:
        return "no move"
    target.append(el)
    return f"moved <{el.tag}> into <{target.tag}>"


def m_nest(root: etree._Element, rng: random.Random) -> str:
    """Nest elements deeper than PyBullet's XML parser reads."""
    links = list(root.iter("link")) or [root]
    el = rng.choice(links)
    depth = rng.choice([95, 120, 400])
    for _ in range(depth):
        el = etree.SubElement(el, "x")
    return f"nested {depth} deep"


def m_mesh(root: etree._Element, rng: random.Random) -> str:
    """Point a mesh at a folder, a FIFO, a device or an over-long path."""
    kind = rng.choice(["dir", "fifo", "devzero", "long", "missing", "nul"])
    targets = {"dir": "meshdir.stl", "fifo": "pipe.stl", "devzero": "zero.stl",
               "long": "d" * 300 + "/m.stl", "missing": "gone.stl", "nul": "a\x01b.stl"}
    links = list(root.iter("link"))
    if not links:
        return "no links"
    link = rng.choice(links)
    visual = etree.SubElement(link, "visual")
    etree.SubElement(etree.SubElement(visual, "geometry"), "mesh",
                     filename=targets[kind].replace("\x01", ""))
    return f"mesh:{kind}"


TREE_MUTATIONS: list[Callable[[etree._Element, random.Random], str]] = [
    m_number, m_number, m_number, m_link_name, m_joint_name, m_robot_name, m_joint_type,
    m_delete, m_duplicate, m_move, m_nest, m_mesh, m_material_name]


def byte_mutation(data: bytes, rng: random.Random) -> tuple[bytes, list[str]]:
    """The file cut short, or up to 8 of its bytes replaced at random."""
    if rng.random() < 0.5:
        cut = rng.randrange(1, len(data))
        return data[:cut], [f"truncated at {cut}"]
    flipped = bytearray(data)
    for _ in range(rng.randint(1, 8)):
        i = rng.randrange(len(flipped))  # before the new byte: the seeded samples' order
        flipped[i] = rng.randrange(256)
    return bytes(flipped), ["byte flips"]


def mutate(seed_name: str, data: bytes, rng: random.Random) -> Mutant:
    """One mutant: one or two tree mutations, or a byte-level one."""
    if rng.random() < 0.15:
        return Mutant(seed_name, *byte_mutation(data, rng))
    root = etree.fromstring(data, etree.XMLParser(remove_blank_text=True,
                                                  resolve_entities=False))
    done = []
    mesh = None
    for _ in range(rng.choice([1, 1, 2])):
        fn = rng.choice(TREE_MUTATIONS)
        what = fn(root, rng)
        done.append(what)
        if what.startswith("mesh:"):
            mesh = what[5:]
    return Mutant(seed_name, etree.tostring(root, xml_declaration=True, encoding="utf-8"),
                  done, mesh)


def seeds(extra: list[Path] | None = None) -> dict[str, bytes]:
    """Our own robot fixtures, plus real robots from pybullet_data (read, never copied)."""
    here = Path(__file__).parent.parent / "fixtures" / "robots"
    out = {p.name: p.read_bytes() for p in sorted(here.rglob("*.urdf"))}
    from urdfkit.sources.uris import pybullet_data_path

    data = pybullet_data_path()
    for rel in ("r2d2.urdf", "racecar/racecar.urdf", "kuka_iiwa/model.urdf",
                "quadruped/minitaur.urdf", "humanoid/humanoid.urdf"):
        if data is not None and (data / rel).is_file():
            out[rel] = (data / rel).read_bytes()
    for p in extra or []:
        out[p.name] = p.read_bytes()
    from urdfkit.model.xmlio import tolerate_quirks

    # pybullet_data holds XML quirks (trailing NUL bytes...): mutate the repaired text.
    return {name: tolerate_quirks(data)[0] for name, data in out.items()}
