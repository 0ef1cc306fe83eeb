"""``urdfkit sweep``: many drives or scenario runs, one row each, on a process pool or on Ray.

A sweep is a base run plus ``vary`` lists: ``steer=0.1,0.2,0.3`` (values),
``wheel_radius=0.08:0.14:4`` (start:stop:count, ends included), or for scenarios a key path
``robots[0].motor.kp=50:400:8``. Several lists form a grid (every combination, the first
varying slowest), or with ``zip=True`` are paired point by point.

Design, for what the issue asks of it:

- **Every point is built and validated before any runs** (:func:`plan`): a bad name, path or
  value is one error naming the point, not a failure an hour in.
- **Each point is the single run it stands for.** A drive point is
:func:`urdfkit.motion.drive.drive`
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
from dataclasses import dataclass, fields
from pathlib import Path
from typing import Any, Literal

from urdfkit.core.errors import InputError, MissingDependencyError, ParameterError, UrdfkitError

# The rows file lives in sweep_journal; its names stay importable from here.
from urdfkit.motion.sweep_journal import MAX_ROWS_BYTES as MAX_ROWS_BYTES
from urdfkit.motion.sweep_journal import Journal as Journal
from urdfkit.motion.sweep_journal import clip as clip
from urdfkit.motion.sweep_journal import parse_value as parse_value
from urdfkit.motion.sweep_journal import read_rows as read_rows

#: What a sweep runs per point, and where its points run.
SweepKind = Literal["drive", "sim"]
Backend = Literal["local", "ray"]
KINDS: tuple[SweepKind, ...] = ("drive", "sim")
BACKENDS: tuple[Backend, ...] = ("local", "ray")
#: Drive options a sweep may vary (DriveConfig fields; the rest are files and switches).
DRIVE_OPTIONS = ("throttle", "steer", "seconds", "steps", "time_step", "max_force",
                 "drivetrain", "gravity", "urdf", "plane", "up", "engine")
#: A sim sweep's short names for scenario key paths (``engine``: each point's engine).
SIM_ALIASES = {"engine": "physics.engine"}
#: The most points one sweep may have: a typo such as 0:1:1e9 must not plan forever.
MAX_POINTS = 1_000_000


@dataclass(frozen=True)
class Vary:
    """One varied name and its values."""

    name: str
    values: tuple[object, ...]


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
    parsed = tuple(parse_value(v) for v in spec.split(","))
    if any(v == "" for v in parsed):
        raise ParameterError(f"`vary` {name}: an empty value in {spec!r}", param="vary")
    return Vary(name, parsed)


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


class Points(Sequence[dict[str, object]]):
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

    def at(self, digits: Sequence[int]) -> dict[str, object]:
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

    kind: SweepKind
    names: list[str]
    assignments: Points
    jobs: Jobs
    label: str


class Jobs(Sequence[tuple[str, dict[str, object]]]):
    """Each point's ``(kind, payload)``, built from the base and the point's values."""

    def __init__(self, kind: SweepKind, assignments: Points,
                 build: Callable[[Mapping[str, object], int], dict[str, object]]) -> None:
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
        kind: ``drive`` (base: a dict of :class:`urdfkit.motion.drive.DriveConfig` fields, with
            ``template_params`` for the built-in simplecar) or ``sim`` (base: a scenario
            file, or ``(document, base_dir)``).
        base: What every point starts from.
        vary: :class:`Vary` or ``NAME=VALUES`` strings.
        zip_: Pair the lists instead of forming a grid.

    Raises:
        ParameterError, InputError: a bad kind, name, path or value, naming the point.
    """
    if kind not in KINDS:
        from urdfkit.core.suggest import hint

        raise ParameterError(f"`kind` must be drive or sim, got {kind!r}{hint(kind, KINDS)}",
                             param="kind")
    parsed = [v if isinstance(v, Vary) else parse_vary(v) for v in vary]
    assignments = points(parsed, zip_)
    names = [v.name for v in parsed]
    build: Callable[[Mapping[str, object], int], dict[str, object]]
    if kind == "drive":
        base_options = _drive_base(base)

        def build(values: Mapping[str, object], i: int) -> dict[str, object]:
            return _drive_point(base_options, values, i)

        label = "drive"
    else:
        document, base_dir, source = _sim_base(base)

        def build(values: Mapping[str, object], i: int) -> dict[str, object]:
            return _sim_point(document, base_dir, source, values, i)

        label = source
    jobs = Jobs(kind, assignments, build)
    for i in assignments.probes():
        jobs[i]  # raises, naming the point
    return Plan(kind, names, assignments, jobs, label)


def _point_label(i: int, values: Mapping[str, object]) -> str:
    return f"point {i} (" + ", ".join(f"{k}={v}" for k, v in values.items()) + ")"


def _drive_base(base: Any) -> dict[str, Any]:  # DriveConfig's keyword arguments
    from urdfkit.motion.drive import DriveConfig

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


def _drive_point(base: Mapping[str, Any], values: Mapping[str, object], i: int
                 ) -> dict[str, object]:
    """The DriveConfig fields of one point, checked (a template's parameters included)."""
    from urdfkit.model.catalog import get_template
    from urdfkit.motion.drive import DriveConfig

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
            from urdfkit.core.suggest import hint

            raise ParameterError(
                f"`vary` {name!r}: not a drive option or simplecar parameter"
                f"{hint(name, [*DRIVE_OPTIONS, *template_names])} (drive options: "
                f"{', '.join(DRIVE_OPTIONS)}; simplecar: {', '.join(template_names)})",
                param="vary")
    if params:
        options["template_params"] = params
    where = _point_label(i, values)
    if options.get("urdf") is not None:
        from urdfkit.sources.resolve import locate

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


def _sim_base(base: Any) -> tuple[dict[str, object], str, str]:
    if isinstance(base, (str, Path)):
        from urdfkit.motion import sac
        from urdfkit.motion.scenario import read_document

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


def set_path(document: dict[str, object], path: str, value: object) -> None:
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


def _sim_point(document: Mapping[str, object], base_dir: str, source: str,
               values: Mapping[str, object], i: int) -> dict[str, object]:
    from urdfkit.motion.scenario import parse_scenario

    edited = copy.deepcopy(dict(document))
    for name, value in values.items():
        set_path(edited, SIM_ALIASES.get(name, name), value)
    try:
        parse_scenario(edited, source=source, base_dir=base_dir)
    except InputError as e:
        raise InputError(f"{_point_label(i, values)}: {e.message}", file=e.file) from None
    return {"document": edited, "base_dir": base_dir}


# --------------------------------------------------------------------------- running a point

#: A point to run: its index, its kind ("drive", "sim", or "error" when its own check
#: failed) and what it runs with (DriveConfig's fields, a scenario document), or the error.
Job = tuple[int, str, dict[str, object] | str]


def run_point(job: Job) -> dict[str, object]:
    """Run one point and return its metrics; a failure becomes ``{"error": ...}``.

    The one function every backend calls, in a worker process, a Ray task or in-process.
    """
    index, kind, payload = job
    if kind == "error" or isinstance(payload, str):  # it failed its check when planned
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


def _drive_metrics(options: Mapping[str, Any]) -> dict[str, object]:
    from urdfkit.motion.drive import DriveConfig, drive

    result = drive(DriveConfig(**options))
    if result.interrupted:  # drive() stops early on Ctrl-C and says so: so does the sweep
        raise KeyboardInterrupt
    data = result.to_dict()
    out: dict[str, object] = {}
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


def _sim_metrics(payload: Mapping[str, Any]) -> dict[str, object]:
    from urdfkit.motion.simulation import Simulation

    with Simulation(payload["document"], base_dir=payload["base_dir"]) as s:
        result = s.run(keep=False)
    if result.interrupted:
        raise KeyboardInterrupt
    out: dict[str, object] = {"steps": result.steps, "rows": result.row_count}
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
        skip: Callable[[Mapping[str, object]], bool] | None = None) -> Iterator[dict[str, object]]:
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
            skip: Callable[[Mapping[str, object]], bool] | None = None
            ) -> Iterator[dict[str, object]]:
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
    rows: Iterator[dict[str, object]]
    if backend == "ray":
        rows = _ray_rows(todo, jobs, address)
    else:
        rows = _local_rows(todo, count, jobs)
    for metrics in rows:
        values = sweep.assignments[metrics["point"]]
        yield {"point": metrics["point"], **values,
               **{k: v for k, v in metrics.items() if k != "point"}}


def _todo(sweep: Plan, skip: Callable[[Mapping[str, object]], bool] | None
          ) -> Iterator[Job]:
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


def _local_rows(todo: Iterable[Job], count: int, jobs: int | None
                ) -> Iterator[dict[str, object]]:
    workers = min(jobs or default_jobs(), count)
    if workers <= 1:
        for job in todo:
            yield run_point(job)
        return
    import multiprocessing

    from urdfkit.checks.check import worker_init
    from urdfkit.engine.registry import preload

    preload("pybullet")  # once, here: the forked workers inherit it, warm
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


def _ray_rows(todo: Iterable[Job], jobs: int | None, address: str | None
              ) -> Iterator[dict[str, object]]:
    ray = _ray()
    started = False
    if not ray.is_initialized():
        options: dict[str, object] = {"include_dashboard": False, "log_to_driver": False,
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


def metric_names(rows: Sequence[Mapping[str, object]], names: Sequence[str]) -> list[str]:
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
    from urdfkit.core.suggest import hint

    raise ParameterError(f"`plot` {metric!r} is not a column of this sweep"
                         f"{hint(metric, known)} (columns: {', '.join(known)})", param="plot")


def check_metric(kind: str, rows: Sequence[Mapping[str, object]], names: Sequence[str],
                 metric: str) -> None:
    """Refuse a ``--plot`` metric a sweep does not have, or a sweep with nothing varied.

    Drive rows have known columns, checked before the run (``rows`` empty); a scenario's
    depend on its robots, and are checked on the rows.
    """
    known = list(DRIVE_METRICS) if kind == "drive" else metric_names(rows, names)
    if metric not in known:
        from urdfkit.core.suggest import hint

        raise ParameterError(f"`plot` {metric!r} is not a numeric column of these rows"
                             f"{hint(metric, known)} (columns: {', '.join(known) or 'none'})",
                             param="plot")
    if not names:
        raise ParameterError("`plot` needs a varied value to plot against", param="plot")
