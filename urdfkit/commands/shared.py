"""What the commands share: the options declared once, flag names in messages, small helpers.

Every command module under :mod:`urdfkit.commands` builds its signature from these
``Annotated`` options, so ``drive`` and ``sweep drive`` take the very same objects. Nothing
heavy is imported here: ``urdfkit --help`` imports every command module.
"""

from collections.abc import Callable
from typing import Annotated, Any, TypeVar

import typer

from urdfkit.commands import present as show
from urdfkit.commands.flags import input_flags

F = TypeVar("F", bound=Callable[..., Any])


class _FromLibrary:
    def __repr__(self) -> str:
        return "<the library's default>"


#: A default the library owns (e.g. DriveConfig's): the command module puts the library's value
#: in before typer builds the command (see :func:`library_defaults`). Only ``urdfkit --help``
#: builds commands without it, and parses no option.
FROM_LIBRARY: Any = _FromLibrary()


def command(epilog: str) -> Callable[[F], F]:
    """Mark a function as a command with its examples; :mod:`urdfkit.cli` registers it."""
    def mark(func: F) -> F:
        func.__dict__["epilog"] = epilog
        return func
    return mark


def library_defaults(func: Callable[..., Any], defaults: dict[str, Any]) -> None:
    """Put the library's defaults in place of :data:`FROM_LIBRARY` in ``func``'s signature.

    typer reads the defaults when it builds the command, so the help shows the library's
    value and an option not given gets it, without the library imported by ``urdfkit --help``.
    """
    code = func.__code__
    names = code.co_varnames[:code.co_argcount]
    old = func.__defaults__ or ()
    func.__defaults__ = tuple(defaults.get(n, d) if d is FROM_LIBRARY else d
                              for n, d in zip(names[len(names) - len(old):], old, strict=True))


def examples(*lines: str) -> str:
    """The examples block that ends every command's help (kept verbatim by rich help)."""
    return "\n\n[bold]Examples[/]\n\n" + "\n".join(f"  [dim]$[/] {line}" for line in lines)


SetOpt = Annotated[list[str] | None, typer.Option(
    "--set", "-s", metavar="KEY=VALUE",
    help="Template parameter (repeatable). See `urdfkit templates`.")]
ArgOpt = Annotated[list[str] | None, typer.Option(
    "--arg", "-a", metavar="NAME:=VALUE", help="xacro argument (repeatable).")]
ForceOpt = Annotated[bool, typer.Option("--force", "-f", help="Overwrite an existing file.")]
# Options shared by every command that reads a robot file (resolve.open_input takes them raw).
PackageOpt = Annotated[list[str] | None, typer.Option(
    "--package", "-p", metavar="NAME=PATH",
    help="Where package://NAME/ points (repeatable); else found by walking up from the file.")]
PackagePathOpt = Annotated[list[str] | None, typer.Option(
    "--package-path", metavar="DIR",
    help="A folder searched for ROS packages (package.xml) for package:// and $(find) "
    "(repeatable); ROS_PACKAGE_PATH and AMENT_PREFIX_PATH are searched too.")]
JsonOpt = Annotated[bool, typer.Option("--json", help="Print one JSON object on stdout.")]
FixedBaseOpt = Annotated[bool, typer.Option("--fixed-base", help="Pin the root link to the world.")]
FlagsOpt = Annotated[str | None, typer.Option(
    "--flags", metavar="NAMES",
    help="Exactly these PyBullet loadURDF flags, comma-separated (URDF_USE_INERTIA_FROM_FILE, "
    "URDF_USE_IMPLICIT_CYLINDER, ...; the URDF_ may be left out), or none: to match your own "
    "p.loadURDF call. Default: URDF_USE_IMPLICIT_CYLINDER (true cylinders).",
    show_default=False)]
NoGuardOpt = Annotated[bool, typer.Option(
    "--no-guard", help="Lift the guard's refusals that are stricter than PyBullet ('%' in a "
    "joint name, names over 1000 bytes); each is printed as a warning. What crashes PyBullet "
    "stays refused.")]

MovableOpt = Annotated[bool, typer.Option("--movable", help="Only joints that can move.")]
TypeOpt = Annotated[list[str] | None, typer.Option(
    "--type", "-t", metavar="TYPE",
    help="Only joints of this type (repeatable): revolute, continuous, prismatic, fixed, ...")]
AllOpt = Annotated[bool, typer.Option("--all", help="Show every field, however wide.")]
FileArg = Annotated[str, typer.Argument(
    help="A .urdf or .xacro file; a bare name is also looked up in pybullet_data, and a "
    "template name (simplecar) is that template.")]


def open_input_and_warn(file: str, *, packages: list[str] | None,
                        xacro_args: list[str] | None, guard: bool,
                        package_paths: list[str] | None = None, meshes: bool = True) -> Any:
    """:func:`urdfkit.sources.resolve.open_input`, and its warnings said on stderr.

    Takes the library's keyword-only options under the library's names: a command passes
    ``guard=not no_guard``, so no flag means its opposite on the way down.
    """
    from urdfkit.sources.resolve import open_input

    resolved = open_input(file, packages=packages, xacro_args=xacro_args, guard=guard,
                          package_paths=package_paths, meshes=meshes)
    for w in resolved.warnings:
        show.warn(input_flags(w))
    return resolved


def split_joints(items: list[str] | None) -> list[str] | None:
    """``--wheels a,b --wheels c``: the joint names or indices, one list."""
    if items is None:
        return None
    return [j.strip() for item in items for j in item.split(",") if j.strip()]


# Options of `drive` that `sweep drive` takes too.
ThrottleOpt = Annotated[float, typer.Option(
    help="Wheel speed, rad/s: of a wheel on the car's centre line (each wheel turns as "
    "its path needs); with --drivetrain locked, of every wheel. Negative reverses.")]
SteerOpt = Annotated[float, typer.Option(
    help="Steering angle, rad, of the kinematic bicycle model (hinges get Ackermann "
    "angles); positive turns left. Without hinges (skid steer): the yaw rate, rad/s.")]
DrivetrainOpt = Annotated[str, typer.Option(
    "--drivetrain", metavar="differential|rear|locked",
    help="differential: every wheel at the speed its path needs; rear: rear wheels so, "
    "fronts roll free; locked: every wheel at --throttle, as the tutorial.")]
SecondsOpt = Annotated[float | None, typer.Option(
    help="Simulated duration in seconds.", show_default="10")]
StepsOpt = Annotated[int | None, typer.Option(help="Number of physics steps instead.")]
TimeStepOpt = Annotated[float, typer.Option(help="Physics time step, s.", show_default="1/240")]
MaxForceOpt = Annotated[float | None, typer.Option(
    help="Wheel motor torque limit, N m.", show_default="10")]
UrdfOpt = Annotated[str | None, typer.Option(
    help="Car to drive (.urdf/.xacro; pybullet_data and template names work).",
    show_default="the built-in simplecar")]
PlaneOpt = Annotated[str | None, typer.Option(
    help="Ground to drive on.", show_default="the built-in simpleplane")]
# drive, sim: the physics engine (urdfkit/engine/registry.py); sim's default is the scenario's.
EngineOpt = Annotated[str, typer.Option(
    "--engine", metavar="pybullet|mujoco", help="The physics engine: mujoco runs the MJCF "
    "export in memory (needs urdfkit\\[mujoco]; docs/engines.md).")]
UpOpt = Annotated[str, typer.Option(
    "--up", metavar="z|y|x", help="The car's up axis: y stands up a Y-up model.")]
# drive --view and sim --view: the run streamed to a browser page (urdfkit/view.py).
ViewOpt = Annotated[bool, typer.Option(
    "--view", help="Stream the run to a browser page (urdfkit view) while it simulates "
    "headless; the run starts when a page connects, and the page stays up after the run "
    "until Ctrl-C.")]
SpeedOpt = Annotated[str, typer.Option(
    "--speed", metavar="FACTOR|max", help="With --view: simulated seconds per wall second "
    "(max: no pacing).")]
NoWaitOpt = Annotated[bool, typer.Option(
    "--no-wait", help="With --view: start the run at once, not when the first page "
    "connects, and end with it (for scripts).")]
WaitTimeoutOpt = Annotated[float | None, typer.Option(
    "--wait-timeout", min=0, metavar="SECONDS", help="With --view: wait at most SECONDS for "
    "a page; none came, the run starts unwatched and the command ends with it.",
    show_default="no limit")]
RunPortOpt = Annotated[int | None, typer.Option(
    "--port", min=1, max=65535, help="With --view: the port to serve on.",
    show_default="a free one")]


def parse_speed(text: str) -> float | None:
    """``--speed``: a positive factor, or None for ``max``."""
    import math

    from urdfkit.core.errors import ParameterError

    if text.strip().lower() == "max":
        return None
    try:
        value = float(text)
    except ValueError:
        value = math.nan
    if not (math.isfinite(value) and value > 0):
        raise ParameterError(f"`speed` takes a positive factor or max, got {text!r}",
                             param="speed")
    return value


def say_streaming(command: str, viewer: Any, pace: float | None) -> None:
    """Where a run streams, and how fast (on stderr: stdout stays the command's own)."""
    pacing = "as fast as it goes" if pace is None else \
        ("in real time" if pace == 1 else f"at {pace:g}x real time")
    show.line(f"urdfkit {command}: {viewer.url} (the run streams there {pacing})", stderr=True)


def check_wait(view: bool, no_wait: bool, wait_timeout: float | None) -> None:
    """``--wait-timeout`` takes ``--view``, and not ``--no-wait`` (which waits for nothing)."""
    import math

    from urdfkit.core.errors import ParameterError

    if wait_timeout is not None and not math.isfinite(wait_timeout):
        raise ParameterError(f"`wait_timeout` takes a number of seconds, got {wait_timeout}",
                             param="wait_timeout")
    if wait_timeout is not None and not view:
        raise ParameterError("`wait_timeout` bounds --view's wait for a page; add --view",
                             param="wait_timeout")
    if wait_timeout is not None and no_wait:
        raise ParameterError("`no_wait` waits for no page: drop --wait-timeout",
                             param="no_wait")


def wait_for_page(command: str, viewer: Any, wait: bool, timeout: float | None = None) -> bool:
    """Hold the run until a page has connected (``wait``), saying so on stderr; whether one has.

    A run streamed to nobody is over before anyone sees it: by default it starts when the
    first page connects. ``--no-wait`` (``wait`` False) starts it at once; ``--wait-timeout``
    (``timeout``) starts it unwatched after that many seconds. Without a terminal, nothing
    but a page, a signal or the timeout ends the wait: stderr says so. Interrupted, the page
    is closed.
    """
    import sys
    import time

    if not wait:
        return False
    head = f"urdfkit {command}: waiting for a page to connect to {viewer.url} before the run " \
           "starts"
    if timeout is not None:
        show.line(f"{head} (at most {timeout:g} s; then it starts unwatched)", stderr=True)
    elif sys.stdin is not None and sys.stdin.isatty():
        show.line(f"{head} (--no-wait starts it at once)", stderr=True)
    else:
        show.line(f"{head}; with no terminal, only a page, a signal (Ctrl-C) or --wait-timeout "
                  "ends the wait (--no-wait starts it at once)", stderr=True)
    end = None if timeout is None else time.monotonic() + timeout
    try:  # short waits: Ctrl-C is taken between them (and closes the page)
        while not viewer.wait_for_page(0.5 if end is None else
                                       max(0.0, min(0.5, end - time.monotonic()))):
            if end is not None and time.monotonic() >= end:
                show.line(f"urdfkit {command}: no page connected in {timeout:g} s; the run "
                          "starts unwatched and the command ends with it", stderr=True)
                return False
    except BaseException:
        viewer.close()
        raise
    show.line(f"urdfkit {command}: a page connected; the run starts", stderr=True)
    return True


def end_of_run(command: str, viewer: Any, watched: bool) -> None:
    """After a streamed run: a watched page stays until Ctrl-C; an unwatched one closes."""
    if watched:
        serve_until_interrupted(viewer, "the run is over; its page", command)
        return
    viewer.close()
    show.line(f"urdfkit {command}: the run is over; its page at {viewer.url} is closed",
              stderr=True)


def serve_until_interrupted(viewer: Any, what: str, command: str = "drive") -> None:
    """Keep a page up until Ctrl-C, then close it (the command's exit code is its own)."""
    import time

    try:  # the line inside: a Ctrl-C right after it still closes the page, exit unchanged
        show.line(f"urdfkit {command}: {what} stays at {viewer.url} until Ctrl-C", stderr=True)
        while True:
            time.sleep(3600)
    except KeyboardInterrupt:
        pass
    finally:
        viewer.close()
