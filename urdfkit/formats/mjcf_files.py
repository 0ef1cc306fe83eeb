"""Every file an MJCF makes MuJoCo open, checked before MuJoCo opens any of them.

MuJoCo opens what a model names as it meets it, with a blocking ``open``: a FIFO there waits
for a writer forever, a folder reads as an empty file, ``/dev/zero`` never ends, and an
``<asset><model file=...>`` that names a model above it recurses until the stack overflows
(a segfault). So ``agree`` walks the model first, every ``<include>`` and sub-model with it,
parsed by the house's safe parser (no entities, no network), and refuses anything that is not
a regular file with one line naming the file and line that refer to it.

Where MuJoCo 4.0.0 looks, measured (tests/test_mjcf_files.py keeps each rule):

- ``<include file>``: in the top model's folder, then in the including file's folder (the
  first that opens wins: both present, the top folder's). A file included twice, however
  spelled, is refused by MuJoCo ("already included"); the walk refuses it first.
- ``<mesh>``, ``<hfield>``, ``<skin>``, ``<flexcomp type="mesh|gmsh">`` ``file``: in
  ``meshdir`` (relative to the top model's folder), else ``assetdir``, else that folder; for
  a reference in an included file, then in that file's own folder (without ``meshdir``).
- ``<texture>`` ``file`` and the six cube faces (``fileright`` ...), unless ``builtin``: the
  same with ``texturedir``.
- An empty ``file`` is no file (a mesh given by its vertices loads).
- ``<compiler>``: wherever it stands (an included file too) and after the assets it governs;
  a later attribute replaces an earlier one; ``assetdir`` sets both folders and ``meshdir`` or
  ``texturedir`` in the same element wins over it; ``strippath="true"`` drops an asset's
  folders, not an include's.
- ``<asset><model file>``: in the top model's folder, then the including file's, with neither
  ``assetdir`` nor ``meshdir``; it is a model of its own (its own folder and compiler).
"""

from __future__ import annotations

import os
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from urdfkit.core.errors import InputError

#: The most files one MJCF may make the walk read (its includes and sub-models, itself
#: counted). MuJoCo loads a chain of 1,000 nested sub-models; no real model comes near.
MAX_MJCF_FILES = 1000
#: Cube-map faces of a ``<texture>``, beside its ``file``.
TEXTURE_FILES = ("file", "fileright", "fileleft", "fileup", "filedown", "filefront",
                 "fileback")
#: What a non-regular file would do to MuJoCo.
_CONSEQUENCE = {"a FIFO (named pipe)": "MuJoCo would wait on it forever",
                "a directory": "MuJoCo would read it as an empty file"}


@dataclass
class _Where:
    """A file the walk read: its path, how it is shown, and whether it is a model's top."""

    path: Path
    shown: str
    top: bool


@dataclass
class _Ref:
    """One file reference an element makes, and where it stands."""

    tag: str
    attr: str
    value: str
    holder: _Where
    line: int | None


@dataclass
class _Model:
    """One model: its top file, its compiler's folders, what it refers to."""

    top: _Where
    #: The file the user named (shown in every refusal), and the real paths of the models
    #: this one is a sub-model of.
    root: str
    ancestors: tuple[str, ...] = ()
    meshdir: str = ""
    texturedir: str = ""
    strippath: bool = False
    included: dict[str, str] = field(default_factory=dict)
    assets: list[tuple[_Ref, str]] = field(default_factory=list)  # (reference, folder kind)
    models: list[_Ref] = field(default_factory=list)


def check_mjcf_files(path: str | Path) -> list[Path]:
    """Refuse an MJCF that makes MuJoCo open anything but a regular file.

    ``path`` is the top model, already known to be a regular file. Returns every other file
    MuJoCo will open for it (includes, sub-models, meshes, textures...), in the walk's order.

    Raises:
        InputError: one line naming the file and line of the offending reference.
    """
    top = _Where(Path(path), str(path), True)
    budget = [MAX_MJCF_FILES]
    queue = [_Model(top, top.shown)]
    opened: list[Path] = []
    while queue:
        model = queue.pop()
        _walk(model, budget, opened)
        opened.extend(_find(model, ref, *_folder(model, ref, kind)).path
                      for ref, kind in model.assets)
        subs = _sub_models(model)
        opened.extend(m.top.path for m in subs)
        queue.extend(subs)
    return opened


def _real(path: Path) -> str:
    return os.path.realpath(path)


def _parse(model: _Model, where: _Where, budget: list[int]) -> Any:
    from urdfkit.model.xmlio import parse_xml, read_regular

    budget[0] -= 1
    try:
        if budget[0] < 0:
            raise InputError(f"the model reads more than {MAX_MJCF_FILES} files (includes and "
                             "sub-models); urdfkit stops there", file=where.shown)
        data = read_regular(where.path, kind="MJCF file", track=False)
        return parse_xml(data, where.shown).getroot()
    except InputError as e:
        if where.shown == model.root:
            raise
        raise InputError(f"{e.message} (read for {model.root})", file=e.file,
                         line=e.line) from None


def _walk(model: _Model, budget: list[int], opened: list[Path]) -> None:
    """Read the model and its includes in document order: compiler folders, references."""
    model.included[_real(model.top.path)] = model.top.shown
    stack = [(_parse(model, model.top, budget).iter(), model.top)]
    while stack:
        elements, holder = stack[-1]
        el = next(elements, None)
        if el is None:
            stack.pop()
            continue
        tag = el.tag
        if not isinstance(tag, str):
            continue  # comments, processing instructions
        if tag == "include" and el.get("file"):
            found = _include(model, _ref(el, "file", holder))
            opened.append(found.path)
            stack.append((_parse(model, found, budget).iter(), found))
        elif tag == "compiler":
            _compiler(model, el)
        elif tag == "model" and el.get("file") and _parent_tag(el) == "asset":
            model.models.append(_ref(el, "file", holder))
        elif tag in ("mesh", "hfield", "skin") and el.get("file"):
            model.assets.append((_ref(el, "file", holder), "meshdir"))
        elif tag == "flexcomp" and el.get("type") in ("mesh", "gmsh") and el.get("file"):
            model.assets.append((_ref(el, "file", holder), "meshdir"))
        elif tag == "texture" and el.get("builtin", "none") == "none":
            model.assets.extend((_ref(el, a, holder), "texturedir") for a in TEXTURE_FILES
                                if el.get(a))


def _ref(el: Any, attr: str, holder: _Where) -> _Ref:
    return _Ref(el.tag, attr, el.get(attr), holder, el.sourceline)


def _parent_tag(el: Any) -> str:
    parent = el.getparent()
    return parent.tag if parent is not None and isinstance(parent.tag, str) else ""


def _compiler(model: _Model, el: Any) -> None:
    asset = el.get("assetdir")
    if asset is not None:
        model.meshdir = model.texturedir = asset
    model.meshdir = el.get("meshdir", model.meshdir)
    model.texturedir = el.get("texturedir", model.texturedir)
    if el.get("strippath") is not None:
        model.strippath = el.get("strippath") == "true"


def _candidates(model: _Model, ref: _Ref, folder: str, name: str) -> list[tuple[Path, str]]:
    """Where MuJoCo looks, in order: the top's folder (and ``folder``), then the holder's."""
    top_dir, top_shown = model.top.path.parent, os.path.dirname(model.top.shown)
    out = [(top_dir / folder / name, os.path.join(top_shown, folder, name))]
    if not ref.holder.top:
        out.append((ref.holder.path.parent / name,
                    os.path.join(os.path.dirname(ref.holder.shown), name)))
    return out


def _find(model: _Model, ref: _Ref, folder: str = "", name: str | None = None) -> _Where:
    """The file MuJoCo opens for ``ref``: the first candidate that exists, if regular."""
    from urdfkit.sources.uris import not_a_file

    tried = []
    for path, shown in _candidates(model, ref, folder, ref.value if name is None else name):
        why = not_a_file(path)
        if why is None:
            return _Where(path, shown, False)
        if why != "missing":
            then = _CONSEQUENCE.get(why, "MuJoCo reads only regular files")
            _refuse(model, ref, f"{shown} is {why}, not a regular file; {then}")
        tried.append(shown)
    _refuse(model, ref, "no such file (looked for " + " and ".join(dict.fromkeys(tried)) + ")")
    raise AssertionError  # pragma: no cover - _refuse raises


def _refuse(model: _Model, ref: _Ref, why: str) -> None:
    value = ref.value if len(ref.value) <= 120 else ref.value[:117] + "..."
    inside = "" if ref.holder.shown == model.root else f" (read for {model.root})"
    raise InputError(f"<{ref.tag} {ref.attr}={value!r}>: {why}{inside}",
                     file=ref.holder.shown, line=ref.line)


def _include(model: _Model, ref: _Ref) -> _Where:
    found = _find(model, ref)
    real = _real(found.path)
    first = model.included.get(real)
    if first is not None:
        _refuse(model, ref, f"{found.shown} is already included (as {first}); MuJoCo "
                "includes a file once")
    model.included[real] = found.shown
    return found


def _folder(model: _Model, ref: _Ref, kind: str) -> tuple[str, str]:
    """The folder an asset is looked for in, and its name as MuJoCo reads it."""
    folder = model.meshdir if kind == "meshdir" else model.texturedir
    return folder, os.path.basename(ref.value) if model.strippath else ref.value


def _sub_models(model: _Model) -> list[_Model]:
    out = []
    here = _real(model.top.path)
    for ref in model.models:
        found = _find(model, ref)
        if _real(found.path) in (here, *model.ancestors):
            _refuse(model, ref, f"{found.shown} is a model this one is part of; MuJoCo "
                    "would recurse until it crashes")
        out.append(_Model(_Where(found.path, found.shown, True), model.root,
                          (*model.ancestors, here)))
    return out
