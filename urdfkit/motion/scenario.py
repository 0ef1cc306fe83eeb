"""The scenario file: what ``urdfkit sim`` reads, checked before anything is simulated.

A scenario is a JSON or TOML document (see ``docs/scenario.md`` for every key). It is
validated with pydantic, imported lazily (it costs ~0.1 s and is an optional extra), into the
models built by :func:`schema`. Every problem is reported with its path in the document, the
way a user would point at it: ``robots[1].drive[0].until: expected a number``.

Checks that need more than the types (a template's parameters, a URDF file that must exist,
segments in time order) run right after pydantic, in :func:`check`, and use the same paths.
Checks that need the loaded body (joint and link names) run in :mod:`urdfkit.sim` and name the
path too.
"""

from __future__ import annotations

import functools
import json
import math
import sys
from collections.abc import Mapping, Sequence
from pathlib import Path
from types import ModuleType
from typing import TYPE_CHECKING, Annotated, Union, get_args, get_origin

from urdfkit.core.errors import InputError, MissingDependencyError, ParameterError
from urdfkit.model.spec import MAX_STEPS

if TYPE_CHECKING:
    from pydantic_core import ErrorDetails

    from urdfkit.motion.scenario_models import (
        DriveSegment,
        JointSegment,
        RobotConfig,
        ScenarioConfig,
    )

#: The observation fields that carry noise; each is a vector or a joint-keyed mapping.
OBSERVATION_FIELDS = (
    "motor_angles", "motor_velocities", "motor_accelerations", "base_position",
    "base_orientation", "base_lin_vel", "base_ang_vel", "base_lin_vel_body_frame",
    "base_ang_vel_body_frame",
)
#: The noise fields of joint-keyed values, and of base 3-vectors.
JOINT_NOISE_FIELDS = ("motor_angles", "motor_velocities", "motor_accelerations", "motor_torques")

_INSTALL_HINT = "urdfkit installs it; reinstall it: pip install --force-reinstall pydantic"


@functools.cache
def schema() -> ModuleType:
    """The pydantic models of a scenario (:mod:`~urdfkit.motion.scenario_models`), imported lazily.

    Returns:
        The module: ``ScenarioConfig`` (the document) and the models it nests,
        ``Physics``, ``Ground``, ``RecordConfig``, ``RobotConfig``, ``DriveSegment``,
        ``Vehicle``, ``JointSegment``,
        ``Motor``, ``InitialJoint``, ``Noise``, ``LinkDynamics``, ``Randomize``.

    Raises:
        MissingDependencyError: pydantic is not installed.
    """
    try:
        import pydantic  # noqa: F401 - the dependency, checked before the models that need it
    except ImportError as e:
        raise MissingDependencyError(f"scenario files need pydantic: {_INSTALL_HINT}") from e
    from urdfkit.motion import scenario_models

    return scenario_models


# --------------------------------------------------------------------------- error paths


def format_path(loc: Sequence[str | int]) -> str:
    """``('robots', 1, 'drive', 0, 'until')`` -> ``robots[1].drive[0].until``."""
    out = ""
    for part in loc:
        if isinstance(part, int):
            out += f"[{part}]"
        else:
            out += f".{part}" if out else str(part)
    return out or "(top level)"


def _peel(tp: object) -> object:
    """Strip Annotated and Optional down to the type that holds the next level."""
    while True:
        origin = get_origin(tp)
        if origin is Annotated:
            tp = get_args(tp)[0]
        elif origin is Union or type(tp).__name__ == "UnionType":
            args = [a for a in get_args(tp) if a is not type(None)]
            tp = args[0]
        else:
            return tp


def _known_keys(root: object, loc: Sequence[str | int]) -> list[str]:
    """The keys the model at ``loc`` accepts (to suggest them after an unknown key)."""
    tp: object = root
    for part in loc:
        tp = _peel(tp)
        fields = getattr(tp, "model_fields", None)
        if isinstance(fields, dict) and isinstance(part, str) and part in fields:
            tp = fields[part].annotation
        elif get_origin(tp) is list and isinstance(part, int):
            tp = get_args(tp)[0]
        elif get_origin(tp) is dict and isinstance(part, str):
            tp = get_args(tp)[1]
        else:
            return []
    fields = getattr(_peel(tp), "model_fields", None)
    return list(fields) if isinstance(fields, dict) else []


def _known_size(root: object, loc: Sequence[str | int]) -> int | None:
    """The fixed length of the vector field at ``loc`` (3 for a position), if it has one."""
    if not loc or not isinstance(loc[-1], str):
        return None
    parent: object = root
    for part in loc[:-1]:
        parent = _peel(parent)
        fields = getattr(parent, "model_fields", None)
        if isinstance(fields, dict) and isinstance(part, str) and part in fields:
            parent = fields[part].annotation
        elif get_origin(parent) in (list, dict):
            parent = get_args(parent)[-1]
        else:
            return None
    fields = getattr(_peel(parent), "model_fields", None)
    if not isinstance(fields, dict) or loc[-1] not in fields:
        return None
    field = fields[loc[-1]]
    metadata = list(field.metadata)
    tp = field.annotation
    for arg in (get_args(tp) if get_origin(tp) is Union or type(tp).__name__ == "UnionType"
                else (tp,)):
        if get_origin(arg) is Annotated:
            for m in arg.__metadata__:  # a Field(...) inside Optional keeps its own metadata
                metadata += list(getattr(m, "metadata", [m]))
    low = {getattr(m, "min_length", None) for m in metadata} - {None}
    high = {getattr(m, "max_length", None) for m in metadata} - {None}
    return low.pop() if len(low) == 1 and low == high else None


#: Parts pydantic adds to an error's location for the member of a union it tried
#: (``constrained-float``, ``dict[str,constrained-float]``): not keys of the document.
_TAG_PREFIXES = ("constrained-", "function-", "json-or-python", "is-instance", "lax-or-strict",
                 "nullable", "tagged-union", "chain")
_TAG_NAMES = frozenset({"float", "int", "str", "bool", "none"})


def key_path(loc: Sequence[str | int]) -> tuple[str | int, ...]:
    """An error location as the document's keys, without pydantic's union-member tags."""
    return tuple(p for p in loc if isinstance(p, int) or not (
        "[" in p or p.startswith(_TAG_PREFIXES) or p in _TAG_NAMES))


def _describe(error: ErrorDetails, root: object) -> str:
    """One pydantic error as ``path: what was expected``."""
    kind = error["type"]
    loc = key_path(error["loc"])
    ctx = error.get("ctx") or {}
    simple = {
        "float_type": "expected a number", "float_parsing": "expected a number",
        "finite_number": "expected a finite number",
        "int_type": "expected an integer", "int_parsing": "expected an integer",
        "int_from_float": "expected an integer",
        "bool_type": "expected true or false", "bool_parsing": "expected true or false",
        "string_type": "expected a string", "list_type": "expected a list",
        "dict_type": "expected an object (a table in TOML)",
        "model_type": "expected an object (a table in TOML)",
        "model_attributes_type": "expected an object (a table in TOML)",
        "missing": "required key is missing",
    }
    if kind in simple:
        message = simple[kind]
    elif kind == "extra_forbidden":
        known = _known_keys(root, loc[:-1])
        message = f"unknown key {loc[-1]!r}" + (f"; known keys: {', '.join(known)}"
                                                 if known else "")
    elif kind == "literal_error":
        message = f"expected {ctx.get('expected', 'one of the allowed values')}"
    elif kind in ("too_short", "too_long"):
        bound = ctx.get("min_length" if kind == "too_short" else "max_length")
        size = _known_size(root, loc)
        if size is not None:
            message = f"expected {size} numbers, got {ctx.get('actual_length')}"
        else:
            least = "at least" if kind == "too_short" else "at most"
            message = (f"expected {least} {bound} item{'' if bound == 1 else 's'}, "
                       f"got {ctx.get('actual_length')}")
    elif kind in ("greater_than", "greater_than_equal", "less_than", "less_than_equal"):
        op = {"greater_than": ">", "greater_than_equal": ">=", "less_than": "<",
              "less_than_equal": "<="}[kind]
        bound = next(iter(ctx.values()), "?")
        message = f"must be {op} {bound}"
    else:
        message = str(error.get("msg", kind)).removeprefix("Value error, ")
    return f"{format_path(loc)}: {message}"


# --------------------------------------------------------------------------- loading


def _no_duplicates(pairs: list[tuple[str, object]]) -> dict[str, object]:
    out: dict[str, object] = {}
    for key, value in pairs:
        if key in out:
            raise ValueError(f"duplicate key {key!r}")
        out[key] = value
    return out


def read_document(path: str | Path) -> dict[str, object]:
    """Read a scenario file's JSON or TOML into plain data (not yet validated).

    Raises:
        InputError: missing, a folder, not .json/.toml, or not parseable (with the line).
    """
    file = Path(path)
    if not file.exists():
        raise InputError("no such file", file=path)
    if file.is_dir():
        raise InputError("is a directory, not a scenario file", file=path)
    suffix = file.suffix.lower()
    if suffix not in (".json", ".toml"):
        raise InputError("a scenario is a .json or .toml file", file=path)
    from urdfkit.model.xmlio import read_regular

    raw = read_regular(file, kind="scenario file")  # never a FIFO, a device, or too much
    try:
        text = raw.decode("utf-8")
    except UnicodeDecodeError as e:
        raise InputError(f"not UTF-8 text (byte {e.start})", file=path) from None
    if suffix == ".toml":
        if sys.version_info >= (3, 11):
            import tomllib
        else:  # pragma: no cover - Python 3.10
            import tomli as tomllib
        try:
            data = tomllib.loads(text)
        except tomllib.TOMLDecodeError as e:
            raise InputError(f"invalid TOML: {e}", file=path) from None
        except RecursionError:
            raise InputError(_TOO_DEEP, file=path) from None
    else:
        try:
            data = json.loads(text, object_pairs_hook=_no_duplicates)
        except json.JSONDecodeError as e:
            raise InputError(f"invalid JSON: {e.msg} (column {e.colno})", file=path,
                             line=e.lineno) from None
        except ValueError as e:  # a duplicate key
            raise InputError(f"invalid JSON: {e}", file=path) from None
        except RecursionError:
            raise InputError(_TOO_DEEP, file=path) from None
    if not isinstance(data, dict):
        raise InputError("the top level must be an object", file=path)
    return data


def parse_scenario(data: Mapping[str, object], *, source: str | Path | None = None,
                   base_dir: str | Path | None = None) -> ScenarioConfig:
    """Validate plain data into a ``Scenario`` model and run the cross-field checks.

    Args:
        data: The document, as JSON or TOML parse it.
        source: The file name used in messages.
        base_dir: Where relative ``urdf`` paths are resolved; default: the source's folder,
            else the current folder.

    Raises:
        InputError: with the path in the document of the first problem.
    """
    models = schema()
    from pydantic import ValidationError

    try:
        scenario = models.ScenarioConfig.model_validate(dict(data))
    except ValidationError as e:
        errors = e.errors()
        message = _describe(errors[0], models.ScenarioConfig)
        # Each member of a union a value fails is an error of its own: one place, one problem.
        more = len({key_path(x["loc"]) for x in errors} - {key_path(errors[0]["loc"])})
        if more:
            message += f" (and {more} more problem{'s' if more > 1 else ''})"
        raise InputError(message, file=source) from None
    scenario._source = str(source) if source is not None else None
    if base_dir is not None:
        scenario._base_dir = Path(base_dir)
    elif source is not None:
        scenario._base_dir = Path(source).resolve().parent
    check(scenario)
    return scenario


def load_scenario(path: str | Path) -> ScenarioConfig:
    """Read and validate a scenario file (``.json`` or ``.toml``).

    A simulation_and_control config (top-level ``sim``, ``robot_pybullet``, ...) is mapped
    onto a native scenario first (:mod:`urdfkit.motion.sac`); its notes are the scenario's
    ``notes``.
    """
    data = read_document(path)
    from urdfkit.motion import sac

    if not sac.is_config(data):
        return parse_scenario(data, source=path)
    imported = sac.convert(data, source=path)
    scenario = parse_scenario(imported.scenario, source=path)
    scenario._notes = list(imported.notes)
    return scenario


def _fail(scenario: ScenarioConfig, path: str, message: str) -> InputError:
    return InputError(f"{path}: {message}", file=scenario.source)


def _check_segments(scenario: ScenarioConfig, path: str,
                    segments: Sequence[DriveSegment | JointSegment]) -> None:
    last = 0.0
    for i, seg in enumerate(segments):
        if seg.until <= last:
            raise _fail(scenario, f"{path}[{i}].until",
                        f"must be later than the previous segment's ({last:g} s)")
        last = seg.until


def _check_template(scenario: ScenarioConfig, path: str, name: str,
                    params: Mapping[str, object]) -> None:
    from urdfkit.model.catalog import get_template

    try:
        get_template(name).resolve(params)
    except ParameterError as e:
        where = f"{path}.params" if params and not str(e).startswith("no template") else \
            f"{path}.template"
        raise _fail(scenario, where, str(e)) from None


def _check_file(scenario: ScenarioConfig, path: str, name: str) -> None:
    from urdfkit.sources.resolve import locate

    try:
        locate(scenario.path_of(name))
    except InputError as e:
        if e.message.startswith("no such file"):
            raise _fail(scenario, path, f"no such file: {name} (looked next to the scenario "
                                        "and in pybullet_data)") from None
        raise _fail(scenario, path, f"{name}: {e.message}") from None
    except (OSError, ValueError) as e:
        raise _fail(scenario, path, f"{name}: cannot read: {getattr(e, 'strerror', e)}"
                    ) from None


_TOO_DEEP = "nested deeper than Python's parser can follow (a config is a few levels deep)"


def check(scenario: ScenarioConfig) -> None:
    """The checks pydantic's types cannot express; each error names its path.

    Raises:
        InputError: the first problem found.
    """
    if scenario.ground is not None:
        g = scenario.ground
        _check_source(scenario, "ground", g.template, g.urdf, g.params)
    steps = scenario.duration / scenario.physics.time_step
    if not steps <= MAX_STEPS:
        many = f"{steps:.3g}" if math.isfinite(steps) else "more than 1e308"
        raise _fail(scenario, "duration", f"{scenario.duration:g} s at a time step of "
                    f"{scenario.physics.time_step:g} s is {many} steps; a run takes at most "
                    f"{MAX_STEPS:,} (shorten it, or lengthen physics.time_step)")
    names: dict[str, int] = {}
    for i, robot in enumerate(scenario.robots):
        path = f"robots[{i}]"
        if robot.name is None:
            robot.name = f"robot{i}"
        if robot.name in names:
            raise _fail(scenario, f"{path}.name",
                        f"{robot.name!r} is already the name of robots[{names[robot.name]}]")
        names[robot.name] = i
        _check_source(scenario, path, robot.template, robot.urdf, robot.params)
        if robot.orientation_rpy is not None and robot.orientation_quat is not None:
            raise _fail(scenario, path, "give orientation_rpy or orientation_quat, not both")
        if robot.orientation_quat is not None and \
                math.fsum(q * q for q in robot.orientation_quat) < 1e-12:
            raise _fail(scenario, f"{path}.orientation_quat", "must not be all zeros")
        _check_controllers(scenario, path, robot)


def _check_source(scenario: ScenarioConfig, path: str, template: str | None, urdf: str | None,
                  params: Mapping[str, object]) -> None:
    """A robot or the ground comes from exactly one of a template (with its params) or a file."""
    if (template is None) == (urdf is None):
        raise _fail(scenario, path, "give either 'template' or 'urdf'")
    if template is not None:
        _check_template(scenario, path, template, params)
    else:
        if params:
            raise _fail(scenario, f"{path}.params", "params are for templates only")
        assert urdf is not None
        _check_file(scenario, f"{path}.urdf", urdf)


def _check_controllers(scenario: ScenarioConfig, path: str, robot: RobotConfig) -> None:
    """One controller, its segments in time order, and a mode for every target."""
    if robot.drive is not None and robot.joints is not None:
        raise _fail(scenario, path, "give one controller: 'drive' or 'joints', not both")
    if robot.vehicle is not None and robot.drive is None:
        raise _fail(scenario, f"{path}.vehicle", "only applies with 'drive'")
    if robot.motor is not None and robot.drive is not None:
        raise _fail(scenario, f"{path}.motor",
                    "the servo model drives 'joints' targets; it cannot be used with 'drive'")
    for key in ("drive", "joints"):
        segments = getattr(robot, key)
        if segments is not None:
            if not segments:
                raise _fail(scenario, f"{path}.{key}", "needs at least one segment")
            _check_segments(scenario, f"{path}.{key}", segments)
    for k, seg in enumerate(robot.joints or []):
        if isinstance(seg.mode, dict):
            where = f"{path}.joints[{k}].mode"
            missing = [name for name in seg.targets if name not in seg.mode]
            if missing:
                raise _fail(scenario, where, f"no mode for target {missing[0]!r}: with a "
                                             "mode per joint, every target needs one")
            extra = [name for name in seg.mode if name not in seg.targets]
            if extra:
                raise _fail(scenario, f"{where}.{extra[0]}", "not a target of this segment")
