"""``urdfkit build``: a template or a xacro file in, checked URDF bytes out.

A template is built by urdfkit's own model, strictly. A xacro file is expanded and written as
PyBullet would load it: what would crash PyBullet (the guard's refusals) is refused, with the
file and line it was written on; every other ``check`` error (an inertia that is not positive
definite, a mass of 0 on a moving link) is reported as a warning and the file is written, as
PyBullet loads it. What PyBullet would refuse to load (a missing mesh, an ``<inertial>``
without ``<inertia>``: :data:`PYBULLET_REFUSES`) is never written (exit 1). ``strict`` makes
every error refuse the build (exit 1, nothing written).
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field
from pathlib import Path

from lxml import etree

from urdfkit.checks.validate import ALL_RULES
from urdfkit.core.errors import InputError, ParameterError
from urdfkit.core.finding import Finding
from urdfkit.core.output import atomic_write
from urdfkit.model.catalog import TEMPLATES, build_template, parse_assignments
from urdfkit.model.xmlio import parse_xml, read_bytes, to_bytes, xacro_marker
from urdfkit.sources.expand import expand_xacro
from urdfkit.sources.guard import GUARD_CODES, guard_findings, run_rules
from urdfkit.sources.resolve import locate
from urdfkit.sources.uris import pybullet_data_path


@dataclass
class BuildResult:
    """A built URDF, not yet written.

    Attributes:
        data: The URDF bytes.
        default_output: The file name to write when none is given.
        links: How many links it has.
        joints: How many joints.
        warnings: ``check``'s errors on it (a xacro build writes them as warnings), each
            ``file[:line]: message (code)`` with the file and line it was written on.
        base: The folder its relative mesh and texture paths start from (the xacro file's),
            or None (a template names no files).
    """

    data: bytes
    default_output: str
    links: int
    joints: int
    warnings: list[str] = field(default_factory=list)
    base: Path | None = None

    def written_at(self, out: str | Path) -> tuple[bytes, list[tuple[str, str]]]:
        """The bytes to write at ``out``, and the ``(old, new)`` paths rewritten for it.

        Written in another folder than the xacro file's, each relative mesh and texture path
        is rewritten to name the same file from there
        (:func:`urdfkit.sources.uris.rebased`), so the file loads where it is written.
        """
        from urdfkit.model.spec import FILE_TAGS
        from urdfkit.sources.uris import rebased

        if self.base is None:
            return self.data, []
        folder = Path(out).expanduser().absolute().parent
        root = parse_xml(self.data, str(out)).getroot()
        moved = []
        for el in root.iter(*FILE_TAGS):
            old = el.get("filename")
            new = None if old is None else rebased(old, self.base, folder)
            if old is not None and new is not None:
                el.set("filename", new)
                moved.append((old, new))
        return (to_bytes(root) if moved else self.data), moved


class BuildFindings(InputError):
    """``strict``: the expanded file has ``check`` errors; nothing is written (exit 1)."""

    exit_code = 1


def _where(f: Finding) -> str:
    """Where a finding on xacro output was written: its origin, else the file alone."""
    return f.origin if f.origin else f.file


def build(target: str, params: list[str] | None = None,
          xacro_args: list[str] | None = None,
          packages: Mapping[str, Path] | None = None, strict: bool = False) -> BuildResult:
    """Build ``target``: a built-in template name, or a path to a ``.xacro`` file.

    ``packages`` (a :class:`~urdfkit.sources.uris.PackageIndex` or ``NAME: PATH`` pairs) answers the
    file's ``$(find NAME)`` and ``package://NAME`` references, as in every loading command.
    A ``.urdf`` that holds xacro (``${...}``, ``$(arg ...)``, ``<xacro:...>``) is expanded
    like a ``.xacro``. ``strict``: see the module docstring.

    Raises:
        InputError: the file cannot be expanded, or holds what crashes PyBullet.
        BuildFindings: ``strict``, and ``check`` finds errors in the expanded file.
    """
    if target in TEMPLATES:
        if xacro_args:
            raise ParameterError("`xacro_args` are for xacro files, not templates",
                                 param="xacro_args")
        robot = build_template(target, parse_assignments(params))
        data = robot.to_bytes()
        default = f"{target}.urdf"
        name = f"template {target}"
        base = None
    else:
        path = Path(target)
        pybullet_data = None if path.is_absolute() else pybullet_data_path()
        # A bare name is looked up in pybullet_data, as every command looks it up (locate).
        if path.suffix != ".xacro" and not path.exists() and not (
                pybullet_data is not None and (pybullet_data / path).is_file()):
            from urdfkit.core.suggest import files, hint

            known = ", ".join(TEMPLATES)
            close = [repr(f) for f in files(target)]
            more = hint(target, TEMPLATES) or (f"; did you mean {' or '.join(close)}?"
                                               if close else "")
            raise ParameterError(f"'{target}' is neither a template ({known}) nor a file{more}")
        if params:
            raise ParameterError("`params` are for built-in templates; xacro files take "
                                 "`xacro_args`", param="params")
        source = locate(target)
        if source.suffix != ".xacro" and xacro_marker(read_bytes(source)) is None:
            raise InputError("build takes a template name or a xacro file; this file is "
                             "already URDF (it holds no xacro)", file=target)
        return _build_xacro(source, target, parse_assignments(xacro_args, "xacro_args"),
                            packages, strict)
    # The same rules `urdfkit check` runs: what build writes, check accepts.
    tree = parse_xml(data, name)
    errors = [f for f in run_rules(tree.getroot(), name, ALL_RULES, base=base, packages=packages)
              if f.level == "error"]
    if errors:
        raise InputError(f"the built URDF is invalid: {errors[0].message} ({errors[0].code})",
                         file=name)
    return BuildResult(data, default, len(robot.links), len(robot.joints),
                       warnings=start_pose_contacts(data, target))


def start_pose_contacts(data: bytes, template: str) -> list[str]:
    """Link pairs of a built template in contact at its start pose, each said with its depth.

    A template's ``--set`` values can put one part inside another (a wider body around the
    front wheels): PyBullet loads it, and pushes the pair apart every step once self-collision
    is on. Tested as ``urdfkit collisions`` tests it (one PyBullet load, ~50 ms).
    """
    import tempfile

    from urdfkit.checks.collisions import self_collisions
    from urdfkit.sources.resolve import resolve

    with tempfile.TemporaryDirectory(prefix="urdfkit-build-") as tmp:
        path = Path(tmp) / f"{template}.urdf"
        path.write_bytes(data)
        with resolve(path) as resolved:
            resolved.name = f"template {template}"
            found = self_collisions(resolved)
    return [f"template {template}: links {x.link_a!r} and {x.link_b!r} "
            f"{'interpenetrate by' if x.distance < 0 else 'touch at'} "
            f"{abs(x.distance) * 1000:.3g} mm at the start pose (urdfkit collisions would "
            "report them; self-collision makes them jitter): change the --set values that "
            "place them" for x in found.pairs]


def _build_xacro(source: Path, target: str, args: Mapping[str, str],
                 packages: Mapping[str, Path] | None, strict: bool) -> BuildResult:
    """Expand, refuse only what crashes PyBullet, and report check's errors as warnings."""
    expanded = expand_xacro(source, args, display=target, packages=packages)
    tree = parse_xml(expanded, target)
    root = tree.getroot()
    origins = expanded.origins
    refused = [f for f in guard_findings(root, target, origins) if f.code in GUARD_CODES]
    if refused:
        f = refused[0]
        # The line of xacro's output means nothing to the user: the element's own file and
        # line when xacro says where it was written, else the file alone.
        at, _, line = (f.origin or "").rpartition(":")
        raise InputError(f.message, file=at or target,
                         line=int(line) if at and line.isdigit() else None)
    findings = run_rules(root, target, ALL_RULES, base=source.resolve().parent,
                         packages=packages, origins=origins)
    errors = [f for f in findings if f.level == "error"]
    unloadable = _unloadable(root, source.resolve().parent, packages)
    refused_too = [f for f in errors if f.code in PYBULLET_REFUSES]
    if unloadable is not None or refused_too:
        if unloadable is not None:
            code, text = unloadable
            # check reported it too, with where it was written (xacro's origin)
            same = next((f for f in errors if f.code == code and f.message == text), None)
            message, at = f"{text} ({code})", _where(same) if same else target
        else:
            message, at = f"{refused_too[0].message} ({refused_too[0].code})", \
                _where(refused_too[0])
        raise BuildFindings(f"PyBullet refuses the expanded file: {message}; nothing written "
                            "(a mesh in another package: --package NAME=PATH or "
                            "--package-path)", file=at)
    if strict and errors:
        f = errors[0]
        more = f" (and {len(errors) - 1} more)" if len(errors) > 1 else ""
        raise BuildFindings(f"{f.message} ({f.code}){more}; nothing written (--strict)",
                            file=_where(f))
    if source.suffix == ".xacro":
        default = source.name.removesuffix(".xacro")
        if not default.endswith(".urdf"):
            default += ".urdf"
    else:  # a .urdf holding xacro: never the input's own name
        default = f"{source.stem}.expanded.urdf"
    # Every error left is one PyBullet loads the file with (those it refuses are refused
    # above, measured against raw loadURDF in tests/test_cli_build.py).
    warnings = [f"{_where(f)}: {f.message} ({f.code}); PyBullet loads it as written"
                for f in errors]
    links = sum(1 for el in root if el.tag == "link")
    joints = sum(1 for el in root if el.tag == "joint")
    return BuildResult(to_bytes(root), default, links, joints, warnings,
                       base=source.absolute().parent)


#: check's error codes for what makes ``p.loadURDF`` fail outright (docs/check.md): a
#: ``<geometry>`` without a shape or not first, a ``<visual>``/``<collision>`` without
#: ``<geometry>``, an ``<inertial>`` without (a whole) ``<inertia>``, a visual's material
#: without a name, a revolute/prismatic joint without ``<limit>``. Files are judged apart
#: (:func:`_unloadable`), as the loaders judge them.
PYBULLET_REFUSES = frozenset({"U110", "U302", "U502", "U505", "U506", "U609", "U610"})


def _unloadable(root: etree._Element, base: Path, packages: Mapping[str, Path] | None
                ) -> tuple[str, str] | None:
    """(code, message) of the first file reference PyBullet refuses the URDF for, else None.

    The loaders' rule (:func:`urdfkit.sources.resolve.resolve`): a mesh or SDF that is missing,
    not a regular file or in a format PyBullet does not read, or any reference to an unknown
    package or a FIFO/device; a missing texture is drawn without. A mesh file PyBullet
    crashes or hangs on (:func:`urdfkit.sources.guard.mesh_crash`, U712-U713) is refused too.
    """
    from urdfkit.model.spec import FILE_SHAPES, FILE_TAGS, ignored_shape
    from urdfkit.sources.references import mesh_crash, reference

    for el in root.iter(*FILE_TAGS):
        fn = (el.get("filename") or "").strip()
        if not fn or ignored_shape(el):
            continue
        ref = reference(str(el.tag), fn, base, packages)
        if ref.level == "error" and ref.code is not None and (
                el.tag in FILE_SHAPES or ref.code in ("U702", "U704")):
            return ref.code, ref.message
        crash = mesh_crash(el, ref) if el.tag == "mesh" else None
        if crash is not None:
            return crash
    return None


def unreachable_packages(data: bytes, out: Path) -> str | None:
    """A warning when raw PyBullet cannot find the written file's ``package://`` files.

    urdfkit finds packages by their package.xml (``--package-path``, ROS_PACKAGE_PATH);
    PyBullet drops ``package://`` and looks for ``NAME/rest`` in the file's folder and each
    folder above it. A package nested in a workspace (create3_sim's
    irobot_create_common/irobot_create_description, which turtlebot4 includes) is then out
    of its reach wherever the file is written outside it: ``p.loadURDF`` says "Cannot load
    URDF file." None when every such file is found from ``out``'s folder.
    """
    from urdfkit.sources.uris import pybullet_search

    folder = out.resolve().parent
    lost: dict[str, None] = {}
    # As urdfkit read it (undeclared namespace prefixes too: fix keeps the file's bytes).
    for el in parse_xml(data, out).getroot().iter("mesh", "texture"):
        fn = (el.get("filename") or "").strip()
        if fn.startswith("package://") and \
                pybullet_search(fn[len("package://"):], folder) is None:
            lost[fn] = None
    if not lost:
        return None
    names = list(lost)
    shown = ", ".join(names[:3]) + (f" and {len(names) - 3} more" if len(names) > 3 else "")
    return (f"{out}: raw p.loadURDF will not find {len(names)} package:// file(s) from "
            f"{folder} ({shown}): PyBullet looks for NAME/... in the file's folder and those "
            "above it, and knows no package.xml; load it through urdfkit (--package-path), or "
            "write it inside the folder that holds those packages")


def write_output(path: str, data: bytes, *, force: bool) -> Path:
    """Write atomically, never replacing a file without ``force``."""
    return atomic_write(path, data, force=force)
