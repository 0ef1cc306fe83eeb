"""sim: scenario files run by urdfkit/sim.py, and sim convert."""

import sys
from pathlib import Path
from typing import Annotated, Any

import typer

from urdfkit.commands import present as show
from urdfkit.commands.shared import (
    ForceOpt,
    JsonOpt,
    NoWaitOpt,
    RunPortOpt,
    SpeedOpt,
    ViewOpt,
    WaitTimeoutOpt,
    check_wait,
    command,
    end_of_run,
    examples,
    parse_speed,
    say_streaming,
    wait_for_page,
)


@command(examples(
    "urdfkit sim scenario.toml -o rows.csv", "urdfkit sim scenario.toml --gui",
    "urdfkit sim configs/robot.json   # a simulation_and_control config",
    "urdfkit sim convert configs/robot.json -o scenario.toml"))
def sim(
    scenario: Annotated[str, typer.Argument(
        help="A scenario file (.json or .toml): robots, controllers, physics. See "
             "docs/scenario.md. A simulation_and_control config runs as it is. Or the word "
             "convert, then a simulation_and_control config: write it as a native scenario.",
        metavar="SCENARIO")],
    config: Annotated[str | None, typer.Argument(
        help="With convert: the simulation_and_control config (.json).",
        show_default=False)] = None,
    out: Annotated[str | None, typer.Option(
        "--out", "-o", metavar="FILE",
        help="Write the observation rows to FILE.jsonl, FILE.csv or FILE.parquet (with "
             "convert: the scenario to FILE.toml; default standard output).")] = None,
    gui: Annotated[bool, typer.Option(
        "--gui", help="Watch the run in PyBullet's GUI window, in real time (needs a "
                      "display).")] = False,
    real_time: Annotated[bool, typer.Option(
        "--real-time", help="Pace the steps to the wall clock.")] = False,
    as_json: JsonOpt = False,
    force: ForceOpt = False,
    view: ViewOpt = False,
    speed: SpeedOpt = "1",
    port: RunPortOpt = None,
    no_wait: NoWaitOpt = False,
    wait_timeout: WaitTimeoutOpt = None,
    engine: Annotated[str | None, typer.Option(
        "--engine", metavar="pybullet|mujoco", help="The physics engine instead of the "
        "scenario's physics.engine: mujoco runs the MJCF export in memory (needs "
        "urdfkit\\[mujoco]; docs/engines.md).", show_default="the scenario's")] = None,
) -> None:
    """Simulate a scenario of one or more robots and record their observations.

    Without --out a summary per robot prints; with --json, one JSON object (holding the rows
    too when there is no --out).
    """
    from urdfkit import sim as simulation

    if scenario == "convert":
        _check_convert(config, gui or real_time or as_json or view)
        assert config is not None
        _sim_convert(config, out, force)
        return
    pace = _check_sim_options(scenario, config, gui=gui, real_time=real_time, view=view,
                              speed=speed)
    check_wait(view, no_wait, wait_timeout)
    if out is not None:
        simulation.check_rows_output(out, force=force)  # fail before the run, not after it
    if engine is not None:
        from urdfkit.engine.registry import check

        check(engine)
    with simulation.Simulation.from_file(scenario, gui=gui, engine=engine) as s:
        for note in s.config.notes:
            show.warn(note)
        stream = _sim_view(s, pace, port) if view else None
        watched = stream is not None and wait_for_page("sim", stream.viewer, not no_wait,
                                                       wait_timeout)
        result, written = _sim_run(s, out, force=force, real_time=real_time or gui,
                                   stream=stream)
    if stream is not None and result.interrupted:
        stream.viewer.close()
        stream = None
    rows = result.to_dicts()
    summaries = simulation.summarize(result)
    if as_json:
        data: dict[str, Any] = {
            "scenario": scenario, "engine": s.engine.name,
            "time_step": result.time_step, "steps": result.steps,
            "duration": result.steps * result.time_step, "rows": result.row_count,
            "robots": [x.to_dict() for x in summaries],
            "out": None if written is None else str(written),
            "interrupted": result.interrupted}
        if written is None:
            data["observations"] = rows
        show.print_json(data)
    else:
        on = "" if s.engine.name == "pybullet" else f" on {s.engine.label}"
        _sim_table(scenario + on, result, summaries, written)
    if result.interrupted:
        show.interrupted("interrupted; the rows cover the steps simulated")
        raise typer.Exit(130)
    if stream is not None:
        end_of_run("sim", stream.viewer, watched)


def _check_convert(config: str | None, run_options: bool) -> None:
    """``sim convert`` needs a config, and takes none of the run's options."""
    from urdfkit.core.errors import ParameterError

    if config is None:
        raise ParameterError("convert needs the simulation_and_control config: "
                             "urdfkit sim convert conf.json -o scenario.toml",
                             param="scenario")
    if run_options:
        raise ParameterError("convert writes a file; --gui, --real-time, --view and --json "
                             "do not apply", param="scenario")


def _check_sim_options(scenario: str, config: str | None, *, gui: bool, real_time: bool,
                       view: bool, speed: str) -> float | None:
    """Refuse what cannot run together, before the run; the pace of ``--view``."""
    from urdfkit.core.errors import ParameterError
    from urdfkit.engine.session import has_display

    if config is not None:
        raise ParameterError(f"one scenario at a time; got {scenario!r} and {config!r} (to "
                             "convert a config: urdfkit sim convert conf.json)",
                             param="scenario")
    if view and (gui or real_time):
        raise ParameterError("`view` paces the run itself (--speed) and replaces `gui`: drop "
                             "--gui and --real-time", param="view")
    pace = parse_speed(speed) if view else None
    if gui and not has_display():
        raise ParameterError("`gui` needs a display (DISPLAY is not set); drop it to run "
                             "headless, or use --view", param="gui")
    return pace


def _sim_run(s: Any, out: str | None, *, force: bool, real_time: bool,
             stream: Any) -> tuple[Any, Any]:
    """The run, its rows to ``out`` if given, streamed to the page if any; result, file."""
    from urdfkit import sim as simulation

    written = None
    tick = None if stream is None else (lambda _batch: stream.tick(s.t))
    try:
        if out is None:
            result = s.run(real_time=real_time, sink=tick)
        else:
            result, written = simulation.run_to_file(s, out, force=force, real_time=real_time,
                                                     also=tick)
        if stream is not None:
            stream.finish(f"**Done**: {result.steps:,} steps of {result.time_step:.5g} s "
                          f"simulated, {result.row_count:,} rows")
    except BaseException:
        if stream is not None:
            stream.viewer.close()
        raise
    return result, written


def _sim_table(scenario: str, result: Any, summaries: list[Any], written: Any) -> None:
    """The text summary: a row per robot, its final joints, the file written."""
    fixed = show.fixed
    show.table(f"sim {scenario}: {result.steps:,} steps of {result.time_step:.5g} s", [
        ("robot", 0, "left"), ("rows", 0, "right"), ("end x y z (m)", 0, "left"),
        ("moved m", 1, "right"), ("top m/s", 1, "right"), ("yaw deg", 1, "right")], [
        [x.robot, str(x.rows), " ".join(fixed(v) for v in x.end), fixed(x.distance),
         fixed(x.top_speed), fixed(x.heading_deg, 1)] for x in summaries])
    for x in summaries:
        if x.final_joints:
            joints = ", ".join(f"{k} {fixed(v)}" for k, v in x.final_joints.items())
            show.line((x.robot, "cyan"), f" final joints: {joints}")
    if written is not None:
        show.wrote(written, f"{result.row_count:,} rows")


def _sim_view(s: Any, pace: float | None, port: int | None) -> Any:
    """Start the page a scenario streams to (sim --view): every robot, and say where."""
    from urdfkit.draw.view import Viewer
    from urdfkit.draw.view_stream import RunStream, joint_reader

    bodies = [b for b in s.bodies.values() if b.loaded is not None]
    if not bodies:
        from urdfkit.core.errors import ParameterError

        raise ParameterError("the scenario has no robot to show", param="view")
    first, options = bodies[0].loaded
    # Findings name the robot as the scenario does (its urdf, or its template), not the
    # built copy PyBullet loaded.
    display = bodies[0].config.urdf or bodies[0].config.template
    viewer = Viewer(first, inertia_from_file=options.inertia_from_file, port=port,
                    watch=False, ground=20.0, stand_on_grid=False,
                    display=str(display) if display else None)
    try:
        for b in bodies[1:]:
            viewer.add_robot(b.loaded[0], inertia_from_file=b.loaded[1].inertia_from_file)
        # The joint readouts show the followed robot's joints (the first's by default).
        models = [viewer.model, *(m for m, _ in viewer.extra)]
        joints = [joint_reader(s.engine, b.body, m.joints)
                  for b, m in zip(bodies, models, strict=True)]
        stream = RunStream(viewer, s.link_poses, pace, s.total_steps * s.time_step,
                           robots=True, joints=joints, names=[b.name for b in bodies])
        stream.push()
        say_streaming("sim", viewer, pace)
    except BaseException:
        viewer.close()
        raise
    return stream


def _sim_convert(config: str, out: str | None, force: bool) -> None:
    """``sim convert``: a simulation_and_control config as a native TOML scenario."""
    from urdfkit.core.errors import InputError
    from urdfkit.core.output import atomic_write, check_output
    from urdfkit.motion import sac
    from urdfkit.motion.scenario import read_document

    if out is not None and out != "-":
        check_output(out, force=force, suffixes=(".toml",), what="the scenario")
    data = read_document(config)
    if not sac.is_config(data):
        raise InputError("not a simulation_and_control config (no sim, robot_pybullet, "
                         "env_pybullet or robot_pin section); it is already a scenario",
                         file=config)
    imported = sac.convert(data, source=config)
    from urdfkit.motion.scenario import parse_scenario

    parse_scenario(imported.scenario, source=config)  # what is written must load
    for note in imported.notes:
        show.warn(note)
    if out is None or out == "-":
        sys.stdout.write(sac.to_toml(imported, source=config, out_dir=None))
        sys.stdout.flush()
        return
    text = sac.to_toml(imported, source=config, out_dir=Path(out).parent)
    show.wrote(atomic_write(out, text.encode("utf-8"), force=force),
               f"{len(imported.scenario['robots'])} robot(s)")
