"""render and view: a robot drawn to a PNG, or shown in a browser page."""

import sys
from pathlib import Path
from typing import TYPE_CHECKING, Annotated, cast

import typer

from urdfkit.commands import present as show
from urdfkit.commands.shared import (
    ArgOpt,
    FileArg,
    ForceOpt,
    NoGuardOpt,
    PackageOpt,
    PackagePathOpt,
    command,
    examples,
)

if TYPE_CHECKING:
    from urdfkit.model.spec import UpAxis


@command(examples(
    "urdfkit render r2d2.urdf", "urdfkit render car.urdf --views all -o car.png",
    "urdfkit render arm.urdf --joints elbow=1.2 --frames --collision -o arm.png"))
def render(
    file: FileArg,
    output: Annotated[str | None, typer.Option(
        "--output", "-o", help="The PNG to write; '-' for stdout.",
        show_default="<name>.png here")] = None,
    view: Annotated[str, typer.Option(
        "--view", help="Camera: iso, front, side or top.")] = "iso",
    views: Annotated[str | None, typer.Option(
        "--views", metavar="all|V,V,V,V",
        help="Four views as a labelled 2x2 grid: 'all' (iso, front, side, top) or a list.")]
    = None,
    size: Annotated[str, typer.Option("--size", metavar="WxH", help="Image size in pixels.")]
    = "800x600",
    ground: Annotated[str, typer.Option(
        "--ground", help="grid (lines), plane (shaded, with shadow) or none.")] = "grid",
    joints: Annotated[list[str] | None, typer.Option(
        "--joints", "-j", metavar="NAME=VALUE",
        help="Pose a joint before the shot, in rad or m (repeatable, or a=1,b=2).")] = None,
    collision: Annotated[bool, typer.Option(
        "--collision", help="Draw the collision shapes instead of the visuals.")] = False,
    frames: Annotated[bool, typer.Option(
        "--frames", help="Mark link frames (x red, y green, z blue) and joint axes.")] = False,
    up: Annotated[str, typer.Option(
        "--up", metavar="z|y|x", help="The model's up axis: y stands up a Y-up model (CAD "
        "and graphics exports) that would otherwise lie down.")] = "z",
    as_json: Annotated[bool, typer.Option(
        "--json", help="Print what was drawn (cameras, bounding box) as JSON.")] = False,
    force: ForceOpt = False,
    package: PackageOpt = None,
    package_path: PackagePathOpt = None,
    arg: ArgOpt = None,
    no_guard: NoGuardOpt = False,
) -> None:
    """Draw a robot to a PNG, headless (PyBullet's TinyRenderer: no GPU, no display)."""
    from urdfkit.draw import render as rendering

    width, height = rendering.parse_size(size)
    if views is None:
        chosen: tuple[str, ...] = (view,)
    elif views.strip() == "all":
        chosen = rendering.ALL_VIEWS
    else:
        chosen = tuple(v.strip() for v in views.split(",") if v.strip())
    # The flags' text as RenderOptions' literals: it checks each one (the view, the ground,
    # the up axis) and refuses any other with a "did you mean".
    options = rendering.RenderOptions(
        views=cast("tuple[rendering.View, ...]", chosen), width=width, height=height,
        ground=cast("rendering.Ground", ground),
        joints=rendering.parse_joint_positions(joints), collision=collision, frames=frames,
        up=cast("UpAxis", up))
    out = output if output is not None else f"{Path(file).name.split('.')[0] or 'robot'}.png"
    if out != "-":  # refuse before the work, not after it
        rendering.check_picture_path(out, force=force)
    picture = rendering.render_file(file, options, packages=package, xacro_args=arg,
                                    guard=not no_guard, package_paths=package_path)
    for w in picture.warnings:
        show.warn(w)
    if out == "-":
        sys.stdout.buffer.write(picture.png_bytes())
        sys.stdout.flush()
        return
    path = rendering.write_png(picture, out, force=force)
    if as_json:
        show.print_json({"output": str(path), **picture.to_dict()})
        return
    show.wrote(path, f"{picture.width}x{picture.height}, {', '.join(chosen)}"
               f"{', collision shapes' if collision else ''}")


@command(examples(
    "urdfkit view r2d2.urdf", "urdfkit view arm.urdf.xacro --arg prefix:=left_ --open",
    "urdfkit view robot.urdf --host 0.0.0.0 --port 8080"))
def view(
    file: FileArg,
    port: Annotated[int | None, typer.Option(
        "--port", min=1, max=65535, help="The port to serve on.", show_default="a free one")]
    = None,
    host: Annotated[str, typer.Option(
        "--host", help="The address to serve on; 0.0.0.0 serves beyond this machine.")]
    = "127.0.0.1",
    open_browser: Annotated[bool, typer.Option("--open", help="Open the page in a browser.")]
    = False,
    inertia_from_file: Annotated[bool, typer.Option(
        "--inertia-from-file", help="Load the file's <inertia> (URDF_USE_INERTIA_FROM_FILE) "
        "instead of PyBullet's recomputed one.")] = False,
    package: PackageOpt = None,
    package_path: PackagePathOpt = None,
    arg: ArgOpt = None,
) -> None:
    """Show the robot in a browser as PyBullet loads it, with check's findings on its links.

    Joint sliders, visual and collision shapes, frames, centres of mass and inertia boxes;
    the page reloads when the file or its includes and meshes change.
    Serves until Ctrl-C (exit 130). See docs/view.md.
    """
    from urdfkit.draw.view import Viewer

    viewer = Viewer(file, packages=package, package_paths=package_path, xacro_args=arg,
                    inertia_from_file=inertia_from_file, host=host, port=port)
    try:
        show.line(f"urdfkit view: {viewer.url} (Ctrl-C to stop)")
        if open_browser:
            import webbrowser

            webbrowser.open(viewer.url)
        import time

        while True:
            time.sleep(3600)
    finally:
        viewer.close()
