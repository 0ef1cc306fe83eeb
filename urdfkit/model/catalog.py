"""The built-in templates: their typed parameters, and building a robot from one.

A template is a xacro file in ``templates/`` (shipped as ``urdfkit.templates``) plus the typed
parameter list below. Parameters are checked here, before xacro runs, so a bad value fails with
a message that names the parameter rather than some link deep in the output.

Built-in templates are our own files, so they are expanded in-process (fast: ``drive`` builds
simplecar on every run). A user's xacro may run arbitrary code and goes through
:func:`urdfkit.sources.expand.expand_xacro` in a subprocess instead.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Mapping
from dataclasses import dataclass, field
from typing import Any, Literal

from urdfkit.core.errors import ParameterError
from urdfkit.model.robot import Robot
from urdfkit.model.templatedir import template_dir

#: A template parameter's type: one number, three, or one word of ``choices``.
ParamKind = Literal["float", "vec3", "choice"]


@dataclass(frozen=True)
class Param:
    """A typed template parameter.

    Attributes:
        name: The key users pass with ``--set name=value``.
        kind: ``"float"``, ``"vec3"`` (three numbers) or ``"choice"`` (one of ``choices``).
        default: The value when none is given.
        help: One line for ``urdfkit templates``.
        minimum: Values must be above this (or equal, if ``inclusive``).
        maximum: Values must be at most this.
        inclusive: Whether ``minimum`` itself is allowed.
        to_args: Maps the value to xacro ``arg`` names; by default ``{name: value}``.
        choices: The words a ``"choice"`` parameter takes.
    """

    name: str
    kind: ParamKind
    default: Any
    help: str
    minimum: float | None = 0.0
    maximum: float | None = None
    inclusive: bool = False
    to_args: Callable[[Any], dict[str, float]] | None = None
    choices: tuple[str, ...] = ()

    def parse(self, raw: Any) -> Any:
        """Turn a string or number into this parameter's type, checking its range."""
        if self.kind == "choice":
            word = str(raw).strip() if isinstance(raw, str) else raw
            if word not in self.choices:
                raise ParameterError(f"parameter '{self.name}' expects one of "
                                     f"{', '.join(self.choices)}, got {raw!r}")
            return word
        if self.kind == "vec3":
            items = raw.replace(",", " ").split() if isinstance(raw, str) else raw
            try:
                values = tuple(float(v) for v in items)
            except (TypeError, ValueError):
                raise ParameterError(f"parameter '{self.name}' expects three numbers, "
                                     f"got {raw!r}") from None
            if len(values) != 3:
                raise ParameterError(f"parameter '{self.name}' expects three numbers, "
                                     f"got {len(values)}")
            for v in values:
                self._check_range(v, raw)
            return values
        if isinstance(raw, bool):
            raise ParameterError(f"parameter '{self.name}' expects a number, got {raw!r}")
        try:
            value = float(raw)
        except (TypeError, ValueError):
            raise ParameterError(f"parameter '{self.name}' expects a number, got {raw!r}") from None
        self._check_range(value, raw)
        return value

    def _check_range(self, v: float, raw: Any) -> None:
        if not math.isfinite(v):
            raise ParameterError(f"parameter '{self.name}' must be finite, got {raw!r}")
        if self.minimum is not None:
            if v < self.minimum or (v == self.minimum and not self.inclusive):
                op = ">=" if self.inclusive else ">"
                raise ParameterError(f"parameter '{self.name}' must be {op} {self.minimum:g}, "
                                     f"got {raw!r}")
        if self.maximum is not None and v > self.maximum:
            raise ParameterError(f"parameter '{self.name}' must be <= {self.maximum:g}, "
                                 f"got {raw!r}")

    def args(self, value: Any) -> dict[str, Any]:
        """The xacro arguments this value sets."""
        if self.to_args is not None:
            return self.to_args(value)
        return {self.name: value}

    def show(self, value: Any) -> str:
        """Format a value for people."""
        if isinstance(value, tuple):
            return " ".join(f"{v:g}" for v in value)
        if isinstance(value, str):
            return value
        return f"{value:g}"


@dataclass(frozen=True)
class Template:
    """A built-in template: a xacro file and its parameters."""

    name: str
    file: str
    description: str
    params: tuple[Param, ...] = field(default_factory=tuple)

    def param(self, key: str) -> Param:
        """The parameter called ``key``; unknown keys list the known ones."""
        for p in self.params:
            if p.name == key:
                return p
        from urdfkit.core.suggest import hint

        names = [p.name for p in self.params]
        raise ParameterError(f"template '{self.name}' has no parameter '{key}'"
                             f"{hint(key, names)} (known: {', '.join(names)})", param="params")

    def resolve(self, values: Mapping[str, Any] | None = None) -> dict[str, Any]:
        """Every parameter's value: the defaults overridden by ``values``, checked."""
        out = {p.name: p.default for p in self.params}
        for key, raw in (values or {}).items():
            out[key] = self.param(key).parse(raw)
        return out

    def xacro_args(self, values: Mapping[str, Any] | None = None) -> dict[str, str]:
        """The xacro ``arg`` mappings for these parameter values."""
        resolved = self.resolve(values)
        args: dict[str, str] = {}
        for p in self.params:
            for k, v in p.args(resolved[p.name]).items():
                args[k] = v if isinstance(v, str) else repr(float(v))
        return args

    def source(self) -> str:
        """The template's xacro text."""
        return (template_dir() / self.file).read_text("utf-8")


def _body_size_args(v: tuple[float, float, float]) -> dict[str, float]:
    return {"body_length": v[0], "body_width": v[1], "body_height": v[2]}


TEMPLATES: dict[str, Template] = {
    t.name: t
    for t in (
        Template(
            "simplecar", "simplecar.urdf.xacro",
            "The PyBullet tutorial car: box body, steered front wheels, driven rear wheels.",
            (
                Param("wheel_radius", "float", 0.1, "Wheel radius (m)"),
                Param("wheel_width", "float", 0.05, "Wheel width (m)"),
                Param("wheel_mass", "float", 0.3, "Mass of each wheel (kg)"),
                Param("wheelbase", "float", 0.4, "Distance from rear to front axle (m)"),
                Param("track", "float", 0.35, "Distance between the rear wheel centres (m)"),
                Param("front_track", "float", 0.4, "Distance between the front wheel centres (m)"),
                Param("body_size", "vec3", (0.5, 0.3, 0.1), "Body box length, width, height (m)",
                      to_args=_body_size_args),
                Param("body_mass", "float", 6.0, "Body mass (kg)"),
                Param("hinge_mass", "float", 0.01, "Mass of each steering hinge (kg)"),
                Param("steer_limit", "float", 0.5, "Steering hinge limit, +- (rad)",
                      maximum=math.pi / 2),
                Param("lateral_friction", "float", 1.0, "Tyre lateral friction coefficient",
                      inclusive=True),
            ),
        ),
        Template(
            "simpleplane", "simpleplane.urdf.xacro",
            "A static ground with high friction: a slab whose top is z = 0 (the default), "
            "PyBullet's infinite plane, or the tutorial's 20 x 20 m box.",
            (
                Param("shape", "choice", "slab", "slab: a box whose top face is z = 0 (wheels "
                      "roll straight); plane: PyBullet's infinite plane at z = 0; box: the "
                      "tutorial's box centred on its origin", minimum=None,
                      choices=("slab", "plane", "box")),
                Param("size", "float", 20.0, "Side length of the square drawn (m); the box's too"),
                Param("thickness", "float", 0.01, "Thickness of the box (m)"),
                Param("lateral_friction", "float", 4.0, "Ground lateral friction coefficient",
                      inclusive=True),
            ),
        ),
    )
}


def get_template(name: str) -> Template:
    """The built-in template called ``name``."""
    try:
        return TEMPLATES[name]
    except KeyError:
        from urdfkit.core.suggest import hint

        raise ParameterError(f"no template named '{name}'{hint(name, TEMPLATES)} (known: "
                             f"{', '.join(TEMPLATES)})") from None


def parse_assignments(items: list[str] | None, param: str = "params") -> dict[str, str]:
    """Parse repeated ``key=value`` (or ``key:=value``) items into a dict.

    ``param`` names the argument they came in, for the error message.
    """
    out: dict[str, str] = {}
    for item in items or []:
        key, sep, value = item.replace(":=", "=", 1).partition("=")
        if not sep or not key.strip():
            raise ParameterError(f"`{param}` expects key=value, got {item!r}", param=param)
        out[key.strip()] = value.strip()
    return out


def expand_template(name: str, values: Mapping[str, Any] | None = None) -> bytes:
    """Expand a built-in template to URDF bytes (in-process: these files are ours)."""
    template = get_template(name)
    args = template.xacro_args(values)
    import xacro

    try:
        doc = xacro.process_file(str(template_dir() / template.file), mappings=args)
    except Exception as e:  # xacro raises plain Exceptions
        raise ParameterError(f"template '{name}' failed to expand: {e}") from None
    return doc.toxml(encoding="utf-8")


def build_template(name: str, values: Mapping[str, Any] | None = None) -> Robot:
    """Build a built-in template into a checked :class:`Robot`."""
    robot = Robot.from_string(expand_template(name, values), file=f"<template {name}>")
    robot.complete_inertia()
    return robot
