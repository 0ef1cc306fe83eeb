"""``urdfkit build``: a template or a xacro file in, checked URDF bytes out."""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field
from pathlib import Path

from .builder import Robot
from .catalog import TEMPLATES, build_template, parse_assignments
from .errors import InputError, ParameterError
from .expand import expand_xacro
from .output import atomic_write
from .resolve import locate
from .validate import ALL_RULES, guard, run_rules
from .xmlio import parse_xml, to_bytes


@dataclass
class BuildResult:
    """A built URDF, not yet written."""

    data: bytes
    default_output: str
    links: int
    joints: int
    warnings: list[str] = field(default_factory=list)


def build(target: str, params: list[str] | None = None,
          xacro_args: list[str] | None = None,
          packages: Mapping[str, Path] | None = None) -> BuildResult:
    """Build ``target``: a built-in template name, or a path to a ``.xacro`` file.

    ``packages`` (a :class:`~urdfkit.uris.PackageIndex` or ``NAME: PATH`` pairs) answers the
    file's ``$(find NAME)`` and ``package://NAME`` references, as in every loading command.
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
        if path.suffix != ".xacro" and not path.exists():
            from .suggest import files, hint

            known = ", ".join(TEMPLATES)
            close = [repr(f) for f in files(target)]
            more = hint(target, TEMPLATES) or (f"; did you mean {' or '.join(close)}?"
                                               if close else "")
            raise ParameterError(f"'{target}' is neither a template ({known}) nor a file{more}")
        if params:
            raise ParameterError("`params` are for built-in templates; xacro files take "
                                 "`xacro_args`", param="params")
        source = locate(target)
        if source.suffix != ".xacro":
            raise InputError("build takes a template name or a .xacro file; this file is "
                             "already URDF", file=target)
        expanded = expand_xacro(source, parse_assignments(xacro_args, "xacro_args"),
                                display=target, packages=packages)
        tree = parse_xml(expanded, target)
        guard(tree, target)
        robot = Robot.from_string(expanded, file=target)
        data = to_bytes(tree.getroot())
        default = source.name.removesuffix(".xacro")
        if not default.endswith(".urdf"):
            default += ".urdf"
        name = target
        base = source.resolve().parent
    # The same rules `urdfkit check` runs: what build writes, check accepts.
    tree = parse_xml(data, name)
    errors = [f for f in run_rules(tree.getroot(), name, ALL_RULES, base=base, packages=packages)
              if f.level == "error"]
    if errors:
        raise InputError(f"the built URDF is invalid: {errors[0].message} ({errors[0].code})",
                         file=name)
    return BuildResult(data, default, len(robot.links), len(robot.joints))


def write_output(path: str, data: bytes, *, force: bool) -> Path:
    """Write atomically, never replacing a file without ``force``."""
    return atomic_write(path, data, force=force)
