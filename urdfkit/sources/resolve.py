"""From a name on the command line to a checked URDF file PyBullet can load.

``resolve`` does, in order:

1. find the file: as given (relative to the current folder), else in ``pybullet_data``, the
   way ``p.loadURDF("r2d2.urdf")`` finds it after ``setAdditionalSearchPath``;
2. expand ``.xacro`` in a subprocess with a timeout (xacro's ``${}`` runs Python code: it is
   not a sandbox, and a hostile file must not hang or own the process);
3. parse it safely and run the crash guard;
4. resolve ``package://NAME/...`` through ``--package NAME=PATH`` or by walking up from the
   file, and make relative mesh paths absolute, writing a rewritten copy to a temp folder only
   when something changed.
"""

from __future__ import annotations

import os
from collections.abc import Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from lxml import etree

from urdfkit.core.errors import InputError
from urdfkit.core.finding import Finding
from urdfkit.model.spec import (
    BUILT_CHILDREN,
    FILE_SHAPES,
    FILE_TAGS,
    PYBULLET_LINE_BYTES,
    SCHEMA,
    did_you_mean,
    ignored_shape,
    nearest_tags,
    used_shape,
)
from urdfkit.model.xmlio import (
    line_of,
    long_line,
    parse_xml,
    read_bytes,
    to_bytes,
    undeclared_prefixes,
    xacro_marker,
    xacro_note,
)
from urdfkit.sources.expand import expand_xacro
from urdfkit.sources.guard import GUARD_WARNINGS, STRICTER, refuse_oversized
from urdfkit.sources.guard import guard as run_guard
from urdfkit.sources.references import mesh_crash, reference
from urdfkit.sources.uris import not_a_file, pybullet_data_path
from urdfkit.sources.uris import (
    parse_packages as parse_packages,  # re-exported: callers import it here
)


def _clip(text: str, most: int = 120) -> str:
    """``text`` quoted, or its start and its length when longer than ``most``."""
    return repr(text) if len(text) <= most else f"{text[:most]!r}... ({len(text)} characters)"


def locate(name: str | Path) -> Path:
    """Find a file as given, else in pybullet_data, else a built-in template's; refuse folders.

    A bare template name (``simplecar``) that is no file here nor in pybullet_data is the
    template built with its defaults (:func:`urdfkit.sources.builtin.template_file`), as
    ``drive`` drives it.
    """
    path = Path(name).expanduser()
    why = not_a_file(path)
    if why is None:
        return path
    if why != "missing":
        raise InputError(f"is {why}, not a URDF file", file=name)
    if path.is_symlink():  # the name is there: no "did you mean" the same name
        raise InputError("no such file: it is a symlink to nothing (its target "
                         f"{_clip(os.readlink(path))} does not exist)", file=name)
    data = None if path.is_absolute() else pybullet_data_path()
    if data is not None and (data / path).is_file():
        return data / path
    from urdfkit.sources.builtin import template_file, template_names

    built = template_file(str(name))
    if built is not None:
        return built
    from urdfkit.core.suggest import close as close_names
    from urdfkit.core.suggest import files

    close = [c for c in files(str(name), data) if c != str(name)]
    if os.sep not in str(name):
        close += close_names(str(name), template_names())
    more = f"; did you mean {' or '.join(repr(c) for c in close)}?" if close else ""
    where = "" if path.is_absolute() else \
        " (looked in the current folder, in pybullet_data and among the built-in templates)"
    raise InputError(f"no such file{where}{more}", file=name)


def where(f: Finding) -> str:
    """``file:line`` of a finding."""
    return f.file if f.line is None else f"{f.file}:{f.line}"


def _utf8(text: str) -> bool:
    try:
        text.encode("utf-8")
    except UnicodeEncodeError:
        return False
    return True


@dataclass
class Resolved:
    """A located, expanded, parsed and guarded URDF.

    Attributes:
        name: The file as the user named it (used in every message).
        source: The file found on disk (the xacro itself for xacro input).
        load_path: What to hand to ``loadURDF``: ``source`` or a rewritten temp copy.
        tree: The parsed document (after xacro and package:// rewriting).
    """

    name: str
    source: Path
    load_path: Path
    tree: etree._ElementTree
    _tmp: Any = field(default=None, repr=False)  # a TemporaryDirectory, when we made a copy
    warnings: list[str] = field(default_factory=list)

    @property
    def root(self) -> etree._Element:
        """The ``<robot>`` element."""
        return self.tree.getroot()

    @property
    def robot_name(self) -> str:
        """The robot's name attribute."""
        return self.root.get("name", "")

    def close(self) -> None:
        """Remove the temp copy, if any."""
        if self._tmp is not None:
            self._tmp.cleanup()
            self._tmp = None

    def __enter__(self) -> Resolved:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()


def _check_files(root: etree._Element, base: Path, packages: Mapping[str, Path],
                 name: str) -> bool:
    """Refuse what PyBullet cannot load, and point every reference at an absolute path.

    Returns whether PyBullet needs the rewritten copy: a ``package://`` or ``file://``
    reference, or a mesh found only in pybullet_data.

    Each reference is judged by :func:`urdfkit.sources.guard.reference`, the rule ``check`` runs:
    a missing or unreadable mesh, a folder/FIFO/device, a format PyBullet does not read, an
    unknown package is one line naming the file and the URDF line, before PyBullet sees it
    (which would fail with "Could not parse visual element", hang or abort). So is a mesh
    file PyBullet crashes or hangs on (:func:`urdfkit.sources.guard.mesh_crash`, U712-U713). A
    missing texture is left to PyBullet, which warns and draws without it.
    """
    changed = False
    for el in root.iter(*FILE_TAGS):
        fn = el.get("filename")
        if not fn or ignored_shape(el):  # PyBullet never opens a shape after the first
            continue
        ref = reference(str(el.tag), fn.strip(), base, packages)
        if ref.level == "error" and ref.code is not None and (
                el.tag in FILE_SHAPES or ref.code in ("U702", "U704")):
            raise InputError(ref.message, file=name, line=line_of(el))
        crash = mesh_crash(el, ref) if el.tag == "mesh" else None
        if crash is not None:
            raise InputError(crash[1], file=name, line=line_of(el))
        if ref.load_path is not None:
            changed |= ref.code == "U703" or fn.startswith(("package://", "file://"))
            el.set("filename", str(ref.load_path.resolve()))
    return changed


def resolve(name: str | Path, *, packages: Mapping[str, Path] | None = None,
            xacro_args: Mapping[str, str] | None = None, guard: bool = True,
            strict_args: bool = True, meshes: bool = True) -> Resolved:
    """Locate, expand, parse, guard and package-resolve a URDF for loading.

    With ``guard=False`` the guard's refusals that are stricter than PyBullet (see
    :data:`urdfkit.sources.guard.LIFTABLE_CODES`) become :attr:`Resolved.warnings`; whatever
    crashes PyBullet is refused either way. ``strict_args=False`` lets a xacro file ignore
    ``xacro_args`` it does not take (``check`` passes one set to every file). With
    ``meshes=False`` (``tree``, which reads the file only) a mesh that cannot be found or
    loaded is a warning, not a refusal.
    """
    display = str(name)
    source = locate(name)
    if source.suffix == ".xacro":
        expanded = expand_xacro(source, xacro_args, display=display, packages=packages,
                                strict_args=strict_args)
        try:
            return _resolve_tree(source, display, parse_xml(expanded, display), packages,
                                 guard, copy=True, origins=expanded.origins, meshes=meshes)
        except InputError as e:
            # Lines of xacro's output are not lines of the file the user wrote: say none
            # rather than a false one (the message names the element and, where recovered,
            # the file and line it was written on).
            raise type(e)(e.message, file=e.file, param=e.param) from None
    else:
        data = read_bytes(source)
        refuse_oversized(data, display)  # before a tree of 280,000 links is built
        # PyBullet breaks lines over 8191 bytes (and may then refuse or misread the file): it
        # gets a reformatted copy, one element per line.
        resolved = _resolve_tree(source, display, parse_xml(data, display), packages, guard,
                                 copy=long_line(data) is not None, meshes=meshes)
        # Read though libxml2 refuses it, as PyBullet reads it: said, as check says it (U004).
        resolved.warnings[:0] = [f"{display}:{line}: {note}"
                                 for line, note in undeclared_prefixes(data)]
        xacro = xacro_marker(data)
        if xacro is not None:
            resolved.warnings.insert(0, f"{display}:{xacro[0]}: {xacro_note(xacro[1])} (U009)")
        return resolved


def misspelt_tags(root: etree._Element) -> list[tuple[int | None, str]]:
    """Unknown tags nearest a tag PyBullet builds from (``<jiont>``, ``<colision>``), said.

    PyBullet skips an element it does not know without a word, so a typo in one of these
    changes the robot it builds (a joint it never sees, a collision it drops). One walk over
    the robot's children and theirs, two levels down: what ``check`` reports as U801.
    """
    out: list[tuple[int | None, str]] = []

    def look(el: etree._Element, depth: int) -> None:
        parent = str(el.tag)
        known = SCHEMA.get(parent)
        built = BUILT_CHILDREN.get(parent)
        if known is None or built is None:
            return
        for child in el:
            tag = child.tag
            if not isinstance(tag, str) or tag[:1] == "{":
                continue
            if tag not in known[1]:
                near = [n for n in nearest_tags(tag, parent) if n in built]
                if near:
                    out.append((line_of(child), f"<{tag}> is not a URDF tag inside <{el.tag!s}>"
                                f"{did_you_mean(near)} PyBullet builds the robot without it "
                                "(U801)"))
            elif depth < 2:
                look(child, depth + 1)

    look(root, 0)
    return out


def _resolve_tree(source: Path, display: str, tree: etree._ElementTree,
                  packages: Mapping[str, Path] | None, guard: bool,
                  copy: bool = False, origins: list[str | None] | None = None,
                  meshes: bool = True) -> Resolved:
    root = tree.getroot()
    # xacro's output lines are not the user's: its typos are said without one
    typos = [(None if origins is not None else line, typo) for line, typo in misspelt_tags(root)]
    try:
        found = run_guard(tree, display, strict=guard, origins=origins)
    except InputError as e:
        if not typos:
            raise
        # "2 root links" is what a misspelt <joint> looks like to the guard: name the cause.
        line, typo = typos[0]
        at = "" if line is None else f"at line {line}, "
        raise type(e)(f"{e.message}; {at}{typo}", file=e.file, line=e.line,
                      param=e.param) from None
    lifted = [f"{display}{'' if line is None else f':{line}'}: {typo}" for line, typo in typos]
    lifted += [f"{where(f)}: {f.message} ({f.code})" if f.code in GUARD_WARNINGS else
               f"{where(f)}: let through without the guard ({f.code}): "
               f"{f.message.removesuffix(STRICTER)}" for f in found]
    # PyBullet takes paths as UTF-8 text: a file name that is not (bytes from another locale,
    # kept by Python as surrogates) is loaded from a copy with a clean name.
    needs_copy = copy or not _utf8(str(source))
    try:
        needs_copy = _check_files(root, source.resolve().parent, packages or {}, display) \
            or needs_copy
    except InputError as e:
        if meshes:
            raise
        # Only the file is read (tree): a mesh it names is not needed, so its problem is a
        # note; the tree is built from the file as written.
        lifted.append(f"{e}: not needed to read the tree" if e.file else str(e))
    if needs_copy:
        import tempfile  # here, not at the top: most loads need no copy

        tmp = tempfile.TemporaryDirectory(prefix="urdfkit-")
        name = source.name.removesuffix(".xacro") if _utf8(source.name) else "robot.urdf"
        load_path = Path(tmp.name) / (name or "robot.urdf")
        if load_path.suffix != ".urdf":
            load_path = load_path.with_suffix(load_path.suffix + ".urdf")
        for el in root.iter(*FILE_TAGS):
            if not _utf8(el.get("filename") or ""):
                tmp.cleanup()
                raise InputError("PyBullet cannot open a mesh whose path is not valid UTF-8: "
                                 f"{el.get('filename')!r}", file=display, line=line_of(el))
        body = to_bytes(root)
        if long_line(body) is not None:  # a long comment is harmless, but costs nothing to drop
            for comment in list(root.iter(etree.Comment)):
                parent = comment.getparent()
                if parent is not None:
                    parent.remove(comment)  # (lxml keeps the comment's tail text)
            body = to_bytes(root)
        too_long = long_line(body)
        if too_long is not None:
            tmp.cleanup()
            raise InputError(f"an element of {too_long[1]} bytes on one line even when "
                             f"formatted; PyBullet breaks lines every {PYBULLET_LINE_BYTES} "
                             "bytes and misreads them: shorten its attributes", file=display)
        load_path.write_bytes(body)
        return Resolved(display, source, load_path, tree, tmp, warnings=lifted)
    return Resolved(display, source, source, tree, warnings=lifted)


def undrawn_visuals(resolved: Resolved) -> tuple[int, list[str]]:
    """How many visual shapes the robot has, and why each one PyBullet cannot draw is not.

    For ``render`` and ``view`` to say how much of the robot is missing from the picture
    (check's U715 says it of the file): an empty mesh file, COLLADA through ``<instance_node>``.
    """
    from urdfkit.sources.meshes import mesh_kind, undrawn_visual
    from urdfkit.sources.references import reference

    total, out = 0, []
    base = resolved.source.resolve().parent
    for visual in resolved.root.iter("visual"):
        total += 1
        geometry = visual.find("geometry")
        mesh = used_shape(geometry) if geometry is not None else None
        fn = (mesh.get("filename") or "").strip() if mesh is not None and \
            mesh.tag == "mesh" else ""
        if not fn:
            continue
        ref = reference("mesh", fn, base, None)
        if ref.load is None or (mesh_kind(ref.load) != ".dae" and (
                ref.stat is None or ref.stat.st_size != 0)):
            continue
        why = undrawn_visual(ref.load)
        if why is not None:
            link = visual.getparent()
            owner = link.get("name") if link is not None else None
            out.append(f"{fn!r} of link {owner!r} {why}")
    return total, out


def undrawn_note(resolved: Resolved) -> str | None:
    """``"2 of 7 visual shapes cannot be drawn: ..."``, or None when every one can."""
    total, why = undrawn_visuals(resolved)
    if not why:
        return None
    more = f" (and {len(why) - 1} more)" if len(why) > 1 else ""
    return (f"{resolved.name}: {len(why)} of {total} visual shape(s) cannot be drawn, so "
            f"the picture misses them: {why[0]}{more} (U715)")


def open_input(name: str | Path, *, packages: list[str] | None = None,
               xacro_args: list[str] | None = None, guard: bool = True,
               package_paths: list[str] | None = None, meshes: bool = True) -> Resolved:
    """:func:`resolve` with the raw ``--package NAME=PATH`` and ``--arg k:=v`` option lists.

    The options are keyword-only, so no call can pass ``guard`` where ``packages`` goes; the
    command line's flags reach here through
    :func:`urdfkit.commands.shared.open_input_and_warn`.
    """
    args: dict[str, str] = {}
    if xacro_args:
        # Only now: catalog pulls in the builder model (~15 ms), which plain loads never need.
        from urdfkit.model.catalog import parse_assignments

        args = dict(parse_assignments(xacro_args, "xacro_args"))
    return resolve(name, packages=parse_packages(packages, package_paths), xacro_args=args,
                   guard=guard, meshes=meshes)
