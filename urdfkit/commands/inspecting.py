"""joints, links, tree, info: what PyBullet loads, as tables or JSON (urdfkit/engine/)."""

import sys
from typing import Annotated, Any

import typer

from urdfkit.commands import present as show
from urdfkit.commands.shared import (
    AllOpt,
    ArgOpt,
    FileArg,
    FixedBaseOpt,
    FlagsOpt,
    ForceOpt,
    JsonOpt,
    MovableOpt,
    NoGuardOpt,
    PackageOpt,
    PackagePathOpt,
    TypeOpt,
    command,
    examples,
    open_input_and_warn,
)


def _inspect(file: str, package: list[str] | None, arg: list[str] | None, *,
             fixed_base: bool = False, inertia_from_file: bool = False,
             links: bool = False, info: bool = False, no_guard: bool = False,
             package_path: list[str] | None = None, flags: str | None = None) -> Any:
    from urdfkit.engine.report import inspect_file
    from urdfkit.engine.session import LoadOptions, parse_flags

    if flags is not None:
        if inertia_from_file:
            from urdfkit.core.errors import ParameterError

            raise ParameterError("give --inertia-from-file or --flags (with "
                                 "URDF_USE_INERTIA_FROM_FILE in it), not both", param="flags")
        options = LoadOptions(fixed_base=fixed_base, **parse_flags(flags))
    else:
        options = LoadOptions(fixed_base=fixed_base, inertia_from_file=inertia_from_file)
    with open_input_and_warn(file, packages=package, xacro_args=arg, guard=not no_guard,
                             package_paths=package_path) as resolved:
        report = inspect_file(resolved, options, links=links, info=info)
    report.load_flags = options.flag_names()
    return report


def _loaded_with(report: Any) -> None:
    """The flags the robot was loaded with, under the table (text mode)."""
    show.note("loaded with " + (" | ".join(report.load_flags) or "no flags"), stderr=False)


@command(examples(
    "urdfkit joints r2d2.urdf", "urdfkit joints car.urdf --movable --type continuous",
    "urdfkit joints kuka_iiwa/model.urdf --json | jq '.joints[].jointName'"))
def joints(
    file: FileArg,
    as_json: JsonOpt = False,
    show_all: AllOpt = False,
    movable: MovableOpt = False,
    joint_type: TypeOpt = None,
    fixed_base: FixedBaseOpt = False,
    flags: FlagsOpt = None,
    package: PackageOpt = None,
    package_path: PackagePathOpt = None,
    arg: ArgOpt = None,
    no_guard: NoGuardOpt = False,
) -> None:
    """Every joint as PyBullet's getJointInfo sees it, decoded: index, type, limits, axis.

    --json prints {"file", "robot", "base_link", "joints": [...]} with the 17 getJointInfo
    fields under the Quickstart Guide names (jointIndex ... parentIndex); see docs/inspect.md.
    """
    from urdfkit.engine.joints import filter_joints

    report = _inspect(file, package, arg, fixed_base=fixed_base, no_guard=no_guard,
                      package_path=package_path, flags=flags)
    rows = filter_joints(report.joints, movable=movable, types=joint_type or ())
    if as_json:
        show.print_json({**report.header(), "joints": [j.to_dict() for j in rows],
                         "diagnostics": report.diagnostics})
        return
    show.diagnostics(report.diagnostics)
    num, nums = show.num, show.nums
    mimics = any(j.mimic for j in rows)  # the column only where a joint has one
    columns = [("#", 0, "right"), ("joint", 0, "left"), ("type", 0, "left"),
               ("child link", 1, "left"), ("parent", 3, "left"), ("limits", 1, "right"),
               ("axis", 2, "left"), *([("mimic", 2, "left")] if mimics else []),
               ("origin xyz", 3, "left"), ("origin rpy", 3, "left"),
               ("max force", 3, "right"), ("max vel", 3, "right"),
               ("parentFramePos", 4, "left"), ("parentFrameRpy", 4, "left"), ("q", 5, "right"),
               ("u", 5, "right"), ("damping", 6, "right"), ("friction", 6, "right"),
               ("quat", 9, "left"), ("flags", 9, "right"), ("jointAxis", 9, "left")]
    cells = []
    for j in rows:
        if j.limited:
            limits = f"{num(j.joint_lower_limit)} .. {num(j.joint_upper_limit)}"
        else:
            limits = "unlimited" if j.movable else ""
        cells.append([
            str(j.joint_index), j.joint_name, j.type_label, j.link_name,
            f"{j.parent_index} {j.parent_link_name}", limits,
            # The file's axis (the joint frame); PyBullet's jointAxis is in the child's
            # inertial frame, turned by an <inertial><origin rpy> (its own column).
            nums(j.axis_xyz if j.axis_xyz is not None else j.joint_axis) if j.movable else "",
            *([_mimic_cell(j.mimic, num)] if mimics else []),
            nums(j.origin_xyz) if j.origin_xyz is not None else "",
            nums(j.origin_rpy) if j.origin_rpy is not None else "",
            num(j.joint_max_force),
            num(j.joint_max_velocity), nums(j.parent_frame_pos), nums(j.parent_frame_rpy),
            str(j.q_index), str(j.u_index), num(j.joint_damping), num(j.joint_friction),
            nums(j.parent_frame_orn), str(j.flags), nums(j.joint_axis) if j.movable else ""])
    shown = f"{len(rows)} of {len(report.joints)}" if len(rows) != len(report.joints) \
        else str(len(rows))
    show.table(f"{report.robot}: {shown} joints, base link {report.base_link}", columns, cells,
               show_all)
    _loaded_with(report)
    if mimics:
        show.note("mimic: the file's <mimic> (position = leader x multiplier + offset); "
                  "PyBullet ignores it, so the joint moves on its own", stderr=False)


def _mimic_cell(mimic: dict[str, Any] | None, num: Any) -> str:
    """``leader x multiplier + offset`` of a joint's ``<mimic>`` ("" without one)."""
    if not mimic:
        return ""
    offset = mimic["offset"]
    return (f"{mimic['joint']} x {num(mimic['multiplier'])}"
            + (f" {'-' if offset < 0 else '+'} {num(abs(offset))}" if offset else ""))


@command(examples(
    "urdfkit links r2d2.urdf", "urdfkit links car.urdf --inertia-from-file",
    "urdfkit links car.urdf --json"))
def links(
    file: FileArg,
    as_json: JsonOpt = False,
    show_all: AllOpt = False,
    inertia_from_file: Annotated[bool, typer.Option(
        "--inertia-from-file",
        help="Load with URDF_USE_INERTIA_FROM_FILE. Without it PyBullet ignores <inertia> "
             "and recomputes it from the collision shapes.")] = False,
    fixed_base: FixedBaseOpt = False,
    flags: FlagsOpt = None,
    package: PackageOpt = None,
    package_path: PackagePathOpt = None,
    arg: ArgOpt = None,
    no_guard: NoGuardOpt = False,
) -> None:
    """Each link's getDynamicsInfo (mass, friction, inertia) beside what the file says.

    A '!' marks engine values that differ from the file's: by default PyBullet recomputes
    inertia from the collision shapes, and a link without <inertial> gets 1 kg.
    """
    report = _inspect(file, package, arg, fixed_base=fixed_base,
                      inertia_from_file=inertia_from_file, links=True, no_guard=no_guard,
                      package_path=package_path, flags=flags)
    inertia_from_file = "URDF_USE_INERTIA_FROM_FILE" in report.load_flags
    if as_json:
        show.print_json({**report.header(), "inertia_from_file": inertia_from_file,
                         "links": [link.to_dict() for link in report.links],
                         "diagnostics": report.diagnostics})
        return
    show.diagnostics(report.diagnostics)
    num, nums = show.num, show.nums
    columns = [("#", 0, "right"), ("link", 0, "left"), ("mass", 0, "right"),
               ("file mass", 1, "right"), ("inertia diagonal", 0, "left"),
               ("file principal inertia", 1, "left"), ("lateral", 2, "right"),
               ("rolling", 3, "right"), ("spinning", 3, "right"), ("restitution", 4, "right"),
               ("stiffness", 5, "right"), ("damping", 5, "right"), ("com xyz", 4, "left"),
               ("com quat", 9, "left")]
    cells = []
    differs = False
    for link in report.links:
        f = link.file
        mass_mark = " !" if link.mass_differs else ""
        inertia_mark = " !" if link.inertia_differs else ""
        differs = differs or bool(mass_mark or inertia_mark)
        cells.append([
            str(link.link_index), link.link_name, num(link.mass) + mass_mark,
            num(f.mass) if f else "none", nums(link.local_inertia_diagonal) + inertia_mark,
            nums(f.principal) if f else "none", num(link.lateral_friction),
            num(link.rolling_friction), num(link.spinning_friction), num(link.restitution),
            num(link.contact_stiffness), num(link.contact_damping),
            nums(link.local_inertial_pos), nums(link.local_inertial_orn)])
    inertia = "from the file" if inertia_from_file else "recomputed by PyBullet"
    show.table(f"{report.robot}: {len(report.links)} links, inertia {inertia}", columns, cells,
               show_all)
    _loaded_with(report)
    if differs and not inertia_from_file:
        show.note("! = PyBullet's value differs from the file's; --inertia-from-file keeps the "
                  "file's <inertia>", stderr=False)


@command(examples(
    "urdfkit tree r2d2.urdf", "urdfkit tree car.urdf --json",
    "urdfkit tree robot.urdf -o robot.svg"))
def tree(
    file: FileArg,
    as_json: JsonOpt = False,
    package: PackageOpt = None,
    package_path: PackagePathOpt = None,
    arg: ArgOpt = None,
    dot: Annotated[bool, typer.Option(
        "--dot", help="Print the graph as Graphviz DOT (links boxes, joints edges).")] = False,
    output: Annotated[str | None, typer.Option(
        "--output", "-o", help="Write the graph: .dot/.gv as DOT text, .svg/.png/.pdf drawn "
        "by Graphviz `dot` (implies --dot).")] = None,
    force: ForceOpt = False,
    no_guard: NoGuardOpt = False,
) -> None:
    r"""The kinematic tree: links, and the joints between them with type, axis and index.

    Read from the file alone; PyBullet is not loaded. \[n] is the index PyBullet will give
    the joint. --json is flat: every joint with its parent and child link, in index order.
    """
    from urdfkit.draw.tree import kinematic_tree

    if dot or output is not None:
        _tree_dot(file, package, arg, output, force, as_json, no_guard, package_path)
        return
    with open_input_and_warn(file, packages=package, xacro_args=arg, guard=not no_guard,
                             package_paths=package_path, meshes=False) as resolved:
        root = kinematic_tree(resolved.root)
        robot = resolved.robot_name
    if as_json:
        show.print_json({"file": file, "robot": robot, **root.to_flat_dict()})
        return
    show.tree(root, robot)


@command(examples(
    "urdfkit info r2d2.urdf", "urdfkit info car.urdf --fixed-base",
    "urdfkit info racecar/racecar.urdf --json"))
def info(
    file: FileArg,
    as_json: JsonOpt = False,
    fixed_base: FixedBaseOpt = False,
    flags: FlagsOpt = None,
    package: PackageOpt = None,
    package_path: PackagePathOpt = None,
    arg: ArgOpt = None,
    no_guard: NoGuardOpt = False,
) -> None:
    """The robot at a glance: links, joints by type, DOF, total mass, bounding box."""
    from urdfkit.model.spec import default_mass

    report = _inspect(file, package, arg, fixed_base=fixed_base, info=True, no_guard=no_guard,
                      package_path=package_path, flags=flags)
    s = report.summary
    if as_json:
        show.print_json({**report.header(), **s.to_dict(), "diagnostics": report.diagnostics})
        return
    show.diagnostics(report.diagnostics)
    num, nums = show.num, show.nums
    types = ", ".join(f"{n} {t}" for t, n in s.joint_types.items()) or "none"
    mass = f"{num(s.total_mass)} kg"
    if abs(s.total_mass - s.file_mass) > 1e-9 * max(1.0, s.file_mass):
        mass += f" (file says {num(s.file_mass)} kg"
        phantom = [n for n in s.links_without_inertial if default_mass(n)]
        if phantom:
            mass += f"; {len(phantom)} link(s) without <inertial> get 1 kg"
        mass += ")"
    show.fields([(s.robot, "bold")], [
        ("file", str(report.path)), ("base link", s.base_link),
        ("links", str(s.links)), ("joints", f"{s.joints} ({types})"),
        ("degrees of freedom", f"{s.dof}" + (" + 6 (floating base)" if s.static_base is None
                                             else f" (static base: {s.static_base})")),
        ("total mass", mass),
        ("bounding box", f"{nums(s.aabb_min)} .. {nums(s.aabb_max)}"),
        ("size", f"{nums(s.size)} m"),
        ("loaded with", " | ".join(report.load_flags) or "no flags (--flags)"),
    ])


# ---- check: validation rules over files and folders (urdfkit/check.py, urdfkit/validate.py)


def _tree_dot(file: str, package: list[str] | None, arg: list[str] | None,
              output: str | None, force: bool, as_json: bool, no_guard: bool,
              package_path: list[str] | None) -> None:
    """``tree --dot`` / ``tree -o graph.svg``: the kinematic graph as DOT text or a drawing."""
    from urdfkit.core.errors import ParameterError
    from urdfkit.draw.graph import check_graph_path, dot_graph, write_graph

    if as_json:
        raise ParameterError("--json and --dot/-o are different outputs; choose one")
    if output is not None and output != "-":
        check_graph_path(output, force=force)
    with open_input_and_warn(file, packages=package, xacro_args=arg, guard=not no_guard,
                             package_paths=package_path) as resolved:
        text = dot_graph(resolved.root)
    if output is None or output == "-":
        sys.stdout.write(text)
        sys.stdout.flush()
        return
    show.wrote(write_graph(text, output, force=force))


# ---- sim: scenario files (urdfkit/scenario.py) run by urdfkit/sim.py
