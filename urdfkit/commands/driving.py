"""drive and sweep: a headless throttle/steer run, and many runs (urdfkit/drive.py, sweep)."""

from typing import Annotated, Any

import typer

from urdfkit.commands import present as show
from urdfkit.commands.flags import flag_message, input_flags
from urdfkit.commands.shared import (
    FROM_LIBRARY,
    AllOpt,
    ArgOpt,
    DrivetrainOpt,
    EngineOpt,
    ForceOpt,
    JsonOpt,
    MaxForceOpt,
    NoGuardOpt,
    NoWaitOpt,
    PackageOpt,
    PackagePathOpt,
    PlaneOpt,
    RunPortOpt,
    SecondsOpt,
    SetOpt,
    SpeedOpt,
    SteerOpt,
    StepsOpt,
    ThrottleOpt,
    TimeStepOpt,
    UpOpt,
    UrdfOpt,
    ViewOpt,
    WaitTimeoutOpt,
    check_wait,
    command,
    end_of_run,
    examples,
    library_defaults,
    parse_speed,
    say_streaming,
    split_joints,
    wait_for_page,
)


@command(examples(
    "urdfkit drive --throttle 10 --steer 0.2",
    "urdfkit drive --urdf racecar/racecar.urdf --seconds 5 --json",
    "urdfkit drive --urdf husky/husky.urdf --throttle 3 --steer 0.5   # skid steer: yaw rad/s",
    "urdfkit drive --steer 0.3 --trajectory run.csv --plot run.png"))
def drive(
    throttle: ThrottleOpt = FROM_LIBRARY,
    steer: SteerOpt = FROM_LIBRARY,
    drivetrain: DrivetrainOpt = FROM_LIBRARY,
    tutorial: Annotated[bool, typer.Option(
        "--tutorial", help="Reproduce the PyBullet tutorial's loop exactly: locked wheels, "
        "PyBullet's default motor force, no load flags, car at 0 0 0.1 before the plane.")]
    = False,
    seconds: SecondsOpt = None,
    steps: StepsOpt = None,
    time_step: TimeStepOpt = FROM_LIBRARY,
    max_force: MaxForceOpt = None,
    urdf: UrdfOpt = None,
    plane: PlaneOpt = None,
    set_: SetOpt = None,
    arg: ArgOpt = None,
    package: PackageOpt = None,
    package_path: PackagePathOpt = None,
    wheels: Annotated[list[str] | None, typer.Option(
        metavar="JOINTS", help="Wheel joints (names or indices, comma-separated) instead of "
        "the detected ones.")] = None,
    hinges: Annotated[list[str] | None, typer.Option(
        metavar="JOINTS", help="Steering hinge joints instead of the detected ones.")] = None,
    trajectory: Annotated[str | None, typer.Option(
        metavar="FILE", help="Write samples to FILE.csv or FILE.jsonl.")] = None,
    sample_every: Annotated[int | None, typer.Option(
        help="Steps between samples.", show_default="10 samples per simulated second")]
    = None,
    plot: Annotated[str | None, typer.Option(
        metavar="FILE.png", help="Draw the path and speed (needs urdfkit\\[plot]).")] = None,
    force: ForceOpt = False,
    gui: Annotated[bool, typer.Option(
        "--gui", help="Open the PyBullet GUI with Steering and Throttle sliders.")] = False,
    as_json: JsonOpt = False,
    no_guard: NoGuardOpt = False,
    up: UpOpt = FROM_LIBRARY,
    limp: Annotated[bool, typer.Option(
        "--limp", help="Let joints that are neither wheels, hinges nor casters go limp "
        "instead of holding their start angle (with the URDF's effort).")] = False,
    gazebo_contacts: Annotated[bool, typer.Option(
        "--gazebo-contacts", help="Apply the file's <gazebo reference> contact parameters, "
        "which PyBullet ignores: lateral friction from mu1/mu2 (the smaller), contact "
        "stiffness and damping from kp/kd.")] = False,
    no_mimic: Annotated[bool, typer.Option(
        "--no-mimic", help="Raw PyBullet, which ignores <mimic>: by default each follower is "
        "geared to its leader (multiplier x leader + offset).")] = False,
    view: ViewOpt = False,
    speed: SpeedOpt = "1",
    port: RunPortOpt = None,
    no_wait: NoWaitOpt = False,
    wait_timeout: WaitTimeoutOpt = None,
    engine: EngineOpt = FROM_LIBRARY,
) -> None:
    """Drive a car headless at a fixed throttle and steer, and report where it went.

    Wheels (continuous joints about a horizontal axis) and steering hinges (revolute joints
    about a vertical axis that carry wheels) are detected. See docs/drive.md.
    """
    from urdfkit.motion.drive import DriveConfig, Scenario

    pace = _check_drive_options(seconds=seconds, steps=steps, tutorial=tutorial,
                                drivetrain=drivetrain, max_force=max_force, gui=gui, view=view,
                                speed=speed, trajectory=trajectory, plot=plot, force=force)
    check_wait(view, no_wait, wait_timeout)
    params = None
    if set_:
        from urdfkit.model.catalog import parse_assignments  # imports the builder: only when needed

        params = parse_assignments(set_, "template_params")
    # seconds and max_force not given: DriveConfig's own defaults.
    given: dict[str, Any] = {name: value for name, value in (("seconds", seconds),
                                                           ("max_force", max_force))
             if value is not None}
    config = DriveConfig(
        urdf=urdf, plane=plane, template_params=params,
        packages=package, xacro_args=arg, steps=steps, time_step=time_step, throttle=throttle,
        steer=steer, drivetrain=drivetrain, tutorial=tutorial, keep_trajectory=plot is not None,
        wheels=split_joints(wheels), hinges=split_joints(hinges), sample_every=sample_every,
        gui=gui, guard=not no_guard, package_paths=package_path, up=up, limp=limp,
        gazebo_contacts=gazebo_contacts, mimic=not no_mimic, engine=engine, **given)
    with Scenario(config) as sc:
        _say_drivetrain(sc)
        said = list(sc.warnings)
        stream = _run_view(sc, config, pace, port) if view else None
        watched = stream is not None and wait_for_page("drive", stream.viewer, not no_wait,
                                                       wait_timeout)
        result, written = _drive_run(sc, trajectory, force=force, stream=stream,
                                     quiet=as_json or view)
    if plot is not None:
        from urdfkit.draw.plot import write_plot

        written.append(write_plot(result, plot, force=force))
    _drive_report(result, written, said, as_json)
    _drive_exit(result, stream, watched)


def use_library_defaults() -> None:
    """Give drive's and sweep's options DriveConfig's defaults (written once, in the library)."""
    from dataclasses import fields

    from urdfkit.motion.drive import DriveConfig

    defaults = {f.name: f.default for f in fields(DriveConfig)}
    library_defaults(drive, defaults)
    library_defaults(sweep, defaults)


def _check_drive_options(*, seconds: float | None, steps: int | None, tutorial: bool,
                         drivetrain: str, max_force: float | None, gui: bool, view: bool,
                         speed: str, trajectory: str | None, plot: str | None,
                         force: bool) -> float | None:
    """Refuse what cannot run together, and unwritable outputs, before the run; the pace."""
    from dataclasses import fields

    from urdfkit.core.errors import ParameterError
    from urdfkit.engine.session import has_display
    from urdfkit.motion.drive import DriveConfig
    from urdfkit.motion.drive_result import trajectory_format

    if seconds is not None and steps is not None:
        raise ParameterError("give `seconds` or `steps`, not both", param="seconds")
    default = next(f.default for f in fields(DriveConfig) if f.name == "drivetrain")
    if tutorial and (drivetrain != default or max_force is not None):
        raise ParameterError("`tutorial` fixes the drivetrain (locked) and the motor force "
                             "(PyBullet's default); drop --drivetrain and --max-force",
                             param="tutorial")
    if view and gui:
        raise ParameterError("`view` replaces `gui`: give one of them", param="view")
    pace = parse_speed(speed) if view else None
    if gui and not has_display():
        raise ParameterError("`gui` needs a display (DISPLAY is not set); drop it to drive "
                             "headless, or use --view", param="gui")
    # Check the outputs before a long run, not after it.
    if trajectory is not None:
        from urdfkit.core.output import check_output

        trajectory_format(trajectory)
        check_output(trajectory, force=force)
    if plot is not None:
        from urdfkit.draw.plot import check_plot_path

        check_plot_path(plot, force=force)
    return pace


def _say_drivetrain(sc: Any) -> None:
    """What was detected (wheels, hinges, casters, held and limp joints), and the warnings."""
    t = sc.drivetrain

    def names(joints: list[int]) -> str:
        return ", ".join(t.joint_names[j] for j in joints) or "none"

    casters = [t.joint_names[j] for j in t.casters] + \
        [t.link_names.get(k, str(k)) for k in t.caster_links]
    show.note(f"{sc.model}: wheels {names(t.wheels)}; hinges {names(t.hinges)}; "
              f"casters {', '.join(casters) or 'none'}; held {names(list(sc.held))}; "
              f"limp {names(sc.limp)}; drivetrain {t.mode} ({t.steering} steering)"
              + ("" if sc.config.engine == "pybullet" else f"; engine {sc.engine.label}"))
    if sc.gazebo_applied:
        show.note("Gazebo contacts applied: " + "; ".join(
            f"{k} " + ", ".join(f"{n} {v:g}" for n, v in vals.items())
            for k, vals in sc.gazebo_applied.items()))
    for w in sc.warnings:
        show.warn(w)


def _drive_run(sc: Any, trajectory: str | None, *, force: bool, stream: Any,
               quiet: bool) -> tuple[Any, list[Any]]:
    """The run, with a progress line (unless ``quiet``); the result and the files written."""
    progress, stop = show.progress("driving", "steps", enabled=not quiet)
    written = []
    try:
        if trajectory is None:
            result = sc.run(progress, sink=stream)
        else:
            from urdfkit.motion.drive import drive_to_file

            result, path = drive_to_file(sc, trajectory, force=force, progress=progress,
                                         sink=stream)
            written.append(path)
        if stream is not None:
            stream.finish(_run_view_summary(result))
    except BaseException:
        if stream is not None:
            stream.viewer.close()
        raise
    finally:
        stop()
    return result, written


def _drive_report(result: Any, written: list[Any], said: list[str], as_json: bool) -> None:
    """The run's JSON object (with the files written), or its summary and the files."""
    if as_json:
        data = result.to_dict()
        data["files"] = [str(w) for w in written]
        show.print_json(data)
    else:
        _drive_summary(result, said)
        for path in written:
            show.wrote(path)


def _drive_exit(result: Any, stream: Any, watched: bool) -> None:
    """130 interrupted; with --view, a watched page served until Ctrl-C; 1 a suspect run."""
    if result.interrupted:
        if stream is not None:
            stream.viewer.close()
        show.interrupted("interrupted; the results cover the steps simulated")
        raise typer.Exit(130)
    if stream is not None:
        end_of_run("drive", stream.viewer, watched)
    if result.problems:  # the run is physically suspect: a finding, for CI
        raise typer.Exit(1)


def _run_view(sc: Any, config: Any, pace: float | None, port: int | None) -> Any:
    """Start the page a run streams to (drive --view), and say where it is."""
    import math

    from urdfkit.draw.view import Viewer
    from urdfkit.draw.view_stream import RunStream, joint_reader

    total = config.total_steps * config.time_step
    reach = abs(config.throttle) * sc.drivetrain.reference_radius * total
    # Findings name the file the user gave, or the template: never the cache path built.
    display = config.urdf or "simplecar"
    viewer = Viewer(sc.car_file, packages=config.packages, package_paths=config.package_paths,
                    xacro_args=config.xacro_args, inertia_from_file=not config.tutorial,
                    port=port, watch=False, ground=float(max(4, math.ceil(2 * reach + 2))),
                    display=display, stand_on_grid=False)
    try:
        joints = joint_reader(sc.engine, sc.body, viewer.model.joints)
        stream = RunStream(viewer, sc.link_poses, pace, total, joints=joints)
        stream.push()
        say_streaming("drive", viewer, pace)
    except BaseException:
        viewer.close()
        raise
    return stream


def _run_view_summary(r: Any) -> str:
    """The run's summary, as the page shows it at the end."""
    x, y, _ = r.final_position
    radius = "none" if r.turning_radius is None else f"{r.turning_radius:.3f} m"
    text = (f"**Done**: {r.sim_time:.2f} s simulated; {r.distance:.3f} m along the path to "
            f"x {x:.3f}, y {y:.3f}; heading change {r.heading_change:.3f} rad; turning radius "
            f"{radius}")
    if r.problems:
        text += "\n\n**Problems**: " + "; ".join(r.problems)
    return text


@command(examples(
    "urdfkit sweep drive --vary steer=0.1,0.2,0.3 --seconds 5",
    "urdfkit sweep drive --vary wheel_radius=0.08:0.14:4 --vary steer=0.1,0.3 --out r.csv "
    "--plot turning_radius",
    "urdfkit sweep sim arm.toml --vary 'robots[0].motor.kp=50:400:8' --jobs 2 --out r.jsonl",
    "urdfkit sweep drive --vary steer=0:0.4:41 --backend ray --address auto --out r.parquet"))
def sweep(
    kind: Annotated[str, typer.Argument(
        metavar="drive|sim", help="What each point runs: a drive, or a scenario.")],
    scenario: Annotated[str | None, typer.Argument(
        metavar="[SCENARIO]", help="With sim: the scenario file (.json or .toml).",
        show_default=False)] = None,
    vary: Annotated[list[str] | None, typer.Option(
        "--vary", "-v", metavar="NAME=VALUES",
        help="A drive option, simplecar parameter or scenario key path, and its values: "
        "a,b,c or start:stop:count (repeatable: a grid).")] = None,
    zip_: Annotated[bool, typer.Option(
        "--zip", help="Pair the --vary lists point by point instead of a grid.")] = False,
    jobs: Annotated[int | None, typer.Option(
        "--jobs", "-j", min=1, help="Worker processes (1: in this process).",
        show_default="every core")] = None,
    backend: Annotated[str, typer.Option(
        "--backend", metavar="local|ray", help="local: a process pool; ray: Ray tasks "
        "(pip install 'urdfkit\\[ray]').")] = "local",
    address: Annotated[str | None, typer.Option(
        "--address", metavar="auto|ray://HOST:PORT",
        help="With --backend ray: the cluster to run on.", show_default="a local Ray")]
    = None,
    out: Annotated[str | None, typer.Option(
        "--out", "-o", metavar="FILE", help="Write the rows to FILE.csv, .jsonl or .parquet, "
        "as points finish (FILE.partial until the sweep ends).")] = None,
    resume: Annotated[bool, typer.Option(
        "--resume", help="Skip the points already in --out (or its .partial) without an "
        "error.")] = False,
    plot: Annotated[str | None, typer.Option(
        "--plot", metavar="METRIC", help="Draw METRIC against the varied value(s) (needs "
        "urdfkit\\[plot]).")] = None,
    plot_file: Annotated[str | None, typer.Option(
        "--plot-file", metavar="FILE.png", help="Where --plot draws.",
        show_default="sweep-METRIC.png")] = None,
    as_json: JsonOpt = False,
    show_all: AllOpt = False,
    force: ForceOpt = False,
    throttle: ThrottleOpt = FROM_LIBRARY,
    steer: SteerOpt = FROM_LIBRARY,
    drivetrain: DrivetrainOpt = FROM_LIBRARY,
    seconds: SecondsOpt = None,
    steps: StepsOpt = None,
    time_step: TimeStepOpt = FROM_LIBRARY,
    max_force: MaxForceOpt = None,
    urdf: UrdfOpt = None,
    plane: PlaneOpt = None,
    set_: SetOpt = None,
    arg: ArgOpt = None,
    package: PackageOpt = None,
    package_path: PackagePathOpt = None,
    up: UpOpt = FROM_LIBRARY,
    engine: EngineOpt = FROM_LIBRARY,
) -> None:
    """Run many drives or scenario runs, one row of results per point.

    Several --vary form a grid; --zip pairs them. The drive options (--throttle, --seconds,
    ...) hold for every point of a drive sweep. Every value is checked before any point runs;
    rows are written as points finish. Exit 0: every point ran; 1: some failed (their rows say
    why); 2: bad input; 130: interrupted (the rows so far are kept). See docs/sweep.md.
    """
    from urdfkit.motion import sweep_run

    request = sweep_run.SweepRequest(
        kind=kind, vary=vary, scenario=scenario, zip_=zip_, jobs=jobs, backend=backend,
        address=address, out=out, resume=resume, plot=plot, plot_file=plot_file, force=force,
        keep_rows=as_json, drive={
            "throttle": throttle, "steer": steer, "drivetrain": drivetrain, "seconds": seconds,
            "steps": steps, "time_step": time_step, "max_force": max_force, "urdf": urdf,
            "plane": plane, "template_params": set_, "xacro_args": arg, "packages": package,
            "package_paths": package_path, "up": up, "engine": engine})
    run = sweep_run.SweepRun(request)  # every option and point checked before any runs
    outcome = _sweep_run(run, as_json)
    _sweep_report(outcome, as_json, show_all, rows=out is None)
    if outcome.interrupted:
        show.interrupted("interrupted; the rows so far are kept")
        raise typer.Exit(130)
    if outcome.failed or outcome.plot_error is not None:
        raise typer.Exit(1)


def _sweep_report(outcome: Any, as_json: bool, show_all: bool, *, rows: bool) -> None:
    """The sweep's JSON object, or its table (of the rows, unless they went to a file)."""
    if as_json:
        show.print_json(outcome.to_dict())
        return
    show.sweep_report(outcome.plan, outcome.rows if rows else [], outcome.ran, outcome.failed,
                      outcome.skipped, show_all)
    for path in (outcome.out, outcome.plot):
        if path is not None:
            show.wrote(path)


def _sweep_run(run: Any, as_json: bool) -> Any:
    """Run the sweep with a progress line, saying the journal's notes; draw its plot."""
    for note in run.notes:
        show.warn(note)
    progress, stop = show.progress("sweeping", "points", enabled=not as_json, rate=True)
    try:
        outcome = run.run(progress)
    finally:
        stop()
    for note in outcome.notes:
        show.warn(note)
    run.draw(outcome)
    if outcome.plot_error is not None:
        show.warn(f"no plot: {input_flags(flag_message(outcome.plot_error.message))}")
    return outcome


def _drive_summary(r: Any, said: list[str]) -> None:
    x, y, z = r.final_position
    model = {"ackermann": "kinematic bicycle model", "differential": "v / omega"}.get(
        r.drivetrain.steering, "model")
    bicycle = ("" if r.expected_radius is None
               else f" ({model}: {r.expected_radius:.3f} m)")
    turn = (f"none: {r.radius_note}{bicycle}" if r.turning_radius is None else
            f"{r.turning_radius:.3f} m around ({r.turn_center[0]:.2f}, {r.turn_center[1]:.2f})"
            f"{bicycle}")
    sim = r.simulated
    force = (f"PyBullet's default ({sim['wheel_force']:g} N m)" if sim["wheel_force_default"]
             else f"{sim['wheel_force']:g} N m")
    flags = ", ".join(sim["load_flags"]) or "none"
    unit = "rad/s of yaw" if r.drivetrain.yaw_steered else "rad"
    show.fields([("drive", "bold"), f" {r.model}: throttle {r.throttle:g} rad/s, "
                 f"steer {r.steer:g} {unit}"], [
        ("final position", f"x {x:.3f}  y {y:.3f}  z {z:.3f} m"),
        ("final yaw", f"{r.final_yaw:.3f} rad ({r.final_yaw * 57.29577951308232:.1f} deg)"),
        ("heading change", f"{r.heading_change:.3f} rad"),
        ("distance", f"{r.distance:.3f} m along the path"),
        ("mean speed", f"{r.mean_speed:.3f} m/s"),
        ("turning radius", turn),
        ("drivetrain", f"{sim['drivetrain']}, {sim['steering']} steering; wheel force "
                       f"{force}"),
        ("load flags", flags),
        ("simulated", f"{r.sim_time:.3f} s in {r.steps:,} steps of {r.time_step:.5g} s"
                      + ("" if sim["engine"] == "pybullet" else f" on {sim['engine']}")
                      + f"; link damping {sim['link_damping']['linear']:g} "
                      f"({sim['link_damping']['note']})"),
        ("wall time", f"{r.wall_time:.3f} s (real-time factor {r.real_time_factor:.1f}x)"),
    ])
    # Every warning shows in text too, not only in JSON: those found by the run itself (a
    # base turning at a fraction of its command, the problems) after the summary.
    for w in r.warnings:
        if w not in said:
            show.warn(w)


# ---- render: headless PNG pictures (urdfkit/render.py) and tree --dot (urdfkit/graph.py)
