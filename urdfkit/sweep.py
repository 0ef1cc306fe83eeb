"""``urdfkit sweep``: many drives or scenario runs, one row each, on a process pool or on Ray.

A sweep is a base run plus ``vary`` lists: ``steer=0.1,0.2,0.3`` (values),
``wheel_radius=0.08:0.14:4`` (start:stop:count, ends included), or for scenarios a key path
``robots[0].motor.kp=50:400:8``. Several lists form a grid (every combination, the first
varying slowest), or with ``zip=True`` are paired point by point.

Design, for what the issue asks of it:

- **Every point is built and validated before any runs** (:func:`plan`): a bad name, path or
  value is one error naming the point, not a failure an hour in.
- **Each point is the single run it stands for.** A drive point is :func:`urdfkit.drive.drive`
  on a fresh PyBullet client with exactly the options ``urdfkit drive`` would pass; a sim point
  is a fresh :class:`urdfkit.sim.Simulation` of the edited document. Rows hold what their
  ``--json`` prints (the same rounding), less what is not deterministic (wall time).
- **Start-up is paid once per worker.** Workers are forked after pybullet is imported, and
  the built-in templates come from urdfkit's cache (built once per parameter set).
- **Rows are yielded as points finish** (completion order; ``point`` says which). A point
  that fails yields a row with its ``error`` and the sweep goes on.
- **Ray** (``backend="ray"``) runs each point as a Ray task, through the same function the
  pool runs, so the rows are the same; scheduling, retries and clusters are Ray's.
"""

from __future__ import annotations

import copy
import itertools
import math
import os
import re
import sys
from collections.abc import Callable, Iterable, Iterator, Mapping, Sequence
from dataclasses import dataclass, field, fields
from pathlib import Path
from typing import Any

from .errors import (
    InputError,
    MissingDependencyError,
    OutputError,
    ParameterError,
    UrdfkitError,
)

KINDS = ("drive", "sim")
BACKENDS = ("local", "ray")
#: Drive options a sweep may vary (DriveConfig fields; the rest are files and switches).
DRIVE_OPTIONS = ("throttle", "steer", "seconds", "steps", "time_step", "max_force",
                 "drivetrain", "gravity", "urdf", "plane", "up")
#: The most points one sweep may have: a typo such as 0:1:1e9 must not plan forever.
MAX_POINTS = 1_000_000


@dataclass(frozen=True)
class Vary:
    """One varied name and its values."""

    name: str
    values: tuple[Any, ...]


def parse_value(text: str) -> Any:
    """A value as typed: a number where it reads as one, true/false, else the text."""
    t = text.strip()
    if t.lower() in ("true", "false"):
        return t.lower() == "true"
    try:
        number = float(t)
    except ValueError:
        return t
    if not math.isfinite(number):
        return t  # "nan", "inf": refused where the value is checked, as text
    if re.fullmatch(r"[+-]?\d+", t):
        return int(t)
    return number


def parse_vary(text: str) -> Vary:
    """Parse ``NAME=V1,V2,...`` or ``NAME=START:STOP:COUNT``.

    Raises:
        ParameterError: no ``=``, no values, or a bad range.
    """
    name, sep, spec = text.partition("=")
    name, spec = name.strip(), spec.strip()
    if not sep or not name or not spec:
        raise ParameterError(f"`vary` expects NAME=VALUES (a,b,c or start:stop:count), got "
                             f"{text!r}", param="vary")
    if ":" in spec and "," not in spec:
        parts = spec.split(":")
        try:
            if len(parts) != 3:
                raise ValueError
            start, stop, count = float(parts[0]), float(parts[1]), float(parts[2])
        except ValueError:
            raise ParameterError(f"`vary` {name}: a range is start:stop:count, got {spec!r}",
                                 param="vary") from None
        if not (math.isfinite(start) and math.isfinite(stop)) or count != int(count) or \
                not 1 <= count <= MAX_POINTS:
            raise ParameterError(f"`vary` {name}: a range needs finite ends and a whole "
                                 f"count of 1 to {MAX_POINTS:,}, got {spec!r}", param="vary")
        n = int(count)
        values = tuple(start if n == 1 else _clean(start + (stop - start) * i / (n - 1))
                       for i in range(n))
        return Vary(name, values)
    values = tuple(parse_value(v) for v in spec.split(","))
    if any(v == "" for v in values):
        raise ParameterError(f"`vary` {name}: an empty value in {spec!r}", param="vary")
    return Vary(name, values)


def _clean(x: float) -> float:
    """0.1 + 0.02 * 3 as 0.16, not 0.16000000000000003: 12 significant digits."""
    return float(f"{x:.12g}")


def points(vary: Sequence[Vary], zip_: bool = False) -> Points:
    """The assignments of every point: a grid (first name slowest), or zipped.

    The points are computed on demand (:class:`Points`), so a million-point grid takes no
    more memory than a ten-point one.

    Raises:
        ParameterError: a name varied twice, zipped lists of different lengths, too many points.
    """
    names = [v.name for v in vary]
    twice = sorted({n for n in names if names.count(n) > 1})
    if twice:
        raise ParameterError(f"`vary` {twice[0]} is given twice", param="vary")
    if zip_ and vary:
        lengths = {len(v.values) for v in vary}
        if len(lengths) > 1:
            raise ParameterError("`zip` pairs values point by point, so every --vary needs as "
                                 "many: got " + ", ".join(f"{v.name} {len(v.values)}"
                                                          for v in vary), param="zip")
    elif vary:
        total = math.prod(len(v.values) for v in vary)
        if total > MAX_POINTS:
            raise ParameterError(f"{total:,} points: more than {MAX_POINTS:,}; sweep fewer "
                                 "values", param="vary")
    return Points(tuple(vary), zip_)


class Points(Sequence[dict[str, Any]]):
    """A sweep's points, each computed from its index: a grid (first name slowest) or zipped.

    Point ``i`` of a grid is ``i`` written in mixed radix, one digit per varied name (the
    last name's digit changes fastest), as :func:`itertools.product` orders them.
    """

    def __init__(self, vary: tuple[Vary, ...], zip_: bool) -> None:
        self.vary = vary
        self.zip = zip_
        self.names = [v.name for v in vary]
        if not vary:
            self._len = 1
        elif zip_:
            self._len = len(vary[0].values)
        else:
            self._len = math.prod(len(v.values) for v in vary)

    def __len__(self) -> int:
        return self._len

    def digits(self, i: int) -> list[int]:
        """Each varied name's value index at point ``i``."""
        if self.zip:
            return [i] * len(self.vary)
        out = []
        for v in reversed(self.vary):
            i, d = divmod(i, len(v.values))
            out.append(d)
        return out[::-1]

    def at(self, digits: Sequence[int]) -> dict[str, Any]:
        """The assignment with these value indices."""
        return {v.name: v.values[d] for v, d in zip(self.vary, digits, strict=True)}

    def __getitem__(self, i: Any) -> Any:
        if isinstance(i, slice):
            return [self[j] for j in range(*i.indices(self._len))]
        if not -self._len <= i < self._len:
            raise IndexError(i)
        return self.at(self.digits(i % self._len))

    def probes(self) -> list[int]:
        """Points that together try every value of every name once, checked before a run.

        A zipped sweep has as many points as values: all of them. A grid gets, for each
        name, its every value with the other names at their first value, plus the last point:
        as many as the values given, never the product.
        """
        if self.zip or len(self.vary) <= 1:
            return list(range(self._len))
        seen = {0, self._len - 1}
        radix = [math.prod(len(w.values) for w in self.vary[k + 1:])
                 for k in range(len(self.vary))]
        for k, v in enumerate(self.vary):
            seen.update(d * radix[k] for d in range(len(v.values)))
        return sorted(seen)


# --------------------------------------------------------------------------- planning


@dataclass
class Plan:
    """A validated sweep, ready to run.

    Attributes:
        kind: ``drive`` or ``sim``.
        names: The varied names, in ``vary`` order (the rows' leading columns).
        assignments: Each point's values by name (computed on demand).
        jobs: The payload of each point, as the workers take it (picklable; computed on
            demand, and checked as it is: a point that fails its check becomes a failed row).
        label: What is swept, for messages.
    """

    kind: str
    names: list[str]
    assignments: Points
    jobs: Jobs
    label: str


class Jobs(Sequence[tuple[str, Any]]):
    """Each point's ``(kind, payload)``, built from the base and the point's values."""

    def __init__(self, kind: str, assignments: Points,
                 build: Callable[[Mapping[str, Any], int], Any]) -> None:
        self.kind = kind
        self.assignments = assignments
        self.build = build

    def __len__(self) -> int:
        return len(self.assignments)

    def __getitem__(self, i: Any) -> Any:
        if isinstance(i, slice):
            return [self[j] for j in range(*i.indices(len(self)))]
        return (self.kind, self.build(self.assignments[i], i % len(self)))


def plan(kind: str, base: Any, vary: Sequence[Vary | str], *, zip_: bool = False) -> Plan:
    """Plan a sweep and check its values before any point runs.

    Every value of every name is tried before anything runs (:meth:`Points.probes`: each
    value once, the others at their first, so a million-point grid checks ~as many points
    as values were given, and keeps no point in memory). A combination that only fails
    together (``seconds`` and ``time_step`` too many steps apart) fails that point's row.

    Args:
        kind: ``drive`` (base: a dict of :class:`urdfkit.drive.DriveConfig` fields, with
            ``template_params`` for the built-in simplecar) or ``sim`` (base: a scenario
            file, or ``(document, base_dir)``).
        base: What every point starts from.
        vary: :class:`Vary` or ``NAME=VALUES`` strings.
        zip_: Pair the lists instead of forming a grid.

    Raises:
        ParameterError, InputError: a bad kind, name, path or value, naming the point.
    """
    if kind not in KINDS:
        from .suggest import hint

        raise ParameterError(f"`kind` must be drive or sim, got {kind!r}{hint(kind, KINDS)}",
                             param="kind")
    parsed = [v if isinstance(v, Vary) else parse_vary(v) for v in vary]
    assignments = points(parsed, zip_)
    names = [v.name for v in parsed]
    build: Callable[[Mapping[str, Any], int], Any]
    if kind == "drive":
        base_options = _drive_base(base)

        def build(values: Mapping[str, Any], i: int) -> Any:
            return _drive_point(base_options, values, i)

        label = "drive"
    else:
        document, base_dir, source = _sim_base(base)

        def build(values: Mapping[str, Any], i: int) -> Any:
            return _sim_point(document, base_dir, source, values, i)

        label = source
    jobs = Jobs(kind, assignments, build)
    for i in assignments.probes():
        jobs[i]  # raises, naming the point
    return Plan(kind, names, assignments, jobs, label)


def _point_label(i: int, values: Mapping[str, Any]) -> str:
    return f"point {i} (" + ", ".join(f"{k}={v}" for k, v in values.items()) + ")"


def _drive_base(base: Any) -> dict[str, Any]:
    from .drive import DriveConfig

    if isinstance(base, DriveConfig):
        options = {f.name: getattr(base, f.name) for f in fields(DriveConfig)}
    else:
        options = dict(base or {})
        known = {f.name for f in fields(DriveConfig)}
        unknown = sorted(set(options) - known)
        if unknown:
            raise ParameterError(f"`base` {unknown[0]!r} is not a drive option", param="base")
    options["keep_trajectory"] = False  # rows need the statistics only: memory stays flat
    options["gui"] = False
    return options


def _drive_point(base: Mapping[str, Any], values: Mapping[str, Any], i: int) -> dict[str, Any]:
    """The DriveConfig fields of one point, checked (a template's parameters included)."""
    from .catalog import get_template
    from .drive import DriveConfig

    options = dict(base)
    params = dict(options.get("template_params") or {})
    simplecar = get_template("simplecar")
    template_names = [p.name for p in simplecar.params]
    for name, value in values.items():
        if name in DRIVE_OPTIONS:
            options[name] = value
        elif name in template_names:
            if options.get("urdf") is not None:
                raise ParameterError(f"`vary` {name} is a parameter of the built-in simplecar, "
                                     "and this sweep drives a --urdf file", param="vary")
            params[name] = str(value)
        else:
            from .suggest import hint

            raise ParameterError(
                f"`vary` {name!r}: not a drive option or simplecar parameter"
                f"{hint(name, [*DRIVE_OPTIONS, *template_names])} (drive options: "
                f"{', '.join(DRIVE_OPTIONS)}; simplecar: {', '.join(template_names)})",
                param="vary")
    if params:
        options["template_params"] = params
    where = _point_label(i, values)
    if options.get("urdf") is not None:
        from .resolve import locate

        locate(options["urdf"])  # a missing file, a FIFO or a folder: refused before any runs
    try:
        config = DriveConfig(**options)
        config.check()
        if options.get("urdf") is None:
            simplecar.resolve(params)  # bad parameter values now, not in a worker
    except (UrdfkitError, TypeError) as e:
        message = e.message if isinstance(e, UrdfkitError) else str(e)
        raise ParameterError(f"{where}: {message}", param="vary") from None
    return {f.name: getattr(config, f.name) for f in fields(DriveConfig)}


def _sim_base(base: Any) -> tuple[dict[str, Any], str, str]:
    if isinstance(base, (str, Path)):
        from . import sac
        from .scenario import read_document

        document = read_document(base)
        if sac.is_config(document):
            document = sac.convert(document, source=base).scenario
        return document, str(Path(base).resolve().parent), str(base)
    document, base_dir = base
    return dict(document), str(base_dir), "<scenario>"


_PATH_TOKEN = re.compile(r"([A-Za-z_][A-Za-z0-9_-]*)|\[(-?\d+)\]")


def parse_path(path: str) -> list[str | int]:
    """``robots[0].motor.kp`` as ``["robots", 0, "motor", "kp"]``.

    Raises:
        ParameterError: not a key path.
    """
    out: list[str | int] = []
    pos = 0
    while pos < len(path):
        if out and path[pos] == "." and not path.startswith("[", pos):
            pos += 1
        m = _PATH_TOKEN.match(path, pos)
        if m is None or (out == [] and m.group(2) is not None):
            raise ParameterError(f"`vary` {path!r} is not a key path such as "
                                 "robots[0].motor.kp or physics.time_step", param="vary")
        out.append(m.group(1) if m.group(1) is not None else int(m.group(2)))
        pos = m.end()
    if not out:
        raise ParameterError("`vary` needs a key path", param="vary")
    return out


def set_path(document: dict[str, Any], path: str, value: Any) -> None:
    """Set ``value`` at ``path`` in a scenario document; missing tables are created.

    Raises:
        ParameterError: an index out of range, or a path through a value that is not a
            table or list.
    """
    keys = parse_path(path)
    node: Any = document
    for depth, key in enumerate(keys):
        last = depth == len(keys) - 1
        where = "".join(f"[{k}]" if isinstance(k, int) else f".{k}" for k in keys[:depth + 1])
        where = where.lstrip(".")
        if isinstance(key, int):
            if not isinstance(node, list):
                raise ParameterError(f"`vary` {path}: {where.rsplit('[', 1)[0]} is not a list",
                                     param="vary")
            if not -len(node) <= key < len(node):
                raise ParameterError(f"`vary` {path}: {where} is out of range (the list has "
                                     f"{len(node)})", param="vary")
        elif not isinstance(node, dict):
            raise ParameterError(f"`vary` {path}: {where.rsplit('.', 1)[0]} holds a value, "
                                 "not a table", param="vary")
        if last:
            node[key] = value
            return
        if isinstance(key, str) and key not in node:
            node[key] = {}
        node = node[key]


def _sim_point(document: Mapping[str, Any], base_dir: str, source: str,
               values: Mapping[str, Any], i: int) -> dict[str, Any]:
    from .scenario import parse_scenario

    edited = copy.deepcopy(dict(document))
    for name, value in values.items():
        set_path(edited, name, value)
    try:
        parse_scenario(edited, source=source, base_dir=base_dir)
    except InputError as e:
        raise InputError(f"{_point_label(i, values)}: {e.message}", file=e.file) from None
    return {"document": edited, "base_dir": base_dir}


# --------------------------------------------------------------------------- running a point


def run_point(job: tuple[int, str, Any]) -> dict[str, Any]:
    """Run one point and return its metrics; a failure becomes ``{"error": ...}``.

    The one function every backend calls, in a worker process, a Ray task or in-process.
    """
    index, kind, payload = job
    if kind == "error":  # the point failed its check while the sweep was planned
        return {"point": index, "error": payload}
    try:
        metrics = _drive_metrics(payload) if kind == "drive" else _sim_metrics(payload)
        metrics["error"] = None
    except UrdfkitError as e:
        metrics = {"error": str(e)}
    except KeyboardInterrupt:
        raise
    except Exception as e:  # noqa: BLE001 - one broken point must not end the sweep
        metrics = {"error": f"{type(e).__name__}: {e}"}
    return {"point": index, **metrics}


#: Drive --json keys that are not metrics of the run (or not deterministic).
_DRIVE_SKIP = ("model", "drivetrain", "simulated", "wall_time", "real_time_factor",
               "interrupted", "throttle", "steer", "time_step")


def _drive_metrics(options: Mapping[str, Any]) -> dict[str, Any]:
    from .drive import DriveConfig, drive

    result = drive(DriveConfig(**options))
    if result.interrupted:  # drive() stops early on Ctrl-C and says so: so does the sweep
        raise KeyboardInterrupt
    data = result.to_dict()
    out: dict[str, Any] = {}
    for key, value in data.items():
        if key in _DRIVE_SKIP:
            continue
        if key in ("final_position", "turn_center"):
            for axis, v in zip("xyz", value or (None, None, None), strict=False):
                out[f"{key}_{axis}" if key == "turn_center" else f"final_{axis}"] = v
        elif key in ("warnings", "problems"):
            out[key] = "; ".join(value)
        else:
            out[key] = value
    out["steer_applied"] = data["steer"]
    return out


def _sim_metrics(payload: Mapping[str, Any]) -> dict[str, Any]:
    from .sim import Simulation

    with Simulation(payload["document"], base_dir=payload["base_dir"]) as s:
        result = s.run(keep=False)
    if result.interrupted:
        raise KeyboardInterrupt
    out: dict[str, Any] = {"steps": result.steps, "rows": result.row_count}
    for x in result.summaries:
        prefix = x.robot
        for axis, v in zip("xyz", x.end, strict=False):
            out[f"{prefix}.end_{axis}"] = round(v, 6)
        out[f"{prefix}.distance"] = round(x.distance, 6)
        out[f"{prefix}.top_speed"] = round(x.top_speed, 6)
        out[f"{prefix}.heading_deg"] = round(x.heading_deg, 6)
        for joint, value in x.final_joints.items():
            out[f"{prefix}.joint.{joint}"] = round(value, 6)
            out[f"{prefix}.joint_min.{joint}"] = round(x.joint_min[joint], 6)
            out[f"{prefix}.joint_max.{joint}"] = round(x.joint_max[joint], 6)
    return out


# --------------------------------------------------------------------------- running a sweep


def run(kind: str, base: Any, vary: Sequence[Vary | str], *, zip_: bool = False,
        jobs: int | None = None, backend: str = "local", address: str | None = None,
        skip: Callable[[Mapping[str, Any]], bool] | None = None) -> Iterator[dict[str, Any]]:
    """Run a sweep and yield one row per point, as points finish.

    A row is ``{"point": i, <varied name>: value, ..., <metrics>, "error": None | text}``.

    Args:
        kind: ``drive`` or ``sim``, as :func:`plan`.
        base: What every point starts from, as :func:`plan`.
        vary: The varied names and values, as :func:`plan`.
        zip_: Pair the lists instead of forming a grid.
        jobs: Worker processes (default: every core; 1 runs in this process), or for Ray
            the CPUs of a local cluster it starts.
        backend: ``local`` (a process pool) or ``ray``.
        address: Ray's cluster address (``auto``, ``ray://host:10001``); default: a local
            Ray started here.
        skip: Points (their assignments) not to run (``--resume``: those already done).

    Raises:
        ParameterError, InputError: as :func:`plan`, before anything runs.
        MissingDependencyError: ``ray`` without Ray installed.
    """
    sweep = plan(kind, base, vary, zip_=zip_)
    yield from execute(sweep, jobs=jobs, backend=backend, address=address, skip=skip)


def execute(sweep: Plan, *, jobs: int | None = None, backend: str = "local",
            address: str | None = None,
            skip: Callable[[Mapping[str, Any]], bool] | None = None
            ) -> Iterator[dict[str, Any]]:
    """Run a planned sweep; see :func:`run`."""
    if backend not in BACKENDS:
        raise ParameterError(f"`backend` must be local or ray, got {backend!r}",
                             param="backend")
    if jobs is not None and (isinstance(jobs, bool) or jobs < 1):
        raise ParameterError(f"`jobs` must be 1 or more, got {jobs!r}", param="jobs")
    if address is not None and backend != "ray":
        raise ParameterError("`address` is a Ray cluster's: it needs `backend` ray",
                             param="address")
    count = len(sweep.assignments) if skip is None else \
        sum(1 for values in sweep.assignments if not skip(values))
    todo = _todo(sweep, skip)
    rows: Iterator[dict[str, Any]]
    if backend == "ray":
        rows = _ray_rows(todo, jobs, address)
    else:
        rows = _local_rows(todo, count, jobs)
    for metrics in rows:
        values = sweep.assignments[metrics["point"]]
        yield {"point": metrics["point"], **values,
               **{k: v for k, v in metrics.items() if k != "point"}}


def _todo(sweep: Plan, skip: Callable[[Mapping[str, Any]], bool] | None
          ) -> Iterator[tuple[int, str, Any]]:
    """The points to run, built one at a time (a million-point grid stays flat in memory).

    A point whose own check fails (a combination no single value showed) is run as a
    failing job, so it becomes a row with its error like any failed point.
    """
    for i, values in enumerate(sweep.assignments):
        if skip is not None and skip(values):
            continue
        try:
            kind, payload = sweep.jobs[i]
        except UrdfkitError as e:
            yield (i, "error", e.message)
            continue
        yield (i, kind, payload)


def default_jobs() -> int:
    """Worker processes: the cores this process may run on."""
    if hasattr(os, "sched_getaffinity"):
        return max(1, len(os.sched_getaffinity(0)))
    return os.cpu_count() or 1


def _local_rows(todo: Iterable[tuple[int, str, Any]], count: int, jobs: int | None
                ) -> Iterator[dict[str, Any]]:
    workers = min(jobs or default_jobs(), count)
    if workers <= 1:
        for job in todo:
            yield run_point(job)
        return
    import multiprocessing

    from .check import worker_init
    from .session import import_pybullet

    import_pybullet()  # once, here: the forked workers inherit it, warm
    context = multiprocessing.get_context("fork" if sys.platform.startswith("linux")
                                          else "spawn")
    # The with block terminates the workers on the way out (Ctrl-C included).
    with context.Pool(workers, initializer=worker_init) as pool:
        yield from pool.imap_unordered(run_point, todo, chunksize=1)


def _ray() -> Any:
    try:
        import ray
    except ImportError as e:
        raise MissingDependencyError("`backend` ray needs Ray: pip install 'urdfkit[ray]'",
                                     param="backend") from e
    return ray


def _ray_rows(todo: Iterable[tuple[int, str, Any]], jobs: int | None, address: str | None
              ) -> Iterator[dict[str, Any]]:
    ray = _ray()
    started = False
    if not ray.is_initialized():
        options: dict[str, Any] = {"include_dashboard": False, "log_to_driver": False,
                                   "configure_logging": False}
        if address is not None:
            options["address"] = address
        elif jobs is not None:
            options["num_cpus"] = jobs
        try:
            ray.init(**options)
        except (ConnectionError, ValueError, RuntimeError) as e:
            raise ParameterError(f"cannot reach the Ray cluster {address or '(local)'}: {e}",
                                 param="address") from None
        started = True
    task = ray.remote(num_cpus=1, max_retries=1)(run_point)
    # A window of tasks in flight, not all of them: ray.wait scans the list it is given, so
    # a million pending refs would make every wait slow, and hold every payload at once.
    window = max(16, 4 * int(ray.cluster_resources().get("CPU", 1)))
    queue = iter(todo)
    pending: dict[Any, int] = {}
    try:
        while True:
            for job in itertools.islice(queue, window - len(pending)):
                pending[task.remote(job)] = job[0]
            if not pending:
                break
            done, _ = ray.wait(list(pending), num_returns=1)
            for ref in done:
                index = pending.pop(ref)
                try:
                    yield ray.get(ref)
                except ray.exceptions.RayError as e:  # a worker died: the point's error
                    yield {"point": index, "error": f"Ray: {type(e).__name__}: {e}"}
    finally:
        for ref in pending:
            # Not force=True: killing workers mid-task has crashed Ray's task manager
            # ("Tried to complete task that was not pending") on Ctrl-C.
            try:
                ray.cancel(ref)
            except Exception:  # noqa: BLE001 - cancelling is best effort on the way out
                pass
        if started:
            ray.shutdown()


# --------------------------------------------------------------------------- the rows file


@dataclass
class Journal:
    """Rows written as points finish, to ``OUT.partial`` (JSON lines), then to ``OUT``.

    A crash leaves ``OUT.partial`` with every finished row; ``resume`` reads it (and ``OUT``,
    if a finished sweep left one) to skip the points done. :meth:`finish` writes ``OUT``
    atomically in its format (``.csv``, ``.jsonl`` or ``.parquet``) and removes the partial
    file; it is also called on Ctrl-C, so the rows so far land in ``OUT``.

    The journal is locked (``flock``) from :meth:`open` to :meth:`finish`: a second sweep on
    the same output is refused at once instead of redoing points and clobbering rows. A last
    row cut short (a crash, a full disk) is dropped and its point runs again, with a note in
    :attr:`notes`; a damaged row anywhere else is refused with its line.
    """

    path: Path
    names: list[str]
    resume: bool = False
    force: bool = False
    done: list[dict[str, Any]] = field(default_factory=list)
    assignments: Sequence[dict[str, Any]] = field(default_factory=list)
    #: What the caller should tell the user (rows dropped, and why).
    notes: list[str] = field(default_factory=list)
    _fd: int | None = None
    _keys: set[tuple[str, ...]] | None = None
    _nonfinite: bool = False

    @property
    def partial(self) -> Path:
        """The journal file beside the output."""
        return self.path.with_name(self.path.name + ".partial")

    def open(self) -> None:
        """Check the output, lock the journal, read what a previous run did, start writing."""
        from .sim import check_output

        exists = os.path.lexists(self.path)  # a dangling symlink is there: never replaced
        check_output(self.path, force=self.force or (self.resume and exists) or not exists)
        had_partial = os.path.lexists(self.partial)
        if had_partial and not self.resume and not self.force:
            raise InputError("a sweep that did not finish left its rows here: add "
                             "--resume to carry on, or --force to start again",
                             file=self.partial)
        self._lock()
        try:
            if self.resume:
                found = read_rows(self.path, notes=self.notes) if exists else []
                if had_partial:
                    found += read_rows(self.partial, ".jsonl", notes=self.notes)
                self.done = self._same_sweep(found)
            # Keep what a previous run finished: the journal restarts with those rows.
            assert self._fd is not None
            os.ftruncate(self._fd, 0)
            for row in self.done:
                self._write(row)
        except BaseException:
            if not had_partial:  # refused before any row: leave nothing behind
                try:
                    self.partial.unlink()
                except OSError:
                    pass
            self._unlock()
            raise

    def _lock(self) -> None:
        import errno
        import fcntl

        from .output import check_output as check_target

        check_target(self.partial, force=True, what="the journal")  # no FIFO, no folder
        try:
            fd = os.open(self.partial, os.O_RDWR | os.O_CREAT | getattr(os, "O_CLOEXEC", 0),
                         0o666)
        except OSError as e:
            raise OutputError(f"cannot write the journal: {e.strerror}",
                              file=self.partial) from None
        try:
            fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
        except OSError as e:
            os.close(fd)
            if e.errno in (errno.EWOULDBLOCK, errno.EAGAIN, errno.EACCES):
                raise InputError("another sweep is writing this output now: wait for it, "
                                 "or give another --out", file=self.path) from None
            raise OutputError(f"cannot lock the journal: {e.strerror}",
                              file=self.partial) from None
        self._fd = fd

    def _unlock(self) -> None:
        if self._fd is not None:
            try:
                os.close(self._fd)  # closing releases the lock
            except OSError:
                pass
            self._fd = None

    def _same_sweep(self, rows: list[dict[str, Any]]) -> list[dict[str, Any]]:
        """The rows to keep: each must be a point of this sweep; failed ones run again.

        Raises:
            InputError: a row that is not the same point of this sweep (another grid, other
                names): resuming would mix two sweeps in one file.
        """
        kept: dict[int, dict[str, Any]] = {}
        for row in rows:
            point = row.get("point")
            if isinstance(point, float) and point.is_integer():
                point = int(point)
            if not isinstance(point, int) or not 0 <= point < len(self.assignments) or \
                    _key(row, self.names) != _key(self.assignments[point], self.names) or \
                    any(n not in row for n in self.names):
                shown = clip(", ".join(f"{n}={row.get(n)}" for n in self.names))
                raise InputError(f"holds rows of another sweep (point {clip(str(point))}: "
                                 f"{shown} is not that point of this one): --resume carries "
                                 "on the same command; give another --out, or --force to "
                                 "start again", file=self.path)
            if not row.get("error"):
                kept[point] = row  # a point that failed runs again, and its new row replaces
        return [kept[p] for p in sorted(kept)]

    def _write(self, row: Mapping[str, Any]) -> None:
        import json

        assert self._fd is not None, "open() the journal first"
        data = (json.dumps(row, allow_nan=False, default=str) + "\n").encode("utf-8")
        try:
            view = memoryview(data)
            while view:
                view = view[os.write(self._fd, view):]
        except OSError as e:
            raise _write_error(e, self.partial) from None

    def add(self, row: Mapping[str, Any]) -> None:
        """Record a finished point.

        A metric that is not finite (a robot whose file holds NaN blew up) is recorded as
        null, as ``--json`` writes it, with one note for the run: JSON has no NaN.
        """
        bad = [k for k, v in row.items() if isinstance(v, float) and not math.isfinite(v)]
        if bad:
            row = {k: None if k in bad else v for k, v in row.items()}
            if not self._nonfinite:
                self._nonfinite = True
                self.notes.append(f"point {row.get('point')}: {', '.join(bad[:3])}"
                                  f"{' ...' if len(bad) > 3 else ''} not finite (the "
                                  "simulation blew up): written as null")
        self._write(row)

    def finished(self, values: Mapping[str, Any]) -> bool:
        """Whether a point with these values has a row without an error (for ``skip``)."""
        if self._keys is None:
            self._keys = {_key(r, self.names) for r in self.done if not r.get("error")}
        return _key(values, self.names) in self._keys

    def finish(self) -> Path:
        """Write ``OUT`` from the journal (atomically), remove the journal, unlock."""
        try:
            if self._fd is not None:
                try:
                    os.fsync(self._fd)
                except OSError as e:
                    raise _write_error(e, self.partial) from None
            rows = read_rows(self.partial, ".jsonl", notes=self.notes)
            from .sim import write_rows

            path = write_rows(self.path, rows, force=True)
            self.partial.unlink()
            return path
        finally:
            self._unlock()


def _write_error(e: OSError, path: Path) -> OutputError:
    import errno

    why = {errno.ENOSPC: "the disk is full", errno.EDQUOT: "the disk quota is exceeded",
           errno.EROFS: "the file system is read-only"}.get(e.errno or 0, e.strerror or str(e))
    return OutputError(f"cannot write the journal: {why}; the rows so far are kept here "
                       "(--resume carries on)", file=path)


def clip(text: str, most: int = 200) -> str:
    """``text``, or its first ``most`` characters and its length: error lines stay bounded."""
    return text if len(text) <= most else f"{text[:most]}... ({len(text):,} characters)"


def _key(row: Mapping[str, Any], names: Sequence[str]) -> tuple[str, ...]:
    """The varied values of a row, comparable across formats (CSV gives text back)."""
    out = []
    for n in names:
        v = row.get(n)
        if isinstance(v, str):
            v = parse_value(v)
        out.append(repr(float(v)) if isinstance(v, (int, float)) and not isinstance(v, bool)
                   else str(v))
    return tuple(out)


#: A million rows of a few hundred bytes; a larger file is not a sweep's rows.
MAX_ROWS_BYTES = 1 << 30


def read_rows(path: Path, fmt: str | None = None, *,
              notes: list[str] | None = None) -> list[dict[str, Any]]:
    """The rows of a sweep's output (``.csv``, ``.jsonl``, ``.parquet``) or journal.

    A last row cut short (the file does not end its line: a crash or a full disk) is dropped,
    with a note in ``notes``; its point runs again. Any other row that does not read is
    damage, and refused with its line.

    Raises:
        InputError: unreadable, not a rows file, or a damaged row.
    """
    fmt = fmt or path.suffix.lower()
    if fmt not in (".jsonl", ".csv", ".parquet"):
        raise InputError("rows are .csv, .jsonl or .parquet", file=path)
    from .xmlio import read_regular

    data = read_regular(path, limit=MAX_ROWS_BYTES, kind="rows file")
    if fmt == ".parquet":
        return _parquet_rows(path, data)
    try:
        text = data.decode("utf-8")
    except UnicodeDecodeError as e:
        raise InputError(f"cannot read the rows to resume from: not UTF-8 (byte {e.start})",
                         file=path) from None
    lines = text.split("\n")
    cut = lines.pop() != ""  # text after the last newline: a row cut short
    if cut and notes is not None:
        notes.append(f"{path}: its last row was cut short (line {len(lines) + 1}); that point "
                     "runs again")
    if fmt == ".jsonl":
        return _jsonl_rows(path, lines)
    return _csv_rows(path, lines)


def _jsonl_rows(path: Path, lines: list[str]) -> list[dict[str, Any]]:
    import json

    rows = []
    for n, line in enumerate(lines, 1):
        if not line.strip():
            continue
        try:
            row = json.loads(line)
        except (json.JSONDecodeError, RecursionError):
            row = None
        if not isinstance(row, dict):
            raise InputError(f"row {n} is not a JSON object ({clip(line, 80)!r}): the rows "
                             "file is damaged; --force starts the sweep again",
                             file=path, line=n)
        rows.append(row)
    return rows


def _csv_rows(path: Path, lines: list[str]) -> list[dict[str, Any]]:
    import csv

    reader = csv.reader(lines)
    try:
        header = next(reader)
    except StopIteration:
        return []
    except csv.Error as e:
        raise InputError(f"not a rows file: {e}", file=path, line=1) from None
    rows = []
    try:
        for values in reader:
            if len(values) != len(header):
                raise InputError(f"row {reader.line_num} has {len(values)} values for "
                                 f"{len(header)} columns: the rows file is damaged; --force "
                                 "starts the sweep again", file=path, line=reader.line_num)
            rows.append({k: _csv_value(v) for k, v in zip(header, values, strict=True)})
    except csv.Error as e:
        raise InputError(f"a row does not read as CSV ({e}): the rows file is damaged",
                         file=path, line=reader.line_num) from None
    return rows


def _parquet_rows(path: Path, data: bytes) -> list[dict[str, Any]]:
    from .sim import _pyarrow

    _pyarrow()
    import pyarrow as pa
    import pyarrow.parquet as pq

    try:
        return [dict(r) for r in pq.read_table(pa.BufferReader(data)).to_pylist()]
    except (OSError, ValueError, pa.ArrowException) as e:
        raise InputError(f"cannot read the rows to resume from: {clip(str(e))}",
                         file=path) from None


def _csv_value(text: str | None) -> Any:
    if text is None or text == "":
        return None
    return parse_value(text)


def metric_names(rows: Sequence[Mapping[str, Any]], names: Sequence[str]) -> list[str]:
    """The numeric metric columns of rows (for ``--plot`` and the table)."""
    seen: dict[str, None] = {}
    for r in rows:
        for k, v in r.items():
            if k not in names and k not in ("point", "error") and \
                    isinstance(v, (int, float)) and not isinstance(v, bool):
                seen[k] = None
    return list(seen)


#: The numeric columns of a drive row (the others: radius_note, problems, warnings, error).
DRIVE_METRICS = ("final_x", "final_y", "final_z", "final_yaw", "heading_change", "yaw_rate",
                 "distance", "mean_speed", "turning_radius", "turn_center_x", "turn_center_y",
                 "expected_radius", "sim_time", "steps", "samples", "steer_applied")


#: Per-robot columns of a scenario row (the joint ones end in ``.JOINT``).
SIM_FIELDS = ("end_x", "end_y", "end_z", "distance", "top_speed", "heading_deg")
SIM_JOINT_FIELDS = ("joint", "joint_min", "joint_max")


def check_sim_metric(sweep: Plan, metric: str) -> None:
    """Refuse, before a scenario sweep runs, a ``--plot`` metric its rows cannot have.

    The robot and the field are checked here; a joint's name only once the rows exist (the
    joints are the robot file's).
    """
    robots = [str(r.get("name")) for r in sweep.jobs[0][1]["document"].get("robots", [])
              if isinstance(r, Mapping)]
    if metric in ("steps", "rows"):
        return
    robot, _, field_name = metric.partition(".")
    family = field_name.split(".", 1)[0]
    if robot in robots and (field_name in SIM_FIELDS or
                            (family in SIM_JOINT_FIELDS and "." in field_name)):
        return
    known = ["steps", "rows", *(f"{r}.{f}" for r in robots for f in SIM_FIELDS),
             *(f"{r}.{f}.JOINT" for r in robots for f in SIM_JOINT_FIELDS)]
    from .suggest import hint

    raise ParameterError(f"`plot` {metric!r} is not a column of this sweep"
                         f"{hint(metric, known)} (columns: {', '.join(known)})", param="plot")


def check_metric(kind: str, rows: Sequence[Mapping[str, Any]], names: Sequence[str],
                 metric: str) -> None:
    """Refuse a ``--plot`` metric a sweep does not have, or a sweep with nothing varied.

    Drive rows have known columns, checked before the run (``rows`` empty); a scenario's
    depend on its robots, and are checked on the rows.
    """
    known = list(DRIVE_METRICS) if kind == "drive" else metric_names(rows, names)
    if metric not in known:
        from .suggest import hint

        raise ParameterError(f"`plot` {metric!r} is not a numeric column of these rows"
                             f"{hint(metric, known)} (columns: {', '.join(known) or 'none'})",
                             param="plot")
    if not names:
        raise ParameterError("`plot` needs a varied value to plot against", param="plot")
