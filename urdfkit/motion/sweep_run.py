"""A sweep as ``urdfkit sweep`` runs it: its options checked, the rows file, the loop, the plot.

:mod:`urdfkit.sweep` plans and executes points; this module is the orchestration around it
that the command line only maps flags into: which options conflict, which drive options were
given (against DriveConfig's defaults, the one place they are written), the journal and
``resume``, the loop that counts rows as they finish, and whether a plot can be drawn. It
prints nothing: :class:`SweepRun` returns the notes and the outcome, the caller says them.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, field, fields
from pathlib import Path

from urdfkit.core.errors import ParameterError, UrdfkitError
from urdfkit.motion import sweep_plan as sweeping

#: The drive options a drive sweep holds fixed for every point, in the order messages list them.
FIXED_DRIVE = ("throttle", "steer", "drivetrain", "seconds", "steps", "time_step", "max_force",
               "urdf", "plane", "template_params", "xacro_args", "packages", "package_paths",
               "up", "engine")
#: Of those, the ones whose "not given" is DriveConfig's default value; the rest are None.
VALUED_DRIVE = ("throttle", "steer", "drivetrain", "time_step", "up", "engine")


def drive_defaults() -> dict[str, object]:
    """DriveConfig's defaults of :data:`VALUED_DRIVE`: an option equal to one was not given."""
    from urdfkit.motion.drive import DriveConfig

    return {f.name: f.default for f in fields(DriveConfig) if f.name in VALUED_DRIVE}


@dataclass
class SweepRequest:
    """What ``urdfkit sweep`` was asked, as the library's parameters.

    ``drive`` maps names of :data:`FIXED_DRIVE` to their values: None (or, for
    :data:`VALUED_DRIVE`, DriveConfig's default) when not given; ``template_params`` holds the
    raw ``KEY=VALUE`` strings. ``keep_rows`` keeps every row in the outcome even with ``out``.
    """

    kind: str
    vary: Sequence[str] | None
    scenario: str | None = None
    drive: Mapping[str, object] = field(default_factory=dict)
    zip_: bool = False
    jobs: int | None = None
    backend: str = "local"
    address: str | None = None
    out: str | None = None
    resume: bool = False
    plot: str | None = None
    plot_file: str | None = None
    force: bool = False
    keep_rows: bool = False


@dataclass
class SweepOutcome:
    """What a sweep did: counts, the rows kept, the files written, notes for the user."""

    kind: str
    plan: sweeping.Plan
    rows: list[dict[str, object]]
    total: int
    ran: int = 0
    failed: int = 0
    skipped: int = 0
    interrupted: bool = False
    out: Path | None = None
    plot: Path | None = None
    #: Why no plot was drawn (a metric the rows do not have), or None.
    plot_error: UrdfkitError | None = None
    notes: list[str] = field(default_factory=list)

    def to_dict(self) -> dict[str, object]:
        """The ``--json`` object."""
        return {"kind": self.kind, "points": self.total, "ran": self.ran,
                "skipped": self.skipped, "failed": self.failed,
                "out": None if self.out is None else str(self.out),
                "plot": None if self.plot is None else str(self.plot),
                "interrupted": self.interrupted, "rows": self.rows}


def _given(drive: Mapping[str, object]) -> dict[str, bool]:
    defaults = drive_defaults()
    return {name: drive.get(name) != defaults.get(name) for name in FIXED_DRIVE}


def _sim_base(request: SweepRequest) -> object:
    if request.scenario is None:
        raise ParameterError("sweep sim needs the scenario file: urdfkit sweep sim "
                             "scenario.toml --vary PATH=VALUES", param="kind")
    changed = [name for name, given in _given(request.drive).items() if given]
    if changed == ["engine"]:
        raise ParameterError(f"`engine`: a sim sweep runs on its scenario's physics.engine; "
                             f"for every point on {request.drive['engine']}: `vary` "
                             f"engine={request.drive['engine']}", param="engine")
    if changed:
        raise ParameterError(f"{', '.join(f'`{n}`' for n in changed)}: drive options; a sim "
                             "sweep varies the scenario's keys (`vary` "
                             "'physics.time_step=...')", param=changed[0])
    return request.scenario


def _drive_base(request: SweepRequest) -> dict[str, object]:
    if request.scenario is not None:
        raise ParameterError(f"sweep drive takes no scenario file (got {request.scenario!r}); "
                             "drive options are flags", param="kind")
    drive = dict(request.drive)
    if drive.get("seconds") is not None and drive.get("steps") is not None:
        raise ParameterError("give `seconds` or `steps`, not both", param="seconds")
    params = None
    if drive.get("template_params"):
        from urdfkit.model.catalog import parse_assignments

        params = parse_assignments(_strings(drive["template_params"]), "template_params")
    drive["template_params"] = params
    # Not given: DriveConfig's default (seconds and max_force are None until then).
    return {name: value for name, value in drive.items()
            if name in FIXED_DRIVE and not (value is None and name in ("seconds", "max_force"))}


def _strings(value: object) -> list[str]:
    """A list of ``KEY=VALUE`` strings as given (none: empty)."""
    return [str(v) for v in value] if isinstance(value, (list, tuple)) else []


def _check_vary_against_fixed(request: SweepRequest) -> None:
    """A name both varied and given a fixed value is refused: the fixed one would be lost."""
    given = {name: given for name, given in _given(request.drive).items()
             if name not in ("template_params", "xacro_args", "packages", "package_paths")}
    set_names = {item.replace(":=", "=").partition("=")[0].strip()
                 for item in _strings(request.drive.get("template_params"))}
    for item in request.vary or []:
        name = item.partition("=")[0].strip()
        if given.get(name) or name in set_names:
            how = "template_params" if name in set_names else name
            raise ParameterError(f"{name} is given both by `{how}` and by `vary`; a varied "
                                 "value replaces the fixed one in every point: drop one",
                                 param=how)


def check_request(request: SweepRequest) -> object:
    """Refuse conflicting options, before anything is planned; return the sweep's base."""
    if request.kind == "sim":
        base = _sim_base(request)
    elif request.kind == "drive":
        base = _drive_base(request)
    else:
        raise ParameterError(f"`kind` must be drive or sim, got {request.kind!r}",
                             param="kind")
    if not request.vary:
        raise ParameterError("give at least one --vary NAME=VALUES", param="vary")
    if request.plot_file is not None and request.plot is None:
        raise ParameterError("`plot_file` says where `plot` draws: give `plot` METRIC too",
                             param="plot_file")
    if request.kind == "drive":
        _check_vary_against_fixed(request)
    if request.resume and request.out is None:
        raise ParameterError("`resume` carries on the rows of `out`: give `out`",
                             param="resume")
    return base


class SweepRun:
    """A sweep checked, planned and its rows file opened: :meth:`run` runs it.

    Everything that can be refused is refused here, before any point runs: the options, every
    point (:func:`urdfkit.sweep.plan`), the plot's file and a metric of known columns, the rows
    file (locked; with ``resume``, its rows read). :attr:`notes` says what the journal dropped.
    """

    def __init__(self, request: SweepRequest) -> None:
        """Check ``request`` and prepare the sweep (see the class)."""
        self.request = request
        base = check_request(request)
        self.plan = sweeping.plan(request.kind, base, request.vary or [], zip_=request.zip_)
        self.picture = self._check_plot()
        self.journal: sweeping.Journal | None = None
        if request.out is not None:
            self.journal = sweeping.Journal(Path(request.out), self.plan.names,
                                            resume=request.resume, force=request.force,
                                            assignments=self.plan.assignments)
            self.journal.open()
        self.notes = list(self.journal.notes) if self.journal is not None else []

    def _check_plot(self) -> str | None:
        r = self.request
        if r.plot is None:
            return None
        from urdfkit.draw.plot import check_plot_path

        picture = r.plot_file or f"sweep-{r.plot}.png"
        check_plot_path(picture, force=r.force)
        if r.kind == "drive":  # known columns: refuse a typo before the run
            sweeping.check_metric(r.kind, [], self.plan.names, r.plot)
        else:
            sweeping.check_sim_metric(self.plan, r.plot)
        return picture

    def run(self, progress: Callable[[int, int], None] | None = None) -> SweepOutcome:
        """Run the points not done yet; rows go to the journal as they finish.

        Ctrl-C stops the loop and keeps the rows so far (``interrupted``); the journal is
        finished either way. ``progress(done, count)`` is called after each row.
        """
        r, journal = self.request, self.journal
        keep = r.out is None or r.plot is not None or r.keep_rows
        rows: list[dict[str, object]] = list(journal.done) if journal is not None and keep else []
        skip = journal.finished if journal is not None and r.resume else None
        total = len(self.plan.assignments)
        count = total - sum(1 for a in self.plan.assignments if skip is not None and skip(a))
        outcome = SweepOutcome(r.kind, self.plan, rows, total, skipped=total - count)
        try:
            for row in sweeping.execute(self.plan, jobs=r.jobs, backend=r.backend,
                                        address=r.address, skip=skip):
                outcome.ran += 1
                outcome.failed += bool(row.get("error"))
                if journal is not None:
                    journal.add(row)
                if keep:
                    rows.append(row)
                if progress is not None:
                    progress(outcome.ran, count)
        except KeyboardInterrupt:
            outcome.interrupted = True
        finally:
            if journal is not None:
                outcome.out = journal.finish()
        if journal is not None:
            outcome.notes = journal.notes[len(self.notes):]
        return outcome

    def draw(self, outcome: SweepOutcome) -> None:
        """Draw ``--plot`` from the rows, or say in ``plot_error`` why it cannot be drawn."""
        r = self.request
        if self.picture is None or r.plot is None or not outcome.rows:
            return
        from urdfkit.draw.plot import write_sweep_plot

        try:  # a scenario's joint names are known only now: the rows are kept either way
            sweeping.check_metric(r.kind, outcome.rows, self.plan.names, r.plot)
        except UrdfkitError as e:
            outcome.plot_error = e
        else:
            outcome.plot = write_sweep_plot(outcome.rows, self.plan.names, r.plot,
                                            self.picture, force=r.force)
