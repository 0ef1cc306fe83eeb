"""Mutants of real MJCF exports, for the fuzzer's second campaign (`urdfkit agree`).

The seeds are what ``urdfkit export mjcf`` writes for robots of pybullet_data; each mutant
keeps the robot's URDF and breaks its model the ways hand-edited and foreign MJCFs break:
elements deleted, renamed, duplicated or moved; numbers huge, NaN, negative, zero, empty or
text; attributes of the wrong type; zero sizes and masses; ``<include>``s and mesh, texture,
height-field and skin files that are a FIFO, a folder, a device, missing, the model itself or
a cycle; a sub-model that names its parent; truncation and byte flips.
"""

from __future__ import annotations

import random
from collections.abc import Callable
from dataclasses import dataclass, field

from lxml import etree

from . import mutate
from .mutate import NUMERIC_VALUES, byte_mutation

#: Numbers for MJCF attributes: mostly ones MuJoCo's parser reads (huge, tiny, NaN, zero,
#: negative, too many), so that the mutant reaches the comparison; then the URDF campaign's.
MJCF_NUMBERS = ["nan", "inf", "-inf", "1e308", "-1e308", "1.7976931348623157e308", "1e-320",
                "1e-300", "0", "-0", "-1", "-1e-9", "1e9", "0 0 0", "-1 -1 -1",
                "1e308 1e308 1e308", "nan nan nan nan", "0 0 0 0", "1 2 3 4 5 6 7 8 9 10 11",
                *NUMERIC_VALUES]
#: Values of the wrong type for MJCF's keyword and boolean attributes.
KEYWORDS = ["banana", "", "%s%n", "true", "1", "hinge", "free", "ball", "slide", "box", "mesh",
            "radian", "degree", "é" * 300]
#: Special files a mutation can make beside the model (made by the runner in the mutant's
#: folder): name -> kind.
SPECIALS = {"pipe": "fifo", "folder": "dir", "zero": "devzero", "gone": "missing",
            "bad.xml": "malformed", "cycle.xml": "cycle", "empty.xml": "empty"}


@dataclass
class MjcfMutant:
    """A mutated model: its bytes, what made it, the special files it needs beside it."""

    seed_name: str
    data: bytes
    mutations: list[str] = field(default_factory=list)
    #: (path relative to the mutant's folder, kind) for the runner to create.
    specials: list[tuple[str, str]] = field(default_factory=list)


def _elements(root: etree._Element) -> list[etree._Element]:
    return [el for el in root.iter(etree.Element) if el is not root]


def m_number(root: etree._Element, rng: random.Random, m: MjcfMutant) -> str:
    """A numeric attribute huge, NaN, negative, zero, empty, text or of the wrong count."""
    attrs = []
    for el in root.iter(etree.Element):
        for attr, value in el.items():
            try:
                [float(x) for x in value.split()]
            except ValueError:
                continue
            if value.strip():
                attrs.append((el, attr))
    if not attrs:
        return "no numbers"
    el, attr = rng.choice(attrs)
    value = rng.choice(MJCF_NUMBERS)
    el.set(attr, value)
    return f"<{el.tag} {attr}={value!r}>"


def m_keyword(root: etree._Element, rng: random.Random, m: MjcfMutant) -> str:
    """A keyword or boolean attribute (type, integrator, angle, autolimits...) of the wrong
    type or value."""
    attrs = [(el, a) for el in root.iter(etree.Element) for a, v in el.items()
             if a in ("type", "integrator", "angle", "autolimits", "inertia", "limited",
                      "inertiafromgeom", "coordinate", "contype", "conaffinity", "group",
                      "priority", "condim", "class", "childclass")]
    if not attrs:
        return "no keywords"
    el, attr = rng.choice(attrs)
    value = rng.choice(KEYWORDS)
    el.set(attr, value)
    return f"<{el.tag} {attr}={value[:12]!r}>"


def m_zero(root: etree._Element, rng: random.Random, m: MjcfMutant) -> str:
    """A zero size, mass, inertia or scale."""
    choices = [(el, a) for el in root.iter("geom", "inertial", "mesh") for a in
               ("size", "mass", "diaginertia", "fullinertia", "scale") if el.get(a) is not None]
    if not choices:
        return "nothing to zero"
    el, attr = rng.choice(choices)
    el.set(attr, " ".join("0" for _ in el.get(attr, "").split()) or "0")
    return f"<{el.tag} {attr}> zeroed"


def m_delete(root: etree._Element, rng: random.Random, m: MjcfMutant) -> str:
    """Delete a random element (a body with its subtree, an inertial, the compiler...)."""
    return mutate.m_delete(root, rng)  # the URDF campaign's, with the MJCF mutators' signature


def m_rename_tag(root: etree._Element, rng: random.Random, m: MjcfMutant) -> str:
    """Rename an element's tag (MuJoCo's schema refuses it) or swap it for a sibling kind."""
    els = _elements(root)
    if not els:
        return "nothing"
    el = rng.choice(els)
    old = el.tag
    el.tag = rng.choice(["bodyy", "joint", "body", "geom", "site", "x", "inertial", "include"])
    return f"<{old}> renamed <{el.tag}>"


def m_rename(root: etree._Element, rng: random.Random, m: MjcfMutant) -> str:
    """Rename a body, joint or site (then unmatched by name) to a long, multi-byte, empty or
    taken name; every reference to it renamed too, or left dangling."""
    named = [el for el in root.iter("body", "joint", "site") if el.get("name")]
    if not named:
        return "nothing named"
    el = rng.choice(named)
    old, new = el.get("name"), rng.choice(["", "x" * 5000, "ロ" * 600, "%s%n", "world",
                                           "base_link", "a b", "\t"])
    el.set("name", new)
    every = rng.random() < 0.7
    if every:
        for ref in root.iter(etree.Element):
            for attr, value in ref.items():
                if value == old and attr in ("joint", "body", "site", "joint1", "joint2",
                                             "body1", "body2", "target"):
                    ref.set(attr, new)
    return f"<{el.tag}> renamed to {new[:8]!r} ({len(new)} chars)" + \
        ("" if every else ", references left")


def m_duplicate(root: etree._Element, rng: random.Random, m: MjcfMutant) -> str:
    """Duplicate an element in place (duplicate names, two free joints, two compilers...)."""
    return mutate.m_duplicate(root, rng)  # the URDF campaign's, with the MJCF mutators' signature


def m_move(root: etree._Element, rng: random.Random, m: MjcfMutant) -> str:
    """Move an element under another parent."""
    return mutate.m_move(root, rng)  # the URDF campaign's, with the MJCF mutators' signature


def m_include(root: etree._Element, rng: random.Random, m: MjcfMutant) -> str:
    """An ``<include>`` of a FIFO, a folder, a device, a missing, malformed or empty file, the
    model itself, or a file that includes the model back."""
    kind = rng.choice(["pipe.xml", "folder", "zero", "gone.xml", "bad.xml", "model.xml",
                       "cycle.xml", "empty.xml", "sub/pipe.xml"])
    where = rng.choice([root, *root.iter("worldbody", "asset", "default", "body")])
    el = etree.Element("include", file=kind)
    where.insert(rng.randrange(len(where) + 1), el)
    name = kind.split("/")[-1]
    special = SPECIALS.get(name, SPECIALS.get(name.split(".")[0], ""))
    if special and special != "missing":
        m.specials.append((kind, special))
    return f"include:{kind}"


def m_asset_file(root: etree._Element, rng: random.Random, m: MjcfMutant) -> str:
    """A mesh, texture, height field or skin file that is a FIFO, a folder, a device or
    missing, in the model's mesh folder or beside the model; or meshdir pointed at one."""
    kind = rng.choice(["pipe", "folder", "zero", "gone"])
    special = SPECIALS[kind]
    compiler = root.find("compiler")
    meshdir = compiler.get("meshdir", "") if compiler is not None else ""
    asset = root.find("asset")
    if asset is None:
        asset = etree.SubElement(root, "asset")
    what = rng.choice(["mesh", "existing mesh", "texture", "hfield", "skin", "meshdir"])
    meshes = asset.findall("mesh")
    if what == "meshdir" and compiler is not None:
        compiler.set("meshdir", kind)
        if special != "missing":
            m.specials.append((kind, special))
        return f"meshdir:{kind}"
    name = f"{kind}.{'png' if what in ('texture', 'hfield') else 'stl'}"
    if what == "existing mesh" and meshes:
        rng.choice(meshes).set("file", name)
    elif what == "texture":
        etree.SubElement(asset, "texture", name="fuzz_tex", type="2d", file=name)
    elif what == "hfield":
        etree.SubElement(asset, "hfield", name="fuzz_hf", file=name, size="1 1 1 1")
    elif what == "skin":
        deformable = etree.SubElement(root, "deformable")
        etree.SubElement(deformable, "skin", name="fuzz_skin", file=name)
    else:
        etree.SubElement(asset, "mesh", name="fuzz_mesh", file=name)
    folder = meshdir if what not in ("texture",) else ""
    if special != "missing":
        m.specials.append(((folder + "/" if folder else "") + name, special))
    return f"{what}:{kind}"


def m_sub_model(root: etree._Element, rng: random.Random, m: MjcfMutant) -> str:
    """An ``<asset><model>`` naming the model itself (MuJoCo recursed until it crashed) or a
    special file."""
    asset = root.find("asset")
    if asset is None:
        asset = etree.SubElement(root, "asset")
    target = rng.choice(["model.xml", "pipe.xml", "cycle_model.xml"])
    etree.SubElement(asset, "model", name="fuzz_model", file=target)
    if target == "pipe.xml":
        m.specials.append((target, "fifo"))
    elif target == "cycle_model.xml":
        m.specials.append((target, "model_cycle"))
    return f"model:{target}"


#: Weighted towards what MuJoCo still loads (numbers, zeros, names), so that most mutants
#: reach the comparison rows rather than a refusal.
MUTATIONS: list[Callable[[etree._Element, random.Random, MjcfMutant], str]] = [
    m_number, m_number, m_number, m_number, m_number, m_zero, m_zero, m_rename, m_rename,
    m_keyword, m_delete, m_delete, m_rename_tag, m_duplicate, m_move, m_include, m_asset_file,
    m_sub_model]

#: What the runner writes for each special kind that is a file of text.
SPECIAL_TEXT = {
    "malformed": "<mujoco><worldbody><body name='x'></worldbody>",
    "cycle": '<mujoco><include file="model.xml"/></mujoco>',
    "empty": "",
    "model_cycle": '<mujoco><asset><model name="back" file="model.xml"/></asset></mujoco>',
}


def mutate_mjcf(seed_name: str, data: bytes, rng: random.Random) -> MjcfMutant:
    """One mutant: one or two tree mutations, or a byte-level one."""
    if rng.random() < 0.06:
        return MjcfMutant(seed_name, *byte_mutation(data, rng))
    root = etree.fromstring(data, etree.XMLParser(remove_blank_text=True,
                                                  resolve_entities=False))
    mutant = MjcfMutant(seed_name, b"")
    for _ in range(rng.choice([1, 1, 1, 2])):
        mutant.mutations.append(rng.choice(MUTATIONS)(root, rng, mutant))
    mutant.data = etree.tostring(root, pretty_print=True, encoding="utf-8")
    return mutant
