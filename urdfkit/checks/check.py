"""``urdfkit check``: run every validation rule over many files, in parallel, never crashing.

Folders are searched recursively for ``*.urdf`` and ``*.xacro``; xacro is expanded in a
subprocess (:func:`urdfkit.sources.expand.expand_xacro`). Each file is checked on its own: a file
that cannot be read, expanded or parsed becomes a ``U000`` error finding for that file, never
an exception, so one broken file cannot stop a sweep over a thousand others. PyBullet is never
loaded: checking is pure lxml, which is what makes it safe on hostile input and fast.
"""

from __future__ import annotations

import os
import re
import sys
from collections.abc import Iterable, Mapping, Sequence
from operator import attrgetter
from pathlib import Path
from typing import TYPE_CHECKING, Any

from lxml import etree

from urdfkit.checks.validate import ALL_RULES
from urdfkit.core.errors import InputError, ParameterError, XacroNotExpanded
from urdfkit.core.finding import LEVELS, Finding
from urdfkit.model.spec import PYBULLET_LINE_BYTES
from urdfkit.model.xmlio import (
    line_of,
    long_line,
    parse_xml,
    read_bytes,
    read_regular,
    tolerate_quirks,
    xacro_marker,
    xacro_note,
)
from urdfkit.sources.guard import refuse_oversized, run_rules
from urdfkit.sources.uris import settled

if TYPE_CHECKING:
    from urdfkit.checks.resultcache import ResultCache, RunManifest

#: File suffixes a folder search picks up.
SUFFIXES = (".urdf", ".xacro")
#: Findings that say the same thing of every file: reported once per run, on the first file.
ONCE_PER_RUN = frozenset({"U607"})
#: Below this many files a process pool costs more than it saves.
_PARALLEL_MIN = 8


class FileResult:
    """The findings of one file.

    Attributes:
        file: The file, as the user named it.
        findings: Its findings.
        cached: Whether the findings came from the result cache (not in the JSON).
        entry: What the run's manifest keeps of a cacheable result: the file's stat, the
            paths it read with their signatures, the findings as dicts
            (:class:`urdfkit.checks.resultcache.RunManifest`).
        meshes: The mesh cache entries a worker process used, for the run's pack (not in
            the JSON).
        includes: Whether the bytes checked (the file's own, not xacro's output) mention
            ``include``; None when unknown (a cached result, xacro): what
            :func:`_judge_fragments` would otherwise read the file again to learn.

    Two are equal when their files and findings are. (Plain classes, here and in
    :class:`CheckResult`: each dataclass costs ~0.7 ms at import on every run.)
    """

    __slots__ = ("file", "findings", "cached", "entry", "meshes", "includes")

    def __init__(self, file: str, findings: list[Finding] | None = None, cached: bool = False,
                 entry: tuple[tuple[int, int, int, int], dict[str, Any],
                              list[dict[str, Any]]] | None = None,
                 meshes: dict[str, Any] | None = None) -> None:
        self.file = file
        self.findings: list[Finding] = [] if findings is None else findings
        self.cached = cached
        self.entry = entry
        self.meshes = meshes
        self.includes: bool | None = None

    def __eq__(self, other: object) -> bool:
        if other.__class__ is not FileResult:
            return NotImplemented
        assert isinstance(other, FileResult)
        return (self.file, self.findings) == (other.file, other.findings)

    __hash__ = None  # type: ignore[assignment]  # mutable

    def __repr__(self) -> str:
        return f"FileResult(file={self.file!r}, findings={self.findings!r})"

    def count(self, level: str) -> int:
        """How many findings of ``level``."""
        return sum(1 for f in self.findings if f.level == level)


class CheckResult:
    """The findings of a whole ``check`` run, file by file in discovery order."""

    __slots__ = ("files",)

    def __init__(self, files: list[FileResult]) -> None:
        self.files = files

    def __eq__(self, other: object) -> bool:
        if other.__class__ is not CheckResult:
            return NotImplemented
        assert isinstance(other, CheckResult)
        return self.files == other.files

    __hash__ = None  # type: ignore[assignment]  # mutable

    def __repr__(self) -> str:
        return f"CheckResult(files={self.files!r})"

    @property
    def findings(self) -> list[Finding]:
        """Every finding, file by file."""
        return [f for fr in self.files for f in fr.findings]

    def summary(self) -> dict[str, int]:
        """Counts for the summary line and the JSON ``summary`` (one pass over the findings)."""
        counts = dict.fromkeys(LEVELS, 0)
        with_errors = 0
        for fr in self.files:
            errors = counts["error"]
            for f in fr.findings:
                if f.level in counts:
                    counts[f.level] += 1
            with_errors += counts["error"] > errors
        return {"files": len(self.files), "files_with_errors": with_errors,
                **{level: counts[level] for level in reversed(LEVELS)}}

    def exit_code(self, fail_on: str = "error") -> int:
        """0 if nothing is at or above ``fail_on``, else 1."""
        threshold = LEVELS.index(fail_on)
        return int(any(LEVELS.index(f.level) >= threshold for f in self.findings))

    def to_dict(self) -> dict[str, object]:
        """The ``--json`` form."""
        return {"files": [fr.file for fr in self.files],
                "findings": [f.to_dict() for f in self.findings],
                "summary": self.summary()}


def parse_codes(items: Sequence[str] | None, option: str) -> tuple[str, ...]:
    """Parse ``--select``/``--ignore`` values: codes or code prefixes, comma-separated.

    A prefix selects a family (``U6`` is every mass and inertia rule).

    Raises:
        ParameterError: a value matches no known code.
    """
    if not items:
        return ()
    from urdfkit.checks.validate import CODES

    out: list[str] = []
    for item in items:
        for code in (c.strip().upper() for c in item.split(",")):
            if not code:
                continue
            if not any(k.startswith(code) for k in CODES):
                raise ParameterError(f"{option} {code}: no such rule code (see docs/check.md; "
                                     f"codes run {min(CODES)}..{max(CODES)})")
            out.append(code)
    return tuple(out)


def discover(paths: Iterable[str | Path]) -> list[tuple[str, str, str | None]]:
    """Expand the command-line paths into ``(display name, path, problem)`` triples.

    A folder is walked with ``os.scandir`` (not following symlinked folders, so a link loop
    cannot trap the walk), entries sorted per folder. Every entry named ``*.urdf`` or
    ``*.xacro`` is listed whatever it is (a FIFO, a device, a folder): reading reports what it
    really is. A folder that cannot be listed comes back with its ``problem``, to be reported,
    never skipped.

    Raises:
        ParameterError: a path given on the command line does not exist (exit code 2).
    """
    out: list[tuple[str, str, str | None]] = []
    seen: set[str] = set()

    def add(display: str, path: str, problem: str | None = None, key: str | None = None) -> None:
        key = os.path.abspath(path) if key is None else key
        if key not in seen:
            seen.add(key)
            out.append((display, path, problem))

    for item in paths:
        path = Path(item)
        if not os.path.lexists(path):
            path = _bare_name(item)
        if path.is_dir() and path.suffix.lower() not in SUFFIXES:
            # An entry's abspath is the walk's, then its own part of the path (no "." or ".."
            # in an entry's name, no trailing "/" on a Path's): one abspath per walk.
            top = str(path)
            top_key = os.path.abspath(top)
            stack = [top]
            while stack:
                folder = stack.pop()
                try:
                    with os.scandir(folder) as it:
                        entries = sorted(it, key=_entry_name)
                except OSError as e:
                    add(folder, folder, f"cannot list this folder: {e.strerror}")
                    continue
                subdirs = []
                for entry in entries:
                    if entry.name.lower().endswith(SUFFIXES):
                        add(entry.path, entry.path, key=top_key + entry.path[len(top):])
                        continue
                    try:
                        is_dir = entry.is_dir(follow_symlinks=False)
                    except OSError:
                        is_dir = False
                    if is_dir:
                        subdirs.append(entry.path)
                stack.extend(reversed(subdirs))
        else:
            add(str(item), str(path))
    return out


#: A folder entry's name, the key its folder's entries are sorted by (C, no lambda call).
_entry_name = attrgetter("name")


def _bare_name(item: str | Path) -> Path:
    """A path not found as given: looked up as every command does (pybullet_data, did you mean).

    Raises:
        ParameterError: not there either (exit code 2).
    """
    from urdfkit.sources.resolve import locate

    try:
        return locate(item)
    except InputError as e:
        raise ParameterError(f"{item}: {e.message}") from None


def _is_xacro(name: str) -> bool:
    """Whether ``Path(name).suffix == ".xacro"``, without making the Path."""
    base = name.rpartition(os.sep)[2]
    return base[-6:].lower() == ".xacro" and len(base) > 6


def _read(path: str, display: str, no_exec: bool = False,
          packages: Mapping[str, Path] | None = None,
          xacro_args: Mapping[str, str] | None = None, data: bytes | None = None) -> bytes:
    if _is_xacro(path):
        from urdfkit.sources.expand import expand_xacro
        from urdfkit.sources.uris import not_a_file

        source = Path(path)
        why = not_a_file(source)
        if why is not None:  # never hand xacro a FIFO to block on
            raise InputError(f"is {why}, not a regular file; urdfkit reads only regular files"
                             if why != "missing" else "no such file", file=display)
        return expand_xacro(source, xacro_args, display=display, no_exec=no_exec,
                            packages=packages, strict_args=False, text=data)
    return read_bytes(path) if data is None else data


def check_file(display: str, path: str | Path,
               packages: Mapping[str, Path] | None = None, no_exec: bool = False,
               xacro_args: Mapping[str, str] | None = None,
               physics: bool = False, targets: Sequence[str] = (),
               data: bytes | None = None, expanded: bytes | None = None) -> FileResult:
    """Run every rule on one file; any failure to read it becomes a ``U000`` finding.

    ``data`` stands for the file's bytes (an editor's unsaved buffer; a xacro is expanded as
    if it held them, its includes found beside it). ``expanded`` is a xacro's expansion
    already made (:func:`urdfkit.sources.expand.expand_xacro`, with its origins): not made again.

    ``targets`` (:func:`urdfkit.checks.targets.parse_targets`) adds what those consumers
    refuse or change (``T`` codes).

    With ``no_exec`` (or URDFKIT_NO_EXEC set) a xacro file is not expanded: it gets one
    ``U006`` warning saying so, and is otherwise unchecked. With ``physics`` a file with no
    error is also loaded in PyBullet and tested for self-collision at its zero pose (U950).
    """
    name = os.fspath(path)
    xacro_file = _is_xacro(name)
    result = FileResult(display)
    try:  # (a file that cannot be read leaves data as given: None, or the buffer)
        data = expanded if expanded is not None and xacro_file else \
            _read(name, display, no_exec, packages, xacro_args, data)
        refuse_oversized(data, display)
        fixed, quirks = tolerate_quirks(data)
        tree = parse_xml(fixed, display, tolerated=True)
    except XacroNotExpanded as e:
        result.findings.append(Finding("U006", "warning", e.message, display))
        return result
    except InputError as e:
        code = getattr(e, "code", "U000")  # U209 for a body refused before parsing
        result.findings.append(Finding(code, "error", e.message, display, e.line))
        if targets and code == "U000":  # what other parsers make of it
            from urdfkit.checks.targets import unparsed

            folder = os.path.dirname(os.path.abspath(name))
            result.findings.extend(unparsed(display, data, targets, base=folder,
                                            packages=packages))
        return result
    except (OSError, ValueError, etree.LxmlError) as e:  # belt and braces: never crash a sweep
        result.findings.append(Finding("U000", "error", f"cannot check: {e}", display))
        return result
    findings = result.findings
    if not xacro_file:
        result.includes = b"include" in data
    for line, note in quirks:
        findings.append(Finding("U004", "warning", note, display, line))
    if not xacro_file:
        xacro = xacro_marker(data)
        if xacro is not None:
            findings.append(Finding("U009", "warning", xacro_note(xacro[1]), display, xacro[0]))
        too_long = long_line(data)
        if too_long is not None:
            findings.append(Finding(
                "U008", "warning", f"line {too_long[0]} is {too_long[1]} bytes long: PyBullet "
                f"reads lines in {PYBULLET_LINE_BYTES}-byte pieces and breaks them there, so "
                "p.loadURDF refuses or misreads the file when a break falls inside a name "
                "(urdfkit loads a reformatted copy); put one element per line", display,
                too_long[0]))
    root = tree.getroot()
    if xacro_file and _macro_library(root):
        findings.append(Finding("U007", "info", "a xacro macro library (no links of its "
                                "own): checked through the files that include it", display))
        return result
    # Path(name).absolute().parent, as a string (no Path: ~3 us a file).
    folder = os.path.dirname(name if os.path.isabs(name) else os.path.join(os.getcwd(), name))
    rules = ALL_RULES
    if targets:
        from urdfkit.checks.targets import target_rules

        rules = (*rules, *target_rules(targets))
    found = run_rules(root, display, rules, base=folder,
                      packages=packages, origins=getattr(data, "origins", None))
    if xacro_file:
        # Lines of xacro's output are not lines of the file the user wrote: none, not a false
        # one (each message names its element).
        found = [Finding(f.code, f.level, f.message, f.file, None, f.origin) for f in found]
    findings.extend(found)
    if physics and not any(f.level == "error" for f in findings):
        lines = {} if xacro_file else \
            {el.get("name"): line_of(el) for el in root.iterchildren("link")}
        findings.extend(physics_findings(display, Path(name), lines, packages, xacro_args))
    findings.sort(key=_line_key)
    return result


def _line_key(f: Finding) -> int:
    return f.line or 0


def physics_findings(display: str, path: Path, lines: Mapping[str | None, int | None],
                     packages: Mapping[str, Path] | None = None,
                     xacro_args: Mapping[str, str] | None = None) -> list[Finding]:
    """``check --physics``: load the file in PyBullet and test its zero pose (U950, U951).

    Only files with no error finding get here: the rules have ruled out every crash class.
    """
    from urdfkit.checks.collisions import self_collisions
    from urdfkit.core.errors import UrdfkitError
    from urdfkit.sources.resolve import resolve

    try:
        with resolve(path, packages=packages, xacro_args=xacro_args,
                     strict_args=False) as resolved:
            resolved.name = display
            found = self_collisions(resolved, packages=packages)
    except UrdfkitError as e:
        return [Finding("U951", "error", f"PyBullet cannot load it: {e.message}", display,
                        e.line)]
    args = " with the same --arg values" if xacro_args and path.suffix == ".xacro" else ""
    out = []
    for x in found.pairs:
        hull = (f"; {' and '.join(x.hull)} collide{'s' if len(x.hull) == 1 else ''} as a "
                "convex hull, so the contact may be in a dip of the mesh") if x.hull else ""
        out.append(Finding(
            "U950", "warning", f"links {x.link_a!r} and {x.link_b!r} "
            f"{'interpenetrate by' if x.distance < 0 else 'touch at'} "
            f"{abs(x.distance) * 1000:.3g} mm at the zero pose: once self-collision is on "
            "(URDF_USE_SELF_COLLISION) PyBullet pushes them apart every step and the robot "
            f"jitters; fix the shapes, or disable the pair (urdfkit collisions {display} --python "
            f"or --srdf{args}){hull}", display, lines.get(x.link_a)))
    return out


def _macro_library(root: object) -> bool:
    """A xacro file that only defines macros or properties: after expansion, no <link>.

    Real libraries carry a ``name`` (franka_description's franka_arm.xacro) or use ROS 1's
    ``<root>`` element (pr2_description's sensors); what marks them is that expanding them
    alone makes nothing.
    """
    assert isinstance(root, etree._Element)
    return root.tag in ("robot", "root") and root.find("link") is None


_Job = tuple[str, str, str | None, dict[str, str], bool, dict[str, str], bool, bool,
             tuple[str, ...]]
_caches: dict[tuple[object, ...], object] = {}


def _result_cache(packages: Mapping[str, str], no_exec: bool, xacro_args: Mapping[str, str],
                  physics: bool, targets: tuple[str, ...] = ()) -> ResultCache | None:
    """The result cache for these options, made once per option set and process."""
    from urdfkit.checks.resultcache import ResultCache

    memo = (tuple(sorted(packages.items())), no_exec, tuple(sorted(xacro_args.items())),
            physics, targets, os.environ.get("URDFKIT_CACHE_DIR"))
    if memo not in _caches:  # the key prefix is made once
        options: dict[str, object] = {"packages": dict(packages), "no_exec": no_exec,
                                      "xacro_args": dict(xacro_args), "physics": physics}
        if targets:  # only when given: the keys of a plain check stay as they were
            options["targets"] = list(targets)
        if physics:  # U950/U951 come from PyBullet itself
            from importlib.metadata import version

            options["pybullet"] = version("pybullet")
        _caches[memo] = ResultCache.open(options)
    cache = _caches[memo]
    assert cache is None or isinstance(cache, ResultCache)
    return cache


def _check_one(job: _Job) -> FileResult:
    display, path, problem, packages, no_exec, xacro_args, physics, use_cache, targets = job
    if problem is not None:
        return FileResult(display, [Finding("U000", "error", problem, display)])
    pkgs = {k: Path(v) for k, v in packages.items()} if packages else {}
    cache = _result_cache(packages, no_exec, xacro_args, physics, targets) if use_cache \
        else None
    if cache is None:
        return check_file(display, path, pkgs, no_exec, xacro_args, physics, targets)
    from urdfkit.checks.resultcache import file_stat
    from urdfkit.core import deps

    seen = file_stat(path)  # before the bytes are read: an edit after this misses next run
    key = cache.key(display, path)
    if key is None:
        return check_file(display, path, pkgs, no_exec, xacro_args, physics, targets)
    hit = cache.get_entry(key)
    if hit is not None:
        return FileResult(display, [Finding(**f) for f in hit[1]], cached=True,
                          entry=(seen, *hit) if seen is not None else None)
    with deps.record() as recorded:  # the file itself is in the key, by its content
        result = check_file(display, path, pkgs, no_exec, xacro_args, physics, targets)
    recorded.pop(os.path.abspath(path), None)
    found = [f.to_dict() for f in result.findings]
    if cache.put(key, recorded, found) and seen is not None:
        result.entry = (seen, dict(recorded), found)
    return result


def worker_init() -> None:
    """Pool workers die with their parent and never hold the caller's stdout open."""
    import signal

    signal.signal(signal.SIGINT, signal.SIG_IGN)  # the parent handles Ctrl-C for everyone
    for sig in (signal.SIGTERM, signal.SIGHUP):  # the pool ends workers with SIGTERM: just die
        signal.signal(sig, signal.SIG_DFL)
    devnull = os.open(os.devnull, os.O_WRONLY)
    os.dup2(devnull, 1)  # a `check ... | cat` pipe ends when the parent does
    os.close(devnull)
    if sys.platform.startswith("linux"):
        import ctypes

        try:
            libc = ctypes.CDLL(None, use_errno=True)
            libc.prctl(1, signal.SIGKILL)  # PR_SET_PDEATHSIG: killed when the parent dies
        except (OSError, AttributeError):  # pragma: no cover - no prctl
            pass
        if os.getppid() == 1:  # the parent died before prctl: do not linger
            os._exit(1)


def default_jobs() -> int:
    """Worker processes for ``check``: the cores this process may run on."""
    if hasattr(os, "sched_getaffinity"):
        return max(1, len(os.sched_getaffinity(0)))
    return os.cpu_count() or 1


def _keep(code: str, select: tuple[str, ...], ignore: tuple[str, ...]) -> bool:
    if select and not any(code.startswith(s) for s in select):
        return False
    return not any(code.startswith(i) for i in ignore)


def check_paths(paths: Iterable[str | Path], *, packages: Mapping[str, Path] | None = None,
                select: Sequence[str] = (), ignore: Sequence[str] = (),
                jobs: int | None = None, no_exec: bool = False,
                xacro_args: Mapping[str, str] | None = None,
                physics: bool = False, cache: bool = True,
                targets: Sequence[str] = ()) -> CheckResult:
    """Check every file under ``paths``, over ``jobs`` processes (default: every core).

    ``physics`` loads each file without errors in PyBullet for the U95x rules. ``targets``
    (:func:`urdfkit.checks.targets.parse_targets`) adds what those consumers refuse or
    change. ``cache``
    reuses a file's findings while neither it nor anything it read changed
    (:mod:`urdfkit.checks.resultcache`; also off when ``URDFKIT_CACHE_DIR`` is empty).

    Workers are killed with the parent (Ctrl-C, SIGTERM, even SIGKILL on Linux) and never
    hold its stdout.

    Raises:
        ParameterError: a path does not exist, or ``jobs`` is not positive.
    """
    if jobs is not None and (isinstance(jobs, bool) or jobs < 1):
        raise ParameterError(f"`jobs` must be 1 or more, got {jobs!r}", param="jobs")
    given = [os.fspath(p) for p in paths]
    files = discover(given)
    pkgs = {k: str(v) for k, v in (packages or {}).items()}
    args = dict(xacro_args or {})
    aimed = tuple(targets)
    if select:
        from urdfkit.checks.targets import check_selection

        check_selection(select, aimed)
    manifest = _manifest(given, pkgs, no_exec, args, physics, aimed) if cache else None
    results: list[FileResult | None] = [None] * len(files)
    todo = []
    for n, (display, path, problem) in enumerate(files):
        hit = manifest.lookup(display, path) if manifest and problem is None else None
        if hit is not None:
            results[n] = FileResult(display, hit, cached=True)
        else:
            todo.append(n)
    if todo:
        work = [(*files[n], pkgs, no_exec, args, physics, cache, aimed) for n in todo]
        for n, fr in zip(todo, _check_misses(given, work, jobs, manifest), strict=True):
            results[n] = fr
    if manifest is not None:
        manifest.save()
    if cache and todo:
        from urdfkit.checks.resultcache import ResultCache

        store = ResultCache.open({})
        if store is not None:
            store.trim()  # new entries were written: keep the folder under its cap
    done = [fr for fr in results if fr is not None]
    _judge_fragments(done, files, packages)
    _keep_selected(done, tuple(select), tuple(ignore))
    return CheckResult(done)


def _check_misses(given: Sequence[str], work: list[_Job], jobs: int | None,
                  manifest: RunManifest | None) -> list[FileResult]:
    """Check the files the result cache did not answer; keep what the caches will need.

    The run's mesh pack is loaded before workers fork (they inherit it) and saved after with
    the entries they used; each result the manifest can keep is added to it.
    """
    from urdfkit.sources import meshstore as meshes

    meshes.load_pack(given)
    with settled():  # package lookups made once for the run (its workers fork inside)
        out = _run_jobs(work, jobs)
        for (display, path, problem, *_), fr in zip(work, out, strict=True):
            if manifest is not None and problem is None:
                manifest.add(display, path, fr.entry)
            if fr.meshes:
                meshes.USED.update(fr.meshes)
    meshes.save_pack(given)
    return out


def _keep_selected(done: list[FileResult], select: tuple[str, ...],
                   ignore: tuple[str, ...]) -> None:
    """Keep the findings ``select`` and ``ignore`` let through, and each once-per-run one once."""
    noted = False
    for fr in done:
        kept = []
        for f in fr.findings:
            if f.code in ONCE_PER_RUN:  # the same advice for every file: say it once
                if noted:
                    continue
                noted = True
            if _keep(f.code, select, ignore):
                kept.append(f)
        fr.findings = kept


#: What a file that is not a robot on its own gets: a fragment has no name, no links, or
#: joints to links another file defines, or more than one root.
_NOT_A_ROBOT = frozenset({"U002", "U003", "U201", "U202", "U205", "U206"})
#: ``<xacro:include filename="...">`` (any prefix bound to xacro; either quote). Patterns
#: compiled where used (re keeps them): most runs include nothing, and these cost ~0.3 ms.
_INCLUDE = (rb"<\s*[A-Za-z_][\w.-]*:include\b[^>]*?\bfilename\s*=\s*"
            rb"(?:\"([^\"]*)\"|'([^']*)')")
#: The substitutions an include's filename may hold that can be worked out without xacro.
_SUBST = r"\$\((find|optenv|env)\s+([^\s()]+)(?:\s+((?:[^()]|\([^()]*\))*))?\)"


def _judge_fragments(done: list[FileResult], files: Sequence[tuple[str, str, str | None]],
                     packages: Mapping[str, Path] | None) -> None:
    """A file another checked file includes, and that is no robot alone, is a fragment (U010).

    Clearpath's ``empty.urdf`` placeholders and Sawyer's ``*.gazebo.xacro`` are pieces of the
    robot their includer builds: checked alone they have no name, no links, or joints to
    links defined elsewhere. Their includer's check covers them; they get one note.
    """
    # Only a file that is no robot alone can be one: most runs have none, and then no file is
    # read a second time (a warm re-run reads none at all otherwise).
    by_path = {os.path.abspath(path): n for n, (_, path, problem) in enumerate(files)
               if problem is None and any(f.code in _NOT_A_ROBOT for f in done[n].findings)}
    if not by_path or len(files) < 2:
        return
    includers: dict[int, str] = {}
    for n, (display, path, problem) in enumerate(files):
        if problem is not None or done[n].includes is False:
            continue  # not a file; or its bytes, searched when it was checked, include nothing
        if any(f.code == "U000" for f in done[n].findings):
            continue  # unreadable, or not XML: nothing to follow
        try:  # never a FIFO or device (opened non-blocking, refused unless regular)
            data = read_regular(path, track=False)
        except InputError:
            continue
        if b"include" not in data:
            continue
        folder = os.path.dirname(os.path.abspath(path))
        for m in re.finditer(_INCLUDE, data):
            raw = (m.group(1) or m.group(2) or b"").decode("utf-8", "replace")
            target = _include_target(raw, folder, packages)
            k = by_path.get(target) if target is not None else None
            if k is not None and k != n:
                includers.setdefault(k, display)
    for k, includer in includers.items():
        fr = done[k]
        if any(f.code in _NOT_A_ROBOT for f in fr.findings):
            fr.findings = [Finding("U010", "info", f"a fragment, not a robot: {includer} "
                                   "includes it (xacro:include), and its links and joints are "
                                   "checked through that file", fr.file)]



def _include_target(raw: str, folder: str, packages: Mapping[str, Path] | None) -> str | None:
    """The absolute path an include's filename names, or None where xacro alone can say."""
    from urdfkit.sources.uris import find_package

    def sub(m: re.Match[str]) -> str:
        kind, name, rest = m.group(1), m.group(2), (m.group(3) or "").strip()
        if kind == "find":
            found = (packages or {}).get(name) or find_package(name, Path(folder))
            if found is None:
                raise LookupError(name)
            return str(found)
        value = os.environ.get(name)
        if value is None:
            if kind == "env" or not rest:
                raise LookupError(name)
            return re.sub(_SUBST, sub, rest)
        return value

    try:
        text = re.sub(_SUBST, sub, raw.strip())
    except LookupError:
        return None
    if not text or "$" in text:
        return None  # ${...} or $(arg ...): only xacro knows
    return os.path.abspath(os.path.join(folder, text))


def _manifest(paths: Sequence[str], packages: Mapping[str, str], no_exec: bool,
              xacro_args: Mapping[str, str], physics: bool,
              targets: tuple[str, ...]) -> RunManifest | None:
    cache = _result_cache(packages, no_exec, xacro_args, physics, targets)
    if cache is None:
        return None
    from urdfkit.checks.resultcache import RunManifest

    return RunManifest(cache, paths)


def _run_jobs(work: list[_Job], jobs: int | None) -> list[FileResult]:
    """Check each job, over ``jobs`` processes (default: every core) when there are enough."""
    workers = min(jobs or default_jobs(), max(1, len(work) // _PARALLEL_MIN))
    if workers <= 1:
        return [_check_one(w) for w in work]
    import multiprocessing

    # Large chunks: a URDF takes about a millisecond to check, less than a round trip.
    chunk = max(1, len(work) // (workers * 4))
    context = multiprocessing.get_context("fork" if sys.platform.startswith("linux")
                                          else "spawn")
    # The with block terminates the workers on the way out, normal or not (Ctrl-C).
    with context.Pool(workers, initializer=worker_init) as pool:
        return pool.map(_check_in_worker, work, chunksize=chunk)


def _check_in_worker(job: _Job) -> FileResult:
    """:func:`_check_one` in a pool worker, handing back the mesh entries it used."""
    from urdfkit.sources import meshstore as meshes

    meshes.USED.clear()
    result = _check_one(job)
    result.meshes = dict(meshes.USED)
    return result
